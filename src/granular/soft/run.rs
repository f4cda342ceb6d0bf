//! The soft-sphere engine as the run driver sees it (`rubblepile run`, `kind = "soft-spheres"`). Outputs: `scene.toml`;
//! `timeseries.csv` (flushed per row; columns `t,step,kinetic_energy,gravitational_energy,spring_energy,
//! dissipated_energy,wall_work,energy_residual,momentum_error,angular_momentum_error,max_overlap_fraction,contacts,
//! coordination_number,forcing_work,wall_seconds`); `snapshots/<k>.csv` (`t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz`,
//! usable as a `particles_file`); `summary.json` ([`SoftSummary`]); `last_good_state.csv`, `checkpoint.json`; and
//! with `[spinup]`, `spinup.csv` (the forcing acts after every step).
//!
//! `energy_residual = (E + W_dissipated − W_walls − W_forcing − E₀)/S`, `E` kinetic + gravitational + spring,
//! `S = KE₀ + |U₀| + spring₀` (1 J if zero); `|P − P₀|/Σ m|v|₀`, `|L − ΔL_forcing − L₀|/Σ(|x × m v| + I|ω|)₀`, so the
//! residuals measure integration error in spin-up runs too. Checkpoints hold exact f64 bits of the particles, the
//! last forces and torques, the springs and the bookkeeping: `resume` continues bit for bit. A non-finite state or an
//! overlap above half the smaller radius stops the run, saving the last good state and naming the cause.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::bits::exact_f64_vec;
use crate::engine::{
    ContactLine, Engine, EngineError, Failure, NamedSurface, Outcome, ParticleView, Resumed, RunReport, Sample,
    SampleError, SnapshotView, read_sphere_snapshot,
};
use crate::granular::soft::contact::Springs;
use crate::granular::soft::forces::SoftSystem;
use crate::granular::soft::leapfrog;
use crate::granular::soft::particle::Particle;
use crate::granular::soft::scene::{SoftScene, load_soft_scene, parse_soft_scene};
use crate::granular::soft::spinup::{SpinupDriver, central_body, central_body_par};
use crate::granular::soft::spinup_diagnostics::{SPINUP_HEADER, SPINUP_HEADER_LEGACY, diagnose_run};
use crate::math::Vec3;
use crate::phase::{Kind, Phase};
use rayon::prelude::*;

/// Overlap (fraction of the smaller radius) above which the run is declared broken.
pub const BROKEN_OVERLAP: f64 = 0.5;

/// Spheres per thread at least ([`SoftEngine`]'s `useful_threads`): the smallest grain measured still to gain from
/// more threads (`bench scaling`'s `ssdem-2k`; `analysis/scaling/NOTES.md`), so a smaller run forks over no more
/// threads than this gives.
pub const SPHERES_PER_THREAD: usize = 125;

static PHASE_CHECK_STATE: Phase = Phase::new("soft.check_state", Kind::Parallel);
static PHASE_SPINUP: Phase = Phase::new("soft.spinup_forcing", Kind::Serial);

/// One step of a run from step number `step` (time `step dt`, s) by `dt` (s), as the run driver takes it between
/// samples and as `rubblepile bench ssdem` times it: keeps the state before the step in `before` (for
/// `last_good_state.csv`, copied in the step's first pass), takes the leapfrog step, calls `after` (the spin-up
/// forcing, if any) with the system and the time at the step's end, and checks the new state (in parallel). An error
/// names a non-finite particle or an overlap above [`BROKEN_OVERLAP`].
pub fn checked_step(
    sys: &mut SoftSystem,
    before: &mut Vec<Particle>,
    step: u64,
    dt: f64,
    after: impl FnOnce(&mut SoftSystem, f64),
) -> Result<(), String> {
    leapfrog::step_keeping(sys, step as f64 * dt, dt, Some(before));
    after(sys, (step + 1) as f64 * dt);
    let bad = PHASE_CHECK_STATE.time(|| {
        sys.particles
            .par_iter()
            .with_min_len(4096)
            .position_first(|p| !p.is_finite())
    });
    if let Some(k) = bad {
        return Err(format!("non-finite state of particle {k}"));
    }
    if sys.stats.max_overlap_fraction > BROKEN_OVERLAP {
        return Err(format!(
            "overlap of {} of a radius (> {BROKEN_OVERLAP}): contacts too soft or step too long",
            sys.stats.max_overlap_fraction
        ));
    }
    Ok(())
}

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

