//! The hard-sphere run driver, with the crate's output contract (see [`crate::run`]): `scene.toml` (copy),
//! `timeseries.csv` (flushed row by row), `snapshots/<k>.csv` (in the particles-file columns), `summary.json`
//! (status, wall_seconds, energy error, collision count, events per second, max overlap, absorbed count) and, on
//! failure, `last_good_state.csv` with the cause in the summary. A previous run's output is never overwritten
//! without `force`. Long runs write `checkpoint.json` at output samples (as [`RunOptions`] asks) and continue with
//! [`resume_hard`] (`rubblepile resume DIR`) bit for bit.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::particle::Attachment;
use super::scene::{HardScene, PARTICLE_COLUMNS, STUCK_COLUMN};
use super::stepper::{Counters, Diagnostics, NeighbourState, System};
use crate::io::checkpoint::{CHECKPOINT_FILE, CHECKPOINT_TMP_FILE, exact_f64, exact_f64_vec, fnv1a_hex};
use crate::io::fmt_f64;
use crate::io::resume::{EngineCheckpoint, open_checkpoint, reopen_timeseries};
use crate::math::Vec3;
use crate::run::{RunError, RunOptions, Schedule, prepare_output_dir};
use crate::run::{progress_bar, show_progress};

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
    /// Neighbour-list builds (all particles).
    pub neighbour_rebuilds: u64,
    /// Single particles re-listed in the neighbour list.
    pub neighbour_reanchors: u64,
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
    writeln!(w, "{},{STUCK_COLUMN}", PARTICLE_COLUMNS.join(","))?;
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
        let stuck = p.stuck.map_or(-1, |a| a.wall as i64);
        writeln!(w, "{},{},{},{stuck}", fmt_f64(t), p.id, cols.join(","))?;
    }
    w.flush()
}

/// Everything a hard-sphere run needs to continue bit for bit (`checkpoint.json`, written atomically at an output
/// sample). Every `f64` that influences the continuation is stored as its bit pattern ([`exact_f64`]).
#[derive(Debug, Clone, Serialize, Deserialize)]
struct HardCheckpoint {
    format: String,
    version: u32,
    writer: String,
    /// FNV-1a hash of the run's `scene.toml` copy.
    scene_hash: String,
    /// Directory a relative `scene.particles_file` is resolved against.
    scene_base_dir: PathBuf,
    /// For people reading the file only.
    t_seconds: f64,
    #[serde(with = "exact_f64")]
    t: f64,
    steps: u64,
    next_sample: u64,
    rows: u64,
    timeseries_bytes: u64,
    checkpoints: u64,
    #[serde(with = "exact_f64")]
    wall_seconds: f64,
    /// Per particle ([`PARTICLE_STATE`] numbers): alive, x, v, ω, t_local, stuck wall (−1 free), offset, t_stuck.
    #[serde(with = "exact_f64_vec")]
    state: Vec<f64>,
    /// Neighbour-list anchors (3 per particle) and allowances (1 per particle); empty before the first build.
    #[serde(with = "exact_f64_vec")]
    anchors: Vec<f64>,
    #[serde(with = "exact_f64_vec")]
    allowances: Vec<f64>,
    /// pair, wall, events, guarded, rebuilds, re-anchors, absorbed.
    counts: [u64; 7],
    /// max_overlap, energy_exchanged, then the run's book: E0, scale, energy error, residual, momentum error, P0.
    #[serde(with = "exact_f64_vec")]
    book: Vec<f64>,
    /// Counters at the last time-series row: collisions, pair, wall, events.
    last_counts: [u64; 4],
    #[serde(with = "exact_f64")]
    last_wall_clock: f64,
}

impl EngineCheckpoint for HardCheckpoint {
    fn format(&self) -> &str {
        &self.format
    }
    fn scene_hash(&self) -> &str {
        &self.scene_hash
    }
}

/// The `format` tag of a hard-sphere checkpoint.
pub const HARD_CHECKPOINT_FORMAT: &str = "rubblepile-hsdem-checkpoint";
/// Numbers per particle in a checkpoint.
const PARTICLE_STATE: usize = 16;

