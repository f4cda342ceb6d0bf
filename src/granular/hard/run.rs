//! The hard-sphere engine as the run driver (`driver`) sees it: `timeseries.csv` in [`TIMESERIES_COLUMNS`]
//! (flushed row by row), `snapshots/<k>.csv` in the particles-file columns, `summary.json` as [`HardRunSummary`]
//! (status, wall_seconds, energy error, collision count, events per second, max overlap, absorbed count) and, on
//! failure, `last_good_state.csv` with the cause in the summary. Checkpoints ([`HardState`]) continue bit for bit
//! (`rubblepile resume DIR`).

use std::io::Write;
use std::path::Path;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::particle::Attachment;
use super::scene::{HardScene, PARTICLE_COLUMNS, STUCK_COLUMN};
use super::stepper::{Counters, Diagnostics, NeighbourState, System};
use crate::bits::exact_f64_vec;
use crate::engine::{
    Engine, EngineError, Failure, MOMENTUM_COLUMNS, NamedSurface, Outcome, ParticleView, Resumed, RunReport, Sample,
    SampleError, Schedule, SnapshotView, column_names, momentum_values, read_sphere_snapshot,
};
use crate::io::fmt_f64;
use crate::math::Vec3;

/// Columns of `timeseries.csv`.
pub const TIMESERIES_COLUMNS: [&str; 22] = column_names(&[
    &[
        "t",
        "kinetic",
        "rotational",
        "potential",
        "energy",
        "energy_change",
        "energy_residual",
    ],
    &MOMENTUM_COLUMNS,
    &[
        "collisions",
        "pair_collisions",
        "wall_collisions",
        "events_per_second",
        "max_overlap",
        "free",
        "stuck",
        "absorbed",
        "wall_seconds",
    ],
]);

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
    /// The error: largest |E − E0 − exchanged| / scale over the samples (scale = max(|E0|, kinetic at t = 0)), the
    /// bookkeeping residual once the energy lost to restitution, the walls' work and what sticking and absorbed
    /// particles took away are accounted for.
    pub energy_error: f64,
    /// Largest |E − E0| / scale: how much the energy changed (physics, not an error, with restitution < 1 or moving
    /// walls).
    pub energy_change: f64,
    /// Energy exchanged in collisions, sticking and absorption (J): `energy_restitution + energy_walls +
    /// energy_removed`.
    pub energy_exchanged: f64,
    /// Energy lost to restitution (J, ≤ 0 for restitution ≤ 1), in the frame of each contact.
    pub energy_restitution: f64,
    /// Work done by moving walls on the free particles (J).
    pub energy_walls: f64,
    /// Energy taken out with particles that stuck or were absorbed (J).
    pub energy_removed: f64,
    /// The error: largest |P − P0 − J_walls − J_field| (kg m/s), the momentum residual once the walls' and the
    /// gravity field's impulses are accounted for.
    pub momentum_error: f64,
    /// Largest |P − P0| (kg m/s): how much the momentum changed (physics, not an error, with walls or gravity).
    pub momentum_change: f64,
    /// |J_walls| at the end (kg m/s): momentum the walls gave the free particles (bounces, stuck particles'
    /// contacts, minus what sticking and absorbed particles took away).
    pub wall_impulse: f64,
    /// |J_field| at the end (kg m/s): momentum the uniform gravity field gave the free particles.
    pub field_impulse: f64,
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

/// The walls at time `t` (s), unbounded ones cut to a piece reaching past every particle.
fn wall_surfaces(walls: &[crate::geometry::walls::Wall], t: f64, particles: &[ParticleView]) -> Vec<NamedSurface> {
    let reach = |w: &crate::geometry::walls::Wall| crate::engine::reach(particles, &w.origin_at(t));
    crate::granular::wall_surfaces(walls.iter().map(|w| w.surface_at(t, reach(w))))
}

/// Writes the alive particles in the particles-file columns.
pub fn write_particles(path: &Path, t: f64, system: &System) -> std::io::Result<()> {
    let mut w = crate::io::safe_write::AtomicFile::create(path)?;
    writeln!(w, "{},{STUCK_COLUMN}", PARTICLE_COLUMNS.join(","))?;
    for p in system.particles.iter().filter(|p| p.alive) {
        let v = crate::io::particles::sphere_state(p.mass, p.radius, &p.position, &p.velocity, &p.spin);
        let cols: Vec<String> = v.iter().map(|&x| fmt_f64(x)).collect();
        let stuck = p.stuck.map_or(-1, |a| a.wall as i64);
        writeln!(w, "{},{},{},{stuck}", fmt_f64(t), p.id, cols.join(","))?;
    }
    w.finish()
}

