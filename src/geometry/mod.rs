//! Geometry shared by the engines: neighbour search, ellipsoid overlap, soft-contact walls (`wall`), the
//! hard-sphere wall primitives with their times of impact (`walls`), lattices, Voronoi cells, shape models.

pub mod ellipsoid_overlap;
pub mod lattice;
pub mod neighbours;
pub mod polyhedron;
pub mod shape_metrics;
pub mod voronoi;
pub mod wall;
pub mod walls;
