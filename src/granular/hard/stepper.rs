//! The hard-sphere stepper (Richardson11 §2.1): kick–drift–kick with uniform gravity in the half kicks; within the
//! drift of length h every particle's earliest events against neighbours and walls are queued ([`super::events`]),
//! the globally earliest processed and only its particles re-predicted, until the step ends.
//!
//! Neighbours: a Verlet list with per-particle skins. Particle k has an anchor `a_k` and allowance `L_k`; candidates
//! have `|a_i − a_j| < R_i + R_j + L_i + L_j` ([`crate::geometry::neighbours::sphere_pairs`]), near walls lie within
//! `R_k + L_k`. A particle that could leave its allowance (checked at each drift start and after each of its
//! collisions) is re-listed alone ([`super::anchors`]; more than half at once: a full rebuild), so no collision is
//! missed. `L_k = max(min(skin_steps · |v_k| h + ½ |g| (skin_steps · h)², R_k), |v_k| (t1 − t))`, ≥ 1e-3 of the
//! smallest radius; `skin_steps = 0` is the per-step reference of `tests/hsdem_neighbours.rs`. Wall contacts are
//! re-predicted each drift start, free pairs keep certificates ([`super::certificates`]) and change no bit
//! (`tests/hsdem_certificates.rs`). Touching, approaching contacts collide at once: no overlap is integrated.
//! Particles stuck to a sticky wall move rigidly with it as infinite masses.

use super::anchors::{AnchorGrid, Entry};
use super::certificates::{self, Calendar, Due};
use super::collision::{self, Body, Restitution};
use super::events::{Event, EventQueue, Partner};
use super::particle::{Attachment, Particle};
use crate::geometry::neighbours::sphere_pairs;
use crate::geometry::walls::Wall;
use crate::math::Vec3;
use crate::phase::{Kind, Phase};

// Where a step's time goes (`rubblepile bench hsdem` prints the split; `crate::phase`). The phases are leaves: the
// event loop is timed piece by piece so that re-listing inside it is not counted twice.
/// Both half kicks, the stuck particles' secants and the finiteness check.
static PHASE_KICK: Phase = Phase::new("hard.kick", Kind::Serial);
/// The drift start's check of every particle against its neighbour-list allowance.
static PHASE_LIST_CHECK: Phase = Phase::new("hard.list_check", Kind::Serial);
/// Re-listing single particles (at drift starts and after collisions).
static PHASE_RELIST: Phase = Phase::new("hard.relist", Kind::Serial);
/// Full neighbour-list builds (the cell grid of all anchors).
static PHASE_REBUILD: Phase = Phase::new("hard.rebuild", Kind::Serial);
/// The drift start's predictions of every listed pair and wall contact.
static PHASE_PREDICT_START: Phase = Phase::new("hard.predict_start", Kind::Serial);
/// The event loop: popping events and applying collisions.
static PHASE_EVENTS: Phase = Phase::new("hard.events", Kind::Serial);
/// Re-predicting the particles of each processed event.
static PHASE_REPREDICT: Phase = Phase::new("hard.repredict", Kind::Serial);
/// Moving every particle to the end of the drift.
static PHASE_ADVANCE: Phase = Phase::new("hard.advance", Kind::Serial);

/// Default [`StepperSettings::skin_steps`]: on the dilute model atmosphere any of 8 to 64 costs under half of a
/// fresh list every step (`analysis/richardson2011/MODULE_NOTES.md`), and 16 keeps the lists shorter in dense piles.
pub const DEFAULT_SKIN_STEPS: f64 = 16.0;

/// Settings of the stepper.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepperSettings {
    /// Uniform gravitational acceleration (m/s²), if any.
    pub gravity: Option<Vec3>,
    /// Inelastic-collapse guard: collisions with a normal approach speed below this (m/s) are elastic.
    pub collapse_speed: f64,
    /// Most events one drift may process before the run stops as stalled.
    pub max_events_per_step: u64,
    /// Neighbour-list skin in steps (≥ 0): a particle's travel allowance is about `skin_steps · |v| · dt`, and it is
    /// re-listed when it could leave it. 0 = a fresh list for all at every step (the reference scheme).
    pub skin_steps: f64,
    /// Predict only what may give an event (module doc): pair certificates kept across steps
    /// ([`super::certificates`], with `skin_steps > 0`) and each particle's near walls. `false` predicts every listed
    /// pair and every wall at every drift start (the scheme before), with the same results to the bit: the reference
    /// of `tests/hsdem_certificates.rs`.
    pub prune_predictions: bool,
}

impl Default for StepperSettings {
    fn default() -> Self {
        StepperSettings {
            gravity: None,
            collapse_speed: 0.0,
            max_events_per_step: 10_000_000,
            skin_steps: DEFAULT_SKIN_STEPS,
            prune_predictions: true,
        }
    }
}

/// Why a step failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StepError {
    /// Too many events in one drift (inelastic collapse or a trapped particle).
    #[error(
        "event loop stalled: more than {limit} events in the step ending at t = {t} s (raise stepping.max_events_per_step or stepping.collapse_speed)"
    )]
    Stalled {
        /// End of the step (s).
        t: f64,
        /// The limit.
        limit: u64,
    },
    /// A particle's state became non-finite.
    #[error("non-finite state of particle {id} at t = {t} s")]
    NonFinite {
        /// Particle id.
        id: usize,
        /// Time (s).
        t: f64,
    },
}

