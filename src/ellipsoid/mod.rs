//! The interacting-ellipsoids model (Roig03 §2): [`body`] (Eq. 4), [`quaternion`] (`R(q)` Eq. 21, `W(q)` Eq. 24),
//! [`potential`] (Gaussian-overlap contact, Eqs. 7–12), [`calibration`] (κ from Eq. 14, `U0` from Eq. 11),
//! [`gravity`] (monopole, Eq. 6) and [`gravity_tree`] (Barnes–Hut for large N), [`dissipation`] (Eqs. 40–41) and
//! [`dissipation_jacobian`], [`clumps`] (bodies in contact), [`barrier`] (Eqs. 13–14 checked during a run),
//! [`tide`] (`[physics.flyby]`), [`equations`] (Eqs. 28–37, an [`crate::integrate::OdeSystem`]).
//!
//! # Conventions and corrected forms
//!
//! Checked numerically by the tests each submodule names. `q = (α, β, γ, δ)`, scalar last; `|q| = 1` (Eq. 20) is
//! kept by Lagrange multipliers and its drift reported, never renormalised away. `R(q)` maps world to body,
//! `(ω_b, 0) = 2 W(q) q̇`, `ω_w = Rᵀ ω_b`. `M(q) = 4 Wᵀ Ĩ W` is inverted in closed form, `M⁻¹ = Wᵀ Ĩ⁻¹ W / (4|q|⁴)`.
//! The contact potential is evaluated in an equivalent cheaper form, `U_C = U0 m_i m_j (κ/π)^{3/2} det(G)^{−1/2}
//! exp(−κ Δᵀ G⁻¹ Δ)` with `G = Σ_i + Σ_j`; Eq. 14 is solved by Newton on `κλ > 1`, a scene without a root
//! `κ > 3/2` refused. Eq. 35 as extracted is wrong: differentiating `q·q̇ = 0` gives
//! `qᵀ M⁻¹ ṗ = qᵀ M⁻¹ Ṁ M⁻¹ p − pᵀ M⁻² p`. The dissipation is in closed form; `dH/dt = 2F` is integrated as one
//! more state component so the energy residual `H − H0 − 2∫F dt` can be checked.

pub mod barrier;
pub mod body;
pub mod calibration;
pub mod cloud;
pub mod clumps;
pub mod dissipation;
pub mod dissipation_jacobian;
pub mod equations;
pub mod gravity;
pub mod gravity_tree;
pub mod output;
pub mod potential;
pub mod quaternion;
pub mod rigid_rotation;
pub mod run;
pub mod scene;
pub mod spin_state;
pub mod summary;
pub mod tide;
