//! The Gaussian-overlap contact potential (Roig03 Eqs. 7–12) in the equivalent, cheaper form of [`crate::ellipsoid`]
//! ("Conventions and corrected forms"): `Σ_i = R_iᵀ diag(A², B², C²) R_i`, `G = Σ_i + Σ_j`, `Δ = r_i − r_j`,
//! `U_C = P_ij det(G)^{−1/2} exp(−κ Δᵀ G⁻¹ Δ)`, `P_ij = U0_ij m_i m_j (κ/π)^{3/2}`. Gradients:
//! `∂U_C/∂r_i = −2κ U_C G⁻¹Δ`, `∂U_C/∂q_i,k = 2 U_C ⟨D_i R_i S, ∂R_i/∂q_k⟩_F`, `S = −½ G⁻¹ + κ (G⁻¹Δ)(G⁻¹Δ)ᵀ`.
//!
//! Far pairs (ours): with `x = κ Δᵀ G⁻¹ Δ`, `U = U_raw T(x)`, a C² quintic taper that is 1 up to
//! `x₀ = κλ_ij − ln(cutoff)` and 0 from `x₀ + 4`, so it changes only what is below `cutoff` of the pair's potential
//! at contact (`x = κλ_ij`; cut relative to the amplitude it would remove a stiff pair's contact itself, guarded in
//! `tests/ellipsoid_gradients.rs`) and the right-hand side stays C² as pairs enter or leave the neighbour list (a hard
//! cut makes forces jump, which extrapolation cannot step across). Then `∂U/∂Δ = −2κ U (T − T′) G⁻¹Δ`,
//! `S = −½ T G⁻¹ + κ (T − T′) y yᵀ`.

use crate::ellipsoid::quaternion::rotation_matrix;
use crate::math::{Mat3, Vec3, Vec4};

/// Per-body quantities of one state that every pair involving the body reuses.
#[derive(Debug, Clone, Copy)]
pub struct BodyGeometry {
    /// `R(q)` (world → body).
    pub rot: Mat3,
    /// `Σ = Rᵀ diag(A², B², C²) R` (m²), the world-frame covariance shape of the body.
    pub sigma: Mat3,
    /// The attitude `q`.
    pub q: Vec4,
    /// `diag(A², B², C²) R` (m²), shared by `Σ` and every pair's quaternion gradient.
    pub axes_rot: Mat3,
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
        // diag(A², B², C²) R: row k of R scaled by the k-th squared axis.
        let axes_rot = Mat3::from_fn(|r, c| axes_sq[r] * rot[(r, c)]);
        let sigma = rot.transpose() * axes_rot;
        let q2 = q.norm_squared();
        let stretch = q2 + (q2 - 1.0).abs();
        BodyGeometry {
            rot,
            sigma,
            q: *q,
            axes_rot,
            axes_sq,
            sigma_bound: axes_sq.x * stretch * stretch,
        }
    }
}

/// The far-pair taper: 1 up to exponent `start`, C² quintic fall to 0 at `end`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Taper {
    /// Exponent `x₀ = −ln(cutoff)` where the taper begins (dimensionless).
    pub start: f64,
    /// Exponent `x₁ = x₀ + TAPER_WIDTH` beyond which the pair contributes exactly nothing.
    pub end: f64,
}

/// Width of the taper in the exponent `x` (a factor e⁴ ≈ 55 in the potential).
pub const TAPER_WIDTH: f64 = 4.0;

impl Taper {
    /// The taper of a pair with `κλ_ij` (Roig03 Eq. 12) for a relative cutoff (e.g. 1e-16): it starts where
    /// the potential is `cutoff` times its value at contact.
    pub fn for_pair(cutoff: f64, kappa_lambda: f64) -> Self {
        let start = kappa_lambda - cutoff.ln();
        Taper {
            start,
            end: start + TAPER_WIDTH,
        }
    }