/// Counters accumulated over the run.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Counters {
    /// Particle–particle collisions applied.
    pub pair_collisions: u64,
    /// Particle–wall collisions applied (including sticking and absorption).
    pub wall_collisions: u64,
    /// Events processed (valid ones, including those that found the bodies separating).
    pub events: u64,
    /// Collisions made elastic by the collapse guard.
    pub guarded: u64,
    /// Neighbour-list builds (all particles).
    pub rebuilds: u64,
    /// Single particles re-anchored in the neighbour list.
    pub reanchors: u64,
    /// Particles absorbed.
    pub absorbed: u64,
    /// Largest overlap seen at a collision, relative to the smaller radius.
    pub max_overlap: f64,
    /// Energy (J) changed by collisions, sticking and absorption (so that `E − E0 − exchanged` is the integration
    /// error): the sum of `energy_restitution`, `energy_walls` and `energy_removed`.
    pub energy_exchanged: f64,
    /// Energy (J) the collisions lost in the frame of the contact (restitution: ≤ 0 for restitution ≤ 1): the
    /// kinetic energy change minus the walls' work.
    pub energy_restitution: f64,
    /// Work (J) of moving walls on the free particles: each wall collision's impulse `J = m Δv` times the wall's
    /// surface velocity at the contact (also for contacts with particles stuck to a wall).
    pub energy_walls: f64,
    /// Energy (J) that sticking and absorbed particles took out of the free particles' total (≤ 0 when it was
    /// positive).
    pub energy_removed: f64,
    /// Momentum (kg m/s) the walls gave the free particles: bounces, contacts with stuck particles, and minus the
    /// momentum of particles that stuck or were absorbed.
    pub wall_impulse: Vec3,
    /// Momentum (kg m/s) the uniform gravity field gave the free particles (its kicks).
    pub field_impulse: Vec3,
}

/// Energies and momenta of the free particles (stuck particles belong to their wall).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Diagnostics {
    /// Translational kinetic energy (J).
    pub kinetic: f64,
    /// Rotational kinetic energy (J).
    pub rotational: f64,
    /// Potential energy in the uniform field, `−Σ m g·r` (J).
    pub potential: f64,
    /// Linear momentum (kg m/s).
    pub momentum: Vec3,
    /// Angular momentum about the origin, orbital plus spin (kg m²/s).
    pub angular_momentum: Vec3,
    /// Free particles.
    pub free: usize,
    /// Stuck particles.
    pub stuck: usize,
}

impl Diagnostics {
    /// Total energy (J).
    pub fn energy(&self) -> f64 {
        self.kinetic + self.rotational + self.potential
    }
}

/// Per-step wall data: reference point at the step start and secant velocity.
#[derive(Debug, Clone, Copy)]
struct WallStep {
    origin0: Vec3,
    velocity: Vec3,
}

/// The hard-sphere system: particles, walls, clock.
#[derive(Debug, Clone)]
pub struct System {
    /// The particles (index = id).
    pub particles: Vec<Particle>,
    /// The walls.
    pub walls: Vec<Wall>,
    /// Settings.
    pub settings: StepperSettings,
    /// Current time (s).
    pub t: f64,
    /// Counters since t = 0.
    pub counters: Counters,
    gens: Vec<u64>,
    /// Certificate generations: bumped when a particle collides or is re-listed, which ends its pairs'
    /// certificates ([`super::certificates`]).
    cert_gens: Vec<u64>,
    /// The allowance floor, 1e-3 of the smallest alive radius, once computed (cleared when a particle dies).
    floor: Option<f64>,
    neighbours: Neighbours,
}

/// The neighbour list kept across steps.
#[derive(Debug, Clone, Default)]
struct Neighbours {
    /// Whether a list has been built.
    built: bool,
    /// Candidate partners of each particle.
    adjacency: Vec<Vec<usize>>,
    /// Positions when listed.
    anchors: Vec<Vec3>,
    /// Travel allowances (m).
    allowances: Vec<f64>,
    /// The anchors by cell, for re-listing one particle (empty for the reference scheme `skin_steps = 0`).
    grid: AnchorGrid,
    /// For each particle, the walls it may touch while it stays within its allowance (all moving walls).
    near_walls: Vec<Vec<usize>>,
    /// The particles with near walls (any order), and where each is in that list (`usize::MAX`: absent).
    near_list: Vec<usize>,
    near_pos: Vec<usize>,
    /// The particles stuck to walls (their pairs are predicted at every drift start).
    stuck_list: Vec<usize>,
    /// Certificates of the listed pairs of free particles ([`super::certificates`]).
    calendar: Calendar,
    /// Whether every listed pair of free particles without a queued event has a certificate in the calendar (false
    /// after a build or a restore until everything has been predicted once).
    certified: bool,
    /// Particles whose pairs have no certificates (they collided or were re-listed since they last had a clean
    /// drift start): the next drift start predicts all their pairs. Every listed pair of free particles has a valid
    /// certificate in the calendar, an event in the queue, or a particle in this list.
    pending: Vec<usize>,
    /// Whether each particle is in `pending`.
    uncertified: Vec<bool>,
    /// Whether each particle collided in the current drift (its pairs are then predicted at the next drift start
    /// without certificates: one that collides at every step, in a dense pile, would only fill the calendar).
    dirty: Vec<bool>,
    /// Calendar entries after its last compaction (stale entries are dropped when it grows well beyond that).
    calendar_live: usize,
    /// For each particle, a time up to which it certainly stays within its allowance (see
    /// [`System::set_expiry`]): a drift start ending no later skips its check. −∞ where unknown.
    expiry: Vec<f64>,
    /// The longest drift the expiries assume (s); a longer drift forgets them.
    expiry_h: f64,
    /// Scratch: the certificates that came due at a drift start.
    due: Vec<Due>,
    /// Scratch: which particles are in the drift start's `pending` list.
    mark: Vec<bool>,
}

/// What a checkpoint needs of the neighbour list to continue bit for bit: the anchors and allowances of the current
/// list (its pairs follow from them), or `None` before the first build.
#[derive(Debug, Clone, PartialEq)]
pub struct NeighbourState {
    /// Positions when listed (m), one per particle.
    pub anchors: Vec<Vec3>,
    /// Travel allowances (m), one per particle.
    pub allowances: Vec<f64>,
}

/// An event the loop applied: its time and the particles it involved.
struct Applied {
    t: f64,
    involved: [Option<usize>; 2],
}

