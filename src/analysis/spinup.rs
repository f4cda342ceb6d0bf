//! Post-processing of spin-up runs (Zhang17 §3): the first two critical spin limits detected in time series (the creep
//! criterion behind the third is in `analysis::creep`, which reads the packing threshold here), stresses (Eqs. 15–16),
//! principal stresses and the Mohr–Coulomb measures (Eqs. 20–21), and the fit of Eq. 22 over bulk densities.
//!
//! Conventions: stresses are in Pa with compression negative (as the paper); periods in hours at the edges
//! (function names say so), SI inside.

pub use crate::granular::soft::stress::{StressState, particle_stress, rve_stress, stress_state};

/// Zhang17 §3: T_c,1 is the first departure of b/a or c/a from its initial value by more than this.
pub const AXIS_RATIO_THRESHOLD: f64 = 0.01;
/// Zhang17 §3: T_c,2 is the first departure of η_B from its initial value by more than this.
pub const PACKING_THRESHOLD: f64 = 0.001;

/// The first sample `k` where `|values[k] − values[0]| > threshold`, if any.
pub fn first_departure(values: &[f64], threshold: f64) -> Option<usize> {
    let v0 = *values.first()?;
    values.iter().position(|v| (v - v0).abs() > threshold)
}

/// How a spun-up aggregate fails (Zhang17 §3.3): the packing changes before the shape (T_c,2 reached at a longer
/// period than T_c,1: surface shedding, as the paper's HCP and PPC), or the shape before or with the packing
/// (internal failure, as RCP, PP1, PP2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FailureMode {
    /// The shape changes first (T_c,2 < T_c,1): material leaves the surface while the interior packing holds.
    SurfaceShedding,
    /// The interior deforms: the packing loosens no earlier than the shape changes.
    InternalFailure,
}

/// T_c,1 and T_c,2 of one spin-up run and the failure mode.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct CriticalLimits {
    /// Spin period (h) at the first departure of b/a or c/a by more than [`AXIS_RATIO_THRESHOLD`].
    pub t_c1_hours: Option<f64>,
    /// Spin period (h) at the first departure of η_B by more than [`PACKING_THRESHOLD`].
    pub t_c2_hours: Option<f64>,
    /// Surface shedding when T_c,2 < T_c,1 (the shape changes first: material leaves the surface while the
    /// interior packing holds), internal failure otherwise (Zhang17: "surface shedding when T_c,2 < T_c,1").
    pub failure_mode: Option<FailureMode>,
}

/// Detects T_c,1 and T_c,2 in the time series of one run: the spin period (h), b/a, c/a and η_B at each sample.
pub fn critical_limits(period_hours: &[f64], b_over_a: &[f64], c_over_a: &[f64], packing: &[f64]) -> CriticalLimits {
    let shape = [
        first_departure(b_over_a, AXIS_RATIO_THRESHOLD),
        first_departure(c_over_a, AXIS_RATIO_THRESHOLD),
    ]
    .into_iter()
    .flatten()
    .min();
    let t_c1_hours = shape.and_then(|k| period_hours.get(k).copied());
    let t_c2_hours = first_departure(packing, PACKING_THRESHOLD).and_then(|k| period_hours.get(k).copied());
    let failure_mode = match (t_c1_hours, t_c2_hours) {
        (Some(t1), Some(t2)) if t2 < t1 => Some(FailureMode::SurfaceShedding),
        (Some(_), Some(_)) => Some(FailureMode::InternalFailure),
        (Some(_), None) => Some(FailureMode::SurfaceShedding),
        (None, Some(_)) => Some(FailureMode::InternalFailure),
        (None, None) => None,
    };
    CriticalLimits {
        t_c1_hours,
        t_c2_hours,
        failure_mode,
    }
}

/// The body's dynamical time `1/√(G ρ_B)` (s) for bulk density `rho_b` (kg/m³) and gravitational constant `g`.
/// The Zhang17 report averages over it in [`smoothed_critical_limits`], its check that a limit is not set by one
/// sample (the slowest collective motion of a self-gravitating pile has about this period).
pub fn dynamical_time(g: f64, rho_b: f64) -> f64 {
    1.0 / (g * rho_b).sqrt()
}