/// Numbers in a checkpoint's bookkeeping ([`HardState`]'s `book`).
const BOOK_LEN: usize = 20;

/// Numbers per particle in a checkpoint.
const PARTICLE_STATE: usize = 16;

/// Bookkeeping of a run (energy and momentum references and the largest errors so far).
#[derive(Debug, Clone, Copy, Default)]
struct Book {
    e0: f64,
    scale: f64,
    energy_change: f64,
    energy_residual: f64,
    momentum_error: f64,
    momentum_change: f64,
    p0: Vec3,
}

/// The counters of a checkpoint ([`HardState::counts`]), in their order there: the one table of save and restore.
fn count_slots(c: &mut Counters) -> [&mut u64; 7] {
    [
        &mut c.pair_collisions,
        &mut c.wall_collisions,
        &mut c.events,
        &mut c.guarded,
        &mut c.rebuilds,
        &mut c.reanchors,
        &mut c.absorbed,
    ]
}

/// The bookkeeping numbers of a checkpoint ([`HardState::book`]) in the counters and the book, in their order
/// there: the one table of save and restore.
fn book_slots<'a>(c: &'a mut Counters, b: &'a mut Book) -> [&'a mut f64; BOOK_LEN] {
    use nalgebra::base::coordinates::XYZ;
    let XYZ { x: px, y: py, z: pz } = &mut *b.p0;
    let XYZ { x: wx, y: wy, z: wz } = &mut *c.wall_impulse;
    let XYZ { x: fx, y: fy, z: fz } = &mut *c.field_impulse;
    [
        &mut c.max_overlap,
        &mut c.energy_exchanged,
        &mut b.e0,
        &mut b.scale,
        &mut b.energy_change,
        &mut b.energy_residual,
        &mut b.momentum_error,
        px,
        py,
        pz,
        &mut c.energy_restitution,
        &mut c.energy_walls,
        &mut c.energy_removed,
        wx,
        wy,
        wz,
        fx,
        fy,
        fz,
        &mut b.momentum_change,
    ]
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

impl RunReport for HardRunSummary {
    fn one_line(&self) -> String {
        format!(
            "{}: t = {} s, {} steps, {} collisions ({:.3e} events/s), energy error {:.2e} (change {:.2e}: restitution {:.2e} J, walls {:.2e} J, removed {:.2e} J), momentum error {:.2e} kg m/s (change {:.2e}), max overlap {:.2e}, {} absorbed, {:.2} s",
            self.status,
            crate::io::messages::fmt_time(self.t_reached),
            self.steps,
            self.collisions,
            self.events_per_second,
            self.energy_error,
            self.energy_change,
            self.energy_restitution,
            self.energy_walls,
            self.energy_removed,
            self.momentum_error,
            self.momentum_change,
            self.max_overlap,
            self.absorbed,
            self.wall_seconds
        )
    }
}

/// What a hard-sphere run's checkpoint holds beside the driver's envelope. Every `f64` that influences the
/// continuation is stored as its bit pattern.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct HardState {
    steps: u64,
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
    /// max_overlap, energy_exchanged, then the run's book: E0, scale, energy change, residual, momentum error, P0;
    /// then the energy lost to restitution, the walls' work, the energy removed, the walls' and the field's
    /// impulses and the largest momentum change.
    #[serde(with = "exact_f64_vec")]
    book: Vec<f64>,
    /// Counters at the last time-series row: collisions, pair, wall, events.
    last_counts: [u64; 4],
    #[serde(with = "crate::bits::exact_f64")]
    last_wall_clock: f64,
}

/// A hard-sphere run (Richardson11): steps of `dt` within which collisions are predicted and applied in time order.
pub struct HardEngine {
    scene: HardScene,
    system: System,
    /// The state at the start of the current sample interval: the last good state if a step fails.
    good: System,
    steps: u64,
    book: Book,
    last_counts: [u64; 4],
    last_wall_clock: f64,
    /// Events when this process started, and its clock (for the summary's events per second).
    events_before: u64,
    clock: Instant,
    /// Wall-clock instant after which an advance stops ([`Engine::set_deadline`]).
    deadline: Option<Instant>,
}

