//! The `rubblepile` command line.
//!
//! - `rubblepile run [SCENE.toml] --out DIR [--force] [--no-progress] [--checkpoint-every-s S]
//!   [--checkpoint-every-sim-s S]`: runs a scene (the built-in default scene without SCENE) and writes
//!   its outputs into DIR, with checkpoints as asked;
//! - `rubblepile resume DIR [--no-progress] [--checkpoint-every-s S] [--checkpoint-every-sim-s S]`:
//!   continues an interrupted run from `DIR/checkpoint.json` (see [`rubblepile::driver`]);
//! - `rubblepile check [SCENE.toml]`: validates a scene and prints what it resolved to; `rubblepile check DIR` (a
//!   directory): whether a run directory is whole ([`rubblepile::driver::inspect`]), one line per finding, exit code 2
//!   when it is not; `rubblepile check --explain [KIND]`: every key of a scene file with its unit, default and
//!   allowed range ([`rubblepile::driver::explain`]);
//! - `rubblepile target build --fragments N --period-h T --seed S --out targets/NAME.csv`: a relaxed
//!   rubble-pile target (Roig03 §3) and its Table 1 quantities in `NAME.json`;
//! - `rubblepile impact --target FILE.csv --projectile P2 --angle-deg 45 --out DIR`: an impact run (Roig03 §3);
//! - `rubblepile campaign FILE.toml [--parallel N] [--checkpoint-every-s S]`: a resumable grid of impact runs
//!   (targets × projectiles × angles × seeds) with `campaign.csv` (see [`rubblepile::impact::campaign`]);
//! - `rubblepile analyze DIR [--at-s 400]`: per-fragment and per-run analysis of an impact run (Roig03 §4);
//! - `rubblepile analyze-campaign DIR [--at-s T] [--by FIELD]`: all completed runs of a campaign, bound fraction vs Q,
//!   Q*_D;
//! - `rubblepile report richardson2011 --atmosphere DIR [--half DIR] [--tumbler DIR…]`: the Richardson11 §3 report
//!   (`analysis/richardson2011/REPORT.md` and figures);
//! - `rubblepile bench rhs --bodies N[,N…] [--repeats R] [--out DIR] [--force]`: times one right-hand-side
//!   evaluation of a random cloud of N ellipsoids, on 1 thread and on all threads;
//! - `rubblepile bench work-precision --problem {top,pair,pair-dissipative,n30} --out DIR [--force]
//!   [--repeats 5]`: work–precision diagrams of Bulirsch–Stoer, Dop853, Dopri5 and Rk4 (CSV + SVG);
//! - `rubblepile bench nbody --problem {pythagorean,outer-solar} --rtol TOL[,TOL…] --out DIR [--force]`:
//!   timed point-mass runs with their final states, for the comparison with REBOUND
//!   (`analysis/rebound_compare`);
//! - `rubblepile ssdem advise --radius-m R --density-kg-m3 RHO [--body-radius-m B] [--spin-period-h T | --speed-m-s V]
//!   [--max-overlap 0.01]` or `--scene FILE`: k_N and dt for soft spheres (see [`rubblepile::granular::soft::advise`]);
//! - `rubblepile bench ssdem --particles N --gravity {off,tree,direct}`: soft-sphere particle-steps per second;
//! - `rubblepile aggregate build --model {hcp,rcp,rcpc,pp1,pp2,ppc} --shape SHAPE --particles N|--radius-m R
//!   --bulk-density-kg-m3 RHO --seed S --out targets/NAME.csv` and `aggregate density`: see [`aggregate`].
//! - `rubblepile spinup critical …` / `rubblepile spinup density-fit …`: the T_c,3 search and the Eq. 22 fit
//!   ([`spinup`]); `rubblepile report zhang2017 RUNS --out analysis/zhang2017 [--force]`: the Table 3 report.
//!
//! - `rubblepile export vtk|xyz DIR [--force]`: a finished run's snapshots for ParaView or OVITO
//!   ([`rubblepile::driver::export`]); `rubblepile render DIR [--view iso] [--color speed] [--size 800x800]`: PNG frames
//!   and an animated GIF ([`rubblepile::render::run`]); `rubblepile bench render`: their cost.
//!
//! `run`, `resume` and `check` dispatch on `scene.kind`: `"soft-spheres"` scenes go to [`ssdem`].
//! - `rubblepile bench stability --out DIR [--force] [--quick] [--only ID,…]`: the stability suite
//!   ([`crate::bench::stability`]): `stability.csv`, `stability.md` and one run directory per case.
//!
//! Units: every flag that carries a dimensional quantity names its unit as a suffix, spelled the same everywhere
//! (`-s`, `-h`, `-m`, `-km`, `-m-s`, `-km-s`, `-deg`, `-kg`, `-kg-m3`, `-rad-s`); dimensionless flags (κ, β, rtol,
//! counts, fractions) keep bare names. Old spellings still parse, with one warning line each ([`units`]).
//!
//! Errors are printed as one line, `error: …`, on stderr; the exit code is 2 for bad input (bad
//! scene, bad arguments, existing output directory, nothing to resume, a run directory that is not whole, a
//! directory another rubblepile process is writing) and 1 for a failed run; 3 when
//! the hidden testing flag `--stop-after-checkpoints N` stopped a run after its N-th checkpoint.
//!
//! # One writer per directory
//!
//! Every command that writes a directory locks it first ([`rubblepile::io::run_lock`]) and keeps the lock until it has
//! written its last byte there: `run` (with `--force` too), `resume`, `impact` and `flyby` their run directory;
//! `campaign` its campaign directory (a shard only its own index, beside the other shards) and each run directory;
//! `campaign merge` the campaign directory; `export` the run directory (the run itself may write the same VTK and
//! XYZ files); `render` and `run --render` the run's `frames/`; `analyze` the run's `analysis/` (so it can read a
//! run still going). A second writer is refused at once with one line naming the directory and the holder's pid
//! (exit code 2); readers (`check DIR`, and reading snapshots) take no lock.

