//! The run driver itself (the module docs of `driver` describe what it writes and how checkpoints and resume
//! work): [`run`] and [`resume`] of any engine, their options and errors, the output directory's lock and the
//! checkpoint file. The choice of engine from a scene (`driver::kind`) sits above it and calls it.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::{formats, inspect, progress, run_files, warm_pool};

use crate::bits::{exact_f64, fnv1a_hex};
use crate::ellipsoid::run::EllipsoidEngine;
use crate::ellipsoid::scene::LoadedScene;
use crate::ellipsoid::summary::RunSummary;
use crate::engine::{Engine, Outcome, Resumed, Sample, SampleError};
use crate::granular::soft::run::{SoftEngine, SoftSummary};
use crate::granular::soft::scene::SoftScene;
use crate::io::manifest::MANIFEST_FILE;
use crate::io::run_budget::Budget;
use crate::io::run_lock::{DirLock, LOCK_FILE, LockError, is_lock_file};
use crate::io::safe_write;

use crate::io::checkpoint::{CHECKPOINT_FILE, CHECKPOINT_TMP_FILE};

/// The `format` tag of a checkpoint.
pub const CHECKPOINT_FORMAT: &str = "rubblepile-checkpoint";
/// The checkpoint layout this build writes and reads (1: one layout per engine, before the one driver; 2: before
/// the scale-free error norm and error-per-unit-step control, whose step-size state means another norm).
pub const CHECKPOINT_VERSION: u32 = 3;

/// Default wall-clock checkpoint cadence (s) of [`RunOptions::default`] and of the command line: runs shorter than
/// this never write a checkpoint.
pub const DEFAULT_CHECKPOINT_EVERY: f64 = 600.0;

/// How a run behaves (not what it simulates).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunOptions {
    /// Write into an existing non-empty output directory (removing a previous run's files first).
    pub force: bool,
    /// Show a progress bar on stderr when stderr is a terminal.
    pub progress: bool,
    /// Checkpoint at the first output sample after this many wall-clock seconds since the last checkpoint (or the
    /// start of the process); `None` or a value ≤ 0 = never by wall clock.
    pub checkpoint_every: Option<f64>,
    /// Checkpoint at the first output sample at least this many simulated seconds after the last checkpoint's time
    /// (or the start); `Some(0.0)` = at every output sample; `None` = never by simulated time.
    pub checkpoint_every_sim: Option<f64>,
    /// Extra snapshot formats to write beside the engine's CSV snapshots ([`formats`]).
    pub formats: formats::Formats,
    /// Wall-clock seconds between progress lines when `progress` is on and stderr is not a terminal (a batch log);
    /// 0 = no lines. Default [`progress::DEFAULT_PROGRESS_EVERY`] (60 s).
    pub progress_every: f64,
    /// Testing hook: stop with [`RunError::Stopped`] right after this process has written this many checkpoints
    /// (as if the process had been killed then).
    pub stop_after_checkpoints: Option<u64>,
    /// Most steps the run may take (`--max-steps`), over the scene's `[run] max_steps`; `None`: the scene's, else
    /// [`crate::io::run_budget::DEFAULT_MAX_STEPS`] ([`crate::io::run_budget`]).
    pub max_steps: Option<u64>,
    /// Most wall-clock seconds this process may run the run (`--max-wall-s`), over the scene's
    /// `[run] max_wall_seconds`; `None`: the scene's, else no limit.
    pub max_wall_seconds: Option<f64>,
    /// The name of this run in its progress lines and bar (`None`: unnamed), for a command that runs several one
    /// after another (a flyby's `run` and `control`).
    pub progress_label: Option<&'static str>,
}

impl Default for RunOptions {
    /// `force: false, progress: true`, checkpoints every [`DEFAULT_CHECKPOINT_EVERY`] wall-clock seconds, none by
    /// simulated time, no stop.
    fn default() -> Self {
        RunOptions {
            force: false,
            progress: true,
            checkpoint_every: Some(DEFAULT_CHECKPOINT_EVERY),
            checkpoint_every_sim: None,
            formats: formats::Formats::NONE,
            progress_every: progress::DEFAULT_PROGRESS_EVERY,
            stop_after_checkpoints: None,
            max_steps: None,
            max_wall_seconds: None,
            progress_label: None,
        }
    }
}

/// Why a run did not complete; `S` is the engine's summary (carried by [`RunError::Failed`]). Messages are one line.
#[derive(Debug, thiserror::Error)]
pub enum RunError<S> {
    /// The output directory holds files and `force` was not given.
    #[error("output directory {} exists and is not empty; use --force to overwrite it", .dir.display())]
    OutputExists {
        /// The directory.
        dir: PathBuf,
    },
    /// The output path exists and is not a directory.
    #[error("output path {} exists and is not a directory", .dir.display())]
    NotADirectory {
        /// The path.
        dir: PathBuf,
    },
    /// Reading or writing a file failed (or a symbolic link was found where a file is written).
    #[error("{}", crate::io::safe_write::describe(.path, .source))]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The engine could not be set up from the scene (e.g. bad integrator tolerances).
    #[error("{0}")]
    Setup(String),
    /// The run failed; `summary.json` and `last_good_state.csv` were written.
    #[error("run failed: {cause}; last good state (t = {t} s) in {}", .last_good_state.display())]
    Failed {
        /// Last good time (s).
        t: f64,
        /// The cause (also in the summary's `status`).
        cause: String,
        /// Where the last good state was written.
        last_good_state: PathBuf,
        /// The summary written.
        summary: Box<S>,
    },
    /// [`resume`]: the directory holds no checkpoint.
    #[error("nothing to resume: {} does not exist (checkpoints are written only when due, see --checkpoint-every-s)", .dir.join(CHECKPOINT_FILE).display())]
    NoCheckpoint {
        /// The run directory.
        dir: PathBuf,
    },
    /// [`resume`]: the run already completed.
    #[error("the run in {} already completed (t = {t} s); nothing to resume", .dir.display())]
    AlreadyCompleted {
        /// The run directory.
        dir: PathBuf,
        /// Its final time (s).
        t: f64,
    },
    /// [`resume`]: the checkpoint or the run directory cannot be used (corrupt checkpoint, changed scene or input
    /// file, truncated time series, …).
    #[error("cannot resume: {0}")]
    BadCheckpoint(String),
    /// Another process (or thread) is writing the directory ([`crate::io::run_lock`]): refused at once.
    #[error(transparent)]
    Locked(#[from] LockError),
    /// The run stopped with a checkpoint at an output sample because its budget ([`crate::io::run_budget`]: most
    /// steps, most wall-clock seconds) would not last to the next one.
    #[error(
        "stopped at t = {t} s: {reason}; a checkpoint was written: continue with `rubblepile resume {}` and a larger \
         budget",
        .dir.display()
    )]
    Budget {
        /// The run directory.
        dir: PathBuf,
        /// Time of the checkpoint (s).
        t: f64,
        /// Which budget, and how much of it was used.
        reason: String,
    },
    /// The run stopped after a checkpoint as asked by [`RunOptions::stop_after_checkpoints`].
    #[error("stopped after checkpoint {checkpoints} at t = {t} s (--stop-after-checkpoints); continue with `rubblepile resume {}`", .dir.display())]
    Stopped {
        /// The run directory.
        dir: PathBuf,
        /// Time of the checkpoint (s).
        t: f64,
        /// Checkpoints this process wrote.
        checkpoints: u64,
    },
}