impl HardEngine {
    /// The engine for a validated scene, at t = 0.
    pub fn new(scene: HardScene) -> Self {
        let system = System::new(scene.particles.clone(), scene.walls.clone(), scene.settings);
        let d0 = system.diagnostics();
        let book = Book {
            e0: d0.energy(),
            scale: d0.energy().abs().max(d0.kinetic + d0.rotational).max(f64::MIN_POSITIVE),
            p0: d0.momentum,
            ..Book::default()
        };
        HardEngine {
            scene,
            good: system.clone(),
            system,
            steps: 0,
            book,
            last_counts: [0; 4],
            last_wall_clock: 0.0,
            events_before: 0,
            clock: Instant::now(),
            deadline: None,
        }
    }

    /// Loads and validates the scene file at `path`. Errors are one line naming the field.
    pub fn load(path: &Path) -> Result<Self, EngineError> {
        Ok(HardEngine::new(super::scene::load_hard_scene(path)?))
    }

    /// The scene's warnings ([`super::scene::HardScene::warnings`]), printed by `rubblepile check` and before a run.
    pub fn scene_warnings(&self) -> &[String] {
        &self.scene.warnings
    }

    /// What the scene resolves to, for `rubblepile check`.
    pub fn describe(&self) -> Vec<String> {
        let s = &self.scene;
        vec![format!(
            "{}: hard spheres: {} particles, {} walls, t_end = {} s, dt = {} s, {} snapshots, a time-series row every \
             {} s",
            s.name,
            s.particles.len(),
            s.walls.len(),
            s.t_end,
            s.dt,
            s.times.len(),
            s.every
        )]
    }
}

impl Engine for HardEngine {
    type Summary = HardRunSummary;
    type State = HardState;
    const KIND: &'static str = super::scene::KIND;

    /// The event loop is serial (Richardson11 §2.1: one globally earliest event at a time): one thread, so that
    /// no idle worker of the pool polls for work beside it.
    fn useful_threads(&self) -> usize {
        1
    }

    fn from_scene_text(text: &str, name: &str, base_dir: Option<&Path>) -> Result<Self, EngineError> {
        let base = base_dir.unwrap_or(Path::new("."));
        Ok(HardEngine::new(super::scene::parse_hard_scene(text, name, base)?))
    }

    fn scene_source(&self) -> &str {
        &self.scene.source
    }

    fn estimated_steps(&self) -> Option<f64> {
        Some((self.scene.t_end / self.scene.dt).ceil())
    }

    fn steps_taken(&self) -> u64 {
        self.steps
    }

    fn set_deadline(&mut self, deadline: Option<Instant>) {
        self.deadline = deadline;
    }

    fn error_so_far(&self) -> Option<(&'static str, f64)> {
        // Restitution and moving walls change the energy on purpose: the residual after them is the error.
        Some(("energy residual", self.book.energy_residual))
    }

    fn scene_base_dir(&self) -> Option<&Path> {
        Some(&self.scene.base_dir)
    }

    fn t_end(&self) -> f64 {
        self.scene.t_end
    }

    fn time(&self) -> f64 {
        self.system.t
    }

    fn samples(&self) -> Vec<Sample> {
        Schedule::new(self.scene.t_end, self.scene.every, &self.scene.times).collect()
    }

    fn timeseries_header(&self) -> String {
        format!("{}\n", TIMESERIES_COLUMNS.join(","))
    }

    fn open_outputs(&mut self, _dir: &Path) -> std::io::Result<()> {
        Ok(())
    }

    fn advance(&mut self, _index: usize, to: &Sample, progress: &mut dyn FnMut(f64)) -> Result<(), Failure> {
        self.good.clone_from(&self.system);
        let dt = self.scene.dt;
        while self.system.t < to.t {
            if self.steps.is_multiple_of(64) {
                progress(self.system.t);
                if self.deadline.is_some_and(|d| Instant::now() >= d) {
                    return Err(Failure::deadline(self.system.t));
                }
            }
            let left = to.t - self.system.t;
            let h = if left < 1.000001 * dt { left } else { dt };
            self.system.step(h).map_err(|e| Failure::new(e.to_string()))?;
            self.steps += 1;
            if left == h {
                self.system.t = to.t;
            }
        }
        Ok(())
    }

