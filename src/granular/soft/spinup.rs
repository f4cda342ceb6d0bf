//! Quasi-static spin-up of a soft-sphere rubble pile (Zhang17 §2.3.4, Fig. 3, Table 5): the scene table
//! `[spinup]` ([`SpinupSection`]: periods in hours, times in seconds), the period path `T(t)`, the forcing of the
//! central body and its release once global disruption is confirmed.
//!
//! Path ([`SpinupPath`]): `T = T_start` until `t_start`, linear in `T` to `T_inter` at `t_inter`, then to `T_final`
//! at `t_final` in `rests + 1` linear stages separated by rests of `rest_length` (Fig. 3), then held. The central
//! body is the heaviest contact-connected set of particles ([`central_body`]). After each step its angular momentum
//! `L` along `axis` is set to `L*` by a rigid-rotation increment about its centre of mass, `Δω = (L* − L)/I`:
//! `v_i += Δω a × (x_i − R)`, `ω_i += Δω a` (linear momentum kept; the work is booked in the residuals). `L* = I Ω(t)`
//! for `target = "period"` (the period "is strictly constrained to the spin-up path", §2.3.4), `L* = I_ref Ω(t)`
//! with `I_ref` of the members as placed at t = 0 for `"angular_momentum"` (an expanding body spins down).
//! Release (§2.3.4 footnote 6): when b/a, c/a or η_B moves from its value at `t_start` by more than
//! `release_axis_ratio` / `release_packing` at `release_samples` consecutive outputs, the forcing stops for good.

use scene_derive::SceneFields;
use serde::{Deserialize, Serialize};

use crate::granular::soft::ordered_sum::{SUM_CHUNK, ordered_reduce, ordered_sum};
use crate::granular::soft::particle::Particle;
use crate::io::scene_file::SceneError;
use crate::math::Vec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering};

fn d_release_samples() -> u32 {
    2
}
fn d_rve() -> usize {
    300
}

/// The `[spinup]` table as written (periods in hours, times in seconds).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "spinup")]
#[serde(deny_unknown_fields)]
pub struct SpinupSection {
    /// spin period held while the body settles
    #[serde(rename = "T_start")]
    #[field(unit = "h", default = "required", range = Positive)]
    pub period_start_h: f64,
    /// spin period at t_inter (<= T_start)
    #[serde(rename = "T_inter")]
    #[field(unit = "h", default = "required", range = Positive)]
    pub period_inter_h: f64,
    /// final spin period, held after t_final (<= T_inter)
    #[serde(rename = "T_final")]
    #[field(unit = "h", default = "required", range = Positive)]
    pub period_final_h: f64,
    /// end of the settling phase
    #[field(unit = "s", default = "required", range = NonNegative)]
    pub t_start: f64,
    /// end of the fast linear spin-up (>= t_start)
    #[field(unit = "s", default = "required", range = NonNegative)]
    pub t_inter: f64,
    /// end of the slow spin-up (>= t_inter)
    #[field(unit = "s", default = "required", range = NonNegative)]
    pub t_final: f64,
    /// rest stages in the slow phase
    #[serde(default)]
    #[field(unit = "count", default = "0", range = Rule("integer >= 0"))]
    pub rests: u32,
    /// length of each rest; all rests together shorter than t_final - t_inter
    #[serde(default)]
    #[field(unit = "s", default = "0", range = NonNegative)]
    pub rest_length: f64,
    /// spin axis, fixed in space
    #[serde(default, deserialize_with = "crate::io::scene_file::exact::option")]
    #[field(unit = "-", default = "[0, 0, 1]", range = Rule("3 finite numbers, non-zero"))]
    pub axis: Option<[f64; 3]>,
    /// What the forcing holds on the path ([`SpinupTarget`]; Zhang17 §2.3.4).
    #[serde(default)]
    #[field(unit = "text", default = "\"period\"", range = Rule("\"period\" | \"angular_momentum\""))]
    #[field(meaning = "what the forcing holds on the path: the rotation period, or L = I_ref 2 pi/T(t)")]
    pub target: Option<String>,
    /// disruption when |d(b/a)| or |d(c/a)| exceeds this
    #[serde(default = "crate::granular::vocabulary::hundredths::<10>")]
    #[field(unit = "-", default = "0.1", range = Positive)]
    pub release_axis_ratio: f64,
    /// disruption when the interior packing fraction changes by more than this
    #[serde(default = "crate::granular::vocabulary::hundredths::<1>")]
    #[field(unit = "-", default = "0.01", range = Positive)]
    pub release_packing: f64,
    /// consecutive samples beyond a release threshold that confirm disruption
    #[serde(default = "d_release_samples")]
    #[field(unit = "count", default = "2", range = Rule("integer >= 1"))]
    pub release_samples: u32,
    /// target particles per representative volume element (stress diagnostics)
    #[serde(default = "d_rve")]
    #[field(unit = "count", default = "300", range = Rule("integer >= 8"))]
    pub rve_particles: usize,
    /// The depth of [`InteriorRule::Depth`], the rule for η_B meant for piles of unequal spheres (PP1).
    #[serde(default)]
    #[field(unit = "m", default = "none (layer rule)", range = NonNegative)]
    #[field(
        meaning = "depth below the surface layer from which a particle counts in eta_B (piles of unequal spheres)"
    )]
    pub interior_depth: Option<f64>,
    /// depth span over which a particle's eta_B weight rises from 0 to 1; needs interior_depth
    #[serde(default)]
    #[field(unit = "m", default = "interior_depth", range = Positive)]
    pub interior_ramp: Option<f64>,
}

