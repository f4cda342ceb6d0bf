//! Canonical problems of the interacting-ellipsoids model for the tests and the benchmarks (`bench work-precision`,
//! `bench nbody`), in the style of russell_ode's `Samples`: one function each, with its end time, error measure and
//! reference. [`WorkPrecisionProblem`]: `Top` (torque-free ellipsoid, analytic ω, [`torque_free_spin`]), `Pair`
//! and `PairDissipative` (two ellipsoids, G = 1, F0 = 0.1), `N30` (`targets/N30_T4.csv` + projectile P1), `StiffPair`
//! (F0 = 1e4), `Pile` (N30 squeezed to 0.9, F0 = 1e-6…1e-2), referenced to another method at 1e-14 or a tight
//! explicit (else implicit) BS; [`NBodyProblem`]: `Pythagorean`, `OuterSolar` (REBOUND, `analysis/rebound_compare`).
//!
//! Errors (dimensionless): [`ProblemSetup::state_error`], per block kind (`r`, `q`, `u`, `p`) the largest body
//! error over the largest reference block norm, maxed over kinds (`∫F dt` left out); [`ProblemSetup::spin_error`],
//! `|ω − ω_exact|₂ / |ω_exact|₂` (body frame); [`ProblemSetup::energy_residual`],
//! `|H(t) − H(0) − 2∫F dt| / E_scale(0)`, `E_scale = K + |U_C| + |U_G|` ([`Diagnostics`]).

use crate::ellipsoid::body::{Body, Ellipsoid, InertiaModel};
use crate::ellipsoid::equations::{
    ContactTerm, Diagnostics, DissipationTerm, EllipsoidSystem, G_SI, GravityTerm, ModelConfig, Physics,
};
use crate::ellipsoid::output::{BodyRecord, read_bodies};
use crate::impact::geometry::ImpactGeometry;
use crate::impact::projectile::{ProjectileSpec, set_up_aimed_impact};
use crate::impact::target::{centre_of_mass, to_centre_of_mass_frame};
use crate::integrate::OdeSystem;
use crate::integrate::problems::torque_free_spin;
use crate::math::{Vec3, Vec4};

/// The N30_T4 target of Roig03 §3 (`targets/N30_T4.csv`), embedded so the problem does not depend on the
/// working directory.
pub const N30_T4_CSV: &str = include_str!("../../targets/N30_T4.csv");
/// The N200_T4 target (the Roig03 campaign's), embedded so the problem needs no files.
pub const N200_T4_CSV: &str = include_str!("../../targets/N200_T4.csv");

/// The problems of `rubblepile bench work-precision --problem`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WorkPrecisionProblem {
    /// A free asymmetric top: one ellipsoid, no forces, with the analytic body-frame spin as reference.
    Top,
    /// Two ellipsoids in mutual gravity (G = 1) with the contact potential, bouncing, no dissipation.
    Pair,
    /// The same pair with Rayleigh dissipation (F0 = 0.1 s m⁻²).
    PairDissipative,
    /// The N30_T4 target hit by projectile P1 (5 km/s, 45°), SI units, gravity + contact + dissipation.
    N30,
    /// The N200_T4 target hit by projectile P2 (5 km/s, 45°) as in the Roig03 campaign (F0 = 1e-6 s m⁻²), to
    /// 400 s: the impact and the first 310 s of ejection.
    N200,
    /// A stiff damped pair: two overlapping ellipsoids (G = 1) whose contact damping (F0 = 1e4) is about 1000×
    /// faster than their contact oscillation, settling into one another ([`stiff_pair`]).
    StiffPair,
    /// An overdamped pile: the N30_T4 target squeezed to 0.9 of its size about its centre of mass, relaxing
    /// under contact, gravity and dissipation (F0 = 1e-2 s m⁻² unless `--f0`; [`squeezed_pile`]).
    Pile,
}