impl<S> RunError<S> {
    /// Whether the error is the caller's (bad arguments) rather than a failed run: the CLI exits with code 2 for
    /// these and 1 otherwise.
    pub fn is_usage(&self) -> bool {
        matches!(
            self,
            RunError::OutputExists { .. }
                | RunError::NotADirectory { .. }
                | RunError::Setup(_)
                | RunError::NoCheckpoint { .. }
                | RunError::AlreadyCompleted { .. }
                | RunError::BadCheckpoint(_)
                | RunError::Locked(_)
        )
    }

    /// The command line's exit code: 2 for [`RunError::is_usage`], 3 for [`RunError::Stopped`] and
    /// [`RunError::Budget`], 1 otherwise.
    pub fn exit_code(&self) -> u8 {
        if self.is_usage() {
            2
        } else if matches!(self, RunError::Stopped { .. } | RunError::Budget { .. }) {
            3
        } else {
            1
        }
    }

    /// The same error with the failed run's summary mapped by `f` (every other variant unchanged).
    pub fn map_summary<T>(self, f: impl FnOnce(S) -> T) -> RunError<T> {
        match self {
            RunError::OutputExists { dir } => RunError::OutputExists { dir },
            RunError::NotADirectory { dir } => RunError::NotADirectory { dir },
            RunError::Io { path, source } => RunError::Io { path, source },
            RunError::Setup(m) => RunError::Setup(m),
            RunError::Failed {
                t,
                cause,
                last_good_state,
                summary,
            } => RunError::Failed {
                t,
                cause,
                last_good_state,
                summary: Box::new(f(*summary)),
            },
            RunError::NoCheckpoint { dir } => RunError::NoCheckpoint { dir },
            RunError::AlreadyCompleted { dir, t } => RunError::AlreadyCompleted { dir, t },
            RunError::BadCheckpoint(m) => RunError::BadCheckpoint(m),
            RunError::Locked(e) => RunError::Locked(e),
            RunError::Stopped { dir, t, checkpoints } => RunError::Stopped { dir, t, checkpoints },
            RunError::Budget { dir, t, reason } => RunError::Budget { dir, t, reason },
        }
    }
}

fn io_err<S>(path: &Path) -> impl FnOnce(std::io::Error) -> RunError<S> + '_ {
    move |source| RunError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Files a run writes at the top of its directory (removed by `force`).
const OUTPUT_FILES: [&str; 10] = [
    "scene.toml",
    "summary.json",
    "timeseries.csv",
    "tracks.csv",
    "spinup.csv",
    "last_good_state.csv",
    "barrier_overruns.csv",
    CHECKPOINT_FILE,
    CHECKPOINT_TMP_FILE,
    "impact.json",
];

/// Checks `dir` is usable as an output directory, creates it and locks it for this process; the lock is held until
/// the returned guard is dropped (keep it for as long as the directory is written). Nothing in `dir` is removed.
///
/// Errors: [`RunError::NotADirectory`]; [`RunError::OutputExists`] when `dir` holds files but no lock file (a
/// directory rubblepile never wrote gets no lock file) and `force` is not given; [`RunError::Locked`] at once when
/// another rubblepile process writes `dir`.
pub fn lock_output_dir<S>(dir: &Path, force: bool) -> Result<DirLock, RunError<S>> {
    if dir.exists() && !dir.is_dir() {
        return Err(RunError::NotADirectory { dir: dir.to_path_buf() });
    }
    std::fs::create_dir_all(dir).map_err(io_err(dir))?;
    if !force && !dir.join(LOCK_FILE).exists() && holds_outputs(dir)? {
        return Err(RunError::OutputExists { dir: dir.to_path_buf() });
    }
    Ok(DirLock::acquire(dir).map_err(|e| e.or("use another --out"))?)
}

/// Whether `dir` holds anything but lock files.
fn holds_outputs<S>(dir: &Path) -> Result<bool, RunError<S>> {
    let mut entries = std::fs::read_dir(dir).map_err(io_err(dir))?;
    Ok(entries.any(|e| e.is_ok_and(|e| !is_lock_file(&e.file_name()))))
}

/// Checks `dir` is usable, creates it, locks it for this process ([`lock_output_dir`]) and creates `snapshots/`; the
/// lock is held until the returned guard is dropped (keep it for as long as the directory is written). With `force`,
/// a previous run's files are removed first, with its derived `analysis/` and `frames/` (only those: other files
/// are left alone, the lock file too).
///
/// Errors: [`RunError::NotADirectory`]; [`RunError::Locked`] at once when another rubblepile process writes `dir`
/// (before anything in it is removed, `--force` or not); [`RunError::OutputExists`] when `dir` holds anything but
/// lock files and `force` is not given.
pub fn prepare_output_dir<S>(dir: &Path, force: bool) -> Result<DirLock, RunError<S>> {
    let lock = lock_output_dir(dir, force)?;
    if holds_outputs(dir)? {
        if !force {
            return Err(RunError::OutputExists { dir: dir.to_path_buf() });
        }
        refuse_links(dir)?;
        for name in OUTPUT_FILES.iter().chain([&MANIFEST_FILE]) {
            let p = dir.join(name);
            if p.is_file() && *name != "impact.json" {
                std::fs::remove_file(&p).map_err(io_err(&p))?;
            }
        }
        // The previous run's derived outputs (`analysis/`, `frames/`) describe its snapshots: they go too; a link
        // there is refused (nothing is removed through a link).
        for name in crate::io::manifest::NOT_RECORDED {
            let p = dir.join(name);
            safe_write::refuse_symlink(&p).map_err(io_err(&p))?;
            if p.is_dir() {
                std::fs::remove_dir_all(&p).map_err(io_err(&p))?;
            }
        }
        let snaps = dir.join("snapshots");
        if snaps.is_dir() {
            for entry in std::fs::read_dir(&snaps).map_err(io_err(&snaps))? {
                let entry = entry.map_err(io_err(&snaps))?;
                let name = entry.file_name();
                let name = name.to_string_lossy();
                let is_snapshot = name
                    .strip_suffix(".csv")
                    .is_some_and(|stem| !stem.is_empty() && stem.bytes().all(|b| b.is_ascii_digit()));
                // A killed writer's temporary file goes too (crate::io::safe_write).
                if is_snapshot || name.starts_with(safe_write::TMP_PREFIX) {
                    std::fs::remove_file(entry.path()).map_err(io_err(&entry.path()))?;
                }
            }
        }
    }
    let snaps = dir.join("snapshots");
    safe_write::ensure_dir(&snaps).map_err(io_err(&snaps))?;
    Ok(lock)
}

