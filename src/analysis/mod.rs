//! Post-processing of states and runs.

pub mod rigid_rotation;
