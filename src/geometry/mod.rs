//! Geometry shared by the engines: neighbour search and wall primitives.

pub mod ellipsoid_overlap;
pub mod neighbours;
pub mod wall;
