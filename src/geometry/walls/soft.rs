//! Walls for soft-sphere contact (Zhang17 §2.1: a wall touches a particle through the same
//! spring–dashpot–slider law as a particle pair, with the wall as an infinitely massive partner).
//!
//! A wall reports, for a sphere of centre `c` and radius `r` at time `t`, the contact geometry
//! ([`WallTouch`]): the unit normal from the sphere's centre towards the wall, the overlap and the wall's
//! velocity at the contact point. Walls may oscillate sinusoidally ([`Oscillation`], for shaking).

use crate::math::Vec3;
use serde::{Deserialize, Serialize};

/// Sinusoidal rigid translation of a wall: offset `A sin(2π f t)` (m), velocity `2π f A cos(2π f t)` (m/s).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Oscillation {
    /// Amplitude vector `A` (m): direction and size of the displacement.
    pub amplitude: [f64; 3],
    /// Frequency `f` (Hz, > 0).
    pub frequency: f64,
}

impl Oscillation {
    /// Displacement of the wall at time `t` (s), in m.
    pub fn offset(&self, t: f64) -> Vec3 {
        Vec3::from(self.amplitude) * (std::f64::consts::TAU * self.frequency * t).sin()
    }

    /// Velocity of the wall at time `t` (s), in m/s.
    pub fn velocity(&self, t: f64) -> Vec3 {
        let w = std::f64::consts::TAU * self.frequency;
        Vec3::from(self.amplitude) * (w * (w * t).cos())
    }
}

/// Where a sphere touches a wall.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallTouch {
    /// Unit normal from the sphere's centre towards the wall (the pair law's `n̂`, Zhang17 Eq. 1).
    pub normal: Vec3,
    /// Overlap `x` (m, > 0).
    pub overlap: f64,
    /// Velocity of the wall's surface at the contact point (m/s).
    pub wall_velocity: Vec3,
}

/// An infinite plane through `point` whose unit `normal` points into the half-space the particles occupy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// A point on the plane at rest (m).
    pub point: Vec3,
    /// Unit normal towards the particles' side.
    pub normal: Vec3,
    /// Optional oscillation of the whole plane.
    pub oscillation: Option<Oscillation>,
}

/// The inside of a sphere of radius `radius` about `centre`: particles are kept inside it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereContainer {
    /// Centre at rest (m).
    pub centre: Vec3,
    /// Inner radius (m).
    pub radius: f64,
    /// Optional oscillation of the whole container.
    pub oscillation: Option<Oscillation>,
}

/// A wall of either kind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Wall {
    /// An infinite plane.
    Plane(Plane),
    /// A spherical container (contact on its inner surface).
    Sphere(SphereContainer),
}

fn motion(osc: &Option<Oscillation>, t: f64) -> (Vec3, Vec3) {
    match osc {
        Some(o) => (o.offset(t), o.velocity(t)),
        None => (Vec3::zeros(), Vec3::zeros()),
    }
}

impl Plane {
    /// Contact of a sphere (`centre`, `radius`) with the plane at time `t`, if they overlap.
    ///
    /// ```
    /// use rubblepile::geometry::walls::soft::Plane;
    /// use rubblepile::math::Vec3;
    /// let floor = Plane { point: Vec3::zeros(), normal: Vec3::z(), oscillation: None };
    /// let touch = floor.touch(&Vec3::new(0.0, 0.0, 0.99), 1.0, 0.0).unwrap();
    /// assert!((touch.overlap - 0.01).abs() < 1e-12 && touch.normal == -Vec3::z());
    /// ```
    pub fn touch(&self, centre: &Vec3, radius: f64, t: f64) -> Option<WallTouch> {
        let (offset, velocity) = motion(&self.oscillation, t);
        let distance = (centre - (self.point + offset)).dot(&self.normal);
        let overlap = radius - distance;
        (overlap > 0.0).then(|| WallTouch {
            normal: -self.normal,
            overlap,
            wall_velocity: velocity,
        })
    }
}

impl SphereContainer {
    /// Contact of a sphere (`centre`, `radius`) with the container's inner surface at time `t`.
    pub fn touch(&self, centre: &Vec3, radius: f64, t: f64) -> Option<WallTouch> {
        let (offset, velocity) = motion(&self.oscillation, t);
        let d = centre - (self.centre + offset);
        let distance = d.norm();
        let overlap = distance + radius - self.radius;
        (overlap > 0.0 && distance > 0.0).then(|| WallTouch {
            normal: d / distance,
            overlap,
            wall_velocity: velocity,
        })
    }
}

impl Wall {
    /// Contact of a sphere with this wall at time `t`, if any.
    pub fn touch(&self, centre: &Vec3, radius: f64, t: f64) -> Option<WallTouch> {
        match self {
            Wall::Plane(p) => p.touch(centre, radius, t),
            Wall::Sphere(s) => s.touch(centre, radius, t),
        }
    }
}