impl crate::named::Named for WorkPrecisionProblem {
    /// All problems, in `--problem` order.
    const ALL: &'static [WorkPrecisionProblem] = &[
        WorkPrecisionProblem::Top,
        WorkPrecisionProblem::Pair,
        WorkPrecisionProblem::PairDissipative,
        WorkPrecisionProblem::N30,
        WorkPrecisionProblem::N200,
        WorkPrecisionProblem::StiffPair,
        WorkPrecisionProblem::Pile,
    ];

    /// The `--problem` value, e.g. `"pair-dissipative"`.
    fn name(self) -> &'static str {
        match self {
            WorkPrecisionProblem::Top => "top",
            WorkPrecisionProblem::Pair => "pair",
            WorkPrecisionProblem::PairDissipative => "pair-dissipative",
            WorkPrecisionProblem::N30 => "n30",
            WorkPrecisionProblem::N200 => "n200",
            WorkPrecisionProblem::StiffPair => "stiff-pair",
            WorkPrecisionProblem::Pile => "pile",
        }
    }

    fn help(self) -> &'static str {
        match self {
            WorkPrecisionProblem::Top => "a free asymmetric top with its analytic spin",
            WorkPrecisionProblem::Pair => "two ellipsoids in gravity and contact, bouncing (G = 1)",
            WorkPrecisionProblem::PairDissipative => "the pair with Rayleigh dissipation (F0 = 0.1)",
            WorkPrecisionProblem::N30 => "N30_T4 hit by P1 (5 km/s, 45°), SI",
            WorkPrecisionProblem::N200 => "N200_T4 hit by P2 as in the Roig03 campaign, to 400 s",
            WorkPrecisionProblem::StiffPair => "a stiff damped pair (damping ~1000× faster than contact)",
            WorkPrecisionProblem::Pile => "an overdamped pile: N30_T4 squeezed to 0.9, relaxing",
        }
    }
}

impl WorkPrecisionProblem {
    /// Whether the problem has dissipation whose F0 `--f0` may set.
    pub fn takes_f0(self) -> bool {
        matches!(self, WorkPrecisionProblem::StiffPair | WorkPrecisionProblem::Pile)
    }

    /// Builds the problem with its F0 replaced by `f0` (s m⁻² in the problem's units; only where
    /// [`Self::takes_f0`], otherwise `None` is expected and the problem is built as it is).
    pub fn setup_with_f0(self, f0: Option<f64>) -> ProblemSetup {
        match self {
            WorkPrecisionProblem::StiffPair => stiff_pair(f0.unwrap_or(STIFF_PAIR_F0)),
            WorkPrecisionProblem::Pile => squeezed_pile(f0.unwrap_or(PILE_F0)),
            WorkPrecisionProblem::Top => free_top(),
            WorkPrecisionProblem::Pair => bouncing_pair(None),
            WorkPrecisionProblem::PairDissipative => bouncing_pair(Some(PAIR_F0)),
            WorkPrecisionProblem::N30 => n30_impact(),
            WorkPrecisionProblem::N200 => n200_impact(),
        }
    }

    /// Builds the problem.
    pub fn setup(self) -> ProblemSetup {
        self.setup_with_f0(None)
    }
}

/// The problems of `rubblepile bench nbody --problem` (point masses: spheres of radius 1e-6, gravity only,
/// G = 1, no contact term, no dissipation, so only `r` and `u` are integrated).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NBodyProblem {
    /// Burrau's Pythagorean three-body problem: masses 3, 4, 5 at rest at (1, 3), (−2, −1), (1, −1), to t = 10.
    Pythagorean,
    /// Sun (mass 1) and four giants on circular coplanar orbits (a = 5.2, 9.5, 19.2, 30.1; masses 9.5e-4,
    /// 2.9e-4, 4.4e-5, 5.2e-5), to t = 1000 (about 13 orbits of the innermost).
    OuterSolar,
}

impl crate::named::Named for NBodyProblem {
    const ALL: &'static [NBodyProblem] = &[NBodyProblem::Pythagorean, NBodyProblem::OuterSolar];

    /// The `--problem` value.
    fn name(self) -> &'static str {
        match self {
            NBodyProblem::Pythagorean => "pythagorean",
            NBodyProblem::OuterSolar => "outer-solar",
        }
    }

    fn help(self) -> &'static str {
        match self {
            NBodyProblem::Pythagorean => "Burrau's Pythagorean three-body problem, to t = 10",
            NBodyProblem::OuterSolar => "the Sun and the four giant planets, to t = 1000",
        }
    }
}