/// Which particles the interior packing fraction η_B is taken over
/// (`analysis::spinup_diagnostics`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum InteriorRule {
    /// Closed cells, less every particle within 10 % of the sum of the radii from a particle with an open cell
    /// (two surface layers of equal spheres). A sphere is in or out, so for unequal spheres (PP1, radii over
    /// 8×) η_B jumps by ±0.01 as large spheres near the surface enter or leave the set.
    #[default]
    Layers,
    /// Every closed cell weighted by its depth `d` below the surface layer (the distance from its centre to the
    /// nearest centre with an open cell): weight 0 for `d ≤ depth`, rising linearly to 1 at `depth + ramp` (m).
    /// The weights and the cell volumes change continuously with the positions, so η_B does too.
    Depth {
        /// Depth (m) from which a particle counts.
        depth: f64,
        /// Depth span (m) over which its weight rises from 0 to 1.
        ramp: f64,
    },
}

/// The spin-period path `T(t)` in SI units (periods and times in s).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpinupPath {
    /// `T_start` (s).
    pub period_start: f64,
    /// `T_inter` (s).
    pub period_inter: f64,
    /// `T_final` (s).
    pub period_final: f64,
    /// `t_start` (s).
    pub t_start: f64,
    /// `t_inter` (s).
    pub t_inter: f64,
    /// `t_final` (s).
    pub t_final: f64,
    /// Rests in the slow phase.
    pub rests: u32,
    /// Length of each rest (s).
    pub rest_length: f64,
}

impl SpinupPath {
    /// The path's period (s) at time `t` (s).
    pub fn period(&self, t: f64) -> f64 {
        let lerp = |a: f64, b: f64, f: f64| a + (b - a) * f.clamp(0.0, 1.0);
        if t <= self.t_start {
            return self.period_start;
        }
        if t <= self.t_inter {
            let span = self.t_inter - self.t_start;
            let f = if span > 0.0 { (t - self.t_start) / span } else { 1.0 };
            return lerp(self.period_start, self.period_inter, f);
        }
        if t >= self.t_final {
            return self.period_final;
        }
        let stages = self.rests as f64 + 1.0;
        let stage = (self.t_final - self.t_inter - self.rests as f64 * self.rest_length) / stages;
        let cycle = stage + self.rest_length;
        let s = t - self.t_inter;
        let k = (s / cycle).floor().min(self.rests as f64);
        let within = s - k * cycle;
        let done = k + if stage > 0.0 { (within / stage).min(1.0) } else { 1.0 };
        lerp(self.period_inter, self.period_final, done / stages)
    }

    /// The path's spin rate `2π/T(t)` (rad/s).
    pub fn omega(&self, t: f64) -> f64 {
        std::f64::consts::TAU / self.period(t)
    }
}

/// What the spin-up forcing holds on the path (`[spinup] target`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SpinupTarget {
    /// The body's rotation period `2π I/L` (current inertia) equals the path's after every step.
    Period,
    /// The body's angular momentum equals `I_ref 2π/T(t)`, `I_ref` its members' inertia as placed at t = 0.
    AngularMomentum,
}

/// Validated `[spinup]` settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpinupSettings {
    /// The path.
    pub path: SpinupPath,
    /// What the forcing holds on the path.
    pub target: SpinupTarget,
    /// Unit spin axis.
    pub axis: Vec3,
    /// Release threshold on b/a and c/a.
    pub release_axis_ratio: f64,
    /// Release threshold on η_B.
    pub release_packing: f64,
    /// Consecutive samples that confirm disruption.
    pub release_samples: u32,
    /// Target particles per RVE.
    pub rve_particles: usize,
    /// Which particles η_B is taken over.
    pub interior: InteriorRule,
}

