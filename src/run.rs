//! The run driver: integrates a [`LoadedScene`] from t = 0 to `t_end` and writes the outputs.
//!
//! Files written in the output directory:
//! - `scene.toml`: a copy of the scene text;
//! - `timeseries.csv`: energies, momenta and the energy residual every `output.every` seconds and
//!   at each snapshot time (written and flushed row by row);
//! - `snapshots/<k>.csv`: the bodies at the k-th `output.times` entry;
//! - `tracks.csv` (only when `output.track` lists bodies): those bodies' rows, in the snapshot columns, at
//!   every time-series sample;
//! - `summary.json`: counters and conservation errors ([`RunSummary`]);
//! - `last_good_state.csv` (only when a run fails): the last good state, in snapshot format;
//! - `barrier_overruns.csv` (only when a pair overran its contact barrier): one row per pair and sampled
//!   time, appended as found ([`crate::ellipsoid::barrier`]; the pairs are listed in `summary.json`'s
//!   `barrier`, and the run goes on);
//! - `checkpoint.json` (only when checkpoints are due, see [`RunOptions`]): the full state the run
//!   continues from with [`resume_run`] (format in [`crate::io::checkpoint`]).
//!
//! # Checkpoints and resume
//!
//! Checkpoints are taken at output samples only (after the sample's time-series row and snapshot
//! are written), when [`RunOptions::checkpoint_every`] wall-clock seconds have passed since the
//! last checkpoint (or since the process started) or [`RunOptions::checkpoint_every_sim`] simulated
//! seconds have passed since the last checkpoint's time; never after the last sample. Taking a
//! checkpoint does not touch the integration, and [`resume_run`] restores the integrator's internal
//! state exactly ([`crate::integrate::Integrator::restore_state`]), so a run interrupted after a
//! checkpoint and resumed ends with the same snapshots, time series (the `wall_seconds` column
//! aside) and summary counters, bit for bit, as an uninterrupted run.
//!
//! On resume the scene is re-read from the run's `scene.toml` copy; a relative `scene.bodies_file`
//! in it is resolved against the *original* scene file's directory, stored (absolute) in the
//! checkpoint, and the bodies read are checked against a fingerprint stored with it (as is the
//! scene text), so a moved or edited bodies file gives a clear error instead of a different run.
//! `timeseries.csv` is truncated to the rows written up to the checkpoint (a process killed later
//! may have written more), and so is `tracks.csv`; snapshots written after the checkpoint are rewritten
//! identically.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use crate::ellipsoid::barrier::{BarrierMonitor, BarrierSettings, OVERRUN_FILE};
use crate::ellipsoid::equations::{Diagnostics, EllipsoidSystem};
use crate::integrate::{IntegrateError, Integrator, OdeSystem, Tolerances, make_integrator};
use crate::io::checkpoint::{
    CHECKPOINT_FILE, CHECKPOINT_FORMAT, CHECKPOINT_TMP_FILE, CHECKPOINT_VERSION, Checkpoint, CheckpointError,
    DriverState, ErrorState, TimeseriesAppender, fnv1a_hex, read_checkpoint, write_checkpoint,
};
use crate::io::csv::{TimeseriesRow, TimeseriesWriter, TracksWriter, snapshot_records, write_snapshot};
pub use crate::io::summary::RunSummary;
use crate::io::summary::{CalibrationSummary, PhysicsSummary, Scales, write_summary};
use crate::scene::{KappaSource, LoadedScene, parse_scene};

/// Quaternion norm errors above this mean the unit-norm constraint broke; the run stops.
pub const QUATERNION_NORM_LIMIT: f64 = 1e-3;

/// Default wall-clock checkpoint cadence (s) of [`RunOptions::default`] and of the command line:
/// runs shorter than this never write a checkpoint.
pub const DEFAULT_CHECKPOINT_EVERY: f64 = 600.0;

/// How a run behaves (not what it simulates).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunOptions {
    /// Write into an existing non-empty output directory (removing a previous run's files first).
    pub force: bool,
    /// Show a progress bar on stderr when stderr is a terminal.
    pub progress: bool,
    /// Checkpoint at the first output sample after this many wall-clock seconds since the last
    /// checkpoint (or the start of the process); `None` or a value ≤ 0 = never by wall clock.
    pub checkpoint_every: Option<f64>,
    /// Checkpoint at the first output sample at least this many simulated seconds after the last
    /// checkpoint's time (or t = 0); `Some(0.0)` = at every output sample; `None` = never by
    /// simulated time.
    pub checkpoint_every_sim: Option<f64>,
    /// Testing hook: stop with [`RunError::Stopped`] right after this process has written this many
    /// checkpoints (as if the process had been killed then).
    pub stop_after_checkpoints: Option<u64>,
}

impl Default for RunOptions {
    /// `force: false, progress: true`, checkpoints every [`DEFAULT_CHECKPOINT_EVERY`] wall-clock
    /// seconds, none by simulated time, no stop.
    fn default() -> Self {
        RunOptions {
            force: false,
            progress: true,
            checkpoint_every: Some(DEFAULT_CHECKPOINT_EVERY),
            checkpoint_every_sim: None,
            stop_after_checkpoints: None,
        }
    }
}