/// Working state of one drift.
struct Drift {
    t0: f64,
    t1: f64,
    walls: Vec<WallStep>,
    queue: EventQueue,
    events: u64,
}

impl System {
    /// A system at t = 0.
    pub fn new(particles: Vec<Particle>, walls: Vec<Wall>, settings: StepperSettings) -> System {
        let n = particles.len();
        System {
            particles,
            walls,
            settings,
            t: 0.0,
            counters: Counters::default(),
            gens: vec![0; n],
            cert_gens: vec![0; n],
            floor: None,
            neighbours: Neighbours::default(),
        }
    }

    /// The current neighbour list's anchors and allowance (for checkpoints), `None` before the first step.
    pub fn neighbour_state(&self) -> Option<NeighbourState> {
        self.neighbours.built.then(|| NeighbourState {
            anchors: self.neighbours.anchors.clone(),
            allowances: self.neighbours.allowances.clone(),
        })
    }

    /// Restores a neighbour list saved by [`System::neighbour_state`] (its pairs are found again from the anchors,
    /// as the build found them). Returns an error when the anchors do not match the particles.
    pub(crate) fn restore_neighbours(&mut self, state: Option<NeighbourState>) -> Result<(), String> {
        let Some(st) = state else {
            self.neighbours = Neighbours::default();
            return Ok(());
        };
        if st.anchors.len() != self.particles.len() || st.allowances.len() != self.particles.len() {
            return Err(format!(
                "{} neighbour anchors and {} allowances for {} particles",
                st.anchors.len(),
                st.allowances.len(),
                self.particles.len()
            ));
        }
        self.neighbours.anchors = st.anchors;
        self.neighbours.allowances = st.allowances;
        self.neighbours.adjacency = self.candidate_pairs();
        self.neighbours.built = true;
        self.floor = None;
        self.file_all();
        Ok(())
    }

    /// After a full build: files every anchor in the cell grid, finds every particle's near walls, and empties the
    /// calendar (the next drift start predicts everything).
    fn file_all(&mut self) {
        let n = self.particles.len();
        let nb = &mut self.neighbours;
        nb.calendar.clear(0.0, 1.0);
        nb.calendar_live = 0;
        nb.certified = false;
        nb.pending.clear();
        nb.uncertified = vec![false; n];
        nb.dirty = vec![false; n];
        nb.mark = vec![false; n];
        nb.expiry = vec![f64::NEG_INFINITY; n];
        if self.settings.skin_steps > 0.0 {
            let particles = &self.particles;
            let entries = (0..n).filter(|&k| particles[k].alive).map(|k| Entry {
                anchor: nb.anchors[k],
                radius: particles[k].radius,
                allowance: nb.allowances[k],
                k,
            });
            nb.grid = AnchorGrid::new(n, entries);
        }
        self.neighbours.near_walls.resize_with(n, Vec::new);
        self.neighbours.near_list.clear();
        self.neighbours.near_pos = vec![usize::MAX; n];
        for k in 0..n {
            self.update_near_walls(k);
        }
        self.neighbours.stuck_list = (0..n).filter(|&k| self.particles[k].stuck.is_some()).collect();
    }

    /// Finds particle `k`'s near walls again (from its anchor and allowance) and files it in the list of particles
    /// with near walls accordingly.
    fn update_near_walls(&mut self, k: usize) {
        let mut near = std::mem::take(&mut self.neighbours.near_walls[k]);
        self.walls_near(k, &mut near);
        let nb = &mut self.neighbours;
        let listed = nb.near_pos[k] != usize::MAX;
        if !near.is_empty() && !listed {
            nb.near_pos[k] = nb.near_list.len();
            nb.near_list.push(k);
        } else if near.is_empty() && listed {
            let at = nb.near_pos[k];
            nb.near_list.swap_remove(at);
            if let Some(&moved) = nb.near_list.get(at) {
                nb.near_pos[moved] = at;
            }
            nb.near_pos[k] = usize::MAX;
        }
        nb.near_walls[k] = near;
    }

    /// The walls particle `k` may touch while it stays within its allowance of its anchor: every wall that moves,
    /// and each fixed one within the particle's radius plus allowance of the anchor (plus a margin far above the
    /// rounding of the distance), since a wall's distance changes no faster than the centre moves. Skipping the
    /// others changes no prediction: their time of impact would be none.
    fn walls_near(&self, k: usize, out: &mut Vec<usize>) {
        out.clear();
        let a = self.neighbours.anchors[k];
        let reach = self.particles[k].radius + self.neighbours.allowances[k];
        for (w, wall) in self.walls.iter().enumerate() {
            let fixed = wall.motion.velocity == Vec3::zeros() && wall.motion.oscillation.is_none();
            if fixed {
                let dist = wall.distance(&wall.origin, &a);
                let margin = certificates::MARGIN_RELATIVE * reach + 1e-10 * (a - wall.origin).norm();
                if dist > reach + margin {
                    continue;
                }
            }
            out.push(w);
        }
    }

    /// Candidate partners from the anchors and the allowance of the current list.
    fn candidate_pairs(&self) -> Vec<Vec<usize>> {
        let nb = &self.neighbours;
        let alive: Vec<usize> = (0..self.particles.len()).filter(|&k| self.particles[k].alive).collect();
        let centres: Vec<Vec3> = alive.iter().map(|&k| nb.anchors[k]).collect();
        let radii: Vec<f64> = alive
            .iter()
            .map(|&k| self.particles[k].radius + nb.allowances[k])
            .collect();
        let mut adjacency = vec![Vec::new(); self.particles.len()];
        for (a, b) in sphere_pairs(&centres, &radii) {
            let (i, j) = (alive[a], alive[b]);
            adjacency[i].push(j);
            adjacency[j].push(i);
        }
        adjacency
    }