impl crate::io::scene_file::Validator<'_> {
    /// Checks a `[spinup]` table; errors name the field (`spinup.T_final`, …) and the expected value.
    pub(crate) fn spinup(&self, s: &SpinupSection) -> Result<SpinupSettings, SceneError> {
        let ts = self.field(&SpinupSection::PERIOD_START_H, s.period_start_h)?;
        let ti = self.field(&SpinupSection::PERIOD_INTER_H, s.period_inter_h)?;
        let tf = self.field(&SpinupSection::PERIOD_FINAL_H, s.period_final_h)?;
        if ti > ts {
            return Err(self.invalid("spinup.T_inter", format!("must be <= T_start = {ts} h, got {ti}")));
        }
        if tf > ti {
            return Err(self.invalid("spinup.T_final", format!("must be <= T_inter = {ti} h, got {tf}")));
        }
        let t0 = self.field(&SpinupSection::T_START, s.t_start)?;
        let t1 = self.field(&SpinupSection::T_INTER, s.t_inter)?;
        let t2 = self.field(&SpinupSection::T_FINAL, s.t_final)?;
        if t1 < t0 {
            return Err(self.invalid("spinup.t_inter", format!("must be >= t_start = {t0} s, got {t1}")));
        }
        if t2 < t1 {
            return Err(self.invalid("spinup.t_final", format!("must be >= t_inter = {t1} s, got {t2}")));
        }
        let rest = self.field(&SpinupSection::REST_LENGTH, s.rest_length)?;
        if s.rests as f64 * rest >= t2 - t1 && s.rests > 0 {
            return Err(self.invalid(
                "spinup.rest_length",
                format!(
                    "rests x rest_length must be < t_final - t_inter = {} s, got {} x {rest}",
                    t2 - t1,
                    s.rests
                ),
            ));
        }
        let axis = Vec3::from(s.axis.unwrap_or([0.0, 0.0, 1.0]));
        if !(axis.iter().all(|x| x.is_finite()) && axis.norm() > 0.0) {
            return Err(self.invalid(
                "spinup.axis",
                format!("must be a finite non-zero vector, got {:?}", s.axis),
            ));
        }
        if s.release_samples == 0 {
            return Err(self.invalid("spinup.release_samples", "must be >= 1, got 0"));
        }
        let target = match s.target.as_deref() {
            None | Some("period") => SpinupTarget::Period,
            Some("angular_momentum") => SpinupTarget::AngularMomentum,
            Some(other) => {
                return Err(self.invalid(
                    "spinup.target",
                    format!("must be \"period\" or \"angular_momentum\", got {other:?}"),
                ));
            }
        };
        let interior = match (s.interior_depth, s.interior_ramp) {
            (None, None) => InteriorRule::Layers,
            (None, Some(_)) => {
                return Err(self.invalid("spinup.interior_ramp", "needs spinup.interior_depth (m, >= 0)"));
            }
            (Some(d), ramp) => {
                let depth = self.field(&SpinupSection::INTERIOR_DEPTH, d)?;
                let ramp = match ramp {
                    Some(w) => self.field(&SpinupSection::INTERIOR_RAMP, w)?,
                    None if depth > 0.0 => depth,
                    None => {
                        return Err(self.invalid(
                            "spinup.interior_ramp",
                            "must be given (m, > 0) when spinup.interior_depth is 0",
                        ));
                    }
                };
                InteriorRule::Depth { depth, ramp }
            }
        };
        if s.rve_particles < 8 {
            return Err(self.invalid("spinup.rve_particles", format!("must be >= 8, got {}", s.rve_particles)));
        }
        Ok(SpinupSettings {
            path: SpinupPath {
                period_start: ts * 3600.0,
                period_inter: ti * 3600.0,
                period_final: tf * 3600.0,
                t_start: t0,
                t_inter: t1,
                t_final: t2,
                rests: s.rests,
                rest_length: rest,
            },
            axis: axis.normalize(),
            target,
            release_axis_ratio: self.field(&SpinupSection::RELEASE_AXIS_RATIO, s.release_axis_ratio)?,
            release_packing: self.field(&SpinupSection::RELEASE_PACKING, s.release_packing)?,
            release_samples: s.release_samples,
            rve_particles: s.rve_particles,
            interior,
        })
    }
}

/// Membership of the central body: the largest-mass set of particles connected by the pair contacts `contacts`
/// (`(i, j)` keys, as `granular::soft::forces::SoftSystem::touching_pairs` after a force evaluation); ties go
/// to the set holding the lowest index.
pub fn central_body(particles: &[Particle], contacts: impl IntoIterator<Item = (usize, usize)>) -> Vec<bool> {
    central_body_par(particles, |union| contacts.into_iter().for_each(|(i, j)| union(i, j)))
}

