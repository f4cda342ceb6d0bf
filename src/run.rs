//! The run driver: integrates a [`LoadedScene`] from t = 0 to `t_end` and writes the outputs.
//!
//! Files written in the output directory:
//! - `scene.toml`: a copy of the scene text;
//! - `timeseries.csv`: energies, momenta and the energy residual every `output.every` seconds and
//!   at each snapshot time (written and flushed row by row);
//! - `snapshots/<k>.csv`: the bodies at the k-th `output.times` entry;
//! - `summary.json`: counters and conservation errors ([`RunSummary`]);
//! - `last_good_state.csv` (only when a run fails): the last good state, in snapshot format.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use crate::ellipsoid::equations::{Diagnostics, EllipsoidSystem};
use crate::integrate::{IntegrateError, OdeSystem, Tolerances, make_integrator};
use crate::io::csv::{TimeseriesRow, TimeseriesWriter, write_snapshot};
pub use crate::io::summary::RunSummary;
use crate::io::summary::{CalibrationSummary, PhysicsSummary, Scales, write_summary};
use crate::scene::{KappaSource, LoadedScene};

/// Quaternion norm errors above this mean the unit-norm constraint broke; the run stops.
pub const QUATERNION_NORM_LIMIT: f64 = 1e-3;

/// How a run behaves (not what it simulates).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RunOptions {
    /// Write into an existing non-empty output directory (removing a previous run's files first).
    pub force: bool,
    /// Show a progress bar on stderr when stderr is a terminal.
    pub progress: bool,
}

impl Default for RunOptions {
    /// `force: false, progress: true`.
    fn default() -> Self {
        RunOptions {
            force: false,
            progress: true,
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
}

impl RunError {
    /// Whether the error is the caller's (bad arguments) rather than a failed run: the CLI exits
    /// with code 2 for these and 1 otherwise.
    pub fn is_usage(&self) -> bool {
        matches!(self, RunError::OutputExists { .. } | RunError::NotADirectory { .. })
    }
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> RunError + '_ {
    move |source| RunError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Files a run writes at the top of its directory (removed by `force`).
const OUTPUT_FILES: [&str; 4] = ["scene.toml", "summary.json", "timeseries.csv", "last_good_state.csv"];

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

fn progress_bar(enabled: bool, t_end: f64) -> Option<indicatif::ProgressBar> {
    if !enabled || !std::io::stderr().is_terminal() {
        return None;
    }
    let pb = indicatif::ProgressBar::with_draw_target(Some(1_000_000), indicatif::ProgressDrawTarget::stderr());
    let style = indicatif::ProgressStyle::with_template("{spinner} [{elapsed_precise}] {wide_bar} {msg} ETA {eta}")
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
    pb.set_style(style);
    pb.set_message(format!("t = 0/{t_end} s"));
    pb.enable_steady_tick(Duration::from_millis(250));
    Some(pb)
}

/// Runs `scene`, writing the outputs into `out_dir` (see the module docs).
///
/// Refuses an existing non-empty `out_dir` unless `options.force`. On an integrator error, a
/// non-finite diagnostic or a broken quaternion constraint (`||q| − 1| > 1e-3`), writes
/// `last_good_state.csv` and `summary.json` (its `status` names the cause) and returns
/// [`RunError::Failed`]. Prints nothing but the progress bar; see [`RunSummary::one_line`].
pub fn run_scene(scene: &LoadedScene, out_dir: &Path, options: &RunOptions) -> Result<RunSummary, RunError> {
    prepare_output_dir(out_dir, options.force)?;
    let scene_copy = out_dir.join("scene.toml");
    std::fs::write(&scene_copy, &scene.source).map_err(io_err(&scene_copy))?;

    let system = EllipsoidSystem::new(&scene.bodies, scene.model, scene.physics);
    let settings = scene.integrator;
    let mut integrator = make_integrator(
        settings.method,
        Tolerances::uniform(settings.rtol, settings.atol, system.dim()),
        settings.step,
    )
    .map_err(RunError::Setup)?;

    let ts_path = out_dir.join("timeseries.csv");
    let mut timeseries = TimeseriesWriter::create(&ts_path).map_err(io_err(&ts_path))?;
    let snapshot_path = |k: usize| out_dir.join("snapshots").join(format!("{k}.csv"));

    let start = Instant::now();
    let mut t = 0.0;
    let mut y = system.initial_state();
    let d0 = system.diagnostics(&y);
    let mut tracker = ErrorTracker::new(&d0);
    let mut last_good = (t, y.clone());
    let pb = progress_bar(options.progress, scene.t_end);

    let summary_of = |status: String, final_time: f64, tracker: &ErrorTracker, stats: crate::integrate::Stats| {
        let scales = tracker.scales();
        RunSummary {
            status,
            wall_seconds: start.elapsed().as_secs_f64(),
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
        }
    };

    // On failure: last good state + summary, then the error.
    let fail = |cause: String,
                t_good: f64,
                y_good: &[f64],
                tracker: &ErrorTracker,
                stats: crate::integrate::Stats|
     -> RunError {
        if let Some(pb) = &pb {
            pb.abandon();
        }
        let lgs = out_dir.join("last_good_state.csv");
        if let Err(e) = write_snapshot(&lgs, t_good, &system.bodies_at(t_good, y_good)) {
            return RunError::Io { path: lgs, source: e };
        }
        let summary = summary_of(cause.clone(), t_good, tracker, stats);
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

    for sample in Schedule::new(scene.t_end, scene.output.every, &scene.output.times) {
        if sample.t > t
            && let Err(e) = integrator.advance(&system, &mut t, &mut y, sample.t)
        {
            let cause = format!("integrator error: {e}");
            return Err(fail(cause, t, &y, &tracker, integrator.stats()));
        }
        let d = if t == 0.0 { d0 } else { system.diagnostics(&y) };
        if let Some(cause) = check_state(t, &d) {
            let (tg, yg) = &last_good;
            return Err(fail(cause, *tg, yg, &tracker, integrator.stats()));
        }
        tracker.update(&d);
        let row = TimeseriesRow {
            t,
            diagnostics: d,
            energy_residual: tracker.energy_residual(&d) / tracker.energy_scale_for_rows(),
            wall_seconds: start.elapsed().as_secs_f64(),
        };
        timeseries.write_row(&row).map_err(io_err(&ts_path))?;
        if let Some(k) = sample.snapshot {
            let p = snapshot_path(k);
            write_snapshot(&p, t, &system.bodies_at(t, &y)).map_err(io_err(&p))?;
        }
        last_good.0 = t;
        last_good.1.copy_from_slice(&y);
        if let Some(pb) = &pb {
            pb.set_position((t / scene.t_end * 1e6) as u64);
            pb.set_message(format!("t = {t:.4}/{} s", scene.t_end));
        }
    }
    timeseries.finish().map_err(io_err(&ts_path))?;
    if let Some(pb) = &pb {
        pb.finish_and_clear();
    }
    let summary = summary_of("completed".into(), t, &tracker, integrator.stats());
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