    fn sample(&mut self, to: &Sample, wall: f64) -> Result<String, SampleError> {
        let system = &self.system;
        let book = &mut self.book;
        let d: Diagnostics = system.diagnostics();
        let c = system.counters;
        let e = d.energy();
        book.energy_change = book.energy_change.max((e - book.e0).abs() / book.scale);
        book.energy_residual = book
            .energy_residual
            .max((e - book.e0 - c.energy_exchanged).abs() / book.scale);
        book.momentum_change = book.momentum_change.max((d.momentum - book.p0).norm());
        book.momentum_error = book
            .momentum_error
            .max((d.momentum - book.p0 - c.wall_impulse - c.field_impulse).norm());
        let [last_coll, last_pair, last_wall, last_events] = self.last_counts;
        let coll = c.pair_collisions + c.wall_collisions;
        let eps = if wall > self.last_wall_clock {
            (c.events - last_events) as f64 / (wall - self.last_wall_clock)
        } else {
            0.0
        };
        let energies = [
            to.t,
            d.kinetic,
            d.rotational,
            d.potential,
            e,
            (e - book.e0) / book.scale,
            (e - book.e0 - c.energy_exchanged) / book.scale,
        ];
        let events = [
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
        let momenta = momentum_values(&d.momentum, &d.angular_momentum);
        let cols: Vec<String> = energies
            .iter()
            .chain(&momenta)
            .chain(&events)
            .map(|&x| fmt_f64(x))
            .collect();
        self.last_counts = [coll, c.pair_collisions, c.wall_collisions, c.events];
        self.last_wall_clock = wall;
        Ok(cols.join(",") + "\n")
    }

    fn write_snapshot(&self, path: &Path) -> std::io::Result<()> {
        write_particles(path, self.system.t, &self.system)
    }

    fn particles(&self) -> Vec<ParticleView> {
        self.system
            .particles
            .iter()
            .filter(|p| p.alive)
            .map(|p| ParticleView::sphere(p.id, p.mass, p.radius, p.position, p.velocity, p.spin))
            .collect()
    }

    const SPHERES: bool = true;

    fn surfaces(&self) -> Vec<NamedSurface> {
        wall_surfaces(&self.system.walls, self.system.t, &self.particles())
    }

    fn view_of_snapshot(&self, path: &Path) -> Result<SnapshotView, EngineError> {
        let (t, particles) = read_sphere_snapshot(path)?;
        Ok(SnapshotView {
            t,
            spheres: true,
            surfaces: wall_surfaces(&self.system.walls, t, &particles),
            particles,
            ..Default::default()
        })
    }

    fn scene_vtk(&self) -> bool {
        self.scene.file.output.vtk
    }

    fn write_last_good_state(&self, path: &Path) -> std::io::Result<f64> {
        write_particles(path, self.good.t, &self.good)?;
        Ok(self.good.t)
    }

    fn summary(&self, outcome: Outcome<'_>, _samples: u64, wall_seconds: f64) -> HardRunSummary {
        let (state, status) = match outcome {
            Outcome::Completed => (&self.system, "completed".to_string()),
            Outcome::Failed(f) => (&self.good, f.cause.clone()),
        };
        let c = self.system.counters;
        let d = state.diagnostics();
        let book = &self.book;
        let this_process = self.clock.elapsed().as_secs_f64();
        HardRunSummary {
            status,
            kind: super::scene::KIND.into(),
            scene: self.scene.name.clone(),
            seed: self.scene.seed,
            t_end: self.scene.t_end,
            t_reached: state.t,
            steps: self.steps,
            particles: self.scene.particles.len(),
            wall_seconds,
            energy_initial: book.e0,
            energy_final: d.energy(),
            energy_error: book.energy_residual,
            energy_change: book.energy_change,
            energy_exchanged: c.energy_exchanged,
            energy_restitution: c.energy_restitution,
            energy_walls: c.energy_walls,
            energy_removed: c.energy_removed,
            momentum_error: book.momentum_error,
            momentum_change: book.momentum_change,
            wall_impulse: c.wall_impulse.norm(),
            field_impulse: c.field_impulse.norm(),
            collisions: c.pair_collisions + c.wall_collisions,
            pair_collisions: c.pair_collisions,
            wall_collisions: c.wall_collisions,
            events: c.events,
            events_per_second: if this_process > 0.0 {
                (c.events - self.events_before) as f64 / this_process
            } else {
                0.0
            },
            guarded_collisions: c.guarded,
            neighbour_rebuilds: c.rebuilds,
            neighbour_reanchors: c.reanchors,
            max_overlap: c.max_overlap,
            absorbed: c.absorbed,
            stuck: d.stuck,
        }
    }

    fn save(&mut self) -> std::io::Result<HardState> {
        let system = &self.system;
        let (mut c, mut book) = (system.counters, self.book);
        let nb = system.neighbour_state();
        Ok(HardState {
            steps: self.steps,
            state: pack_particles(system),
            anchors: nb
                .as_ref()
                .map(|s| s.anchors.iter().flat_map(|a| a.iter().copied()).collect())
                .unwrap_or_default(),
            allowances: nb.as_ref().map(|s| s.allowances.clone()).unwrap_or_default(),
            counts: count_slots(&mut c).map(|x| *x),
            book: book_slots(&mut c, &mut book).map(|x| *x).to_vec(),
            last_counts: self.last_counts,
            last_wall_clock: self.last_wall_clock,
        })
    }

    fn restore(&mut self, ck: HardState, dir: &Path, at: Resumed) -> Result<(), EngineError> {
        self.restore_from(ck, dir, at).map_err(EngineError::State)
    }
}

impl HardEngine {
    /// Sets the positions (m), velocities (m/s) and spins (rad/s, world frame) of the particles still in the run
    /// (those [`Engine::particles`] lists, in that order) between two output samples; the run continues from them.
    /// What the stepper keeps from the last step is dropped: the neighbour list, the certificates of the pairs
    /// that cannot meet for a while and the predicted collisions are rebuilt from the new state at the next step,
    /// as after a fresh start. Masses and radii are the scene's; a particle stuck to a wall keeps its state (giving
    /// it another is refused). The conserved quantities are still measured against t = 0. New positions must not
    /// overlap (the run's maximum-overlap diagnostic would report it).
    ///
    /// Errors ([`EngineError::State`], one line, nothing changed): another number of particles, a non-finite
    /// value, a changed state of a particle stuck to a wall.
    pub fn set_particles(
        &mut self,
        positions: &[Vec3],
        velocities: &[Vec3],
        spins: &[Vec3],
    ) -> Result<(), EngineError> {
        let alive: Vec<usize> = (0..self.system.particles.len())
            .filter(|&k| self.system.particles[k].alive)
            .collect();
        let arrays = [("positions", positions), ("velocities", velocities), ("spins", spins)];
        crate::granular::check_particle_arrays(alive.len(), "particles", arrays)?;
        for (i, &k) in alive.iter().enumerate() {
            let p = &self.system.particles[k];
            let same = p.position == positions[i] && p.velocity == velocities[i] && p.spin == spins[i];
            if p.stuck.is_some() && !same {
                return Err(EngineError::State(format!(
                    "particle {i}: stuck to a wall, its state cannot change"
                )));
            }
        }
        let t = self.system.t;
        for (i, &k) in alive.iter().enumerate() {
            let p = &mut self.system.particles[k];
            p.position = positions[i];
            p.velocity = velocities[i];
            p.spin = spins[i];
            p.t_local = t;
        }
        self.system.restore_neighbours(None).map_err(EngineError::State)?;
        self.good = self.system.clone();
        Ok(())
    }

