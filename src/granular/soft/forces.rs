//! Forces and torques on every sphere (Zhang17 Eq. 1): self-gravity (direct or octree), a uniform external
//! field, and the contact law ([`crate::granular::soft::contact`]) for every touching pair and every
//! sphere–wall contact.
//!
//! The pair contacts (Verlet list, springs, evaluation in a fixed order on any number of threads) are in
//! [`crate::granular::soft::pairs`]. Wall histories live in a vector sorted by `(i, wall)`. Every per-sphere
//! pass runs in parallel, and the scalar sums over the spheres (gravitational energy) are taken in fixed chunks
//! (`ordered_sum`), so the results do not depend on the number of threads.

use crate::geometry::walls::soft::Wall;
use crate::granular::soft::contact::{Kinematics, Law, Material, Output, Springs, evaluate_law};
use crate::granular::soft::ordered_sum::SUM_CHUNK;
pub use crate::granular::soft::pairs::ContactRecord;
use crate::granular::soft::pairs::PairList;
use crate::granular::soft::particle::Particle;
use crate::gravity::{SelfGravity, accelerations};
use crate::math::Vec3;
use crate::phase::{Kind, Phase};
use rayon::prelude::*;

// Where a force evaluation's time goes (`rubblepile bench ssdem --phases`, `bench scaling`; see [`crate::phase`]).
static PHASE_BASE: Phase = Phase::new("soft.base_forces", Kind::Parallel);
static PHASE_OPEN: Phase = Phase::new("soft.kick_drift", Kind::Parallel);
static PHASE_CLOSE: Phase = Phase::new("soft.kick", Kind::Parallel);
static PHASE_WALLS: Phase = Phase::new("soft.walls", Kind::Parallel);
static PHASE_WALL_SUM: Phase = Phase::new("soft.wall_sum", Kind::Serial);

/// Gravity settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gravity {
    /// Uniform external field (m/s²).
    pub uniform: Vec3,
    /// Self-gravity, if on.
    pub self_gravity: Option<SelfGravity>,
    /// Gravitational constant (m³ kg⁻¹ s⁻²).
    pub g: f64,
}

/// Diagnostics of the last force evaluation.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ForceStats {
    /// Gravitational potential energy, self plus external (J).
    pub gravitational_energy: f64,
    /// Energy stored in the contact springs (J).
    pub spring_energy: f64,
    /// Largest overlap divided by the smaller radius of the contact (dimensionless).
    pub max_overlap_fraction: f64,
    /// Pair contacts.
    pub pair_contacts: usize,
    /// Sphere–wall contacts.
    pub wall_contacts: usize,
}

/// The spheres, walls and everything the forces need between steps.
#[derive(Debug, Clone)]
pub struct SoftSystem {
    /// The spheres.
    pub particles: Vec<Particle>,
    /// The walls.
    pub walls: Vec<Wall>,
    /// Contact material.
    pub material: Material,
    /// Gravity.
    pub gravity: Gravity,
    /// Forces (N) from the last evaluation.
    pub forces: Vec<Vec3>,
    /// Torques (N m) from the last evaluation.
    pub torques: Vec<Vec3>,
    /// Wall spring histories, sorted by `(particle, wall)`.
    pub wall_springs: Vec<((usize, usize), Springs)>,
    /// Diagnostics of the last evaluation.
    pub stats: ForceStats,
    /// Energy dissipated by dampers and sliders so far (J).
    pub dissipated: f64,
    /// Work done on the spheres by moving walls so far (J).
    pub wall_work: f64,
    /// Work done on the spheres by an external spin-up forcing so far (J; the spin-up of `soft::spinup`).
    pub forcing_work: f64,
    /// Angular momentum given to the spheres by that forcing so far (kg m²/s, about the origin).
    pub forcing_angular_impulse: Vec3,
    /// Keep per-contact records of the last evaluation in [`SoftSystem::records`] (off by default).
    pub keep_records: bool,
    /// Per-contact records of the last evaluation when [`SoftSystem::keep_records`] is set.
    pub records: Vec<ContactRecord>,
    /// Sum the pair springs' stored energy into [`ForceStats::spring_energy`] at the next evaluations (default
    /// true). Runs turn it off for the steps that end between output samples, where nothing reads it (as MD codes
    /// compute energies only on output steps); the pair springs' share of `spring_energy` is then 0. The
    /// dissipation is summed either way.
    pub spring_energy_wanted: bool,
    /// Self-gravity is evaluated once every this many steps (steps, ≥ 1; r-RESPA, see
    /// `soft::respa`); 1 = with the contacts, every step.
    pub gravity_interval: u64,
    /// Steps taken in the current block of `gravity_interval` steps.
    pub gravity_phase: u64,
    /// Self-gravity accelerations (m/s²) of the last slow evaluation (only when `gravity_interval > 1`).
    pub slow_accelerations: Vec<Vec3>,
    /// Self-gravity potential energy (J) of the last slow evaluation (0 when `gravity_interval = 1`).
    pub slow_energy: f64,
    /// The pair contacts: Verlet list and springs.
    pairs: PairList,
}

