//! The hard-sphere run driver, with the crate's output contract (see [`crate::run`]): `scene.toml` (copy),
//! `timeseries.csv` (flushed row by row), `snapshots/<k>.csv` (in the particles-file columns), `summary.json`
//! (status, wall_seconds, energy error, collision count, events per second, max overlap, absorbed count) and, on
//! failure, `last_good_state.csv` with the cause in the summary. A previous run's output is never overwritten
//! without `force`.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::Serialize;

use super::scene::{HardScene, PARTICLE_COLUMNS};
use super::stepper::{Diagnostics, System};
use crate::io::fmt_f64;
use crate::run::{RunError, Schedule, prepare_output_dir};

/// Columns of `timeseries.csv`.
pub const TIMESERIES_COLUMNS: [&str; 22] = [
    "t",
    "kinetic",
    "rotational",
    "potential",
    "energy",
    "energy_change",
    "energy_residual",
    "px",
    "py",
    "pz",
    "lx",
    "ly",
    "lz",
    "collisions",
    "pair_collisions",
    "wall_collisions",
    "events_per_second",
    "max_overlap",
    "free",
    "stuck",
    "absorbed",
    "wall_seconds",
];

/// `summary.json` of a hard-sphere run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HardRunSummary {
    /// `"completed"` or the failure's cause.
    pub status: String,
    /// Scene kind (`"hard-spheres"`).
    pub kind: String,
    /// Scene name.
    pub scene: String,
    /// Seed.
    pub seed: u64,
    /// Requested end time (s).
    pub t_end: f64,
    /// Time reached (s).
    pub t_reached: f64,
    /// Steps taken.
    pub steps: u64,
    /// Particles at t = 0.
    pub particles: usize,
    /// Wall-clock seconds of the run.
    pub wall_seconds: f64,
    /// Total energy at t = 0 (J; kinetic + rotational + uniform-field potential of the free particles).
    pub energy_initial: f64,
    /// Total energy at the end (J).
    pub energy_final: f64,
    /// Largest |E − E0| / scale over the samples (scale = max(|E0|, kinetic at t = 0)).
    pub energy_error: f64,
    /// Largest |E − E0 − exchanged| / scale: the integration error once the energy changed by inelastic
    /// collisions, moving walls, sticking and absorption is accounted for.
    pub energy_residual: f64,
    /// Energy exchanged in collisions, sticking and absorption (J).
    pub energy_exchanged: f64,
    /// Largest |P − P0| (kg m/s).
    pub momentum_error: f64,
    /// Collisions applied (pairs + walls).
    pub collisions: u64,
    /// Particle–particle collisions.
    pub pair_collisions: u64,
    /// Particle–wall collisions.
    pub wall_collisions: u64,
    /// Events processed.
    pub events: u64,
    /// Events per wall-clock second.
    pub events_per_second: f64,
    /// Collisions made elastic by the collapse guard.
    pub guarded_collisions: u64,
    /// Neighbour-list builds.
    pub neighbour_rebuilds: u64,
    /// Largest overlap at a collision, relative to the smaller radius.
    pub max_overlap: f64,
    /// Particles absorbed.
    pub absorbed: u64,
    /// Particles stuck to walls at the end.
    pub stuck: usize,
}

