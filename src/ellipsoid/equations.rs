//! Equations of motion of N interacting ellipsoids (Roig03 Eqs. 28–37) as an [`OdeSystem`].
//!
//! State per body, in order: `r` (3, m), `q` (4), `u = m ṙ` (3, kg m/s), `p = M(q) q̇` (4, kg m² s⁻¹),
//! i.e. 14 numbers; when attitudes are not integrated (all bodies spheres and no dissipation, so nothing
//! depends on attitude) only `r, u` (6 numbers) and the spins stay constant. With dissipation on, one
//! more component at the end carries `∫F dt` (J), so `H(t) − H0 − 2∫F dt` is a checkable residual.
//!
//! `u̇ = ∂L/∂r + ∂F/∂ṙ`; `ṗ = ∂L/∂q + ∂F/∂q̇ − λ q` with λ fixed by differentiating `q·q̇ = 0` twice:
//! `qᵀ M⁻¹ ṗ = qᵀ M⁻¹ Ṁ M⁻¹ p − pᵀ M⁻² p` (Roig03 Eq. 35 as corrected in the notes). The right-hand side
//! solves it per body in the closed form [`constrained_momentum_rate_closed_form`] (`ṗ = g − λ q`); the paper's
//! 4×4 system of Eq. 36 solved by LU is its test oracle.
//!
//! The attitude parts of the pair forces are summed per body as torques conjugate to the world spin
//! ([`contact_spin_gradient`], the dissipation's `∂F/∂ω`) and mapped to the quaternion once per body: that is the
//! tangential part of `∂U_C/∂q` on `|q| = 1`, and `ṗ` does not depend on the radial part (it only shifts `λ`).

use crate::ellipsoid::body::{Body, Ellipsoid, InertiaModel};
use crate::ellipsoid::calibration::{lambda, pair_prefactor};
use crate::ellipsoid::dissipation::{BodyVelocity, pair_dissipation};
use crate::ellipsoid::dissipation_jacobian::{BodyLinear, DissipationJacobian, PairLinear};
use crate::ellipsoid::gravity::{
    BLOCKED_FROM, add_gravity_forces, add_gravity_forces_packed, gravity_blocks, gravity_forces,
};
use crate::ellipsoid::gravity_tree::{GravityMethod, frozen_tree_gravity_forces, tree_gravity_forces};
use crate::ellipsoid::potential::{
    BodyGeometry, Taper, contact_spin_gradient, interaction_radius, is_negligible, max_cull_exponent, overlap,
    overlap_within_taper,
};
use crate::ellipsoid::quaternion::{
    body_spin, extended_inertia, from_unit_quaternion, inverse_mass_apply, mass_matrix, q_dot_from_body_spin,
    rotation_matrix, rotational_kinetic_gradient, to_unit_quaternion, w_matrix,
};
use crate::ellipsoid::tide::TideTerm;
use crate::geometry::neighbours::sphere_pairs;
use crate::gravity::octree::{FrozenOctree, Octree};
use crate::integrate::OdeSystem;
use crate::integrate::linearly_implicit::StiffSolve;
use crate::math::{Vec3, Vec4};
use crate::phase::{Kind, Phase};
use rayon::prelude::*;
use std::sync::Arc;

/// SI gravitational constant (m³ kg⁻¹ s⁻²), the default of `gravity = { G = … }`.
pub const G_SI: f64 = 6.674e-11;

/// Monopole gravity term (Roig03 Eq. 6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GravityTerm {
    /// Gravitational constant G (m³ kg⁻¹ s⁻²); SI default [`G_SI`].
    pub g: f64,
    /// Exact pair sum or octree ([`GravityMethod`]; default [`GravityMethod::Auto`]: the tree from 5000 bodies).
    pub method: GravityMethod,
}

impl GravityTerm {
    /// Gravity with constant `g` (m³ kg⁻¹ s⁻²) and the default method ([`GravityMethod::Auto`]).
    pub fn new(g: f64) -> Self {
        GravityTerm {
            g,
            method: GravityMethod::default(),
        }
    }
}

/// Gaussian-overlap contact term (Roig03 Eqs. 10–12).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactTerm {
    /// Pairs whose potential is provably below `cutoff × amplitude` are skipped (dimensionless, default 1e-16).
    pub cutoff: f64,
}

impl Default for ContactTerm {
    fn default() -> Self {
        ContactTerm { cutoff: 1e-16 }
    }
}

/// Point dissipation term (Roig03 Eqs. 40–41).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DissipationTerm {
    /// Dissipation coefficient F0 (s m⁻²): `F_ij = −F0 U_Cij [ … velocity² … ]`.
    pub f0: f64,
}

/// Which physics a scene enables; `None` = not computed at all.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Physics {
    /// Monopole gravity.
    pub gravity: Option<GravityTerm>,
    /// Contact potential.
    pub contact: Option<ContactTerm>,
    /// Dissipation (weights by the contact overlap; may be on without the contact force).
    pub dissipation: Option<DissipationTerm>,
}

impl Physics {
    /// Everything on, as the impact experiments run it: gravity with SI G, contact with the default cutoff,
    /// dissipation with `f0` (s m⁻²).
    pub fn impact(f0: f64) -> Self {
        Physics {
            gravity: Some(GravityTerm::new(G_SI)),
            contact: Some(ContactTerm::default()),
            dissipation: Some(DissipationTerm { f0 }),
        }
    }
}

/// Model constants shared by all pairs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelConfig {
    /// Width parameter κ of the Gaussian mass distribution (Roig03 Eq. 2), > 3/2.
    pub kappa: f64,
    /// Which moments of inertia the bodies get.
    pub inertia: InertiaModel,
    /// G used in `U0_ij` (Roig03 Eq. 11) — the gravity term's G, or [`G_SI`] when gravity is off.
    pub contact_g: f64,
}

impl ModelConfig {
    /// Gaussian moments of inertia (Roig03 Eq. 4) and SI G in `U0_ij`, with the given κ.
    pub fn gaussian_si(kappa: f64) -> Self {
        ModelConfig {
            kappa,
            inertia: InertiaModel::Gaussian,
            contact_g: G_SI,
        }
    }
}

/// Energies, momenta and constraint errors of a state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Diagnostics {
    /// Translational kinetic energy K_T (J).
    pub kinetic_translational: f64,
    /// Rotational kinetic energy K_R (J).
    pub kinetic_rotational: f64,
    /// Contact potential energy U_C (J); 0 when the contact term is off.
    pub potential_contact: f64,
    /// Gravitational potential energy U_G (J); 0 when gravity is off.
    pub potential_gravity: f64,
    /// `2 ∫ F dt` so far (J, ≤ 0).
    pub dissipated: f64,
    /// Tidal energy `E_tide` of a flyby (J, see [`crate::ellipsoid::tide`]); 0 without one or from
    /// [`EllipsoidSystem::diagnostics`] (which has no time).
    pub potential_tidal: f64,
    /// Total linear momentum (kg m/s).
    pub momentum: Vec3,
    /// Total angular momentum about the origin, orbital + spin (kg m²/s).
    pub angular_momentum: Vec3,
    /// Scale for momentum errors: Σ m|v| (kg m/s).
    pub momentum_scale: f64,
    /// Scale for angular-momentum errors: Σ (|r × m v| + |I ω|) (kg m²/s).
    pub angular_momentum_scale: f64,
    /// Scale for energy errors: K + |U_C| + |U_G| + |E_tide| (J).
    pub energy_scale: f64,
    /// max over bodies of ||q| − 1|.
    pub quaternion_norm_error: f64,
    /// Impulse of the flyby tide's net force `∫ Σ F_tide dt` so far (kg m/s); 0 without a tide (or a massless
    /// planet). Integrated as state components ([`EllipsoidSystem::tide_impulse_index`]).
    pub tidal_impulse: Vec3,
    /// Impulse of the tide's torque about the origin `∫ Σ r × F_tide dt` so far (kg m²/s); 0 without a tide.
    pub tidal_torque_impulse: Vec3,
}

impl Diagnostics {
    /// Total mechanical energy H = K_T + K_R + U_C + U_G (+ E_tide in a flyby) (J).
    pub fn energy(&self) -> f64 {
        self.kinetic_translational
            + self.kinetic_rotational
            + self.potential_contact
            + self.potential_gravity
            + self.potential_tidal
    }
}