    /// `(T(x), T′(x))`.
    pub fn value_and_slope(&self, x: f64) -> (f64, f64) {
        if x <= self.start {
            (1.0, 0.0)
        } else if x >= self.end {
            (0.0, 0.0)
        } else {
            let w = self.end - self.start;
            let t = (x - self.start) / w;
            let s = t * t * t * (10.0 - 15.0 * t + 6.0 * t * t);
            let ds = 30.0 * t * t * (1.0 - t) * (1.0 - t) / w;
            (1.0 - s, -ds)
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
    /// `U_raw = amplitude · exp(−x)` (J), the untapered potential (not `U / T`: `T` is 0 beyond the taper).
    pub potential_raw: f64,
    /// `U_C` (J), tapered: `U_raw · T(x)`.
    pub potential: f64,
    /// `T(x)`.
    pub taper: f64,
    /// `T′(x)`.
    pub taper_slope: f64,
}

/// Evaluates the overlap integral of a pair. `prefactor` is `U0_ij m_i m_j (κ/π)^{3/2}` (J m³),
/// see [`crate::ellipsoid::calibration::pair_prefactor`].
pub fn overlap(
    prefactor: f64,
    kappa: f64,
    delta: &Vec3,
    gi: &BodyGeometry,
    gj: &BodyGeometry,
    taper: &Taper,
) -> Overlap {
    let (g_inv, det, y, exponent) = overlap_exponent(kappa, delta, gi, gj);
    finish_overlap(prefactor, taper, g_inv, det, y, exponent)
}

/// [`overlap`] for a pair whose exponent is below its taper's end, else `None`: beyond the end the potential,
/// its gradients and the dissipation weight are all exactly zero, and the `exp`, square root and division of
/// the amplitude are not worth computing. The same bits as [`overlap`] where it returns a value.
pub fn overlap_within_taper(
    prefactor: f64,
    kappa: f64,
    delta: &Vec3,
    gi: &BodyGeometry,
    gj: &BodyGeometry,
    taper: &Taper,
) -> Option<Overlap> {
    let (g_inv, det, y, exponent) = overlap_exponent(kappa, delta, gi, gj);
    // (a NaN exponent is kept, so that a broken state still shows in the forces)
    if exponent >= taper.end {
        return None;
    }
    Some(finish_overlap(prefactor, taper, g_inv, det, y, exponent))
}

/// `G⁻¹`, `det G`, `y = G⁻¹Δ` and the exponent `x = κ Δ·y` of a pair.
fn overlap_exponent(kappa: f64, delta: &Vec3, gi: &BodyGeometry, gj: &BodyGeometry) -> (Mat3, f64, Vec3, f64) {
    let g = gi.sigma + gj.sigma;
    // G is symmetric positive definite for any non-degenerate bodies; the closed-form 3×3 inverse is exact enough.
    let (det, g_inv) = determinant_and_inverse(&g);
    let y = g_inv * delta;
    let exponent = kappa * delta.dot(&y);
    (g_inv, det, y, exponent)
}

/// The rest of [`overlap`] once the exponent is known.
fn finish_overlap(prefactor: f64, taper: &Taper, g_inv: Mat3, det: f64, y: Vec3, exponent: f64) -> Overlap {
    let amplitude = prefactor / det.sqrt();
    let (t, t_slope) = taper.value_and_slope(exponent);
    let potential_raw = amplitude * (-exponent).exp();
    Overlap {
        g_inv,
        y,
        amplitude,
        exponent,
        potential_raw,
        potential: potential_raw * t,
        taper: t,
        taper_slope: t_slope,
    }
}

/// `det(m)` and `m⁻¹` of a symmetric 3×3 matrix (its upper triangle is read; `G = Σ_i + Σ_j` is symmetric to
/// round-off) by cofactors: six cofactors and one division instead of nine (NaN where `det(m) = 0`). The
/// determinant is needed by every pair's amplitude, the inverse by its exponent.
fn determinant_and_inverse(m: &Mat3) -> (f64, Mat3) {
    let (a, b, c) = (m[(0, 0)], m[(0, 1)], m[(0, 2)]);
    let (d, e, f) = (m[(1, 1)], m[(1, 2)], m[(2, 2)]);
    let c00 = d * f - e * e;
    let c01 = c * e - b * f;
    let c02 = b * e - c * d;
    let det = a * c00 + b * c01 + c * c02;
    if det == 0.0 {
        return (det, Mat3::from_element(f64::NAN));
    }
    let r = 1.0 / det;
    let (c11, c12, c22) = (a * f - c * c, b * c - a * e, a * d - b * b);
    let inv = Mat3::new(
        c00 * r,
        c01 * r,
        c02 * r,
        c01 * r,
        c11 * r,
        c12 * r,
        c02 * r,
        c12 * r,
        c22 * r,
    );
    (det, inv)
}

/// `∂U_C/∂r_i` and the matrix `S` with `dU_C = U_raw ⟨S, dΣ⟩_F` for a change `dΣ` of either body's `Σ` (taper
/// included, see the module doc).
fn position_gradient_and_shape_matrix(ov: &Overlap, kappa: f64) -> (Vec3, Mat3) {
    let (t, dt) = (ov.taper, ov.taper_slope);
    let s = -0.5 * t * ov.g_inv + kappa * (t - dt) * ov.y * ov.y.transpose();
    (-2.0 * kappa * ov.potential_raw * (t - dt) * ov.y, s)
}

/// Gradients of the contact potential of a pair with respect to the positions and the world-frame spins.
#[derive(Debug, Clone, Copy)]
pub struct ContactSpinGradient {
    /// `∂U_C/∂r_i` (N); `∂U_C/∂r_j` is its negative.
    pub d_ri: Vec3,
    /// `∂U_C/∂ω_i` (J s = N m s): `U_C` changes at the rate `∂U_C/∂ω_i · ω_i` while body `i` turns at world
    /// spin `ω_i` (the potential's torque on body `i` is its negative).
    pub d_wi: Vec3,
    /// `∂U_C/∂ω_j` (J s).
    pub d_wj: Vec3,
}

/// The contact gradient of the module doc with the attitude derivatives as spin gradients: while a body turns at world spin `ω`,
/// `Σ̇ = [ω]× Σ − Σ [ω]×`, so `U̇_C = U_raw tr((Σ S − S Σ) [ω]×)` and `∂U_C/∂ω = −2 U_raw axial(Σ S − S Σ)`
/// (`tr([m]× [ω]×) = −2 m·ω`). Through `ω = Rᵀ 2 W₃(q) q̇`, `2 W₃ᵀ R ∂U_C/∂ω` is the part of `∂U_C/∂q` tangent
/// to `|q| = 1`, the only part the constrained equations of motion see (Roig03 Eq. 36 removes the radial one),
/// so the right-hand side can add the contact and dissipation spin terms of all pairs first and map each body's
/// sum to its quaternion once: six off-diagonal products per body instead of two 3×3 products and a 4×9
/// contraction per pair.
pub fn contact_spin_gradient(ov: &Overlap, kappa: f64, gi: &BodyGeometry, gj: &BodyGeometry) -> ContactSpinGradient {
    let (d_ri, s) = position_gradient_and_shape_matrix(ov, kappa);
    ContactSpinGradient {
        d_ri,
        d_wi: spin_gradient(ov.potential_raw, &s, &gi.sigma),
        d_wj: spin_gradient(ov.potential_raw, &s, &gj.sigma),
    }
}

/// `−2 u axial(Σ S − S Σ)` for symmetric `Σ` and `S`: `Σ S − S Σ = A − Aᵀ` with `A = Σ S`, so only the
/// off-diagonal entries of `A` are needed.
fn spin_gradient(u: f64, s: &Mat3, sigma: &Mat3) -> Vec3 {
    let a = |r: usize, c: usize| sigma[(r, 0)] * s[(0, c)] + sigma[(r, 1)] * s[(1, c)] + sigma[(r, 2)] * s[(2, c)];
    -2.0 * u * Vec3::new(a(2, 1) - a(1, 2), a(0, 2) - a(2, 0), a(1, 0) - a(0, 1))
}

/// The largest taper end over all pairs, `2κ − ln(cutoff) + TAPER_WIDTH` (λ ≤ 2), for the neighbour search.
pub fn max_cull_exponent(kappa: f64, cutoff: f64) -> f64 {
    Taper::for_pair(cutoff, 2.0 * kappa).end
}

/// Whether a pair provably contributes nothing: with `cull_exp` its taper's end, pairs with
/// `κ|Δ|²/(λ̄_i + λ̄_j) > cull_exp` have `x = κ Δᵀ G⁻¹ Δ` beyond it too (since `Δᵀ G⁻¹ Δ ≥ |Δ|²/λ_max(G)` and
/// `λ_max(G) ≤ λ̄_i + λ̄_j` with `λ̄` = [`BodyGeometry::sigma_bound`]), where the tapered potential and
/// the dissipation weight are exactly 0.
pub fn is_negligible(kappa: f64, delta: &Vec3, gi: &BodyGeometry, gj: &BodyGeometry, cull_exp: f64) -> bool {
    kappa * delta.norm_squared() > cull_exp * (gi.sigma_bound + gj.sigma_bound)
}

/// Radius (m) of the sphere around a body outside which no partner can interact: with `cull_exp` at least
/// every pair's taper end ([`max_cull_exponent`]), a pair is a candidate only if `|Δ| < ρ_i + ρ_j` with
/// `ρ = sqrt(cull_exp · λ̄ / κ)`, which contains every pair that [`is_negligible`] keeps because
/// `√(a+b) ≤ √a + √b`.
pub fn interaction_radius(kappa: f64, gi: &BodyGeometry, cull_exp: f64) -> f64 {
    (cull_exp * gi.sigma_bound / kappa).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A xorshift stream of numbers in [−1, 1) (no dependency for a few hundred test draws).
    fn uniform_in_minus_one_one(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
    }

    /// The symmetric cofactor inverse agrees with nalgebra's general determinant and inverse on the `G` of random
    /// pairs, to round-off.
    #[test]
    fn symmetric_inverse_matches_the_general_one() {
        let mut rand = uniform_in_minus_one_one(0x9e37_79b9_7f4a_7c15);
        for _ in 0..500 {
            let q = Vec4::new(rand(), rand(), rand(), rand()).normalize();
            let p = Vec4::new(rand(), rand(), rand(), rand()).normalize();
            let gi = BodyGeometry::new(&Vec3::new(3.0 + rand(), 1.5, 0.3 + 0.2 * rand()), &q);
            let gj = BodyGeometry::new(&Vec3::new(1e3 * (2.0 + rand()), 800.0, 500.0), &p);
            let g = gi.sigma + gj.sigma;
            let (det, inv) = determinant_and_inverse(&g);
            let (det_ref, inv_ref) = (g.determinant(), g.try_inverse().unwrap());
            assert!((det - det_ref).abs() <= 1e-12 * det_ref.abs(), "{det} vs {det_ref}");
            assert!((inv - inv_ref).norm() <= 1e-12 * inv_ref.norm(), "{inv} vs {inv_ref}");
        }
    }
}
