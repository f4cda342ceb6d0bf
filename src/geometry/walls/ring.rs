//! Thin ring wall of radius R in the wall frame's z = 0 plane, centred on the origin (Richardson11 §2.2, ≈Eqs. 13–21
//! and 25; derivations in the docs of `geometry::walls`, "Ring"). It is also the rim of a disk and the end of a finite
//! cylinder.
//!
//! A sphere of radius s touches the ring when its centre is on the torus of tube radius s about it. With
//! `G(t) = α t² + β t + γ`, α = D·D, β = 2 P·D, γ = |P|² − s² − R², the torus is the zero set of the quartic
//! `Q(t) = G² + 4R²(z(t)² − s²)` (from `(|p|² + R² − s²)² = 4R²(x² + y²)`). `Q` factors as `(d_near² − s²)(d_far² −
//! s²)` with the distances to the nearest and the farthest point of the ring, so the first sign change of `Q` from
//! outside is the first contact. The real roots in the step are isolated by [`super::roots::real_roots_in`] (an
//! equally robust alternative to the paper's Laguerre iteration). Special cases first: R = 0 is a point; a centre on
//! the axis moving along it keeps `Q ≥ 0` (a double root), so it is solved as `z² = s² − R²` directly.

use super::point;
use super::roots::{quadratic, real_roots_in};
use crate::math::Vec3;

/// Distance from `p` to the ring and the unit normal from the nearest ring point towards `p` (Eq. 25). On the axis
/// every ring point is nearest; the one on +x is used.
pub fn nearest(p: &Vec3, radius: f64) -> (f64, Vec3) {
    let rho = (p.x * p.x + p.y * p.y).sqrt();
    let q = if rho > 0.0 {
        Vec3::new(radius * p.x / rho, radius * p.y / rho, 0.0)
    } else {
        Vec3::new(radius, 0.0, 0.0)
    };
    let v = p - q;
    let r = v.norm();
    if r > 0.0 { (r, v / r) } else { (0.0, Vec3::z()) }
}

/// Squared distance to the ring minus s², the exact "gap" function used to polish a quartic root.
fn gap(p: &Vec3, radius: f64, s: f64) -> f64 {
    let rho = (p.x * p.x + p.y * p.y).sqrt();
    (rho - radius) * (rho - radius) + p.z * p.z - s * s
}

/// Earliest t in (0, t_max] at which a sphere of radius `s` at `p + d t` first touches the ring from outside.
pub fn toi(p: &Vec3, d: &Vec3, s: f64, t_max: f64, radius: f64) -> Option<f64> {
    if radius == 0.0 {
        return point::toi(p, d, s, t_max);
    }
    if p.x == 0.0 && p.y == 0.0 && d.x == 0.0 && d.y == 0.0 {
        // On the axis, moving along it: distance² = z² + R², contact at z² = s² − R² (only if s > R).
        let h2 = s * s - radius * radius;
        if h2 <= 0.0 || p.z * d.z >= 0.0 {
            return None;
        }
        let [t, _] = quadratic(d.z * d.z, 2.0 * p.z * d.z, p.z * p.z - h2);
        return t.filter(|&t| t > 0.0 && t <= t_max);
    }
    let alpha = d.norm_squared();
    if alpha == 0.0 {
        return None;
    }
    let beta = 2.0 * p.dot(d);
    let gamma = p.norm_squared() - s * s - radius * radius;
    let r2 = radius * radius;
    let c = [
        gamma * gamma + 4.0 * r2 * (p.z * p.z - s * s),
        2.0 * beta * gamma + 8.0 * r2 * p.z * d.z,
        beta * beta + 2.0 * alpha * gamma + 4.0 * r2 * d.z * d.z,
        2.0 * alpha * beta,
        alpha * alpha,
    ];
    for t in real_roots_in(&c, 0.0, t_max) {
        if t <= 0.0 {
            continue;
        }
        // Entering the torus solid: the exact gap must be decreasing through zero. A root of the far factor
        // (inside the solid, s > R only) or a leaving root is skipped.
        let x = p + d * t;
        let (dist, n) = nearest(&x, radius);
        if (dist - s).abs() > 1e-6 * (s + radius) || d.dot(&n) >= 0.0 {
            continue;
        }
        return Some(polish(p, d, s, radius, t, t_max));
    }
    None
}

/// Refines a quartic root `t` on the exact gap function by bisection in a small bracket around it, so the contact
/// time has the accuracy of the distance, not of the quartic's coefficients.
fn polish(p: &Vec3, d: &Vec3, s: f64, radius: f64, t: f64, t_max: f64) -> f64 {
    let g = |t: f64| gap(&(p + d * t), radius, s);
    let scale = t_max.max(t).max(f64::MIN_POSITIVE);
    let mut w = 1e-12 * scale;
    for _ in 0..6 {
        let (a, b) = ((t - w).max(0.0), (t + w).min(t_max));
        let (ga, gb) = (g(a), g(b));
        if ga > 0.0 && gb <= 0.0 {
            let (mut a, mut b) = (a, b);
            for _ in 0..100 {
                let m = 0.5 * (a + b);
                if m <= a || m >= b {
                    break;
                }
                if g(m) > 0.0 {
                    a = m;
                } else {
                    b = m;
                }
            }
            return b;
        }
        w *= 100.0;
    }
    t
}
