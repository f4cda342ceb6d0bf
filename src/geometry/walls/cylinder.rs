//! Cylinder wall about the wall axis, radius R_c, infinite or of length L centred on the origin, open-ended
//! (Richardson11 §2.2, ≈Eqs. 10–12; derivations in the docs of `geometry::walls`, "Infinite cylinder", "Finite
//! cylinder"). Both faces are walls: from inside the sphere hits `ρ = R_c − s` (ρ increasing; the larger root), from
//! outside `ρ = R_c + s` (ρ decreasing; the smaller root). A finite cylinder accepts a side hit only where `|z| ≤ L/2`;
//! its ends are rings. The degenerate cases (R_c = 0: a line, L = 0: a ring) are mapped to those primitives by the
//! scene.

use super::ring;
use super::roots::quadratic;
use crate::math::Vec3;

/// Distance from `p` to the cylinder surface and the unit normal from the nearest point towards `p`.
pub fn nearest(p: &Vec3, radius: f64, length: Option<f64>) -> (f64, Vec3) {
    let rho = (p.x * p.x + p.y * p.y).sqrt();
    let (ex, ey) = if rho > 0.0 { (p.x / rho, p.y / rho) } else { (1.0, 0.0) };
    let z = length.map_or(p.z, |l| p.z.clamp(-0.5 * l, 0.5 * l));
    let q = Vec3::new(radius * ex, radius * ey, z);
    let v = p - q;
    let r = v.norm();
    if r > 0.0 {
        (r, v / r)
    } else {
        (0.0, Vec3::new(ex, ey, 0.0))
    }
}

/// Earliest t in (0, t_max] at which a sphere of radius `s` at `p + d t` first touches the cylinder.
pub fn toi(p: &Vec3, d: &Vec3, s: f64, t_max: f64, radius: f64, length: Option<f64>) -> Option<f64> {
    let mut best: Option<f64> = None;
    let within = |t: f64| length.is_none_or(|l| (p.z + d.z * t).abs() <= 0.5 * l);
    let a = d.x * d.x + d.y * d.y;
    let b = 2.0 * (p.x * d.x + p.y * d.y);
    let c = p.x * p.x + p.y * p.y;
    let mut candidates: [Option<f64>; 2] = [None, None];
    // Inner face (exists when the sphere fits inside): entering while ρ grows through R_c − s.
    let inner = radius - s;
    if inner > 0.0 {
        let [_, t] = quadratic(a, b, c - inner * inner);
        candidates[0] = t.filter(|&t| 2.0 * a * t + b > 0.0);
    }
    // Outer face: entering while ρ shrinks through R_c + s.
    let outer = radius + s;
    let [t, _] = quadratic(a, b, c - outer * outer);
    candidates[1] = t.filter(|&t| 2.0 * a * t + b < 0.0);
    for t in candidates.into_iter().flatten() {
        if t > 0.0 && t <= t_max && within(t) && best.is_none_or(|x| t < x) {
            best = Some(t);
        }
    }
    if let Some(l) = length {
        for end in [0.5 * l, -0.5 * l] {
            let q = p - Vec3::new(0.0, 0.0, end);
            if let Some(t) = ring::toi(&q, d, s, best.unwrap_or(t_max), radius)
                && best.is_none_or(|x| t < x)
            {
                best = Some(t);
            }
        }
    }
    best
}
