//! Forces and torques on every sphere (Zhang17 Eq. 1): self-gravity (direct or octree), a uniform external
//! field, and the contact law ([`crate::granular::soft::contact`]) for every touching pair and every
//! sphere–wall contact.
//!
//! Contacts are found from a Verlet list built on the cell grid of [`crate::geometry::neighbours`] with
//! reach `r + skin/2`, rebuilt when any sphere has moved more than `skin/2` since the last build. The pair
//! list is sorted by key `(i, j)`, `i < j`, and the pair spring histories live in an array parallel to it
//! (no look-up; carried over by a merge on key when the list is rebuilt); wall histories live in a vector
//! sorted by `(i, wall)`. Forces are accumulated in key order: on one thread in the same pass that evaluates
//! the contacts, on several threads after a parallel pass that stores each pair's output. Both orders are the
//! same, so the forces depend neither on the number of threads nor on when the Verlet list was rebuilt.

use crate::geometry::neighbours::sphere_pairs;
use crate::geometry::walls::soft::Wall;
use crate::granular::soft::contact::{Kinematics, Law, Material, Output, Springs, evaluate_inner, evaluate_law};
use crate::granular::soft::particle::Particle;
use crate::gravity::{SelfGravity, accelerations};
use crate::math::Vec3;
use crate::phase::{Kind, Phase};
use rayon::prelude::*;

// Where a force evaluation's time goes (`rubblepile bench ssdem --phases`, `bench scaling`; see [`crate::phase`]).
static PHASE_BASE: Phase = Phase::new("soft.base_forces", Kind::Serial);
static PHASE_VERLET_CHECK: Phase = Phase::new("soft.verlet_check", Kind::Serial);
static PHASE_VERLET_PAIRS: Phase = Phase::new("soft.verlet_pairs", Kind::Parallel);
static PHASE_VERLET_MERGE: Phase = Phase::new("soft.verlet_merge", Kind::Serial);
static PHASE_PAIR_EVAL: Phase = Phase::new("soft.pair_eval", Kind::Parallel);
static PHASE_PAIR_SUM: Phase = Phase::new("soft.pair_sum", Kind::Serial);
static PHASE_COMBINE: Phase = Phase::new("soft.combine", Kind::Serial);
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

/// A pair contact's record at the last force evaluation (for tests and diagnostics).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactRecord {
    /// Particle `i`.
    pub i: usize,
    /// Partner: particle index, or `n_particles + wall index` for a wall.
    pub j: usize,
    /// Overlap (m).
    pub overlap: f64,
    /// The law's output.
    pub output: Output,
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
    /// Work done on the spheres by an external spin-up forcing so far (J; [`crate::granular::soft::spinup`]).
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
    /// [`crate::granular::soft::respa`]); 1 = with the contacts, every step.
    pub gravity_interval: u64,
    /// Steps taken in the current block of `gravity_interval` steps.
    pub gravity_phase: u64,
    /// Self-gravity accelerations (m/s²) of the last slow evaluation (only when `gravity_interval > 1`).
    pub slow_accelerations: Vec<Vec3>,
    /// Self-gravity potential energy (J) of the last slow evaluation (0 when `gravity_interval = 1`).
    pub slow_energy: f64,
    skin: f64,
    /// Candidate pairs `(i, j)`, `i < j`, sorted.
    verlet: Vec<PairKey>,
    /// Per entry of `verlet`: the springs if the pair touched at the last evaluation.
    pair_slots: Vec<Slot>,
    /// Per entry of `verlet`: this evaluation's outcome (only filled when pairs are evaluated in parallel).
    pair_hits: Vec<Option<PairHit>>,
    /// Per sphere: the pair contacts' force and torque of the evaluation under way.
    pair_load: Vec<(Vec3, Vec3)>,
    verlet_origin: Vec<Vec3>,
}

/// A Verlet-list pair `(i, j)`, `i < j`, as 32-bit indices: half the bytes of `(usize, usize)`, which with
/// [`Slot`] keeps the contact data of 40 000 spheres (~240 000 contacts) inside a 32 MiB cache.
type PairKey = (u32, u32);

/// `(i, j)` as a [`PairKey`]. A system of 2³² spheres would need far more memory than any machine holds, so
/// the indices always fit.
fn pair_key((i, j): (usize, usize)) -> PairKey {
    (i as u32, j as u32)
}

/// `key` as particle indices.
fn pair_indices((i, j): PairKey) -> (usize, usize) {
    (i as usize, j as usize)
}