/// Refuses, naming the first, a symbolic link among the files a run writes or removes at the top of `dir`, the
/// `snapshots/` directory and the files in it ([`crate::io::safe_write`]): nothing is written through a link.
pub fn refuse_links<S>(dir: &Path) -> Result<(), RunError<S>> {
    let check = |p: &Path| safe_write::refuse_symlink(p).map_err(io_err(p));
    for name in OUTPUT_FILES.iter().chain([&MANIFEST_FILE, &"snapshots"]) {
        check(&dir.join(name))?;
    }
    if let Ok(entries) = std::fs::read_dir(dir.join("snapshots")) {
        for entry in entries.flatten() {
            check(&entry.path())?;
        }
    }
    Ok(())
}

/// `checkpoint.json`: the driver's envelope around the engine's state `S`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(super) struct Checkpoint<S> {
    format: String,
    version: u32,
    writer: String,
    /// The engine's scene kind.
    kind: String,
    /// FNV-1a hash of the run's `scene.toml` copy.
    scene_hash: String,
    /// Directory relative input files of the scene are resolved against (absolute).
    scene_base_dir: Option<PathBuf>,
    #[serde(with = "exact_f64")]
    pub(super) t: f64,
    /// For people reading the file only.
    t_seconds: f64,
    /// Index of the next output sample.
    pub(super) next_sample: u64,
    timeseries_rows: u64,
    timeseries_bytes: u64,
    /// Checkpoints written by the run so far (all processes).
    checkpoints: u64,
    #[serde(with = "exact_f64")]
    wall_seconds: f64,
    pub(super) engine: S,
}

/// The envelope alone, read first to say clearly which checkpoint this is before its engine part is parsed.
#[derive(Debug, Deserialize)]
struct Header {
    format: Option<String>,
    version: Option<u32>,
    kind: Option<String>,
}

/// Where a [`Session`] starts: t = 0, or a checkpoint.
struct Start {
    next_sample: u64,
    rows: u64,
    bytes: u64,
    wall_before: f64,
    checkpoints: u64,
    timeseries: File,
}

/// What every checkpoint of a run repeats.
struct Identity {
    scene_base_dir: Option<PathBuf>,
    scene_hash: String,
}

fn absolute_base<S>(engine: &impl Engine) -> Result<Option<PathBuf>, RunError<S>> {
    let absolute = |d: &Path| std::fs::canonicalize(d).or_else(|_| std::path::absolute(d));
    engine
        .scene_base_dir()
        .map(|d| absolute(d).map_err(io_err(d)))
        .transpose()
}

/// The scene text a run keeps as `out_dir/scene.toml`: the engine's own, with its relative input files written by
/// their absolute paths ([`crate::io::standalone`]) unless the scene's directory is the run directory itself
/// (`impact`, `flyby` and campaigns keep their `initial_bodies.csv` there, so the directory can move as a whole).
fn standalone_scene(engine: &impl Engine, out_dir: &Path) -> String {
    let text = engine.scene_source();
    match engine.scene_base_dir() {
        Some(base) if !same_dir(base, out_dir) => crate::io::standalone::with_absolute_inputs(text, base),
        _ => text.to_string(),
    }
}

/// Whether `a` and `b` name the same existing directory.
fn same_dir(a: &Path, b: &Path) -> bool {
    let canon = |p: &Path| std::fs::canonicalize(if p.as_os_str().is_empty() { Path::new(".") } else { p });
    matches!((canon(a), canon(b)), (Ok(x), Ok(y)) if x == y)
}

/// Runs `engine` from its initial state, writing the outputs into `out_dir` (see the module docs).
///
/// Holds the lock of `out_dir` ([`prepare_output_dir`]) until it returns, and refuses an existing non-empty
/// `out_dir` unless `options.force`. When the engine fails (non-finite state, step
/// size underflow, a broken constraint), writes `last_good_state.csv` and `summary.json` (naming the cause) and
/// returns [`RunError::Failed`]. Prints nothing but the progress bar; see [`RunReport::one_line`].
pub fn run<E: Engine>(engine: E, out_dir: &Path, options: &RunOptions) -> Result<E::Summary, RunError<E::Summary>> {
    Session::start(engine, out_dir, options)?.run_to_end()
}

/// A step count as people read it: digits below 1e7, `1e9` above.
fn count(n: u64) -> String {
    if n < 10_000_000 {
        n.to_string()
    } else {
        format!("{:e}", n as f64)
    }
}

/// The budget `engine`'s run is held to: the command line's over the scene's `[run]` table.
fn budget_of(engine: &impl Engine, options: &RunOptions) -> Budget {
    Budget::resolve(
        crate::io::run_budget::from_scene_text(engine.scene_source()),
        options.max_steps,
        options.max_wall_seconds,
    )
}

/// The final time of a completed run in `dir` (from its `summary.json`), if it completed.
fn completed_run(dir: &Path) -> Option<f64> {
    let text = std::fs::read_to_string(dir.join("summary.json")).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    (v.get("status")?.as_str()? == "completed").then(|| {
        v.get("final_time")
            .or(v.get("t_reached"))
            .and_then(|t| t.as_f64())
            .unwrap_or(f64::NAN)
    })
}

