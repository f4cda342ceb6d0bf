//! The interacting-ellipsoids model (Roig03 §2).
//!
//! - [`body`]: shape, mass, moments of inertia;
//! - [`quaternion`]: `R(q)` (Eq. 21), `W(q)` (Eq. 24) and their derivatives;
//! - [`potential`]: the Gaussian-overlap contact potential (Eqs. 7–12) and its gradients;
//! - [`calibration`]: κ from Eq. 14 and `U0` from Eq. 11;
//! - [`gravity`]: monopole gravity (Eq. 6);
//! - [`gravity_tree`]: the same by a Barnes–Hut octree for large N, and the choice between the two;
//! - [`dissipation`]: the point dissipation function (Eqs. 40–41);
//! - [`dissipation_jacobian`]: its analytic Jacobian in the momenta and the solve the stiff integrator needs;
//! - [`clumps`]: connected sets of bodies in contact;
//! - [`barrier`]: the contact-barrier overrun detector (calibration of Eqs. 13–14 checked during a run);
//! - [`tide`]: a planet on a prescribed Kepler orbit (the `[physics.flyby]` term);
//! - [`equations`]: the equations of motion (Eqs. 28–37) as an [`crate::integrate::OdeSystem`].
//!
//! # Conventions and corrected forms
//!
//! Our reading of the paper, each point checked numerically by the tests named:
//! - **Quaternions** `q = (α, β, γ, δ)` store the vector part first and the scalar `δ` last; `|q| = 1` is a constraint
//!   (Eq. 20) kept by Lagrange multipliers, and its drift is reported, never hidden by renormalising.
//! - **`R(q)` (Eq. 21) maps world to body**: a world point `r` has body coordinates `R (r − r_i)`, and a body point
//!   `s` sits at `r_i + Rᵀ s`. The body-frame spin is `(ω_b, 0) = 2 W(q) q̇` (Eq. 24), the world-frame spin
//!   `ω_w = Rᵀ ω_b`, and `Ṙᵀ R = [ω_w]×` (finite differences in `tests/ellipsoid_gradients.rs`).
//! - **Inertia (Eq. 4)**: `I = m/(2κ) diag(B² + C², C² + A², A² + B²)`, a uniform ellipsoid's for `κ = 5/2`. The
//!   rotational mass matrix `M(q) = 4 Wᵀ Ĩ W` with `Ĩ = diag(I₁, I₂, I₃, Tr I)` is inverted in closed form, since
//!   `Wᵀ W = |q|² 1` gives `M⁻¹ = Wᵀ Ĩ⁻¹ W / (4|q|⁴)`.
//! - **Contact potential (Eqs. 8–10)** in an equivalent cheaper form ([`potential`]): with `Σ_i = Rᵢᵀ diag(A², B², C²) Rᵢ`,
//!   `G = Σ_i + Σ_j` and `Δ = r_i − r_j`, the Gaussian overlap is
//!   `U_C = U0 m_i m_j (κ/π)^{3/2} det(G)^{−1/2} exp(−κ Δᵀ G⁻¹ Δ)`, with `∂U_C/∂Δ = −2κ U_C G⁻¹ Δ` and
//!   `∂ln U_C/∂G = −½ G⁻¹ + κ G⁻¹ΔΔᵀG⁻¹` chained through `R(q)`; every gradient is checked by central differences.
//! - **Calibration (Eqs. 11–14)** ([`calibration`]): Eq. 11's `U0` puts the two-sphere minimum of `U_C + U_G` at
//!   contact, where `U_C/|U_G| = 1/(2κλ)`; Eq. 14, `exp(κλ)/(κλ) = β v² (R_k + R_l)/(G m_k)` (k the smallest, l the
//!   largest fragment; ellipsoids by their equivalent radius `(ABC)^{1/3}`), is solved by Newton on `x = κλ > 1`, and
//!   a scene without a root `κ > 3/2` is refused.
//! - **Eq. 35 as extracted is wrong**: differentiating `q·q̇ = 0` gives
//!   `qᵀ M⁻¹ ṗ = qᵀ M⁻¹ Ṁ M⁻¹ p − pᵀ M⁻² p` (the last term is `|q̇|²`). [`equations`] solves Eq. 36 as the paper does
//!   and is tested against the equivalent closed form `ṗ = g − λ q`, `λ = (qᵀ M⁻¹ g − c)/(qᵀ M⁻¹ q)`.
//! - **Dissipation (Eqs. 40–41)** in closed form ([`dissipation`]): with the product-Gaussian centre
//!   `r_ij = r_i + Σ_i G⁻¹ (r_j − r_i)`, its covariance `P = Σ_i G⁻¹ Σ_j`, `w = ω_w,i − ω_w,j` and the centre's relative
//!   velocity `v0`, `F_ij = −F0 U_C [(|w|² Tr P − wᵀ P w)/(2κ) + |v0|²]`. `F` vanishes for a common rigid motion and
//!   conserves both momenta; `dH/dt = 2F`, integrated as one more state component so the energy residual
//!   `H − H0 − 2∫F dt` can be checked.

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