impl RunReport for SoftSummary {
    fn one_line(&self) -> String {
        format!(
            "{}: t = {} s, {} steps, {} particles, energy error {:.3e}, max overlap {:.3e} of radius, {:.2} s",
            self.status,
            crate::io::messages::fmt_time(self.final_time),
            self.steps,
            self.n_particles,
            self.energy_error,
            self.max_overlap_fraction,
            self.wall_seconds
        ) + &self.accuracy_hint().map_or(String::new(), |h| format!("; {h}"))
    }
}

impl SoftSummary {
    /// When the energy residual is above [`ENERGY_HINT_ABOVE`], what in the scene explains it: a step longer than the
    /// advised one, or a `k_N` below the advised one (`rubblepile ssdem advise`), or neither.
    pub fn accuracy_hint(&self) -> Option<String> {
        if self.energy_error.is_nan() || self.energy_error <= ENERGY_HINT_ABOVE {
            return None;
        }
        let mut causes = Vec::new();
        if self.k_n < 0.5 * self.advised_k_n {
            causes.push(format!(
                "k_N is {:.1}x below the advised {:.2e} N/m",
                self.advised_k_n / self.k_n,
                self.advised_k_n
            ));
        }
        if self.dt > 2.0 * self.advised_dt {
            causes.push(format!(
                "dt is {:.1}x the step advised with that k_N ({:.2e} s)",
                self.dt / self.advised_dt,
                self.advised_dt
            ));
        }
        Some(if causes.is_empty() {
            format!(
                "energy residual above {ENERGY_HINT_ABOVE:.0e} of the energy scale, with dt and k_N as advised: shorten dt to check convergence"
            )
        } else {
            format!(
                "energy residual above {ENERGY_HINT_ABOVE:.0e}: {} (see `rubblepile ssdem advise`)",
                causes.join(", ")
            )
        })
    }
}

/// The energy residual above which the done line says what in the scene explains it ([`SoftSummary::accuracy_hint`]).
pub const ENERGY_HINT_ABOVE: f64 = 1e-2;

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

// ---- spin-up hook (Zhang17 §2.3.4; crate::granular::soft::spinup) --------------------------------------
#[derive(Debug, Clone, Serialize, Deserialize)]
struct SpinupCheckpoint {
    #[serde(with = "exact_f64_vec")]
    state: Vec<f64>,
    bytes: u64,
}

/// The first line of the text file at `path` (without its newline), if it can be read.
fn first_line(path: &Path) -> Option<String> {
    use std::io::BufRead;
    let mut line = String::new();
    std::io::BufReader::new(File::open(path).ok()?)
        .read_line(&mut line)
        .ok()?;
    Some(line.trim_end().to_string())
}

/// A spin-up run's driver and its open `spinup.csv`.
struct SpinRun {
    driver: SpinupDriver,
    csv: BufWriter<File>,
    bytes: u64,
    /// The file was started with [`SPINUP_HEADER_LEGACY`] (a run resumed from before `coordination_loaded`):
    /// its rows keep those columns.
    legacy: bool,
}