/// Reads `dir/checkpoint.json` as a checkpoint of engine `E`, with one-line errors naming what is wrong.
pub(super) fn read_checkpoint<E: Engine>(dir: &Path) -> Result<Checkpoint<E::State>, RunError<E::Summary>> {
    let path = dir.join(CHECKPOINT_FILE);
    let corrupt = |reason: String| {
        RunError::BadCheckpoint(format!(
            "{}: corrupt or incompatible checkpoint: {}",
            path.display(),
            reason.split_whitespace().collect::<Vec<_>>().join(" ")
        ))
    };
    let text = match crate::io::scene_file::read_text_bounded(&path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(RunError::NoCheckpoint { dir: dir.to_path_buf() });
        }
        // Not UTF-8, larger than MAX_INPUT_BYTES or a line longer than MAX_LINE_BYTES (the message says which).
        Err(e) if e.kind() == std::io::ErrorKind::InvalidData => return Err(corrupt(e.to_string())),
        Err(source) => return Err(RunError::Io { path, source }),
    };
    let header: Header = serde_json::from_str(&text).map_err(|e| corrupt(e.to_string()))?;
    match header.format.as_deref() {
        Some(CHECKPOINT_FORMAT) => {}
        Some(f @ ("rubblepile-ssdem-checkpoint" | "rubblepile-hsdem-checkpoint")) => {
            return Err(RunError::BadCheckpoint(format!(
                "{}: format {f:?} was written by an older rubblepile (before the one run driver); this build reads \
                 {CHECKPOINT_FORMAT:?} version {CHECKPOINT_VERSION}: re-run the scene from the start",
                path.display()
            )));
        }
        other => {
            return Err(corrupt(format!(
                "format is {:?}, expected {CHECKPOINT_FORMAT:?}",
                other.unwrap_or("missing")
            )));
        }
    }
    if header.version != Some(CHECKPOINT_VERSION) {
        return Err(RunError::BadCheckpoint(format!(
            "{}: version {} was written by an older rubblepile (this build reads version {CHECKPOINT_VERSION}; version \
             1 predates the one run driver, version 2 the scale-free error norm of the integrator): re-run the scene \
             from the start",
            path.display(),
            header.version.map_or("missing".to_string(), |v| v.to_string())
        )));
    }
    if header.kind.as_deref() != Some(E::KIND) {
        return Err(RunError::BadCheckpoint(format!(
            "{}: a checkpoint of a {:?} run, but the run's scene is of kind {:?}",
            path.display(),
            header.kind.as_deref().unwrap_or("missing"),
            E::KIND
        )));
    }
    let de = &mut serde_json::Deserializer::from_str(&text);
    let c: Checkpoint<E::State> = serde_path_to_error::deserialize(de).map_err(|e| {
        let at = e.path().to_string();
        let inner = e.into_inner();
        if at.is_empty() || at == "." {
            corrupt(inner.to_string())
        } else {
            corrupt(format!("{at}: {inner}"))
        }
    })?;
    if !c.t.is_finite() {
        return Err(corrupt("non-finite time".into()));
    }
    Ok(c)
}

/// Continues the run in `dir` from its `checkpoint.json` (see the module docs), as if it had never stopped: same
/// snapshots, time-series rows (after cutting those written after the checkpoint) and summary. `options.force` is
/// ignored; the checkpoint options apply to the continued run.
///
/// The directory is locked ([`crate::io::run_lock`]) from before it is read until the run ends, and nothing in it
/// is changed before every check has passed.
///
/// Errors: [`RunError::Locked`] at once when another rubblepile process writes `dir`; [`RunError::AlreadyCompleted`]
/// when `dir/summary.json` says the run completed, [`RunError::NoCheckpoint`] without a checkpoint,
/// [`RunError::BadCheckpoint`] when the checkpoint is corrupt or does not match the directory (scene copy, input
/// files, a snapshot written before the checkpoint missing, a time series shorter than at the checkpoint); otherwise
/// as [`run`].
pub fn resume<E: Engine>(dir: &Path, options: &RunOptions) -> Result<E::Summary, RunError<E::Summary>> {
    Session::<E>::resume(dir, options)?.run_to_end()
}

/// The bytes of `dir/checkpoint.json` for `checkpoint`.
fn checkpoint_bytes<S: Serialize>(checkpoint: &Checkpoint<S>) -> std::io::Result<Vec<u8>> {
    let mut bytes = serde_json::to_vec_pretty(checkpoint).map_err(std::io::Error::other)?;
    bytes.push(b'\n');
    Ok(bytes)
}

fn write_summary<S: Serialize>(path: &Path, summary: &S) -> std::io::Result<()> {
    let text = serde_json::to_string_pretty(summary).map_err(std::io::Error::other)?;
    safe_write::write_atomic(path, text + "\n")
}

/// Runs `op` on a worker thread of rayon's global pool while the caller waits (in place when already on a pool's
/// worker). An engine's parallel passes are then forked from inside the pool; forked from outside it, every pass
/// is injected into the pool and the caller sleeps until it ends. The pool's other workers stay awake for the run
/// ([`warm_pool::with_warm_workers`]).
///
/// With `useful` threads fewer than the pool has (see [`Engine::useful_threads`]), `op` runs on a pool of its own
/// of `useful` threads instead: the run's parallel passes then fork over no more threads than pay for themselves.
fn on_pool<R: Send>(useful: usize, op: impl FnOnce() -> R + Send) -> R {
    if useful < rayon::current_num_threads()
        && let Ok(pool) = rayon::ThreadPoolBuilder::new().num_threads(useful.max(1)).build()
    {
        return pool.install(|| warm_pool::with_warm_workers(op));
    }
    if rayon::current_thread_index().is_some() {
        warm_pool::with_warm_workers(op)
    } else {
        rayon::scope(|_| warm_pool::with_warm_workers(op))
    }
}

/// How one call of [`Session::step`] ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Step<S> {
    /// One output sample was reached and written; more remain.
    Sampled,
    /// The last output sample was reached: the run completed, its summary written.
    Completed(S),
}