    /// Whether every alive particle stays within the list's allowance until `t1` when it moves on straight lines
    /// from `t` (distance from its anchor plus `|v|` times the time left).
    fn list_holds(&self, k: usize, t: f64, t1: f64) -> bool {
        let p = &self.particles[k];
        !p.alive
            || (p.position_at(t) - self.neighbours.anchors[k]).norm() + p.velocity.norm() * (t1 - t)
                <= self.neighbours.allowances[k]
    }

    /// Bounds when particle `k`, now at time `t` in a drift of length `h`, could first fail [`System::list_holds`]
    /// at a drift start, assuming it does not collide (a collision sets a new bound) and no drift is longer than
    /// `h` or the longest drift so far (a longer one forgets every bound). Between kicks a free particle moves on straight lines and the kicks add at most `|g|` times the time
    /// elapsed plus one step to its velocity, so by a drift start whose drift ends `τ` after `t` it has moved at most
    /// `|v| τ + |g| τ (τ/2 + h)` and the check adds at most `(|v| + |g| (τ + h)) h`; the check holds while the
    /// distance from its anchor now plus `|g| τ² + (|v| + 2|g| h) τ + |v| h + 2|g| h²` (a little more) stays within
    /// its allowance, less a margin far above the rounding of the positions. Capped at
    /// [`certificates::HORIZON_STEPS`] steps so that the rounding stays bounded. Stuck particles (moved by their wall)
    /// get −∞: they are checked at every drift start.
    fn set_expiry(&mut self, k: usize, t: f64, h: f64) {
        let p = &self.particles[k];
        let nb = &self.neighbours;
        // The longest drift seen (a landing step may be shorter than the next ones).
        let h = h.max(nb.expiry_h);
        let e = if !p.alive {
            f64::INFINITY
        } else if p.stuck.is_some() {
            f64::NEG_INFINITY
        } else {
            let horizon = certificates::HORIZON_STEPS * h;
            let v = p.velocity.norm();
            let g = self.settings.gravity.map_or(0.0, |g| g.norm());
            let here = p.position_at(t);
            let l = nb.allowances[k];
            let budget = l
                - (here - nb.anchors[k]).norm()
                - certificates::MARGIN_RELATIVE * l
                - 1e-10 * (here.norm() + v * horizon + g * horizon * horizon);
            let (a, b, c) = (g, v + 2.0 * g * h, v * h + 2.0 * g * h * h - budget);
            let tau = if c > 0.0 {
                f64::NEG_INFINITY
            } else if a > 0.0 {
                // The positive root of a τ² + b τ + c, in the form that does not cancel.
                2.0 * (-c) / (b + (b * b - 4.0 * a * c).sqrt())
            } else if b > 0.0 {
                -c / b
            } else {
                horizon
            };
            t + tau.min(horizon)
        };
        self.neighbours.expiry[k] = e;
    }

    /// A fresh allowance for particle `k` listed at `t` in a drift ending at `t1` (module doc) with `skin_steps`
    /// scaled by `stagger`, at least `floor`.
    fn allowance(&self, k: usize, t: f64, t1: f64, h: f64, floor: f64, stagger: f64) -> f64 {
        let v = self.particles[k].velocity.norm();
        let g = self.settings.gravity.map_or(0.0, |g| g.norm());
        let reach = self.settings.skin_steps * stagger * h;
        // At most one radius beyond what this drift needs: larger skins only grow the lists in dense regions.
        let skin = (reach * v + 0.5 * g * reach * reach).min(self.particles[k].radius);
        skin.max(v * (t1 - t)).max(floor)
    }

    /// 1e-3 of the smallest alive radius: keeps resting particles from being re-listed at every collision. Kept
    /// until a particle dies (a pass over all particles at every re-listing cost more than the re-listing).
    fn allowance_floor(&mut self) -> f64 {
        if let Some(f) = self.floor {
            return f;
        }
        let r_min = self
            .particles
            .iter()
            .filter(|p| p.alive)
            .map(|p| p.radius)
            .fold(f64::INFINITY, f64::min);
        let f = if r_min.is_finite() { 1e-3 * r_min } else { 0.0 };
        self.floor = Some(f);
        f
    }

    /// Re-lists particle `k` alone at `t`: fresh anchor and allowance, its pairs found against every other alive
    /// particle's anchor and allowance (the criterion of [`sphere_pairs`], so the list stays what a full build from
    /// the same anchors would give; the candidates come from the cell grid of anchors, [`AnchorGrid`]), its near
    /// walls found again, and its pairs' certificates ended.
    fn reanchor(&mut self, k: usize, t: f64, d: &Drift) {
        self.counters.reanchors += 1;
        self.uncertify(k);
        let floor = self.allowance_floor();
        let l = self.allowance(k, t, d.t1, d.t1 - d.t0, floor, 1.0);
        let nb = &mut self.neighbours;
        let mut mine = std::mem::take(&mut nb.adjacency[k]);
        for &j in &mine {
            nb.adjacency[j].retain(|&x| x != k);
        }
        mine.clear();
        nb.anchors[k] = self.particles[k].position_at(t);
        nb.allowances[k] = l;
        let me = Entry {
            anchor: nb.anchors[k],
            radius: self.particles[k].radius,
            allowance: l,
            k,
        };
        nb.grid.insert(me);
        // The criterion of the full build, `|a_k − a_j| < (R_k + L_k) + R_j + L_j`, in the same arithmetic.
        let rk = self.particles[k].radius + l;
        nb.grid.query(&me.anchor, rk, |e| {
            let reach = rk + e.radius + e.allowance;
            if e.k != k && (e.anchor - me.anchor).norm_squared() < reach * reach {
                mine.push(e.k);
            }
        });
        for &j in &mine {
            nb.adjacency[j].push(k);
        }
        nb.adjacency[k] = mine;
        self.update_near_walls(k);
        self.set_expiry(k, t, d.t1 - d.t0);
    }