impl SpinRun {
    /// Forcing after a step ending at time `t` (s), on the central body of the step's contacts.
    fn after_step(&self, sys: &mut SoftSystem, t: f64) {
        if !self.driver.released {
            PHASE_SPINUP.time(|| {
                // the touching pairs straight from the list, joined in parallel: a copy of every spring would cost
                // ~20 MB a step at 40 000 spheres
                let member = central_body_par(&sys.particles, |union| sys.for_each_touching_pair(union));
                let inc = self.driver.apply(&mut sys.particles, &member, t);
                sys.forcing_work += inc.work;
                sys.forcing_angular_impulse += inc.angular_impulse;
            })
        }
    }
    /// The diagnostics row at an output sample (time `t`, s), then the release check.
    fn sample(&mut self, sys: &SoftSystem, t: f64) -> std::io::Result<()> {
        let d = diagnose_run(sys, &self.driver, t);
        let line = if self.legacy { d.csv_row_legacy() } else { d.csv_row() };
        self.csv.write_all(line.as_bytes())?;
        self.csv.flush()?;
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
    let mut w = crate::io::safe_write::AtomicFile::create(path)?;
    writeln!(w, "t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz")?;
    for (id, p) in particles.iter().enumerate() {
        let (x, v, s) = (p.position, p.velocity, p.spin);
        writeln!(
            w,
            "{t},{id},{},{},{},{},{},{},{},{},{},{},{}",
            p.mass, p.radius, x.x, x.y, x.z, v.x, v.y, v.z, s.x, s.y, s.z
        )?;
    }
    w.finish()
}

/// The particle–particle contacts of `sys` at time `t` (s) with their normal forces, from one force evaluation on a
/// copy (the run's own state and spring histories are untouched; the normal force needs no history).
fn contact_lines(sys: &SoftSystem, t: f64) -> Vec<ContactLine> {
    let mut probe = sys.clone();
    probe.keep_records = true;
    probe.compute_forces(t, 0.0);
    let n = probe.particles.len();
    probe
        .records
        .iter()
        .filter(|r| r.j < n)
        .map(|r| ContactLine {
            i: r.i,
            j: r.j,
            normal_force: r.output.normal_force,
        })
        .collect()
}

/// The walls at time `t` (s); planes cut to a patch reaching past every particle.
fn wall_surfaces(
    walls: &[crate::geometry::walls::soft::Wall],
    t: f64,
    particles: &[ParticleView],
) -> Vec<NamedSurface> {
    let reach = |w: &crate::geometry::walls::soft::Wall| crate::engine::reach(particles, &w.anchor());
    crate::granular::wall_surfaces(walls.iter().map(|w| w.surface_at(t, reach(w))))
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

/// What a soft-sphere run's checkpoint holds beside the driver's envelope: every particle's state, the last forces
/// and torques (leapfrog needs them), the spring histories and the bookkeeping, as exact f64 bit patterns.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SoftState {
    step: u64,
    /// Per particle: x, v, ω, F, τ (15 numbers).
    #[serde(with = "exact_f64_vec")]
    state: Vec<f64>,
    pair_springs: Vec<SpringRecord>,
    wall_springs: Vec<SpringRecord>,
    /// dissipated, wall_work, forcing_work, forcing angular impulse (x, y, z).
    #[serde(with = "exact_f64_vec")]
    work: Vec<f64>,
    /// Steps taken in the current self-gravity block (r-RESPA; 0 without).
    gravity_phase: u64,
    /// Self-gravity accelerations of the block's start (3 per particle) and its potential energy, when
    /// `[gravity] interval_steps > 1`; empty otherwise.
    #[serde(with = "exact_f64_vec")]
    slow: Vec<f64>,
    #[serde(with = "exact_f64_vec")]
    book: Vec<f64>,
    /// The spin-up driver's state and the length of `spinup.csv`, for a `[spinup]` scene.
    spinup: Option<SpinupCheckpoint>,
}

/// A soft-sphere run (Zhang17): leapfrog steps of a fixed `dt`, with the spin-up forcing after every step when the
/// scene has a `[spinup]` table.
pub struct SoftEngine {
    scene: SoftScene,
    sys: SoftSystem,
    step: u64,
    book: Book,
    spin: Option<SpinRun>,
    plan: Vec<(u64, Option<usize>)>,
    /// The state before the current step, kept for `last_good_state.csv` (allocated once).
    before: Vec<Particle>,
    /// Wall-clock instant after which an advance stops ([`Engine::set_deadline`]).
    deadline: Option<std::time::Instant>,
}

impl SoftEngine {
    /// The engine for a validated scene, forces evaluated at t = 0.
    pub fn new(scene: SoftScene) -> Self {
        let mut sys = SoftSystem::new(
            scene.particles.clone(),
            scene.walls.clone(),
            scene.material,
            scene.gravity,
        );
        sys.gravity_interval = scene.gravity_interval;
        sys.compute_forces(0.0, 0.0);
        let book = Book::new(&sys);
        let plan = sample_steps(&scene);
        let before = sys.particles.clone();
        SoftEngine {
            scene,
            sys,
            step: 0,
            book,
            spin: None,
            plan,
            before,
            deadline: None,
        }
    }

    /// Loads and validates the scene file at `path`. Errors are one line naming the field.
    pub fn load(path: &Path) -> Result<Self, EngineError> {
        Ok(SoftEngine::new(load_soft_scene(path)?))
    }

    /// The scene's warnings (e.g. a step longer than advised).
    pub fn scene_warnings(&self) -> &[String] {
        &self.scene.warnings
    }