/// What the pair pass does with the neighbour search's candidates at one state ([`EllipsoidSystem::pair_census`]):
/// the counts that, with the cost of each stage, make up the contact part of a right-hand side.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PairCensus {
    /// Candidate pairs of the bounding-sphere search (the Verlet list, grown by its skin).
    pub candidates: usize,
    /// Candidates that pass the cheap bound ([`is_negligible`]) and need the overlap exponent (a 3×3 inverse).
    pub exponent_evaluated: usize,
    /// Pairs whose exponent lies below their taper's end: potential, gradients and dissipation computed.
    pub interacting: usize,
    /// Interacting pairs at or inside the contact of their equivalent spheres (exponent ≤ κλ_ij, Roig03 Eq. 12).
    pub touching: usize,
}

/// Kinematic quantities of one body in one state.
#[derive(Debug, Clone, Copy)]
struct Kinematics {
    r: Vec3,
    q: Vec4,
    u: Vec3,
    /// `ṙ = u/m` (m/s).
    velocity: Vec3,
    p: Vec4,
    q_dot: Vec4,
    /// `M(q)⁻¹ q` (zero when attitudes are not integrated).
    m_inv_q: Vec4,
    spin_body: Vec3,
    spin_world: Vec3,
    geometry: Option<BodyGeometry>,
}

/// Contributions of one pair to the generalised forces.
#[derive(Debug, Clone, Copy)]
struct PairTerms {
    i: usize,
    j: usize,
    /// Generalised force on `r_i` (N); `r_j` gets its negative.
    force_i: Vec3,
    /// Generalised forces conjugate to the world spins `ω_i`, `ω_j` (N m): `−∂U_C/∂ω + ∂F/∂ω`, mapped to the
    /// quaternions per body ([`spin_force_to_quaternion`]) after all pairs are summed.
    torque_i: Vec3,
    torque_j: Vec3,
    /// `U_C` of the pair (J), counted only when the contact term is on.
    potential: f64,
    /// `F_ij` (W).
    dissipation: f64,
}

/// A candidate pair of the neighbour search with its constants, which depend only on the two bodies: computed
/// once when the candidate list is built instead of at every evaluation (the prefactor costs an `exp`).
#[derive(Debug, Clone, Copy)]
struct CandidatePair {
    i: usize,
    j: usize,
    /// `U0_ij m_i m_j (κ/π)^{3/2}` (J m³), see [`pair_prefactor`].
    prefactor: f64,
    /// The far-pair taper ([`Taper::for_pair`]).
    taper: Taper,
}

/// Candidates per block of the pair pass: each block keeps its interacting pairs in its own reused buffer.
const PAIR_BLOCK: usize = 64;

/// The slot of a culled candidate (see `RhsScratch::slots`).
const NO_TERMS: u32 = u32::MAX;

/// Buffers of the right-hand side kept between evaluations: once grown, an evaluation allocates nothing.
#[derive(Default)]
struct RhsScratch {
    kin: Vec<Kinematics>,
    positions: Vec<Vec3>,
    /// The interacting pairs of candidate block `b` (candidates `b·PAIR_BLOCK ..`), in candidate order.
    blocks: Vec<Vec<PairTerms>>,
    /// Where candidate `k`'s terms are in its block (`blocks[k / PAIR_BLOCK][slots[k]]`), [`NO_TERMS`] when it was
    /// culled.
    slots: Vec<u32>,
    /// Per-block gravity forces ([`gravity_blocks`]).
    gravity: Vec<Vec<Vec3>>,
    /// Pair forces per body (N).
    force: Vec<Vec3>,
    /// Pair torques per body (N m, world frame; [`PairTerms::torque_i`]).
    torque: Vec<Vec3>,
}

/// Below this many candidate pairs the cull and pair terms run serially: the work does not pay for waking the
/// thread pool.
const PARALLEL_CANDIDATES: usize = 512;

/// From this many bodies the pair cache's check (one distance per body, ~1 ns each) runs in parallel: below it a
/// fork–join (tens of µs with sleeping workers) costs more than the whole check, which runs once per evaluation.
const PARALLEL_COVERS: usize = 8192;

/// Candidates per parallel task at least (a culled candidate costs a few ns, a kept one ~100 ns).
const CANDIDATES_PER_TASK: usize = 64;

/// From this many bodies on, the per-body passes (kinematics, gravity blocks, body rates) run in parallel.
const PARALLEL_BODIES: usize = 64;

/// Bodies per thread at least ([`EllipsoidSystem::useful_threads`]): with fewer, joining a parallel pass costs more
/// than the thread's share of it.
pub const BODIES_PER_THREAD: usize = 25;

// Where an evaluation's time goes (`rubblepile bench scaling`; see [`crate::phase`]).
static PHASE_GATHER: Phase = Phase::new("ellipsoid.gather_positions", Kind::Serial);
static PHASE_KINEMATICS: Phase = Phase::new("ellipsoid.kinematics", Kind::Parallel);
static PHASE_CANDIDATES: Phase = Phase::new("ellipsoid.candidate_pairs", Kind::Serial);
static PHASE_PAIR_FORCES: Phase = Phase::new("ellipsoid.pair_forces", Kind::Parallel);
static PHASE_PAIR_SUM: Phase = Phase::new("ellipsoid.pair_sum", Kind::Serial);
static PHASE_PAIR_SUM_PARALLEL: Phase = Phase::new("ellipsoid.pair_sum_per_body", Kind::Parallel);
static PHASE_GRAVITY: Phase = Phase::new("ellipsoid.gravity", Kind::Parallel);
static PHASE_SMALL_GRAVITY: Phase = Phase::new("ellipsoid.gravity_half_loop", Kind::Serial);
static PHASE_RATES: Phase = Phase::new("ellipsoid.body_rates", Kind::Parallel);

/// The N-ellipsoid system.
pub struct EllipsoidSystem {
    initial: Vec<Body>,
    shapes: Vec<Ellipsoid>,
    moments: Vec<Vec3>,
    inertia_ext: Vec<Vec4>,
    radii: Vec<f64>,
    model: ModelConfig,
    physics: Physics,
    rotation: bool,
    stride: usize,
    /// The contact term's relative cutoff: each pair's taper starts `−ln(cutoff)` above its contact exponent κλ.
    cutoff: f64,
    cull_exp: f64,
    /// Verlet list of candidate pairs, reused while no body has moved more than its skin (see
    /// [`PairCache`]); a cache only: the pairs used at a state never depend on it.
    pair_cache: std::sync::Mutex<Option<Arc<PairCache>>>,
    /// Buffers reused by [`OdeSystem::rhs`] (an evaluation that finds them in use allocates its own).
    scratch: std::sync::Mutex<RhsScratch>,
    /// Tree gravity's interaction lists, fixed at the state of the step being taken
    /// ([`OdeSystem::begin_step`]) so that the tree's forces are smooth within the step; `None` (outside an
    /// integrator's advance, under an integrator that does not call `begin_step`, or without tree gravity):
    /// every evaluation walks a fresh tree.
    gravity_lists: std::sync::Mutex<Option<Arc<FrozenOctree>>>,
    /// Body masses (kg), contiguous for the gravity sums.
    masses: Vec<f64>,
    /// A planet on a prescribed orbit ([`EllipsoidSystem::with_tide`]); `None`: no tide computed.
    tide: Option<TideTerm>,
}

/// Skin of the candidate-pair (Verlet) list, as a fraction of each body's interaction radius.
pub const PAIR_SKIN_FRACTION: f64 = 0.25;

/// Candidate pairs found with each body's interaction radius grown by a skin `s_i`, valid for any state where
/// every body satisfies `|r_i − r_i,ref| + max(0, ρ_i − ρ_i,ref) ≤ s_i`: then every pair with
/// `|Δ| < ρ_i + ρ_j` is among the candidates. The exact cull ([`is_negligible`]) is applied to the candidates at
/// each state, so the pairs used (and their order, sorted) are exactly those of a fresh search.
struct PairCache {
    positions: Vec<Vec3>,
    radii: Vec<f64>,
    skins: Vec<f64>,
    /// Shared with the evaluations that use it, so that none copies it or holds the lock while using it.
    candidates: Arc<Candidates>,
}

/// The candidate pairs (sorted by `(i, j)`) and, per body, the candidates it takes part in.
struct Candidates {
    pairs: Vec<CandidatePair>,
    /// Body `b`'s candidates are `members[start[b]..start[b + 1]]`, in candidate order: the pairs `(i, b)`, then the
    /// pairs `(b, j)`. Summing a body's pair terms in this order adds them exactly as the serial scatter over the
    /// candidates does, so the per-body sum can run in parallel with the same bits ([`sum_pair_terms`]).
    start: Vec<u32>,
    members: Vec<u32>,
}

