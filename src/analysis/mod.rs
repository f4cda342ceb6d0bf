//! Post-processing of states and runs.

pub mod atmosphere;
pub mod figures;
pub mod fits;
pub mod fragments;
pub mod report_richardson2011;
pub mod report_roig2003;
pub mod report_zhang2017;
pub use crate::ellipsoid::rigid_rotation;
pub mod run_analysis;
pub use crate::geometry::shape_metrics;
pub mod spinup;
pub mod spinup_search;
pub use crate::granular::soft::spinup_diagnostics;
pub mod tumbler;