/// Why a run did not complete. Messages are one line.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
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
    /// Reading or writing a file failed.
    #[error("{}: {source}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The integrator could not be built (e.g. bad tolerances).
    #[error("integrator setup: {0}")]
    Setup(IntegrateError),
    /// The integration failed; `summary.json` and `last_good_state.csv` were written.
    #[error("run failed: {cause}; last good state (t = {t} s) in {}", .last_good_state.display())]
    Failed {
        /// Last good time (s).
        t: f64,
        /// The cause (also the summary's `status`).
        cause: String,
        /// Where the last good state was written.
        last_good_state: PathBuf,
        /// The summary written.
        summary: Box<RunSummary>,
    },
    /// [`resume_run`]: the directory holds no checkpoint.
    #[error("nothing to resume: {} does not exist (checkpoints are written only when due, see --checkpoint-every)", .dir.join(CHECKPOINT_FILE).display())]
    NoCheckpoint {
        /// The run directory.
        dir: PathBuf,
    },
    /// [`resume_run`]: the run already completed.
    #[error("the run in {} already completed (t = {t} s); nothing to resume", .dir.display())]
    AlreadyCompleted {
        /// The run directory.
        dir: PathBuf,
        /// Its final time (s).
        t: f64,
    },
    /// [`resume_run`]: the checkpoint or the run directory cannot be used (corrupt checkpoint,
    /// changed scene or bodies file, truncated time series, …).
    #[error("cannot resume: {0}")]
    BadCheckpoint(String),
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

impl RunError {
    /// Whether the error is the caller's (bad arguments) rather than a failed run: the CLI exits
    /// with code 2 for these and 1 otherwise.
    pub fn is_usage(&self) -> bool {
        matches!(
            self,
            RunError::OutputExists { .. }
                | RunError::NotADirectory { .. }
                | RunError::NoCheckpoint { .. }
                | RunError::AlreadyCompleted { .. }
                | RunError::BadCheckpoint(_)
        )
    }

    /// The command line's exit code for this error: 2 for [`RunError::is_usage`], 3 for
    /// [`RunError::Stopped`], 1 otherwise.
    pub fn exit_code(&self) -> u8 {
        if self.is_usage() {
            2
        } else if matches!(self, RunError::Stopped { .. }) {
            3
        } else {
            1
        }
    }
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> RunError + '_ {
    move |source| RunError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Files a run writes at the top of its directory (removed by `force`).
const OUTPUT_FILES: [&str; 8] = [
    "scene.toml",
    "summary.json",
    "timeseries.csv",
    "tracks.csv",
    "last_good_state.csv",
    OVERRUN_FILE,
    CHECKPOINT_FILE,
    CHECKPOINT_TMP_FILE,
];

/// Checks `dir` is usable and creates it (and `snapshots/`). With `force`, a previous run's files
/// are removed first (only those: other files are left alone).
pub fn prepare_output_dir(dir: &Path, force: bool) -> Result<(), RunError> {
    if dir.exists() {
        if !dir.is_dir() {
            return Err(RunError::NotADirectory { dir: dir.to_path_buf() });
        }
        let non_empty = std::fs::read_dir(dir).map_err(io_err(dir))?.next().is_some();
        if non_empty {
            if !force {
                return Err(RunError::OutputExists { dir: dir.to_path_buf() });
            }
            for name in OUTPUT_FILES {
                let p = dir.join(name);
                if p.is_file() {
                    std::fs::remove_file(&p).map_err(io_err(&p))?;
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
                    if is_snapshot {
                        std::fs::remove_file(entry.path()).map_err(io_err(&entry.path()))?;
                    }
                }
            }
        }
    }
    let snaps = dir.join("snapshots");
    std::fs::create_dir_all(&snaps).map_err(io_err(&snaps))?;
    Ok(())
}

/// The times at which the run samples its state: `0, every, 2·every, …` below `t_end`, then `t_end`,
/// merged with the snapshot times (an interior grid time within `1e-9·every` of a snapshot time is replaced by it;
/// 0 and `t_end` are always sampled).
#[derive(Debug, Clone)]
pub struct Schedule {
    every: f64,
    t_end: f64,
    n_grid: u64,
    next_grid: u64,
    end_done: bool,
    snapshots: Vec<f64>,
    next_snapshot: usize,
    tol: f64,
}

/// One sampling time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Time (s).
    pub t: f64,
    /// Index `k` of the snapshot to write (`snapshots/<k>.csv`), if this is a snapshot time.
    pub snapshot: Option<usize>,
}