/// A run in progress, held in memory and advanced one output sample at a time: what [`run`] and [`resume`] drive
/// to the end, for callers that want the state between samples (the Python front, `src/python/`). It writes the
/// same files as [`run`], as it goes, and holds the output directory's lock until dropped.
///
/// The wall-clock time it reports counts from [`Session::start`] (or [`Session::resume`]), pauses between
/// [`Session::step`] calls included.
pub struct Session<E: Engine> {
    engine: E,
    out_dir: PathBuf,
    options: RunOptions,
    identity: Identity,
    budget: Budget,
    files: run_files::RunFiles,
    manifest: crate::io::manifest::Recorder,
    samples: Vec<Sample>,
    next_sample: usize,
    rows: u64,
    bytes: u64,
    wall_before: f64,
    checkpoints: u64,
    checkpoints_here: u64,
    started: Instant,
    last_checkpoint_wall: Instant,
    last_checkpoint_t: f64,
    shown: progress::Progress,
    deadline: Option<Instant>,
    done: bool,
    _lock: Option<DirLock>,
}

impl<E: Engine> Session<E> {
    /// Starts a run of `engine` from its initial state in `out_dir`, as [`run`] does before its first sample
    /// (refusing a scene whose work estimate exceeds its budget, locking and preparing the directory, writing
    /// `scene.toml` and the time series' header). Errors: as [`run`].
    pub fn start(mut engine: E, out_dir: &Path, options: &RunOptions) -> Result<Self, RunError<E::Summary>> {
        // A scene its own work estimate says will not end within the budget is refused before anything is written.
        let budget = budget_of(&engine, options);
        if let Some(steps) = engine.estimated_steps()
            && steps > budget.max_steps as f64
        {
            return Err(RunError::Setup(format!(
                "the scene needs about {steps:.1e} steps to t_end = {} s, more than max_steps = {} ({}); raise it with \
                 [run] max_steps or --max-steps to run the scene anyway, or shorten t_end",
                engine.t_end(),
                count(budget.max_steps),
                budget.steps_from
            )));
        }
        let lock = prepare_output_dir(out_dir, options.force)?;
        let scene_copy = out_dir.join("scene.toml");
        let scene_text = standalone_scene(&engine, out_dir);
        safe_write::write_atomic(&scene_copy, &scene_text).map_err(io_err(&scene_copy))?;
        let identity = Identity {
            scene_base_dir: absolute_base(&engine)?,
            scene_hash: fnv1a_hex(scene_text.as_bytes()),
        };
        let ts_path = out_dir.join("timeseries.csv");
        let mut timeseries = safe_write::create_fresh(&ts_path).map_err(io_err(&ts_path))?;
        let header = engine.timeseries_header();
        timeseries.write_all(header.as_bytes()).map_err(io_err(&ts_path))?;
        engine.open_outputs(out_dir).map_err(io_err(out_dir))?;
        let start = Start {
            next_sample: 0,
            rows: 0,
            bytes: header.len() as u64,
            wall_before: 0.0,
            checkpoints: 0,
            timeseries,
        };
        Ok(Session::new(
            engine,
            out_dir,
            options,
            start,
            identity,
            budget,
            Some(lock),
        ))
    }

    /// Continues the run in `dir` from its checkpoint, as [`resume`] does before its first sample. Errors: as
    /// [`resume`].
    pub fn resume(dir: &Path, options: &RunOptions) -> Result<Self, RunError<E::Summary>> {
        // A directory that does not exist is left to the checks below to name.
        let lock = dir.is_dir().then(|| DirLock::acquire(dir)).transpose()?;
        // Nothing through a link: refused before anything is read or changed.
        if dir.is_dir() {
            refuse_links(dir)?;
        }
        if let Some(t) = completed_run(dir) {
            return Err(RunError::AlreadyCompleted {
                dir: dir.to_path_buf(),
                t,
            });
        }
        let ckpt = read_checkpoint::<E>(dir)?;
        let bad = RunError::BadCheckpoint;
        let scene_path = dir.join("scene.toml");
        let text = std::fs::read_to_string(&scene_path).map_err(|e| bad(format!("{}: {e}", scene_path.display())))?;
        if fnv1a_hex(text.as_bytes()) != ckpt.scene_hash {
            return Err(bad(format!(
                "{} changed since the checkpoint was written",
                scene_path.display()
            )));
        }
        let mut engine = E::from_scene_text(&text, &scene_path.display().to_string(), ckpt.scene_base_dir.as_deref())
            .map_err(|e| bad(e.to_string()))?;

        // The checkpoint must sit right after one of the run's samples.
        let samples = engine.samples();
        let prev = ckpt.next_sample.checked_sub(1).and_then(|i| samples.get(i as usize));
        if ckpt.next_sample as usize >= samples.len() || prev.is_none_or(|p| p.t.to_bits() != ckpt.t.to_bits()) {
            return Err(bad(format!(
                "the checkpoint (t = {} s, next sample {}) does not match the scene's output samples",
                ckpt.t, ckpt.next_sample
            )));
        }
        if ckpt.timeseries_rows != ckpt.next_sample {
            return Err(bad(format!(
                "the checkpoint counts {} time-series rows for {} samples",
                ckpt.timeseries_rows, ckpt.next_sample
            )));
        }
        // What the run wrote before the checkpoint must all be there: a resumed run never writes it again.
        let missing = inspect::missing_snapshots(dir, &samples[..ckpt.next_sample as usize]);
        if !missing.is_empty() {
            return Err(bad(format!(
                "{}; re-run the scene from the start",
                inspect::describe_missing(dir, &missing, &format!("the checkpoint at t = {} s", ckpt.t))
            )));
        }
        let ts_path = dir.join("timeseries.csv");
        match std::fs::metadata(&ts_path) {
            Err(e) => return Err(bad(format!("{}: {e}", ts_path.display()))),
            Ok(m) if m.len() < ckpt.timeseries_bytes => {
                return Err(bad(format!(
                    "{}: holds {} bytes, fewer than the {} written before the checkpoint; re-run the scene from the start",
                    ts_path.display(),
                    m.len(),
                    ckpt.timeseries_bytes
                )));
            }
            Ok(_) => {}
        }
        // Every finished file as the manifest records it (a directory written before the manifest: the snapshots row
        // by row), before anything is continued from them.
        match crate::io::manifest::verify_all(dir) {
            Err(e) => return Err(bad(format!("{e}; re-run the scene from the start"))),
            Ok(Some(_)) => {}
            Ok(None) => {
                for k in samples[..ckpt.next_sample as usize].iter().filter_map(|s| s.snapshot) {
                    let p = dir.join("snapshots").join(format!("{k}.csv"));
                    crate::io::manifest::check_rows(&p, true)
                        .map_err(|e| bad(format!("{e}; re-run the scene from the start")))?;
                }
            }
        }
        engine
            .restore(
                ckpt.engine,
                dir,
                Resumed {
                    t: ckpt.t,
                    samples_done: ckpt.next_sample,
                },
            )
            .map_err(|e| bad(e.to_string()))?;

        // Stale files of the interrupted process (a failure summary, a half-written checkpoint).
        for name in ["summary.json", "last_good_state.csv", CHECKPOINT_TMP_FILE] {
            let p = dir.join(name);
            if p.is_file() {
                std::fs::remove_file(&p).map_err(io_err(&p))?;
            }
        }
        let snaps = dir.join("snapshots");
        safe_write::ensure_dir(&snaps).map_err(io_err(&snaps))?;
        let timeseries =
            crate::engine::reopen_truncated(&ts_path, ckpt.timeseries_bytes).map_err(|e| bad(e.to_string()))?;
        let identity = Identity {
            scene_base_dir: ckpt.scene_base_dir.clone(),
            scene_hash: ckpt.scene_hash.clone(),
        };
        let start = Start {
            next_sample: ckpt.next_sample,
            rows: ckpt.timeseries_rows,
            bytes: ckpt.timeseries_bytes,
            wall_before: ckpt.wall_seconds,
            checkpoints: ckpt.checkpoints,
            timeseries,
        };
        let budget = budget_of(&engine, options);
        Ok(Session::new(engine, dir, options, start, identity, budget, lock))
    }

