//! Infinite thin plane wall, two-sided (Richardson11 §2.2, ≈Eq. 9; derivations in the docs of `geometry::walls`,
//! "Infinite plane"). In the wall frame the plane is z = 0; a sphere of radius s touches it when |z| = s.

use crate::math::Vec3;

/// Distance from `p` to the plane and the unit normal from the nearest point towards `p` (+z on the plane).
pub fn nearest(p: &Vec3) -> (f64, Vec3) {
    let sign = if p.z < 0.0 { -1.0 } else { 1.0 };
    (p.z.abs(), Vec3::new(0.0, 0.0, sign))
}

/// Earliest t in (0, t_max] at which a sphere of radius `s` at `p + d t` reaches either face from outside:
/// upper face `t = (s − z)/v_z` (needs v_z < 0), lower face `t = (−s − z)/v_z` (needs v_z > 0).
pub fn toi(p: &Vec3, d: &Vec3, s: f64, t_max: f64) -> Option<f64> {
    let t = if p.z >= s && d.z < 0.0 {
        (s - p.z) / d.z
    } else if p.z <= -s && d.z > 0.0 {
        (-s - p.z) / d.z
    } else {
        return None;
    };
    (t > 0.0 && t <= t_max).then_some(t)
}
