//! Settling a rescaled or re-spun pile before a flyby: the pile evolves under its own gravity, contact
//! and dissipation (no tide) until it moves as one rigid body, so that what a flyby measures afterwards is the
//! tide's doing and not the pile's own settling.
//!
//! The criterion is the one of `target build` (Roig03 §3 as implemented in [`crate::impact::target`]): the kinetic
//! energy of the motion relative to the best-fit rigid rotation ([`crate::ellipsoid::rigid_rotation`]) below
//! [`SETTLE_NON_RIGID_FRACTION`] of the kinetic energy, at two successive checks a quarter of a free-fall time apart,
//! after at least [`SETTLE_MIN_FREE_FALLS`] free-fall times. The settling stops at a cap (default
//! [`SETTLE_MAX_FREE_FALLS`] free-fall times), and says so ([`SettleReport::capped`]).

use serde::{Deserialize, Serialize};

use crate::ellipsoid::body::Body;
use crate::ellipsoid::equations::{EllipsoidSystem, G_SI, ModelConfig, Physics};
use crate::ellipsoid::rigid_rotation::fit_rigid_rotation;
use crate::ellipsoid::spin_state::principal_axes;
use crate::impact::target::{centre_of_mass, set_rigid_rotation, to_centre_of_mass_frame};
use crate::integrate::{IntegrateError, Method, Tolerances, make_integrator};
use crate::math::Vec3;

/// Settled when `K_rel/K` (kinetic energy relative to the best-fit rigid rotation over the kinetic energy) is below
/// this at two successive checks: the rigidity of `target build`.
pub const SETTLE_NON_RIGID_FRACTION: f64 = 1e-4;
/// The settling lasts at least this many free-fall times `√(3π/(32 G ρ))` (ρ: mass over the apparent sphere).
pub const SETTLE_MIN_FREE_FALLS: f64 = 3.0;
/// Default cap on the settling time, in free-fall times (64 h for `targets/N30_T4.csv` scaled to 170 m).
pub const SETTLE_MAX_FREE_FALLS: f64 = 100.0;
/// Checks per free-fall time.
const CHECKS_PER_FREE_FALL: f64 = 4.0;

/// Free-fall time `√(3π/(32 G ρ))` (s) of `mass` (kg) spread uniformly over a sphere of `radius` (m).
pub fn free_fall_time(mass: f64, radius: f64) -> f64 {
    let density = mass / (4.0 / 3.0 * std::f64::consts::PI * radius.powi(3));
    (3.0 * std::f64::consts::PI / (32.0 * G_SI * density)).sqrt()
}

/// How a settling went (`flyby.json`, SI units).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SettleReport {
    /// Simulated settling time (s).
    pub time: f64,
    /// Free-fall time of the pile (s).
    pub free_fall_time: f64,
    /// The cap on the settling time (s).
    pub max_time: f64,
    /// Whether the cap was reached before the criterion was met.
    pub capped: bool,
    /// `K_rel/K` at the end.
    pub non_rigid_fraction: f64,
    /// `K_rel/K` at the start.
    pub non_rigid_fraction_start: f64,
    /// Rigid spin period `2π/|ω|` at the start and at the end (h).
    pub period_hours: [f64; 2],
    /// Largest `|H − H0 − 2∫F dt|` over the checks, over `K + |U_C| + |U_G|` at the start.
    pub energy_error: f64,
    /// Whether the settled pile was then put into principal-axis rotation about its largest moment.
    pub set_to_principal: bool,
}