impl Candidates {
    /// The candidates of `n` bodies and their per-body lists (a counting sort: two passes over the pairs).
    fn new(pairs: Vec<CandidatePair>, n: usize) -> Candidates {
        let mut start = vec![0u32; n + 1];
        for c in &pairs {
            start[c.i + 1] += 1;
            start[c.j + 1] += 1;
        }
        for b in 0..n {
            start[b + 1] += start[b];
        }
        let mut next: Vec<u32> = start[..n].to_vec();
        let mut members = vec![0u32; 2 * pairs.len()];
        for (k, c) in pairs.iter().enumerate() {
            for b in [c.i, c.j] {
                members[next[b] as usize] = k as u32;
                next[b] += 1;
            }
        }
        Candidates { pairs, start, members }
    }
}

impl PairCache {
    fn build(
        centres: &[Vec3],
        radii: &[f64],
        candidate: impl Fn((usize, usize)) -> CandidatePair + Sync + Send,
    ) -> Self {
        let skins: Vec<f64> = radii.iter().map(|r| PAIR_SKIN_FRACTION * r).collect();
        let grown: Vec<f64> = radii.iter().zip(&skins).map(|(r, s)| r + s).collect();
        PairCache {
            positions: centres.to_vec(),
            radii: radii.to_vec(),
            candidates: Arc::new(Candidates::new(
                candidates_of(sphere_pairs(centres, &grown), candidate),
                centres.len(),
            )),
            skins,
        }
    }

    fn covers(&self, centres: &[Vec3], radii: &[f64]) -> bool {
        let holds =
            |i: usize| (centres[i] - self.positions[i]).norm() + (radii[i] - self.radii[i]).max(0.0) <= self.skins[i];
        centres.len() == self.positions.len()
            && if centres.len() >= PARALLEL_COVERS {
                (0..centres.len())
                    .into_par_iter()
                    .with_min_len(PARALLEL_COVERS)
                    .all(holds)
            } else {
                (0..centres.len()).all(holds)
            }
    }
}

/// The pair terms of `blocks` summed per body into `force` and `torque` (zeros on entry), in parallel over the
/// bodies: each body adds its candidates' terms in candidate order ([`Candidates::members`]), which are the adds of
/// the serial scatter over the candidates in the same order, so the bits are those of one thread. Returns the
/// total dissipation rate, summed in candidate order beside the bodies' sums.
fn sum_pair_terms(
    candidates: &Candidates,
    blocks: &[Vec<PairTerms>],
    slots: &[u32],
    force: &mut [Vec3],
    torque: &mut [Vec3],
) -> f64 {
    let per_body = |(b, (f, tq)): (usize, (&mut Vec3, &mut Vec3))| {
        let (lo, hi) = (candidates.start[b] as usize, candidates.start[b + 1] as usize);
        for &k in &candidates.members[lo..hi] {
            let k = k as usize;
            let slot = slots[k];
            if slot == NO_TERMS {
                continue;
            }
            let t = &blocks[k / PAIR_BLOCK][slot as usize];
            if t.i == b {
                *f += t.force_i;
                *tq += t.torque_i;
            } else {
                *f -= t.force_i;
                *tq += t.torque_j;
            }
        }
    };
    let ((), dissipation) = rayon::join(
        || {
            force
                .par_iter_mut()
                .zip(torque.par_iter_mut())
                .enumerate()
                .with_min_len(PARALLEL_BODIES / 4)
                .for_each(per_body)
        },
        || blocks.iter().flatten().fold(0.0, |sum, t| sum + t.dissipation),
    );
    dissipation
}

/// The pairs' constants, in the pairs' order; in parallel for many pairs (each costs an exponential).
fn candidates_of(
    pairs: Vec<(usize, usize)>,
    candidate: impl Fn((usize, usize)) -> CandidatePair + Sync + Send,
) -> Vec<CandidatePair> {
    if pairs.len() >= PARALLEL_CANDIDATES {
        pairs
            .into_par_iter()
            .with_min_len(CANDIDATES_PER_TASK)
            .map(candidate)
            .collect()
    } else {
        pairs.into_iter().map(candidate).collect()
    }
}

impl EllipsoidSystem {
    /// Builds the system from bodies (validated by the caller), model constants and physics.
    pub fn new(bodies: &[Body], model: ModelConfig, physics: Physics) -> Self {
        let shapes: Vec<Ellipsoid> = bodies.iter().map(|b| b.shape).collect();
        let kappa_i = model.inertia.inertia_kappa(model.kappa);
        let moments: Vec<Vec3> = shapes.iter().map(|s| s.principal_moments(kappa_i)).collect();
        let rotation = physics.dissipation.is_some() || !shapes.iter().all(|s| s.is_sphere());
        let cutoff = physics.contact.map_or(ContactTerm::default().cutoff, |c| c.cutoff);
        EllipsoidSystem {
            initial: bodies.to_vec(),
            inertia_ext: moments.iter().map(extended_inertia).collect(),
            radii: shapes.iter().map(|s| s.equivalent_radius()).collect(),
            shapes,
            moments,
            model,
            physics,
            rotation,
            stride: if rotation { 14 } else { 6 },
            cutoff,
            cull_exp: max_cull_exponent(model.kappa, cutoff),
            pair_cache: std::sync::Mutex::new(None),
            scratch: std::sync::Mutex::new(RhsScratch::default()),
            gravity_lists: std::sync::Mutex::new(None),
            masses: bodies.iter().map(|b| b.shape.mass).collect(),
            tide: None,
        }
    }

    /// The same system with the flyby tide `tide` (`None`: none) added to every body's force.
    pub fn with_tide(mut self, tide: Option<TideTerm>) -> Self {
        self.tide = tide;
        self
    }

    /// The packed initial state (quaternions normalised, `q̇ ⊥ q`).
    pub fn initial_state(&self) -> Vec<f64> {
        let mut y = vec![0.0; self.dim()];
        self.pack_bodies(&self.initial, &mut y);
        y
    }

    /// Writes the positions, velocities and (when integrated, [`EllipsoidSystem::rotation_integrated`]) attitudes
    /// and body-frame spins of `bodies` (one per body of the system, in order; their shapes are not read) into the
    /// packed state `y`, as [`EllipsoidSystem::initial_state`] packs the initial bodies (quaternions normalised,
    /// `q̇ ⊥ q`). Components past the bodies' are left as they are.
    pub fn pack_bodies(&self, bodies: &[Body], y: &mut [f64]) {
        for (i, b) in bodies.iter().enumerate() {
            let s = &mut y[i * self.stride..(i + 1) * self.stride];
            let u = b.velocity * b.shape.mass;
            s[0..3].copy_from_slice(b.position.as_slice());
            if self.rotation {
                let q = b.quaternion.normalize();
                let q_dot = q_dot_from_body_spin(&q, &b.spin_body);
                let p = mass_matrix(&q, &self.inertia_ext[i]) * q_dot;
                s[3..7].copy_from_slice(q.as_slice());
                s[7..10].copy_from_slice(u.as_slice());
                s[10..14].copy_from_slice(p.as_slice());
            } else {
                s[3..6].copy_from_slice(u.as_slice());
            }
        }
    }