/// [`central_body`] with the contacts handed over in parallel: `contacts` calls its argument once for every
/// contact `(i, j)`, from any thread, in any order (`SoftSystem::for_each_touching_pair`). The sets are joined by a
/// lock-free union–find, so the result is the same on any number of threads: the sets do not depend on the order
/// of the unions, and every set is named by its lowest index.
pub fn central_body_par(particles: &[Particle], contacts: impl FnOnce(&(dyn Fn(usize, usize) + Sync))) -> Vec<bool> {
    let sets = DisjointSets::new(particles.len());
    contacts(&|i, j| sets.union(i, j));
    sets.heaviest(particles)
}

/// Disjoint sets of particle indices with atomic parent links: a root is linked only to a lower index (by a
/// compare-and-swap that fails if it has stopped being a root meanwhile), so every set's root is its lowest index
/// whatever the order of the unions and the threads doing them.
struct DisjointSets {
    parent: Vec<AtomicU32>,
}

impl DisjointSets {
    /// `n` singletons.
    fn new(n: usize) -> Self {
        assert!(n < u32::MAX as usize, "{n} particles: indices must fit in 32 bits");
        DisjointSets {
            parent: (0..n as u32).map(AtomicU32::new).collect(),
        }
    }

    /// The root of `i`'s set. Links are followed without compressing them while unions may run: only roots are
    /// ever linked, to a root of lower index, so with the contacts in key order the paths stay short, and plain
    /// loads cost far less than the atomic writes of path halving (`analysis/ssdem_perf/NOTES.md`).
    fn find(&self, mut i: u32) -> u32 {
        loop {
            let p = self.parent[i as usize].load(Ordering::Acquire);
            if p == i {
                return i;
            }
            i = p;
        }
    }

    /// Joins the sets of `i` and `j` (ignored unless both are particle indices).
    fn union(&self, i: usize, j: usize) {
        let n = self.parent.len();
        if i >= n || j >= n {
            return;
        }
        let (mut a, mut b) = (i as u32, j as u32);
        loop {
            a = self.find(a);
            b = self.find(b);
            if a == b {
                return;
            }
            let (low, high) = (a.min(b), a.max(b));
            if self.parent[high as usize]
                .compare_exchange(high, low, Ordering::AcqRel, Ordering::Acquire)
                .is_ok()
            {
                return;
            }
        }
    }

    /// Members of the set of largest mass (ties: the set of lowest root, i.e. lowest index). The set masses are
    /// summed in particle order.
    fn heaviest(&self, particles: &[Particle]) -> Vec<bool> {
        let n = particles.len();
        // The unions are done: compress every path to its root (all writers store the same root, so the order of
        // the stores does not matter), which bounds the cost whatever the order of the unions was.
        let root: Vec<u32> = (0..n as u32)
            .into_par_iter()
            .with_min_len(4096)
            .map(|i| {
                let r = self.find(i);
                let mut k = i;
                while k != r {
                    let next = self.parent[k as usize].load(Ordering::Acquire);
                    if next != r {
                        self.parent[k as usize].store(r, Ordering::Release);
                    }
                    k = next;
                }
                r
            })
            .collect();
        let mut mass = vec![0.0; n];
        for (p, &r) in particles.iter().zip(&root) {
            mass[r as usize] += p.mass;
        }
        let best = (0..n).fold(0, |b, r| if mass[r] > mass[b] { r } else { b }) as u32;
        root.par_iter().with_min_len(4096).map(|&r| r == best).collect()
    }
}

/// Rotation of a set of particles about an axis through their centre of mass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyRotation {
    /// Centre of mass (m).
    pub centre: Vec3,
    /// Centre-of-mass velocity (m/s).
    pub velocity: Vec3,
    /// Moment of inertia about the axis through the centre (kg m²), spheres' own (2/5) m r² included.
    pub inertia: f64,
    /// Angular momentum along the axis about the centre, orbital plus spins (kg m²/s).
    pub angular_momentum: f64,
    /// Mass (kg).
    pub mass: f64,
}

impl BodyRotation {
    /// Effective spin period `2π I/L` (s); infinite without rotation.
    pub fn period(&self) -> f64 {
        if self.angular_momentum.abs() > 0.0 {
            std::f64::consts::TAU * self.inertia / self.angular_momentum.abs()
        } else {
            f64::INFINITY
        }
    }
}

