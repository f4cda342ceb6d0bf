//! Line wall along the wall axis, infinite or a segment of length L centred on the origin (Richardson11 §2.2;
//! derivations in the docs of `geometry::walls`: a cylinder of zero radius, which has no inner face; a segment's ends
//! are points).

use super::point;
use super::roots::quadratic;
use crate::math::Vec3;

/// Distance from `p` to the line (segment when `length` is given) and the unit normal towards `p`.
pub fn nearest(p: &Vec3, length: Option<f64>) -> (f64, Vec3) {
    let z = length.map_or(p.z, |l| p.z.clamp(-0.5 * l, 0.5 * l));
    let v = p - Vec3::new(0.0, 0.0, z);
    let r = v.norm();
    if r > 0.0 { (r, v / r) } else { (0.0, Vec3::x()) }
}

/// Earliest t in (0, t_max] at which a sphere of radius `s` at `p + d t` reaches the line: the radial quadratic
/// `ρ(t) = s` (smaller root, ρ decreasing), accepted for a segment only if `|z| ≤ L/2` there; then the ends.
pub fn toi(p: &Vec3, d: &Vec3, s: f64, t_max: f64, length: Option<f64>) -> Option<f64> {
    let mut best: Option<f64> = None;
    let mut keep = |t: f64| {
        if t > 0.0 && t <= t_max && best.is_none_or(|b| t < b) {
            best = Some(t);
        }
    };
    let a = d.x * d.x + d.y * d.y;
    let b = 2.0 * (p.x * d.x + p.y * d.y);
    if b < 0.0 {
        let [t, _] = quadratic(a, b, p.x * p.x + p.y * p.y - s * s);
        if let Some(t) = t
            && length.is_none_or(|l| (p.z + d.z * t).abs() <= 0.5 * l)
        {
            keep(t);
        }
    }
    if let Some(l) = length {
        for end in [0.5 * l, -0.5 * l] {
            let q = p - Vec3::new(0.0, 0.0, end);
            if let Some(t) = point::toi(&q, d, s, t_max) {
                keep(t);
            }
        }
    }
    best
}
