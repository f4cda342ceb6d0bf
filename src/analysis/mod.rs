//! Post-processing of states and runs.

pub mod atmosphere;
pub mod figures;
pub mod fits;
pub mod fragments;
pub mod report_roig2003;
pub mod report_zhang2017;
pub mod rigid_rotation;
pub mod run_analysis;
pub mod shape_metrics;
pub mod spinup;
pub mod spinup_diagnostics;
pub mod tumbler;
