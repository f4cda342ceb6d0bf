//! Quaternion attitude algebra of Roig03 §2.2: `R(q)` (Eq. 21), `W(q)` (Eq. 24), the mass matrix
//! `M = 4 Wᵀ Ĩ W` (Eqs. 25–26) and the derivatives the equations of motion need.
//!
//! Convention (see [`crate::ellipsoid`] ("Conventions and corrected forms"), checked by `tests/ellipsoid_gradients.rs`):
//! `q = (α, β, γ, δ)`, vector part first, scalar `δ` last. `R(q)` maps world to body coordinates,
//! `s = R (r − r_i)`. Body spin: `(ω_b, 0) = 2 W(q) q̇`; world spin `ω_w = Rᵀ ω_b`; `Ṙᵀ R = [ω_w]×`.
//! `R(q)` equals the transpose of the active rotation matrix of the Hamilton quaternion
//! `w + x i + y j + z k` with `(x, y, z, w) = (α, β, γ, δ)`.

use crate::math::{Mat3, Mat4, Vec3, Vec4};

/// `R(q)` of Roig03 Eq. 21 (world → body). Exactly orthogonal only for `|q| = 1`; the paper's form
/// (with `−½` on the diagonal) is used as written so that gradients are exact for it.
pub fn rotation_matrix(q: &Vec4) -> Mat3 {
    let (a, b, g, d) = (q.x, q.y, q.z, q.w);
    2.0 * Mat3::new(
        a * a + d * d - 0.5,
        a * b + g * d,
        a * g - b * d,
        a * b - g * d,
        b * b + d * d - 0.5,
        b * g + a * d,
        a * g + b * d,
        b * g - a * d,
        g * g + d * d - 0.5,
    )
}

/// `W(q)` of Roig03 Eq. 24; `Wᵀ W = |q|² 1`.
pub fn w_matrix(q: &Vec4) -> Mat4 {
    let (a, b, g, d) = (q.x, q.y, q.z, q.w);
    Mat4::new(
        d, g, -b, -a, //
        -g, d, a, -b, //
        b, -a, d, -g, //
        a, b, g, d,
    )
}

/// `B(v)` such that `W(q) v = B(v) q` for every `q` (W is linear in q). Its k-th column is `W(e_k) v`.
pub fn w_transposed_action(v: &Vec4) -> Mat4 {
    let mut b = Mat4::zeros();
    for k in 0..4 {
        let mut e = Vec4::zeros();
        e[k] = 1.0;
        b.set_column(k, &(w_matrix(&e) * v));
    }
    b
}

/// Body-frame spin `ω_b = 2 W₃(q) q̇` (rad/s; the first three rows of Roig03 Eq. 23).
pub fn body_spin(q: &Vec4, q_dot: &Vec4) -> Vec3 {
    let w = w_matrix(q) * q_dot;
    2.0 * Vec3::new(w.x, w.y, w.z)
}

/// `q̇` with `q·q̇ = 0` that produces body spin `ω_b` (inverse of [`body_spin`]): `q̇ = ½ Wᵀ (ω_b, 0) / |q|²`.
pub fn q_dot_from_body_spin(q: &Vec4, spin_body: &Vec3) -> Vec4 {
    0.5 * w_matrix(q).transpose() * Vec4::new(spin_body.x, spin_body.y, spin_body.z, 0.0) / q.norm_squared()
}

/// `Ĩ = diag(I₁, I₂, I₃, Tr I)` of Roig03 Eq. 26, from the principal moments.
pub fn extended_inertia(moments: &Vec3) -> Vec4 {
    Vec4::new(moments.x, moments.y, moments.z, moments.x + moments.y + moments.z)
}

/// The quaternion mass matrix `M(q) = 4 Wᵀ Ĩ W` (Roig03 Eq. 25).
pub fn mass_matrix(q: &Vec4, inertia_ext: &Vec4) -> Mat4 {
    let w = w_matrix(q);
    4.0 * w.transpose() * Mat4::from_diagonal(inertia_ext) * w
}

/// `M(q)⁻¹ v = Wᵀ (Ĩ⁻¹ ∘ (W v)) / (4 |q|⁴)`, since `M(q)⁻¹ = Wᵀ Ĩ⁻¹ W / (4 |q|⁴)` (`W` is orthogonal times `|q|`),
/// without forming `M⁻¹`. The right-hand side needs only `M⁻¹ p = q̇` and `M⁻¹ q`.
pub fn inverse_mass_apply(q: &Vec4, inertia_ext: &Vec4, v: &Vec4) -> Vec4 {
    let w = w_matrix(q);
    w.transpose() * (w * v).component_div(inertia_ext) / (4.0 * q.norm_squared().powi(2))
}

/// `∂K_R/∂q` at fixed `q̇`, where `K_R = ½ q̇ᵀ M(q) q̇`: `4 B(q̇)ᵀ Ĩ W(q) q̇`.
pub fn rotational_kinetic_gradient(q: &Vec4, q_dot: &Vec4, inertia_ext: &Vec4) -> Vec4 {
    let wq = w_matrix(q) * q_dot;
    4.0 * w_transposed_action(q_dot).transpose() * inertia_ext.component_mul(&wq)
}

/// Converts a scalar-last quaternion to nalgebra's unit quaternion (body → world rotation).
pub fn to_unit_quaternion(q: &Vec4) -> nalgebra::UnitQuaternion<f64> {
    nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q.w, q.x, q.y, q.z))
}

/// Converts nalgebra's unit quaternion (body → world) to the scalar-last convention.
pub fn from_unit_quaternion(u: &nalgebra::UnitQuaternion<f64>) -> Vec4 {
    Vec4::new(u.i, u.j, u.k, u.w)
}
