//! Impact campaigns: a grid of impact runs (targets × projectiles × angles × seeds, Roig03 §3) from one
//! TOML file, run in parallel, resumable, summarised in `campaign.csv`.
//!
//! The file's keys are documented once, on the structs of [`file`](mod@file) (units, defaults, ranges); the README's
//! "Impact campaigns" gives a complete example. [`sweep`] sets any field over a list or a grid. Each grid point runs
//! as `rubblepile impact` would in `<out>/<target stem>_<projectile>_z<angle>_s<seed>/`, and `<out>/campaign.csv`
//! ([`CAMPAIGN_COLUMNS`]) is rewritten atomically whenever a run starts or ends. What happens to each point is
//! decided when the campaign starts ([`Action`]): completed → skipped; checkpointed → resumed bit for bit; a run
//! whose `scene.toml` or `initial_bodies.csv` differ from what this campaign would write → recorded as failed and
//! left alone; otherwise started afresh. A failed run does not stop the others. Runs execute on `parallel` plain
//! threads (not a rayon pool, so that each run's own rayon work goes to the global pool instead of stealing whole
//! runs while it waits).
//!
//! # Layout
//!
//! [`file`](mod@file) is the campaign file format, [`sweep`] its `[sweep]` table, [`plan`] expands it into the grid of runs,
//! [`execute`] runs the grid on this machine's threads (in parallel, resumable; [`run_point`] runs one point),
//! [`index`] keeps `campaign.csv`, and [`shard`] splits the grid into deterministic parts and merges what they ran.
//! Launching a campaign on a cluster (Slurm job-array scripts, MPI ranks) is the `rubblepile` binary's business:
//! it builds on [`Shard`], [`plan_runs`], [`run_point`] and [`write_campaign_csv`].

pub mod execute;
pub mod file;
pub mod index;
pub mod plan;
pub mod shard;
pub mod sweep;

pub use execute::*;
pub use file::*;
pub use index::*;
pub use plan::*;
pub use shard::*;
pub use sweep::*;

use std::path::PathBuf;

use crate::io::run_lock::DirLock;

/// Name of the campaign table in the campaign directory.
pub const CAMPAIGN_CSV: &str = "campaign.csv";

/// The file in the campaign directory naming the campaign file (one line, its absolute path).
pub const CAMPAIGN_SOURCE: &str = "campaign.source";

/// Columns of `campaign.csv`.
pub const CAMPAIGN_COLUMNS: [&str; 14] = [
    "run",
    "target",
    "projectile",
    "angle_deg",
    "seed",
    "q_erg_per_g",
    "status",
    "wall_seconds",
    "final_time",
    "steps_accepted",
    "rhs_evaluations",
    "energy_error",
    "linear_momentum_error",
    "angular_momentum_error",
];

/// A bad campaign file, or a campaign directory that cannot be written. Messages are one line.
#[derive(Debug, thiserror::Error)]
pub enum CampaignError {
    /// The campaign file could not be read, is malformed (TOML, an unknown or missing key, a value of the wrong
    /// type) or has a value out of range (or a target file that cannot be used): the scene files' errors, whose
    /// `Invalid` field is the dotted path, e.g. `campaign.angles[2]`.
    #[error(transparent)]
    File(#[from] crate::io::scene_file::SceneError),
    /// Another rubblepile process writes the campaign directory (or this shard's index).
    #[error(transparent)]
    Locked(#[from] crate::io::run_lock::LockError),
    /// Writing the campaign directory or `campaign.csv` failed (or a symbolic link stands where it writes).
    #[error("{}", crate::io::safe_write::describe(.path, .source))]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
}

impl CampaignError {
    /// The command line's exit code: 2 for a bad campaign file, 1 for an I/O failure.
    pub fn exit_code(&self) -> u8 {
        match self {
            CampaignError::Io { .. } => 1,
            _ => 2,
        }
    }
}

/// Locks the campaign directory `out` for this process ([`crate::io::run_lock`]) until the guards are dropped: whole,
/// or, for a shard, shared with the other shards (each writes its own runs) and with its own index exclusively. So two
/// campaigns, a campaign and a shard, or one shard twice never write one campaign directory at once; each run
/// directory is locked by its run besides. Errors: [`CampaignError::Locked`], without waiting for the holder.
pub fn lock_campaign_dir(out: &std::path::Path, shard: Option<Shard>) -> Result<Vec<DirLock>, CampaignError> {
    let advice = "use another --out";
    Ok(match shard {
        None => vec![DirLock::acquire(out).map_err(|e| e.or(advice))?],
        Some(s) => vec![
            DirLock::acquire_shared(out).map_err(|e| e.or(advice))?,
            DirLock::acquire_part(out, &s.index_file()).map_err(|e| e.or(advice))?,
        ],
    })
}

pub(crate) fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}
