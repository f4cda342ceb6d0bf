//! Finite thin disk wall of radius R in the wall frame's z = 0 plane (Richardson11 §2.2; derivations in the docs of
//! `geometry::walls`, "Finite disk"): a plane hit accepted only inside the disk, else the rim (a ring).

use super::{plane, ring};
use crate::math::Vec3;

/// Distance from `p` to the (closed) disk and the unit normal from the nearest disk point towards `p`.
pub fn nearest(p: &Vec3, radius: f64) -> (f64, Vec3) {
    if p.x * p.x + p.y * p.y <= radius * radius {
        plane::nearest(p)
    } else {
        ring::nearest(p, radius)
    }
}

/// Earliest t in (0, t_max] at which a sphere of radius `s` at `p + d t` first touches the disk: the face hit if its
/// in-plane point lies within the disk, or the rim hit, whichever is first.
pub fn toi(p: &Vec3, d: &Vec3, s: f64, t_max: f64, radius: f64) -> Option<f64> {
    let face = plane::toi(p, d, s, t_max).filter(|&t| {
        let x = p + d * t;
        x.x * x.x + x.y * x.y <= radius * radius
    });
    let rim = ring::toi(p, d, s, face.unwrap_or(t_max), radius);
    match (face, rim) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}