/// [`BodyRotation`] of the members of `particles` about unit `axis`. The sums over the members run in parallel
/// in fixed chunks of particles (`ordered_sum::ordered_reduce`): the same bits on any number of threads.
pub fn body_rotation(particles: &[Particle], member: &[bool], axis: &Vec3) -> BodyRotation {
    let n = particles.len().min(member.len());
    let (m, mx, mv) = ordered_reduce(
        n,
        (0.0, Vec3::zeros(), Vec3::zeros()),
        |(m, mx, mv), k| {
            if member[k] {
                let p = &particles[k];
                *m += p.mass;
                *mx += p.position * p.mass;
                *mv += p.velocity * p.mass;
            }
        },
        |(m, mx, mv), (cm, cmx, cmv)| {
            *m += cm;
            *mx += cmx;
            *mv += cmv;
        },
    );
    if m <= 0.0 {
        return BodyRotation {
            centre: Vec3::zeros(),
            velocity: Vec3::zeros(),
            inertia: 0.0,
            angular_momentum: 0.0,
            mass: 0.0,
        };
    }
    let (centre, velocity) = (mx / m, mv / m);
    let (inertia, l) = ordered_reduce(
        n,
        (0.0, 0.0),
        |(inertia, l), k| {
            if member[k] {
                let p = &particles[k];
                let d = p.position - centre;
                let perp = d - axis * d.dot(axis);
                *inertia += p.mass * perp.norm_squared() + p.inertia();
                *l += d.cross(&(p.velocity - velocity)).dot(axis) * p.mass + p.inertia() * p.spin.dot(axis);
            }
        },
        |(inertia, l), (ci, cl)| {
            *inertia += ci;
            *l += cl;
        },
    );
    BodyRotation {
        centre,
        velocity,
        inertia,
        angular_momentum: l,
        mass: m,
    }
}

/// The forcing's state through a run (checkpointed by [`SpinupDriver::state`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SpinupDriver {
    /// Settings.
    pub settings: SpinupSettings,
    initial: Vec<Vec3>,
    initial_centre: Vec3,
    /// Whether the forcing has been released.
    pub released: bool,
    /// Time of the release (s).
    pub release_time: Option<f64>,
    strikes: u32,
    /// b/a, c/a and η_B at the first sample at or after `t_start` (the release reference).
    pub reference: Option<[f64; 3]>,
}

/// What one spin-up increment did ([`SpinupDriver::apply`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ForcingIncrement {
    /// The rigid-rotation increment `Δω` (rad/s).
    pub d_omega: f64,
    /// Kinetic energy it added (J).
    pub work: f64,
    /// Angular momentum it added, about the origin (kg m²/s).
    pub angular_impulse: Vec3,
}

impl SpinupDriver {
    /// A driver for a run starting from `initial` (the particles at t = 0).
    pub fn new(settings: SpinupSettings, initial: &[Particle]) -> Self {
        let m: f64 = initial.iter().map(|p| p.mass).sum();
        let c = initial.iter().map(|p| p.position * p.mass).sum::<Vec3>() / m.max(f64::MIN_POSITIVE);
        SpinupDriver {
            settings,
            initial: initial.iter().map(|p| p.position).collect(),
            initial_centre: c,
            released: false,
            release_time: None,
            strikes: 0,
            reference: None,
        }
    }

    /// `I_ref` of the members: their moment of inertia about the axis as placed at t = 0 (kg m²).
    pub fn reference_inertia(&self, particles: &[Particle], member: &[bool]) -> f64 {
        let a = self.settings.axis;
        let n = particles.len().min(member.len()).min(self.initial.len());
        ordered_sum(n, |k| {
            if member[k] {
                let (p, d) = (&particles[k], self.initial[k] - self.initial_centre);
                p.mass * (d - a * d.dot(&a)).norm_squared() + p.inertia()
            } else {
                0.0
            }
        })
    }

    /// Applies the spin-up increment at time `t` (s) to the central body given by `member`; nothing once released.
    /// Returns what it did: the applied `Δω` (rad/s), the work (J) and the angular momentum about the origin
    /// (kg m²/s) it gave the spheres, for the run's forcing-aware energy and angular-momentum residuals.
    pub fn apply(&self, particles: &mut [Particle], member: &[bool], t: f64) -> ForcingIncrement {
        let mut inc = ForcingIncrement::default();
        if self.released {
            return inc;
        }
        let a = self.settings.axis;
        let rot = body_rotation(particles, member, &a);
        if rot.inertia <= 0.0 {
            return inc;
        }
        let inertia = match self.settings.target {
            SpinupTarget::Period => rot.inertia,
            SpinupTarget::AngularMomentum => self.reference_inertia(particles, member),
        };
        let target = inertia * self.settings.path.omega(t);
        let dw = (target - rot.angular_momentum) / rot.inertia;
        // In parallel over fixed chunks of particles, whose sums are added in order (as `ordered_reduce`).
        let chunks: Vec<(f64, Vec3)> = particles
            .par_chunks_mut(SUM_CHUNK)
            .zip(member.par_chunks(SUM_CHUNK))
            .map(|(ps, ms)| {
                let (mut work, mut impulse) = (0.0, Vec3::zeros());
                for (p, _) in ps.iter_mut().zip(ms).filter(|(_, k)| **k) {
                    let dv = a.cross(&(p.position - rot.centre)) * dw;
                    let ds = a * dw;
                    work += p.mass * (p.velocity.dot(&dv) + 0.5 * dv.norm_squared())
                        + p.inertia() * (p.spin.dot(&ds) + 0.5 * ds.norm_squared());
                    impulse += p.position.cross(&dv) * p.mass + ds * p.inertia();
                    p.velocity += dv;
                    p.spin += ds;
                }
                (work, impulse)
            })
            .collect();
        for (work, impulse) in chunks {
            inc.work += work;
            inc.angular_impulse += impulse;
        }
        inc.d_omega = dw;
        inc
    }

