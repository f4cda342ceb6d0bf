//! Geometry shared by the engines: neighbour search and the hard-sphere wall primitives.

pub mod ellipsoid_overlap;
pub mod neighbours;
pub mod walls;
