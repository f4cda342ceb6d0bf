//! Forces and torques on every sphere (Zhang17 Eq. 1): self-gravity (direct or octree), a uniform external
//! field, and the contact law ([`crate::granular::soft::contact`]) for every touching pair and every
//! sphere–wall contact.
//!
//! Contacts are found from a Verlet list built on the cell grid of [`crate::geometry::neighbours`] with
//! reach `r + skin/2`, rebuilt when any sphere has moved more than `skin/2` since the last build. Spring
//! histories live in vectors sorted by key (`(i, j)` with `i < j` for pairs, `(i, wall)` for walls). Pair
//! contacts are evaluated in parallel but collected and then accumulated in key order, so the forces do not
//! depend on the number of threads nor on when the Verlet list was rebuilt.

use crate::geometry::neighbours::sphere_pairs;
use crate::geometry::wall::Wall;
use crate::granular::soft::contact::{Kinematics, Material, Output, Springs, evaluate};
use crate::granular::soft::particle::Particle;
use crate::gravity::{SelfGravity, accelerations};
use crate::math::Vec3;
use rayon::prelude::*;

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
    /// Pair spring histories, sorted by `(i, j)`.
    pub pair_springs: Vec<((usize, usize), Springs)>,
    /// Wall spring histories, sorted by `(particle, wall)`.
    pub wall_springs: Vec<((usize, usize), Springs)>,
    /// Diagnostics of the last evaluation.
    pub stats: ForceStats,
    /// Energy dissipated by dampers and sliders so far (J).
    pub dissipated: f64,
    /// Work done on the spheres by moving walls so far (J).
    pub wall_work: f64,
    /// Keep per-contact records of the last evaluation in [`SoftSystem::records`] (off by default).
    pub keep_records: bool,
    /// Per-contact records of the last evaluation when [`SoftSystem::keep_records`] is set.
    pub records: Vec<ContactRecord>,
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
    verlet: Vec<(usize, usize)>,
    verlet_origin: Vec<Vec3>,
}

const PAR_MIN: usize = 64;

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
            pair_springs: Vec::new(),
            wall_springs: Vec::new(),
            stats: ForceStats::default(),
            dissipated: 0.0,
            wall_work: 0.0,
            keep_records: false,
            records: Vec::new(),
            gravity_interval: 1,
            gravity_phase: 0,
            slow_accelerations: Vec::new(),
            slow_energy: 0.0,
            skin: if r_min.is_finite() { 0.1 * r_min } else { 0.0 },
            verlet: Vec::new(),
            verlet_origin: Vec::new(),
        }
    }

    fn refresh_verlet(&mut self) {
        let stale = self.verlet_origin.len() != self.particles.len()
            || self
                .particles
                .iter()
                .zip(&self.verlet_origin)
                .any(|(p, o)| (p.position - o).norm_squared() > 0.25 * self.skin * self.skin);
        if stale {
            let centres: Vec<Vec3> = self.particles.iter().map(|p| p.position).collect();
            let reach: Vec<f64> = self.particles.iter().map(|p| p.radius + 0.5 * self.skin).collect();
            self.verlet = sphere_pairs(&centres, &reach);
            self.verlet_origin = centres;
        }
    }

    fn pair_kinematics(&self, i: usize, j: usize) -> Option<Kinematics> {
        let (a, b) = (&self.particles[i], &self.particles[j]);
        let d = b.position - a.position;
        let dist = d.norm();
        let overlap = a.radius + b.radius - dist;
        if overlap <= 0.0 || dist <= 0.0 {
            return None;
        }
        let n = d / dist;
        let (li, lj) = (a.radius - 0.5 * overlap, b.radius - 0.5 * overlap);
        let u = b.velocity - a.velocity - b.spin.cross(&n) * lj - a.spin.cross(&n) * li;
        Some(Kinematics {
            normal: n,
            overlap,
            lever_i: li,
            lever_j: lj,
            relative_velocity: u,
            spin_i: a.spin,
            spin_j: b.spin,
            r_eff: a.radius * b.radius / (a.radius + b.radius),
            mass_eff: a.mass * b.mass / (a.mass + b.mass),
        })
    }

    /// Evaluates all forces and torques at time `t` (s) for a step of `dt` (s) (the springs advance by the
    /// relative motion over `dt`; pass `dt = 0` to evaluate without advancing them, e.g. at t = 0).
    pub fn compute_forces(&mut self, t: f64, dt: f64) {
        let n = self.particles.len();
        if self.split_gravity() && self.slow_accelerations.len() != n {
            self.update_slow_gravity();
        }
        let positions: Vec<Vec3> = self.particles.iter().map(|p| p.position).collect();
        let masses: Vec<f64> = self.particles.iter().map(|p| p.mass).collect();
        let mut stats = ForceStats {
            gravitational_energy: self.slow_energy,
            ..ForceStats::default()
        };
        // With r-RESPA the self-gravity is the slow force, kept apart (`respa.rs`); here only the fast ones.
        let (mut forces, potentials) = match self.gravity.self_gravity {
            Some(mode) if n > 1 && !self.split_gravity() => accelerations(mode, &positions, &masses, self.gravity.g),
            _ => (vec![Vec3::zeros(); n], vec![0.0; n]),
        };
        for k in 0..n {
            let m = masses[k];
            forces[k] = (forces[k] + self.gravity.uniform) * m;
            stats.gravitational_energy += 0.5 * m * potentials[k] - m * self.gravity.uniform.dot(&positions[k]);
        }
        let mut torques = vec![Vec3::zeros(); n];

        // Pair contacts.
        self.refresh_verlet();
        let material = self.material;
        let old = &self.pair_springs;
        let results: Vec<((usize, usize), Springs, f64, Output)> = self
            .verlet
            .par_iter()
            .with_min_len(PAR_MIN)
            .filter_map(|&(i, j)| {
                let kin = self.pair_kinematics(i, j)?;
                let mut springs = lookup(old, (i, j)).unwrap_or_else(|| Springs::new(kin.normal));
                let out = evaluate(&material, &kin, &mut springs, dt);
                Some(((i, j), springs, kin.overlap, out))
            })
            .collect();
        let mut dissipated = 0.0;
        let mut records = Vec::new();
        for &((i, j), _, overlap, ref out) in &results {
            forces[i] += out.force_i;
            forces[j] -= out.force_i;
            torques[i] += out.torque_i;
            torques[j] += out.torque_j;
            stats.spring_energy += out.stored_energy;
            dissipated += out.dissipated;
            let r_small = self.particles[i].radius.min(self.particles[j].radius);
            stats.max_overlap_fraction = stats.max_overlap_fraction.max(overlap / r_small);
            if self.keep_records {
                records.push(ContactRecord {
                    i,
                    j,
                    overlap,
                    output: *out,
                });
            }
        }
        stats.pair_contacts = results.len();
        self.pair_springs = results.into_iter().map(|(key, s, _, _)| (key, s)).collect();

        // Wall contacts.
        let mut wall_springs = Vec::new();
        let mut wall_work = 0.0;
        if !self.walls.is_empty() {
            let old = &self.wall_springs;
            let per_particle: Vec<Vec<WallHit>> = self
                .particles
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
                        let out = evaluate(&material, &kin, &mut springs, dt);
                        hits.push((w, springs, touch.overlap, touch.wall_velocity, out));
                    }
                    hits
                })
                .collect();
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