    /// Energies and momenta of the free, alive particles.
    pub fn diagnostics(&self) -> Diagnostics {
        let mut d = Diagnostics::default();
        for p in self.particles.iter().filter(|p| p.alive) {
            if p.stuck.is_some() {
                d.stuck += 1;
                continue;
            }
            d.free += 1;
            d.kinetic += 0.5 * p.mass * p.velocity.norm_squared();
            d.rotational += 0.5 * p.inertia() * p.spin.norm_squared();
            if let Some(g) = self.settings.gravity {
                d.potential -= p.mass * g.dot(&p.position);
            }
            d.momentum += p.velocity * p.mass;
            d.angular_momentum += p.position.cross(&p.velocity) * p.mass + p.spin * p.inertia();
        }
        d
    }

    /// Where a stuck particle is at time `t`: the wall's law applied to its attachment offset.
    fn attached_position(&self, a: &Attachment, t: f64) -> Vec3 {
        let w = &self.walls[a.wall];
        let angle = w.motion.spin * (t - a.t_stuck);
        let (s, c) = angle.sin_cos();
        let o = a.offset;
        let rotated = Vec3::new(c * o.x - s * o.y, s * o.x + c * o.y, o.z);
        w.origin_at(t) + w.to_world(&rotated)
    }

    /// Advances the system by one kick–drift–kick step of length `h` (s).
    pub fn step(&mut self, h: f64) -> Result<(), StepError> {
        let t0 = self.t;
        let t1 = t0 + h;
        PHASE_KICK.time(|| {
            self.kick(0.5 * h);
            // Stuck particles follow their wall on the secant of this step.
            for k in 0..self.particles.len() {
                if let Particle {
                    alive: true,
                    stuck: Some(a),
                    ..
                } = self.particles[k]
                {
                    let end = self.attached_position(&a, t1);
                    let p = &mut self.particles[k];
                    p.velocity = (end - p.position) / h;
                    p.spin = self.walls[a.wall].axis * self.walls[a.wall].motion.spin;
                }
            }
        });
        self.drift(t0, t1)?;
        PHASE_KICK.time(|| {
            self.kick(0.5 * h);
            self.t = t1;
            let finite = |v: &Vec3| v.x.is_finite() && v.y.is_finite() && v.z.is_finite();
            for p in &self.particles {
                if p.alive && !(finite(&p.position) && finite(&p.velocity)) {
                    return Err(StepError::NonFinite { id: p.id, t: t1 });
                }
            }
            Ok(())
        })
    }

    fn kick(&mut self, dt: f64) {
        if let Some(g) = self.settings.gravity {
            let mut kicked = 0.0;
            for p in self.particles.iter_mut().filter(|p| p.alive && p.stuck.is_none()) {
                p.velocity += g * dt;
                kicked += p.mass;
            }
            self.counters.field_impulse += g * (dt * kicked);
        }
    }

    fn drift(&mut self, t0: f64, t1: f64) -> Result<(), StepError> {
        let walls = self
            .walls
            .iter()
            .map(|w| WallStep {
                origin0: w.origin_at(t0),
                velocity: w.motion.step_velocity(t0, t1),
            })
            .collect();
        let mut d = Drift {
            t0,
            t1,
            walls,
            queue: EventQueue::new(),
            events: 0,
        };
        let failing: Vec<usize> = PHASE_LIST_CHECK.time(|| {
            let mut failing = Vec::new();
            if self.neighbours.built {
                let nb = &mut self.neighbours;
                if t1 - t0 > nb.expiry_h {
                    nb.expiry_h = t1 - t0;
                    nb.expiry.iter_mut().for_each(|e| *e = f64::NEG_INFINITY);
                }
                for k in 0..self.particles.len() {
                    // The exact check only where the bound of `set_expiry` does not already settle it.
                    if t1 <= self.neighbours.expiry[k] {
                        continue;
                    }
                    if self.list_holds(k, t0, t1) {
                        self.set_expiry(k, t0, t1 - t0);
                    } else {
                        failing.push(k);
                    }
                }
            }
            failing
        });
        let local =
            self.settings.skin_steps > 0.0 && self.neighbours.built && failing.len() * 2 <= self.particles.len();
        if local {
            PHASE_RELIST.time(|| {
                for &k in &failing {
                    self.reanchor(k, t0, &d);
                }
            });
            if self.neighbours.certified && self.settings.prune_predictions {
                PHASE_PREDICT_START.time(|| self.predict_start(&mut d, t0));
            } else {
                PHASE_PREDICT_START.time(|| self.predict_all(&mut d, t0));
            }
        } else {
            self.rebuild(&mut d, t0);
        }
        loop {
            let next = PHASE_EVENTS.time(|| self.next_event(&mut d));
            let Some(Applied { t, involved }) = next? else {
                break;
            };
            let mut must_rebuild = false;
            for k in involved.into_iter().flatten() {
                self.gens[k] += 1;
                self.uncertify(k);
                self.neighbours.dirty[k] = true;
                if !self.list_holds(k, t, t1) {
                    if self.settings.skin_steps > 0.0 {
                        PHASE_RELIST.time(|| self.reanchor(k, t, &d));
                    } else {
                        must_rebuild = true;
                    }
                } else {
                    self.set_expiry(k, t, t1 - t0);
                }
            }
            if must_rebuild {
                self.rebuild(&mut d, t);
            } else {
                PHASE_REPREDICT.time(|| {
                    let [first, second] = involved;
                    if let Some(i) = first {
                        self.predict(&mut d, i, t, None);
                    }
                    if let Some(j) = second {
                        // The pair itself was predicted from the first side (the same event, bit for bit).
                        self.predict(&mut d, j, t, first);
                    }
                });
            }
        }
        PHASE_ADVANCE.time(|| {
            for k in 0..self.particles.len() {
                if !self.particles[k].alive {
                    continue;
                }
                self.particles[k].advance(t1);
                if let Some(a) = self.particles[k].stuck {
                    self.particles[k].position = self.attached_position(&a, t1);
                }
            }
        });
        Ok(())
    }