/// Centred running mean of `values` sampled at increasing `times` (s): each value is replaced by the mean of the
/// samples within ±`window`/2 of it (fewer near the ends, where the window is cut). A `window` ≤ 0 returns the
/// values unchanged.
///
/// ```
/// use rubblepile::analysis::spinup::running_mean;
/// let t = [0.0, 1.0, 2.0, 3.0];
/// assert_eq!(running_mean(&t, &[1.0, 3.0, 1.0, 3.0], 2.0), vec![2.0, 5.0 / 3.0, 7.0 / 3.0, 2.0]);
/// ```
pub fn running_mean(times: &[f64], values: &[f64], window: f64) -> Vec<f64> {
    if window <= 0.0 {
        return values.to_vec();
    }
    let half = 0.5 * window;
    let (mut lo, mut hi, mut sum) = (0usize, 0usize, 0.0);
    let mut out = Vec::with_capacity(values.len());
    for &t in times {
        while hi < times.len() && times[hi] <= t + half {
            sum += values[hi];
            hi += 1;
        }
        while times[lo] < t - half {
            sum -= values[lo];
            lo += 1;
        }
        out.push(sum / (hi - lo) as f64);
    }
    out
}

/// [`critical_limits`] on centred running means over `window` seconds ([`running_mean`]) of b/a, c/a and η_B
/// sampled at `times` (s). With the window set to the body's [`dynamical_time`], the breathing oscillation of
/// a pile of a few thousand particles no longer trips the 0.001 threshold of η_B; the price is that a departure
/// is seen up to half a window early (the mean looks ahead). The
/// reference values are those of the first sample whose window is whole (a window cut at the start would
/// average part of an oscillation: up to 0.64 of its amplitude); later windows may be cut at the end.
pub fn smoothed_critical_limits(
    times: &[f64],
    period_hours: &[f64],
    b_over_a: &[f64],
    c_over_a: &[f64],
    packing: &[f64],
    window: f64,
) -> CriticalLimits {
    let first = times
        .first()
        .and_then(|&t0| times.iter().position(|&t| t - 0.5 * window.max(0.0) >= t0))
        .unwrap_or(times.len());
    let whole = |v: &[f64]| running_mean(times, v, window)[first..].to_vec();
    critical_limits(
        &period_hours[first..],
        &whole(b_over_a),
        &whole(c_over_a),
        &whole(packing),
    )
}

/// Zhang17 Eq. 22: the critical spin rate scales with the bulk density as `Ω_c = κ √(4πGρ_B/3)`. Least-squares κ
/// through the origin from `(ρ_B [kg m⁻³], critical period [h])` pairs, its standard error, and the critical bulk
/// density at which a body spinning with `period_hours` sits at the limit, `ρ_c = 3Ω²/(4πGκ²)`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct DensityFit {
    /// κ of Eq. 22.
    pub kappa: f64,
    /// Its standard error (0 with fewer than 2 points).
    pub sigma_kappa: f64,
    /// Critical bulk density for the given period (kg m⁻³).
    pub critical_density: f64,
}

/// Fits [`DensityFit`] with gravitational constant `g` (m³ kg⁻¹ s⁻²); `None` without a positive point.
pub fn fit_density(points: &[(f64, f64)], g: f64, period_hours: f64) -> Option<DensityFit> {
    let xy: Vec<(f64, f64)> = points
        .iter()
        .filter(|(rho, t)| *rho > 0.0 && *t > 0.0)
        .map(|&(rho, t)| ((4.0 * std::f64::consts::PI * g * rho / 3.0).sqrt(), omega_of_hours(t)))
        .collect();
    if xy.is_empty() {
        return None;
    }
    let sxx: f64 = xy.iter().map(|(x, _)| x * x).sum();
    let sxy: f64 = xy.iter().map(|(x, y)| x * y).sum();
    let kappa = sxy / sxx;
    let n = xy.len();
    let sigma_kappa = if n > 1 {
        let rss: f64 = xy.iter().map(|(x, y)| (y - kappa * x).powi(2)).sum();
        (rss / (n - 1) as f64 / sxx).sqrt()
    } else {
        0.0
    };
    let omega = omega_of_hours(period_hours);
    Some(DensityFit {
        kappa,
        sigma_kappa,
        critical_density: 3.0 * omega * omega / (4.0 * std::f64::consts::PI * g * kappa * kappa),
    })
}

/// Spin rate (rad/s) of a period in hours.
pub fn omega_of_hours(period_hours: f64) -> f64 {
    2.0 * std::f64::consts::PI / (period_hours * 3600.0)
}

/// Zhang17 Table 1: the nominal mass of the Didymos primary (kg), the reference of `ρ_B = 2100 M/M_P`.
pub const DIDYMOS_MASS: f64 = 5.23e11;