/// Why a hard-sphere run did not complete.
#[derive(Debug, thiserror::Error)]
pub enum HardRunError {
    /// Output directory problems (exists, not a directory, I/O).
    #[error(transparent)]
    Output(#[from] RunError),
    /// The run failed; the summary and `last_good_state.csv` were written.
    #[error("run failed: {cause}; last good state (t = {t} s) in {}", .last_good_state.display())]
    Failed {
        /// Last good time (s).
        t: f64,
        /// The cause.
        cause: String,
        /// The state file.
        last_good_state: PathBuf,
        /// The summary written.
        summary: Box<HardRunSummary>,
    },
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> HardRunError + '_ {
    move |source| {
        HardRunError::Output(RunError::Io {
            path: path.to_path_buf(),
            source,
        })
    }
}

/// Writes the alive particles in the particles-file columns.
pub fn write_particles(path: &Path, t: f64, system: &System) -> std::io::Result<()> {
    let mut w = BufWriter::new(File::create(path)?);
    writeln!(w, "{}", PARTICLE_COLUMNS.join(","))?;
    for p in system.particles.iter().filter(|p| p.alive) {
        let v = [
            p.mass,
            p.radius,
            p.position.x,
            p.position.y,
            p.position.z,
            p.velocity.x,
            p.velocity.y,
            p.velocity.z,
            p.spin.x,
            p.spin.y,
            p.spin.z,
        ];
        let cols: Vec<String> = v.iter().map(|&x| fmt_f64(x)).collect();
        writeln!(w, "{},{},{}", fmt_f64(t), p.id, cols.join(","))?;
    }
    w.flush()
}

/// Runs a hard-sphere scene into `out`.
pub fn run_hard_scene(scene: &HardScene, out: &Path, force: bool) -> Result<HardRunSummary, HardRunError> {
    prepare_output_dir(out, force)?;
    let scene_copy = out.join("scene.toml");
    std::fs::write(&scene_copy, &scene.source).map_err(io(&scene_copy))?;
    let ts_path = out.join("timeseries.csv");
    let mut ts = BufWriter::new(File::create(&ts_path).map_err(io(&ts_path))?);
    writeln!(ts, "{}", TIMESERIES_COLUMNS.join(",")).map_err(io(&ts_path))?;
    ts.flush().map_err(io(&ts_path))?;

    let start = Instant::now();
    let mut system = System::new(scene.particles.clone(), scene.walls.clone(), scene.settings);
    let d0 = system.diagnostics();
    let scale = d0.energy().abs().max(d0.kinetic + d0.rotational).max(f64::MIN_POSITIVE);
    let mut summary = HardRunSummary {
        status: "running".into(),
        kind: super::scene::KIND.into(),
        scene: scene.name.clone(),
        seed: scene.seed,
        t_end: scene.t_end,
        t_reached: 0.0,
        steps: 0,
        particles: scene.particles.len(),
        wall_seconds: 0.0,
        energy_initial: d0.energy(),
        energy_final: d0.energy(),
        energy_error: 0.0,
        energy_residual: 0.0,
        energy_exchanged: 0.0,
        momentum_error: 0.0,
        collisions: 0,
        pair_collisions: 0,
        wall_collisions: 0,
        events: 0,
        events_per_second: 0.0,
        guarded_collisions: 0,
        neighbour_rebuilds: 0,
        max_overlap: 0.0,
        absorbed: 0,
        stuck: 0,
    };
    let (mut last_coll, mut last_pair, mut last_wall, mut last_events) = (0u64, 0u64, 0u64, 0u64);
    let mut last_wall_clock = 0.0;
    let mut failure: Option<(String, System)> = None;
    for sample in Schedule::new(scene.t_end, scene.every, &scene.times) {
        let good = system.clone();
        let mut failed = None;
        while system.t < sample.t {
            let left = sample.t - system.t;
            let h = if left < 1.000001 * scene.dt { left } else { scene.dt };
            if let Err(e) = system.step(h) {
                failed = Some(e.to_string());
                break;
            }
            summary.steps += 1;
            if left == h {
                system.t = sample.t;
            }
        }
        if let Some(cause) = failed {
            failure = Some((cause, good));
            break;
        }
        let d: Diagnostics = system.diagnostics();
        let c = system.counters;
        let e = d.energy();
        summary.energy_error = summary.energy_error.max((e - d0.energy()).abs() / scale);
        summary.energy_residual = summary
            .energy_residual
            .max((e - d0.energy() - c.energy_exchanged).abs() / scale);
        summary.momentum_error = summary.momentum_error.max((d.momentum - d0.momentum).norm());
        let wall = start.elapsed().as_secs_f64();
        let coll = c.pair_collisions + c.wall_collisions;
        let eps = if wall > last_wall_clock {
            (c.events - last_events) as f64 / (wall - last_wall_clock)
        } else {
            0.0
        };
        let row = [
            sample.t,
            d.kinetic,
            d.rotational,
            d.potential,
            e,
            (e - d0.energy()) / scale,
            (e - d0.energy() - c.energy_exchanged) / scale,
            d.momentum.x,
            d.momentum.y,
            d.momentum.z,
            d.angular_momentum.x,
            d.angular_momentum.y,
            d.angular_momentum.z,
            (coll - last_coll) as f64,
            (c.pair_collisions - last_pair) as f64,
            (c.wall_collisions - last_wall) as f64,
            eps,
            c.max_overlap,
            d.free as f64,
            d.stuck as f64,
            c.absorbed as f64,
            wall,
        ];
        let cols: Vec<String> = row.iter().map(|&x| fmt_f64(x)).collect();
        writeln!(ts, "{}", cols.join(",")).map_err(io(&ts_path))?;
        ts.flush().map_err(io(&ts_path))?;
        (last_coll, last_pair, last_wall, last_events, last_wall_clock) =
            (coll, c.pair_collisions, c.wall_collisions, c.events, wall);
        if let Some(k) = sample.snapshot {
            let p = out.join("snapshots").join(format!("{k}.csv"));
            write_particles(&p, sample.t, &system).map_err(io(&p))?;
        }
    }
    let wall = start.elapsed().as_secs_f64();
    let state = match &failure {
        Some((_, good)) => good,
        None => &system,
    };
    let c = system.counters;
    let d = state.diagnostics();
    summary.t_reached = state.t;
    summary.wall_seconds = wall;
    summary.energy_final = d.energy();
    summary.energy_exchanged = c.energy_exchanged;
    summary.collisions = c.pair_collisions + c.wall_collisions;
    summary.pair_collisions = c.pair_collisions;
    summary.wall_collisions = c.wall_collisions;
    summary.events = c.events;
    summary.events_per_second = if wall > 0.0 { c.events as f64 / wall } else { 0.0 };
    summary.guarded_collisions = c.guarded;
    summary.neighbour_rebuilds = c.rebuilds;
    summary.max_overlap = c.max_overlap;
    summary.absorbed = c.absorbed;
    summary.stuck = d.stuck;
    summary.status = match &failure {
        Some((cause, _)) => cause.clone(),
        None => "completed".into(),
    };
    let sp = out.join("summary.json");
    let json = serde_json::to_string_pretty(&summary).map_err(|e| io(&sp)(std::io::Error::other(e)))?;
    std::fs::write(&sp, json + "\n").map_err(io(&sp))?;
    if let Some((cause, good)) = failure {
        let p = out.join("last_good_state.csv");
        write_particles(&p, good.t, &good).map_err(io(&p))?;
        return Err(HardRunError::Failed {
            t: good.t,
            cause,
            last_good_state: p,
            summary: Box::new(summary),
        });
    }
    Ok(summary)
}

impl HardRunSummary {
    /// One line for the terminal.
    pub fn one_line(&self) -> String {
        format!(
            "{}: t = {} s, {} steps, {} collisions ({:.3e} events/s), energy error {:.2e}, max overlap {:.2e}, {} absorbed, {:.2} s",
            self.status,
            self.t_reached,
            self.steps,
            self.collisions,
            self.events_per_second,
            self.energy_error,
            self.max_overlap,
            self.absorbed,
            self.wall_seconds
        )
    }
}

/// `rubblepile run SCENE --out DIR [--force]` for a hard-sphere scene: prints the one-line summary; exit code 2 for
/// bad input or an existing output directory, 1 for a failed run.
pub fn cli_run(path: &Path, out: &Path, force: bool) -> Result<(), crate::cli::CliError> {
    let scene = super::scene::load_hard_scene(path).map_err(crate::cli::CliError::usage)?;
    match run_hard_scene(&scene, out, force) {
        Ok(s) => {
            println!("{}", s.one_line());
            Ok(())
        }
        Err(HardRunError::Output(e)) if e.is_usage() => Err(crate::cli::CliError::usage(e)),
        Err(e) => Err(crate::cli::CliError::failed(e)),
    }
}
