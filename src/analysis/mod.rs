//! Post-processing of states and runs: what any run needs (fragments, fits, clumps, composition, flyby outcome,
//! spin-up diagnostics, the verdicts of T_c,3 searches, creep, campaigns against any field, figures). The three papers' reports are in the binary, in `src/studies/` (nothing here names them).

pub mod campaign_analysis;
pub mod campaign_by;
pub mod clumps;
pub mod composition;
pub mod creep;
pub mod critical;
pub mod figures;
pub mod fits;
pub mod flyby;
pub mod fragments;
pub mod q_star_bootstrap;
pub use crate::ellipsoid::rigid_rotation;
pub mod run_analysis;
pub use crate::geometry::shape_metrics;
pub mod spin_likelihood;
pub mod spinup;
pub use crate::granular::soft::spinup_diagnostics;

/// Why an analysis could not be made: a run directory or file to read is missing or malformed, or a figure or
/// report could not be written. Messages are one line naming the file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AnalysisError {
    /// A run or input file is missing, unreadable or malformed.
    #[error("{0}")]
    Input(String),
    /// A figure or report could not be written.
    #[error("{0}")]
    Output(String),
}

impl From<String> for AnalysisError {
    /// A message from a reader: an input error.
    fn from(message: String) -> Self {
        AnalysisError::Input(message)
    }
}

impl From<crate::io::table::TableError> for AnalysisError {
    fn from(e: crate::io::table::TableError) -> Self {
        AnalysisError::Input(e.to_string())
    }
}

impl From<AnalysisError> for String {
    /// The one-line message, for callers that report errors as text.
    fn from(e: AnalysisError) -> Self {
        e.to_string()
    }
}

impl From<&str> for AnalysisError {
    /// A message from a figure or reader: an input error.
    fn from(message: &str) -> Self {
        AnalysisError::Input(message.to_string())
    }
}
