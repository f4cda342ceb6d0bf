//! Collision resolution of rough spheres with normal and tangential restitution (Richardson11 §2.1, ≈Eqs. 4–8).
//!
//! With n̂ from sphere 1 to 2, the contact-point velocity `u = (v₂ + R₂ n̂×ω₂) − (v₁ + R₁ ω₁×n̂)` acts only if
//! `u·n̂ < 0`. With `μ = m₁m₂/M` and `β = 1/(1 + μ(R₁²/I₁ + R₂²/I₂))` (2/7 for uniform spheres) the impulses are
//! `p = (1+ε_n) u_n + β(1−ε_t) u_t`, `q = μβ(1−ε_t)(n̂ × u)`: `v₁ += (m₂/M) p`, `v₂ −= (m₁/M) p`, `ω₁ += (R₁/I₁) q`,
//! `ω₂ += (R₂/I₂) q`; ε_n ∈ [0, 1], ε_t ∈ [−1, 1] (1 smooth, −1 reversed). Both momenta are conserved exactly; the
//! energy changes by `−½ μ (1−ε_n²) u_n² − ½ μβ (1−ε_t²) |u_t|²` (`tests/hsdem_collisions.rs`). Against a wall
//! (infinite mass): `v −= (1 + ε_n) u_n + (2/7)(1 − ε_t) u_t`, `ω −= (5/7)(1 − ε_t)(R × u)/s²`; a wall's ε override
//! the particle's, sticky walls hold, absorbing ones remove.
//!
//! Inelastic-collapse guard: a collision approaching slower than `collapse_speed` is made elastic, so a pile at rest
//! under gravity bounces at speeds of order g·dt instead of making infinitely many ever smaller bounces in finite
//! time, and the events per step stay bounded.

use crate::math::Vec3;

/// Restitution used for one collision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Restitution {
    /// Normal coefficient ε_n ∈ [0, 1].
    pub eps_n: f64,
    /// Tangential coefficient ε_t ∈ [−1, 1].
    pub eps_t: f64,
}

/// One side of a collision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    /// Mass (kg).
    pub mass: f64,
    /// Radius (m).
    pub radius: f64,
    /// Moment of inertia (kg m²).
    pub inertia: f64,
    /// Centre position (m).
    pub position: Vec3,
    /// Velocity (m/s).
    pub velocity: Vec3,
    /// Spin (rad/s).
    pub spin: Vec3,
}

/// What a collision did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Outcome {
    /// Whether the bodies were approaching (otherwise nothing changed).
    pub applied: bool,
    /// Whether the collapse guard made it elastic.
    pub guarded: bool,
}

/// The restitution a contact with normal relative velocity `un` (m/s, negative when approaching) gets: `None`
/// when the surfaces separate (no collision); elastic, and flagged as guarded, when the approach is slower than
/// `collapse_speed` (the inelastic-collapse guard); `r` otherwise.
fn effective_restitution(un: f64, r: Restitution, collapse_speed: f64) -> Option<(Restitution, bool)> {
    if un >= 0.0 {
        return None;
    }
    let guarded = -un < collapse_speed;
    Some((
        if guarded {
            Restitution { eps_n: 1.0, eps_t: 1.0 }
        } else {
            r
        },
        guarded,
    ))
}

/// Resolves a collision between two free spheres in contact (velocities and spins updated in place).
pub fn resolve_pair(b1: &mut Body, b2: &mut Body, r: Restitution, collapse_speed: f64) -> Outcome {
    let n = (b2.position - b1.position).normalize();
    // The contact-point velocity of body 2 relative to body 1.
    let u = (b2.velocity + b2.spin.cross(&(-n * b2.radius))) - (b1.velocity + b1.spin.cross(&(n * b1.radius)));
    let un = u.dot(&n);
    let Some((r, guarded)) = effective_restitution(un, r, collapse_speed) else {
        return Outcome::default();
    };
    let u_n = n * un;
    let u_t = u - u_n;
    let m = b1.mass + b2.mass;
    let mu = b1.mass * b2.mass / m;
    let beta = 1.0 / (1.0 + mu * (b1.radius * b1.radius / b1.inertia + b2.radius * b2.radius / b2.inertia));
    let p = u_n * (1.0 + r.eps_n) + u_t * (beta * (1.0 - r.eps_t));
    let q = n.cross(&u) * (mu * beta * (1.0 - r.eps_t));
    b1.velocity += p * (b2.mass / m);
    b2.velocity -= p * (b1.mass / m);
    b1.spin += q * (b1.radius / b1.inertia);
    b2.spin += q * (b2.radius / b2.inertia);
    Outcome { applied: true, guarded }
}

/// Resolves a collision of a sphere with an infinitely massive surface (a wall, or a particle stuck to one):
/// `n` is the unit normal from the contact point to the sphere's centre and `surface_velocity` the surface's
/// velocity at the contact point. `u = v + ω × R − v_wall` with `R = −s n̂`; then
/// `v' = v − (1+ε_n) u_n − β(1−ε_t) u_t` and `ω' = ω − (mβ/I)(1−ε_t) (R × u)` with `β = 1/(1 + m s²/I)`
/// (= 2/7 and `mβ/I = (5/7)/s²` for a uniform sphere).
pub fn resolve_wall(b: &mut Body, n: &Vec3, surface_velocity: &Vec3, r: Restitution, collapse_speed: f64) -> Outcome {
    let arm = -n * b.radius;
    let u = b.velocity + b.spin.cross(&arm) - surface_velocity;
    let un = u.dot(n);
    let Some((r, guarded)) = effective_restitution(un, r, collapse_speed) else {
        return Outcome::default();
    };
    let u_n = n * un;
    let u_t = u - u_n;
    let beta = 1.0 / (1.0 + b.mass * b.radius * b.radius / b.inertia);
    b.velocity -= u_n * (1.0 + r.eps_n) + u_t * (beta * (1.0 - r.eps_t));
    b.spin -= arm.cross(&u) * (b.mass * beta * (1.0 - r.eps_t) / b.inertia);
    Outcome { applied: true, guarded }
}