    /// Pulls every attitude of the packed state `y` back onto the constraint `|q| = 1, q·q̇ = 0` and returns the
    /// largest `||q| − 1|` it found (0 when attitudes are not integrated).
    ///
    /// Roig03 enforces `|q| = 1` only through the multiplier of Eq. 35, which holds `d²|q|²/dt² = 0`: the
    /// integrator's local errors in `|q|` and `q·q̇` are never pulled back and add up, turn after turn. Per body,
    /// this keeps the body-frame spin `ω_b = 2 W₃(q) q̇` and sets `q ← q/|q|`, `q̇ ← ½ Wᵀ(q)(ω_b, 0)` (tangent),
    /// `p ← M(q) q̇` (Roig03 Eq. 25). Positions, momenta `u` and the dissipation integral are left bit-identical;
    /// the body's rotational kinetic energy `½ ω_b·I ω_b` and its world spin change only through the norm error
    /// (a projection method, Hairer, Lubich & Wanner, *Geometric Numerical Integration*, §IV.4).
    ///
    /// ```
    /// use rubblepile::ellipsoid::body::{Body, Ellipsoid, InertiaModel};
    /// use rubblepile::ellipsoid::equations::{EllipsoidSystem, G_SI, ModelConfig, Physics};
    /// use rubblepile::math::{Vec3, Vec4};
    /// let body = Body {
    ///     shape: Ellipsoid { axes: Vec3::new(3.0, 2.0, 1.0), mass: 2000.0 },
    ///     position: Vec3::zeros(),
    ///     velocity: Vec3::zeros(),
    ///     quaternion: Vec4::new(0.0, 0.0, 0.0, 1.0),
    ///     spin_body: Vec3::new(0.1, 0.0, 1e-3),
    /// };
    /// let model = ModelConfig { kappa: 10.0, inertia: InertiaModel::Gaussian, contact_g: G_SI };
    /// let system = EllipsoidSystem::new(&[body], model, Physics::default());
    /// let mut y = system.initial_state();
    /// for k in 3..7 { y[k] *= 1.0 + 1e-4; } // |q| = 1 + 1e-4
    /// let drift = system.project_attitudes(&mut y);
    /// assert!((drift - 1e-4).abs() < 1e-12);
    /// let q = Vec4::new(y[3], y[4], y[5], y[6]);
    /// assert!((q.norm() - 1.0).abs() < 1e-15);
    /// ```
    pub fn project_attitudes(&self, y: &mut [f64]) -> f64 {
        if !self.rotation {
            return 0.0;
        }
        let mut drift: f64 = 0.0;
        for i in 0..self.n_bodies() {
            let k = self.kinematics(i, y, false);
            drift = drift.max((k.q.norm() - 1.0).abs());
            let q = k.q.normalize();
            let p = mass_matrix(&q, &self.inertia_ext[i]) * q_dot_from_body_spin(&q, &k.spin_body);
            let s = &mut y[i * self.stride..(i + 1) * self.stride];
            s[3..7].copy_from_slice(q.as_slice());
            s[10..14].copy_from_slice(p.as_slice());
        }
        drift
    }

    /// Whether attitudes are integrated (false for a system of spheres without dissipation, whose spins are
    /// constant and whose attitudes follow from them).
    pub fn rotation_integrated(&self) -> bool {
        self.rotation
    }

    /// Whether the forces are smooth functions of the state under every integrator: false when gravity is
    /// summed by the tree, whose forces jump where an interaction list changes (see
    /// [`crate::ellipsoid::gravity_tree`]). Under an integrator that calls [`OdeSystem::begin_step`]
    /// (Bulirsch–Stoer, Dop853) the lists are fixed per step and the forces are smooth within each step.
    pub fn forces_are_smooth(&self) -> bool {
        let n = self.n_bodies();
        self.physics.gravity.is_none_or(|g| g.method.tree_theta(n).is_none())
    }

    /// The most threads an evaluation uses well: one per [`BODIES_PER_THREAD`] bodies, at least one (the run
    /// driver forks over no more; the bits do not depend on it).
    pub fn useful_threads(&self) -> usize {
        (self.n_bodies() / BODIES_PER_THREAD).max(1)
    }

    /// Number of bodies.
    pub fn n_bodies(&self) -> usize {
        self.shapes.len()
    }

    /// The model constants.
    pub fn model(&self) -> &ModelConfig {
        &self.model
    }

    /// Principal moments of inertia of each body (kg m²).
    pub fn principal_moments(&self) -> &[Vec3] {
        &self.moments
    }

    /// State components per body (14 with rotation: position, momentum, quaternion and its momentum; 6 without).
    pub fn stride(&self) -> usize {
        self.stride
    }

    /// The dissipation's Jacobian in the momenta at state `y` ([`DissipationJacobian`], the stiff part the linearly
    /// implicit integrator solves with), over the pairs whose dissipation the right-hand side computes; `None`
    /// without dissipation.
    pub fn dissipation_jacobian(&self, y: &[f64]) -> Option<DissipationJacobian> {
        let f0 = self.physics.dissipation?.f0;
        if !self.rotation {
            return None;
        }
        let kappa = self.model.kappa;
        let kin = self.all_kinematics(y, true);
        let candidates = self.candidate_pairs(&kin);
        let pairs = candidates
            .pairs
            .iter()
            .filter_map(|c| {
                let (gi, gj) = (kin[c.i].geometry.as_ref()?, kin[c.j].geometry.as_ref()?);
                let delta = kin[c.i].r - kin[c.j].r;
                if is_negligible(kappa, &delta, gi, gj, c.taper.end) {
                    return None;
                }
                let ov = overlap_within_taper(c.prefactor, kappa, &delta, gi, gj, &c.taper)?;
                Some(PairLinear::new(f0, kappa, c.i, c.j, &ov, gi, gj))
            })
            .collect();
        let bodies = kin
            .iter()
            .enumerate()
            .map(|(i, k)| {
                let g = k.geometry.as_ref().expect("geometry computed above");
                BodyLinear::new(self.shapes[i].mass, &self.moments[i], &self.inertia_ext[i], g)
            })
            .collect();
        Some(DissipationJacobian::new(self.stride, bodies, pairs))
    }

    /// Index of the `∫F dt` component in the state, when dissipation is on.
    pub fn dissipation_index(&self) -> Option<usize> {
        self.physics.dissipation.map(|_| self.n_bodies() * self.stride)
    }

    /// Index of the first of the six state components holding the tide's impulses (`∫ Σ F_tide dt`, then
    /// `∫ Σ r × F_tide dt`), after the bodies and the dissipation integral; `None` without a tide or with a massless
    /// planet (whose run stays bit-identical to one without `[physics.flyby]`). They let the run tell the momentum
    /// the tide gave from the integration's error: `|L − L0 − ∫τ dt|` is an error, `∫τ dt` is physics.
    pub fn tide_impulse_index(&self) -> Option<usize> {
        self.tide
            .filter(|t| t.gm != 0.0)
            .map(|_| self.n_bodies() * self.stride + usize::from(self.physics.dissipation.is_some()))
    }

    /// Adds `Σ m a_tide` and `Σ r × m a_tide` at time `t` for `positions` to `rates[0..6]` (the impulses' rates).
    fn add_tide_impulse_rates(&self, t: f64, positions: &[Vec3], rates: &mut [f64]) {
        let Some(tide) = &self.tide else { return };
        let planet = tide.planet_position(t);
        let (mut force, mut torque) = (Vec3::zeros(), Vec3::zeros());
        for (r, m) in positions.iter().zip(&self.masses) {
            let f = tide.acceleration(r, &planet) * *m;
            force += f;
            torque += r.cross(&f);
        }
        rates[0..3].copy_from_slice(force.as_slice());
        rates[3..6].copy_from_slice(torque.as_slice());
    }

    /// Body `i`'s position in the packed state `y` (m).
    fn position(&self, y: &[f64], i: usize) -> Vec3 {
        Vec3::new(y[i * self.stride], y[i * self.stride + 1], y[i * self.stride + 2])
    }

    /// Every body's position in `y` (m).
    fn positions(&self, y: &[f64]) -> Vec<Vec3> {
        (0..self.n_bodies()).map(|i| self.position(y, i)).collect()
    }

    fn kinematics(&self, i: usize, y: &[f64], with_geometry: bool) -> Kinematics {
        let s = &y[i * self.stride..(i + 1) * self.stride];
        let r = Vec3::new(s[0], s[1], s[2]);
        if self.rotation {
            let q = Vec4::new(s[3], s[4], s[5], s[6]);
            let u = Vec3::new(s[7], s[8], s[9]);
            let p = Vec4::new(s[10], s[11], s[12], s[13]);
            let q_dot = inverse_mass_apply(&q, &self.inertia_ext[i], &p);
            let m_inv_q = inverse_mass_apply(&q, &self.inertia_ext[i], &q);
            let spin_body = body_spin(&q, &q_dot);
            let geometry = with_geometry.then(|| BodyGeometry::new(&self.shapes[i].axes, &q));
            let rot = geometry.map_or_else(|| rotation_matrix(&q), |g| g.rot);
            Kinematics {
                r,
                q,
                u,
                velocity: u / self.shapes[i].mass,
                p,
                q_dot,
                m_inv_q,
                spin_body,
                spin_world: rot.transpose() * spin_body,
                geometry,
            }
        } else {
            let b = &self.initial[i];
            let q = b.quaternion.normalize();
            let spin_world = rotation_matrix(&q).transpose() * b.spin_body;
            let u = Vec3::new(s[3], s[4], s[5]);
            Kinematics {
                r,
                q,
                u,
                velocity: u / self.shapes[i].mass,
                p: Vec4::zeros(),
                q_dot: Vec4::zeros(),
                m_inv_q: Vec4::zeros(),
                spin_body: b.spin_body,
                spin_world,
                // Spheres: Σ = R² 1 whatever the attitude.
                geometry: with_geometry.then(|| BodyGeometry::new(&self.shapes[i].axes, &Vec4::w())),
            }
        }
    }