/// From this many spheres per task on, the wall contacts are evaluated in parallel.
const PAR_MIN: usize = 64;
/// One sphere–wall contact of a step: wall index, springs, overlap (m), wall velocity (m/s), wall spin (rad/s), law
/// output.
type WallHit = (usize, Springs, f64, Vec3, Vec3, Output);

fn lookup(list: &[((usize, usize), Springs)], key: (usize, usize)) -> Option<Springs> {
    list.binary_search_by(|e| e.0.cmp(&key)).ok().map(|k| list[k].1)
}

impl SoftSystem {
    /// The bytes the engine holds on the heap between steps (capacities of its buffers: spheres, forces, torques,
    /// the pair list with its springs, the wall springs, records, the slow accelerations); the self-gravity tree, built
    /// afresh at each evaluation, is not counted. `rubblepile bench memory` reports it per sphere beside the peak
    /// resident set.
    pub fn heap_bytes(&self) -> usize {
        use crate::math::vec_bytes;
        vec_bytes(&self.particles)
            + vec_bytes(&self.walls)
            + vec_bytes(&self.forces)
            + vec_bytes(&self.torques)
            + vec_bytes(&self.wall_springs)
            + vec_bytes(&self.records)
            + vec_bytes(&self.slow_accelerations)
            + self.pairs.heap_bytes()
    }

    /// A system at rest in force terms (call [`SoftSystem::compute_forces`] before stepping). The Verlet skin
    /// is a tenth of the smallest radius.
    pub fn new(particles: Vec<Particle>, walls: Vec<Wall>, material: Material, gravity: Gravity) -> Self {
        let n = particles.len();
        let r_min = particles.iter().map(|p| p.radius).fold(f64::INFINITY, f64::min);
        SoftSystem {
            particles,
            walls,
            material,
            gravity,
            forces: vec![Vec3::zeros(); n],
            torques: vec![Vec3::zeros(); n],
            wall_springs: Vec::new(),
            stats: ForceStats::default(),
            dissipated: 0.0,
            wall_work: 0.0,
            forcing_work: 0.0,
            forcing_angular_impulse: Vec3::zeros(),
            keep_records: false,
            records: Vec::new(),
            spring_energy_wanted: true,
            gravity_interval: 1,
            gravity_phase: 0,
            slow_accelerations: Vec::new(),
            slow_energy: 0.0,
            pairs: PairList::new(if r_min.is_finite() { 0.1 * r_min } else { 0.0 }),
        }
    }

    /// The spring histories of the pairs that touched at the last evaluation, sorted by `(i, j)`
    /// (for checkpoints).
    pub fn pair_springs(&self) -> Vec<((usize, usize), Springs)> {
        self.pairs.springs()
    }

    /// The pairs `(i, j)`, `i < j`, that touched at the last evaluation, in key order (no allocation).
    pub fn touching_pairs(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.pairs.touching()
    }

    /// Calls `f(i, j)` for every pair that touched at the last evaluation, in parallel and in no particular order.
    pub fn for_each_touching_pair(&self, f: impl Fn(usize, usize) + Sync) {
        self.pairs.for_each_touching(f)
    }

    /// Replaces the pair spring histories by `springs` (as from [`SoftSystem::pair_springs`], e.g. on
    /// resuming a checkpoint); the next evaluation rebuilds the Verlet list and carries them over.
    pub fn set_pair_springs(&mut self, springs: Vec<((usize, usize), Springs)>) {
        self.pairs.set_springs(self.particles.len(), springs);
    }

