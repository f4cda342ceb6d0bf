//! The one run driver: integrates any [`crate::engine::Engine`] from t = 0 (or from a checkpoint) to its end time and writes the
//! outputs, the same way for the ellipsoids, the soft spheres and the hard spheres.
//!
//! Files written in the output directory (engines add their own, e.g. `tracks.csv`, `spinup.csv`):
//! - `scene.toml`: a copy of the scene text;
//! - `timeseries.csv`: the engine's diagnostics row at every output sample (handed to the OS at least once a
//!   second, see [`run_files`]);
//! - `snapshots/<k>.csv`: the state at the k-th snapshot time (landed on exactly);
//! - `summary.json`: the engine's summary (status, counters, conservation errors beside the wall time);
//! - `last_good_state.csv` (only when a run fails): the last good state, in snapshot format, the cause named in
//!   `summary.json` and on stderr;
//! - `checkpoint.json` (only when due, see [`RunOptions`]): the state [`resume`] continues from;
//! - `manifest.txt`: every finished file with its size and BLAKE3 checksum ([`crate::io::manifest`]), rewritten at
//!   each checkpoint and at the end.
//!
//! Every file is written without following a symbolic link ([`crate::io::safe_write`]). A run is held to its
//! budget ([`crate::io::run_budget`]): refused when its work estimate exceeds `max_steps`, stopped with a
//! checkpoint ([`RunError::Budget`]) when it would overrun its steps or wall-clock seconds.
//!
//! # Checkpoints and resume
//!
//! A checkpoint is taken at an output sample (never mid-step, never after the last sample) when
//! [`RunOptions::checkpoint_every`] wall-clock seconds have passed since the last one (or since the process
//! started), or [`RunOptions::checkpoint_every_sim`] simulated seconds since the last checkpoint's time. It is
//! written atomically (a temporary file beside it, fsync, rename, directory fsync: [`crate::io::safe_write`]) after
//! the rows it counts are on disk, and the manifest of the run's finished files ([`crate::io::manifest`]) after it.
//! Its envelope (format, version, engine kind, scene fingerprint, time, sample index, time-series length, wall
//! time) is the driver's; the engine's state sits under `engine`. Every `f64` that influences the continuation is
//! stored as its bit pattern ([`crate::bits::exact_f64`]), so a run resumed from a checkpoint ends with the same
//! snapshots, time series (`wall_seconds` aside) and summary counters as an uninterrupted one, bit for bit.
//!
//! On resume the scene is re-read from the run's `scene.toml` copy (refused if it changed since the checkpoint),
//! relative input files are resolved against the original scene's directory stored in the checkpoint,
//! `timeseries.csv` is cut back to its length at the checkpoint, and the engine reopens its own files likewise.

pub mod branch;
pub mod convert;
pub mod export;
pub mod formats;
pub mod inspect;
pub mod kind;
pub mod progress;
pub mod run_files;
pub mod runner;
pub mod scene_kind;
pub mod warm_pool;

pub use crate::ellipsoid::summary::RunSummary;
pub use crate::io::checkpoint::{CHECKPOINT_FILE, CHECKPOINT_TMP_FILE};
pub use kind::{AnyReport, check_file, explain, resume_dir, run_file};
pub use progress::{progress_bar, show_progress};
pub use runner::*;
pub use scene_kind::SceneKind;
