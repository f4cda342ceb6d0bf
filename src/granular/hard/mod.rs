//! Hard-sphere discrete-element method after Richardson et al. (2011, Icarus 212, 427) ("Richardson11"):
//! rigid spheres with spin that collide instantaneously with normal and tangential restitution, walls made of
//! primitives ([`crate::geometry::walls`]), kick–drift–kick stepping with predicted collisions inside each drift.
//!
//! - [`particle`]: the sphere state;
//! - [`anchors`]: the cell grid of the neighbour list's anchors (re-listing one particle);
//! - [`certificates`]: pair certificates kept across steps (which pairs a drift start must predict);
//! - [`collision`]: collision resolution (particle–particle and particle–wall) and the inelastic-collapse guard;
//! - [`events`]: the priority queue of predicted collisions;
//! - [`stepper`]: the stepping and event loop;
//! - [`scene`]: the `kind = "hard-spheres"` scene file;
//! - [`run`]: the engine as the run driver sees it (`rubblepile run`).
//!
//! # Collisions
//!
//! **Prediction (≈Eqs. 1–3).** With `r = r_i − r_j`, `v = v_i − v_j` and `s = R_i + R_j`, two spheres touch when
//! `v² t² + 2(r·v) t + r² − s² = 0`, possible only while approaching (`r·v < 0`); the earliest root is computed in the
//! form `t = (r² − s²)/(−r·v + √((r·v)² − v²(r² − s²)))`, which does not cancel. A touching or overlapping pair that
//! approaches collides at once (`t ≤ 0` allowed), so round-off never loses a collision.
//!
//! **Resolution with spin (≈Eq. 4).** With the unit normal `n̂` from sphere 1 to sphere 2, the contact-point relative
//! velocity `u = (v₂ + R₂ n̂ × ω₂) − (v₁ + R₁ ω₁ × n̂)` is resolved only if `u·n̂ < 0`. Split `u` into normal `u_n` and
//! tangential `u_t` parts; with `μ = m₁m₂/M` and `β = 1/(1 + μ(R₁²/I₁ + R₂²/I₂))` (2/7 for uniform spheres) the
//! impulses are `p = (1 + ε_n) u_n + β(1 − ε_t) u_t` and `q = μβ(1 − ε_t) n̂ × u`, applied as `v₁ += (m₂/M) p`,
//! `v₂ −= (m₁/M) p`, `ω₁ += (R₁/I₁) q`, `ω₂ += (R₂/I₂) q`. `ε_n ∈ [0, 1]` (0 sticks), `ε_t ∈ [−1, 1]` (1 smooth,
//! −1 reverses the tangential motion); both momenta are conserved exactly, and the energy when `ε_n = 1`, `ε_t = ±1`.
//! Against a wall (infinite mass; see [`crate::geometry::walls`] for `u` there) the update is
//! `v −= (1 + ε_n) u_n + (2/7)(1 − ε_t) u_t`, `ω −= (5/7)(1 − ε_t)(R × u)/s²`; a wall's ε override the particle's,
//! a sticky wall holds the particle rigidly, an absorbing one removes it.
//!
//! **Stepping (§2.1).** Kick–drift–kick leapfrog with uniform gravity in the kicks only, so that drifts are straight
//! lines; within a drift the globally earliest predicted event is processed and only the particles it involved are
//! re-predicted, until the step ends. Since a uniform kick changes no relative velocity, pairs of free particles
//! keep certificates across steps and a drift start re-predicts only those that came due ([`certificates`]).

pub mod anchors;
pub mod certificates;
pub mod collision;
pub mod events;
pub mod particle;
pub mod run;
pub mod scene;
pub mod stepper;