    /// Evaluates all forces and torques at time `t` (s) for a step of `dt` (s) (the springs advance by the
    /// relative motion over `dt`; pass `dt = 0` to evaluate without advancing them, e.g. at t = 0).
    pub fn compute_forces(&mut self, t: f64, dt: f64) {
        let n = self.particles.len();
        if self.split_gravity() && self.slow_accelerations.len() != n {
            self.update_slow_gravity();
        }
        let uniform = self.gravity.uniform;
        // With r-RESPA the self-gravity is the slow force, kept apart (`respa.rs`); here only the fast ones.
        let every_step = match self.gravity.self_gravity {
            Some(mode) if n > 1 && !self.split_gravity() => {
                let (positions, masses): (Vec<Vec3>, Vec<f64>) =
                    PHASE_BASE.time(|| self.particles.par_iter().map(|p| (p.position, p.mass)).unzip());
                Some(accelerations(mode, &positions, &masses, self.gravity.g))
            }
            _ => None,
        };
        let particles = &self.particles;
        // The non-contact force on sphere k and its potential energy, added to its contact force as the pairs'
        // sums are finished; the energies are summed there in the chunks of `ordered_sum`.
        let base = |k: usize| {
            let p = &particles[k];
            match &every_step {
                Some((acc, potentials)) => (
                    (acc[k] + uniform) * p.mass,
                    0.5 * p.mass * potentials[k] - p.mass * uniform.dot(&p.position),
                ),
                None => (uniform * p.mass, 0.0 - p.mass * uniform.dot(&p.position)),
            }
        };
        let mut stats = ForceStats::default();

        // Pair contacts. The force and torque buffers are reused from step to step: per-step arrays of a
        // 40 000-sphere system cost page faults and cache space.
        let mut forces = std::mem::take(&mut self.forces);
        let mut torques = std::mem::take(&mut self.torques);
        let law = Law::new(&self.material);
        // Contact records want |M_R| and |M_T|; the force loop alone does not. Records always come with the
        // stored energy.
        let pairs = &mut self.pairs;
        let totals = match (self.keep_records, self.spring_energy_wanted) {
            (true, _) => pairs.evaluate::<true, true>(particles, &law, dt, base, &mut forces, &mut torques),
            (false, true) => pairs.evaluate::<false, true>(particles, &law, dt, base, &mut forces, &mut torques),
            (false, false) => pairs.evaluate::<false, false>(particles, &law, dt, base, &mut forces, &mut torques),
        };
        stats.gravitational_energy = self.slow_energy + totals.base_energy;
        stats.spring_energy = totals.spring_energy;
        stats.max_overlap_fraction = totals.max_overlap_fraction;
        stats.pair_contacts = totals.contacts;
        let mut dissipated = totals.dissipated;
        let mut records = totals.records;

        // Wall contacts.
        let mut wall_springs = Vec::new();
        let mut wall_work = 0.0;
        if !self.walls.is_empty() {
            let old = &self.wall_springs;
            let per_particle: Vec<Vec<WallHit>> = PHASE_WALLS.time(|| {
                self.particles
                    .par_iter()
                    .with_min_len(PAR_MIN)
                    .enumerate()
                    .map(|(i, p)| {
                        let mut hits = Vec::new();
                        for (w, wall) in self.walls.iter().enumerate() {
                            let Some(touch) = wall.touch(&p.position, p.radius, t) else {
                                continue;
                            };
                            let nrm = touch.normal;
                            let li = p.radius - touch.overlap;
                            let kin = Kinematics {
                                normal: nrm,
                                overlap: touch.overlap,
                                lever_i: li,
                                lever_j: f64::INFINITY,
                                relative_velocity: touch.wall_velocity - p.velocity - p.spin.cross(&nrm) * li,
                                spin_i: p.spin,
                                spin_j: touch.wall_spin,
                                r_eff: p.radius,
                                mass_eff: p.mass,
                            };
                            let mut springs = lookup(old, (i, w)).unwrap_or_else(|| Springs::new(nrm));
                            let out = evaluate_law(&law, &kin, &mut springs, dt);
                            hits.push((w, springs, touch.overlap, touch.wall_velocity, touch.wall_spin, out));
                        }
                        hits
                    })
                    .collect()
            });
            PHASE_WALL_SUM.time(|| {
                for (i, hits) in per_particle.into_iter().enumerate() {
                    for (w, springs, overlap, wall_velocity, wall_spin, out) in hits {
                        forces[i] += out.force_i;
                        torques[i] += out.torque_i;
                        stats.spring_energy += out.stored_energy;
                        dissipated += out.dissipated;
                        wall_work += out.force_i.dot(&wall_velocity) * dt;
                        if wall_spin != Vec3::zeros() {
                            // A spinning wall also works through the twisting and rolling couples it takes
                            // (`torque_j`, the opposite of those on the sphere).
                            wall_work -= out.torque_j.dot(&wall_spin) * dt;
                        }
                        stats.max_overlap_fraction = stats.max_overlap_fraction.max(overlap / self.particles[i].radius);
                        stats.wall_contacts += 1;
                        if self.keep_records {
                            records.push(ContactRecord {
                                i,
                                j: n + w,
                                overlap,
                                output: out,
                            });
                        }
                        wall_springs.push(((i, w), springs));
                    }
                }
            });
        }
        self.wall_springs = wall_springs;
        self.forces = forces;
        self.torques = torques;
        self.stats = stats;
        self.dissipated += dissipated;
        self.wall_work += wall_work;
        self.records = records;
    }