    fn new(
        mut engine: E,
        out_dir: &Path,
        options: &RunOptions,
        start: Start,
        identity: Identity,
        budget: Budget,
        lock: Option<DirLock>,
    ) -> Self {
        let ts_path = out_dir.join("timeseries.csv");
        let started = Instant::now();
        let shown = progress::Progress::new(
            options.progress,
            options.progress_every,
            engine.t_end(),
            engine.time(),
            options.progress_label,
        );
        // The wall-clock budget holds inside a sample interval too: past the deadline an advance stops, and the run
        // stops with a checkpoint of the state saved at the sample before (kept only when there is a budget).
        let deadline = budget
            .max_wall_seconds
            .and_then(|s| started.checked_add(std::time::Duration::try_from_secs_f64(s).ok()?));
        engine.set_deadline(deadline);
        Session {
            samples: engine.samples(),
            last_checkpoint_t: engine.time(),
            engine,
            out_dir: out_dir.to_path_buf(),
            options: *options,
            identity,
            budget,
            files: run_files::RunFiles::new(start.timeseries, &ts_path),
            // The manifest of the run's finished files (crate::io::manifest), rewritten at each checkpoint and at
            // the end.
            manifest: crate::io::manifest::Recorder::new(),
            next_sample: start.next_sample as usize,
            rows: start.rows,
            bytes: start.bytes,
            wall_before: start.wall_before,
            checkpoints: start.checkpoints,
            checkpoints_here: 0,
            started,
            last_checkpoint_wall: Instant::now(),
            shown,
            deadline,
            done: false,
            _lock: lock,
        }
    }

    /// The engine, with its state at the last sample reached.
    pub fn engine(&self) -> &E {
        &self.engine
    }

    /// The engine, to change its state between samples (the run is then no longer the scene's alone; a checkpoint
    /// written after the change holds the changed state).
    pub fn engine_mut(&mut self) -> &mut E {
        &mut self.engine
    }

    /// The run's output directory.
    pub fn out_dir(&self) -> &Path {
        &self.out_dir
    }

    /// Every output sample of the run, in time order.
    pub fn samples(&self) -> &[Sample] {
        &self.samples
    }

    /// The index of the next sample to reach (the number reached so far).
    pub fn next_sample(&self) -> usize {
        self.next_sample
    }

    /// Whether every sample was reached (the run completed).
    pub fn is_done(&self) -> bool {
        self.done
    }

    /// The run's wall-clock seconds so far (those before its checkpoint included).
    pub fn wall_seconds(&self) -> f64 {
        self.wall_before + self.started.elapsed().as_secs_f64()
    }

    /// The engine's summary of the run so far, as [`Engine::summary`] of a completed run would give it now.
    pub fn summary(&self) -> E::Summary {
        self.engine.summary(Outcome::Completed, self.rows, self.wall_seconds())
    }

    /// Runs the remaining samples to the end (on rayon's pool, as [`run`] does) and returns the summary.
    pub fn run_to_end(mut self) -> Result<E::Summary, RunError<E::Summary>> {
        let useful = self.engine.useful_threads();
        on_pool(useful, || {
            loop {
                if let Step::Completed(summary) = self.step()? {
                    return Ok(summary);
                }
            }
        })
    }

    /// Runs `op` with the session on rayon's pool as [`run`] does (the engine's parallel passes forked from a
    /// worker; a pool of [`Engine::useful_threads`] threads when that is fewer).
    pub fn on_pool<R: Send>(&mut self, op: impl FnOnce(&mut Self) -> R + Send) -> R {
        let useful = self.engine.useful_threads();
        on_pool(useful, || op(self))
    }

    /// On failure: the rows so far, the last good state and the summary, then the error.
    fn fail(&mut self, failure: &crate::engine::Failure) -> RunError<E::Summary> {
        self.shown.abandon();
        let mut write = || -> Result<RunError<E::Summary>, RunError<E::Summary>> {
            self.files.flush().map_err(file_error)?;
            let lgs = self.out_dir.join("last_good_state.csv");
            let t_good = self.engine.write_last_good_state(&lgs).map_err(io_err(&lgs))?;
            let summary = self
                .engine
                .summary(Outcome::Failed(failure), self.rows, self.wall_seconds());
            let sp = self.out_dir.join("summary.json");
            write_summary(&sp, &summary).map_err(io_err(&sp))?;
            let mp = self.out_dir.join(MANIFEST_FILE);
            self.files.sync().map_err(file_error)?;
            self.manifest
                .write(&self.out_dir, "failed", true)
                .map_err(io_err(&mp))?;
            Ok(RunError::Failed {
                t: t_good,
                cause: failure.cause.clone(),
                last_good_state: lgs,
                summary: Box::new(summary),
            })
        };
        match write() {
            Ok(e) | Err(e) => e,
        }
    }

