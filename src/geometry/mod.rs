//! Geometry shared by the engines: neighbour search, ellipsoid overlap, wall primitives, lattices, Voronoi
//! cells, shape models.

pub mod ellipsoid_overlap;
pub mod lattice;
pub mod neighbours;
pub mod polyhedron;
pub mod voronoi;
pub mod wall;