impl Schedule {
    /// `every > 0`, `t_end > 0`, snapshot times sorted within `[0, t_end]` (as validated by the scene).
    pub fn new(t_end: f64, every: f64, snapshots: &[f64]) -> Self {
        let tol = 1e-9 * every;
        // Number of grid points i·every (i ≥ 0) strictly below t_end − tol.
        let limit = t_end - tol;
        let mut n = (limit / every).ceil().max(0.0) as u64;
        while n > 0 && (n - 1) as f64 * every >= limit {
            n -= 1;
        }
        while (n as f64) * every < limit {
            n += 1;
        }
        Schedule {
            every,
            t_end,
            n_grid: n,
            next_grid: 0,
            end_done: false,
            snapshots: snapshots.to_vec(),
            next_snapshot: 0,
            tol,
        }
    }

    fn peek_grid(&self) -> Option<f64> {
        if self.next_grid < self.n_grid {
            Some(self.next_grid as f64 * self.every)
        } else if !self.end_done {
            Some(self.t_end)
        } else {
            None
        }
    }

    fn pop_grid(&mut self) {
        if self.next_grid < self.n_grid {
            self.next_grid += 1;
        } else {
            self.end_done = true;
        }
    }
}

impl Iterator for Schedule {
    type Item = Sample;

    fn next(&mut self) -> Option<Sample> {
        let grid = self.peek_grid();
        let snap = self.snapshots.get(self.next_snapshot).copied();
        match (grid, snap) {
            (None, None) => None,
            (Some(g), None) => {
                self.pop_grid();
                Some(Sample { t: g, snapshot: None })
            }
            (None, Some(s)) => {
                let k = self.next_snapshot;
                self.next_snapshot += 1;
                Some(Sample {
                    t: s,
                    snapshot: Some(k),
                })
            }
            (Some(g), Some(s)) => {
                // Interior grid times within tol of a snapshot time are replaced by it; 0 and t_end
                // are always sampled exactly.
                let interior = g != 0.0 && g != self.t_end;
                if g == s || (interior && (g - s).abs() <= self.tol) {
                    self.pop_grid();
                    let k = self.next_snapshot;
                    self.next_snapshot += 1;
                    Some(Sample {
                        t: s,
                        snapshot: Some(k),
                    })
                } else if g < s {
                    self.pop_grid();
                    Some(Sample { t: g, snapshot: None })
                } else {
                    let k = self.next_snapshot;
                    self.next_snapshot += 1;
                    Some(Sample {
                        t: s,
                        snapshot: Some(k),
                    })
                }
            }
        }
    }
}

/// Running maxima of the conservation errors (absolute; made relative at the end).
#[derive(Debug, Clone)]
struct ErrorTracker {
    h0: f64,
    dissipated0: f64,
    p0: crate::math::Vec3,
    l0: crate::math::Vec3,
    scales0: [f64; 3],
    scales_max: [f64; 3],
    energy: f64,
    momentum: f64,
    angular: f64,
    quaternion: f64,
    samples: u64,
}

impl ErrorTracker {
    fn new(d0: &Diagnostics) -> Self {
        let s = [d0.energy_scale, d0.momentum_scale, d0.angular_momentum_scale];
        ErrorTracker {
            h0: d0.energy(),
            dissipated0: d0.dissipated,
            p0: d0.momentum,
            l0: d0.angular_momentum,
            scales0: s,
            scales_max: s,
            energy: 0.0,
            momentum: 0.0,
            angular: 0.0,
            quaternion: 0.0,
            samples: 0,
        }
    }

    /// The tracker as stored in a checkpoint.
    fn to_state(&self) -> ErrorState {
        ErrorState {
            h0: self.h0,
            dissipated0: self.dissipated0,
            p0: [self.p0.x, self.p0.y, self.p0.z],
            l0: [self.l0.x, self.l0.y, self.l0.z],
            scales0: self.scales0,
            scales_max: self.scales_max,
            energy: self.energy,
            momentum: self.momentum,
            angular: self.angular,
            quaternion: self.quaternion,
            samples: self.samples,
        }
    }

    /// The tracker stored in a checkpoint.
    fn from_state(s: &ErrorState) -> Self {
        ErrorTracker {
            h0: s.h0,
            dissipated0: s.dissipated0,
            p0: crate::math::Vec3::new(s.p0[0], s.p0[1], s.p0[2]),
            l0: crate::math::Vec3::new(s.l0[0], s.l0[1], s.l0[2]),
            scales0: s.scales0,
            scales_max: s.scales_max,
            energy: s.energy,
            momentum: s.momentum,
            angular: s.angular,
            quaternion: s.quaternion,
            samples: s.samples,
        }
    }

    /// Absolute signed energy residual `H − H0 − (dissipated − dissipated0)`.
    fn energy_residual(&self, d: &Diagnostics) -> f64 {
        d.energy() - self.h0 - (d.dissipated - self.dissipated0)
    }

    /// The energy scale used for the time series (energy_scale(0), or 1 J if that is 0).
    fn energy_scale_for_rows(&self) -> f64 {
        if self.scales0[0] > 0.0 && self.scales0[0].is_finite() {
            self.scales0[0]
        } else {
            1.0
        }
    }