pub mod aggregate;
pub mod analyze;
pub mod campaign;
pub mod common;
pub mod flyby;
pub mod impact;
pub mod render_args;
pub mod report_richardson2011;
pub mod spinup;
pub mod ssdem;
pub mod stability;
pub mod target;
pub mod units;
pub mod visual;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use common::report;
pub use common::{CheckpointArgs, CliError};
use rubblepile::driver::RunOptions;

/// Dynamics of rubble-pile asteroids: interacting ellipsoids (Roig et al. 2003).
#[derive(Debug, Parser)]
#[command(name = "rubblepile", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a scene and write its outputs (summary.json, timeseries.csv, snapshots/) into DIR.
    Run(RunArgs),
    /// Continue an interrupted run in DIR from its checkpoint (DIR/checkpoint.json).
    Resume(ResumeArgs),
    /// Validate a scene file and print what it resolves to (κ, bodies, output times); of a run directory, say whether
    /// it is whole (scene copy, status, snapshots, time series).
    Check(CheckArgs),
    /// Rubble-pile targets.
    #[command(subcommand)]
    Target(target::TargetCommand),
    /// Run an impact of a projectile (P1, P2, P3 or custom) on a target.
    Impact(Box<impact::ImpactArgs>),
    /// Run a tidal flyby of a target pile past a planet (default Earth); analysis in DIR/analysis/flyby.json.
    Flyby(Box<flyby::FlybyArgs>),
    /// Run a campaign of impacts (targets × projectiles × angles × seeds) from a campaign file; resumable.
    Campaign(Box<campaign::CampaignArgs>),
    /// Analyse a run: clumps of any run (largest and second remnant, clumps.csv, sfd.svg); of an impact run also the
    /// per-fragment table and per-run results (Roig03 §4); of a flyby run its state before and after (flyby.json).
    Analyze(analyze::AnalyzeArgs),
    /// Analyse every completed run of a campaign; bound fraction vs Q and Q*_D (Roig03 Fig. 5).
    AnalyzeCampaign(analyze::AnalyzeCampaignArgs),
    /// Reproduction reports of the three papers: `report roig2003|zhang2017|richardson2011 …`.
    #[command(subcommand)]
    Report(ReportCommand),
    /// Old spelling of `report roig2003`.
    #[command(hide = true)]
    ReportRoig2003(analyze::ReportRoig2003Args),
    /// Old spelling of `report richardson2011`.
    #[command(hide = true)]
    ReportRichardson2011(report_richardson2011::ReportRichardson2011Args),
    /// Benchmarks.
    #[command(subcommand)]
    Bench(BenchCommand),
    /// Soft-sphere (SSDEM) tools.
    #[command(subcommand)]
    Ssdem(ssdem::SsdemCommand),
    /// Rubble-pile aggregates for spin-up studies (Zhang17 §2.3.2): build, bulk-density variants.
    #[command(subcommand)]
    Aggregate(aggregate::AggregateCommand),
    /// Spin-up studies (Zhang17 §3–4): the T_c,3 search and the Eq. 22 density fit.
    #[command(subcommand)]
    Spinup(spinup::SpinupCommand),
    /// Old spelling of `report zhang2017`.
    #[command(hide = true)]
    ReportZhang2017(crate::studies::zhang2017::report::ReportZhang2017Args),
    /// Write a finished run's snapshots in another format: `export vtk DIR` (ParaView) or `export xyz DIR`.
    Export(visual::ExportArgs),
    /// Convert pkdgrav `.ss` files to and from bodies/particles CSV (units converted at the edge).
    Convert(visual::ConvertArgs),
    /// Draw a run: one PNG per snapshot and an animated GIF in DIR/frames.
    Render(render_args::RenderArgs),
}

