//! The stability suite: the interacting-ellipsoids model (Roig03 §2, Eqs. 10–14, 28–41) pushed to its
//! regimes of trouble, each as an ordinary scene run through [`rubblepile::driver::run_scene`].
//!
//! The cases ([`cases::all_cases`]) are (a) head-on impacts at the calibrated speed of Roig03 Eq. 14 and
//! above it (the contact-barrier detector of [`rubblepile::ellipsoid::barrier`] must name the pair), (b) needles
//! and plates with C/A = 0.05, (c) a mass ratio of 1e-6, (d) attitudes at the Euler-angle singularity θ = 0,
//! (e) stiff dissipation F0 = 100 s m⁻², (f) κ from 1.6 to 50, (g) a cloud of N = 2000 collapsing,
//! (h) a resting contact held for 1e6 s. `rubblepile bench stability` runs them and writes `stability.csv`
//! and `stability.md`; `tests/stability.rs` runs the quick set.
//!
//! # Verdicts
//!
//! Every case states its numeric criteria in its row's `note`:
//! - **pass**: the run did what the case expects (completed, or stopped with the expected message) and
//!   every criterion holds, *including* an expected warning (the 3× impact must report its overrun);
//! - **warn**: the run completed and the hard criteria hold, but a soft one missed (e.g. the energy residual
//!   between the strict and the loose bound, or an unexpected barrier warning);
//! - **fail**: a hard criterion broke: a crash or a stop the case does not expect, NaN, an energy residual
//!   above the loose bound, a missing or wrong warning.

use std::path::{Path, PathBuf};
use std::time::Instant;

use rubblepile::driver::{RunError, RunOptions, run_scene};
use rubblepile::ellipsoid::scene::parse_scene;

pub use super::case::{Case, CaseRun, Verdict};

/// One row of `stability.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct StabilityRow {
    /// Case id.
    pub case: String,
    /// Case description.
    pub description: String,
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps.
    pub rejections: u64,
    /// Right-hand-side evaluations.
    pub rhs_evaluations: u64,
    /// Wall-clock time of the case (s): the run, including output.
    pub wall_seconds: f64,
    /// The run's relative energy residual `max |H − H0 − 2∫F| / energy scale`
    /// ([`rubblepile::driver::RunSummary::energy_error`]).
    pub energy_error: f64,
    /// max over samples and bodies of `||q| − 1|`.
    pub max_quat_norm_error: f64,
    /// Smallest accepted step (s); NaN before the first step.
    pub min_step: f64,
    /// The verdict.
    pub verdict: Verdict,
    /// The criteria and measured values.
    pub note: String,
}

/// A case's result: its row and its run (for further checks by tests).
#[derive(Debug)]
pub struct CaseResult {
    /// The row.
    pub row: StabilityRow,
    /// The run.
    #[cfg_attr(not(test), allow(dead_code, reason = "read by the suite's tests"))]
    pub run: CaseRun,
}

/// Why the suite could not run. One-line messages.
#[derive(Debug, thiserror::Error)]
pub enum StabilityError {
    /// The output directory already holds results and `--force` was not given.
    #[error("--out: {} already holds stability results; use --force to overwrite them", .0.display())]
    OutputExists(PathBuf),
    /// A case's scene did not parse (a bug in the case definitions).
    #[error("case {case}: scene: {message}")]
    Scene {
        /// Case id.
        case: String,
        /// The scene error.
        message: String,
    },
    /// A run could not start or write its outputs.
    #[error("case {case}: {message}")]
    Run {
        /// Case id.
        case: String,
        /// The error.
        message: String,
    },
    /// Writing a result file failed.
    #[error("{}: {source}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
}

/// Runs one case into `runs_dir/<id>` (`force`: overwrite a previous run there) and judges it.
pub fn run_case(case: &Case, runs_dir: &Path, force: bool) -> Result<CaseResult, StabilityError> {
    let name = format!("{}.toml", case.id);
    let scene = parse_scene(&case.scene_toml, &name, None).map_err(|e| StabilityError::Scene {
        case: case.id.clone(),
        message: e.to_string(),
    })?;
    let dir = runs_dir.join(&case.id);
    let options = RunOptions {
        force,
        progress: false,
        checkpoint_every: None,
        checkpoint_every_sim: None,
        formats: rubblepile::driver::formats::Formats::NONE,
        stop_after_checkpoints: None,
        ..RunOptions::default()
    };
    let started = Instant::now();
    let (summary, failure) = match run_scene(&scene, &dir, &options) {
        Ok(s) => (s, None),
        Err(RunError::Failed { cause, summary, .. }) => (*summary, Some(cause)),
        Err(e) => {
            return Err(StabilityError::Run {
                case: case.id.clone(),
                message: e.to_string(),
            });
        }
    };
    let wall_seconds = started.elapsed().as_secs_f64();
    let run = CaseRun {
        dir,
        scene,
        summary,
        failure,
    };
    let j = (case.check)(&run);
    let s = &run.summary;
    let row = StabilityRow {
        case: case.id.clone(),
        description: case.description.clone(),
        steps: s.steps_accepted,
        rejections: s.steps_rejected,
        rhs_evaluations: s.rhs_evaluations,
        wall_seconds,
        energy_error: s.energy_error,
        max_quat_norm_error: s.quaternion_norm_error,
        min_step: s.smallest_step.unwrap_or(f64::NAN),
        verdict: j.verdict,
        note: j.note,
    };
    Ok(CaseResult { row, run })
}
#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::stability::case::judge;

    #[test]
    fn judge_orders_verdicts() {
        let ok = |hard| (hard, true, "x".to_string());
        let bad = |hard| (hard, false, "y".to_string());
        assert_eq!(judge(&[ok(true), ok(false)]).verdict, Verdict::Pass);
        assert_eq!(judge(&[ok(true), bad(false)]).verdict, Verdict::Warn);
        let j = judge(&[bad(true), bad(false)]);
        assert_eq!(j.verdict, Verdict::Fail);
        assert_eq!(j.note, "NOT MET: y; NOT MET: y");
    }
}