impl NBodyProblem {
    /// Builds the problem (one energy check, at the end: the integrator runs straight to `t_end`).
    pub fn setup(self) -> ProblemSetup {
        match self {
            NBodyProblem::Pythagorean => pythagorean(),
            NBodyProblem::OuterSolar => outer_solar(),
        }
    }
}

/// How a problem's reference solution is obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReferenceKind {
    /// Closed form (the top's body-frame spin).
    Analytic,
    /// A tight run of a different method.
    Numerical,
    /// A stiff problem: one reference for every method, a tight explicit Bulirsch–Stoer run where it finishes
    /// within its time limit, else a tight linearly implicit run (the work–precision bench's `References`).
    Stiff,
}

/// A built problem: the system, its initial bodies, the time span and what the benchmarks need.
pub struct ProblemSetup {
    /// Short name (the `--problem` value).
    pub name: &'static str,
    /// One-line description (bodies, physics, units, end time).
    pub description: String,
    /// The initial bodies.
    pub bodies: Vec<Body>,
    /// The equations of motion.
    pub system: EllipsoidSystem,
    /// End time (s in the problem's time unit).
    pub t_end: f64,
    /// Number of equally spaced times in `(0, t_end]` where the energy residual is checked (the integrator
    /// lands on each).
    pub energy_samples: usize,
    /// Default fixed steps for Rk4 (time unit of the problem), largest first.
    pub rk4_steps: Vec<f64>,
    /// Analytic or numerical reference.
    pub reference: ReferenceKind,
}

impl ProblemSetup {
    /// The packed initial state.
    pub fn initial_state(&self) -> Vec<f64> {
        self.system.initial_state()
    }

    /// Components per body in the packed state (14 with attitudes, 6 without).
    pub fn stride(&self) -> usize {
        if self.system.rotation_integrated() { 14 } else { 6 }
    }

    /// The block norm of `y − y_ref` (see the [module docs](self)).
    pub fn state_error(&self, y: &[f64], y_ref: &[f64]) -> f64 {
        let stride = self.stride();
        let blocks: &[(usize, usize)] = if stride == 14 {
            &[(0, 3), (3, 7), (7, 10), (10, 14)]
        } else {
            &[(0, 3), (3, 6)]
        };
        let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let mut worst: f64 = 0.0;
        for &(lo, hi) in blocks {
            let (mut err, mut scale): (f64, f64) = (0.0, 0.0);
            for b in 0..self.system.n_bodies() {
                let (a, z) = (b * stride + lo, b * stride + hi);
                let diff: Vec<f64> = y[a..z].iter().zip(&y_ref[a..z]).map(|(p, q)| p - q).collect();
                err = err.max(norm(&diff));
                scale = scale.max(norm(&y_ref[a..z]));
            }
            let e = if scale > 0.0 { err / scale } else { err };
            worst = worst.max(if e.is_nan() { f64::INFINITY } else { e });
        }
        worst
    }

    /// The exact body-frame spin of body 0 at time `t` (rad/s) when the problem is the free top.
    pub fn exact_spin(&self, t: f64) -> Option<Vec3> {
        if self.reference != ReferenceKind::Analytic {
            return None;
        }
        let moments = self.system.principal_moments()[0];
        let w0 = self.bodies[0].spin_body;
        torque_free_spin([moments.x, moments.y, moments.z], [w0.x, w0.y, w0.z], t).map(Vec3::from)
    }

    /// `|ω − ω_exact|₂ / |ω_exact|₂` of body 0's body-frame spin in the state `y` at time `t` (the top's error).
    pub fn spin_error(&self, t: f64, y: &[f64]) -> Option<f64> {
        let exact = self.exact_spin(t)?;
        let w = self.system.bodies_at(t, y)[0].spin_body;
        Some((w - exact).norm() / exact.norm())
    }