    fn all_kinematics(&self, y: &[f64], with_geometry: bool) -> Vec<Kinematics> {
        let mut kin = Vec::new();
        self.kinematics_into(y, with_geometry, &mut kin);
        kin
    }

    /// [`Self::kinematics`] of every body into `out` (its allocation reused).
    fn kinematics_into(&self, y: &[f64], with_geometry: bool, out: &mut Vec<Kinematics>) {
        let n = self.n_bodies();
        if n >= PARALLEL_BODIES {
            (0..n)
                .into_par_iter()
                .map(|i| self.kinematics(i, y, with_geometry))
                .collect_into_vec(out);
        } else {
            out.clear();
            out.extend((0..n).map(|i| self.kinematics(i, y, with_geometry)));
        }
    }

    /// The interacting pairs among `candidates` with their forces, into one reused buffer per block of
    /// [`PAIR_BLOCK`] candidates (each block culled and evaluated by one task, in candidate order).
    /// Each candidate's slot among its block's terms goes to `slots` (every slot is written).
    fn pair_forces_into(
        &self,
        candidates: &[CandidatePair],
        kin: &[Kinematics],
        blocks: &mut Vec<Vec<PairTerms>>,
        slots: &mut Vec<u32>,
    ) {
        blocks.resize_with(candidates.len().div_ceil(PAIR_BLOCK), Vec::new);
        slots.resize(candidates.len(), NO_TERMS);
        let block = |((terms, slots), cands): ((&mut Vec<PairTerms>, &mut [u32]), &[CandidatePair])| {
            terms.clear();
            for (slot, c) in slots.iter_mut().zip(cands) {
                *slot = match self.pair_terms(c, kin, true) {
                    Some(t) => {
                        terms.push(t);
                        (terms.len() - 1) as u32
                    }
                    None => NO_TERMS,
                };
            }
        };
        if candidates.len() >= PARALLEL_CANDIDATES {
            blocks
                .par_iter_mut()
                .zip(slots.par_chunks_mut(PAIR_BLOCK))
                .zip(candidates.par_chunks(PAIR_BLOCK))
                .for_each(block);
        } else {
            blocks
                .iter_mut()
                .zip(slots.chunks_mut(PAIR_BLOCK))
                .zip(candidates.chunks(PAIR_BLOCK))
                .for_each(block);
        }
    }

    fn needs_pairs(&self) -> bool {
        self.physics.contact.is_some() || self.physics.dissipation.is_some()
    }

    /// Candidate pairs of the bounding-sphere search (the cached Verlet list when it covers the state), with their
    /// constants; [`Self::pair_terms`] applies the exact cull.
    fn candidate_pairs(&self, kin: &[Kinematics]) -> Arc<Candidates> {
        let kappa = self.model.kappa;
        let centres: Vec<Vec3> = kin.iter().map(|k| k.r).collect();
        let radii: Vec<f64> = kin
            .iter()
            .map(|k| interaction_radius(kappa, k.geometry.as_ref().expect("geometry"), self.cull_exp))
            .collect();
        let candidate = |(i, j): (usize, usize)| self.candidate_pair(i, j);
        let finite = centres.iter().all(|c| c.iter().all(|x| x.is_finite()));
        if !finite {
            // Not a state to remember (the integrator will reject it): the plain search.
            return Arc::new(Candidates::new(
                candidates_of(sphere_pairs(&centres, &radii), candidate),
                centres.len(),
            ));
        }
        // The lock is held only to copy or replace the cache's handle, never across the parallel check or build:
        // a rayon worker blocked on it could be waiting for a job of its own (another caller's evaluation stolen
        // while this one's build runs), and every worker so blocked is a deadlock. A poisoned lock only means
        // another thread panicked mid-update.
        let cache = || self.pair_cache.lock().unwrap_or_else(|e| e.into_inner());
        let cached = cache().clone();
        match cached {
            Some(c) if c.covers(&centres, &radii) => Arc::clone(&c.candidates),
            _ => {
                let fresh = Arc::new(PairCache::build(&centres, &radii, candidate));
                let candidates = Arc::clone(&fresh.candidates);
                *cache() = Some(fresh);
                candidates
            }
        }
    }

    /// The state-independent constants of pair `(i, j)`.
    fn candidate_pair(&self, i: usize, j: usize) -> CandidatePair {
        CandidatePair {
            i,
            j,
            prefactor: pair_prefactor(
                self.model.contact_g,
                self.model.kappa,
                self.radii[i],
                self.shapes[i].mass,
                self.radii[j],
                self.shapes[j].mass,
            ),
            taper: Taper::for_pair(self.cutoff, self.model.kappa * lambda(self.radii[i], self.radii[j])),
        }
    }

    /// The terms of a candidate pair, or `None` when it provably contributes nothing: culled by the bound of
    /// [`is_negligible`], or (for the forces, `with_forces`) beyond its taper's end, where the potential, its
    /// gradients and the dissipation are all zeros (skipping them leaves every sum's bits unchanged; the
    /// diagnostics keep such pairs so that their sums stay exactly as they were).
    fn pair_terms(&self, c: &CandidatePair, kin: &[Kinematics], with_forces: bool) -> Option<PairTerms> {
        let kappa = self.model.kappa;
        let (i, j) = (c.i, c.j);
        let (ki, kj) = (&kin[i], &kin[j]);
        let (gi, gj) = (ki.geometry.as_ref().unwrap(), kj.geometry.as_ref().unwrap());
        let delta = ki.r - kj.r;
        if is_negligible(kappa, &delta, gi, gj, c.taper.end) {
            return None;
        }
        let ov = if with_forces {
            overlap_within_taper(c.prefactor, kappa, &delta, gi, gj, &c.taper)?
        } else {
            overlap(c.prefactor, kappa, &delta, gi, gj, &c.taper)
        };
        let mut t = PairTerms {
            i,
            j,
            force_i: Vec3::zeros(),
            torque_i: Vec3::zeros(),
            torque_j: Vec3::zeros(),
            potential: 0.0,
            dissipation: 0.0,
        };
        if self.physics.contact.is_some() {
            t.potential = ov.potential;
            if with_forces {
                let grad = contact_spin_gradient(&ov, kappa, gi, gj);
                t.force_i -= grad.d_ri;
                if self.rotation {
                    t.torque_i -= grad.d_wi;
                    t.torque_j -= grad.d_wj;
                }
            }
        }
        if let Some(d) = self.physics.dissipation {
            let vi = BodyVelocity {
                velocity: ki.velocity,
                spin_world: ki.spin_world,
            };
            let vj = BodyVelocity {
                velocity: kj.velocity,
                spin_world: kj.spin_world,
            };
            let pd = pair_dissipation(d.f0, kappa, &ov, gi, gj, &vi, &vj);
            t.dissipation = pd.value;
            if with_forces {
                t.force_i += pd.d_vi;
                t.torque_i += pd.d_wi;
                t.torque_j += pd.d_wj;
            }
        }
        Some(t)
    }

    /// The terms of the interacting pairs, in candidate (sorted) order whatever the number of threads.
    fn all_pair_terms(&self, kin: &[Kinematics], with_forces: bool) -> Vec<PairTerms> {
        if !self.needs_pairs() {
            return Vec::new();
        }
        let candidates = self.candidate_pairs(kin);
        let terms = |c: &CandidatePair| self.pair_terms(c, kin, with_forces);
        // The exact cull runs in the same parallel pass as the pair terms (one fork-join, not two); rayon's
        // collect keeps the candidates' order.
        if candidates.pairs.len() >= PARALLEL_CANDIDATES {
            candidates
                .pairs
                .par_iter()
                .with_min_len(CANDIDATES_PER_TASK)
                .filter_map(terms)
                .collect()
        } else {
            candidates.pairs.iter().filter_map(terms).collect()
        }
    }

