//! What the subcommands share: the error of the command line ([`CliError`], its exit codes), the checkpoint and
//! progress flags of `run`, `resume` and the batch commands ([`CheckpointArgs`]), and the report of a run's end
//! ([`report`]). Below `cli/mod.rs`, which re-exports them, so that each subcommand's file uses them one way.

use rubblepile::driver::{DEFAULT_CHECKPOINT_EVERY, RunOptions};

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
    /// Checkpoint at the first output sample after every SECONDS of wall-clock time (0 = never; else 0.001 to
    /// 1e7).
    #[arg(long = "checkpoint-every-s", value_name = "SECONDS", default_value_t = DEFAULT_CHECKPOINT_EVERY)]
    pub checkpoint_every: f64,
    /// Also checkpoint at the first output sample SECONDS of simulated time after the last
    /// checkpoint (0 = at every output sample; at most 1e18).
    #[arg(long = "checkpoint-every-sim-s", value_name = "SECONDS")]
    pub checkpoint_every_sim: Option<f64>,
    /// Extra snapshot format(s) beside the CSV snapshots, e.g. `--format xyz` (extended XYZ for OVITO/VMD/ASE);
    /// repeat for several.
    #[arg(long, value_name = "NAME")]
    pub format: Vec<String>,
    /// When stderr is not a terminal (a batch log): a progress line (t, %, ETA, the energy error) every SECONDS
    /// of wall-clock time (0.1 to 1e7), 0 = none [default: $RUBBLEPILE_PROGRESS_EVERY, else 60]. On a terminal the
    /// bar is shown.
    #[arg(long = "progress-every-s", value_name = "SECONDS")]
    pub progress_every: Option<f64>,
    /// Most steps the run may take, over the scene's `[run] max_steps` [default: the scene's, else 1e9]: a scene
    /// estimated to need more is refused; a run reaching it stops with a checkpoint (exit code 3).
    #[arg(long, value_name = "N")]
    pub max_steps: Option<f64>,
    /// Most wall-clock seconds this process may run, over the scene's `[run] max_wall_seconds` [default: none]:
    /// the run stops with a checkpoint at the output sample before it would overrun (exit code 3).
    #[arg(long = "max-wall-s", value_name = "SECONDS")]
    pub max_wall_seconds: Option<f64>,
    /// Testing: exit with code 3 right after the N-th checkpoint this process writes.
    #[arg(long, value_name = "N", hide = true)]
    pub stop_after_checkpoints: Option<u64>,
}

impl CheckpointArgs {
    /// The run options these arguments ask for: every time option within its floor and ceiling
    /// ([`rubblepile::io::limits`]), the budget's within [`rubblepile::io::run_budget`]'s, each refused by name otherwise.
    pub(crate) fn options(&self, progress: bool) -> Result<RunOptions, CliError> {
        use rubblepile::driver::progress::{DEFAULT_PROGRESS_EVERY, PROGRESS_EVERY_ENV};
        if self.stop_after_checkpoints == Some(0) {
            return Err(CliError::usage("--stop-after-checkpoints must be at least 1"));
        }
        let t = rubblepile::io::run_budget::TimeOptions {
            checkpoint_every: self.checkpoint_every,
            checkpoint_every_sim: self.checkpoint_every_sim,
            progress_every: self.progress_every,
            max_steps: self.max_steps,
            max_wall_seconds: self.max_wall_seconds,
        }
        .check()
        .map_err(CliError::usage)?;
        let progress_every = match (t.progress_every, std::env::var(PROGRESS_EVERY_ENV)) {
            (Some(s), _) => s,
            (None, Ok(text)) => rubblepile::driver::progress::every_from_env(&text).map_err(CliError::usage)?,
            (None, Err(_)) => DEFAULT_PROGRESS_EVERY,
        };
        Ok(RunOptions {
            progress,
            checkpoint_every: (t.checkpoint_every > 0.0).then_some(t.checkpoint_every),
            checkpoint_every_sim: t.checkpoint_every_sim,
            formats: rubblepile::driver::formats::Formats::parse(&self.format).map_err(CliError::usage)?,
            progress_every,
            stop_after_checkpoints: self.stop_after_checkpoints,
            max_steps: t.max_steps.map(|n| n as u64),
            max_wall_seconds: t.max_wall_seconds,
            ..RunOptions::default()
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
pub(crate) fn report<S: rubblepile::engine::RunReport>(
    result: Result<S, rubblepile::driver::RunError<S>>,
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
            if let rubblepile::driver::RunError::Failed { summary, .. } = &e {
                print(summary);
            }
            Err(CliError {
                message: e.to_string(),
                code: e.exit_code(),
            })
        }
    }
}