    /// `|H − H0 − 2∫F dt| / E_scale(0)` of the state `y`, given the diagnostics `d0` of the initial state.
    pub fn energy_residual(&self, d0: &Diagnostics, y: &[f64]) -> f64 {
        let d = self.system.diagnostics(y);
        let r = (d.energy() - d0.energy() - d.dissipated).abs() / d0.energy_scale;
        if r.is_nan() { f64::INFINITY } else { r }
    }
}

fn body(axes: [f64; 3], mass: f64, position: [f64; 3], velocity: [f64; 3], quaternion: Vec4, spin: [f64; 3]) -> Body {
    Body {
        shape: Ellipsoid {
            axes: Vec3::from(axes),
            mass,
        },
        position: Vec3::from(position),
        velocity: Vec3::from(velocity),
        quaternion: quaternion.normalize(),
        spin_body: Vec3::from(spin),
    }
}

/// The free top: an ellipsoid with semi-axes (3, 2, 1) m and mass 1000 kg (uniform-density moments
/// `I = m/5 (B²+C², C²+A², A²+B²) = (1000, 2000, 2600) kg m²`), tilted attitude, spin (0.4, 0.1, 0.8) rad/s
/// about its principal axes (rotation about the axis of largest moment, `M² > 2EI₂`, elliptic parameter
/// m = 0.1665); no forces. To t = 100 s, 8.46 periods of the body-frame spin (11.81 s).
pub fn free_top() -> ProblemSetup {
    let bodies = vec![body(
        [3.0, 2.0, 1.0],
        1000.0,
        [0.0; 3],
        [0.0; 3],
        Vec4::new(0.2, -0.3, 0.1, 0.9),
        [0.4, 0.1, 0.8],
    )];
    let model = ModelConfig {
        kappa: 10.0,
        inertia: InertiaModel::Uniform,
        contact_g: G_SI,
    };
    let system = EllipsoidSystem::new(&bodies, model, Physics::default());
    ProblemSetup {
        name: "top",
        description: "free asymmetric top: one ellipsoid (3, 2, 1) m, 1000 kg, uniform moments, spin (0.4, 0.1, \
                      0.8) rad/s, no forces, full quaternion equations (14 components), t = 0..100 s"
            .into(),
        bodies,
        system,
        t_end: 100.0,
        energy_samples: 20,
        rk4_steps: vec![0.5, 0.2, 0.1, 0.05, 0.02, 0.01],
        reference: ReferenceKind::Analytic,
    }
}

/// F0 of the dissipative pair (s m⁻² in the problem's units).
pub const PAIR_F0: f64 = 0.1;

/// Two ellipsoids in G = 1 units: A (1, 0.8, 0.6), mass 1, and B (0.8, 0.6, 0.5), mass 0.6, κ = 10, Gaussian
/// moments; released 5 apart with relative velocity (−0.1, 0.2, 0.02), which is a bound orbit (period
/// ≈ 22) whose pericentre (≈ 0.33) lies inside contact, so they collide (t ≈ 8–10), bounce off the contact
/// potential, exchange spin and separate again; small initial spins. Centre-of-mass frame; t = 0..15 (up to
/// just before the second collision: over longer spans the tumbling pair is so chaotic that two 1e-13 runs of
/// different methods part at 1e-9 by t = 20 and at O(1) by t = 60). With `f0`, dissipation is on (`F0 = f0`).
pub fn bouncing_pair(f0: Option<f64>) -> ProblemSetup {
    let (bodies, system) = two_ellipsoids([5.0, 0.0, 0.3], [-0.1, 0.2, 0.02], f0);
    let dissipative = f0.is_some();
    ProblemSetup {
        name: if dissipative { "pair-dissipative" } else { "pair" },
        description: format!(
            "bouncing pair: ellipsoids (1, 0.8, 0.6) m=1 and (0.8, 0.6, 0.5) m=0.6, G = 1, kappa = 10, gravity + \
             contact{}, bound orbit with pericentre inside contact (one bounce), t = 0..15",
            f0.map(|f| format!(" + dissipation F0 = {f}")).unwrap_or_default()
        ),
        bodies,
        system,
        t_end: 15.0,
        energy_samples: 15,
        rk4_steps: vec![0.05, 0.02, 0.01, 0.005, 0.002, 0.001],
        reference: ReferenceKind::Numerical,
    }
}

