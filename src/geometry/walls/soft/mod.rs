//! Walls for soft-sphere contact (Zhang17 §2.1: a wall touches a particle through the same
//! spring–dashpot–slider law as a particle pair, with the wall as an infinitely massive partner).
//!
//! A wall reports, for a sphere of centre `c` and radius `r` at time `t`, the contact geometry
//! ([`WallTouch`]): the unit normal from the sphere's centre towards the wall, the overlap, and the velocity and
//! spin of the wall's surface at the contact point. Walls may oscillate sinusoidally (the [`Oscillation`] law of
//! both granular engines, for shaking); a cylinder ([`cylinder`]) may also spin about its axis (a drum).

pub mod cylinder;
pub mod touch;

pub use super::motion::Oscillation;
use crate::math::Vec3;
pub use cylinder::Cylinder;
pub use touch::WallTouch;
use touch::motion;

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

/// A wall of any kind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Wall {
    /// An infinite plane.
    Plane(Plane),
    /// A spherical container (contact on its inner surface).
    Sphere(SphereContainer),
    /// A cylinder, infinite or finite, touched from inside or outside ([`cylinder`]).
    Cylinder(Cylinder),
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
            wall_spin: Vec3::zeros(),
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
            wall_spin: Vec3::zeros(),
        })
    }
}

impl Wall {
    /// Contact of a sphere with this wall at time `t`, if any.
    pub fn touch(&self, centre: &Vec3, radius: f64, t: f64) -> Option<WallTouch> {
        match self {
            Wall::Plane(p) => p.touch(centre, radius, t),
            Wall::Sphere(s) => s.touch(centre, radius, t),
            Wall::Cylinder(c) => c.touch(centre, radius, t),
        }
    }

    /// The wall's reference point at rest (m): a plane's point, a sphere's or cylinder's centre.
    pub fn anchor(&self) -> Vec3 {
        match self {
            Wall::Plane(p) => p.point,
            Wall::Sphere(s) => s.centre,
            Wall::Cylinder(c) => c.centre,
        }
    }
}
