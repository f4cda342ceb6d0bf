//! The Gaussian-overlap contact potential (Roig03 Eqs. 7–12) in the equivalent, cheaper form of
//! `shared/notes/ellipsoid-model.md`:
//!
//! `Σ_i = R_iᵀ diag(A², B², C²) R_i`, `G = Σ_i + Σ_j`, `Δ = r_i − r_j`,
//! `U_C = P_ij · det(G)^{−1/2} · exp(−κ Δᵀ G⁻¹ Δ)` with `P_ij = U0_ij m_i m_j (κ/π)^{3/2}`.
//!
//! Gradients: `∂U_C/∂r_i = −2κ U_C G⁻¹Δ`; `∂U_C/∂q_i,k = 2 U_C ⟨D_i R_i S, ∂R_i/∂q_k⟩_F` with
//! `S = −½ G⁻¹ + κ (G⁻¹Δ)(G⁻¹Δ)ᵀ` (chain rule of `ln U_C` through `G` and `R(q)`).

use crate::ellipsoid::quaternion::{rotation_matrix, rotation_matrix_derivatives};
use crate::math::{Mat3, Vec3, Vec4};

/// Per-body quantities of one state that every pair involving the body reuses.
#[derive(Debug, Clone, Copy)]
pub struct BodyGeometry {
    /// `R(q)` (world → body).
    pub rot: Mat3,
    /// `Σ = Rᵀ diag(A², B², C²) R` (m²), the world-frame covariance shape of the body.
    pub sigma: Mat3,
    /// `∂R/∂q_k`, k = α, β, γ, δ.
    pub d_rot: [Mat3; 4],
    /// `(A², B², C²)` (m²).
    pub axes_sq: Vec3,
    /// An upper bound on the largest eigenvalue of `Σ` (m²), used by far-pair culling:
    /// `A² (|q|² + ||q|² − 1|)²` (exact `A²` for `|q| = 1`).
    pub sigma_bound: f64,
}

impl BodyGeometry {
    /// Builds the geometry of a body with semi-axes `axes` (m) at attitude `q`.
    pub fn new(axes: &Vec3, q: &Vec4) -> Self {
        let rot = rotation_matrix(q);
        let axes_sq = axes.component_mul(axes);
        let d_rot_x = Mat3::from_diagonal(&axes_sq) * rot;
        let sigma = rot.transpose() * d_rot_x;
        let q2 = q.norm_squared();
        let stretch = q2 + (q2 - 1.0).abs();
        BodyGeometry {
            rot,
            sigma,
            d_rot: rotation_matrix_derivatives(q),
            axes_sq,
            sigma_bound: axes_sq.x * stretch * stretch,
        }
    }
}

/// The overlap of two Gaussian bodies at separation `Δ = r_i − r_j`.
#[derive(Debug, Clone, Copy)]
pub struct Overlap {
    /// `G⁻¹` (m⁻²).
    pub g_inv: Mat3,
    /// `y = G⁻¹ Δ` (m⁻¹).
    pub y: Vec3,
    /// The pair amplitude `P_ij det(G)^{−1/2}` (J): the potential at full overlap.
    pub amplitude: f64,
    /// `κ Δᵀ G⁻¹ Δ` (dimensionless).
    pub exponent: f64,
    /// `U_C` (J).
    pub potential: f64,
}

/// Evaluates the overlap integral of a pair. `prefactor` is `U0_ij m_i m_j (κ/π)^{3/2}` (J m³),
/// see [`crate::ellipsoid::calibration::pair_prefactor`].
pub fn overlap(prefactor: f64, kappa: f64, delta: &Vec3, gi: &BodyGeometry, gj: &BodyGeometry) -> Overlap {
    let g = gi.sigma + gj.sigma;
    let det = g.determinant();
    // G is symmetric positive definite for any non-degenerate bodies; the closed-form 3×3 inverse is exact enough.
    let g_inv = g.try_inverse().unwrap_or_else(|| Mat3::from_element(f64::NAN));
    let y = g_inv * delta;
    let exponent = kappa * delta.dot(&y);
    let amplitude = prefactor / det.sqrt();
    Overlap {
        g_inv,
        y,
        amplitude,
        exponent,
        potential: amplitude * (-exponent).exp(),
    }
}

/// Gradients of `U_C` with respect to the positions and quaternions of a pair.
#[derive(Debug, Clone, Copy)]
pub struct ContactGradient {
    /// `∂U_C/∂r_i` (N); `∂U_C/∂r_j` is its negative.
    pub d_ri: Vec3,
    /// `∂U_C/∂q_i` (J).
    pub d_qi: Vec4,
    /// `∂U_C/∂q_j` (J).
    pub d_qj: Vec4,
}

/// `∂U_C/∂q` of one body of the pair, `2 U_C ⟨D R S, ∂R/∂q_k⟩_F`.
fn quaternion_gradient(u: f64, s: &Mat3, body: &BodyGeometry) -> Vec4 {
    let x = Mat3::from_diagonal(&body.axes_sq) * body.rot * s;
    let mut out = Vec4::zeros();
    for k in 0..4 {
        out[k] = 2.0 * u * x.dot(&body.d_rot[k]);
    }
    out
}

/// Analytic gradients of the contact potential of a pair (see the module doc).
pub fn contact_gradient(ov: &Overlap, kappa: f64, gi: &BodyGeometry, gj: &BodyGeometry) -> ContactGradient {
    let u = ov.potential;
    let s = -0.5 * ov.g_inv + kappa * ov.y * ov.y.transpose();
    ContactGradient {
        d_ri: -2.0 * kappa * u * ov.y,
        d_qi: quaternion_gradient(u, &s, gi),
        d_qj: quaternion_gradient(u, &s, gj),
    }
}

/// `−ln(cutoff)`: pairs with `κ|Δ|²/(λ̄_i + λ̄_j) > −ln(cutoff)` have `U_C < cutoff × amplitude`
/// (since `Δᵀ G⁻¹ Δ ≥ |Δ|²/λ_max(G)` and `λ_max(G) ≤ λ̄_i + λ̄_j` with `λ̄` = [`BodyGeometry::sigma_bound`]).
pub fn cull_exponent(cutoff: f64) -> f64 {
    -cutoff.ln()
}

/// Whether a pair is provably negligible: `U_C < cutoff · amplitude` (and so is its dissipation weight).
pub fn is_negligible(kappa: f64, delta: &Vec3, gi: &BodyGeometry, gj: &BodyGeometry, cull_exp: f64) -> bool {
    kappa * delta.norm_squared() > cull_exp * (gi.sigma_bound + gj.sigma_bound)
}

/// Radius (m) of the sphere around a body outside which no partner (of any size up to its own bound)
/// can interact: a pair is a candidate only if `|Δ| < ρ_i + ρ_j` with `ρ = sqrt(cull_exp · λ̄ / κ)`,
/// which contains every pair that [`is_negligible`] keeps because `√(a+b) ≤ √a + √b`.
pub fn interaction_radius(kappa: f64, gi: &BodyGeometry, cull_exp: f64) -> f64 {
    (cull_exp * gi.sigma_bound / kappa).sqrt()
}