    /// [`Engine::restore`] with one-line `String` errors (made [`EngineError::State`] there).
    fn restore_from(&mut self, ck: HardState, _dir: &Path, at: Resumed) -> Result<(), String> {
        let system = &mut self.system;
        unpack_particles(system, &ck.state)?;
        system.t = at.t;
        let anchors = match ck.anchors.len() {
            0 => None,
            n if n == 3 * system.particles.len() => Some(NeighbourState {
                anchors: ck.anchors.chunks(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect(),
                allowances: ck.allowances.clone(),
            }),
            n => return Err(format!("{n} anchor numbers for {} particles", system.particles.len())),
        };
        system.restore_neighbours(anchors)?;
        if ck.book.len() != BOOK_LEN {
            return Err(format!(
                "malformed bookkeeping: {} numbers, expected {BOOK_LEN} (a checkpoint from before the energy and \
                 momentum exchanges were split cannot be resumed)",
                ck.book.len()
            ));
        }
        let (mut counters, mut book) = (Counters::default(), Book::default());
        for (slot, &n) in count_slots(&mut counters).into_iter().zip(&ck.counts) {
            *slot = n;
        }
        for (slot, &x) in book_slots(&mut counters, &mut book).into_iter().zip(&ck.book) {
            *slot = x;
        }
        system.counters = counters;
        self.book = book;
        self.steps = ck.steps;
        self.last_counts = ck.last_counts;
        self.last_wall_clock = ck.last_wall_clock;
        self.events_before = counters.events;
        self.good = self.system.clone();
        self.clock = Instant::now();
        Ok(())
    }
}
