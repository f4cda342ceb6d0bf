//! The point dissipation function (Roig03 Eqs. 40–41) in closed form (see [`crate::ellipsoid`], "Conventions and
//! corrected forms").
//!
//! With the product-Gaussian centre offsets `d_i = r_ij − r_i = −Σ_i G⁻¹Δ`, `d_j = r_ij − r_j = Σ_j G⁻¹Δ`,
//! its covariance `P = Σ_i G⁻¹ Σ_j`, relative spin `w = ω_i − ω_j` (world frame) and relative point velocity
//! `v0 = ṙ_i − ṙ_j + ω_i × d_i − ω_j × d_j`:
//!
//! `F_ij = −F0 U_Cij [ (|w|² Tr P − wᵀ P w)/(2κ) + |v0|² ]` (W, ≤ 0).
//!
//! It vanishes for a common rigid motion and conserves total linear and angular momentum (Roig03 App. A).
//! Generalised forces: `∂F/∂ṙ_i`, and `∂F/∂q̇_i = 2 W₃(q_i)ᵀ R_i ∂F/∂ω_i` (chain rule through
//! `ω_w = Rᵀ ω_b`, `ω_b = 2 W₃ q̇`).

use crate::ellipsoid::potential::{BodyGeometry, Overlap};
use crate::math::{Mat3, Vec3};

/// Velocities of one body entering the dissipation function.
#[derive(Debug, Clone, Copy)]
pub struct BodyVelocity {
    /// Centre-of-mass velocity ṙ (m/s).
    pub velocity: Vec3,
    /// World-frame spin ω_w (rad/s).
    pub spin_world: Vec3,
}

/// `F_ij` and its derivatives with respect to the pair's velocities.
#[derive(Debug, Clone, Copy)]
pub struct PairDissipation {
    /// `F_ij` (W, ≤ 0).
    pub value: f64,
    /// `∂F/∂ṙ_i` (N); `∂F/∂ṙ_j` is its negative.
    pub d_vi: Vec3,
    /// `∂F/∂ω_i` (N m, world frame).
    pub d_wi: Vec3,
    /// `∂F/∂ω_j` (N m, world frame).
    pub d_wj: Vec3,
}

/// Evaluates `F_ij` of a pair whose overlap is `ov` (with `U_C` = `ov.potential`), and its velocity derivatives.
/// `f0` is F0 (s m⁻²).
pub fn pair_dissipation(
    f0: f64,
    kappa: f64,
    ov: &Overlap,
    gi: &BodyGeometry,
    gj: &BodyGeometry,
    vi: &BodyVelocity,
    vj: &BodyVelocity,
) -> PairDissipation {
    let d_i = -(gi.sigma * ov.y);
    let d_j = gj.sigma * ov.y;
    let p: Mat3 = gi.sigma * ov.g_inv * gj.sigma;
    let w = vi.spin_world - vj.spin_world;
    let v0 = vi.velocity - vj.velocity + vi.spin_world.cross(&d_i) - vj.spin_world.cross(&d_j);
    let trace_p = p.trace();
    let pw = p * w;
    let c = -f0 * ov.potential;
    let value = c * ((w.norm_squared() * trace_p - w.dot(&pw)) / (2.0 * kappa) + v0.norm_squared());
    // ∂/∂w of the spin term: (2 w Tr P − 2 P w)/(2κ) (P symmetric).
    let d_w = (w * trace_p - pw) / kappa;
    PairDissipation {
        value,
        d_vi: 2.0 * c * v0,
        d_wi: c * (d_w + 2.0 * d_i.cross(&v0)),
        d_wj: c * (-d_w - 2.0 * d_j.cross(&v0)),
    }
}