/// `rubblepile report …`: one verb for the papers' reproduction reports.
#[derive(Debug, Subcommand)]
pub enum ReportCommand {
    /// Re-analyse the Roig03 campaign (and its uniform-inertia partner) and write analysis/roig2003/REPORT.md.
    Roig2003(analyze::ReportRoig2003Args),
    /// Read spin-up runs (RUNS/<model>/path2, RUNS/<model>/critical) and write REPORT.md and Fig. 5-style figures.
    Zhang2017(crate::studies::zhang2017::report::ReportZhang2017Args),
    /// Re-analyse the Richardson11 model-atmosphere and tumbler runs and write analysis/richardson2011/REPORT.md.
    Richardson2011(report_richardson2011::ReportRichardson2011Args),
    /// Read Richardson11 tumbler runs at the paper's scale; write analysis/richardson2011/TUMBLER_PAPER.md.
    Richardson2011Tumbler(crate::studies::richardson2011::tumbler_paper::TumblerPaperArgs),
    /// Roig03 after the referee: the runs of referee_runs.sh into compact CSVs, the CSVs into REFEREE.md.
    #[command(subcommand)]
    Roig2003Referee(crate::studies::roig2003::referee::RefereeArgs),
}

/// `rubblepile run`.
#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// Scene file (TOML). Without it, the built-in default scene runs.
    pub scene: Option<PathBuf>,
    /// Output directory (created if missing; must be empty unless --force).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Overwrite the outputs of a previous run in DIR.
    #[arg(long)]
    pub force: bool,
    /// Never show the progress bar (it is shown only when stderr is a terminal anyway).
    #[arg(long)]
    pub no_progress: bool,
    /// Render the run afterwards (DIR/frames: PNGs and run.gif, as `rubblepile render`); always done for the
    /// built-in default scene.
    #[arg(long)]
    pub render: bool,
    /// Checkpoint options.
    #[command(flatten)]
    pub checkpoints: CheckpointArgs,
}

/// `rubblepile resume`.
#[derive(Debug, clap::Args)]
pub struct ResumeArgs {
    /// The run's output directory (holding checkpoint.json and scene.toml).
    pub dir: PathBuf,
    /// Never show the progress bar (it is shown only when stderr is a terminal anyway).
    #[arg(long)]
    pub no_progress: bool,
    /// Checkpoint options.
    #[command(flatten)]
    pub checkpoints: CheckpointArgs,
}

/// `rubblepile check`.
#[derive(Debug, clap::Args)]
pub struct CheckArgs {
    /// Scene file (TOML), or a run directory (is it whole?). Without it, the built-in default scene is checked.
    pub scene: Option<PathBuf>,
    /// Print the built-in default scene's TOML instead (a starting point for your own scenes).
    #[arg(long, conflicts_with = "scene")]
    pub print_default: bool,
    /// Print every key of a KIND scene file (all kinds without one): its unit, default, allowed range and meaning.
    #[arg(long, value_name = "KIND", conflicts_with_all = ["scene", "print_default"],
          value_parser = crate::choice::choice::<rubblepile::driver::SceneKind>())]
    pub explain: Option<Option<rubblepile::driver::SceneKind>>,
    /// Rewrite the granular scene SCENE to the current key names: to stdout, to --out FILE, or in place with --force.
    #[arg(long, requires = "scene", conflicts_with_all = ["print_default", "explain"])]
    pub migrate: bool,
    /// With --migrate: the file to write (an existing one only with --force).
    #[arg(long, value_name = "FILE", requires = "migrate")]
    pub out: Option<PathBuf>,
    /// With --migrate: overwrite SCENE itself (or an existing --out FILE).
    #[arg(long, requires = "migrate")]
    pub force: bool,
}

