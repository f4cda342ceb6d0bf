//! `rubblepile spinup …`: the options, and the calls into [`crate::studies::zhang2017::spinup_tools`] and the search.

use std::path::PathBuf;

use crate::cli::common::CliError;
use crate::studies::zhang2017::spinup_tools::{density_fit as fit, judge_dir};
use rubblepile::analysis::creep::CreepCriterionKind;
use rubblepile::analysis::critical::SearchError;
use rubblepile::experiment::critical_search::{CriticalOptions, critical as run_critical};

/// `rubblepile spinup …`.
#[derive(Debug, clap::Subcommand)]
pub enum SpinupCommand {
    /// Search T_c,3: hold runs at T_final stepped by 0.01 h until one is free of creep (Zhang17 §3.3.3), several
    /// at once with --parallel N or over a job array with --shard I/N.
    Critical(CriticalArgs),
    /// Fit κ of Eq. 22 over bulk densities and give the critical bulk density.
    DensityFit(DensityFitArgs),
    /// Judge the holds of a search again (its directory, or a compact copy with critical.csv and holds.csv) by
    /// every creep criterion over their first --judge-window-s seconds; prints (and writes --csv).
    Judge(JudgeArgs),
}

/// `rubblepile spinup judge`.
#[derive(Debug, clap::Args)]
pub struct JudgeArgs {
    /// A `spinup critical` directory or its compact copy.
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// Judge only the first SECONDS of each hold.
    #[arg(long = "judge-window-s", value_name = "SECONDS")]
    pub judge_window: Option<f64>,
    /// Standard errors by which a weakening rate must exceed zero for the paper's criterion (default 2).
    #[arg(long, value_name = "Z")]
    pub significance: Option<f64>,
    /// Also write the verdicts as a critical.csv (a running search's compact copy; never overwrites).
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
}

/// `rubblepile spinup judge`.
pub fn judge(args: &JudgeArgs) -> Result<(), CliError> {
    judge_dir(&args.dir, args.judge_window, args.significance, args.csv.as_deref()).map_err(cli_error)
}

/// `rubblepile spinup critical`.
#[derive(Debug, clap::Args)]
pub struct CriticalArgs {
    /// Soft-sphere scene with a `[spinup]` table whose run lasts past `t_final` (the hold).
    #[arg(long, value_name = "SCENE.toml")]
    pub scene: PathBuf,
    /// First T_final (hours).
    #[arg(long = "from-h")]
    pub from: f64,
    /// Last T_final (hours).
    #[arg(long = "to-h")]
    pub to: f64,
    /// Step of T_final (hours).
    #[arg(long = "step-h", default_value_t = 0.01)]
    pub step: f64,
    /// Directory of the hold runs and `critical.json`.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Overwrite an earlier `critical.json` in DIR (completed runs are still reused).
    #[arg(long)]
    pub force: bool,
    /// Branch the hold runs off one run of the scene's path (`DIR/base`) instead of running each from t = 0: the
    /// hold at T_final = X starts where the scene's path passes X (the same spin-up rate, stopped at X). Needs a
    /// path without rests.
    #[arg(long)]
    pub branch: bool,
    /// Which creep criterion gives critical.json's top-level T_c,3 and φ: `paper` (Zhang17 §3.3.3 with zero
    /// tolerance: θ_max rising, η_B or the coordination number falling over a hold's second half at a rate beyond
    /// --significance standard errors is creep), `paper-tolerance` (the same directions, changes beyond 0.5°, 0.0005
    /// and --coordination-tolerance; the default before Dec 2026) or `ours` (θ_max or η_B moving either way). All
    /// are judged and recorded per hold; the search runs until all have a stable hold.
    #[arg(long, value_name = "paper|paper-tolerance|ours", default_value = "paper")]
    pub creep_criterion: CreepCriterionKind,
    /// Standard errors by which a weakening rate must exceed zero for the paper's criterion (default 2).
    #[arg(long, value_name = "Z")]
    pub significance: Option<f64>,
    /// Largest fall of the coordination number (contacts per particle) over the second half of a hold that the
    /// paper-tolerance criterion lets pass (default 0.05).
    #[arg(long, value_name = "CHANGE")]
    pub coordination_tolerance: Option<f64>,
    /// Length of each hold (s); needs `--branch` (refused without it); default: the scene's `t_end − t_final`.
    #[arg(long = "hold-s", value_name = "SECONDS")]
    pub hold: Option<f64>,
    /// Run every hold from --from-h to --to-h, also after both criteria have found a stable one (by default the
    /// search stops one hold after that): shows whether the verdicts stay stable at slower spins.
    #[arg(long)]
    pub all_holds: bool,
    /// Judge only the first SECONDS of each hold (T_c,3 against the hold length from one set of long holds).
    #[arg(long = "judge-window-s", value_name = "SECONDS")]
    pub judge_window: Option<f64>,
    /// Holds run at once (the base run of --branch is shared and runs first); outputs are those of --parallel 1.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub parallel: usize,
    /// Threads of each hold (default: the threads of the process shared among the holds at once).
    #[arg(long, value_name = "K")]
    pub threads_per_hold: Option<usize>,
    /// Run only the holds k with k mod N = I (grid order), for a job array (Slurm: --shard $SLURM_ARRAY_TASK_ID/N),
    /// after writing the branches; judge afterwards with the same command without --shard.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<rubblepile::impact::campaign::Shard>,
    /// Run a hold whose forcing was released to its end (by default it stops within 2000 simulated seconds of the
    /// release: its verdict is fixed).
    #[arg(long)]
    pub finish_released: bool,
    /// Write the base run of --branch and every hold's branch, then stop (the first job before an array of
    /// --shard jobs; see README.md).
    #[arg(long)]
    pub prepare_only: bool,
}

/// `rubblepile spinup density-fit`.
#[derive(Debug, clap::Args)]
pub struct DensityFitArgs {
    /// Comma-separated `RHO:T` pairs: bulk density (kg/m³) and critical period (h).
    #[arg(long, value_delimiter = ',')]
    pub points: Vec<String>,
    /// Period (h) at which to give the critical bulk density.
    #[arg(long = "period-h", default_value_t = 2.26)]
    pub period: f64,
}

fn cli_error(e: SearchError) -> CliError {
    match e {
        SearchError::Usage(m) => CliError::usage(m),
        SearchError::Failed(m) => CliError::failed(m),
    }
}

/// `rubblepile spinup critical`.
pub fn critical(args: &CriticalArgs) -> Result<(), CliError> {
    let options = CriticalOptions {
        scene: args.scene.clone(),
        from: args.from,
        to: args.to,
        step: args.step,
        out: args.out.clone(),
        force: args.force,
        branch: args.branch,
        criterion: args.creep_criterion,
        coordination_tolerance: args.coordination_tolerance,
        significance: args.significance,
        hold: args.hold,
        judge_window: args.judge_window,
        all_holds: args.all_holds,
        parallel: args.parallel,
        threads_per_hold: args.threads_per_hold,
        shard: args.shard,
        finish_released: args.finish_released,
        prepare_only: args.prepare_only,
    };
    run_critical(&options).map_err(cli_error)
}

/// `rubblepile spinup density-fit`.
pub fn density_fit(args: &DensityFitArgs) -> Result<(), CliError> {
    fit(&args.points, args.period).map_err(cli_error)
}