    /// Feeds the diagnostics of an output sample at time `t` (s): sets the reference at the first sample at or
    /// after `t_start`, then counts consecutive samples beyond a release threshold and releases the forcing at
    /// `release_samples` of them. Non-finite values (e.g. no interior particle left) count as beyond.
    pub fn observe(&mut self, t: f64, b_over_a: f64, c_over_a: f64, packing: f64) {
        if self.released || t < self.settings.path.t_start {
            return;
        }
        let Some(r) = self.reference else {
            self.reference = Some([b_over_a, c_over_a, packing]);
            return;
        };
        let beyond = |x: f64, x0: f64, tol: f64| (x - x0).abs() > tol || (x - x0).is_nan();
        let s = &self.settings;
        let out = beyond(b_over_a, r[0], s.release_axis_ratio)
            || beyond(c_over_a, r[1], s.release_axis_ratio)
            || (r[2].is_finite() && beyond(packing, r[2], s.release_packing));
        self.strikes = if out { self.strikes + 1 } else { 0 };
        if self.strikes >= s.release_samples {
            self.released = true;
            self.release_time = Some(t);
        }
    }

    /// The checkpointed state: released, release time (NaN if none), strikes, reference (NaN × 3 if none).
    pub fn state(&self) -> Vec<f64> {
        let r = self.reference.unwrap_or([f64::NAN; 3]);
        vec![
            if self.released { 1.0 } else { 0.0 },
            self.release_time.unwrap_or(f64::NAN),
            self.strikes as f64,
            if self.reference.is_some() { 1.0 } else { 0.0 },
            r[0],
            r[1],
            r[2],
        ]
    }