/// `rubblepile bench …`.
#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Time one right-hand-side evaluation for a random cloud of ellipsoids (1 thread vs all threads).
    Rhs(crate::bench::rhs::RhsArgs),
    /// Work-precision diagrams (error and energy error vs wall time) of the integrators on a canonical problem.
    WorkPrecision(crate::bench::work_precision_sweep::WorkPrecisionArgs),
    /// Timed point-mass N-body runs (Pythagorean three-body, outer Solar System) with final states (CSV).
    Nbody(crate::bench::nbody::NBodyArgs),
    /// Wall-clock time of whole impact runs (default N200_T4 + P2, ζ = 45°, 10 000 s, the impact default rtol) per
    /// integrator, tolerance, F0 and thread count, with each run's energy error and a goal line (60 s, or `--goal-s`).
    Impact(crate::bench::impact_wall_time::ImpactBenchArgs),
    /// Soft-sphere engine throughput (particle-steps per second) on 1 and 2 threads (CSV + SVG).
    Ssdem(crate::bench::ssdem::BenchSsdemArgs),
    /// Bytes per grain or body: peak resident set and the engine's own count, each case in a process of its own.
    Memory(crate::bench::memory::BenchMemoryArgs),
    /// Strong scaling of every engine at 1, 2, 4, … threads: speed-up, efficiency, Karp–Flatt serial fraction,
    /// where the time goes (CSV + plot).
    Scaling(crate::bench::scaling::ScalingArgs),
    /// Hard-sphere engine speed (collisions and steps per CPU second, time per stepper phase) on a scene.
    Hsdem(crate::bench::hsdem::BenchHsdemArgs),
    /// Run the stability suite (impacts above the calibrated speed, needles and plates, mass ratio 1e-6,
    /// θ = 0, F0 = 100, κ sweep, cloud collapse, resting contact) and write stability.csv/.md.
    Stability(stability::StabilityArgs),
    /// Tolerance proportionality: final-state error over rtol on the canonical problems, rtol 1e-6…1e-12 (CSV).
    Tolerance(crate::bench::tolerance::ToleranceArgs),
    /// Milliseconds per rendered frame at N bodies on 1 and all threads, and VTK export MB/s (CSV + plot).
    Render(crate::bench::render::RenderBenchArgs),
    /// Wall time of a T_c,3 search's holds one at a time and several at once (`spinup critical --parallel`), on
    /// one prepared base run, with the load average (CSV + plot).
    Critical(crate::bench::critical::BenchCriticalArgs),
    /// Two builds timed on the same command, alternately, in one invocation (before/after a change; CSV + plot).
    Ab(crate::bench::ab::BenchAbArgs),
}

