//! What the subcommands share: the error of the command line ([`CliError`], its exit codes), the checkpoint and
//! progress flags of `run`, `resume` and the batch commands ([`CheckpointArgs`]), and the report of a run's end
//! ([`report`]). Below `cli/mod.rs`, which re-exports them, so that each subcommand's file uses them one way.

use crate::driver::{DEFAULT_CHECKPOINT_EVERY, RunOptions};

/// A CLI failure: the message (one line) and the exit code.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CliError {
    /// One-line message (printed after `error: `).
    pub message: String,
    /// Exit code: 2 bad input, 1 failed run, 3 stopped after a checkpoint on request.
    pub code: u8,
}

impl CliError {
    /// Bad input (exit code 2).
    pub fn usage(message: impl std::fmt::Display) -> Self {
        CliError {
            message: message.to_string(),
            code: 2,
        }
    }
    /// A failure while running (exit code 1).
    pub fn failed(message: impl std::fmt::Display) -> Self {
        CliError {
            message: message.to_string(),
            code: 1,
        }
    }
}

/// When `run` and `resume` write `DIR/checkpoint.json` (always at an output sample), and how often a batch log
/// gets a progress line.
#[derive(Debug, Clone, clap::Args)]
pub struct CheckpointArgs {
    /// Checkpoint at the first output sample after every SECONDS of wall-clock time (0 = never).
    #[arg(long, value_name = "SECONDS", default_value_t = DEFAULT_CHECKPOINT_EVERY)]
    pub checkpoint_every: f64,
    /// Also checkpoint at the first output sample SECONDS of simulated time after the last
    /// checkpoint (0 = at every output sample).
    #[arg(long, value_name = "SECONDS")]
    pub checkpoint_every_sim: Option<f64>,
    /// Extra snapshot format(s) beside the CSV snapshots, e.g. `--format xyz` (extended XYZ for OVITO/VMD/ASE);
    /// repeat for several.
    #[arg(long, value_name = "NAME")]
    pub format: Vec<String>,
    /// When stderr is not a terminal (a batch log): a progress line (t, %, ETA, the energy error) every SECONDS
    /// of wall-clock time, 0 = none [default: $RUBBLEPILE_PROGRESS_EVERY, else 60]. On a terminal the bar is shown.
    #[arg(long, value_name = "SECONDS")]
    pub progress_every: Option<f64>,
    /// Testing: exit with code 3 right after the N-th checkpoint this process writes.
    #[arg(long, value_name = "N", hide = true)]
    pub stop_after_checkpoints: Option<u64>,
}

impl CheckpointArgs {
    /// The run options these arguments ask for.
    pub(crate) fn options(&self, progress: bool) -> Result<RunOptions, CliError> {
        let ok = |v: f64| v.is_finite() && v >= 0.0;
        if !ok(self.checkpoint_every) {
            return Err(CliError::usage(format!(
                "--checkpoint-every must be a finite number of seconds >= 0, got {}",
                self.checkpoint_every
            )));
        }
        if let Some(s) = self.checkpoint_every_sim
            && !ok(s)
        {
            return Err(CliError::usage(format!(
                "--checkpoint-every-sim must be a finite number of seconds >= 0, got {s}"
            )));
        }
        if self.stop_after_checkpoints == Some(0) {
            return Err(CliError::usage("--stop-after-checkpoints must be at least 1"));
        }
        use crate::driver::progress::{DEFAULT_PROGRESS_EVERY, PROGRESS_EVERY_ENV};
        let progress_every = match (self.progress_every, std::env::var(PROGRESS_EVERY_ENV)) {
            (Some(s), _) if ok(s) => s,
            (Some(s), _) => {
                return Err(CliError::usage(format!(
                    "--progress-every must be a finite number of seconds >= 0, got {s}"
                )));
            }
            (None, Ok(text)) => match text.trim().parse::<f64>() {
                Ok(s) if ok(s) => s,
                _ => {
                    return Err(CliError::usage(format!(
                        "{PROGRESS_EVERY_ENV} must be a finite number of seconds >= 0, got {text:?}"
                    )));
                }
            },
            (None, Err(_)) => DEFAULT_PROGRESS_EVERY,
        };
        Ok(RunOptions {
            force: false,
            progress,
            checkpoint_every: (self.checkpoint_every > 0.0).then_some(self.checkpoint_every),
            checkpoint_every_sim: self.checkpoint_every_sim,
            formats: crate::driver::formats::Formats::parse(&self.format).map_err(CliError::usage)?,
            progress_every,
            stop_after_checkpoints: self.stop_after_checkpoints,
        })
    }
}

impl From<crate::bench::BenchError> for CliError {
    fn from(e: crate::bench::BenchError) -> Self {
        CliError {
            message: e.message,
            code: e.code,
        }
    }
}

/// Prints the one-line summary of a finished (or failed) run and its warnings (`warning: …` lines on stderr, e.g.
/// contact-barrier overruns); maps errors to exit codes.
pub(crate) fn report<S: crate::engine::RunReport>(
    result: Result<S, crate::driver::RunError<S>>,
) -> Result<(), CliError> {
    let print = |summary: &S| {
        println!("{}", summary.one_line());
        for w in summary.warnings() {
            eprintln!("warning: {w}");
        }
    };
    match result {
        Ok(summary) => {
            print(&summary);
            Ok(())
        }
        Err(e) => {
            if let crate::driver::RunError::Failed { summary, .. } = &e {
                print(summary);
            }
            Err(CliError {
                message: e.to_string(),
                code: e.exit_code(),
            })
        }
    }
}