    /// What the scene resolves to, for `rubblepile check`.
    pub fn describe(&self) -> Vec<String> {
        let s = &self.scene;
        vec![
            format!("{}: ok", s.name),
            format!(
                "  {} particles, {} walls, t_end = {} s, dt = {} s ({} steps)",
                s.particles.len(),
                s.walls.len(),
                s.t_end,
                s.dt,
                s.n_steps
            ),
            format!(
                "  k_n = {:e} N/m (advised {:e} N/m, dt {:e} s)",
                s.material.k_n, s.advice.k_n, s.advice.dt
            ),
        ]
    }
}

impl Engine for SoftEngine {
    type Summary = SoftSummary;
    type State = SoftState;
    const KIND: &'static str = crate::granular::soft::scene::KIND;

    fn from_scene_text(text: &str, name: &str, base_dir: Option<&Path>) -> Result<Self, EngineError> {
        Ok(SoftEngine::new(parse_soft_scene(text, name, base_dir)?))
    }

    /// One thread per [`SPHERES_PER_THREAD`] spheres, at least one (the bits do not depend on it).
    fn useful_threads(&self) -> usize {
        (self.sys.particles.len() / SPHERES_PER_THREAD).max(1)
    }

    fn scene_source(&self) -> &str {
        &self.scene.source
    }

    fn estimated_steps(&self) -> Option<f64> {
        Some(self.scene.n_steps as f64)
    }

    fn steps_taken(&self) -> u64 {
        self.step
    }

    fn set_deadline(&mut self, deadline: Option<std::time::Instant>) {
        self.deadline = deadline;
    }

    fn error_so_far(&self) -> Option<(&'static str, f64)> {
        Some(("energy error", self.book.max_energy))
    }

    fn scene_base_dir(&self) -> Option<&Path> {
        self.scene.base_dir.as_deref()
    }

    fn t_end(&self) -> f64 {
        self.scene.t_end
    }

    fn time(&self) -> f64 {
        self.step as f64 * self.scene.dt
    }

    fn samples(&self) -> Vec<Sample> {
        self.plan
            .iter()
            .map(|&(step, snapshot)| Sample {
                t: step as f64 * self.scene.dt,
                snapshot,
            })
            .collect()
    }

    fn timeseries_header(&self) -> String {
        TIMESERIES_HEADER.to_string()
    }

    fn open_outputs(&mut self, dir: &Path) -> std::io::Result<()> {
        if let Some(settings) = &self.scene.spinup {
            // the body starts on the path (T_start) and the t = 0 sample needs the contact records
            let sys = &mut self.sys;
            let driver = SpinupDriver::new(*settings, &self.scene.particles);
            let member = central_body(&sys.particles, sys.touching_pairs());
            driver.apply(&mut sys.particles, &member, 0.0);
            sys.keep_records = true;
            sys.set_pair_springs(Vec::new());
            sys.compute_forces(0.0, 0.0);
            let mut csv = BufWriter::new(crate::io::safe_write::create_fresh(&dir.join("spinup.csv"))?);
            csv.write_all(SPINUP_HEADER.as_bytes())?;
            self.spin = Some(SpinRun {
                driver,
                csv,
                bytes: SPINUP_HEADER.len() as u64,
                legacy: false,
            });
            self.book = Book::new(&self.sys);
        }
        Ok(())
    }

    fn advance(&mut self, index: usize, _to: &Sample, progress: &mut dyn FnMut(f64)) -> Result<(), Failure> {
        let sample_step = self.plan[index].0;
        let dt = self.scene.dt;
        let sys = &mut self.sys;
        while self.step < sample_step {
            let step = self.step;
            if step.is_multiple_of(256) {
                progress(step as f64 * dt);
                if self.deadline.is_some_and(|d| std::time::Instant::now() >= d) {
                    return Err(Failure::deadline(step as f64 * dt));
                }
            }
            // the spin-up diagnostics at a sample need that step's contact records
            sys.keep_records = self.spin.is_some() && step + 1 == sample_step;
            // the spring energy is read only at samples (the energy residual of the row)
            sys.spring_energy_wanted = step + 1 == sample_step;
            let spin = &self.spin;
            checked_step(sys, &mut self.before, step, dt, |sys, t| {
                if let Some(s) = spin {
                    s.after_step(sys, t)
                }
            })
            .map_err(Failure::new)?;
            self.book.max_overlap = self.book.max_overlap.max(sys.stats.max_overlap_fraction);
            self.step += 1;
        }
        Ok(())
    }