/// The two ellipsoids of [`bouncing_pair`] and [`stiff_pair`]: (1, 0.8, 0.6) of mass 1 at rest at the origin and
/// (0.8, 0.6, 0.5) of mass 0.6 at `position` with `velocity`, small fixed spins and attitudes, moved to their
/// centre-of-mass frame; G = 1, κ = 10, Gaussian moments, gravity + contact, and dissipation at `f0` if given.
fn two_ellipsoids(position: [f64; 3], velocity: [f64; 3], f0: Option<f64>) -> (Vec<Body>, EllipsoidSystem) {
    let mut bodies = vec![
        body(
            [1.0, 0.8, 0.6],
            1.0,
            [0.0; 3],
            [0.0; 3],
            Vec4::new(0.1, 0.2, -0.3, 0.9),
            [0.05, -0.1, 0.2],
        ),
        body(
            [0.8, 0.6, 0.5],
            0.6,
            position,
            velocity,
            Vec4::new(-0.4, 0.1, 0.2, 0.8),
            [0.0, 0.15, -0.1],
        ),
    ];
    to_centre_of_mass_frame(&mut bodies);
    let model = ModelConfig {
        kappa: 10.0,
        inertia: InertiaModel::Gaussian,
        contact_g: 1.0,
    };
    let physics = Physics {
        gravity: Some(GravityTerm::new(1.0)),
        contact: Some(ContactTerm::default()),
        dissipation: f0.map(|f0| DissipationTerm { f0 }),
    };
    let system = EllipsoidSystem::new(&bodies, model, physics);
    (bodies, system)
}

/// End time of the N30 impact (s).
pub const N30_T_END: f64 = 60.0;

/// F0 of [`n30_impact`] (s m⁻²).
pub const N30_F0: f64 = 1e-4;

/// The N30_T4 target ([`N30_T4_CSV`]) hit by projectile P1 (equivalent radius 14.14 km, 5 km/s) at ζ = 45°
/// placed to touch at t = 5 s; SI units, κ calibrated as `rubblepile impact` does (Roig03 Eq. 14, β = 10 at
/// the impact speed), gravity (SI G) + contact + dissipation (F0 = 1e-4 s m⁻²); t = 0..60 s: the projectile
/// ploughs through the target and the struck fragments fly apart. 31 bodies, 435 state components.
pub fn n30_impact() -> ProblemSetup {
    let setup = ImpactProblem {
        name: "n30",
        target_csv: N30_T4_CSV,
        target_path: "targets/N30_T4.csv",
        projectile: "P1",
        // 5 s instead of the campaign's 90 s: the 60 s window is the impact itself.
        contact_time: Some(5.0),
        // fixed, not the impact default, so that the problem and analysis/work_precision/ stay what they were
        f0: Some(N30_F0),
        t_end: N30_T_END,
        energy_samples: 12,
        rk4_steps: vec![0.2, 0.1, 0.05, 0.02, 0.01, 0.005],
    };
    setup.build()
}

/// F0 of [`stiff_pair`] by default (s m⁻² in G = 1 units).
pub const STIFF_PAIR_F0: f64 = 100.0;