/// Evolves `bodies` under `model` and `physics` (no tide) until settled or until `max_time` (s), with Bulirsch–Stoer at
/// `rtol` (relative and absolute, scale-free); returns the settled bodies in their centre-of-mass frame.
pub fn settle(
    bodies: &[Body],
    model: ModelConfig,
    physics: Physics,
    rtol: f64,
    max_time: f64,
) -> Result<(Vec<Body>, SettleReport), IntegrateError> {
    let mass: f64 = bodies.iter().map(|b| b.shape.mass).sum();
    let t_ff = free_fall_time(mass, apparent_radius(bodies));
    let system = EllipsoidSystem::new(bodies, model, physics);
    let moments = system.principal_moments().to_vec();
    let mut y = system.initial_state();
    let mut integrator = make_integrator(Method::BulirschStoer, Tolerances::scale_free(rtol, rtol, &system), None)?;
    let d0 = system.diagnostics(&y);
    let start = fit_rigid_rotation(bodies, &moments);
    let (mut t, mut quiet_checks, mut energy_error) = (0.0, 0, 0.0_f64);
    let check_every = t_ff / CHECKS_PER_FREE_FALL;
    loop {
        let target = (t + check_every).min(max_time);
        // Bounded like a run (crate::io::run_budget): at most the step ceiling in all.
        let stats = integrator.stats();
        let taken = stats.steps_accepted + stats.steps_rejected;
        let left = crate::io::run_budget::DEFAULT_MAX_STEPS.saturating_sub(taken);
        integrator.set_max_steps(left.min(crate::integrate::bulirsch_stoer::DEFAULT_MAX_STEPS));
        integrator
            .advance(&system, &mut t, &mut y, target)
            .map_err(|e| match e {
                IntegrateError::TooManySteps { t, .. }
                    if left <= crate::integrate::bulirsch_stoer::DEFAULT_MAX_STEPS =>
                {
                    IntegrateError::TooManySteps {
                        t,
                        max_steps: crate::io::run_budget::DEFAULT_MAX_STEPS,
                    }
                }
                e => e,
            })?;
        let d = system.diagnostics(&y);
        energy_error = energy_error.max((d.energy() - d0.energy() - d.dissipated).abs() / d0.energy_scale);
        let now = system.bodies_at(t, &y);
        let fit = fit_rigid_rotation(&now, &moments);
        if t >= SETTLE_MIN_FREE_FALLS * t_ff && fit.non_rigid_fraction() < SETTLE_NON_RIGID_FRACTION {
            quiet_checks += 1;
        } else {
            quiet_checks = 0;
        }
        let done = quiet_checks >= 2;
        if done || t >= max_time {
            let mut now = now;
            to_centre_of_mass_frame(&mut now);
            // The integrated |q| drifts by the run's tolerance; a scene takes unit quaternions (1e-6).
            for b in &mut now {
                b.quaternion = b.quaternion.normalize();
            }
            let report = SettleReport {
                time: t,
                free_fall_time: t_ff,
                max_time,
                capped: !done,
                non_rigid_fraction: fit.non_rigid_fraction(),
                non_rigid_fraction_start: start.non_rigid_fraction(),
                period_hours: [start.period() / 3600.0, fit.period() / 3600.0],
                energy_error,
                set_to_principal: false,
            };
            return Ok((now, report));
        }
    }
}

/// Puts `bodies` (principal moments `moments`, kg m²) into rigid rotation about the axis of their largest total
/// moment `I_max`, with the same `|L|`: `ω = (|L|/I_max) ê`, `ê` the axis turned to `ê·L > 0`. Returns `ω` (rad/s).
pub fn set_principal_axis_rotation(bodies: &mut [Body], moments: &[Vec3]) -> Vec3 {
    let fit = fit_rigid_rotation(bodies, moments);
    let (principal, axes) = principal_axes(&fit.inertia);
    let axis = axes.column(2).into_owned();
    let l = fit.angular_momentum;
    let sign = if axis.dot(&l) < 0.0 { -1.0 } else { 1.0 };
    let omega = axis * (sign * l.norm() / principal[2]);
    set_rigid_rotation(bodies, &omega);
    omega
}

/// Apparent radius (m): max over bodies of `|r − r_cm| + A`, the size the free-fall time of the settling is taken
/// at (and the flyby's reach of the pile).
pub fn apparent_radius(bodies: &[Body]) -> f64 {
    let (cm, _) = centre_of_mass(bodies);
    bodies
        .iter()
        .map(|b| (b.position - cm).norm() + b.shape.axes.x)
        .fold(0.0, f64::max)
}