    /// Writes the checkpoint of `state` (the state at the sample before `next_sample`, at time `t`) between two
    /// manifests: the first records it as pending, the second as the checkpoint, so that a run killed at any
    /// instant leaves a directory whose manifest verifies the checkpoint there (the old one or the new).
    fn checkpoint_at(&mut self, state: E::State, t: f64, next_sample: u64) -> Result<(), RunError<E::Summary>> {
        self.checkpoints += 1;
        let ckpt = Checkpoint {
            format: CHECKPOINT_FORMAT.into(),
            version: CHECKPOINT_VERSION,
            writer: format!("rubblepile {}", env!("CARGO_PKG_VERSION")),
            kind: E::KIND.into(),
            scene_hash: self.identity.scene_hash.clone(),
            scene_base_dir: self.identity.scene_base_dir.clone(),
            t,
            t_seconds: t,
            next_sample,
            timeseries_rows: self.rows,
            timeseries_bytes: self.bytes,
            checkpoints: self.checkpoints,
            wall_seconds: self.wall_seconds(),
            engine: state,
        };
        let out_dir = &self.out_dir;
        let mp = out_dir.join(MANIFEST_FILE);
        let cp = out_dir.join(CHECKPOINT_FILE);
        let ckpt_bytes = checkpoint_bytes(&ckpt).map_err(io_err(&cp))?;
        self.manifest
            .write_with_pending(
                out_dir,
                &format!("checkpoint at t = {t} s being written"),
                false,
                Some((CHECKPOINT_FILE, &ckpt_bytes)),
            )
            .map_err(io_err(&mp))?;
        safe_write::write_atomic_durable(&cp, &ckpt_bytes).map_err(io_err(&cp))?;
        self.manifest
            .write(out_dir, &format!("checkpoint at t = {t} s"), false)
            .map_err(io_err(&mp))
    }

    /// Writes a checkpoint of the state now (at the last sample reached), from which [`resume`] continues the run.
    ///
    /// Errors: [`RunError::Setup`] before the first sample and after the last (no checkpoint is taken there);
    /// [`RunError::Io`].
    pub fn checkpoint(&mut self) -> Result<(), RunError<E::Summary>> {
        if self.next_sample == 0 || self.done {
            return Err(RunError::Setup(format!(
                "no checkpoint of the run in {} {}: a checkpoint sits between two output samples",
                self.out_dir.display(),
                if self.done {
                    "after it completed"
                } else {
                    "before its first output sample"
                }
            )));
        }
        self.files.sync().map_err(file_error)?;
        let state = self.engine.save().map_err(io_err(&self.out_dir))?;
        let t = self.engine.time();
        self.checkpoint_at(state, t, self.next_sample as u64)?;
        self.last_checkpoint_wall = Instant::now();
        self.last_checkpoint_t = t;
        Ok(())
    }

    fn steps_spent(&self, steps: u64) -> String {
        format!(
            "max_steps = {} ({}) reached: {steps} steps taken",
            count(self.budget.max_steps),
            self.budget.steps_from
        )
    }

    fn budget_stop(&self, t: f64, reason: String) -> RunError<E::Summary> {
        RunError::Budget {
            dir: self.out_dir.to_path_buf(),
            t,
            reason,
        }
    }

    /// Advances the run to its next output sample and writes what is due there (the time-series row, a snapshot,
    /// a checkpoint); after the last sample, the summary and the final manifest.
    ///
    /// Errors: as [`run`]; after any error, and after the run completed, the session is finished and a further
    /// call is refused with [`RunError::Setup`].
    pub fn step(&mut self) -> Result<Step<E::Summary>, RunError<E::Summary>> {
        let result = self.step_inner();
        if result.is_err() {
            self.done = true;
        }
        result
    }

