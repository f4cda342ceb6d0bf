//! Point wall (Richardson11 §2.2; derivations in the docs of `geometry::walls`: a cylinder with zero radius and length,
//! or a ring of zero radius). A sphere of radius s touches it when `|p| = s`: the particle–particle quadratic.

use super::roots::quadratic;
use crate::math::Vec3;

/// Distance from `p` to the point and the unit normal towards `p` (+z when `p` is the point itself).
pub fn nearest(p: &Vec3) -> (f64, Vec3) {
    let r = p.norm();
    if r > 0.0 { (r, p / r) } else { (0.0, Vec3::z()) }
}

/// Earliest t in (0, t_max] at which `|p + d t| = s` with the distance decreasing (the smaller root).
pub fn toi(p: &Vec3, d: &Vec3, s: f64, t_max: f64) -> Option<f64> {
    let b = p.dot(d);
    if b >= 0.0 {
        return None;
    }
    let [t, _] = quadratic(d.norm_squared(), 2.0 * b, p.norm_squared() - s * s);
    t.filter(|&t| t > 0.0 && t <= t_max)
}
