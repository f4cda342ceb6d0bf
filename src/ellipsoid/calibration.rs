//! κ and the contact amplitude `U0_ij` (Roig03 Eqs. 11–14).
//!
//! For two spheres of radii `R_i, R_j` the pair potential `U_C + U_G` has its minimum exactly at
//! `|r_i − r_j| = R_i + R_j` when `U0_ij` is Eq. 11; there `U_C/|U_G| = 1/(2κλ_ij)` with `λ_ij` of Eq. 12.
//! Ellipsoids use their equivalent radius `(ABC)^{1/3}` (the paper's rule).

use std::f64::consts::PI;

/// Why κ could not be calibrated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CalibrationError {
    /// Eq. 14 has no root with κ > 3/2 for the given β and v.
    #[error(
        "model.calibrate: no kappa > 3/2 solves Roig03 Eq. 14 for beta = {beta}, v = {v} m/s; need v^2 > {v2_min:e} m^2/s^2 (raise v or beta)"
    )]
    Unreachable {
        /// β given.
        beta: f64,
        /// v given (m/s).
        v: f64,
        /// Minimum v² (m²/s²) for κ > 3/2 at this β.
        v2_min: f64,
    },
    /// β, v, radii, mass or G not positive and finite.
    #[error("model.calibrate: {field} must be > 0 and finite, got {value}")]
    BadInput {
        /// Which input.
        field: &'static str,
        /// Its value.
        value: f64,
    },
}

/// `λ_ij = (R_i + R_j)² / (R_i² + R_j²)` (Roig03 Eq. 12), `1 < λ ≤ 2`.
pub fn lambda(r_i: f64, r_j: f64) -> f64 {
    (r_i + r_j).powi(2) / (r_i * r_i + r_j * r_j)
}

/// `U0_ij = G π^{3/2}/2 (R_i+R_j)² exp(κλ)/(κλ)^{5/2}` (Roig03 Eq. 11), in m⁵ kg⁻¹ s⁻² … such that
/// `U_C = U0 ∫ρ_iρ_j d³r` is an energy.
pub fn contact_amplitude_u0(g: f64, kappa: f64, r_i: f64, r_j: f64) -> f64 {
    let x = kappa * lambda(r_i, r_j);
    0.5 * g * PI.powf(1.5) * (r_i + r_j).powi(2) * x.exp() / x.powf(2.5)
}

/// The pair prefactor `U0_ij m_i m_j (κ/π)^{3/2}` (J m³) so that
/// `U_C = prefactor · det(G)^{−1/2} · exp(−κ Δᵀ G⁻¹ Δ)` (the note's cheaper form of Eq. 10).
///
/// Evaluated without `powf` (it runs for every interacting pair at every RHS evaluation):
/// `U0 (κ/π)^{3/2} = ½ G (R_i+R_j)² e^{κλ} / (κ λ^{5/2})`.
pub fn pair_prefactor(g: f64, kappa: f64, r_i: f64, m_i: f64, r_j: f64, m_j: f64) -> f64 {
    let sum = r_i + r_j;
    let lam = sum * sum / (r_i * r_i + r_j * r_j);
    0.5 * g * sum * sum * (kappa * lam).exp() / (kappa * lam * lam * lam.sqrt()) * m_i * m_j
}

/// Solves Roig03 Eq. 14 for κ: `exp(κλ)/(κλ) = β v² (R_k + R_l)/(G m_k)`, where `k` is the smallest
/// (equivalent radius `r_small`, mass `m_small`) and `l` the largest body (`r_large`).
/// Newton on `x = κλ` on the branch `x > 1`; refuses when the root has κ ≤ 3/2.
///
/// ```
/// use rubblepile::ellipsoid::calibration::{calibrate_kappa, lambda};
/// let (g, r, m) = (6.674e-11, 1000.0, 1.2566e13);
/// let kappa = calibrate_kappa(10.0, 5.0, r, m, r, g).unwrap();
/// let x = kappa * lambda(r, r);
/// let rhs = 10.0 * 25.0 * 2.0 * r / (g * m);
/// assert!(((x.exp() / x) / rhs - 1.0).abs() < 1e-12);
/// ```
pub fn calibrate_kappa(
    beta: f64,
    v: f64,
    r_small: f64,
    m_small: f64,
    r_large: f64,
    g: f64,
) -> Result<f64, CalibrationError> {
    for (field, value) in [
        ("beta", beta),
        ("v", v),
        ("smallest body's radius", r_small),
        ("smallest body's mass", m_small),
        ("largest body's radius", r_large),
        ("G", g),
    ] {
        if !(value > 0.0 && value.is_finite()) {
            return Err(CalibrationError::BadInput { field, value });
        }
    }
    let lam = lambda(r_small, r_large);
    let rhs = beta * v * v * (r_small + r_large) / (g * m_small);
    // κ > 3/2  ⇔  x > 1.5 λ; exp(x)/x is increasing for x > 1.
    let x_min = 1.5 * lam;
    let unreachable = || CalibrationError::Unreachable {
        beta,
        v,
        v2_min: x_min.exp() / x_min * g * m_small / (beta * (r_small + r_large)),
    };
    // (written so that a NaN right side is refused too)
    if rhs.is_nan() || rhs <= x_min.exp() / x_min {
        return Err(unreachable());
    }
    // f(x) = x − ln x − ln(rhs) is convex and increasing for x > 1: Newton from the right converges monotonically.
    let ln_rhs = rhs.ln();
    let mut x = (ln_rhs + ln_rhs.ln().max(0.0) + 1.0).max(x_min + 1.0);
    for _ in 0..200 {
        let f = x - x.ln() - ln_rhs;
        let step = f / (1.0 - 1.0 / x);
        x -= step;
        if step.abs() <= 1e-15 * x {
            break;
        }
    }
    let kappa = x / lam;
    if kappa > 1.5 && kappa.is_finite() {
        Ok(kappa)
    } else {
        Err(unreachable())
    }
}