/// The stiff damped pair: the [`bouncing_pair`]'s two ellipsoids (G = 1, κ = 10, Gaussian moments) placed with
/// their centres 1.2 apart (overlapping: their equivalent radii add up to 1.47), approaching at 0.1 and spinning,
/// with gravity, contact and dissipation at `f0`; centre-of-mass frame; t = 0..10. With the formulas of
/// `targets/README.md` ("Choosing κ and F0") the contact oscillates with a period of about 2 (time units) and a
/// relative velocity decays in `τ_v = μ/(2 F0 U_C(d)) ≈ 20/F0`: at the default F0 = 1e4 the damping is about
/// 1000× faster than the oscillation, an overdamped contact that an explicit method must follow at its damping
/// rate (steps ~ τ_v) while the solution itself creeps on the slow time scale.
pub fn stiff_pair(f0: f64) -> ProblemSetup {
    let (bodies, system) = two_ellipsoids([1.2, 0.1, 0.05], [-0.1, 0.03, 0.0], Some(f0));
    ProblemSetup {
        name: "stiff-pair",
        description: format!(
            "stiff damped pair: ellipsoids (1, 0.8, 0.6) m=1 and (0.8, 0.6, 0.5) m=0.6 overlapping (centres 1.2 \
             apart), G = 1, kappa = 10, gravity + contact + dissipation F0 = {f0:e}, t = 0..10"
        ),
        bodies,
        system,
        t_end: 10.0,
        energy_samples: 10,
        rk4_steps: Vec::new(),
        reference: ReferenceKind::Stiff,
    }
}

/// F0 of [`squeezed_pile`] by default (s m⁻²).
pub const PILE_F0: f64 = 1e-2;
/// The factor by which [`squeezed_pile`] shrinks the N30_T4 target's positions about its centre of mass.
pub const PILE_SQUEEZE: f64 = 0.9;
/// End time of [`squeezed_pile`] (s).
pub const PILE_T_END: f64 = 100.0;

/// The overdamped pile: the N30_T4 target ([`N30_T4_CSV`], 30 ellipsoids of 25–90 km) with its positions squeezed
/// to [`PILE_SQUEEZE`] about its centre of mass (velocities and spins as in the file), so its contacts overlap
/// more deeply than at rest and push it apart against the damping; κ as in [`n30_impact`] (calibrated for P1, the
/// N30 problems' κ), SI gravity + contact + dissipation at `f0`; t = 0..[`PILE_T_END`]. The damping rates grow
/// like F0 `U_C`: at F0 = 1e-6 s m⁻² (the impact default) the pile is not stiff, at 1e-4 the damping is the
/// fastest time scale of the deepest contacts, at 1e-2 of every contact (overdamped: the pile creeps apart).
/// 30 bodies, 420 state components (431 with the dissipation integral).
pub fn squeezed_pile(f0: f64) -> ProblemSetup {
    let mut bodies = embedded_bodies(N30_T4_CSV);
    let projectile = ProjectileSpec::preset("P1").expect("a preset projectile");
    let cfg = crate::impact::run::ImpactConfig::new("targets/N30_T4.csv".into(), projectile);
    let kappa = cfg.kappa(&bodies).expect("the target and projectile calibrate");
    let (centre, _) = centre_of_mass(&bodies);
    for b in &mut bodies {
        b.position = centre + (b.position - centre) * PILE_SQUEEZE;
    }
    let system = EllipsoidSystem::new(&bodies, ModelConfig::gaussian_si(kappa), Physics::impact(f0));
    ProblemSetup {
        name: "pile",
        description: format!(
            "overdamped pile: targets/N30_T4.csv squeezed to {PILE_SQUEEZE} of its size, SI, kappa = {kappa:.4}, \
             gravity + contact + dissipation F0 = {f0:e} s/m^2, {} bodies, t = 0..{PILE_T_END} s",
            bodies.len()
        ),
        bodies,
        system,
        t_end: PILE_T_END,
        energy_samples: 10,
        rk4_steps: Vec::new(),
        reference: ReferenceKind::Stiff,
    }
}

/// End time of the N200 impact (s).
pub const N200_T_END: f64 = 400.0;

/// The N200_T4 target ([`N200_T4_CSV`]) hit by projectile P2 at ζ = 45°, placed to touch at t = 90 s, as the
/// Roig03 campaign runs it (κ calibrated with β = 10, F0 = 1e-6 s m⁻², SI gravity + contact + dissipation), to
/// t = 400 s, where the campaign measures its outcomes. 201 bodies, 2815 state components.
pub fn n200_impact() -> ProblemSetup {
    let setup = ImpactProblem {
        name: "n200",
        target_csv: N200_T4_CSV,
        target_path: "targets/N200_T4.csv",
        projectile: "P2",
        contact_time: None,
        f0: None,
        t_end: N200_T_END,
        energy_samples: 8,
        rk4_steps: vec![0.05, 0.02],
    };
    setup.build()
}