/// A Verlet-list entry's springs, or none (the pair did not touch at the last evaluation). "None" is a NaN
/// twist angle rather than an `Option`, so that a slot is 80 and not 88 bytes; a touching pair's twist is
/// always finite (a NaN anywhere in the state stops the run first).
#[derive(Debug, Clone, Copy)]
struct Slot(Springs);

impl Slot {
    /// The empty slot.
    fn empty() -> Self {
        Slot(Springs {
            twist: f64::NAN,
            ..Springs::default()
        })
    }

    /// A slot holding `springs`.
    fn full(springs: Springs) -> Self {
        Slot(springs)
    }

    /// The springs, if any.
    #[inline(always)]
    fn get(&self) -> Option<Springs> {
        (!self.0.twist.is_nan()).then_some(self.0)
    }
}

/// What one touching pair contributes at one evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
struct PairHit {
    /// Overlap (m).
    overlap: f64,
    /// The smaller radius (m).
    r_small: f64,
    /// The law's output.
    out: Output,
}

/// Running sums of one evaluation, added to in key order.
struct Sums<'a> {
    /// Per sphere: contact force and torque side by side (one cache line for a random partner `j`).
    load: &'a mut [(Vec3, Vec3)],
    stats: &'a mut ForceStats,
    dissipated: f64,
    records: Option<&'a mut Vec<ContactRecord>>,
}

impl Sums<'_> {
    /// Adds pair `(i, j)`'s contribution (the one place that does, so that the serial and the parallel paths
    /// add the same numbers in the same order).
    #[inline(always)]
    fn add_pair(&mut self, i: usize, j: usize, hit: &PairHit) {
        let out = &hit.out;
        self.load[i].0 += out.force_i;
        self.load[j].0 -= out.force_i;
        self.load[i].1 += out.torque_i;
        self.load[j].1 += out.torque_j;
        self.stats.spring_energy += out.stored_energy;
        self.dissipated += out.dissipated;
        // max(m, x/r) with the division only when x/r may exceed m (rounding of m r is far below 1e-12).
        let max = &mut self.stats.max_overlap_fraction;
        if hit.overlap >= *max * hit.r_small * (1.0 - 1e-12) {
            *max = max.max(hit.overlap / hit.r_small);
        }
        self.stats.pair_contacts += 1;
        if let Some(records) = self.records.as_deref_mut() {
            records.push(ContactRecord {
                i,
                j,
                overlap: hit.overlap,
                output: *out,
            });
        }
    }
}

/// The kinematics of pair `(i, j)` if the spheres overlap.
#[inline(always)]
fn pair_kinematics(particles: &[Particle], i: usize, j: usize) -> Option<Kinematics> {
    let (a, b) = (&particles[i], &particles[j]);
    let d = b.position - a.position;
    let reach = a.radius + b.radius;
    let dist2 = d.norm_squared();
    if dist2 >= reach * reach {
        return None;
    }
    let dist = dist2.sqrt();
    let overlap = reach - dist;
    if overlap <= 0.0 || dist <= 0.0 {
        return None;
    }
    let n = d * (1.0 / dist);
    let (li, lj) = (a.radius - 0.5 * overlap, b.radius - 0.5 * overlap);
    let inv = 1.0 / (reach * (a.mass + b.mass));
    let u = b.velocity - a.velocity - b.spin.cross(&n) * lj - a.spin.cross(&n) * li;
    Some(Kinematics {
        normal: n,
        overlap,
        lever_i: li,
        lever_j: lj,
        relative_velocity: u,
        spin_i: a.spin,
        spin_j: b.spin,
        // R = r_i r_j/(r_i + r_j) and μ = m_i m_j/(m_i + m_j) with one division.
        r_eff: a.radius * b.radius * (a.mass + b.mass) * inv,
        mass_eff: a.mass * b.mass * reach * inv,
    })
}

/// Evaluates pair `(i, j)` with the springs of its slot, and updates the slot (emptied if they do not touch).
#[inline(always)]
fn pair_contact<const SIZES: bool, const STORED: bool>(
    particles: &[Particle],
    law: &Law,
    key: PairKey,
    slot: &mut Slot,
    dt: f64,
) -> Option<PairHit> {
    let (i, j) = pair_indices(key);
    let Some(kin) = pair_kinematics(particles, i, j) else {
        *slot = Slot::empty();
        return None;
    };
    let mut springs = slot.get().unwrap_or_else(|| Springs::new(kin.normal));
    let out = evaluate_inner::<SIZES, STORED>(law, &kin, &mut springs, dt);
    *slot = Slot::full(springs);
    Some(PairHit {
        overlap: kin.overlap,
        r_small: particles[i].radius.min(particles[j].radius),
        out,
    })
}