    /// Pops events until a valid one within the drift, applies it and returns its time and the particles it
    /// involved; `None` when the drift has no more events.
    fn next_event(&mut self, d: &mut Drift) -> Result<Option<Applied>, StepError> {
        while let Some(e) = d.queue.pop() {
            if e.t > d.t1 {
                return Ok(None);
            }
            if e.gen_i != self.gens[e.i] {
                continue;
            }
            if let Partner::Particle(j) = e.partner
                && e.gen_j != self.gens[j]
            {
                continue;
            }
            d.events += 1;
            self.counters.events += 1;
            if d.events > self.settings.max_events_per_step {
                return Err(StepError::Stalled {
                    t: d.t1,
                    limit: self.settings.max_events_per_step,
                });
            }
            let involved = match e.partner {
                Partner::Particle(j) => {
                    self.collide_pair(e.i, j, e.t);
                    [Some(e.i), Some(j)]
                }
                Partner::Wall(w) => {
                    self.collide_wall(d, e.i, w, e.t);
                    [Some(e.i), None]
                }
            };
            return Ok(Some(Applied { t: e.t, involved }));
        }
        Ok(None)
    }

    /// Rebuilds the neighbour list at `t` with a fresh allowance and anchors (positions at `t`; the particles' states
    /// are not touched) and re-predicts everything.
    fn rebuild(&mut self, d: &mut Drift, t: f64) {
        self.counters.rebuilds += 1;
        let floor = self.allowance_floor();
        let n = self.particles.len();
        self.neighbours.allowances = if self.settings.skin_steps > 0.0 {
            // Skins spread over [0.5, 1.5) × skin_steps (golden-ratio sequence), so that particles listed together
            // are not all re-listed at the same later step.
            (0..n)
                .map(|k| {
                    let stagger = 0.5 + (k as f64 * 0.618_033_988_749_895).fract();
                    self.allowance(k, t, d.t1, d.t1 - d.t0, floor, stagger)
                })
                .collect()
        } else {
            let v_max = self
                .particles
                .iter()
                .filter(|p| p.alive)
                .map(|p| p.velocity.norm())
                .fold(0.0, f64::max);
            vec![(2.0 * v_max * (d.t1 - t)).max(floor); n]
        };
        self.neighbours.anchors = self.particles.iter().map(|p| p.position_at(t)).collect();
        PHASE_REBUILD.time(|| {
            self.neighbours.adjacency = self.candidate_pairs();
            self.neighbours.built = true;
            self.file_all();
        });
        PHASE_PREDICT_START.time(|| self.predict_all(d, t));
    }

    /// Empties the queue and the calendar and predicts every listed pair and every wall contact from `t`,
    /// certifying the pairs of free particles without an event in this drift when neither collided in the last one.
    fn predict_all(&mut self, d: &mut Drift, t: f64) {
        d.queue.clear();
        let certify = self.settings.skin_steps > 0.0 && self.settings.prune_predictions;
        let nb = &mut self.neighbours;
        nb.calendar.clear(t, d.t1 - d.t0);
        nb.certified = certify;
        for k in nb.pending.drain(..) {
            nb.uncertified[k] = false;
        }
        for k in 0..self.particles.len() {
            if !self.particles[k].alive {
                continue;
            }
            for jx in 0..self.neighbours.adjacency[k].len() {
                let j = self.neighbours.adjacency[k][jx];
                if j > k {
                    let clean = certify && !self.neighbours.dirty[k] && !self.neighbours.dirty[j];
                    self.predict_pair(d, k, j, t, clean);
                }
            }
            self.predict_walls(d, k, t);
        }
        // The particles that collided in the last drift certify their pairs at their first clean drift start.
        for k in 0..self.particles.len() {
            if std::mem::take(&mut self.neighbours.dirty[k]) && certify {
                self.uncertify(k);
            }
        }
        self.neighbours.calendar_live = self.neighbours.calendar.len();
    }

    /// Ends particle `k`'s pairs' certificates and lists it for the next drift start.
    fn uncertify(&mut self, k: usize) {
        self.cert_gens[k] += 1;
        let nb = &mut self.neighbours;
        if nb.certified && !nb.uncertified[k] {
            nb.uncertified[k] = true;
            nb.pending.push(k);
        }
    }

    /// The drift start's predictions when the calendar is complete: the same events as [`System::predict_all`]
    /// from only the pairs that may have one (module doc). Predicted afresh at `t0`: every pair of a pending
    /// particle (one that collided or was re-listed since its last clean drift start; certified unless either
    /// particle collided in the last drift), the pairs whose certificates come due within the drift, every pair with
    /// a stuck particle (not kicked, so its relative velocity changes at every step), and every free particle against
    /// its near walls (the kicks change every velocity relative to the walls).
    fn predict_start(&mut self, d: &mut Drift, t0: f64) {
        d.queue.clear();
        let pending = std::mem::take(&mut self.neighbours.pending);
        for &k in &pending {
            self.neighbours.mark[k] = true;
        }
        for &k in &pending {
            if !self.particles[k].alive || self.particles[k].stuck.is_some() {
                continue;
            }
            for jx in 0..self.neighbours.adjacency[k].len() {
                let j = self.neighbours.adjacency[k][jx];
                // A pair of two pending particles once; pairs with a stuck particle below.
                if (self.neighbours.mark[j] && j < k) || self.particles[j].stuck.is_some() {
                    continue;
                }
                let clean = !self.neighbours.dirty[k] && !self.neighbours.dirty[j];
                self.predict_pair(d, k, j, t0, clean);
            }
        }
        let mut still = Vec::new();
        for &k in &pending {
            let nb = &mut self.neighbours;
            nb.mark[k] = false;
            let p = &self.particles[k];
            // One that collided in the last drift stays pending until a drift start finds it clean.
            if std::mem::take(&mut nb.dirty[k]) && p.alive && p.stuck.is_none() {
                still.push(k);
            } else {
                nb.uncertified[k] = false;
            }
        }
        self.neighbours.pending = still;
        let mut due = std::mem::take(&mut self.neighbours.due);
        self.neighbours.calendar.take_due(d.t1, &mut due);
        for c in &due {
            if self.certificate_valid(c) {
                self.predict_pair(d, c.i, c.j, t0, true);
            }
        }
        self.neighbours.due = due;
        for sx in 0..self.neighbours.stuck_list.len() {
            let k = self.neighbours.stuck_list[sx];
            if self.particles[k].alive {
                for jx in 0..self.neighbours.adjacency[k].len() {
                    let j = self.neighbours.adjacency[k][jx];
                    self.predict_pair(d, k, j, t0, false);
                }
            }
        }
        for wx in 0..self.neighbours.near_list.len() {
            let k = self.neighbours.near_list[wx];
            self.predict_walls(d, k, t0);
        }
        // Stale certificates (a particle collided or was re-listed) wait in the calendar until they come due; when
        // they outnumber the live ones, drop them.
        let nb = &self.neighbours;
        if nb.calendar.len() > 2 * nb.calendar_live + 8 * self.particles.len() + 1024 {
            let mut calendar = std::mem::take(&mut self.neighbours.calendar);
            calendar.retain(|c| self.certificate_valid(c));
            self.neighbours.calendar_live = calendar.len();
            self.neighbours.calendar = calendar;
        }
    }