    /// The first half of a leapfrog step in one pass over the spheres (each sphere on its own, so the bits are
    /// those of separate passes): copies the state into `before` (resized to the spheres) if given, gives the
    /// slow kick `v += a_slow τ` if `slow` is `Some(τ)` (r-RESPA, `respa.rs`), kicks `v += F/m h`, `ω += τ/I h`
    /// and drifts `x += v dt`; and tells the pair list whether a sphere has moved far enough to rebuild it, so that
    /// the force evaluation that must follow needs no pass of its own for that.
    pub(crate) fn open_step(&mut self, before: Option<&mut Vec<Particle>>, slow: Option<f64>, h: f64, dt: f64) {
        let (forces, torques, slow_acc, pairs) = (&self.forces, &self.torques, &self.slow_accelerations, &self.pairs);
        let one = |c: usize, ps: &mut [Particle], keep: Option<&mut [Particle]>| -> bool {
            if let Some(keep) = keep {
                keep.copy_from_slice(ps);
            }
            let mut moved = false;
            for (k, p) in ps.iter_mut().enumerate() {
                let i = c * SUM_CHUNK + k;
                if let Some(tau) = slow {
                    p.velocity += slow_acc[i] * tau;
                }
                p.velocity += forces[i] * (h / p.mass);
                p.spin += torques[i] * (h / p.inertia());
                p.position += p.velocity * dt;
                moved |= pairs.moved_too_far(i, &p.position);
            }
            moved
        };
        let moved = PHASE_OPEN.time(|| match before {
            Some(before) => {
                before.resize(self.particles.len(), Particle::default());
                self.particles
                    .par_chunks_mut(SUM_CHUNK)
                    .zip(before.par_chunks_mut(SUM_CHUNK))
                    .enumerate()
                    .map(|(c, (ps, keep))| one(c, ps, Some(keep)))
                    .reduce(|| false, |a, b| a || b)
            }
            None => self
                .particles
                .par_chunks_mut(SUM_CHUNK)
                .enumerate()
                .map(|(c, ps)| one(c, ps, None))
                .reduce(|| false, |a, b| a || b),
        });
        self.pairs.set_checked(moved);
    }

    /// The second half of a leapfrog step in one pass: kicks `v += F/m h`, `ω += τ/I h`, then gives the slow
    /// kick `v += a_slow τ` if `slow` is `Some(τ)`.
    pub(crate) fn close_step(&mut self, slow: Option<f64>, h: f64) {
        let (forces, torques, slow_acc) = (&self.forces, &self.torques, &self.slow_accelerations);
        PHASE_CLOSE.time(|| {
            self.particles
                .par_chunks_mut(SUM_CHUNK)
                .enumerate()
                .for_each(|(c, ps)| {
                    for (k, p) in ps.iter_mut().enumerate() {
                        let i = c * SUM_CHUNK + k;
                        p.velocity += forces[i] * (h / p.mass);
                        p.spin += torques[i] * (h / p.inertia());
                        if let Some(tau) = slow {
                            p.velocity += slow_acc[i] * tau;
                        }
                    }
                })
        })
    }

    /// Kinetic energy, translational plus rotational (J).
    pub fn kinetic_energy(&self) -> f64 {
        self.particles.iter().map(Particle::kinetic_energy).sum()
    }

    /// Total energy: kinetic + gravitational + spring (J), with the potentials of the last evaluation.
    pub fn energy(&self) -> f64 {
        self.kinetic_energy() + self.stats.gravitational_energy + self.stats.spring_energy
    }

    /// Total linear momentum (kg m/s).
    pub fn momentum(&self) -> Vec3 {
        self.particles.iter().map(|p| p.velocity * p.mass).sum()
    }

    /// Total angular momentum about the origin, orbital plus spin (kg m²/s).
    pub fn angular_momentum(&self) -> Vec3 {
        self.particles
            .iter()
            .map(|p| p.position.cross(&(p.velocity * p.mass)) + p.spin * p.inertia())
            .sum()
    }

    /// Mean number of contacts per sphere, `(2 pairs + wall contacts)/N`.
    pub fn coordination_number(&self) -> f64 {
        if self.particles.is_empty() {
            0.0
        } else {
            (2 * self.stats.pair_contacts + self.stats.wall_contacts) as f64 / self.particles.len() as f64
        }
    }
}
