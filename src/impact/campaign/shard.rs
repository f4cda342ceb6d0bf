//! Campaigns past one machine without a distributed system of our own: deterministic shards of the grid for any
//! scheduler's job array (Slurm, PBS, GNU parallel), the merge of their run directories into one `campaign.csv`,
//! and a ready Slurm job-array script.
//!
//! Shard `I/N` (0 ≤ I < N) runs the grid points whose index k (in the grid's order: targets, projectiles, angles,
//! seeds) has k mod N = I, so N shards cover the grid exactly once and interleave long and short runs. A sharded
//! campaign keeps its index in `campaign.shard-I-of-N.csv` (shards never write the same file); `rubblepile
//! campaign merge DIR` rebuilds `campaign.csv` from the run directories themselves, so it is right whatever
//! shards ran, died or ran twice.

use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::time::Instant;

use super::*;

/// One of N deterministic parts of a grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// Which part, 0-based (`SLURM_ARRAY_TASK_ID` of an array `0-(N-1)`).
    pub index: usize,
    /// How many parts.
    pub count: usize,
}

impl FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Shard, String> {
        let bad = || format!("--shard: expected I/N with 0 <= I < N (e.g. 0/8), got {s:?}");
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count): (usize, usize) = (
            i.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl Shard {
    /// Whether grid point `k` belongs to this shard.
    pub fn contains(&self, k: usize) -> bool {
        k % self.count == self.index
    }

    /// The shard's own index file.
    pub fn index_file(&self) -> String {
        format!("campaign.shard-{}-of-{}.csv", self.index, self.count)
    }
}

/// The status a run directory shows by itself: completed (with its numbers), failed (its summary says so and it
/// has no checkpoint), a different run (conflict), or pending (not started, or checkpointed and unfinished).
fn status_of(dir: &Path, point: &GridPoint) -> (RunStatus, Option<RunNumbers>) {
    let (action, numbers) = decide(dir, &point.plan);
    match action {
        Action::Skip => (RunStatus::Completed, numbers),
        Action::Conflict(why) => (RunStatus::Failed(why), numbers),
        Action::Resume => (RunStatus::Pending, None),
        Action::Start => {
            let text = std::fs::read_to_string(dir.join("summary.json")).ok();
            let status = text
                .as_deref()
                .and_then(|t| serde_json::from_str::<serde_json::Value>(t).ok())
                .and_then(|v| v.get("status")?.as_str().map(str::to_string));
            match status {
                Some(s) if s.starts_with("failed") => (
                    RunStatus::Failed(one_line(s.trim_start_matches("failed").trim_start_matches(':').trim())),
                    text.as_deref().map(RunNumbers::from_summary_text),
                ),
                _ => (RunStatus::Pending, None),
            }
        }
    }
}

/// The campaign whose directory is `dir` (from the campaign file recorded there, [`CAMPAIGN_SOURCE`]).
pub fn campaign_of_dir(dir: &Path) -> Result<Campaign, CampaignError> {
    let pointer = dir.join(CAMPAIGN_SOURCE);
    let text = std::fs::read_to_string(&pointer).map_err(|e| CampaignError::Read {
        file: pointer.display().to_string(),
        reason: format!("{e} (is {} a campaign directory?)", dir.display()),
    })?;
    let mut campaign = load_campaign(Path::new(text.trim()))?;
    // The directory given wins over the file's `out` (the campaign may have been run with --out).
    campaign.out = dir.to_path_buf();
    Ok(campaign)
}

/// Rebuilds `campaign.csv` of the campaign directory `dir` from its run directories; returns the report (every
/// run `Skip`ped, as nothing ran). Refused at once ([`CampaignError::Locked`]) while a campaign or one of its shards
/// writes `dir`.
pub fn merge_campaign(dir: &Path) -> Result<CampaignReport, CampaignError> {
    let started = Instant::now();
    let campaign = campaign_of_dir(dir)?;
    // The index is rewritten: not while a campaign or a shard writes the directory.
    let _lock = lock_campaign_dir(dir, None)?;
    let runs: Vec<RunRecord> = campaign
        .points
        .iter()
        .map(|p| {
            let (status, numbers) = status_of(&dir.join(&p.name), p);
            RunRecord {
                name: p.name.clone(),
                action: Action::Skip,
                status,
                stopped: false,
                numbers,
            }
        })
        .collect();
    index::write_campaign_csv(dir, CAMPAIGN_CSV, &campaign.points, &runs)?;
    Ok(CampaignReport {
        runs,
        wall_seconds: started.elapsed().as_secs_f64(),
    })
}

/// What the Slurm script of `campaign slurm` asks of the scheduler and which binary it runs (options named as
/// `sbatch`'s).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SlurmJob {
    /// Array tasks (shards), at least 1.
    pub tasks: usize,
    /// Cores per task, at least 1.
    pub threads: usize,
    /// `--time` (wall-clock limit per task: `MINUTES`, `HH:MM:SS`, `D-HH:MM`, …); `None`: the partition's default.
    pub time: Option<String>,
    /// `--partition`; `None`: the cluster's default.
    pub partition: Option<String>,
    /// `--account` charged; `None`: the user's default.
    pub account: Option<String>,
    /// `--mem` per node (e.g. `4G`, `500M`; a bare number is MB); `None`: the partition's default.
    pub mem: Option<String>,
    /// Most array tasks running at once (`--array=0-(N-1)%K`); `None`: no limit.
    pub throttle: Option<usize>,
    /// The rubblepile executable the tasks run.
    pub binary: PathBuf,
}