/// Runs a parsed command line.
pub fn execute(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Run(args) => {
            let options = RunOptions {
                force: args.force,
                ..args.checkpoints.options(!args.no_progress)?
            };
            let result = rubblepile::driver::run_file(args.scene.as_deref(), &args.out, &options);
            if result.is_err() || !(args.render || args.scene.is_none()) {
                return report(result);
            }
            // the built-in default scene (or --render) is drawn into frames/run.gif, the name `render` uses
            let opts = rubblepile::render::run::RenderRunOptions {
                force: args.force,
                ..Default::default()
            };
            let r = rubblepile::render::run::render_run(&args.out, &opts).map_err(CliError::failed)?;
            println!(
                "rendered {} frames in {:.1} s (median {:.0} ms per frame)",
                r.frames, r.seconds, r.median_frame_ms
            );
            report(result)?;
            println!("look at it: {}", r.gif.display());
            let pvd = args
                .out
                .join("vtk")
                .join(rubblepile::driver::formats::vtk::COLLECTION_FILE);
            if pvd.exists() {
                println!("in ParaView: open {} (see README, \"Looking at a run\")", pvd.display());
            }
            Ok(())
        }
        Command::Resume(args) => {
            let options = args.checkpoints.options(!args.no_progress)?;
            report(rubblepile::driver::resume_dir(&args.dir, &options))
        }
        Command::Check(args) => {
            if let Some(kind) = args.explain {
                print!("{}", rubblepile::driver::explain(kind));
                return Ok(());
            }
            if args.print_default {
                print!("{}", rubblepile::ellipsoid::scene::DEFAULT_SCENE_TOML);
                return Ok(());
            }
            if let (true, Some(scene)) = (args.migrate, &args.scene) {
                return rubblepile::granular::migrate::command(scene, args.out, args.force).map_err(CliError::usage);
            }
            if let Some(dir) = args.scene.as_deref().filter(|p| p.is_dir()) {
                return check_run_dir(dir);
            }
            let (warnings, lines) = rubblepile::driver::check_file(args.scene.as_deref()).map_err(CliError::usage)?;
            for w in warnings {
                eprintln!("warning: {w}");
            }
            for l in lines {
                println!("{l}");
            }
            Ok(())
        }
        Command::Target(target::TargetCommand::Build(args)) => target::build(&args),
        Command::Target(target::TargetCommand::Table(args)) => target::table(&args),
        Command::Impact(args) => impact::impact(&args),
        Command::Flyby(args) => flyby(&args.config(), &args.checkpoints.options(!args.no_progress)?),
        Command::Campaign(args) => campaign::campaign(&args),
        Command::Analyze(args) => analyze::analyze(&args),
        Command::AnalyzeCampaign(args) => analyze::analyze_campaign(&args),
        Command::Report(ReportCommand::Roig2003(args)) | Command::ReportRoig2003(args) => {
            analyze::report_roig2003(&args)
        }
        Command::Report(ReportCommand::Richardson2011(args)) | Command::ReportRichardson2011(args) => {
            report_richardson2011::report(&args)
        }
        Command::Report(ReportCommand::Richardson2011Tumbler(a)) => {
            crate::studies::richardson2011::tumbler_paper::tumbler_paper_command(&a).map_err(CliError::usage)
        }
        Command::Report(ReportCommand::Roig2003Referee(a)) => {
            crate::studies::roig2003::referee::referee_command(&a).map_err(CliError::usage)
        }
        Command::Report(ReportCommand::Zhang2017(args)) | Command::ReportZhang2017(args) => {
            crate::studies::zhang2017::report::report_command(&args).map_err(CliError::usage)
        }
        Command::Bench(BenchCommand::Rhs(args)) => crate::bench::rhs::rhs(&args).map_err(CliError::from),
        Command::Bench(BenchCommand::WorkPrecision(args)) => {
            crate::bench::work_precision_sweep::work_precision(&args).map_err(CliError::from)
        }
        Command::Bench(BenchCommand::Nbody(args)) => crate::bench::nbody::nbody(&args).map_err(CliError::from),
        Command::Bench(BenchCommand::Impact(args)) => {
            crate::bench::impact_wall_time::impact(&args).map_err(CliError::from)
        }
        Command::Bench(BenchCommand::Ssdem(args)) => Ok(crate::bench::ssdem::bench(&args)?),
        Command::Bench(BenchCommand::Memory(args)) => Ok(crate::bench::memory::bench(&args)?),
        Command::Bench(BenchCommand::Critical(args)) => Ok(crate::bench::critical::bench(&args)?),
        Command::Bench(BenchCommand::Ab(args)) => Ok(crate::bench::ab::bench(&args)?),
        Command::Bench(BenchCommand::Scaling(args)) => Ok(crate::bench::scaling::scaling(&args)?),
        Command::Bench(BenchCommand::Hsdem(args)) => Ok(crate::bench::hsdem::bench(&args)?),
        Command::Ssdem(ssdem::SsdemCommand::Advise(args)) => ssdem::advise(&args),
        Command::Bench(BenchCommand::Stability(args)) => stability::stability(&args),
        Command::Bench(BenchCommand::Tolerance(args)) => {
            crate::bench::tolerance::tolerance(&args).map_err(CliError::from)
        }
        Command::Bench(BenchCommand::Render(args)) => crate::bench::render::render(&args).map_err(CliError::from),
        Command::Aggregate(aggregate::AggregateCommand::Build(args)) => aggregate::build_cmd(&args),
        Command::Aggregate(aggregate::AggregateCommand::Density(args)) => aggregate::density_cmd(&args),
        Command::Spinup(spinup::SpinupCommand::Critical(args)) => spinup::critical(&args),
        Command::Spinup(spinup::SpinupCommand::DensityFit(args)) => spinup::density_fit(&args),
        Command::Spinup(spinup::SpinupCommand::Judge(args)) => spinup::judge(&args),
        Command::Export(args) => visual::export_cmd(&args),
        Command::Render(args) => visual::render_cmd(&args),
        Command::Convert(args) => visual::convert_cmd(&args),
    }
}