    fn sample(&mut self, _to: &Sample, wall_seconds: f64) -> Result<String, SampleError> {
        let line = row(&self.scene, &self.sys, &mut self.book, self.step, wall_seconds);
        let t = self.time();
        if let Some(s) = self.spin.as_mut() {
            s.sample(&self.sys, t).map_err(|source| SampleError::Io {
                path: "spinup.csv".into(),
                source,
            })?;
        }
        Ok(line)
    }

    fn write_snapshot(&self, path: &Path) -> std::io::Result<()> {
        write_particles_csv(path, self.time(), &self.sys.particles)
    }

    fn particles(&self) -> Vec<ParticleView> {
        self.sys
            .particles
            .iter()
            .enumerate()
            .map(|(id, p)| ParticleView::sphere(id, p.mass, p.radius, p.position, p.velocity, p.spin))
            .collect()
    }

    const SPHERES: bool = true;

    fn contacts(&self) -> Option<Vec<ContactLine>> {
        Some(contact_lines(&self.sys, self.time()))
    }

    fn surfaces(&self) -> Vec<NamedSurface> {
        wall_surfaces(&self.sys.walls, self.time(), &self.particles())
    }

    fn view_of_snapshot(&self, path: &Path) -> Result<SnapshotView, EngineError> {
        let (t, particles) = read_sphere_snapshot(path)?;
        let surfaces = wall_surfaces(&self.sys.walls, t, &particles);
        let mut sys = self.sys.clone();
        if particles.len() != sys.particles.len() {
            return Err(EngineError::File {
                path: path.to_path_buf(),
                reason: format!("{} particles, the scene has {}", particles.len(), sys.particles.len()),
            });
        }
        for (p, v) in sys.particles.iter_mut().zip(&particles) {
            (p.position, p.velocity, p.spin) = (v.position, v.velocity, v.spin_world);
        }
        Ok(SnapshotView {
            t,
            spheres: true,
            contacts: Some(contact_lines(&sys, t)),
            particles,
            surfaces,
            ..Default::default()
        })
    }

    fn scene_vtk(&self) -> bool {
        self.scene.vtk
    }

    fn write_last_good_state(&self, path: &Path) -> std::io::Result<f64> {
        let t_good = self.time();
        write_particles_csv(path, t_good, &self.before)?;
        Ok(t_good)
    }

