//! What a soft-sphere wall reports of a sphere touching it ([`WallTouch`]), and the displacement and velocity of a
//! wall's oscillation at a time, which every soft wall takes.

use super::super::motion::Oscillation;
use crate::math::Vec3;

/// Where a sphere touches a wall.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallTouch {
    /// Unit normal from the sphere's centre towards the wall (the pair law's `n̂`, Zhang17 Eq. 1).
    pub normal: Vec3,
    /// Overlap `x` (m, > 0).
    pub overlap: f64,
    /// Velocity of the wall's surface at the contact point (m/s).
    pub wall_velocity: Vec3,
    /// Angular velocity of the wall (rad/s): the partner's spin in the twisting and rolling laws (Zhang17 Eqs. 3–10);
    /// zero but for a spinning cylinder.
    pub wall_spin: Vec3,
}

/// The displacement (m) and velocity (m/s) of an optionally oscillating wall at time `t` (s).
pub(crate) fn motion(osc: &Option<Oscillation>, t: f64) -> (Vec3, Vec3) {
    match osc {
        Some(o) => (o.displacement(t), o.velocity(t)),
        None => (Vec3::zeros(), Vec3::zeros()),
    }
}