/// The bodies of an embedded target file ([`N30_T4_CSV`], [`N200_T4_CSV`]).
fn embedded_bodies(csv: &str) -> Vec<Body> {
    let records = read_bodies(csv.as_bytes()).expect("the embedded target parses");
    records.iter().map(BodyRecord::to_body).collect()
}

/// An impact of a committed target as `rubblepile impact` sets it up (ζ = 45°, κ calibrated with β = 10, SI
/// gravity + contact + dissipation), with the campaign defaults unless overridden.
struct ImpactProblem {
    name: &'static str,
    target_csv: &'static str,
    target_path: &'static str,
    projectile: &'static str,
    /// Time of first contact (s); `None` = the impact default.
    contact_time: Option<f64>,
    /// F0 (s m⁻²); `None` = the impact default.
    f0: Option<f64>,
    t_end: f64,
    energy_samples: usize,
    rk4_steps: Vec<f64>,
}

impl ImpactProblem {
    fn build(self) -> ProblemSetup {
        let target = embedded_bodies(self.target_csv);
        let projectile = ProjectileSpec::preset(self.projectile).expect("a preset projectile");
        let mut cfg = crate::impact::run::ImpactConfig::new(self.target_path.into(), projectile.clone());
        cfg.contact_time = self.contact_time.unwrap_or(cfg.contact_time);
        cfg.f0 = self.f0.unwrap_or(cfg.f0);
        let kappa = cfg.kappa(&target).expect("the target and projectile calibrate");
        let geometry = ImpactGeometry::default();
        let (bodies, ..) = set_up_aimed_impact(
            &target,
            &projectile,
            &geometry,
            cfg.angle_deg,
            cfg.contact_time,
            cfg.seed,
        );
        let system = EllipsoidSystem::new(&bodies, ModelConfig::gaussian_si(kappa), Physics::impact(cfg.f0));
        ProblemSetup {
            name: self.name,
            description: format!(
                "{} target + projectile {} ({} km/s, {} deg, contact at t = {} s), SI, kappa = {kappa:.4}, gravity + \
                 contact + dissipation F0 = {:e} s/m^2, {} bodies, t = 0..{} s",
                self.target_path,
                self.projectile,
                projectile.speed / 1e3,
                cfg.angle_deg,
                cfg.contact_time,
                cfg.f0,
                bodies.len(),
                self.t_end
            ),
            bodies,
            system,
            t_end: self.t_end,
            energy_samples: self.energy_samples,
            rk4_steps: self.rk4_steps,
            reference: ReferenceKind::Numerical,
        }
    }
}

/// Radius of the point masses of the N-body problems (spheres; the contact term is off anyway).
pub const POINT_MASS_RADIUS: f64 = 1e-6;

fn point_masses(name: &'static str, description: String, bodies: Vec<Body>, t_end: f64) -> ProblemSetup {
    let model = ModelConfig {
        kappa: 10.0,
        inertia: InertiaModel::Uniform,
        contact_g: 1.0,
    };
    let physics = Physics {
        gravity: Some(GravityTerm::new(1.0)),
        contact: None,
        dissipation: None,
    };
    let system = EllipsoidSystem::new(&bodies, model, physics);
    ProblemSetup {
        name,
        description,
        bodies,
        system,
        t_end,
        energy_samples: 1,
        rk4_steps: Vec::new(),
        reference: ReferenceKind::Numerical,
    }
}

fn point_mass(mass: f64, position: [f64; 3], velocity: [f64; 3]) -> Body {
    let r = POINT_MASS_RADIUS;
    body([r, r, r], mass, position, velocity, Vec4::w(), [0.0; 3])
}