    fn update(&mut self, d: &Diagnostics) {
        self.energy = self.energy.max(self.energy_residual(d).abs());
        self.momentum = self.momentum.max((d.momentum - self.p0).norm());
        self.angular = self.angular.max((d.angular_momentum - self.l0).norm());
        self.quaternion = self.quaternion.max(d.quaternion_norm_error);
        for (m, s) in self
            .scales_max
            .iter_mut()
            .zip([d.energy_scale, d.momentum_scale, d.angular_momentum_scale])
        {
            if s.is_finite() {
                *m = m.max(s);
            }
        }
        self.samples += 1;
    }

    /// `(scale, definition)` for each quantity: the value at t = 0, or, if that is zero, the
    /// largest value over the run (or 1 if that is zero too).
    fn scales(&self) -> Scales {
        let pick = |k: usize, def0: &str, unit: &str| -> (f64, String) {
            let s0 = self.scales0[k];
            if s0 > 0.0 && s0.is_finite() {
                (s0, format!("{def0} at t = 0 ({unit})"))
            } else if self.scales_max[k] > 0.0 {
                (
                    self.scales_max[k],
                    format!("{def0}: largest value over the sampled times, since it is 0 at t = 0 ({unit})"),
                )
            } else {
                (1.0, format!("1 {unit}: {def0} is 0 throughout, so errors are absolute"))
            }
        };
        let (energy, energy_definition) = pick(0, "K_T + K_R + |U_C| + |U_G|", "J");
        let (momentum, momentum_definition) = pick(1, "sum over bodies of m |v|", "kg m/s");
        let (angular_momentum, angular_momentum_definition) =
            pick(2, "sum over bodies of |r x m v| + |I w| (about the origin)", "kg m^2/s");
        Scales {
            energy,
            energy_definition,
            momentum,
            momentum_definition,
            angular_momentum,
            angular_momentum_definition,
        }
    }
}

fn diagnostics_finite(d: &Diagnostics) -> bool {
    [
        d.kinetic_translational,
        d.kinetic_rotational,
        d.potential_contact,
        d.potential_gravity,
        d.dissipated,
        d.momentum_scale,
        d.angular_momentum_scale,
        d.energy_scale,
        d.quaternion_norm_error,
    ]
    .iter()
    .all(|x| x.is_finite())
        && d.momentum.iter().all(|x| x.is_finite())
        && d.angular_momentum.iter().all(|x| x.is_finite())
}

/// What went wrong with a sampled state, if anything.
fn check_state(t: f64, d: &Diagnostics) -> Option<String> {
    if !diagnostics_finite(d) {
        return Some(format!(
            "non-finite diagnostics at t = {t} s (energy {}, |P| {}, |L| {})",
            d.energy(),
            d.momentum.norm(),
            d.angular_momentum.norm()
        ));
    }
    if d.quaternion_norm_error > QUATERNION_NORM_LIMIT {
        return Some(format!(
            "quaternion norm constraint broken at t = {t} s: max||q|-1| = {:.3e} > {QUATERNION_NORM_LIMIT:e}",
            d.quaternion_norm_error
        ));
    }
    None
}

/// A progress bar on stderr for a run from `t` to `t_end` (s), when `enabled` and stderr is a terminal; shared by
/// the ellipsoid, soft- and hard-sphere drivers.
pub(crate) fn progress_bar(enabled: bool, t_end: f64, t: f64) -> Option<indicatif::ProgressBar> {
    if !enabled || !std::io::stderr().is_terminal() {
        return None;
    }
    let pb = indicatif::ProgressBar::with_draw_target(Some(1_000_000), indicatif::ProgressDrawTarget::stderr());
    let style = indicatif::ProgressStyle::with_template("{spinner} [{elapsed_precise}] {wide_bar} {msg} ETA {eta}")
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
    pb.set_style(style);
    pb.set_position((t / t_end * 1e6) as u64);
    pb.reset_eta();
    pb.set_message(format!("t = {t}/{t_end} s"));
    pb.enable_steady_tick(Duration::from_millis(250));
    Some(pb)
}

/// Moves `pb` to simulated time `t` of `t_end` (s).
pub(crate) fn show_progress(pb: &indicatif::ProgressBar, t: f64, t_end: f64) {
    pb.set_position((t / t_end * 1e6) as u64);
    pb.set_message(format!("t = {t:.4}/{t_end} s"));
}

/// Fingerprint of a scene's initial bodies: FNV-1a of their lossless snapshot rows.
fn bodies_hash(scene: &LoadedScene) -> String {
    let mut text = String::new();
    for row in snapshot_records(0.0, &scene.bodies) {
        text.push_str(&row.join(","));
        text.push('\n');
    }
    fnv1a_hex(text.as_bytes())
}

/// `timeseries.csv`, new or continued after a checkpoint.
type Rows = TimeseriesWriter; // new, or reopened by TimeseriesAppender::open_truncated

