//! Geometry shared by the engines: neighbour search (and, later, wall primitives).

pub mod ellipsoid_overlap;
pub mod neighbours;
pub mod polyhedron;