    /// Whether a certificate still speaks for its pair: neither particle collided or was re-listed since, both alive
    /// and free.
    fn certificate_valid(&self, c: &Due) -> bool {
        let (pi, pj) = (&self.particles[c.i], &self.particles[c.j]);
        c.gen_i == self.cert_gens[c.i]
            && c.gen_j == self.cert_gens[c.j]
            && pi.alive
            && pj.alive
            && pi.stuck.is_none()
            && pj.stuck.is_none()
    }

    /// Re-predicts particle `k` against its neighbours and the walls at time `t`.
    /// (The pair with `done`, already predicted from the other side, is skipped: it would queue the same event.)
    fn predict(&mut self, d: &mut Drift, k: usize, t: f64, done: Option<usize>) {
        if !self.particles[k].alive {
            return;
        }
        for jx in 0..self.neighbours.adjacency[k].len() {
            let j = self.neighbours.adjacency[k][jx];
            if Some(j) != done {
                self.predict_pair(d, k, j, t, false);
            }
        }
        self.predict_walls(d, k, t);
    }

    /// Predicts the pair `(i, j)` from `t`: queues its collision if it falls within the drift, otherwise, when
    /// `certify` (a drift start, both particles free and clean), files its certificate ([`super::certificates`]).
    fn predict_pair(&mut self, d: &mut Drift, i: usize, j: usize, t: f64, certify: bool) {
        let (pi, pj) = (&self.particles[i], &self.particles[j]);
        if !pj.alive || (pi.stuck.is_some() && pj.stuck.is_some()) {
            return;
        }
        let r = pi.position_at(t) - pj.position_at(t);
        let v = pi.velocity - pj.velocity;
        let b = r.dot(&v);
        let s = pi.radius + pj.radius;
        if b < 0.0 {
            let c = r.norm_squared() - s * s;
            let dt = if c <= 0.0 {
                Some(0.0)
            } else {
                let disc = b * b - v.norm_squared() * c;
                // Cancellation-free smaller root (notes, "Particle–particle").
                (disc >= 0.0).then(|| c / (-b + disc.sqrt()))
            };
            if let Some(te) = dt.map(|dt| t + dt)
                && te <= d.t1
            {
                let (a, bb) = if i < j { (i, j) } else { (j, i) };
                d.queue.push(Event {
                    t: te,
                    i: a,
                    partner: Partner::Particle(bb),
                    gen_i: self.gens[a],
                    gen_j: self.gens[bb],
                });
                // Its event is processed or made stale within this drift, and either re-predicts the pair.
                return;
            }
        }
        if certify && pi.stuck.is_none() && pj.stuck.is_none() {
            let horizon = certificates::HORIZON_STEPS * (d.t1 - d.t0);
            let g = self.settings.gravity.map_or(0.0, |g| g.norm());
            let x = pi.position.norm() + pj.position.norm();
            let speed = pi.velocity.norm() + pj.velocity.norm();
            let reach = s + certificates::margin(s, x, speed, g, horizon);
            let (a, bb) = if i < j { (i, j) } else { (j, i) };
            self.neighbours.calendar.push(Due {
                t: certificates::safe_until(t, &r, &v, reach, horizon),
                i: a,
                j: bb,
                gen_i: self.cert_gens[a],
                gen_j: self.cert_gens[bb],
            });
        }
    }

    fn predict_walls(&self, d: &mut Drift, k: usize, t: f64) {
        let p = &self.particles[k];
        if !p.alive
            || p.stuck.is_some()
            || (self.settings.prune_predictions && self.neighbours.near_walls[k].is_empty())
        {
            return;
        }
        let r = p.position_at(t);
        let all: Vec<usize>;
        let walls = if self.settings.prune_predictions {
            &self.neighbours.near_walls[k]
        } else {
            all = (0..self.walls.len()).collect();
            &all
        };
        for &w in walls {
            let wall = &self.walls[w];
            let ws = d.walls[w];
            let origin_now = ws.origin0 + ws.velocity * (t - d.t0);
            if let Some(dt) = wall.time_of_impact(&origin_now, &ws.velocity, &r, &p.velocity, p.radius, d.t1 - t) {
                d.queue.push(Event {
                    t: t + dt,
                    i: k,
                    partner: Partner::Wall(w),
                    gen_i: self.gens[k],
                    gen_j: 0,
                });
            }
        }
    }

    fn body(p: &Particle) -> Body {
        Body {
            mass: p.mass,
            radius: p.radius,
            inertia: p.inertia(),
            position: p.position,
            velocity: p.velocity,
            spin: p.spin,
        }
    }

