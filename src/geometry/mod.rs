//! Geometry shared by the engines: neighbour search, ellipsoid overlap, walls (`walls`: the hard-sphere wall
//! primitives with their times of impact, and the soft-contact walls in `walls::soft`), lattices, Voronoi cells,
//! shape metrics, shape models.

pub mod ellipsoid_overlap;
pub mod lattice;
pub mod mesh;
pub mod neighbours;
pub mod polyhedron;
pub mod shape_metrics;
pub mod voronoi;
pub mod walls;
