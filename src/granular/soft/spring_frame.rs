//! Carrying spring histories along with the contact frame (Zhang17 §2.2.1–2.2.2: "we account for this motion
//! at every step by transforming δ_T according to the change in n̂"; our notes, "Springs follow the contact
//! frame").
//!
//! Each step, the tangential and rolling springs are rotated in two parts: first by the rotation that takes
//! the old normal to the new one along the shortest arc (the swing), then about the new normal by the mean
//! spin of the pair about the mean normal times the step (the twist). Both are rotations, so spring lengths
//! are unchanged; what is left of a normal component from rounding is then projected out. For a pair that
//! co-rotates rigidly the composition equals the pair's rotation to second order in the step, so the springs
//! stay fixed in the pair's frame (tested in `tests/ssdem_spring_frame.rs`).

use crate::math::Vec3;
use nalgebra::{Rotation3, Unit};

/// The rotation carrying the contact frame from normal `n_old` to `n_new` (unit vectors), with the pair's
/// mean spin `mean_spin` (rad/s) acting for `dt` (s) about the mean normal.
///
/// ```
/// use rubblepile::granular::soft::spring_frame::frame_rotation;
/// use rubblepile::math::Vec3;
/// let r = frame_rotation(&Vec3::x(), &Vec3::y(), &Vec3::zeros(), 0.0);
/// assert!((r * Vec3::x() - Vec3::y()).norm() < 1e-15);
/// ```
pub fn frame_rotation(n_old: &Vec3, n_new: &Vec3, mean_spin: &Vec3, dt: f64) -> Rotation3<f64> {
    // Shortest-arc rotation by atan2(|a × b|, a·b), which stays finite when rounding puts a·b above 1
    // (nalgebra's `rotation_between` takes acos of it).
    let axis = n_old.cross(n_new);
    let sin = axis.norm();
    let cos = n_old.dot(n_new);
    let swing = if sin > 1e-300 {
        Rotation3::from_axis_angle(&Unit::new_unchecked(axis / sin), sin.atan2(cos))
    } else if cos >= 0.0 {
        Rotation3::identity()
    } else {
        // Antiparallel normals (never in a real contact step): half a turn about any perpendicular axis.
        let other = if n_old.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() };
        Rotation3::from_axis_angle(&Unit::new_normalize(n_old.cross(&other)), std::f64::consts::PI)
    };
    let mean = n_old + n_new;
    let mean_normal = if mean.norm_squared() > 0.0 {
        mean.normalize()
    } else {
        *n_new
    };
    let angle = mean_spin.dot(&mean_normal) * dt;
    let twist = Rotation3::from_axis_angle(&Unit::new_unchecked(*n_new), angle);
    twist * swing
}

/// Rotates a tangential spring by `rotation` and removes any component along the new normal `n_new`.
pub fn carry(spring: &Vec3, rotation: &Rotation3<f64>, n_new: &Vec3) -> Vec3 {
    let s = rotation * spring;
    s - n_new * s.dot(n_new)
}