/// Bookkeeping of a run (energy and momentum references and the largest errors so far).
#[derive(Debug, Clone, Copy)]
struct Book {
    e0: f64,
    scale: f64,
    energy_error: f64,
    energy_residual: f64,
    momentum_error: f64,
    p0: Vec3,
}

/// Where a run starts from: a fresh system or a checkpoint.
struct Start {
    system: System,
    steps: u64,
    next_sample: usize,
    rows: u64,
    bytes: u64,
    checkpoints: u64,
    wall_before: f64,
    book: Book,
    last_counts: [u64; 4],
    last_wall_clock: f64,
    timeseries: File,
}

fn pack_particles(system: &System) -> Vec<f64> {
    let mut v = Vec::with_capacity(PARTICLE_STATE * system.particles.len());
    for p in &system.particles {
        v.push(f64::from(u8::from(p.alive)));
        v.extend(p.position.iter().chain(p.velocity.iter()).chain(p.spin.iter()));
        v.push(p.t_local);
        match p.stuck {
            Some(a) => {
                v.push(a.wall as f64);
                v.extend(a.offset.iter());
                v.push(a.t_stuck);
            }
            None => v.extend([-1.0, 0.0, 0.0, 0.0, 0.0]),
        }
    }
    v
}

fn unpack_particles(system: &mut System, v: &[f64]) -> Result<(), String> {
    if v.len() != PARTICLE_STATE * system.particles.len() {
        return Err(format!(
            "the checkpoint holds {} numbers for {} particles",
            v.len(),
            system.particles.len()
        ));
    }
    let n_walls = system.walls.len();
    for (p, c) in system.particles.iter_mut().zip(v.chunks(PARTICLE_STATE)) {
        let v3 = |o: usize| Vec3::new(c[o], c[o + 1], c[o + 2]);
        p.alive = c[0] != 0.0;
        p.position = v3(1);
        p.velocity = v3(4);
        p.spin = v3(7);
        p.t_local = c[10];
        p.stuck = if c[11] >= 0.0 {
            let wall = c[11] as usize;
            if wall >= n_walls {
                return Err(format!("particle {} is stuck to wall {wall} of {n_walls}", p.id));
            }
            Some(Attachment {
                wall,
                offset: v3(12),
                t_stuck: c[15],
            })
        } else {
            None
        };
    }
    Ok(())
}

/// Runs a hard-sphere scene into `out` (checkpoints as `options` asks; `options.force` overwrites a previous run).
pub fn run_hard_scene(scene: &HardScene, out: &Path, options: &RunOptions) -> Result<HardRunSummary, HardRunError> {
    prepare_output_dir(out, options.force)?;
    let scene_copy = out.join("scene.toml");
    std::fs::write(&scene_copy, &scene.source).map_err(io(&scene_copy))?;
    let ts_path = out.join("timeseries.csv");
    let mut ts = File::create(&ts_path).map_err(io(&ts_path))?;
    let header = format!("{}\n", TIMESERIES_COLUMNS.join(","));
    ts.write_all(header.as_bytes()).map_err(io(&ts_path))?;
    let system = System::new(scene.particles.clone(), scene.walls.clone(), scene.settings);
    let d0 = system.diagnostics();
    let book = Book {
        e0: d0.energy(),
        scale: d0.energy().abs().max(d0.kinetic + d0.rotational).max(f64::MIN_POSITIVE),
        energy_error: 0.0,
        energy_residual: 0.0,
        momentum_error: 0.0,
        p0: d0.momentum,
    };
    let start = Start {
        system,
        steps: 0,
        next_sample: 0,
        rows: 0,
        bytes: header.len() as u64,
        checkpoints: 0,
        wall_before: 0.0,
        book,
        last_counts: [0; 4],
        last_wall_clock: 0.0,
        timeseries: ts,
    };
    drive(scene, out, options, start)
}

