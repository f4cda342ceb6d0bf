//! The soft-sphere run driver (`rubblepile run` on a `kind = "soft-spheres"` scene): the core's output
//! contract adapted to spheres.
//!
//! Files in the output directory:
//! - `scene.toml`: the scene text;
//! - `timeseries.csv` (flushed per row), every `output.every` (whole steps) and at each snapshot:
//!   `t,step,kinetic_energy,gravitational_energy,spring_energy,dissipated_energy,wall_work,energy_residual,
//!   momentum_error,angular_momentum_error,max_overlap_fraction,contacts,coordination_number,forcing_work,
//!   wall_seconds`;
//!   `energy_residual = (E + W_dissipated − W_walls − W_forcing − E₀)/S` with `E` kinetic + gravitational + spring
//!   energy and `S = KE₀ + |U₀| + spring₀` (1 J if zero); momenta errors are `|P − P₀|/Σ m|v|₀` and
//!   `|L − ΔL_forcing − L₀|/Σ(|x × m v| + I|ω|)₀` (scale 1 if zero); `W_forcing` and `ΔL_forcing` are the work
//!   and angular momentum given by the spin-up forcing (0 without `[spinup]`), so that the residuals measure the
//!   integration error in spin-up runs too; `max_overlap_fraction` is the largest contact overlap over the smaller
//!   radius of the contact at that step;
//! - `snapshots/<k>.csv`: `t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz` (usable as a `particles_file`);
//! - `summary.json` ([`SoftSummary`]), `last_good_state.csv` on failure, `checkpoint.json` when due;
//! - with a `[spinup]` table: `spinup.csv`, one row of [`crate::analysis::spinup_diagnostics`] per time-series
//!   row; the forcing ([`crate::granular::soft::spinup`]) acts after every step.
//!
//! Checkpoints hold every particle's state, the last forces and torques (leapfrog needs them), the spring
//! histories and the bookkeeping, all as exact f64 bit patterns, so [`resume_soft`] continues bit for bit.
//! A non-finite state or an overlap above half the smaller radius stops the run with the last good state
//! saved and the cause named.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::analysis::spinup_diagnostics::{SPINUP_HEADER, diagnose_run};
use crate::granular::soft::contact::Springs;
use crate::granular::soft::forces::SoftSystem;
use crate::granular::soft::leapfrog;
use crate::granular::soft::particle::Particle;
use crate::granular::soft::scene::{SoftScene, parse_soft_scene, scene_kind};
use crate::granular::soft::spinup::{SpinupDriver, central_body};
use crate::io::checkpoint::{CHECKPOINT_FILE, CHECKPOINT_TMP_FILE, exact_f64, exact_f64_vec, fnv1a_hex};
use crate::io::resume::{EngineCheckpoint, open_checkpoint, reopen_timeseries, reopen_truncated};
use crate::math::Vec3;
use crate::run::{RunError, RunOptions, prepare_output_dir};
use crate::run::{progress_bar, show_progress};

/// The `format` tag of a soft-sphere checkpoint.
pub const SOFT_CHECKPOINT_FORMAT: &str = "rubblepile-ssdem-checkpoint";
/// Overlap (fraction of the smaller radius) above which the run is declared broken.
pub const BROKEN_OVERLAP: f64 = 0.5;

const TIMESERIES_HEADER: &str = "t,step,kinetic_energy,gravitational_energy,spring_energy,dissipated_energy,wall_work,energy_residual,momentum_error,angular_momentum_error,max_overlap_fraction,contacts,coordination_number,forcing_work,wall_seconds\n";