    /// How the candidate pairs of state `y` split between the cull, the taper and contact (see [`PairCensus`]);
    /// all zeros when no pair term is on.
    pub fn pair_census(&self, y: &[f64]) -> PairCensus {
        if !self.needs_pairs() {
            return PairCensus::default();
        }
        let kin = self.all_kinematics(y, true);
        let candidates = self.candidate_pairs(&kin);
        let mut census = PairCensus {
            candidates: candidates.pairs.len(),
            ..PairCensus::default()
        };
        let kappa = self.model.kappa;
        for c in &candidates.pairs {
            let (gi, gj) = (kin[c.i].geometry.as_ref().unwrap(), kin[c.j].geometry.as_ref().unwrap());
            let delta = kin[c.i].r - kin[c.j].r;
            if is_negligible(kappa, &delta, gi, gj, c.taper.end) {
                continue;
            }
            census.exponent_evaluated += 1;
            if let Some(ov) = overlap_within_taper(c.prefactor, kappa, &delta, gi, gj, &c.taper) {
                census.interacting += 1;
                if ov.exponent <= c.taper.start + self.cutoff.ln() {
                    census.touching += 1;
                }
            }
        }
        census
    }

    /// The bodies' state at time `t` from the packed state `y` (`spin_body` from `q̇`; for non-integrated
    /// attitudes, the free uniform rotation of a sphere about its constant world spin).
    pub fn bodies_at(&self, t: f64, y: &[f64]) -> Vec<Body> {
        (0..self.n_bodies())
            .map(|i| {
                let k = self.kinematics(i, y, false);
                let mass = self.shapes[i].mass;
                let (quaternion, spin_body) = if self.rotation {
                    (k.q, k.spin_body)
                } else {
                    let rotated =
                        nalgebra::UnitQuaternion::from_scaled_axis(k.spin_world * t) * to_unit_quaternion(&k.q);
                    let q = from_unit_quaternion(&rotated);
                    (q, rotation_matrix(&q) * k.spin_world)
                };
                Body {
                    shape: self.shapes[i],
                    position: k.r,
                    velocity: k.u / mass,
                    quaternion,
                    spin_body,
                }
            })
            .collect()
    }

    /// Diagnostics of the packed state `y`.
    pub fn diagnostics(&self, y: &[f64]) -> Diagnostics {
        let kin = self.all_kinematics(y, self.needs_pairs());
        let mut d = Diagnostics::default();
        for (i, k) in kin.iter().enumerate() {
            let m = self.shapes[i].mass;
            let l_spin = rotation_matrix(&k.q).transpose() * self.moments[i].component_mul(&k.spin_body);
            let l_orb = k.r.cross(&k.u);
            d.kinetic_translational += 0.5 * k.u.norm_squared() / m;
            d.kinetic_rotational += 0.5 * k.spin_body.dot(&self.moments[i].component_mul(&k.spin_body));
            d.momentum += k.u;
            d.angular_momentum += l_orb + l_spin;
            d.momentum_scale += k.u.norm();
            d.angular_momentum_scale += l_orb.norm() + l_spin.norm();
            if self.rotation {
                d.quaternion_norm_error = d.quaternion_norm_error.max((k.q.norm() - 1.0).abs());
            }
        }
        if self.rotation {
            // K_R = ½ pᵀ M⁻¹ p exactly (includes the tiny q·q̇ part the spin form leaves out).
            d.kinetic_rotational = kin.iter().map(|k| 0.5 * k.p.dot(&k.q_dot)).sum();
        }
        if self.physics.contact.is_some() {
            d.potential_contact = self.all_pair_terms(&kin, false).iter().map(|t| t.potential).sum();
        }
        if let Some(gr) = self.physics.gravity {
            let pos: Vec<Vec3> = kin.iter().map(|k| k.r).collect();
            let masses: Vec<f64> = self.shapes.iter().map(|s| s.mass).collect();
            let mut f = vec![Vec3::zeros(); pos.len()];
            // Always the exact U_G, also when the forces come from the tree: the tree's potential is summed in
            // single precision from 1000 bodies on (~1e-6 relative noise), which would swamp the energy error;
            // the exact sum costs little at the diagnostics' few calls, and H − H0 then measures the tree's
            // real departure from energy conservation.
            d.potential_gravity = gravity_forces(gr.g, &pos, &masses, &mut f);
        }
        if let Some(idx) = self.dissipation_index() {
            d.dissipated = 2.0 * y[idx];
        }
        if let Some(idx) = self.tide_impulse_index() {
            d.tidal_impulse = Vec3::new(y[idx], y[idx + 1], y[idx + 2]);
            d.tidal_torque_impulse = Vec3::new(y[idx + 3], y[idx + 4], y[idx + 5]);
        }
        d.energy_scale =
            d.kinetic_translational + d.kinetic_rotational + d.potential_contact.abs() + d.potential_gravity.abs();
        d
    }

    /// [`EllipsoidSystem::diagnostics`] at time `t` (s): with a flyby, the tidal energy `E_tide` is filled in (and
    /// counted in the energy and its scale), so that `H + E_tide` is the conserved energy.
    pub fn diagnostics_at(&self, t: f64, y: &[f64]) -> Diagnostics {
        let mut d = self.diagnostics(y);
        if let Some(tide) = &self.tide {
            d.potential_tidal = tide.energy(t, &self.positions(y), &self.masses, &d.momentum);
            d.energy_scale += d.potential_tidal.abs();
        }
        d
    }
}

/// `∂F/∂q̇ = 2 W₃(q)ᵀ R ∂F/∂ω_w` (the chain rule through `ω_w = Rᵀ 2 W₃ q̇`).
fn spin_force_to_quaternion(q: &Vec4, g: &BodyGeometry, d_spin_world: &Vec3) -> Vec4 {
    let b = g.rot * d_spin_world;
    2.0 * w_matrix(q).transpose() * Vec4::new(b.x, b.y, b.z, 0.0)
}

/// The right side `c = qᵀ M⁻¹ Ṁ M⁻¹ p − pᵀ M⁻² p` of the differentiated constraint (corrected Roig03 Eq. 35),
/// with `M⁻¹ p = q̇` and `Ṁ = 4 (W(q̇)ᵀ Ĩ W(q) + W(q)ᵀ Ĩ W(q̇))`.
/// `m_inv_q` is `M⁻¹ q`.
pub fn constraint_rhs(q: &Vec4, q_dot: &Vec4, m_inv_q: &Vec4, inertia_ext: &Vec4) -> f64 {
    let (w, w_dot) = (w_matrix(q), w_matrix(q_dot));
    let m_dot_q_dot = 4.0
        * (w_dot.transpose() * inertia_ext.component_mul(&(w * q_dot))
            + w.transpose() * inertia_ext.component_mul(&(w_dot * q_dot)));
    m_inv_q.dot(&m_dot_q_dot) - q_dot.norm_squared()
}

/// `ṗ` of Roig03 Eq. 36 (three rows of the projector `|q|² 1 − q qᵀ` applied to `ṗ = g`, `g = ∂L/∂q + ∂F/∂q̇`
/// in J, plus the constraint row `qᵀ M⁻¹ ṗ = c`) in closed form: `ṗ = g − λ q`, `λ = (qᵀM⁻¹g − c)/(qᵀM⁻¹q)` (the
/// projector rows hold because they remove `q`, the constraint row by the choice of λ); `tests/ellipsoid_gradients.rs`
/// checks it against the LU solution of the paper's 4×4 system. `m_inv_q` is `M⁻¹ q`.
pub fn constrained_momentum_rate_closed_form(q: &Vec4, g: &Vec4, m_inv_q: &Vec4, c: f64) -> Vec4 {
    let mq = m_inv_q;
    let lambda = (mq.dot(g) - c) / mq.dot(q);
    g - lambda * q
}

impl OdeSystem for EllipsoidSystem {
    fn dim(&self) -> usize {
        self.n_bodies() * self.stride
            + usize::from(self.physics.dissipation.is_some())
            + if self.tide_impulse_index().is_some() { 6 } else { 0 }
    }