/// Where [`drive`] starts: t = 0, or a checkpoint.
struct Start {
    t: f64,
    y: Vec<f64>,
    tracker: ErrorTracker,
    next_sample: u64,
    rows: u64,
    wall_before: f64,
    checkpoints: u64,
    timeseries: Rows,
    /// `tracks.csv`, when the scene tracks bodies.
    tracks: Option<TracksWriter>,
    barrier: BarrierMonitor,
}

/// What every checkpoint of a run repeats.
struct RunIdentity {
    scene_base_dir: Option<PathBuf>,
    scene_hash: String,
    bodies_hash: String,
}

/// Runs `scene`, writing the outputs into `out_dir` (see the module docs).
///
/// Refuses an existing non-empty `out_dir` unless `options.force`. On an integrator error, a
/// non-finite diagnostic or a broken quaternion constraint (`||q| − 1| > 1e-3`), writes
/// `last_good_state.csv` and `summary.json` (its `status` names the cause) and returns
/// [`RunError::Failed`]. Contact-barrier overruns do not stop the run: they are logged to
/// `barrier_overruns.csv` and listed in the summary ([`RunSummary::warnings`]). Writes checkpoints as
/// [`RunOptions`] asks (see the module docs). Prints nothing but the progress bar; see [`RunSummary::one_line`].
pub fn run_scene(scene: &LoadedScene, out_dir: &Path, options: &RunOptions) -> Result<RunSummary, RunError> {
    prepare_output_dir(out_dir, options.force)?;
    let scene_copy = out_dir.join("scene.toml");
    std::fs::write(&scene_copy, &scene.source).map_err(io_err(&scene_copy))?;
    let scene_base_dir = match &scene.base_dir {
        Some(d) => Some(
            std::fs::canonicalize(d)
                .or_else(|_| std::path::absolute(d))
                .map_err(io_err(d))?,
        ),
        None => None,
    };
    let identity = RunIdentity {
        scene_base_dir,
        scene_hash: fnv1a_hex(scene.source.as_bytes()),
        bodies_hash: bodies_hash(scene),
    };

    let system = EllipsoidSystem::new(&scene.bodies, scene.model, scene.physics);
    let settings = scene.integrator;
    let integrator = make_integrator(
        settings.method,
        Tolerances::uniform(settings.rtol, settings.atol, system.dim()),
        settings.step,
    )
    .map_err(RunError::Setup)?;

    let ts_path = out_dir.join("timeseries.csv");
    let timeseries = TimeseriesWriter::create(&ts_path).map_err(io_err(&ts_path))?;
    let tracks = if scene.output.track.is_empty() {
        None
    } else {
        let path = out_dir.join("tracks.csv");
        Some(TracksWriter::create(&path).map_err(io_err(&path))?)
    };
    let y = system.initial_state();
    let tracker = ErrorTracker::new(&system.diagnostics(&y));
    let barrier = BarrierMonitor::new(
        BarrierSettings::for_kappa_source(&scene.kappa_source),
        scene.physics.contact.is_some(),
        Some(&out_dir.join(OVERRUN_FILE)),
    );
    let start = Start {
        t: 0.0,
        y,
        tracker,
        next_sample: 0,
        rows: 0,
        wall_before: 0.0,
        checkpoints: 0,
        timeseries,
        tracks,
        barrier,
    };
    drive(scene, out_dir, options, &system, integrator, start, &identity)
}

/// The final time of a completed run in `dir` (from its `summary.json`), if it completed.
fn completed_run(dir: &Path) -> Option<f64> {
    let text = std::fs::read_to_string(dir.join("summary.json")).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    (v.get("status")?.as_str()? == "completed")
        .then(|| v.get("final_time").and_then(|t| t.as_f64()).unwrap_or(f64::NAN))
}