/// Zhang17 Table 2's grain counts of its two monodisperse models with Table 3's initial packing η_B of each:
/// (model, grains, η_B). Their grains have the radius [`PAPER_GRAIN_RADIUS`].
pub const PAPER_COUNTS_AND_PACKINGS: [(&str, usize, f64); 2] = [("hcp", 42_062, 0.739), ("rcp", 36_523, 0.641)];
/// Zhang17 Table 2: the grain radius of HCP and RCP (m).
pub const PAPER_GRAIN_RADIUS: f64 = 10.0;

/// The bulk density (kg/m³) the paper's piles had, derived from its own numbers: each monodisperse model's grains
/// (N spheres of 10 m) fill the carved volume `V = N (4/3)π r³ / η_B` at the packing Table 3 gives; HCP's and
/// RCP's volumes agree to 0.1 % (2.384e8 and 2.387e8 m³, D_eq 769 m), and M_P of Table 1 in their mean is
/// `ρ_B = M_P / V̄` ≈ 2193 kg/m³, not the nominal 2100. Returns (ρ_B, V̄ in m³).
///
/// ```
/// let (rho, v) = rubblepile::analysis::spinup::paper_bulk_density();
/// assert!((rho - 2192.5).abs() < 0.5 && (v / 2.3854e8 - 1.0).abs() < 1e-3);
/// ```
pub fn paper_bulk_density() -> (f64, f64) {
    let grain = 4.0 / 3.0 * std::f64::consts::PI * PAPER_GRAIN_RADIUS.powi(3);
    let volumes: Vec<f64> = PAPER_COUNTS_AND_PACKINGS
        .iter()
        .map(|&(_, n, eta)| n as f64 * grain / eta)
        .collect();
    let mean = volumes.iter().sum::<f64>() / volumes.len() as f64;
    (DIDYMOS_MASS / mean, mean)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Mat3, Vec3};

    #[test]
    fn critical_limits_on_synthetic_series() {
        // period falls from 5 h to 2 h; b/a starts to change at sample 60, η at sample 40
        let n = 100;
        let period: Vec<f64> = (0..n).map(|k| 5.0 - 3.0 * k as f64 / (n - 1) as f64).collect();
        let b: Vec<f64> = (0..n)
            .map(|k| 0.9 - if k >= 60 { 0.0023 * (k - 59) as f64 } else { 0.0 })
            .collect();
        let c = vec![0.8; n];
        let eta: Vec<f64> = (0..n)
            .map(|k| 0.74 - if k >= 40 { 0.0004 * (k - 39) as f64 } else { 0.0 })
            .collect();
        let l = critical_limits(&period, &b, &c, &eta);
        // b/a: 0.0023 (k − 59) > 0.01 first at k = 64; η: 0.0004 (k − 39) > 0.001 first at k = 42
        assert_eq!(l.t_c1_hours, Some(period[64]));
        assert_eq!(l.t_c2_hours, Some(period[42]));
        assert_eq!(l.failure_mode, Some(FailureMode::InternalFailure));
        // the shape goes first: b/a leaves at k = 45 (0.0023 (k − 40) > 0.01), η at k = 73 (0.0004 (k − 70) > 0.001)
        let b2: Vec<f64> = (0..n)
            .map(|k| 0.9 - if k >= 40 { 0.0023 * (k - 40) as f64 } else { 0.0 })
            .collect();
        let eta2: Vec<f64> = (0..n)
            .map(|k| 0.74 - if k >= 70 { 0.0004 * (k - 70) as f64 } else { 0.0 })
            .collect();
        let l = critical_limits(&period, &b2, &c, &eta2);
        assert_eq!(l.t_c1_hours, Some(period[45]));
        assert_eq!(l.t_c2_hours, Some(period[73]));
        assert_eq!(l.failure_mode, Some(FailureMode::SurfaceShedding));
        let none = critical_limits(&period, &c, &c, &vec![0.74; n]);
        assert_eq!(
            (none.t_c1_hours, none.t_c2_hours, none.failure_mode),
            (None, None, None)
        );
    }

    /// A breathing oscillation of η_B (±6e-4, period 2700 s, starting at a crest) trips the raw 0.001 rule at its
    /// first trough, long before the packing
    /// changes; averaged over one period it does not, and the real dilation (from t = 20 000 s on) is found
    /// within half a window of its start.
    #[test]
    fn smoothed_limits_ignore_a_breathing_oscillation() {
        let times: Vec<f64> = (0..180).map(|k| k as f64 * 200.0).collect();
        let period: Vec<f64> = times.iter().map(|t| 5.0 - 2.5 * t / 36_000.0).collect();
        let breathing = |t: f64| 6e-4 * (std::f64::consts::TAU * t / 2700.0).cos();
        let eta: Vec<f64> = times
            .iter()
            .map(|&t| {
                0.649 + breathing(t)
                    - if t > 20_000.0 {
                        2e-4 * (t - 20_000.0) / 200.0
                    } else {
                        0.0
                    }
            })
            .collect();
        let flat = vec![0.9; times.len()];
        let raw = critical_limits(&period, &flat, &flat, &eta);
        let raw_k = period.iter().position(|p| Some(*p) == raw.t_c2_hours).unwrap();
        assert!(times[raw_k] < 5000.0, "raw rule trips at t = {}", times[raw_k]);
        let smooth = smoothed_critical_limits(&times, &period, &flat, &flat, &eta, 2700.0);
        let k = period.iter().position(|p| Some(*p) == smooth.t_c2_hours).unwrap();
        assert!(
            (20_000.0 - 1350.0..=20_000.0 + 2000.0).contains(&times[k]),
            "smoothed rule at t = {}",
            times[k]
        );
        // a constant series is its own running mean (to rounding); window 0 changes nothing
        assert!(
            running_mean(&times, &flat, 2700.0)
                .iter()
                .all(|v| (v - 0.9).abs() < 1e-14)
        );
        assert_eq!(running_mean(&times, &eta, 0.0), eta);
        assert!((dynamical_time(6.674e-11, 2100.0) - 2671.1).abs() < 0.1);
    }

    #[test]
    fn hydrostatic_particle_stress_and_mohr_coulomb() {
        // six equal inward forces F at the ends of the axes of a particle of radius R: σ = −2RF/V · 1
        let (r, f, v) = (2.0, 3.0, 10.0);
        let mut contacts = Vec::new();
        for axis in [Vec3::x(), Vec3::y(), Vec3::z()] {
            for s in [-1.0, 1.0] {
                contacts.push((axis * s * r, -axis * s * f));
            }
        }
        let sigma = particle_stress(v, &contacts);
        assert!((sigma - Mat3::identity() * (-2.0 * r * f / v)).norm() < 1e-14);
        let st = stress_state(&sigma);
        assert!((st.pressure + 2.0 * r * f / v).abs() < 1e-14);
        assert!(st.deviatoric.abs() < 1e-14);
        assert!(st.friction_angle_deg.unwrap().abs() < 1e-9);
        // a rotated triaxial state: σ₁ = −1, σ₃ = −3 → θ = arcsin(−2/−4)... = arcsin((σ₃ − σ₁)/(σ₁ + σ₃)) = 30°
        let rot = nalgebra::Rotation3::from_euler_angles(0.3, -0.7, 1.1).into_inner();
        let t = rot * Mat3::from_diagonal(&Vec3::new(-3.0, -1.0, -2.0)) * rot.transpose();
        let st = stress_state(&t);
        assert!((st.principal[0] + 1.0).abs() < 1e-12 && (st.principal[2] + 3.0).abs() < 1e-12);
        assert!((st.friction_angle_deg.unwrap() - 30.0).abs() < 1e-9, "{st:?}");
        assert!((st.deviatoric - 1.0).abs() < 1e-12 && (st.pressure + 2.0).abs() < 1e-12);
        // RVE average weights by volume
        let avg = rve_stress(&[(1.0, Mat3::identity()), (3.0, Mat3::identity() * 5.0)]);
        assert!((avg - Mat3::identity() * 4.0).norm() < 1e-14);
    }

    #[test]
    fn density_fit_recovers_kappa_and_critical_density() {
        let g = 6.674e-11;
        let kappa = 0.9;
        let pts: Vec<(f64, f64)> = [1500.0, 2100.0, 2700.0]
            .iter()
            .map(|&rho| {
                let omega = kappa * (4.0 * std::f64::consts::PI * g * rho / 3.0).sqrt();
                (rho, 2.0 * std::f64::consts::PI / omega / 3600.0)
            })
            .collect();
        let fit = fit_density(&pts, g, 2.26).unwrap();
        assert!((fit.kappa - kappa).abs() < 1e-12 && fit.sigma_kappa < 1e-12, "{fit:?}");
        // at the critical density the limit period is exactly 2.26 h
        let omega = kappa * (4.0 * std::f64::consts::PI * g * fit.critical_density / 3.0).sqrt();
        assert!((2.0 * std::f64::consts::PI / omega / 3600.0 - 2.26).abs() < 1e-12);
    }
}