    /// User units of the state blocks (see [`OdeSystem::state_units`]): `r` 1 (m), `q` 1 (an attitude error of
    /// `δq` is about `2 δq` rad), `u` the body's mass `m` (kg, so the norm sees m/s), `p` twice the mean principal
    /// moment `2 (I₁ + I₂ + I₃)/3` (kg m², since `p = 2 W(q)ᵀ (I ω, 0)` has `|p| ≈ 2 I |ω|`: the norm sees rad/s),
    /// and `∫F dt` the initial energy scale `K + |U_C| + |U_G|` (J, so the dissipated energy is judged relative
    /// to the system's energy; 1 J if that is zero); the tide's impulses the total mass `M` (kg: the norm sees
    /// m/s) and `M R²` (kg m², `R` the largest body distance from the origin plus its major semi-axis: rad/s).
    fn state_units(&self) -> Option<Vec<f64>> {
        let mut units = vec![1.0; self.dim()];
        let bodies = self.n_bodies() * self.stride;
        for (i, chunk) in units[..bodies].chunks_exact_mut(self.stride).enumerate() {
            let m = self.shapes[i].mass;
            if self.rotation {
                let moments = self.moments[i];
                chunk[7..10].fill(m);
                chunk[10..14].fill(2.0 * (moments.x + moments.y + moments.z) / 3.0);
            } else {
                chunk[3..6].fill(m);
            }
        }
        if let Some(idx) = self.dissipation_index() {
            let scale = self.diagnostics(&self.initial_state()).energy_scale;
            units[idx] = if scale.is_finite() && scale > 0.0 { scale } else { 1.0 };
        }
        if let Some(idx) = self.tide_impulse_index() {
            let mass: f64 = self.masses.iter().sum();
            let reach = self
                .initial
                .iter()
                .map(|b| b.position.norm() + b.shape.axes.x)
                .fold(0.0, f64::max);
            units[idx..idx + 3].fill(mass);
            units[idx + 3..idx + 6].fill(mass * reach * reach);
        }
        Some(units)
    }

    /// With tree gravity: builds the tree at `y` and fixes its interaction lists for the step (see
    /// [`FrozenOctree`]); the step's evaluations sum those lists, so its forces are smooth in the state and
    /// the lists change only from one step to the next. The lists are a function of `y` alone, so a resumed
    /// run repeats them.
    fn begin_step(&self, _t: f64, y: &[f64]) {
        let n = self.n_bodies();
        let Some(theta) = self.physics.gravity.and_then(|gr| gr.method.tree_theta(n)) else {
            return;
        };
        let frozen = Octree::build(&self.positions(y), &self.masses).freeze(theta);
        *self.gravity_lists.lock().unwrap_or_else(|e| e.into_inner()) = Some(Arc::new(frozen));
    }