/// Whether `dir` holds a hard-sphere run (its `scene.toml` has `kind = "hard-spheres"`).
pub fn is_hard_run_dir(dir: &Path) -> bool {
    std::fs::read_to_string(dir.join("scene.toml"))
        .is_ok_and(|t| crate::scene::peek_kind(&t).as_deref() == Some(super::scene::KIND))
}

/// Continues an interrupted hard-sphere run from `dir/checkpoint.json`, bit for bit: the snapshots, the final state
/// and every time-series column but `events_per_second` and `wall_seconds` are those of an uninterrupted run.
pub fn resume_hard(dir: &Path, options: &RunOptions) -> Result<HardRunSummary, HardRunError> {
    let bad = |m: String| HardRunError::Output(RunError::BadCheckpoint(m));
    let (ck, text): (HardCheckpoint, String) =
        open_checkpoint(dir, HARD_CHECKPOINT_FORMAT, "hard-sphere").map_err(HardRunError::Output)?;
    let spath = dir.join("scene.toml");
    let scene = super::scene::parse_hard_scene(&text, &spath.display().to_string(), &ck.scene_base_dir)
        .map_err(|e| bad(e.to_string()))?;
    let mut system = System::new(scene.particles.clone(), scene.walls.clone(), scene.settings);
    unpack_particles(&mut system, &ck.state).map_err(bad)?;
    system.t = ck.t;
    let anchors = match ck.anchors.len() {
        0 => None,
        n if n == 3 * system.particles.len() => Some(NeighbourState {
            anchors: ck.anchors.chunks(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect(),
            allowances: ck.allowances.clone(),
        }),
        n => {
            return Err(bad(format!(
                "{n} anchor numbers for {} particles",
                system.particles.len()
            )));
        }
    };
    system.restore_neighbours(anchors).map_err(bad)?;
    if ck.book.len() != 10 {
        return Err(bad("malformed bookkeeping".into()));
    }
    let [pair, wall, events, guarded, rebuilds, reanchors, absorbed] = ck.counts;
    system.counters = Counters {
        pair_collisions: pair,
        wall_collisions: wall,
        events,
        guarded,
        rebuilds,
        reanchors,
        absorbed,
        max_overlap: ck.book[0],
        energy_exchanged: ck.book[1],
    };
    let book = Book {
        e0: ck.book[2],
        scale: ck.book[3],
        energy_error: ck.book[4],
        energy_residual: ck.book[5],
        momentum_error: ck.book[6],
        p0: Vec3::new(ck.book[7], ck.book[8], ck.book[9]),
    };
    let file = reopen_timeseries(dir, ck.timeseries_bytes).map_err(HardRunError::Output)?;
    let start = Start {
        system,
        steps: ck.steps,
        next_sample: ck.next_sample as usize,
        rows: ck.rows,
        bytes: ck.timeseries_bytes,
        checkpoints: ck.checkpoints,
        wall_before: ck.wall_seconds,
        book,
        last_counts: ck.last_counts,
        last_wall_clock: ck.last_wall_clock,
        timeseries: file,
    };
    drive(&scene, dir, options, start)
}

fn drive(scene: &HardScene, out: &Path, options: &RunOptions, start: Start) -> Result<HardRunSummary, HardRunError> {
    let Start {
        mut system,
        steps,
        next_sample,
        mut rows,
        mut bytes,
        mut checkpoints,
        wall_before,
        mut book,
        last_counts,
        mut last_wall_clock,
        timeseries: mut ts,
    } = start;
    let ts_path = out.join("timeseries.csv");
    let clock = Instant::now();
    let wall_now = |c: &Instant| wall_before + c.elapsed().as_secs_f64();
    let base_dir = std::fs::canonicalize(&scene.base_dir)
        .or_else(|_| std::path::absolute(&scene.base_dir))
        .map_err(io(&scene.base_dir))?;
    let mut summary = HardRunSummary {
        status: "running".into(),
        kind: super::scene::KIND.into(),
        scene: scene.name.clone(),
        seed: scene.seed,
        t_end: scene.t_end,
        t_reached: system.t,
        steps,
        particles: scene.particles.len(),
        wall_seconds: 0.0,
        energy_initial: book.e0,
        energy_final: book.e0,
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
        neighbour_reanchors: 0,
        max_overlap: 0.0,
        absorbed: 0,
        stuck: 0,
    };
    let events_before = system.counters.events;
    let [mut last_coll, mut last_pair, mut last_wall, mut last_events] = last_counts;
    let mut failure: Option<(String, System)> = None;
    let mut last_checkpoint_wall = 0.0;
    let mut last_checkpoint_t = system.t;
    let mut written = 0u64;
    let samples: Vec<_> = Schedule::new(scene.t_end, scene.every, &scene.times).collect();
    let pb = progress_bar(options.progress, scene.t_end, system.t);
    for (index, sample) in samples.iter().enumerate().skip(next_sample) {
        let good = system.clone();
        let mut failed = None;
        while system.t < sample.t {
            if let Some(pb) = &pb
                && summary.steps.is_multiple_of(64)
            {
                show_progress(pb, system.t, scene.t_end);
            }
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
        book.energy_error = book.energy_error.max((e - book.e0).abs() / book.scale);
        book.energy_residual = book
            .energy_residual
            .max((e - book.e0 - c.energy_exchanged).abs() / book.scale);
        book.momentum_error = book.momentum_error.max((d.momentum - book.p0).norm());
        let wall = wall_now(&clock);
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
            (e - book.e0) / book.scale,
            (e - book.e0 - c.energy_exchanged) / book.scale,
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
        let line = cols.join(",") + "\n";
        ts.write_all(line.as_bytes()).map_err(io(&ts_path))?;
        rows += 1;
        bytes += line.len() as u64;
        (last_coll, last_pair, last_wall, last_events, last_wall_clock) =
            (coll, c.pair_collisions, c.wall_collisions, c.events, wall);
        if let Some(k) = sample.snapshot {
            let p = out.join("snapshots").join(format!("{k}.csv"));
            write_particles(&p, sample.t, &system).map_err(io(&p))?;
        }
        let last = index + 1 == samples.len();
        let due_wall = options
            .checkpoint_every
            .is_some_and(|w| w > 0.0 && clock.elapsed().as_secs_f64() - last_checkpoint_wall >= w);
        let due_sim = options
            .checkpoint_every_sim
            .is_some_and(|s| system.t - last_checkpoint_t >= s);
        if !last && (due_wall || due_sim) {
            checkpoints += 1;
            let c = system.counters;
            let nb = system.neighbour_state();
            let ck = HardCheckpoint {
                format: HARD_CHECKPOINT_FORMAT.into(),
                version: 1,
                writer: format!("rubblepile {}", env!("CARGO_PKG_VERSION")),
                scene_hash: fnv1a_hex(scene.source.as_bytes()),
                scene_base_dir: base_dir.clone(),
                t_seconds: system.t,
                t: system.t,
                steps: summary.steps,
                next_sample: index as u64 + 1,
                rows,
                timeseries_bytes: bytes,
                checkpoints,
                wall_seconds: wall,
                state: pack_particles(&system),
                anchors: nb
                    .as_ref()
                    .map(|s| s.anchors.iter().flat_map(|a| a.iter().copied()).collect())
                    .unwrap_or_default(),
                allowances: nb.as_ref().map(|s| s.allowances.clone()).unwrap_or_default(),
                counts: [
                    c.pair_collisions,
                    c.wall_collisions,
                    c.events,
                    c.guarded,
                    c.rebuilds,
                    c.reanchors,
                    c.absorbed,
                ],
                book: vec![
                    c.max_overlap,
                    c.energy_exchanged,
                    book.e0,
                    book.scale,
                    book.energy_error,
                    book.energy_residual,
                    book.momentum_error,
                    book.p0.x,
                    book.p0.y,
                    book.p0.z,
                ],
                last_counts: [last_coll, last_pair, last_wall, last_events],
                last_wall_clock,
            };
            let tmp = out.join(CHECKPOINT_TMP_FILE);
            let text = serde_json::to_string_pretty(&ck).map_err(|e| io(&tmp)(std::io::Error::other(e)))?;
            std::fs::write(&tmp, text + "\n").map_err(io(&tmp))?;
            let fin = out.join(CHECKPOINT_FILE);
            std::fs::rename(&tmp, &fin).map_err(io(&fin))?;
            last_checkpoint_wall = clock.elapsed().as_secs_f64();
            last_checkpoint_t = system.t;
            written += 1;
            if options.stop_after_checkpoints == Some(written) {
                return Err(HardRunError::Output(RunError::Stopped {
                    dir: out.to_path_buf(),
                    t: system.t,
                    checkpoints: written,
                }));
            }
        }
    }
    let wall = wall_now(&clock);
    let state = match &failure {
        Some((_, good)) => good,
        None => &system,
    };
    let c = system.counters;
    let d = state.diagnostics();
    summary.t_reached = state.t;
    summary.wall_seconds = wall;
    summary.energy_initial = book.e0;
    summary.energy_final = d.energy();
    summary.energy_error = book.energy_error;
    summary.energy_residual = book.energy_residual;
    summary.momentum_error = book.momentum_error;
    summary.energy_exchanged = c.energy_exchanged;
    summary.collisions = c.pair_collisions + c.wall_collisions;
    summary.pair_collisions = c.pair_collisions;
    summary.wall_collisions = c.wall_collisions;
    summary.events = c.events;
    let this_process = clock.elapsed().as_secs_f64();
    summary.events_per_second = if this_process > 0.0 {
        (c.events - events_before) as f64 / this_process
    } else {
        0.0
    };
    summary.guarded_collisions = c.guarded;
    summary.neighbour_rebuilds = c.rebuilds;
    summary.neighbour_reanchors = c.reanchors;
    summary.max_overlap = c.max_overlap;
    summary.absorbed = c.absorbed;
    summary.stuck = d.stuck;
    summary.status = match &failure {
        Some((cause, _)) => cause.clone(),
        None => "completed".into(),
    };
    if let Some(pb) = &pb {
        match &failure {
            Some(_) => pb.abandon(),
            None => pb.finish_and_clear(),
        }
    }
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
            "{}: t = {} s, {} steps, {} collisions ({:.3e} events/s), energy residual {:.2e} (change {:.2e}), max overlap {:.2e}, {} absorbed, {:.2} s",
            self.status,
            self.t_reached,
            self.steps,
            self.collisions,
            self.events_per_second,
            self.energy_residual,
            self.energy_error,
            self.max_overlap,
            self.absorbed,
            self.wall_seconds
        )
    }
}

fn cli_result(r: Result<HardRunSummary, HardRunError>) -> Result<(), crate::cli::CliError> {
    match r {
        Ok(s) => {
            println!("{}", s.one_line());
            Ok(())
        }
        Err(HardRunError::Output(e)) => Err(crate::cli::CliError {
            message: e.to_string(),
            code: e.exit_code(),
        }),
        Err(e) => Err(crate::cli::CliError::failed(e)),
    }
}

/// `rubblepile run SCENE --out DIR [--force] [--checkpoint-every …]` for a hard-sphere scene: prints the one-line
/// summary; exit code 2 for bad input or an existing output directory, 1 for a failed run, 3 when stopped after a
/// checkpoint on request.
pub fn cli_run(path: &Path, out: &Path, options: &RunOptions) -> Result<(), crate::cli::CliError> {
    let scene = super::scene::load_hard_scene(path).map_err(crate::cli::CliError::usage)?;
    cli_result(run_hard_scene(&scene, out, options))
}

/// `rubblepile resume DIR` of a hard-sphere run.
pub fn cli_resume(dir: &Path, options: &RunOptions) -> Result<(), crate::cli::CliError> {
    cli_result(resume_hard(dir, options))
}