/// Continues the run in `dir` from its `checkpoint.json` (see the module docs), as if it had never
/// stopped: same snapshots, time-series rows (after truncating those written after the checkpoint)
/// and summary. `options.force` is ignored; the checkpoint options apply to the continued run.
///
/// Errors: [`RunError::AlreadyCompleted`] when `dir/summary.json` says the run completed,
/// [`RunError::NoCheckpoint`] without a checkpoint, [`RunError::BadCheckpoint`] when the checkpoint
/// is corrupt or does not match the directory (scene copy, bodies file, time series); otherwise as
/// [`run_scene`].
pub fn resume_run(dir: &Path, options: &RunOptions) -> Result<RunSummary, RunError> {
    if let Some(t) = completed_run(dir) {
        return Err(RunError::AlreadyCompleted {
            dir: dir.to_path_buf(),
            t,
        });
    }
    let ckpt = read_checkpoint(dir).map_err(|e| match e {
        CheckpointError::Missing(_) => RunError::NoCheckpoint { dir: dir.to_path_buf() },
        other => RunError::BadCheckpoint(other.to_string()),
    })?;
    let bad = |msg: String| RunError::BadCheckpoint(msg);
    let scene_path = dir.join("scene.toml");
    let text = std::fs::read_to_string(&scene_path).map_err(|e| bad(format!("{}: {e}", scene_path.display())))?;
    if fnv1a_hex(text.as_bytes()) != ckpt.scene_hash {
        return Err(bad(format!(
            "{} changed since the checkpoint was written",
            scene_path.display()
        )));
    }
    let scene = parse_scene(&text, &scene_path.display().to_string(), ckpt.scene_base_dir.as_deref())
        .map_err(|e| bad(e.to_string()))?;
    let identity = RunIdentity {
        scene_base_dir: ckpt.scene_base_dir.clone(),
        scene_hash: ckpt.scene_hash.clone(),
        bodies_hash: bodies_hash(&scene),
    };
    if identity.bodies_hash != ckpt.bodies_hash || scene.bodies.len() != ckpt.n_bodies {
        let from = match (&scene.file.scene.bodies_file, &ckpt.scene_base_dir) {
            (Some(f), Some(base)) => format!(" (bodies_file {})", base.join(f).display()),
            (Some(f), None) => format!(" (bodies_file {f})"),
            _ => String::new(),
        };
        return Err(bad(format!(
            "the scene's bodies{from} differ from those the run started with"
        )));
    }

    let system = EllipsoidSystem::new(&scene.bodies, scene.model, scene.physics);
    if ckpt.y.len() != system.dim() {
        return Err(bad(format!(
            "the checkpoint's state has {} components, the scene's system {}",
            ckpt.y.len(),
            system.dim()
        )));
    }
    let settings = scene.integrator;
    if ckpt.integrator.method() != settings.method {
        return Err(bad(format!(
            "the checkpoint is of a {} run, the scene asks for {}",
            ckpt.integrator.method(),
            settings.method
        )));
    }
    let mut integrator = make_integrator(
        settings.method,
        Tolerances::uniform(settings.rtol, settings.atol, system.dim()),
        settings.step,
    )
    .map_err(RunError::Setup)?;
    integrator
        .restore_state(&ckpt.integrator)
        .map_err(|e| bad(format!("integrator: {e}")))?;

    // The checkpoint must sit right after one of the run's samples.
    let d = &ckpt.driver;
    let schedule = Schedule::new(scene.t_end, scene.output.every, &scene.output.times);
    let total = schedule.clone().count() as u64;
    let prev = d
        .next_sample
        .checked_sub(1)
        .and_then(|i| schedule.clone().nth(i as usize));
    if d.next_sample > total || prev.is_none_or(|p| p.t.to_bits() != ckpt.t.to_bits()) {
        return Err(bad(format!(
            "the checkpoint (t = {} s, next sample {}) does not match the scene's output samples",
            ckpt.t, d.next_sample
        )));
    }
    if d.timeseries_rows != d.next_sample {
        return Err(bad(format!(
            "the checkpoint counts {} time-series rows for {} samples",
            d.timeseries_rows, d.next_sample
        )));
    }

    // Stale files of the interrupted process (a failure summary, a half-written checkpoint).
    for name in ["summary.json", "last_good_state.csv", CHECKPOINT_TMP_FILE] {
        let p = dir.join(name);
        if p.is_file() {
            std::fs::remove_file(&p).map_err(io_err(&p))?;
        }
    }
    let snaps = dir.join("snapshots");
    std::fs::create_dir_all(&snaps).map_err(io_err(&snaps))?;
    let ts_path = dir.join("timeseries.csv");
    let timeseries =
        TimeseriesAppender::open_truncated(&ts_path, d.timeseries_rows, d.timeseries_bytes).map_err(bad)?;
    // Each sample wrote one row per tracked body; the checkpoint sits right after sample `next_sample − 1`.
    let tracks = if scene.output.track.is_empty() {
        None
    } else {
        let rows = d.next_sample * scene.output.track.len() as u64;
        Some(TracksWriter::open_truncated(&dir.join("tracks.csv"), rows).map_err(bad)?)
    };

    let barrier_log = dir.join(OVERRUN_FILE);
    let barrier = BarrierMonitor::resume(
        BarrierSettings::for_kappa_source(&scene.kappa_source),
        scene.physics.contact.is_some(),
        &barrier_log,
        ckpt.t,
    )
    .map_err(|e| bad(format!("{}: {e}", barrier_log.display())))?;
    let start = Start {
        t: ckpt.t,
        y: ckpt.y.clone(),
        tracker: ErrorTracker::from_state(&d.errors),
        next_sample: d.next_sample,
        rows: d.timeseries_rows,
        wall_before: d.wall_seconds,
        checkpoints: d.checkpoints,
        timeseries,
        tracks,
        barrier,
    };
    drive(&scene, dir, options, &system, integrator, start, &identity)
}