/// `rubblepile check DIR`: one line per finding on stdout (problems as `problem: …`); not whole is an error (exit
/// code 2) naming the first problem.
fn check_run_dir(dir: &std::path::Path) -> Result<(), CliError> {
    let report = rubblepile::driver::inspect::check_run_dir(dir);
    for f in &report.findings {
        println!("{}{}", if f.problem { "problem: " } else { "" }, f.line);
    }
    let line = report.verdict(dir).map_err(CliError::usage)?;
    println!("{line}");
    Ok(())
}

/// clap's multi-line argument error as one line, e.g. `the following required arguments were not
/// provided: --out <DIR> (see `rubblepile run --help`)`.
fn one_line_clap_error(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let body = text.split("Usage:").next().unwrap_or(&text);
    let body = body.trim_start().strip_prefix("error:").unwrap_or(body);
    let body = body.replace("For more information, try '--help'.", "");
    let mut msg: String = if e.kind() == clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
        "a subcommand is required".to_string()
    } else {
        body.split_whitespace().collect::<Vec<_>>().join(" ")
    };
    if let Some(usage) = text.split("Usage:").nth(1) {
        // `Usage: rubblepile run [OPTIONS] --out <DIR> [SCENE]` -> `rubblepile run --help`
        let words: Vec<&str> = usage
            .split_whitespace()
            .take_while(|w| !w.starts_with('-') && !w.starts_with('[') && !w.starts_with('<'))
            .collect();
        if !words.is_empty() {
            msg.push_str(&format!(" (see `{} --help`)", words.join(" ")));
        }
    }
    msg
}

/// The binary's entry point: parses `std::env::args`, runs, prints `error: …` on failure.
pub fn main() -> ExitCode {
    let (args, warnings) = units::rewrite(std::env::args().collect());
    warnings.iter().for_each(|w| eprintln!("{w}"));
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            // --help / --version: print and exit 0.
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            eprintln!("error: {}", one_line_clap_error(&e));
            return ExitCode::from(2);
        }
    };
    match execute(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let msg: String = e.message.split_whitespace().collect::<Vec<_>>().join(" ");
            eprintln!("error: {msg}");
            ExitCode::from(e.code)
        }
    }
}

/// `rubblepile flyby`: prepares and runs the flyby, then analyses it; a bad value is named by its flag.
fn flyby(config: &rubblepile::impact::flyby::FlybyConfig, options: &RunOptions) -> Result<(), CliError> {
    use rubblepile::analysis::flyby::{FlybyAnalysisError, analyze_flyby, settling_line};
    use rubblepile::impact::{flyby, run::ImpactError};
    let runs = flyby::run_flyby(config, options).map_err(|e| CliError {
        message: match &e {
            ImpactError::Invalid { field, message } => format!("{}: {message}", flyby::flag(field)),
            other => other.to_string(),
        },
        code: e.exit_code(),
    })?;
    let Some(runs) = runs else {
        println!("wrote {}", config.out.join("scene.toml").display());
        return Ok(());
    };
    let o = analyze_flyby(&config.out).map_err(|e| CliError {
        code: if matches!(e, FlybyAnalysisError::Locked(_)) {
            2
        } else {
            1
        },
        message: e.to_string(),
    })?;
    if let Some(s) = &runs.setup.settling {
        println!("{}", settling_line(s));
    }
    println!("run: {}", runs.run.one_line());
    if let Some(c) = &runs.control {
        println!("control ({}): {}", flyby::CONTROL_DIR, c.one_line());
    }
    o.lines().iter().for_each(|l| println!("{l}"));
    Ok(())
}
