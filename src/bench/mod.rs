//! Benchmarks and timed systems, on the canonical test problems that the library keeps beside what they exercise
//! (the russell_ode layout: [`rubblepile::integrate::problems`], ODE problems with known solutions;
//! [`rubblepile::impact::problems`], the problems of the ellipsoid model; [`crate::bench::stability`], the stability
//! suite's cases):
//! - [`work_precision`]: work–precision measurements (timed runs, final-state and energy errors);
//! - [`stability`]: the result files of the stability suite of stiff and extreme cases (`rubblepile bench stability`);
//! - the timed systems behind `rubblepile bench …`, each writing CSV and a plot: [`rhs`] (µs per right-hand side,
//!   1 thread vs all), [`work_precision_sweep`] (error vs time per method), [`nbody`] (point-mass runs, REBOUND
//!   comparison), [`impact_wall_time`] (the N200 impact's wall time), [`hsdem`] (hard-sphere collisions per
//!   second), [`scaling`] (every engine's strong scaling), [`critical`] (a T_c,3 search's holds one at a time
//!   and several at once). Their option structs derive `clap::Args` so the command
//!   line embeds them; the command line itself only parses and dispatches.

pub mod ab;
pub mod critical;
pub mod hsdem;
pub mod impact_wall_time;
pub mod memory;
pub mod nbody;
pub mod render;
pub mod rhs;
pub mod scaling;
pub mod ssdem;
pub mod stability;
pub mod tolerance;
pub mod work_precision;
pub mod work_precision_sweep;

/// Why a benchmark did not run: bad options (the caller's, exit code 2 on the command line) or a failure while
/// running or writing its files (exit code 1).
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
pub struct BenchError {
    /// One line.
    pub message: String,
    /// 2 for bad options, 1 for a failure.
    pub code: u8,
}

impl BenchError {
    /// Bad options or inputs.
    pub fn usage(message: impl std::fmt::Display) -> Self {
        BenchError {
            message: message.to_string(),
            code: 2,
        }
    }
    /// A failure while running or writing.
    pub fn failed(message: impl std::fmt::Display) -> Self {
        BenchError {
            message: message.to_string(),
            code: 1,
        }
    }
}

impl From<String> for BenchError {
    /// A message from a reader or a timed system: a failure.
    fn from(message: String) -> Self {
        BenchError::failed(message)
    }
}

impl From<BenchError> for String {
    /// The one-line message, for callers that report errors as text.
    fn from(e: BenchError) -> Self {
        e.message
    }
}