/// The sampling loop shared by [`run_scene`] and [`resume_run`].
fn drive(
    scene: &LoadedScene,
    out_dir: &Path,
    options: &RunOptions,
    system: &EllipsoidSystem,
    mut integrator: Box<dyn Integrator + Send>,
    start: Start,
    identity: &RunIdentity,
) -> Result<RunSummary, RunError> {
    let Start {
        mut t,
        mut y,
        mut tracker,
        next_sample,
        mut rows,
        wall_before,
        mut checkpoints,
        mut timeseries,
        mut tracks,
        mut barrier,
    } = start;
    let tracks_path = out_dir.join("tracks.csv");
    let settings = scene.integrator;
    let ts_path = out_dir.join("timeseries.csv");
    let barrier_path = out_dir.join(OVERRUN_FILE);
    let snapshot_path = |k: usize| out_dir.join("snapshots").join(format!("{k}.csv"));

    let started = Instant::now();
    let wall = || wall_before + started.elapsed().as_secs_f64();
    let mut last_good = (t, y.clone());
    let pb = progress_bar(options.progress, scene.t_end, t);

    let summary_of = |status: String,
                      final_time: f64,
                      tracker: &ErrorTracker,
                      barrier: &BarrierMonitor,
                      stats: crate::integrate::Stats| {
        let scales = tracker.scales();
        RunSummary {
            status,
            wall_seconds: wall(),
            final_time,
            t_end: scene.t_end,
            steps_accepted: stats.steps_accepted,
            steps_rejected: stats.steps_rejected,
            rhs_evaluations: stats.rhs_evaluations,
            smallest_step: stats.smallest_step.is_finite().then_some(stats.smallest_step),
            energy_error: tracker.energy / scales.energy,
            linear_momentum_error: tracker.momentum / scales.momentum,
            angular_momentum_error: tracker.angular / scales.angular_momentum,
            quaternion_norm_error: tracker.quaternion,
            scales,
            samples: tracker.samples,
            kappa: scene.model.kappa,
            kappa_source: match scene.kappa_source {
                KappaSource::Given => "given".into(),
                KappaSource::Calibrated { .. } => "calibrated".into(),
            },
            calibration: match scene.kappa_source {
                KappaSource::Given => None,
                KappaSource::Calibrated { beta, v } => Some(CalibrationSummary { beta, v }),
            },
            inertia: match scene.model.inertia {
                crate::ellipsoid::body::InertiaModel::Gaussian => "gaussian".into(),
                crate::ellipsoid::body::InertiaModel::Uniform => "uniform".into(),
            },
            integrator: settings.method.to_string(),
            rtol: settings.rtol,
            atol: settings.atol,
            step: settings.step,
            n_bodies: system.n_bodies(),
            rotation_integrated: system.rotation_integrated(),
            physics: PhysicsSummary::from(&scene.physics),
            seed: scene.seed,
            barrier: barrier.report(),
        }
    };

    // On failure: last good state + summary, then the error.
    let fail = |cause: String,
                t_good: f64,
                y_good: &[f64],
                tracker: &ErrorTracker,
                barrier: &BarrierMonitor,
                stats: crate::integrate::Stats|
     -> RunError {
        if let Some(pb) = &pb {
            pb.abandon();
        }
        let cause = match barrier.failure_hint() {
            Some(hint) => format!("{cause}; {hint}"),
            None => cause,
        };
        let lgs = out_dir.join("last_good_state.csv");
        if let Err(e) = write_snapshot(&lgs, t_good, &system.bodies_at(t_good, y_good)) {
            return RunError::Io { path: lgs, source: e };
        }
        let summary = summary_of(cause.clone(), t_good, tracker, barrier, stats);
        let sp = out_dir.join("summary.json");
        if let Err(e) = write_summary(&sp, &summary) {
            return RunError::Io { path: sp, source: e };
        }
        RunError::Failed {
            t: t_good,
            cause,
            last_good_state: lgs,
            summary: Box::new(summary),
        }
    };

    let schedule = Schedule::new(scene.t_end, scene.output.every, &scene.output.times);
    let total = schedule.clone().count() as u64;
    let mut last_checkpoint_wall = Instant::now();
    let mut last_checkpoint_t = t;
    let mut checkpoints_here: u64 = 0;
    for (index, sample) in (0u64..).zip(schedule).skip(next_sample as usize) {
        if sample.t > t
            && let Err(e) = integrator.advance(system, &mut t, &mut y, sample.t)
        {
            let cause = format!("integrator error: {e}");
            return Err(fail(cause, t, &y, &tracker, &barrier, integrator.stats()));
        }
        let d = system.diagnostics(&y);
        if let Some(cause) = check_state(t, &d) {
            let (tg, yg) = &last_good;
            return Err(fail(cause, *tg, yg, &tracker, &barrier, integrator.stats()));
        }
        tracker.update(&d);
        barrier.observe(t, system, &y).map_err(io_err(&barrier_path))?;
        let row = TimeseriesRow {
            t,
            diagnostics: d,
            energy_residual: tracker.energy_residual(&d) / tracker.energy_scale_for_rows(),
            wall_seconds: wall(),
        };
        timeseries.write_row(&row).map_err(io_err(&ts_path))?;
        rows += 1;
        if sample.snapshot.is_some() || tracks.is_some() {
            let bodies = system.bodies_at(t, &y);
            if let Some(k) = sample.snapshot {
                let p = snapshot_path(k);
                write_snapshot(&p, t, &bodies).map_err(io_err(&p))?;
            }
            if let Some(w) = tracks.as_mut() {
                w.write_sample(t, &bodies, &scene.output.track)
                    .map_err(io_err(&tracks_path))?;
            }
        }
        last_good.0 = t;
        last_good.1.copy_from_slice(&y);
        if let Some(pb) = &pb {
            show_progress(pb, t, scene.t_end);
        }

        let due_wall = options
            .checkpoint_every
            .is_some_and(|s| s > 0.0 && last_checkpoint_wall.elapsed().as_secs_f64() >= s);
        let due_sim = options
            .checkpoint_every_sim
            .is_some_and(|s| t - last_checkpoint_t >= s.max(0.0));
        if index + 1 < total && (due_wall || due_sim) {
            // The rows the checkpoint counts must be on disk before it is.
            std::fs::OpenOptions::new()
                .write(true)
                .open(&ts_path)
                .and_then(|f| f.sync_all())
                .map_err(io_err(&ts_path))?;
            let timeseries_bytes = std::fs::metadata(&ts_path).map_err(io_err(&ts_path))?.len();
            checkpoints += 1;
            let wall_seconds = wall();
            let ckpt = Checkpoint {
                format: CHECKPOINT_FORMAT.into(),
                version: CHECKPOINT_VERSION,
                writer: format!("rubblepile {}", env!("CARGO_PKG_VERSION")),
                scene_base_dir: identity.scene_base_dir.clone(),
                scene_hash: identity.scene_hash.clone(),
                bodies_hash: identity.bodies_hash.clone(),
                n_bodies: system.n_bodies(),
                t,
                t_seconds: t,
                y: y.clone(),
                integrator: integrator.save_state(),
                driver: DriverState {
                    next_sample: index + 1,
                    timeseries_rows: rows,
                    timeseries_bytes,
                    wall_seconds,
                    wall_seconds_approx: wall_seconds,
                    checkpoints,
                    errors: tracker.to_state(),
                },
            };
            let cp = out_dir.join(CHECKPOINT_FILE);
            write_checkpoint(out_dir, &ckpt).map_err(io_err(&cp))?;
            last_checkpoint_wall = Instant::now();
            last_checkpoint_t = t;
            checkpoints_here += 1;
            if options.stop_after_checkpoints.is_some_and(|n| checkpoints_here >= n) {
                if let Some(pb) = &pb {
                    pb.abandon();
                }
                return Err(RunError::Stopped {
                    dir: out_dir.to_path_buf(),
                    t,
                    checkpoints,
                });
            }
        }
    }
    timeseries.finish().map_err(io_err(&ts_path))?;
    if let Some(pb) = &pb {
        pb.finish_and_clear();
    }
    let summary = summary_of("completed".into(), t, &tracker, &barrier, integrator.stats());
    let sp = out_dir.join("summary.json");
    write_summary(&sp, &summary).map_err(io_err(&sp))?;
    Ok(summary)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn times(s: Schedule) -> Vec<(f64, Option<usize>)> {
        s.map(|x| (x.t, x.snapshot)).collect()
    }

    #[test]
    fn schedule_merges_and_ends_at_t_end() {
        let s = times(Schedule::new(3.0, 1.0, &[0.0, 1.5, 3.0]));
        assert_eq!(
            s,
            vec![(0.0, Some(0)), (1.0, None), (1.5, Some(1)), (2.0, None), (3.0, Some(2))]
        );
        let s = times(Schedule::new(2.5, 1.0, &[]));
        assert_eq!(s, vec![(0.0, None), (1.0, None), (2.0, None), (2.5, None)]);
        // 0.1 steps: 3·0.1 ≠ 0.3 in floating point, but they merge.
        let s = times(Schedule::new(0.3, 0.1, &[0.3]));
        assert_eq!(s.len(), 4);
        assert_eq!(s[3], (0.3, Some(0)));
        let s = times(Schedule::new(1.0, 5.0, &[0.5]));
        assert_eq!(s, vec![(0.0, None), (0.5, Some(0)), (1.0, None)]);
        // Snapshot times next to 0 and t_end do not replace them.
        let s = times(Schedule::new(2.0, 1.0, &[1e-12, 2.0 - 1e-12]));
        assert_eq!(
            s,
            vec![
                (0.0, None),
                (1e-12, Some(0)),
                (1.0, None),
                (2.0 - 1e-12, Some(1)),
                (2.0, None)
            ]
        );
    }

    #[test]
    fn schedule_is_strictly_increasing() {
        for (t_end, every) in [(200.0, 1.0), (1.0, 0.1), (7.3, 0.7), (1e3, 0.001)] {
            let v: Vec<f64> = Schedule::new(t_end, every, &[0.0, t_end / 3.0, t_end])
                .map(|s| s.t)
                .collect();
            assert!(v.windows(2).all(|w| w[1] > w[0]), "{t_end} {every}");
            assert_eq!(*v.last().unwrap(), t_end);
            assert_eq!(v[0], 0.0);
        }
    }
}