/// `summary.json` of a soft-sphere run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SoftSummary {
    /// `"completed"` or `"failed: <cause>"`.
    pub status: String,
    /// Scene kind (`"soft-spheres"`).
    pub kind: String,
    /// Wall-clock seconds of the whole run (all processes).
    pub wall_seconds: f64,
    /// Largest |energy residual| over the samples (see the module docs).
    pub energy_error: f64,
    /// Energy residual at the last sample.
    pub final_energy_residual: f64,
    /// Largest relative linear momentum error over the samples.
    pub momentum_error: f64,
    /// Largest relative angular momentum error over the samples.
    pub angular_momentum_error: f64,
    /// Largest overlap seen at any step, over the smaller radius of the contact.
    pub max_overlap_fraction: f64,
    /// Last time reached (s).
    pub final_time: f64,
    /// Requested end time (s).
    pub t_end: f64,
    /// Steps taken.
    pub steps: u64,
    /// Step (s).
    pub dt: f64,
    /// Time-series samples written.
    pub samples: u64,
    /// Particles.
    pub n_particles: usize,
    /// Walls.
    pub n_walls: usize,
    /// Contacts at the end (pairs + wall contacts).
    pub contacts: usize,
    /// Coordination number at the end.
    pub coordination_number: f64,
    /// `k_N` used (N/m).
    pub k_n: f64,
    /// `k_N` advised for 1 % overlap (N/m).
    pub advised_k_n: f64,
    /// Step advised for the scene's `k_N`... for the advised `k_N` (s).
    pub advised_dt: f64,
    /// Self-gravity: `"off"`, `"direct"` or `"tree (theta = …)"`, with `", every k steps"` when
    /// `[gravity] interval_steps = k > 1`.
    pub self_gravity: String,
    /// Seed.
    pub seed: u64,
    /// Scene warnings.
    pub warnings: Vec<String>,
}

impl SoftSummary {
    /// One line for the terminal.
    pub fn one_line(&self) -> String {
        format!(
            "{}: t = {} s, {} steps, {} particles, energy error {:.3e}, max overlap {:.3e} of radius, {:.2} s",
            self.status,
            self.final_time,
            self.steps,
            self.n_particles,
            self.energy_error,
            self.max_overlap_fraction,
            self.wall_seconds
        )
    }
}