impl SlurmJob {
    /// Checks the options as `sbatch` would read them, naming the option at fault: counts at least 1, a time of
    /// digits with `-` and `:` in one of Slurm's forms, memory as digits with an optional K/M/G/T unit, and
    /// partition and account names of letters, digits and `_ . - ,` (nothing the shell would read).
    pub fn check(&self) -> Result<(), (String, String)> {
        let bad = |opt: &str, why: &str, got: &str| Err((format!("--{opt}"), format!("{why}, got {got:?}")));
        if self.tasks == 0 {
            return bad("tasks", "must be at least 1", "0");
        }
        if self.threads == 0 {
            return bad("threads-per-task", "must be at least 1", "0");
        }
        if self.throttle == Some(0) {
            return bad("throttle", "must be at least 1 (array tasks at once)", "0");
        }
        if let Some(t) = &self.time
            && !slurm_time(t)
        {
            return bad(
                "time",
                "must be a Slurm time limit: MINUTES, MINUTES:SECONDS, HOURS:MINUTES:SECONDS, DAYS-HOURS, \
                 DAYS-HOURS:MINUTES or DAYS-HOURS:MINUTES:SECONDS",
                t,
            );
        }
        if let Some(m) = &self.mem {
            let digits = m.trim_end_matches(['K', 'M', 'G', 'T']);
            if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) || m.len() > digits.len() + 1 {
                return bad(
                    "mem",
                    "must be a whole number with an optional unit K, M, G or T (e.g. 4G)",
                    m,
                );
            }
        }
        for (opt, value) in [("partition", &self.partition), ("account", &self.account)] {
            if let Some(v) = value
                && (v.is_empty() || !v.bytes().all(|b| b.is_ascii_alphanumeric() || b"_.-,".contains(&b)))
            {
                return bad(opt, "must be a name of letters, digits, '_', '.', '-' or ','", v);
            }
        }
        Ok(())
    }
}

/// Whether `t` is one of Slurm's time-limit forms (`sbatch --time`).
fn slurm_time(t: &str) -> bool {
    let numbers = |s: &str, most: usize| {
        let parts: Vec<&str> = s.split(':').collect();
        parts.len() <= most
            && parts
                .iter()
                .all(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()))
    };
    match t.split_once('-') {
        Some((days, rest)) => numbers(days, 1) && numbers(rest, 3),
        None => numbers(t, 3),
    }
}

/// A Slurm job-array script running `campaign` as `job.tasks` shards, one array task each, with `job.threads`
/// cores per task and the scheduler options of `job`; its tasks call `job.binary`.
pub fn slurm_script(campaign: &Campaign, campaign_file: &Path, job: &SlurmJob) -> String {
    let out = campaign.out.display();
    let name = campaign_file
        .file_stem()
        .map_or("campaign".into(), |s| s.to_string_lossy().into_owned());
    let runs = campaign.points.len();
    let tasks = job.tasks;
    let mut options = String::new();
    for (opt, value) in [
        ("time", &job.time),
        ("partition", &job.partition),
        ("account", &job.account),
        ("mem", &job.mem),
    ] {
        if let Some(v) = value {
            options.push_str(&format!("#SBATCH --{opt}={v}\n"));
        }
    }
    format!(
        "#!/bin/bash\n\
         # {runs} impact runs of {file} in {tasks} shards (written by `rubblepile campaign slurm`).\n\
         # Submit:  jobid=$(sbatch --parsable {out}/campaign.slurm)\n\
         # Then:    sbatch --dependency=afterany:$jobid --wrap \"{bin} campaign merge {out}\"\n\
         # A task that dies leaves its finished runs and checkpoints; resubmitting the array resumes them.\n\
         #SBATCH --job-name=rubblepile-{name}\n\
         #SBATCH --array=0-{last}{throttle}\n\
         #SBATCH --ntasks=1\n\
         #SBATCH --cpus-per-task={threads}\n\
         {options}\
         #SBATCH --output={out}/slurm-%A_%a.out\n\
         set -euo pipefail\n\
         export RAYON_NUM_THREADS=$SLURM_CPUS_PER_TASK\n\
         srun {bin} campaign {file} --out {out} --shard $SLURM_ARRAY_TASK_ID/{tasks} --parallel 1 --no-progress\n",
        file = campaign_file.display(),
        bin = job.binary.display(),
        last = tasks - 1,
        threads = job.threads,
        throttle = job.throttle.map_or(String::new(), |k| format!("%{k}")),
    )
}

/// Where `campaign slurm` writes its script.
pub fn slurm_script_path(campaign: &Campaign) -> PathBuf {
    campaign.out.join("campaign.slurm")
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
                job.check().map_err(|(field, message)| CampaignError::Invalid {
                    file: file.display().to_string(),
                    field,
                    message,
                })?;
                let mut campaign = load_campaign(file)?;
                if let Some(o) = out {
                    campaign.out = std::path::absolute(o).unwrap_or_else(|_| o.clone());
                }
                let abs_file = campaign.source.clone().unwrap_or_else(|| file.clone());
                let text = slurm_script(&campaign, &abs_file, &job);
                let path = slurm_script_path(&campaign);
                let io = |source| CampaignError::Io {
                    path: path.clone(),
                    source,
                };
                std::fs::create_dir_all(&campaign.out).map_err(io)?;
                crate::io::safe_write::write_atomic(&path, text).map_err(io)?;
                Ok(vec![format!(
                    "wrote {} ({} runs in {tasks} array tasks); submit it with sbatch, then run `campaign merge {}`",
                    path.display(),
                    campaign.points.len(),
                    campaign.out.display()
                )])
            }
        }
    }
}