    fn collide_pair(&mut self, i: usize, j: usize, t: f64) {
        self.particles[i].advance(t);
        self.particles[j].advance(t);
        let (pi, pj) = (&self.particles[i], &self.particles[j]);
        let s = pi.radius + pj.radius;
        let overlap = (s - (pi.position - pj.position).norm()) / pi.radius.min(pj.radius);
        self.counters.max_overlap = self.counters.max_overlap.max(overlap);
        let collapse = self.settings.collapse_speed;
        let e_before = pi.kinetic_energy() * f64::from(pi.stuck.is_none() as u8)
            + pj.kinetic_energy() * f64::from(pj.stuck.is_none() as u8);
        let mut wall_work = 0.0;
        let outcome = match (pi.stuck, pj.stuck) {
            (None, None) => {
                let r = Restitution {
                    eps_n: 0.5 * (pi.eps_n + pj.eps_n),
                    eps_t: 0.5 * (pi.eps_t + pj.eps_t),
                };
                let (mut b1, mut b2) = (Self::body(pi), Self::body(pj));
                let o = collision::resolve_pair(&mut b1, &mut b2, r, collapse);
                for (k, b) in [(i, b1), (j, b2)] {
                    self.particles[k].velocity = b.velocity;
                    self.particles[k].spin = b.spin;
                }
                o
            }
            (a, b) => {
                // One side is stuck: it is part of its wall (infinite mass) with its rigid velocity.
                let (free, fixed, att) = match (a, b) {
                    (None, Some(att)) => (i, j, att),
                    (Some(att), _) => (j, i, att),
                    _ => unreachable!("both free handled above"),
                };
                let (pf, px) = (&self.particles[free], &self.particles[fixed]);
                let n = (pf.position - px.position).normalize();
                let contact = px.position + n * px.radius;
                let surface = px.velocity + px.spin.cross(&(contact - px.position));
                let wall = &self.walls[att.wall];
                let r = Restitution {
                    eps_n: wall.eps_n.unwrap_or(pf.eps_n),
                    eps_t: wall.eps_t.unwrap_or(pf.eps_t),
                };
                let mut b = Self::body(pf);
                let o = collision::resolve_wall(&mut b, &n, &surface, r, collapse);
                let impulse = (b.velocity - pf.velocity) * pf.mass;
                self.counters.wall_impulse += impulse;
                wall_work = impulse.dot(&surface);
                self.particles[free].velocity = b.velocity;
                self.particles[free].spin = b.spin;
                o
            }
        };
        if outcome.applied {
            self.counters.pair_collisions += 1;
            self.counters.guarded += u64::from(outcome.guarded);
        }
        let (pi, pj) = (&self.particles[i], &self.particles[j]);
        let e_after = pi.kinetic_energy() * f64::from(pi.stuck.is_none() as u8)
            + pj.kinetic_energy() * f64::from(pj.stuck.is_none() as u8);
        self.counters.energy_exchanged += e_after - e_before;
        self.counters.energy_walls += wall_work;
        self.counters.energy_restitution += e_after - e_before - wall_work;
    }

    fn collide_wall(&mut self, d: &Drift, i: usize, w: usize, t: f64) {
        self.particles[i].advance(t);
        let ws = d.walls[w];
        let origin_now = ws.origin0 + ws.velocity * (t - d.t0);
        let wall = &self.walls[w];
        let p = &self.particles[i];
        let (dist, n) = wall.nearest(&origin_now, &p.position);
        self.counters.max_overlap = self.counters.max_overlap.max((p.radius - dist) / p.radius);
        let e_before = p.kinetic_energy();
        let contact = p.position - n * p.radius;
        let surface = wall.surface_velocity(&origin_now, &ws.velocity, &contact);
        // Approaching? (The normal part of the contact velocity is that of the centres: spin is tangential.)
        if (p.velocity - surface).dot(&n) >= 0.0 {
            return;
        }
        self.counters.wall_collisions += 1;
        if wall.absorbing || wall.sticky {
            // The particle leaves the dynamics: its kinetic and potential energy and its momentum go with it.
            let g_pot = self
                .settings
                .gravity
                .map(|g| -p.mass * g.dot(&p.position))
                .unwrap_or(0.0);
            self.counters.energy_exchanged -= e_before + g_pot;
            self.counters.energy_removed -= e_before + g_pot;
            self.counters.wall_impulse -= p.velocity * p.mass;
        }
        if wall.absorbing {
            self.counters.absorbed += 1;
            self.floor = None;
            self.neighbours.grid.remove(i);
            self.particles[i].alive = false;
            return;
        }
        if wall.sticky {
            let att = Attachment {
                wall: w,
                offset: wall.to_local(&(p.position - origin_now)),
                t_stuck: t,
            };
            let end = self.attached_position(&att, d.t1);
            let axis_spin = wall.axis * wall.motion.spin;
            self.neighbours.stuck_list.push(i);
            let p = &mut self.particles[i];
            p.stuck = Some(att);
            p.velocity = if d.t1 > t {
                (end - p.position) / (d.t1 - t)
            } else {
                ws.velocity
            };
            p.spin = axis_spin;
            return;
        }
        let r = Restitution {
            eps_n: wall.eps_n.unwrap_or(p.eps_n),
            eps_t: wall.eps_t.unwrap_or(p.eps_t),
        };
        let mut b = Self::body(p);
        let o = collision::resolve_wall(&mut b, &n, &surface, r, self.settings.collapse_speed);
        self.counters.guarded += u64::from(o.guarded);
        let impulse = (b.velocity - p.velocity) * p.mass;
        let wall_work = impulse.dot(&surface);
        let p = &mut self.particles[i];
        p.velocity = b.velocity;
        p.spin = b.spin;
        let change = p.kinetic_energy() - e_before;
        self.counters.energy_exchanged += change;
        self.counters.energy_walls += wall_work;
        self.counters.energy_restitution += change - wall_work;
        self.counters.wall_impulse += impulse;
    }
}