    fn step_inner(&mut self) -> Result<Step<E::Summary>, RunError<E::Summary>> {
        if self.done {
            return Err(RunError::Setup(format!(
                "the run in {} has ended (t = {} s); nothing to advance",
                self.out_dir.display(),
                self.engine.time()
            )));
        }
        let index = self.next_sample;
        let total = self.samples.len() as u64;
        let Some(&sample) = self.samples.get(index) else {
            return self.complete().map(Step::Completed);
        };
        let budget_max_steps = self.budget.max_steps;
        let t_end = self.engine.t_end();
        // A resumed run whose budget is already spent stops where its checkpoint is, writing nothing.
        let steps_before = self.engine.steps_taken();
        if steps_before >= budget_max_steps {
            self.shown.abandon();
            let reason = self.steps_spent(steps_before);
            return Err(self.budget_stop(self.engine.time(), reason));
        }
        self.engine.limit_steps(budget_max_steps - steps_before);
        let interval_started = Instant::now();
        let t_before = self.engine.time();
        let saved = match self.deadline {
            Some(_) if index > 0 => Some(self.engine.save().map_err(io_err(&self.out_dir))?),
            _ => None,
        };
        // The error of the last sample: the engine is busy while it advances.
        let error = self.engine.error_so_far();
        let shown = &self.shown;
        let mut progress = |t: f64| shown.show(t, t_end, error);
        if let Err(mut failure) = self.engine.advance(index, &sample, &mut progress) {
            if let (true, Some(state)) = (failure.deadline, saved) {
                self.shown.abandon();
                self.files.sync().map_err(file_error)?;
                self.checkpoint_at(state, t_before, index as u64)?;
                let most = self.budget.max_wall_seconds.unwrap_or_default();
                return Err(self.budget_stop(
                    t_before,
                    format!(
                        "the wall-clock budget: max_wall_seconds = {most} s ran out within the sample interval to t = \
                         {} s",
                        sample.t
                    ),
                ));
            }
            if self.engine.steps_taken() >= budget_max_steps {
                failure.cause = format!(
                    "{} within one sample interval (to t = {} s; the integrator said: {})",
                    self.steps_spent(self.engine.steps_taken()),
                    sample.t,
                    failure.cause
                );
            }
            return Err(self.fail(&failure));
        }
        let row = match self.engine.sample(&sample, self.wall_seconds()) {
            Ok(row) => row,
            Err(SampleError::Failed(failure)) => return Err(self.fail(&failure)),
            Err(SampleError::Io { path, source }) => return Err(RunError::Io { path, source }),
        };
        self.files.write_row(&row).map_err(file_error)?;
        self.rows += 1;
        self.bytes += row.len() as u64;
        self.next_sample = index + 1;
        if let Some(k) = sample.snapshot {
            let p = self.out_dir.join("snapshots").join(format!("{k}.csv"));
            self.engine.write_snapshot(&p).map_err(io_err(&p))?;
            self.files.snapshot_written(p);
            let scene_formats: &[&str] = if self.engine.scene_vtk() { &["vtk"] } else { &[] };
            let extra_formats = self.options.formats.with(scene_formats).selected();
            if !extra_formats.is_empty() {
                let view = self.engine.view();
                // Every snapshot up to this one (a resumed run's earlier ones included), for formats' run indexes.
                let written: Vec<(usize, f64)> = self.samples[..=index]
                    .iter()
                    .filter_map(|s| s.snapshot.map(|k| (k, s.t)))
                    .collect();
                for f in &extra_formats {
                    f.write(&self.out_dir, k, &view, &written)
                        .map_err(io_err(&self.out_dir))?;
                }
            }
        }
        let t = self.engine.time();
        self.shown.show(t, t_end, self.engine.error_so_far());

        let options = &self.options;
        let due_wall = options
            .checkpoint_every
            .is_some_and(|s| s > 0.0 && self.last_checkpoint_wall.elapsed().as_secs_f64() >= s);
        let due_sim = options
            .checkpoint_every_sim
            .is_some_and(|s| t - self.last_checkpoint_t >= s.max(0.0));
        // The budget: stop here, with a checkpoint, when the next interval (judged by this one) would overrun it.
        let budget = &self.budget;
        let steps = self.engine.steps_taken();
        let interval_steps = steps - steps_before;
        let spent = self.started.elapsed().as_secs_f64();
        let interval_wall = interval_started.elapsed().as_secs_f64();
        let over_budget = if steps >= budget.max_steps || steps.saturating_add(interval_steps) > budget.max_steps {
            Some(format!(
                "the step budget: {} steps taken, {interval_steps} in the last sample interval, max_steps = {} ({})",
                steps,
                count(budget.max_steps),
                budget.steps_from
            ))
        } else {
            budget.max_wall_seconds.and_then(|most| {
                (spent + interval_wall > most).then(|| {
                    format!(
                        "the wall-clock budget: {spent:.1} s run here, {interval_wall:.1} s in the last sample interval, \
                         max_wall_seconds = {most} s"
                    )
                })
            })
        };
        let over_budget = over_budget.filter(|_| (index as u64) + 1 < total);
        if (index as u64) + 1 < total && (due_wall || due_sim || over_budget.is_some()) {
            self.checkpoint()?;
            self.checkpoints_here += 1;
            if let Some(reason) = over_budget {
                self.shown.abandon();
                return Err(self.budget_stop(t, reason));
            }
            if self
                .options
                .stop_after_checkpoints
                .is_some_and(|n| self.checkpoints_here >= n)
            {
                self.shown.abandon();
                return Err(RunError::Stopped {
                    dir: self.out_dir.to_path_buf(),
                    t,
                    checkpoints: self.checkpoints,
                });
            }
        }
        if self.next_sample == self.samples.len() {
            return self.complete().map(Step::Completed);
        }
        Ok(Step::Sampled)
    }

    /// After the last sample: the summary and the final manifest.
    fn complete(&mut self) -> Result<E::Summary, RunError<E::Summary>> {
        self.done = true;
        // The wall time is the run's; the final flush to disk comes after it, before the summary says "completed".
        let wall_seconds = self.wall_seconds();
        self.files.sync().map_err(file_error)?;
        self.shown.finish();
        let summary = self.engine.summary(Outcome::Completed, self.rows, wall_seconds);
        let sp = self.out_dir.join("summary.json");
        write_summary(&sp, &summary).map_err(io_err(&sp))?;
        let mp = self.out_dir.join(MANIFEST_FILE);
        self.manifest
            .write(&self.out_dir, "completed", true)
            .map_err(io_err(&mp))?;
        Ok(summary)
    }
}

fn file_error<S>((path, source): run_files::FileError) -> RunError<S> {
    RunError::Io { path, source }
}

/// Runs an ellipsoid scene ([`run`] with [`EllipsoidEngine`]).
pub fn run_scene(
    scene: &LoadedScene,
    out_dir: &Path,
    options: &RunOptions,
) -> Result<RunSummary, RunError<RunSummary>> {
    let engine = EllipsoidEngine::new(scene.clone()).map_err(|e| RunError::Setup(e.to_string()))?;
    run(engine, out_dir, options)
}

/// Continues an ellipsoid run ([`resume`] with [`EllipsoidEngine`]).
pub fn resume_run(dir: &Path, options: &RunOptions) -> Result<RunSummary, RunError<RunSummary>> {
    resume::<EllipsoidEngine>(dir, options)
}

/// Runs a soft-sphere scene ([`run`] with [`SoftEngine`]).
pub fn run_soft(scene: &SoftScene, out_dir: &Path, options: &RunOptions) -> Result<SoftSummary, RunError<SoftSummary>> {
    run(SoftEngine::new(scene.clone()), out_dir, options)
}

/// Continues a soft-sphere run ([`resume`] with [`SoftEngine`]).
pub fn resume_soft(dir: &Path, options: &RunOptions) -> Result<SoftSummary, RunError<SoftSummary>> {
    resume::<SoftEngine>(dir, options)
}

#[cfg(test)]
mod tests {
    use super::on_pool;

    /// The driver's loop runs on a worker of the pool, so that the engines' parallel passes fork from inside it.
    #[test]
    fn runs_are_driven_from_a_pool_worker() {
        assert_eq!(rayon::current_thread_index(), None, "the test thread is not a worker");
        assert!(on_pool(usize::MAX, || rayon::current_thread_index().is_some()));
        // already on a worker (of another pool): stays there
        let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        assert_eq!(
            pool.install(|| on_pool(usize::MAX, rayon::current_thread_index)),
            Some(0)
        );
    }

    /// A run that can use fewer threads than the pool has runs on a pool of that many (and no more than the pool
    /// has when it could use more).
    #[test]
    fn a_small_run_forks_over_no_more_threads_than_it_can_use() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(4).build().unwrap();
        assert_eq!(pool.install(|| on_pool(2, rayon::current_num_threads)), 2);
        assert_eq!(pool.install(|| on_pool(1, rayon::current_num_threads)), 1);
        assert_eq!(pool.install(|| on_pool(64, rayon::current_num_threads)), 4);
        assert_eq!(
            pool.install(|| on_pool(0, rayon::current_num_threads)),
            1,
            "at least one thread"
        );
    }
}