    /// Restores [`SpinupDriver::state`]; `None` if malformed.
    pub fn restore(&mut self, v: &[f64]) -> Option<()> {
        if v.len() != 7 {
            return None;
        }
        self.released = v[0] == 1.0;
        self.release_time = v[1].is_finite().then_some(v[1]);
        self.strikes = v[2] as u32;
        self.reference = (v[3] == 1.0).then_some([v[4], v[5], v[6]]);
        Some(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn path(rests: u32, rest_length: f64) -> SpinupPath {
        SpinupPath {
            period_start: 5.0,
            period_inter: 3.0,
            period_final: 2.0,
            t_start: 10.0,
            t_inter: 30.0,
            t_final: 130.0,
            rests,
            rest_length,
        }
    }

    /// The settings of the driver tests: `target` on [`path`] with no rests, about z.
    fn settings(target: SpinupTarget) -> SpinupSettings {
        SpinupSettings {
            path: path(0, 0.0),
            axis: Vec3::z(),
            target,
            release_axis_ratio: 0.1,
            release_packing: 0.01,
            release_samples: 2,
            rve_particles: 300,
            interior: InteriorRule::Layers,
        }
    }

    #[test]
    fn path_nodes_linear_stages_and_rests() {
        let p = path(0, 0.0);
        assert_eq!(p.period(0.0), 5.0);
        assert_eq!(p.period(10.0), 5.0);
        assert!((p.period(20.0) - 4.0).abs() < 1e-12);
        assert!((p.period(30.0) - 3.0).abs() < 1e-12);
        assert!((p.period(80.0) - 2.5).abs() < 1e-12);
        assert_eq!(p.period(130.0), 2.0);
        assert_eq!(p.period(1e6), 2.0);
        // two rests of 20 s: three stages of 20 s (0.333 h of T each), held during the rests
        let p = path(2, 20.0);
        assert!((p.period(50.0) - (3.0 - 1.0 / 3.0)).abs() < 1e-12);
        assert!((p.period(60.0) - (3.0 - 1.0 / 3.0)).abs() < 1e-12);
        assert!((p.period(70.0) - (3.0 - 1.0 / 3.0)).abs() < 1e-12);
        assert!((p.period(80.0) - 2.5).abs() < 1e-12);
        assert!((p.period(100.0) - (2.0 + 1.0 / 3.0)).abs() < 1e-12);
        assert!((p.period(129.999) - 2.0).abs() < 1e-4);
    }

    #[test]
    fn central_body_is_the_heaviest_contact_cluster() {
        let p = |m: f64| Particle {
            mass: m,
            radius: 1.0,
            position: Vec3::zeros(),
            velocity: Vec3::zeros(),
            spin: Vec3::zeros(),
        };
        let ps = [p(1.0), p(1.0), p(1.0), p(5.0), p(1.0)];
        let contacts = [(0, 1), (1, 2), (3, 4)];
        assert_eq!(
            central_body(&ps, contacts.iter().copied()),
            vec![false, false, false, true, true]
        );
    }

    /// The parallel union–find gives the serial one's membership on a random contact graph with several large
    /// clusters, on 1 and 4 threads, and its sets are named by their lowest index.
    #[test]
    fn central_body_in_parallel_equals_the_serial_one() {
        let n = 5000;
        let mut state = 99u64;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as usize
        };
        let ps: Vec<Particle> = (0..n)
            .map(|k| Particle {
                mass: 1.0 + (k % 7) as f64,
                radius: 1.0,
                position: Vec3::zeros(),
                velocity: Vec3::zeros(),
                spin: Vec3::zeros(),
            })
            .collect();
        // edges inside four index bands (clusters of unequal mass), none between them
        let contacts: Vec<(usize, usize)> = (0..6000)
            .map(|_| {
                let band = next() % 4;
                let (lo, len) = (band * 1200, 900 + band * 60);
                let (a, b) = (lo + next() % len, lo + next() % len);
                (a.min(b), a.max(b))
            })
            .filter(|(a, b)| a != b)
            .collect();
        let serial = central_body(&ps, contacts.iter().copied());
        assert!(serial.iter().filter(|m| **m).count() > 500, "a large central body");
        for threads in [1, 4] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let par =
                pool.install(|| central_body_par(&ps, |union| contacts.par_iter().for_each(|&(i, j)| union(i, j))));
            assert_eq!(par, serial, "{threads} threads");
        }
        let sets = DisjointSets::new(n);
        contacts.iter().rev().for_each(|&(i, j)| sets.union(i, j));
        for &(i, j) in &contacts {
            let r = sets.find(i as u32);
            assert!(r <= i.min(j) as u32 && r == sets.find(j as u32));
        }
    }

    /// The forcing of 3000 particles (three chunks of the parallel sums, some particles not members) gives the same
    /// bits on 1 and 4 threads, for both targets.
    #[test]
    fn forcing_is_the_same_on_any_number_of_threads() {
        for target in [SpinupTarget::Period, SpinupTarget::AngularMomentum] {
            let settings = settings(target);
            let ps: Vec<Particle> = (0..3000)
                .map(|k| {
                    let x = k as f64;
                    Particle {
                        mass: 1.0 + (k % 5) as f64,
                        radius: 0.5,
                        position: Vec3::new((0.7 * x).cos() * 20.0, (1.3 * x).sin() * 30.0, (x * 0.37).sin() * 9.0),
                        velocity: Vec3::new(1e-3 * (x * 0.1).sin(), -0.05, 0.02),
                        spin: Vec3::new(0.0, 0.1, 1e-3 * x.cos()),
                    }
                })
                .collect();
            let member: Vec<bool> = (0..ps.len()).map(|k| k % 11 != 3).collect();
            let d = SpinupDriver::new(settings, &ps);
            let run = |threads: usize| {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                let mut ps = ps.clone();
                let inc = pool.install(|| d.apply(&mut ps, &member, 20.0));
                (ps, inc)
            };
            let (one, inc1) = run(1);
            let (four, inc4) = run(4);
            assert!(inc1.d_omega != 0.0);
            assert_eq!(one, four, "{target:?}");
            assert_eq!(inc1.work.to_bits(), inc4.work.to_bits());
            assert_eq!(inc1.angular_impulse, inc4.angular_impulse);
        }
    }

