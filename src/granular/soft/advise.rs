//! Choosing `k_N` and the step (Zhang17 §2.3.3: no overlap above 1 % of the smallest radius; the recipe of Schwartz
//! et al. 2012, §2.6). Dynamic: a sphere hitting a wall at `v` overlaps `v √(m/k_N)`, so `k_N ≥ m v² / x_max²`,
//! `x_max = f r_min`, `m` the largest mass, `v` the given speed or the larger of `R √(8πGρ/3)` and `2πR/T`. Static:
//! `k_N ≥ 4 r² p_c / x_max` with the uniform sphere's central pressure `p_c = 2π/3 G ρ² R²`. Step: `dt = T_c/50`,
//! `T_c = π √(μ_min/k_N)`, `μ_min = m_min/2`; leapfrog's limit `2 √(μ_min/k_N)` is reported (and enforced by the scene
//! check). Gravity interval (r-RESPA, `soft::respa`): `k = max(1, min(⌊t_dyn/(100 dt)⌋, ⌊T_c/(5 dt)⌋))`,
//! `t_dyn = 1/√(Gρ)` (≥ 100 blocks per dynamical time, blocks well below half a contact oscillation, where the
//! impulse method resonates); 10 at the advised step for asteroid densities.

use crate::io::scene_file::SI_G;
use serde::Serialize;

/// Default largest overlap, as a fraction of the smallest radius.
pub const DEFAULT_MAX_OVERLAP: f64 = 0.01;
/// Steps per contact duration in the advised step.
pub const STEPS_PER_CONTACT: f64 = 50.0;

/// What the advice is computed from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdviceInput {
    /// Smallest particle radius (m).
    pub r_min: f64,
    /// Smallest particle mass (kg).
    pub m_min: f64,
    /// Largest particle mass (kg).
    pub m_max: f64,
    /// Largest expected impact speed (m/s), before the body terms.
    pub speed: f64,
    /// The body, if self-gravitating: radius (m) and bulk density (kg/m³).
    pub body: Option<(f64, f64)>,
    /// The body's spin period (s), if spinning.
    pub spin_period: Option<f64>,
    /// Largest overlap as a fraction of `r_min`.
    pub max_overlap: f64,
    /// Gravitational constant (m³ kg⁻¹ s⁻²).
    pub g: f64,
}

/// The advice.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Advice {
    /// Speed used (m/s).
    pub speed: f64,
    /// Static contact force used (N).
    pub static_force: f64,
    /// Suggested normal spring constant (N/m).
    pub k_n: f64,
    /// Contact duration of the lightest pair, `π √(μ_min/k_N)` (s).
    pub contact_time: f64,
    /// Suggested step (s).
    pub dt: f64,
    /// Leapfrog stability limit for the stiffest contact (s).
    pub stability_limit: f64,
    /// The body's dynamical time `1/√(Gρ)` (s), if self-gravitating.
    pub dynamical_time: Option<f64>,
    /// Suggested `[gravity] interval_steps` at the suggested step ([`gravity_interval`]; 1 without a body).
    pub gravity_interval: u64,
}

/// Suggested steps between self-gravity evaluations (see the module docs):
/// `max(1, min(⌊t_dyn/(100 dt)⌋, ⌊T_c/(5 dt)⌋))`, with the dynamical time `t_dyn` (s), the step `dt` (s) and
/// the contact time `T_c` (s).
///
/// ```
/// use rubblepile::granular::soft::advise::gravity_interval;
/// assert_eq!(gravity_interval(1e4, 1e-3, 50e-3), 10);
/// assert_eq!(gravity_interval(0.5, 1e-3, 50e-3), 5);
/// assert_eq!(gravity_interval(1e4, 1e-3, 1e-3), 1);
/// ```
pub fn gravity_interval(dynamical_time: f64, dt: f64, contact_time: f64) -> u64 {
    let k = (dynamical_time / (100.0 * dt)).min(contact_time / (5.0 * dt)).floor();
    if k.is_finite() && k >= 1.0 { k as u64 } else { 1 }
}

/// Stability limit `2 √(μ_min/k_N)` (s) of leapfrog on the stiffest contact (μ_min = m_min/2).
pub fn stability_limit(k_n: f64, m_min: f64) -> f64 {
    2.0 * (0.5 * m_min / k_n).sqrt()
}

/// The advised `k_N` and step.
///
/// ```
/// use rubblepile::granular::soft::advise::{advise, AdviceInput};
/// let a = advise(&AdviceInput { r_min: 1.0, m_min: 1.0, m_max: 1.0, speed: 1.0, body: None,
///     spin_period: None, max_overlap: 0.01, g: 6.674e-11 });
/// assert!((a.k_n - 1e4).abs() < 1e-9 && a.dt < a.stability_limit);
/// ```
pub fn advise(input: &AdviceInput) -> Advice {
    let x_max = input.max_overlap * input.r_min;
    let mut speed = input.speed;
    let mut static_force = 0.0;
    let mut dynamical_time = None;
    if let Some((radius, density)) = input.body {
        dynamical_time = Some(1.0 / (input.g * density).sqrt());
        speed = speed.max(radius * (8.0 * std::f64::consts::PI * input.g * density / 3.0).sqrt());
        let p_c = 2.0 * std::f64::consts::PI / 3.0 * input.g * density * density * radius * radius;
        static_force = 4.0 * input.r_min * input.r_min * p_c;
        if let Some(t) = input.spin_period {
            speed = speed.max(std::f64::consts::TAU * radius / t);
        }
    }
    let k_n = (input.m_max * speed * speed / (x_max * x_max)).max(static_force / x_max);
    let mu = 0.5 * input.m_min;
    let contact_time = std::f64::consts::PI * (mu / k_n).sqrt();
    let dt = contact_time / STEPS_PER_CONTACT;
    Advice {
        speed,
        static_force,
        k_n,
        contact_time,
        dt,
        stability_limit: stability_limit(k_n, input.m_min),
        dynamical_time,
        gravity_interval: dynamical_time.map_or(1, |t| gravity_interval(t, dt, contact_time)),
    }
}

/// Advice for spheres of radius `r` (m) and grain density `rho` (kg/m³) in a body of radius `body_radius`
/// (m, bulk density `bulk_density`, spin period `spin_period` s) or hit at `speed` (m/s).
pub fn advise_for_grains(
    r: f64,
    rho: f64,
    body: Option<(f64, f64)>,
    spin_period: Option<f64>,
    speed: f64,
    max_overlap: f64,
) -> Advice {
    let m = 4.0 / 3.0 * std::f64::consts::PI * r.powi(3) * rho;
    advise(&AdviceInput {
        r_min: r,
        m_min: m,
        m_max: m,
        speed,
        body,
        spin_period,
        max_overlap,
        g: SI_G,
    })
}