    /// The dissipation's Jacobian in the momenta ([`EllipsoidSystem::dissipation_jacobian`]).
    fn stiff_part(&self, _t: f64, y: &[f64]) -> Option<Box<dyn StiffSolve + '_>> {
        self.dissipation_jacobian(y).map(|j| Box::new(j) as Box<dyn StiffSolve>)
    }

    /// Drops the lists of [`OdeSystem::begin_step`]: later evaluations walk fresh trees until the next step.
    fn end_steps(&self) {
        *self.gravity_lists.lock().unwrap_or_else(|e| e.into_inner()) = None;
    }

    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        let tide = self.tide.map(|tide| (tide, tide.planet_position(t)));
        let n = self.n_bodies();
        let tree_theta = self.physics.gravity.and_then(|gr| gr.method.tree_theta(n));
        if !self.rotation && !self.needs_pairs() && n < BLOCKED_FROM && tree_theta.is_none() {
            // Spheres under gravity alone (e.g. planetary N-body problems): ṙ = u/m, u̇ = F_G, straight from
            // the packed state, nothing allocated.
            // the bodies' components only: the tide's impulses follow them when a planet is there
            for (i, out) in dydt[..n * self.stride].chunks_exact_mut(self.stride).enumerate() {
                let m = self.shapes[i].mass;
                for k in 0..3 {
                    out[k] = y[i * self.stride + 3 + k] / m;
                    out[3 + k] = 0.0;
                }
            }
            if let Some(gr) = self.physics.gravity {
                add_gravity_forces_packed(gr.g, y, self.stride, &self.masses, dydt, 3);
            }
            if let Some((tide, planet)) = &tide {
                for (i, out) in dydt[..n * self.stride].chunks_exact_mut(self.stride).enumerate() {
                    let f = tide.acceleration(&self.position(y, i), planet) * self.masses[i];
                    for (o, fk) in out[3..6].iter_mut().zip(f.iter()) {
                        *o += fk;
                    }
                }
            }
            if let Some(idx) = self.tide_impulse_index() {
                self.add_tide_impulse_rates(t, &self.positions(y), &mut dydt[idx..idx + 6]);
            }
            return;
        }
        // Two parallel branches, then one pass: the kinematics followed by the pair terms (summed per body in
        // candidate order), beside the gravity blocks (which need only the positions); then per body, the gravity
        // blocks added in block order and the body's rates. The sums are those of a serial evaluation, whatever
        // the number of threads.
        let mut own = None;
        let mut guard = self.scratch.try_lock().ok();
        let scratch: &mut RhsScratch = match guard.as_deref_mut() {
            Some(s) => s,
            None => own.insert(RhsScratch::default()),
        };
        let RhsScratch {
            kin,
            positions,
            blocks,
            slots,
            gravity,
            force,
            torque,
        } = scratch;
        // Read straight from the state, so that the gravity pass need not wait for the kinematics: the other
        // worker sums gravity while this one computes the kinematics.
        PHASE_GATHER.time(|| {
            positions.clear();
            positions.extend((0..n).map(|i| self.position(y, i)));
        });
        let mut dissipation_rate = 0.0;
        let mut pairs = || {
            PHASE_KINEMATICS.time(|| self.kinematics_into(y, self.needs_pairs(), kin));
            let kin = &*kin;
            force.clear();
            force.resize(n, Vec3::zeros());
            torque.clear();
            torque.resize(n, Vec3::zeros());
            if !self.needs_pairs() {
                return;
            }
            let candidates = PHASE_CANDIDATES.time(|| self.candidate_pairs(kin));
            PHASE_PAIR_FORCES.time(|| self.pair_forces_into(&candidates.pairs, kin, blocks, slots));
            dissipation_rate = if n >= PARALLEL_BODIES && rayon::current_num_threads() > 1 {
                PHASE_PAIR_SUM_PARALLEL.time(|| sum_pair_terms(&candidates, blocks, slots, force, torque))
            } else {
                PHASE_PAIR_SUM.time(|| {
                    let mut dissipation_rate = 0.0;
                    for t in blocks.iter().flatten() {
                        force[t.i] += t.force_i;
                        force[t.j] -= t.force_i;
                        torque[t.i] += t.torque_i;
                        torque[t.j] += t.torque_j;
                        dissipation_rate += t.dissipation;
                    }
                    dissipation_rate
                })
            };
        };
        // From BLOCKED_FROM bodies on the gravity blocks, added per body below; small systems add the half loop.
        // The tree's forces (when the method asks for it at this N) are one block.
        let blocked_gravity = self
            .physics
            .gravity
            .filter(|_| n >= BLOCKED_FROM || tree_theta.is_some());
        let mut gravity_pass = || {
            PHASE_GRAVITY.time(|| match (blocked_gravity, tree_theta) {
                (Some(gr), Some(theta)) => {
                    gravity.resize_with(1, Vec::new);
                    // The handle is copied out: no lock is held across the parallel sums (see `candidate_pairs`).
                    let lists = self.gravity_lists.lock().unwrap_or_else(|e| e.into_inner()).clone();
                    match lists.as_deref().filter(|t| t.len() == n) {
                        Some(frozen) => {
                            frozen_tree_gravity_forces(gr.g, frozen, positions, &self.masses, &mut gravity[0])
                        }
                        None => tree_gravity_forces(gr.g, theta, positions, &self.masses, &mut gravity[0]),
                    };
                }
                (Some(gr), None) => gravity_blocks(gr.g, positions, &self.masses, gravity),
                (None, _) => gravity.clear(),
            })
        };
        if n >= PARALLEL_BODIES {
            rayon::join(pairs, gravity_pass);
        } else {
            pairs();
            gravity_pass();
        }
        if let (Some(gr), None) = (self.physics.gravity, blocked_gravity) {
            PHASE_SMALL_GRAVITY.time(|| add_gravity_forces(gr.g, positions, &self.masses, force));
        }
        let (kin, force, torque, gravity) = (&*kin, &*force, &*torque, &*gravity);
        let stride = self.stride;
        let rotation = self.rotation;
        let body_rate = |(i, out): (usize, &mut [f64])| {
            let mut force = force[i];
            for block in gravity {
                force += block[i];
            }
            let k = &kin[i];
            if let Some((tide, planet)) = &tide {
                force += tide.acceleration(&k.r, planet) * self.masses[i];
            }
            out[0..3].copy_from_slice(k.velocity.as_slice());
            if rotation {
                let ie = &self.inertia_ext[i];

                let mut g = rotational_kinetic_gradient(&k.q, &k.q_dot, ie);
                // (no geometry: no pairs, no torque)
                if let Some(geometry) = &k.geometry {
                    g += spin_force_to_quaternion(&k.q, geometry, &torque[i]);
                }
                let c = constraint_rhs(&k.q, &k.q_dot, &k.m_inv_q, ie);
                let p_dot = constrained_momentum_rate_closed_form(&k.q, &g, &k.m_inv_q, c);
                out[3..7].copy_from_slice(k.q_dot.as_slice());
                out[7..10].copy_from_slice(force.as_slice());
                out[10..14].copy_from_slice(p_dot.as_slice());
            } else {
                out[3..6].copy_from_slice(force.as_slice());
            }
        };
        let (bodies, rest) = dydt.split_at_mut(n * stride);
        PHASE_RATES.time(|| {
            if n >= PARALLEL_BODIES {
                bodies.par_chunks_mut(stride).enumerate().for_each(body_rate);
            } else {
                bodies.chunks_mut(stride).enumerate().for_each(body_rate);
            }
        });
        if self.physics.dissipation.is_some()
            && let Some(slot) = rest.first_mut()
        {
            *slot = dissipation_rate;
        }
        if let Some(idx) = self.tide_impulse_index() {
            let at = idx - n * stride;
            self.add_tide_impulse_rates(t, positions, &mut rest[at..at + 6]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::{Generator, generator, uniform};

    /// `(I − h J) x` for a dense `J`.
    fn apply_dense(jacobian: &nalgebra::DMatrix<f64>, h: f64, x: &[f64]) -> Vec<f64> {
        let xv = nalgebra::DVector::from_column_slice(x);
        (&xv - jacobian * &xv * h).as_slice().to_vec()
    }

    /// Uniform in `[lo, hi)`.
    fn range(rng: &mut Generator, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * uniform(rng)
    }

    /// A random unit quaternion (by rejection from the cube).
    fn unit_quaternion(rng: &mut Generator) -> Vec4 {
        loop {
            let q = Vec4::from_fn(|_, _| range(rng, -1.0, 1.0));
            let n = q.norm();
            if n > 0.2 && n < 1.0 {
                return q / n;
            }
        }
    }

    /// Four ellipsoids of 400–1000 m (density 3000 kg/m³), random attitudes, spins and velocities, their centres
    /// 800–1100 m apart so that every neighbouring pair overlaps.
    fn overlapping_four(seed: u64) -> Vec<Body> {
        let mut rng = generator(seed);
        let centres = [
            [0.0, 0.0, 0.0],
            [1000.0, 100.0, 0.0],
            [400.0, 900.0, 100.0],
            [500.0, 400.0, 850.0],
        ];
        centres
            .iter()
            .map(|&c| {
                let a = range(&mut rng, 700.0, 1000.0);
                let velocity = Vec3::from_fn(|_, _| range(&mut rng, -0.1, 0.1));
                let spin_body = Vec3::from_fn(|_, _| range(&mut rng, -1e-4, 1e-4));
                let axes = Vec3::new(a, a * range(&mut rng, 0.6, 0.9), a * range(&mut rng, 0.4, 0.6));
                let quaternion = unit_quaternion(&mut rng);
                let mass = 3000.0 * 4.0 / 3.0 * std::f64::consts::PI * axes.x * axes.y * axes.z;
                Body {
                    shape: Ellipsoid { axes, mass },
                    position: Vec3::from(c),
                    velocity,
                    quaternion,
                    spin_body,
                }
            })
            .collect()
    }

    /// The analytic `J = −C D B` against central differences of the right-hand side's dissipation part (the RHS at F0
    /// minus the RHS at F0 = 0) in every momentum component; and the solve of `(I − h J) x = b` against the dense `J`.
    #[test]
    fn dissipation_jacobian_matches_finite_differences() {
        let bodies = overlapping_four(7);
        let model = ModelConfig::gaussian_si(6.0);
        let f0 = 100.0;
        let sys = EllipsoidSystem::new(&bodies, model, Physics::impact(f0));
        let free = EllipsoidSystem::new(&bodies, model, Physics::impact(0.0));
        let y = sys.initial_state();
        let n = sys.dim();
        let jac = sys.dissipation_jacobian(&y).expect("dissipation is on");
        assert!(jac.pairs() >= 4, "only {} dissipating pairs", jac.pairs());
        let dense = jac.dense(n);
        let units = sys.state_units().unwrap();
        let diss = |y: &[f64]| {
            let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
            sys.rhs(0.0, y, &mut a);
            free.rhs(0.0, y, &mut b);
            a.iter().zip(&b).map(|(x, z)| x - z).collect::<Vec<f64>>()
        };
        let (mut worst, mut scale) = (0.0_f64, 0.0_f64);
        for body in 0..bodies.len() {
            for c in 7..14 {
                let k = body * 14 + c;
                // The dissipation is linear in the momenta: central differences are exact up to rounding, so the step
                // can be large (1e-3 of the component's user unit: 1 mm/s or 1 mrad/s).
                let d = 1e-3 * units[k];
                let (mut yp, mut ym) = (y.clone(), y.clone());
                yp[k] += d;
                ym[k] -= d;
                let (fp, fm) = (diss(&yp), diss(&ym));
                for row in 0..bodies.len() * 14 {
                    // Columns scaled by the user unit, rows by theirs: entries in s⁻¹.
                    let fd = (fp[row] - fm[row]) / (2.0 * d) * units[k] / units[row];
                    let an = dense[(row, k)] * units[k] / units[row];
                    worst = worst.max((fd - an).abs());
                    scale = scale.max(an.abs());
                }
            }
        }
        eprintln!("largest |J| entry {scale:e} 1/s, largest |J - J_fd| {worst:e}");
        assert!(
            scale > 1e-3,
            "the dissipation is not stiff enough to test ({scale:e} 1/s)"
        );
        assert!(
            worst <= 1e-8 * scale,
            "J differs from finite differences by {:e} relative",
            worst / scale
        );

        // The solve: (I − h J') x = b with the dense J' = [[0, T], [0, J]] (J and the kinematic rows), and total
        // momentum unchanged.
        let solved = jac.dense_with_kinematics(n);
        let mut solver = sys.dissipation_jacobian(&y).unwrap();
        let mut rng = generator(3);
        let b: Vec<f64> = (0..n).map(|k| units[k] * range(&mut rng, -1.0, 1.0)).collect();
        for h in [1e-3, 1.0, 1e3] {
            let mut x = b.clone();
            solver.solve(h, &mut x);
            // Against dense LU of the same matrix: both are limited by its condition, about 1 + h |J| (the pile's
            // stiffness), so they agree to ε (1 + h |J|) of |x|.
            let a = nalgebra::DMatrix::<f64>::identity(n, n) - &solved * h;
            let x_lu = a.lu().solve(&nalgebra::DVector::from_column_slice(&b)).unwrap();
            let diff = x_lu
                .iter()
                .zip(&x)
                .zip(&units)
                .map(|((p, q), u)| ((p - q) / u).abs())
                .fold(0.0, f64::max);
            let size = x.iter().zip(&units).map(|(p, u)| (p / u).abs()).fold(0.0, f64::max);
            let bound = 1e-14 * (1.0 + h * scale) * size;
            eprintln!("h = {h:e}: |x_cg - x_lu| {diff:e}, bound {bound:e} (user units)");
            assert!(diff <= bound, "CG and LU differ by {diff:e} > {bound:e} at h = {h}");
            // The residual of (I − h J) x = b itself, where h J is small.
            if h * scale < 1e3 {
                let back = apply_dense(&solved, h, &x);
                let resid = back
                    .iter()
                    .zip(&b)
                    .zip(&units)
                    .map(|((p, q), u)| ((p - q) / u).abs())
                    .fold(0.0, f64::max);
                assert!(
                    resid <= 1e-13 * (1.0 + h * scale) * size,
                    "residual {resid:e} at h = {h}"
                );
            }
            let sum = |v: &[f64], c: usize| (0..bodies.len()).map(|i| v[i * 14 + 7 + c]).sum::<f64>();
            let p_scale: f64 = (0..bodies.len()).map(|i| units[i * 14 + 7]).sum();
            for c in 0..3 {
                assert!(
                    (sum(&x, c) - sum(&b, c)).abs() <= 1e-14 * p_scale,
                    "momentum changed by the solve"
                );
            }
        }
    }
}
