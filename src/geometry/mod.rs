//! Geometry shared by the engines: neighbour search (and, later, wall primitives).

pub mod neighbours;
