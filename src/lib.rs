#![warn(missing_docs)]
//! rubblepile — dynamics of rubble-pile asteroids.
//!
//! The core is the interacting-ellipsoids model of Roig et al. (2003, Icarus 165) ("Roig03"):
//! rigid triaxial fragments with a Gaussian-overlap contact potential, monopole gravity,
//! quaternion attitudes constrained by Lagrange multipliers, a Rayleigh point-dissipation function,
//! integrated by an adaptive Bulirsch–Stoer integrator.

pub mod aggregate;
pub mod analysis;
pub mod bench;
pub mod bits;
pub mod cli;
pub mod driver;
pub mod ellipsoid;
pub mod engine;
pub mod geometry;
pub mod granular;
pub mod gravity;
pub mod impact;
pub mod integrate;
pub mod io;
pub mod math;
pub mod random;