/// Why a soft-sphere run did not complete.
#[derive(Debug, thiserror::Error)]
pub enum SoftRunError {
    /// Output directory or file-system problems shared with the core driver (existing output without
    /// `--force`, I/O errors).
    #[error(transparent)]
    Run(#[from] RunError),
    /// The run broke (non-finite state, overlap above [`BROKEN_OVERLAP`]); summary and last good state written.
    #[error("run failed: {cause}; last good state (t = {t} s) in {}", .last_good_state.display())]
    Failed {
        /// Last good time (s).
        t: f64,
        /// Cause.
        cause: String,
        /// Where the last good state is.
        last_good_state: PathBuf,
        /// The summary written.
        summary: Box<SoftSummary>,
    },
}

impl SoftRunError {
    /// Exit code for the command line: as [`RunError::exit_code`], 1 for a failed run.
    pub fn exit_code(&self) -> u8 {
        match self {
            SoftRunError::Run(e) => e.exit_code(),
            SoftRunError::Failed { .. } => 1,
        }
    }
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> SoftRunError + '_ {
    move |source| {
        SoftRunError::Run(RunError::Io {
            path: path.to_path_buf(),
            source,
        })
    }
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct SpringRecord {
    i: usize,
    j: usize,
    /// normal (3), shear (3), twist, roll (3).
    #[serde(with = "exact_f64_vec")]
    s: Vec<f64>,
}

fn pack(list: &[((usize, usize), Springs)]) -> Vec<SpringRecord> {
    list.iter()
        .map(|&((i, j), s)| {
            let mut v: Vec<f64> = s.normal.iter().chain(s.shear.iter()).copied().collect();
            v.push(s.twist);
            v.extend(s.roll.iter());
            SpringRecord { i, j, s: v }
        })
        .collect()
}

fn unpack(list: &[SpringRecord]) -> Option<Vec<((usize, usize), Springs)>> {
    list.iter()
        .map(|r| {
            (r.s.len() == 10).then(|| {
                let v = &r.s;
                (
                    (r.i, r.j),
                    Springs {
                        normal: Vec3::new(v[0], v[1], v[2]),
                        shear: Vec3::new(v[3], v[4], v[5]),
                        twist: v[6],
                        roll: Vec3::new(v[7], v[8], v[9]),
                    },
                )
            })
        })
        .collect()
}

/// Bookkeeping carried through a run (and its checkpoints).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Book {
    e0: f64,
    e_scale: f64,
    p0: Vec3,
    p_scale: f64,
    l0: Vec3,
    l_scale: f64,
    max_energy: f64,
    last_energy: f64,
    max_p: f64,
    max_l: f64,
    max_overlap: f64,
}

impl Book {
    fn new(sys: &SoftSystem) -> Self {
        let ps = &sys.particles;
        let e_scale = sys.kinetic_energy() + sys.stats.gravitational_energy.abs() + sys.stats.spring_energy;
        let p_scale: f64 = ps.iter().map(|p| p.mass * p.velocity.norm()).sum();
        let l_scale: f64 = ps
            .iter()
            .map(|p| p.position.cross(&(p.velocity * p.mass)).norm() + p.inertia() * p.spin.norm())
            .sum();
        let nz = |x: f64| if x > 0.0 { x } else { 1.0 };
        Book {
            e0: sys.energy(),
            e_scale: nz(e_scale),
            p0: sys.momentum(),
            p_scale: nz(p_scale),
            l0: sys.angular_momentum(),
            l_scale: nz(l_scale),
            max_energy: 0.0,
            last_energy: 0.0,
            max_p: 0.0,
            max_l: 0.0,
            max_overlap: sys.stats.max_overlap_fraction,
        }
    }
    fn to_vec(self) -> Vec<f64> {
        let mut v = vec![self.e0, self.e_scale];
        v.extend(self.p0.iter());
        v.push(self.p_scale);
        v.extend(self.l0.iter());
        v.extend([
            self.l_scale,
            self.max_energy,
            self.last_energy,
            self.max_p,
            self.max_l,
            self.max_overlap,
        ]);
        v
    }
    fn from_vec(v: &[f64]) -> Option<Self> {
        (v.len() == 15).then(|| Book {
            e0: v[0],
            e_scale: v[1],
            p0: Vec3::new(v[2], v[3], v[4]),
            p_scale: v[5],
            l0: Vec3::new(v[6], v[7], v[8]),
            l_scale: v[9],
            max_energy: v[10],
            last_energy: v[11],
            max_p: v[12],
            max_l: v[13],
            max_overlap: v[14],
        })
    }
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct SoftCheckpoint {
    format: String,
    version: u32,
    writer: String,
    scene_hash: String,
    scene_base_dir: Option<PathBuf>,
    step: u64,
    t_seconds: f64,
    next_sample: u64,
    rows: u64,
    timeseries_bytes: u64,
    checkpoints: u64,
    #[serde(with = "exact_f64")]
    wall_seconds: f64,
    /// Per particle: x, v, ω, F, τ (15 numbers).
    #[serde(with = "exact_f64_vec")]
    state: Vec<f64>,
    pair_springs: Vec<SpringRecord>,
    wall_springs: Vec<SpringRecord>,
    /// dissipated, wall_work, forcing_work, forcing angular impulse (x, y, z).
    #[serde(with = "exact_f64_vec")]
    work: Vec<f64>,
    /// Steps taken in the current self-gravity block (r-RESPA; 0 without).
    #[serde(default)]
    gravity_phase: u64,
    /// Self-gravity accelerations of the block's start (3 per particle) and its potential energy, when
    /// `[gravity] interval_steps > 1`; empty otherwise.
    #[serde(default, with = "exact_f64_vec")]
    slow: Vec<f64>,
    #[serde(with = "exact_f64_vec")]
    book: Vec<f64>,
    /// The spin-up driver's state and the length of `spinup.csv`, for a `[spinup]` scene.
    #[serde(default)]
    spinup: Option<SpinupCheckpoint>,
}

impl EngineCheckpoint for SoftCheckpoint {
    fn format(&self) -> &str {
        &self.format
    }
    fn scene_hash(&self) -> &str {
        &self.scene_hash
    }
}

// ---- spin-up hook (Zhang17 §2.3.4; crate::granular::soft::spinup) --------------------------------------
#[derive(Debug, Clone, Serialize, Deserialize)]
struct SpinupCheckpoint {
    #[serde(with = "exact_f64_vec")]
    state: Vec<f64>,
    bytes: u64,
}

/// A spin-up run's driver and its open `spinup.csv`.
struct SpinRun {
    driver: SpinupDriver,
    csv: BufWriter<File>,
    bytes: u64,
}

impl SpinRun {
    /// Forcing after a step ending at time `t` (s), on the central body of the step's contacts.
    fn after_step(&self, sys: &mut SoftSystem, t: f64) {
        if !self.driver.released {
            let springs = sys.pair_springs();
            let member = central_body(&sys.particles, springs.iter().map(|(k, _)| k));
            let inc = self.driver.apply(&mut sys.particles, &member, t);
            sys.forcing_work += inc.work;
            sys.forcing_angular_impulse += inc.angular_impulse;
        }
    }
    /// The diagnostics row at an output sample (time `t`, s), then the release check.
    fn sample(&mut self, sys: &SoftSystem, t: f64, path: &Path) -> Result<(), SoftRunError> {
        let d = diagnose_run(sys, &self.driver, t).sample;
        let line = d.csv_row();
        self.csv.write_all(line.as_bytes()).map_err(io_err(path))?;
        self.csv.flush().map_err(io_err(path))?;
        self.bytes += line.len() as u64;
        self.driver.observe(t, d.b_over_a, d.c_over_a, d.packing_fraction);
        Ok(())
    }
}
// ---- end of spin-up hook ---------------------------------------------------------------------------------

/// The run's output samples: `(step, snapshot index)` for every time-series row, in order (the `every` grid, the
/// last step, and the snapshot steps).
pub fn sample_steps(scene: &SoftScene) -> Vec<(u64, Option<usize>)> {
    let mut grid: Vec<u64> = (0..=scene.n_steps / scene.every_steps)
        .map(|k| k * scene.every_steps)
        .collect();
    if grid.last() != Some(&scene.n_steps) {
        grid.push(scene.n_steps);
    }
    grid.extend(scene.snapshot_steps.iter());
    grid.sort_unstable();
    grid.dedup();
    grid.into_iter()
        .map(|s| (s, scene.snapshot_steps.iter().position(|&k| k == s)))
        .collect()
}

/// Writes spheres in the snapshot columns.
pub fn write_particles_csv(path: &Path, t: f64, particles: &[Particle]) -> std::io::Result<()> {
    let mut w = BufWriter::new(File::create(path)?);
    writeln!(w, "t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz")?;
    for (id, p) in particles.iter().enumerate() {
        let (x, v, s) = (p.position, p.velocity, p.spin);
        writeln!(
            w,
            "{t},{id},{},{},{},{},{},{},{},{},{},{},{}",
            p.mass, p.radius, x.x, x.y, x.z, v.x, v.y, v.z, s.x, s.y, s.z
        )?;
    }
    w.flush()
}

fn gravity_name(scene: &SoftScene) -> String {
    let name = match scene.gravity.self_gravity {
        None => return "off".into(),
        Some(crate::gravity::SelfGravity::Direct) => "direct".to_string(),
        Some(crate::gravity::SelfGravity::Tree { theta }) => format!("tree (theta = {theta})"),
    };
    match scene.gravity_interval {
        1 => name,
        k => format!("{name}, every {k} steps"),
    }
}

fn summary(
    scene: &SoftScene,
    sys: &SoftSystem,
    book: &Book,
    status: String,
    step: u64,
    rows: u64,
    wall: f64,
) -> SoftSummary {
    SoftSummary {
        status,
        kind: crate::granular::soft::scene::KIND.into(),
        wall_seconds: wall,
        energy_error: book.max_energy,
        final_energy_residual: book.last_energy,
        momentum_error: book.max_p,
        angular_momentum_error: book.max_l,
        max_overlap_fraction: book.max_overlap,
        final_time: step as f64 * scene.dt,
        t_end: scene.t_end,
        steps: step,
        dt: scene.dt,
        samples: rows,
        n_particles: sys.particles.len(),
        n_walls: sys.walls.len(),
        contacts: sys.stats.pair_contacts + sys.stats.wall_contacts,
        coordination_number: sys.coordination_number(),
        k_n: scene.material.k_n,
        advised_k_n: scene.advice.k_n,
        advised_dt: scene.advice.dt,
        self_gravity: gravity_name(scene),
        seed: scene.seed,
        warnings: scene.warnings.clone(),
    }
}

fn write_summary(path: &Path, s: &SoftSummary) -> Result<(), SoftRunError> {
    let text = serde_json::to_string_pretty(s).expect("summary serialises");
    std::fs::write(path, text + "\n").map_err(io_err(path))
}

/// A fresh system for the scene, forces evaluated at t = 0.
pub fn initial_system(scene: &SoftScene) -> SoftSystem {
    let mut sys = SoftSystem::new(
        scene.particles.clone(),
        scene.walls.clone(),
        scene.material,
        scene.gravity,
    );
    sys.gravity_interval = scene.gravity_interval;
    sys.compute_forces(0.0, 0.0);
    sys
}

struct Start {
    sys: SoftSystem,
    step: u64,
    next_sample: usize,
    rows: u64,
    bytes: u64,
    checkpoints: u64,
    wall_before: f64,
    book: Book,
    timeseries: BufWriter<File>,
    spin: Option<SpinRun>,
}

/// Runs a soft-sphere scene into `out_dir` (refuses a non-empty directory unless `options.force`).
pub fn run_soft(scene: &SoftScene, out_dir: &Path, options: &RunOptions) -> Result<SoftSummary, SoftRunError> {
    prepare_output_dir(out_dir, options.force)?;
    let copy = out_dir.join("scene.toml");
    std::fs::write(&copy, &scene.source).map_err(io_err(&copy))?;
    let ts = out_dir.join("timeseries.csv");
    let mut timeseries = BufWriter::new(File::create(&ts).map_err(io_err(&ts))?);
    timeseries
        .write_all(TIMESERIES_HEADER.as_bytes())
        .map_err(io_err(&ts))?;
    timeseries.flush().map_err(io_err(&ts))?;
    let mut sys = initial_system(scene);
    let spin = match &scene.spinup {
        Some(settings) => {
            // the body starts on the path (T_start) and the t = 0 sample needs the contact records
            let driver = SpinupDriver::new(*settings, &scene.particles);
            let springs = sys.pair_springs();
            let member = central_body(&sys.particles, springs.iter().map(|(k, _)| k));
            driver.apply(&mut sys.particles, &member, 0.0);
            sys.keep_records = true;
            sys.set_pair_springs(Vec::new());
            sys.compute_forces(0.0, 0.0);
            let path = out_dir.join("spinup.csv");
            let mut csv = BufWriter::new(File::create(&path).map_err(io_err(&path))?);
            csv.write_all(SPINUP_HEADER.as_bytes()).map_err(io_err(&path))?;
            Some(SpinRun {
                driver,
                csv,
                bytes: SPINUP_HEADER.len() as u64,
            })
        }
        None => None,
    };
    let book = Book::new(&sys);
    let base = match &scene.base_dir {
        Some(d) => Some(
            std::fs::canonicalize(d)
                .or_else(|_| std::path::absolute(d))
                .map_err(io_err(d))?,
        ),
        None => None,
    };
    let start = Start {
        sys,
        step: 0,
        next_sample: 0,
        rows: 0,
        bytes: TIMESERIES_HEADER.len() as u64,
        checkpoints: 0,
        wall_before: 0.0,
        book,
        timeseries,
        spin,
    };
    drive(scene, out_dir, options, start, base)
}

/// Whether `dir` holds a soft-sphere run (its `scene.toml` has `kind = "soft-spheres"`).
pub fn is_soft_run_dir(dir: &Path) -> bool {
    std::fs::read_to_string(dir.join("scene.toml"))
        .is_ok_and(|t| scene_kind(&t).as_deref() == Some(crate::granular::soft::scene::KIND))
}

/// Continues an interrupted soft-sphere run from `dir/checkpoint.json`, bit for bit.
pub fn resume_soft(dir: &Path, options: &RunOptions) -> Result<SoftSummary, SoftRunError> {
    let bad = |m: String| SoftRunError::Run(RunError::BadCheckpoint(m));
    let (ck, text): (SoftCheckpoint, String) =
        open_checkpoint(dir, SOFT_CHECKPOINT_FORMAT, "soft-sphere").map_err(SoftRunError::Run)?;
    let spath = dir.join("scene.toml");
    let scene = parse_soft_scene(&text, &spath.display().to_string(), ck.scene_base_dir.as_deref())
        .map_err(|e| bad(e.to_string()))?;
    let n = scene.particles.len();
    if ck.state.len() != 15 * n {
        return Err(bad(format!(
            "the checkpoint holds {} numbers for {n} particles",
            ck.state.len()
        )));
    }
    let mut sys = SoftSystem::new(
        scene.particles.clone(),
        scene.walls.clone(),
        scene.material,
        scene.gravity,
    );
    for (k, c) in ck.state.chunks(15).enumerate() {
        let v = |o: usize| Vec3::new(c[o], c[o + 1], c[o + 2]);
        sys.particles[k].position = v(0);
        sys.particles[k].velocity = v(3);
        sys.particles[k].spin = v(6);
        sys.forces[k] = v(9);
        sys.torques[k] = v(12);
    }
    sys.set_pair_springs(unpack(&ck.pair_springs).ok_or_else(|| bad("malformed pair springs".into()))?);
    sys.wall_springs = unpack(&ck.wall_springs).ok_or_else(|| bad("malformed wall springs".into()))?;
    // [dissipated, wall work] before the spin-up forcing was accounted; then [.., forcing work, its L (3)]
    if ck.work.len() != 2 && ck.work.len() != 6 {
        return Err(bad("malformed work record".into()));
    }
    sys.dissipated = ck.work[0];
    sys.wall_work = ck.work[1];
    if ck.work.len() == 6 {
        sys.forcing_work = ck.work[2];
        sys.forcing_angular_impulse = Vec3::new(ck.work[3], ck.work[4], ck.work[5]);
    }
    sys.gravity_interval = scene.gravity_interval;
    if sys.split_gravity() {
        if ck.slow.len() != 3 * n + 1 || ck.gravity_phase >= scene.gravity_interval {
            return Err(bad("malformed self-gravity block record (slow, gravity_phase)".into()));
        }
        sys.gravity_phase = ck.gravity_phase;
        sys.slow_accelerations = ck.slow[..3 * n]
            .chunks(3)
            .map(|c| Vec3::new(c[0], c[1], c[2]))
            .collect();
        sys.slow_energy = ck.slow[3 * n];
    }
    let book = Book::from_vec(&ck.book).ok_or_else(|| bad("malformed bookkeeping".into()))?;

    let file = reopen_timeseries(dir, ck.timeseries_bytes).map_err(SoftRunError::Run)?;
    let spin = match (&scene.spinup, &ck.spinup) {
        (Some(settings), Some(sc)) => {
            let mut driver = SpinupDriver::new(*settings, &scene.particles);
            driver
                .restore(&sc.state)
                .ok_or_else(|| bad("malformed spin-up state".into()))?;
            let f = reopen_truncated(&dir.join("spinup.csv"), sc.bytes).map_err(SoftRunError::Run)?;
            Some(SpinRun {
                driver,
                csv: BufWriter::new(f),
                bytes: sc.bytes,
            })
        }
        (None, None) => None,
        _ => return Err(bad("the checkpoint and the scene disagree on [spinup]".into())),
    };
    let start = Start {
        sys,
        step: ck.step,
        next_sample: ck.next_sample as usize,
        rows: ck.rows,
        bytes: ck.timeseries_bytes,
        checkpoints: ck.checkpoints,
        wall_before: ck.wall_seconds,
        book,
        timeseries: BufWriter::new(file),
        spin,
    };
    drive(&scene, dir, options, start, ck.scene_base_dir.clone())
}

#[allow(clippy::too_many_arguments)]
fn row(scene: &SoftScene, sys: &SoftSystem, book: &mut Book, step: u64, wall: f64) -> String {
    let ke = sys.kinetic_energy();
    let s = &sys.stats;
    let residual =
        (ke + s.gravitational_energy + s.spring_energy + sys.dissipated - sys.wall_work - sys.forcing_work - book.e0)
            / book.e_scale;
    let p_err = (sys.momentum() - book.p0).norm() / book.p_scale;
    let l_err = (sys.angular_momentum() - sys.forcing_angular_impulse - book.l0).norm() / book.l_scale;
    book.max_energy = book.max_energy.max(residual.abs());
    book.last_energy = residual;
    book.max_p = book.max_p.max(p_err);
    book.max_l = book.max_l.max(l_err);
    format!(
        "{},{step},{ke},{},{},{},{},{residual},{p_err},{l_err},{},{},{},{},{wall}\n",
        step as f64 * scene.dt,
        s.gravitational_energy,
        s.spring_energy,
        sys.dissipated,
        sys.wall_work,
        s.max_overlap_fraction,
        s.pair_contacts + s.wall_contacts,
        sys.coordination_number(),
        sys.forcing_work,
    )
}

fn drive(
    scene: &SoftScene,
    dir: &Path,
    options: &RunOptions,
    start: Start,
    base: Option<PathBuf>,
) -> Result<SoftSummary, SoftRunError> {
    let Start {
        mut sys,
        mut step,
        next_sample,
        mut rows,
        mut bytes,
        mut checkpoints,
        wall_before,
        mut book,
        mut timeseries,
        mut spin,
    } = start;
    let spin_path = dir.join("spinup.csv");
    let clock = Instant::now();
    let wall = |c: &Instant| wall_before + c.elapsed().as_secs_f64();
    let ts_path = dir.join("timeseries.csv");
    let plan = sample_steps(scene);
    let mut last_checkpoint_wall = 0.0;
    let mut last_checkpoint_t = step as f64 * scene.dt;
    let mut written_this_process = 0u64;
    let dt = scene.dt;
    let pb = progress_bar(options.progress, scene.t_end, step as f64 * dt);
    // the state before the current step, kept for `last_good_state.csv` (allocated once)
    let mut before = sys.particles.clone();
    for (index, &(sample_step, snapshot)) in plan.iter().enumerate().skip(next_sample) {
        while step < sample_step {
            before.clone_from(&sys.particles);
            if let Some(pb) = &pb
                && step.is_multiple_of(256)
            {
                show_progress(pb, step as f64 * dt, scene.t_end);
            }
            // the spin-up diagnostics at a sample need that step's contact records
            sys.keep_records = spin.is_some() && step + 1 == sample_step;
            // the spring energy is read only at samples (the energy residual of the row)
            sys.spring_energy_wanted = step + 1 == sample_step;
            leapfrog::step(&mut sys, step as f64 * dt, dt);
            if let Some(s) = &spin {
                s.after_step(&mut sys, (step + 1) as f64 * dt);
            }
            let broken = if let Some(k) = sys.particles.iter().position(|p| !p.is_finite()) {
                Some(format!("non-finite state of particle {k}"))
            } else if sys.stats.max_overlap_fraction > BROKEN_OVERLAP {
                Some(format!(
                    "overlap of {} of a radius (> {BROKEN_OVERLAP}): contacts too soft or step too long",
                    sys.stats.max_overlap_fraction
                ))
            } else {
                None
            };
            if let Some(cause) = broken {
                if let Some(pb) = &pb {
                    pb.abandon();
                }
                let t_good = step as f64 * dt;
                let lgs = dir.join("last_good_state.csv");
                write_particles_csv(&lgs, t_good, &before).map_err(io_err(&lgs))?;
                let s = summary(
                    scene,
                    &sys,
                    &book,
                    format!("failed: {cause} at t = {} s", t_good + dt),
                    step,
                    rows,
                    wall(&clock),
                );
                write_summary(&dir.join("summary.json"), &s)?;
                return Err(SoftRunError::Failed {
                    t: t_good,
                    cause,
                    last_good_state: lgs,
                    summary: Box::new(s),
                });
            }
            book.max_overlap = book.max_overlap.max(sys.stats.max_overlap_fraction);
            step += 1;
        }
        let line = row(scene, &sys, &mut book, step, wall(&clock));
        timeseries.write_all(line.as_bytes()).map_err(io_err(&ts_path))?;
        timeseries.flush().map_err(io_err(&ts_path))?;
        rows += 1;
        bytes += line.len() as u64;
        let t = step as f64 * dt;
        if let Some(s) = spin.as_mut() {
            s.sample(&sys, t, &spin_path)?;
        }
        if let Some(k) = snapshot {
            let p = dir.join("snapshots").join(format!("{k}.csv"));
            write_particles_csv(&p, t, &sys.particles).map_err(io_err(&p))?;
        }
        let last = index + 1 == plan.len();
        let due_wall = options
            .checkpoint_every
            .is_some_and(|w| w > 0.0 && clock.elapsed().as_secs_f64() - last_checkpoint_wall >= w);
        let due_sim = options.checkpoint_every_sim.is_some_and(|s| t - last_checkpoint_t >= s);
        if !last && (due_wall || due_sim) {
            checkpoints += 1;
            let mut state = Vec::with_capacity(15 * sys.particles.len());
            for (k, p) in sys.particles.iter().enumerate() {
                for v in [p.position, p.velocity, p.spin, sys.forces[k], sys.torques[k]] {
                    state.extend(v.iter());
                }
            }
            let ck = SoftCheckpoint {
                format: SOFT_CHECKPOINT_FORMAT.into(),
                version: 1,
                writer: format!("rubblepile {}", env!("CARGO_PKG_VERSION")),
                scene_hash: fnv1a_hex(scene.source.as_bytes()),
                scene_base_dir: base.clone(),
                step,
                t_seconds: t,
                next_sample: index as u64 + 1,
                rows,
                timeseries_bytes: bytes,
                checkpoints,
                wall_seconds: wall(&clock),
                state,
                pair_springs: pack(&sys.pair_springs()),
                wall_springs: pack(&sys.wall_springs),
                work: vec![
                    sys.dissipated,
                    sys.wall_work,
                    sys.forcing_work,
                    sys.forcing_angular_impulse.x,
                    sys.forcing_angular_impulse.y,
                    sys.forcing_angular_impulse.z,
                ],
                gravity_phase: sys.gravity_phase,
                slow: if sys.split_gravity() {
                    let mut v: Vec<f64> = sys.slow_accelerations.iter().flat_map(|a| a.iter().copied()).collect();
                    v.push(sys.slow_energy);
                    v
                } else {
                    Vec::new()
                },
                book: book.to_vec(),
                spinup: spin.as_ref().map(|s| SpinupCheckpoint {
                    state: s.driver.state(),
                    bytes: s.bytes,
                }),
            };
            let tmp = dir.join(CHECKPOINT_TMP_FILE);
            let text = serde_json::to_string_pretty(&ck).expect("checkpoint serialises");
            std::fs::write(&tmp, text).map_err(io_err(&tmp))?;
            let fin = dir.join(CHECKPOINT_FILE);
            std::fs::rename(&tmp, &fin).map_err(io_err(&fin))?;
            last_checkpoint_wall = clock.elapsed().as_secs_f64();
            last_checkpoint_t = t;
            written_this_process += 1;
            if options.stop_after_checkpoints == Some(written_this_process) {
                return Err(SoftRunError::Run(RunError::Stopped {
                    dir: dir.to_path_buf(),
                    t,
                    checkpoints: written_this_process,
                }));
            }
        }
    }
    if let Some(pb) = &pb {
        pb.finish_and_clear();
    }
    let s = summary(scene, &sys, &book, "completed".into(), step, rows, wall(&clock));
    write_summary(&dir.join("summary.json"), &s)?;
    Ok(s)
}
