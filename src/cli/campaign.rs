//! `rubblepile campaign FILE.toml`: a grid of impact runs (see [`rubblepile::impact::campaign`] for the file
//! format, the campaign directory and how interrupted campaigns resume).

use std::path::PathBuf;

use crate::cli::common::{CheckpointArgs, CliError};
use crate::cluster::launch::{run_campaign_anywhere, threads_per_rank};
use crate::cluster::slurm::{SlurmJob, write_slurm};
use rubblepile::impact::campaign::{CAMPAIGN_CSV, CampaignError, CampaignOptions, load_campaign, merge_campaign};

/// `rubblepile campaign`.
#[derive(Debug, clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct CampaignArgs {
    /// `merge DIR` or `slurm FILE --tasks N` instead of running a campaign.
    #[command(subcommand)]
    pub action: Option<CampaignAction>,
    /// Campaign file (TOML): `[campaign]` out, targets, projectiles, angles, seeds, parallel; optional
    /// `[impact]` overrides and `[[projectile]]` custom projectiles.
    #[arg(required = true)]
    pub file: Option<PathBuf>,
    /// The campaign directory (overrides `campaign.out`).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Run only shard I of N (0 <= I < N): the grid points k with k mod N = I (a job array's task); its index
    /// goes to DIR/campaign.shard-I-of-N.csv, and `campaign merge DIR` rebuilds campaign.csv.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<rubblepile::impact::campaign::Shard>,
    /// Threads of this process, 1 to 4096 [default: the node's cores over its MPI ranks; all cores without MPI].
    /// The runs at once share them: each run has its own pool of threads-per-rank / parallel threads, at least
    /// one, so `--parallel 16 --threads-per-rank 1` runs 16 runs at once on one thread each.
    #[arg(long, value_name = "N", value_parser = rubblepile::io::scene_file::thread_count)]
    pub threads_per_rank: Option<usize>,
    /// Runs at once (overrides `campaign.parallel`).
    #[arg(long, value_name = "N")]
    pub parallel: Option<usize>,
    /// Never show the progress display (it is shown only when stderr is a terminal anyway).
    #[arg(long)]
    pub no_progress: bool,
    /// Checkpoint options of every run.
    #[command(flatten)]
    pub checkpoints: CheckpointArgs,
}

/// Runs `campaign`: one line per finished run and a one-line summary on stdout. Exit code 2 for a bad
/// campaign file, 1 when a run failed (the others still ran), 3 when runs stopped after a checkpoint on
/// request (`--stop-after-checkpoints`).
pub fn campaign(args: &CampaignArgs) -> Result<(), CliError> {
    let to_cli = |e: rubblepile::impact::campaign::CampaignError| CliError {
        message: e.to_string(),
        code: e.exit_code(),
    };
    if let Some(action) = &args.action {
        action.run().map_err(to_cli)?.iter().for_each(|l| println!("{l}"));
        return Ok(());
    }
    let file = args
        .file
        .as_deref()
        .ok_or_else(|| CliError::usage("a campaign file is required"))?;
    if args.parallel == Some(0) {
        return Err(CliError::usage("--parallel: must be at least 1, got 0"));
    }
    let options = CampaignOptions {
        run: args.checkpoints.options(!args.no_progress)?,
        parallel: args.parallel,
        threads_per_run: None,
        verbose: true,
        shard: args.shard,
    };
    let mut campaign = load_campaign(file).map_err(to_cli)?;
    if let Some(out) = &args.out {
        campaign.out = out.clone();
    }
    let threads = threads_per_rank(args.threads_per_rank);
    rayon::ThreadPoolBuilder::new().num_threads(threads).build_global().ok();
    let Some(report) = run_campaign_anywhere(&campaign, &options).map_err(to_cli)? else {
        return Ok(()); // an MPI worker rank: rank 0 reports
    };
    println!("{}", report.one_line());
    let index = args.shard.map_or(CAMPAIGN_CSV.to_string(), |s| s.index_file());
    match report.problem(&campaign.out.join(index)) {
        Some((message, code)) => Err(CliError { message, code }),
        None => Ok(()),
    }
}

/// `rubblepile campaign merge|slurm …`.
#[derive(Debug, clap::Subcommand)]
pub enum CampaignAction {
    /// Rebuild DIR/campaign.csv from the run directories (after shards ran separately).
    Merge {
        /// The campaign directory.
        dir: PathBuf,
    },
    /// Write DIR/campaign.slurm, a Slurm job array running the campaign as N shards (not submitted).
    Slurm {
        /// The campaign file.
        file: PathBuf,
        /// The campaign directory (overrides `campaign.out`).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Array tasks (shards).
        #[arg(long, value_name = "N")]
        tasks: usize,
        /// Cores per task (each task runs one impact at a time on them).
        #[arg(long, value_name = "N", default_value_t = 2)]
        threads_per_task: usize,
        /// Wall-clock limit per array task (`sbatch --time`: MINUTES, HH:MM:SS, D-HH:MM, …) [default: the
        /// partition's].
        #[arg(long, value_name = "LIMIT")]
        time: Option<String>,
        /// Slurm partition (`sbatch --partition`) [default: the cluster's].
        #[arg(long, value_name = "NAME")]
        partition: Option<String>,
        /// Account charged (`sbatch --account`) [default: the user's].
        #[arg(long, value_name = "NAME")]
        account: Option<String>,
        /// Memory per task's node (`sbatch --mem`, e.g. 4G; a bare number is MB) [default: the partition's].
        #[arg(long, value_name = "SIZE")]
        mem: Option<String>,
        /// Most array tasks running at once (the array's `%K`) [default: no limit].
        #[arg(long, value_name = "K")]
        throttle: Option<usize>,
        /// The rubblepile executable the tasks run [default: this one, by its absolute path].
        #[arg(long, value_name = "PATH")]
        binary: Option<PathBuf>,
    },
}

impl CampaignAction {
    /// Does it; the lines to print.
    pub fn run(&self) -> Result<Vec<String>, CampaignError> {
        match self {
            CampaignAction::Merge { dir } => {
                let r = merge_campaign(dir)?;
                Ok(vec![format!(
                    "merged {} runs into {}: {} completed, {} failed, {} pending",
                    r.runs.len(),
                    dir.join(CAMPAIGN_CSV).display(),
                    r.completed(),
                    r.failed(),
                    r.pending()
                )])
            }
            CampaignAction::Slurm {
                file,
                out,
                tasks,
                threads_per_task,
                time,
                partition,
                account,
                mem,
                throttle,
                binary,
            } => {
                let job = SlurmJob {
                    tasks: *tasks,
                    threads: *threads_per_task,
                    time: time.clone(),
                    partition: partition.clone(),
                    account: account.clone(),
                    mem: mem.clone(),
                    throttle: *throttle,
                    binary: binary
                        .clone()
                        .or_else(|| std::env::current_exe().ok())
                        .unwrap_or_else(|| PathBuf::from("rubblepile")),
                };
                let (path, runs, out) = write_slurm(file, out.as_deref(), &job)?;
                Ok(vec![format!(
                    "wrote {} ({runs} runs in {tasks} array tasks); submit it with sbatch, then run `campaign merge {}`",
                    path.display(),
                    out.display()
                )])
            }
        }
    }
}
