//! Impact campaigns: a grid of impact runs (targets × projectiles × angles × seeds, Roig03 §3) from one
//! TOML file, run in parallel, resumable, summarised in `campaign.csv`.
//!
//! # The campaign file
//!
//! ```toml
//! [campaign]
//! out = "../../runs/roig2003"      # campaign directory (required; relative to the campaign file)
//! targets = ["../../targets/N30_T4.csv", "../../targets/N200_T4.csv"]  # bodies files (required, >= 1;
//!                                  # relative to the campaign file; their stems must differ)
//! projectiles = ["P1", "P2", "P3"] # P1/P2/P3 (Roig03 Table 2) or ids of [[projectile]] tables (required)
//! angles = [0.0, 45.0, 90.0]       # ζ between trajectory and spin axis z (degrees, 0-180; required)
//! seeds = [1]                      # seeds of the projectile's attitude (default [1])
//! parallel = 2                     # runs at once (default: the number of cores)
//!
//! [impact]                         # optional; every key optional (defaults of `rubblepile impact`)
//! t_end = 10000.0                  # end time (s; default 10000)
//! method = "bulirsch-stoer"        # or "dop853", "dopri5" (default "bulirsch-stoer")
//! rtol = 1e-6                      # relative = absolute tolerance (default: 1e-6 of the run for Bulirsch-Stoer,
//!                                  # 1e-8 per step for dop853/dopri5)
//! f0 = 1e-6                        # dissipation coefficient F0 (s m^-2; default 1e-6)
//! beta = 10.0                      # beta of Roig03 Eq. 14 for kappa (default 10)
//! contact_time = 90.0              # time at which the surfaces first touch (s; default 90)
//! every = 10.0                     # time-series cadence (s; default 10)
//! snapshots = [0.0, 100.0]         # snapshot times (s; default 0, 100, 400, 1000, 10000 cut at t_end, + t_end)
//! # snapshot_every = 100.0          # or their cadence (s): 0, 100, 200, ... and t_end; not both
//! speed_km_s = 5.0                 # impact speed of P1-P3 and of custom projectiles without one (km/s; default 5)
//! inertia = "gaussian"             # "gaussian" (Roig03 Eq. 4, default) or "uniform" (homogeneous ellipsoids)
//! impact_parameter_frac = 0.7      # aim off the centre (crate::impact::geometry): b as a fraction of R, in [0, 1);
//!                                  # or impact_parameter_m (b in m, >= 0), or impact_angle_deg (theta to the
//!                                  # surface normal, [0, 90)): at most one (default: at the centre of mass)
//! aim_azimuth_deg = 0.0            # psi of the aim point around the approach direction (degrees, [0, 360); default 0)
//! projectile_spin_rad_s = [0.0, 0.0, 1e-3]   # spin of the projectile (rad/s, world frame; default none)
//! projectile_attitude = [0.0, 0.0, 0.0, 1.0] # quaternion x, y, z, w (world -> body; default random from the seed)
//!
//! [[projectile]]                   # optional custom projectiles (density 3000 kg/m^3, axes 1 : 0.7 : 0.5)
//! id = "S1"                        # name in campaign.projectiles and in run names ([A-Za-z0-9_-], not P1-P3)
//! radius_km = 1.0                  # equivalent radius (km)
//! speed_km_s = 0.05                # impact speed (km/s; default impact.speed_km_s)
//!
//! [[projectile]]                   # a rubble-pile projectile (crate::impact::pile): instead of radius_km,
//! id = "pile30"                    # a bodies file thrown whole (relative to the campaign file)
//! projectile_pile = "../../targets/N30_T4.csv"
//! random_attitude = true           # turn it by a random attitude drawn from the seed (default true)
//!
//! [sweep]                          # optional: any field of this file over values; the runs are the product
//! "impact.speed_km_s" = [0.02, 0.05]          # a list (a bare `impact.f0 = [...]` works too)
//! "impact.f0" = { from = 1e-6, to = 1e-4, count = 3 }  # or a grid: { from, to, step } / { from, to, count }
//! seed = { from = 1, to = 4, step = 1 }       # short names: target, projectile, angle, seed (the lists above)
//! ```
//!
//! The sweep's paths (sorted; the first outermost, then targets, projectiles, angles, seeds) are set in the
//! file's TOML value and read back through its schema, so any field is covered and a wrong path is refused naming
//! it and the valid names. A swept run's name ends with `_<last path name><value>` per swept field outside
//! `[campaign]` (e.g. `tiny_S1_z0_s7_speed_km_s0.02`), and `campaign.csv` gains one column per swept path.
//!
//! Unknown keys are refused; every error is one line naming the field (`campaign.angles[2]: …`). Relative
//! paths are joined to the campaign file's directory and cleaned lexically (`a/b/../../t.csv` → `t.csv`).
//!
//! # The campaign directory
//!
//! One run directory per grid point, `<out>/<target stem>_<projectile>_z<angle>_s<seed>/` (e.g.
//! `N30_T4_P1_z45_s1`), holding what [`crate::impact::run::run_impact`] writes, and `<out>/campaign.csv`,
//! rewritten atomically (`campaign.csv.tmp`, then rename) whenever a run starts or ends, one row per grid
//! point: `run,target,projectile,angle_deg,seed,q_erg_per_g,status,wall_seconds,final_time,steps_accepted,
//! rhs_evaluations,energy_error,linear_momentum_error,angular_momentum_error` (`target` is the target
//! file's stem; `status` is `completed`, `failed: <cause>`, `pending` or `running`; the run's numbers come
//! from its `summary.json` and are empty while there is none).
//!
//! # Resuming
//!
//! What happens to each grid point is decided when the campaign starts ([`Action`]):
//! - its `summary.json` says `completed` → skipped;
//! - otherwise its `checkpoint.json` exists → continued with [`resume_run`] (bit-identical to an
//!   uninterrupted run);
//! - otherwise (no directory, an empty one, a run that died before its first checkpoint, a failed run
//!   without a checkpoint) → started afresh, overwriting the run's files;
//! - a completed or checkpointed run whose `scene.toml` (comments aside) or `initial_bodies.csv` differ
//!   from what this campaign would write (a changed `[impact]`, a rebuilt target) is neither skipped nor
//!   resumed but recorded as failed: its results are left alone; move the directory away to redo it.
//!
//! A failed run is recorded (`failed: <cause>`) and the campaign goes on. The runs are executed by
//! `parallel` plain threads (not a rayon pool, so that each run's own rayon work goes to the global pool
//! instead of stealing whole runs while it waits).

//!
//! # Layout
//!
//! [`file`] is the campaign file format, [`plan`] expands it into the grid of runs, [`execute`] runs the grid
//! (in parallel, resumable), and [`index`] keeps `campaign.csv`.

pub mod distributed;
pub mod execute;
pub mod file;
pub mod index;
#[cfg(feature = "mpi")]
pub mod mpi;
pub mod plan;
pub mod shard;
pub mod slurm;
pub mod sweep;

pub use distributed::*;
pub use execute::*;
pub use file::*;
pub use index::*;
pub use plan::*;
pub use shard::*;
pub use slurm::*;
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
            CampaignError::Locked(_) => 2,
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