    fn summary(&self, outcome: Outcome<'_>, samples: u64, wall_seconds: f64) -> SoftSummary {
        let status = match outcome {
            Outcome::Completed => "completed".to_string(),
            Outcome::Failed(f) => format!("failed: {} at t = {} s", f.cause, self.time() + self.scene.dt),
        };
        let (scene, sys, book) = (&self.scene, &self.sys, &self.book);
        SoftSummary {
            status,
            kind: crate::granular::soft::scene::KIND.into(),
            wall_seconds,
            energy_error: book.max_energy,
            final_energy_residual: book.last_energy,
            momentum_error: book.max_p,
            angular_momentum_error: book.max_l,
            max_overlap_fraction: book.max_overlap,
            final_time: self.time(),
            t_end: scene.t_end,
            steps: self.step,
            dt: scene.dt,
            samples,
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

    fn save(&mut self) -> std::io::Result<SoftState> {
        let sys = &self.sys;
        let mut state = Vec::with_capacity(15 * sys.particles.len());
        for (k, p) in sys.particles.iter().enumerate() {
            for v in [p.position, p.velocity, p.spin, sys.forces[k], sys.torques[k]] {
                state.extend(v.iter());
            }
        }
        Ok(SoftState {
            step: self.step,
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
            book: self.book.to_vec(),
            spinup: self.spin.as_ref().map(|s| SpinupCheckpoint {
                state: s.driver.state(),
                bytes: s.bytes,
            }),
        })
    }

    fn restore(&mut self, ck: SoftState, dir: &Path, at: Resumed) -> Result<(), EngineError> {
        self.restore_from(ck, dir, at).map_err(EngineError::State)
    }
}

impl SoftEngine {
    /// Sets the spheres' positions (m), velocities (m/s) and spins (rad/s, world frame), one entry per sphere in
    /// scene order, between two output samples; the run continues from them. What the stepper keeps from the last
    /// step is made to match: the Verlet list is rebuilt, and the forces and torques (which the next step's first
    /// kick uses) are evaluated again at the new state without advancing the contacts' springs (the springs of
    /// pairs still touching are kept; the others are dropped by that evaluation). Masses and radii are the
    /// scene's. The conserved quantities are still measured against t = 0, so a change of energy counts in the
    /// energy error; a `[spinup]` forcing goes on from the new spin.
    ///
    /// Errors ([`EngineError::State`], one line, nothing changed): another number of spheres, a non-finite value,
    /// a run inside a self-gravity block (`[gravity] interval_steps > 1` and the step not on a block boundary:
    /// the block's opening kick used the old positions).
    pub fn set_particles(
        &mut self,
        positions: &[Vec3],
        velocities: &[Vec3],
        spins: &[Vec3],
    ) -> Result<(), EngineError> {
        let arrays = [("positions", positions), ("velocities", velocities), ("spins", spins)];
        crate::granular::check_particle_arrays(self.sys.particles.len(), "spheres", arrays)?;
        if self.sys.split_gravity() && self.sys.gravity_phase != 0 {
            return Err(EngineError::State(format!(
                "the run is inside a self-gravity block (step {} of {}); set the state at a block boundary",
                self.sys.gravity_phase, self.sys.gravity_interval
            )));
        }
        for (k, p) in self.sys.particles.iter_mut().enumerate() {
            p.position = positions[k];
            p.velocity = velocities[k];
            p.spin = spins[k];
        }
        // the same springs, for a Verlet list rebuilt at the new positions
        let springs = self.sys.pair_springs();
        self.sys.set_pair_springs(springs);
        if self.sys.split_gravity() {
            self.sys.update_slow_gravity();
        }
        let t = self.time();
        self.sys.compute_forces(t, 0.0);
        self.before.clone_from(&self.sys.particles);
        Ok(())
    }

    /// [`Engine::restore`] with one-line `String` errors (made [`EngineError::State`] there).
    fn restore_from(&mut self, ck: SoftState, dir: &Path, _at: Resumed) -> Result<(), String> {
        let scene = &self.scene;
        let n = scene.particles.len();
        if ck.state.len() != 15 * n {
            return Err(format!(
                "the checkpoint holds {} numbers for {n} particles",
                ck.state.len()
            ));
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
        sys.set_pair_springs(unpack(&ck.pair_springs).ok_or("malformed pair springs")?);
        sys.wall_springs = unpack(&ck.wall_springs).ok_or("malformed wall springs")?;
        if ck.work.len() != 6 {
            return Err("malformed work record".into());
        }
        sys.dissipated = ck.work[0];
        sys.wall_work = ck.work[1];
        sys.forcing_work = ck.work[2];
        sys.forcing_angular_impulse = Vec3::new(ck.work[3], ck.work[4], ck.work[5]);
        sys.gravity_interval = scene.gravity_interval;
        if sys.split_gravity() {
            if ck.slow.len() != 3 * n + 1 || ck.gravity_phase >= scene.gravity_interval {
                return Err("malformed self-gravity block record (slow, gravity_phase)".into());
            }
            sys.gravity_phase = ck.gravity_phase;
            sys.slow_accelerations = ck.slow[..3 * n]
                .chunks(3)
                .map(|c| Vec3::new(c[0], c[1], c[2]))
                .collect();
            sys.slow_energy = ck.slow[3 * n];
        }
        self.book = Book::from_vec(&ck.book).ok_or("malformed bookkeeping")?;
        self.spin = match (&scene.spinup, &ck.spinup) {
            (Some(settings), Some(sc)) => {
                let mut driver = SpinupDriver::new(*settings, &scene.particles);
                driver.restore(&sc.state).ok_or("malformed spin-up state")?;
                let path = dir.join("spinup.csv");
                let legacy = first_line(&path).is_some_and(|h| h == SPINUP_HEADER_LEGACY.trim_end());
                let f = crate::engine::reopen_truncated(&path, sc.bytes).map_err(|e| e.to_string())?;
                Some(SpinRun {
                    driver,
                    csv: BufWriter::new(f),
                    bytes: sc.bytes,
                    legacy,
                })
            }
            (None, None) => None,
            _ => return Err("the checkpoint and the scene disagree on [spinup]".into()),
        };
        self.before = sys.particles.clone();
        self.sys = sys;
        self.step = ck.step;
        Ok(())
    }
}