const PAR_MIN: usize = 64;
/// Pairs per parallel task.
const PAIR_CHUNK: usize = 1024;

/// One sphere–wall contact of a step: wall index, springs, overlap (m), wall velocity (m/s), law output.
type WallHit = (usize, Springs, f64, Vec3, Output);

fn lookup(list: &[((usize, usize), Springs)], key: (usize, usize)) -> Option<Springs> {
    list.binary_search_by(|e| e.0.cmp(&key)).ok().map(|k| list[k].1)
}

impl SoftSystem {
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
            skin: if r_min.is_finite() { 0.1 * r_min } else { 0.0 },
            verlet: Vec::new(),
            pair_slots: Vec::new(),
            pair_hits: Vec::new(),
            pair_load: Vec::new(),
            verlet_origin: Vec::new(),
        }
    }

    /// The spring histories of the pairs that touched at the last evaluation, sorted by `(i, j)`
    /// (for checkpoints).
    pub fn pair_springs(&self) -> Vec<((usize, usize), Springs)> {
        self.verlet
            .iter()
            .zip(&self.pair_slots)
            .filter_map(|(&key, slot)| slot.get().map(|s| (pair_indices(key), s)))
            .collect()
    }

    /// Replaces the pair spring histories by `springs` (as from [`SoftSystem::pair_springs`], e.g. on
    /// resuming a checkpoint); the next evaluation rebuilds the Verlet list and carries them over.
    pub fn set_pair_springs(&mut self, mut springs: Vec<((usize, usize), Springs)>) {
        springs.sort_by_key(|e| e.0);
        springs.dedup_by_key(|e| e.0);
        self.verlet = springs.iter().map(|e| pair_key(e.0)).collect();
        self.pair_slots = springs.into_iter().map(|e| Slot::full(e.1)).collect();
        self.verlet_origin.clear();
    }

    fn refresh_verlet(&mut self) {
        let stale = PHASE_VERLET_CHECK.time(|| {
            self.verlet_origin.len() != self.particles.len()
                || self
                    .particles
                    .iter()
                    .zip(&self.verlet_origin)
                    .any(|(p, o)| (p.position - o).norm_squared() > 0.25 * self.skin * self.skin)
        });
        if stale {
            let centres: Vec<Vec3> = self.particles.iter().map(|p| p.position).collect();
            let reach: Vec<f64> = self.particles.iter().map(|p| p.radius + 0.5 * self.skin).collect();
            let pairs = PHASE_VERLET_PAIRS.time(|| sphere_pairs(&centres, &reach));
            let merge = PHASE_VERLET_MERGE.time(|| {
                // Carry the springs of touching pairs over: both lists are sorted by key, and every touching pair
                // is in the new list (it holds every pair closer than the sum of radii plus the skin).
                let mut old = self
                    .verlet
                    .iter()
                    .zip(&self.pair_slots)
                    .filter(|(_, slot)| slot.get().is_some())
                    .peekable();
                let pairs: Vec<PairKey> = pairs.into_iter().map(pair_key).collect();
                let mut slots = Vec::with_capacity(pairs.len());
                for key in &pairs {
                    while old.next_if(|(k, _)| *k < key).is_some() {}
                    slots.push(
                        old.next_if(|(k, _)| *k == key)
                            .map_or_else(Slot::empty, |(_, slot)| *slot),
                    );
                }
                (pairs, slots)
            });
            let (pairs, slots) = merge;
            self.verlet = pairs;
            self.pair_slots = slots;
            self.pair_hits.clear();
            self.verlet_origin = centres;
        }
    }

    /// Evaluates every pair of the Verlet list and adds the touching ones to `sums` in key order.
    fn pair_pass<const SIZES: bool, const STORED: bool>(&mut self, law: &Law, dt: f64, sums: &mut Sums<'_>) {
        let particles = &self.particles;
        if rayon::current_num_threads() > 1 && self.verlet.len() > PAIR_CHUNK {
            self.pair_hits.resize(self.verlet.len(), None);
            PHASE_PAIR_EVAL.time(|| {
                self.verlet
                    .par_chunks(PAIR_CHUNK)
                    .zip(self.pair_slots.par_chunks_mut(PAIR_CHUNK))
                    .zip(self.pair_hits.par_chunks_mut(PAIR_CHUNK))
                    .for_each(|((keys, slots), hits)| {
                        for ((&key, slot), hit) in keys.iter().zip(slots).zip(hits) {
                            *hit = pair_contact::<SIZES, STORED>(particles, law, key, slot, dt);
                        }
                    })
            });
            PHASE_PAIR_SUM.time(|| {
                for (&key, hit) in self.verlet.iter().zip(&self.pair_hits) {
                    if let Some(hit) = hit {
                        let (i, j) = pair_indices(key);
                        sums.add_pair(i, j, hit);
                    }
                }
            });
        } else {
            PHASE_PAIR_EVAL.time(|| {
                for (&key, slot) in self.verlet.iter().zip(self.pair_slots.iter_mut()) {
                    if let Some(hit) = pair_contact::<SIZES, STORED>(particles, law, key, slot, dt) {
                        let (i, j) = pair_indices(key);
                        sums.add_pair(i, j, &hit);
                    }
                }
            });
        }
    }

    /// Evaluates all forces and torques at time `t` (s) for a step of `dt` (s) (the springs advance by the
    /// relative motion over `dt`; pass `dt = 0` to evaluate without advancing them, e.g. at t = 0).
    pub fn compute_forces(&mut self, t: f64, dt: f64) {
        let n = self.particles.len();
        if self.split_gravity() && self.slow_accelerations.len() != n {
            self.update_slow_gravity();
        }
        let mut stats = ForceStats {
            gravitational_energy: self.slow_energy,
            ..ForceStats::default()
        };
        // The force buffer is reused from step to step: per-step arrays of a 40 000-sphere system cost page
        // faults and cache space.
        let mut forces = std::mem::take(&mut self.forces);
        forces.clear();
        let uniform = self.gravity.uniform;
        // With r-RESPA the self-gravity is the slow force, kept apart (`respa.rs`); here only the fast ones.
        match self.gravity.self_gravity {
            Some(mode) if n > 1 && !self.split_gravity() => {
                let (positions, masses): (Vec<Vec3>, Vec<f64>) =
                    PHASE_BASE.time(|| self.particles.iter().map(|p| (p.position, p.mass)).unzip());
                let (acc, potentials) = accelerations(mode, &positions, &masses, self.gravity.g);
                PHASE_BASE.time(|| {
                    for k in 0..n {
                        let m = masses[k];
                        forces.push((acc[k] + uniform) * m);
                        stats.gravitational_energy += 0.5 * m * potentials[k] - m * uniform.dot(&positions[k]);
                    }
                });
            }
            _ => PHASE_BASE.time(|| {
                for p in &self.particles {
                    forces.push(uniform * p.mass);
                    stats.gravitational_energy += 0.0 - p.mass * uniform.dot(&p.position);
                }
            }),
        }
        let mut records = std::mem::take(&mut self.records);
        records.clear();

        // Pair contacts.
        self.refresh_verlet();
        let law = Law::new(&self.material);
        let mut load = std::mem::take(&mut self.pair_load);
        PHASE_COMBINE.time(|| {
            load.clear();
            load.resize(n, (Vec3::zeros(), Vec3::zeros()));
        });
        let mut sums = Sums {
            load: &mut load,
            stats: &mut stats,
            dissipated: 0.0,
            records: self.keep_records.then_some(&mut records),
        };
        // Contact records want |M_R| and |M_T|; the force loop alone does not. Records always come with the
        // stored energy.
        match (self.keep_records, self.spring_energy_wanted) {
            (true, _) => self.pair_pass::<true, true>(&law, dt, &mut sums),
            (false, true) => self.pair_pass::<false, true>(&law, dt, &mut sums),
            (false, false) => self.pair_pass::<false, false>(&law, dt, &mut sums),
        }
        let mut dissipated = sums.dissipated;
        let mut torques = std::mem::take(&mut self.torques);
        PHASE_COMBINE.time(|| {
            torques.clear();
            torques.extend(load.iter().map(|l| l.1));
            for (f, l) in forces.iter_mut().zip(&load) {
                *f += l.0;
            }
        });
        self.pair_load = load;

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
                                spin_j: Vec3::zeros(),
                                r_eff: p.radius,
                                mass_eff: p.mass,
                            };
                            let mut springs = lookup(old, (i, w)).unwrap_or_else(|| Springs::new(nrm));
                            let out = evaluate_law(&law, &kin, &mut springs, dt);
                            hits.push((w, springs, touch.overlap, touch.wall_velocity, out));
                        }
                        hits
                    })
                    .collect()
            });
            PHASE_WALL_SUM.time(|| {
                for (i, hits) in per_particle.into_iter().enumerate() {
                    for (w, springs, overlap, wall_velocity, out) in hits {
                        forces[i] += out.force_i;
                        torques[i] += out.torque_i;
                        stats.spring_energy += out.stored_energy;
                        dissipated += out.dissipated;
                        wall_work += out.force_i.dot(&wall_velocity) * dt;
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