/// Burrau's Pythagorean three-body problem (G = 1): masses 3, 4, 5 at rest at (1, 3), (−2, −1), (1, −1)
/// (already the centre-of-mass frame), to t = 10.
pub fn pythagorean() -> ProblemSetup {
    let bodies = vec![
        point_mass(3.0, [1.0, 3.0, 0.0], [0.0; 3]),
        point_mass(4.0, [-2.0, -1.0, 0.0], [0.0; 3]),
        point_mass(5.0, [1.0, -1.0, 0.0], [0.0; 3]),
    ];
    point_masses(
        "pythagorean",
        "Pythagorean three-body problem: masses 3, 4, 5 at rest at (1,3), (-2,-1), (1,-1), G = 1, t = 0..10".into(),
        bodies,
        10.0,
    )
}

/// Semi-major axes of the outer-Solar-System problem (length unit), Jupiter to Neptune.
pub const OUTER_SOLAR_A: [f64; 4] = [5.2, 9.5, 19.2, 30.1];
/// Masses of the giants (Sun = 1), Jupiter to Neptune.
pub const OUTER_SOLAR_MASSES: [f64; 4] = [9.5e-4, 2.9e-4, 4.4e-5, 5.2e-5];

/// Sun (mass 1) and the four giants (G = 1) on circular coplanar orbits: planet `k` starts at
/// `a_k (cos θ_k, sin θ_k, 0)`, `θ_k = k · 90°`, with the circular two-body speed `√(1 + m_k)/√a_k`
/// perpendicular to its radius (heliocentric); the whole system is then moved to its centre-of-mass frame.
/// To t = 1000 (13.4 orbits of the innermost planet, 0.96 of the outermost).
pub fn outer_solar() -> ProblemSetup {
    let mut bodies = vec![point_mass(1.0, [0.0; 3], [0.0; 3])];
    for (k, (&a, &m)) in OUTER_SOLAR_A.iter().zip(&OUTER_SOLAR_MASSES).enumerate() {
        let theta = k as f64 * std::f64::consts::FRAC_PI_2;
        let (s, c) = theta.sin_cos();
        let v = ((1.0 + m) / a).sqrt();
        bodies.push(point_mass(m, [a * c, a * s, 0.0], [-v * s, v * c, 0.0]));
    }
    to_centre_of_mass_frame(&mut bodies);
    point_masses(
        "outer-solar",
        "outer Solar System: Sun + Jupiter, Saturn, Uranus, Neptune on circular coplanar orbits, G = 1, t = \
         0..1000"
            .into(),
        bodies,
        1000.0,
    )
}

/// Plain point-mass gravity `r' = u/m`, `u' = Σ G m_i m_j (r_j − r_i)/|r_j − r_i|³` with the same state
/// layout as an all-sphere [`EllipsoidSystem`] without dissipation (`r`, `u` per body): the bare N-body
/// right-hand side, used to tell the integrator's cost from the general model's in `bench nbody`.
#[derive(Debug, Clone, PartialEq)]
pub struct PointMassGravity {
    /// Gravitational constant.
    pub g: f64,
    /// Masses.
    pub masses: Vec<f64>,
}

impl PointMassGravity {
    /// The point-mass system of `bodies` (their masses) with constant `g`.
    pub fn new(g: f64, bodies: &[Body]) -> Self {
        PointMassGravity {
            g,
            masses: bodies.iter().map(|b| b.shape.mass).collect(),
        }
    }
}

impl OdeSystem for PointMassGravity {
    fn dim(&self) -> usize {
        6 * self.masses.len()
    }

    fn rhs(&self, _t: f64, y: &[f64], dydt: &mut [f64]) {
        let n = self.masses.len();
        for i in 0..n {
            let m = self.masses[i];
            for k in 0..3 {
                dydt[6 * i + k] = y[6 * i + 3 + k] / m;
                dydt[6 * i + 3 + k] = 0.0;
            }
        }
        for i in 0..n {
            for j in (i + 1)..n {
                let d = [
                    y[6 * j] - y[6 * i],
                    y[6 * j + 1] - y[6 * i + 1],
                    y[6 * j + 2] - y[6 * i + 2],
                ];
                let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                let f = self.g * self.masses[i] * self.masses[j] / (r2 * r2.sqrt());
                for k in 0..3 {
                    dydt[6 * i + 3 + k] += f * d[k];
                    dydt[6 * j + 3 + k] -= f * d[k];
                }
            }
        }
    }
}