    #[test]
    fn increment_sets_the_target_angular_momentum_keeps_momentum_and_reports_its_work() {
        let settings = settings(SpinupTarget::AngularMomentum);
        let mut ps: Vec<Particle> = (0..6)
            .map(|k| Particle {
                mass: 1.0 + k as f64,
                radius: 0.5,
                position: Vec3::new((k as f64).cos() * 2.0, (k as f64).sin() * 3.0, k as f64 * 0.3),
                velocity: Vec3::new(0.1 * k as f64, -0.05, 0.02),
                spin: Vec3::new(0.0, 0.1, 0.3),
            })
            .collect();
        let d = SpinupDriver::new(settings, &ps);
        let member = vec![true; 6];
        let p0: Vec3 = ps.iter().map(|p| p.velocity * p.mass).sum();
        let ke = |ps: &[Particle]| -> f64 {
            ps.iter()
                .map(|p| 0.5 * p.mass * p.velocity.norm_squared() + 0.5 * p.inertia() * p.spin.norm_squared())
                .sum()
        };
        let l = |ps: &[Particle]| -> Vec3 {
            ps.iter()
                .map(|p| p.position.cross(&p.velocity) * p.mass + p.spin * p.inertia())
                .sum()
        };
        let (ke0, l0) = (ke(&ps), l(&ps));
        let inc = d.apply(&mut ps, &member, 20.0);
        // the reported work and angular impulse are the changes of kinetic energy and angular momentum
        assert!((ke(&ps) - ke0 - inc.work).abs() < 1e-12 * ke(&ps), "{inc:?}");
        assert!(
            (l(&ps) - l0 - inc.angular_impulse).norm() < 1e-12 * l(&ps).norm(),
            "{inc:?}"
        );
        let rot = body_rotation(&ps, &member, &settings.axis);
        let want = d.reference_inertia(&ps, &member) * std::f64::consts::TAU / 4.0;
        assert!((rot.angular_momentum - want).abs() < 1e-12 * want, "{rot:?} {want}");
        let p1: Vec3 = ps.iter().map(|p| p.velocity * p.mass).sum();
        assert!((p1 - p0).norm() < 1e-12);
        // unmoved particles: I = I_ref, so the period is the path's
        assert!((rot.period() - 4.0).abs() < 1e-12);
    }

    /// A body that has expanded by 10 % since t = 0: the period target puts its period on the path, the
    /// angular-momentum target leaves it slower by the inertia ratio I/I_ref = 1.21.
    #[test]
    fn period_target_holds_the_path_on_an_expanded_body_angular_momentum_target_does_not() {
        let ps0: Vec<Particle> = (0..6)
            .map(|k| Particle {
                mass: 1.0 + k as f64,
                radius: 0.5,
                position: Vec3::new((k as f64).cos() * 2.0, (k as f64).sin() * 3.0, k as f64 * 0.3),
                velocity: Vec3::zeros(),
                spin: Vec3::zeros(),
            })
            .collect();
        let member = vec![true; 6];
        let centre = ps0.iter().map(|p| p.position * p.mass).sum::<Vec3>() / ps0.iter().map(|p| p.mass).sum::<f64>();
        let mut expanded = ps0.clone();
        for p in &mut expanded {
            p.position = centre + (p.position - centre) * 1.1;
        }
        let period_after = |target: SpinupTarget| {
            let settings = settings(target);
            let d = SpinupDriver::new(settings, &ps0);
            let mut ps = expanded.clone();
            d.apply(&mut ps, &member, 20.0);
            let rot = body_rotation(&ps, &member, &Vec3::z());
            (rot.period(), rot.inertia / d.reference_inertia(&ps, &member))
        };
        let (t_period, _) = period_after(SpinupTarget::Period);
        assert!((t_period / 4.0 - 1.0).abs() < 1e-13, "{t_period}");
        let (t_am, ratio) = period_after(SpinupTarget::AngularMomentum);
        assert!(ratio > 1.15, "the expansion must raise the inertia: {ratio}");
        assert!((t_am / (4.0 * ratio) - 1.0).abs() < 1e-12, "{t_am} vs {}", 4.0 * ratio);
    }

    #[test]
    fn release_needs_consecutive_confirmations_and_state_round_trips() {
        let settings = settings(SpinupTarget::Period);
        let mut d = SpinupDriver::new(settings, &[]);
        d.observe(5.0, 0.5, 0.5, 0.5); // before t_start: ignored
        assert_eq!(d.reference, None);
        d.observe(10.0, 0.9, 0.8, 0.74);
        d.observe(20.0, 0.75, 0.8, 0.74); // one strike
        d.observe(30.0, 0.9, 0.8, 0.74); // reset
        d.observe(40.0, 0.9, 0.8, 0.72); // η strike
        assert!(!d.released);
        let mut e = SpinupDriver::new(settings, &[]);
        e.restore(&d.state()).unwrap();
        assert_eq!(e, d);
        d.observe(50.0, 0.9, 0.65, 0.74);
        assert!(d.released);
        assert_eq!(d.release_time, Some(50.0));
    }
}
