//! Walls of infinite mass and prescribed motion ([`motion`]): the hard-sphere primitives with their times of impact
//! (Richardson11 §2.2), and ([`soft`]) the soft-sphere walls, which need an overlap and normal ([`soft::Wall`]).
//!
//! Each primitive ([`plane`], [`disk`], [`cylinder`], [`ring`], [`point`], [`line`]) is axisymmetric about its wall
//! frame's z axis and has `nearest` (distance and unit normal from the surface to the centre) and `toi` (first touch
//! from outside in `(0, t_max]` along a straight relative path); [`Wall::time_of_impact`] collides a touching,
//! approaching sphere at t = 0, so round-off never loses a collision. The paper's equations did not survive text
//! extraction: the forms are re-derived (Richardson 1994; Richardson et al. 2009, App. B; "≈Eq. n" guesses the
//! paper's numbering) and checked by brute force in `tests/hsdem_toi.rs`. Contact: `n̂` from contact point to centre,
//! `u = v + ω × (−s n̂) − v_wall`. Derivations: plane (≈Eq. 9) `t = (±s − ρ⊥)/v⊥`; disk, a plane hit inside `R`
//! else the rim ring; cylinder (≈Eqs. 10–12) `v⊥² t² + 2(ρ⊥·v⊥) t + ρ⊥² − (R_c ∓ s)² = 0` in the axial-free
//! components; ring (≈Eqs. 13–21, 25) the centre meets the torus `(|p|² + R² − s²)² = 4R²(p_x² + p_y²)`, along
//! `p = P + D t` the quartic `a₄ = α²`, `a₃ = 2αβ`, `a₂ = β² + 2αγ + 4R²D_z²`, `a₁ = 2βγ + 8R²P_zD_z`,
//! `a₀ = γ² + 4R²(P_z² − s²)` (`α = D·D`, `β = 2 P·D`, `γ = |P|² − s² − R²`), smallest positive root ([`roots`]).

pub mod cylinder;
pub mod disk;
pub mod line;
pub mod motion;
pub mod plane;
pub mod point;
pub mod ring;
pub mod roots;
pub mod soft;
pub mod surface;

use crate::math::Vec3;
pub use motion::{Oscillation, WallMotion};

/// A sphere whose gap to a surface is at most this fraction of its radius counts as touching.
pub const TOUCH_TOLERANCE: f64 = 1e-12;

/// The geometric primitive of a wall (sizes in metres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// Infinite thin plane through the origin, normal to the axis; both faces are walls.
    Plane,
    /// Thin disk of the given radius (m), normal to the axis.
    Disk {
        /// Disk radius (m), > 0.
        radius: f64,
    },
    /// Open cylinder about the axis.
    Cylinder {
        /// Cylinder radius (m), > 0.
        radius: f64,
        /// Length (m) along the axis, centred on the origin; `None` = infinite.
        length: Option<f64>,
    },
    /// Thin ring in the plane normal to the axis.
    Ring {
        /// Ring radius (m), > 0.
        radius: f64,
    },
    /// A single point (the origin).
    Point,
    /// A line along the axis.
    Line {
        /// Length (m), centred on the origin; `None` = infinite.
        length: Option<f64>,
    },
}

impl Shape {
    /// The name used in scene files.
    pub fn name(&self) -> &'static str {
        match self {
            Shape::Plane => "plane",
            Shape::Disk { .. } => "disk",
            Shape::Cylinder { .. } => "cylinder",
            Shape::Ring { .. } => "ring",
            Shape::Point => "point",
            Shape::Line { .. } => "line",
        }
    }

    /// Distance from `p` (wall frame) to the surface and the unit normal from the nearest point towards `p`.
    pub fn nearest(&self, p: &Vec3) -> (f64, Vec3) {
        match *self {
            Shape::Plane => plane::nearest(p),
            Shape::Disk { radius } => disk::nearest(p, radius),
            Shape::Cylinder { radius, length } => cylinder::nearest(p, radius, length),
            Shape::Ring { radius } => ring::nearest(p, radius),
            Shape::Point => point::nearest(p),
            Shape::Line { length } => line::nearest(p, length),
        }
    }

    /// Distance from `p` (wall frame) to the surface: the distance of [`Shape::nearest`] without its normal (a
    /// neighbour list asks this of every wall at every re-listing, and the normal costs divisions).
    pub fn distance(&self, p: &Vec3) -> f64 {
        let rho = || (p.x * p.x + p.y * p.y).sqrt();
        // √(a² + b²) without the library's `hypot` (no over- or underflow at the sizes of walls and particles).
        let len = |a: f64, b: f64| if b == 0.0 { a.abs() } else { (a * a + b * b).sqrt() };
        // Axial distance beyond a finite length.
        let beyond = |length: Option<f64>| length.map_or(0.0, |l| (p.z.abs() - 0.5 * l).max(0.0));
        match *self {
            Shape::Plane => p.z.abs(),
            Shape::Disk { radius } => {
                let r = rho();
                if r <= radius { p.z.abs() } else { len(r - radius, p.z) }
            }
            Shape::Cylinder { radius, length } => len(rho() - radius, beyond(length)),
            Shape::Ring { radius } => len(rho() - radius, p.z),
            Shape::Point => p.norm(),
            Shape::Line { length } => len(rho(), beyond(length)),
        }
    }

    /// First time in `(0, t_max]` at which a sphere of radius `s` at `p + d t` (wall frame) touches the surface
    /// coming from outside it.
    pub fn toi(&self, p: &Vec3, d: &Vec3, s: f64, t_max: f64) -> Option<f64> {
        match *self {
            Shape::Plane => plane::toi(p, d, s, t_max),
            Shape::Disk { radius } => disk::toi(p, d, s, t_max, radius),
            Shape::Cylinder { radius, length } => cylinder::toi(p, d, s, t_max, radius, length),
            Shape::Ring { radius } => ring::toi(p, d, s, t_max, radius),
            Shape::Point => point::toi(p, d, s, t_max),
            Shape::Line { length } => line::toi(p, d, s, t_max, length),
        }
    }
}

/// A wall: a primitive placed in the world, its motion and its collision properties.
#[derive(Debug, Clone, PartialEq)]
pub struct Wall {
    /// The primitive.
    pub shape: Shape,
    /// Reference point at t = 0 (m).
    pub origin: Vec3,
    /// Unit axis (the plane/disk normal, the cylinder/line/ring axis).
    pub axis: Vec3,
    /// First unit vector normal to the axis (the wall frame's x).
    e1: Vec3,
    /// Second unit vector normal to the axis (the wall frame's y = axis × e1).
    e2: Vec3,
    /// Prescribed motion.
    pub motion: WallMotion,
    /// Normal restitution override (`None`: the particle's).
    pub eps_n: Option<f64>,
    /// Tangential restitution override (`None`: the particle's).
    pub eps_t: Option<f64>,
    /// Particles that touch it stay attached and move with it.
    pub sticky: bool,
    /// Particles that touch it are removed (and counted).
    pub absorbing: bool,
}

impl Wall {
    /// A static wall with the particles' restitution. `axis` need not be normalised but must not vanish.
    pub fn new(shape: Shape, origin: Vec3, axis: Vec3) -> Wall {
        let a = axis.normalize();
        // A helper axis far from `a` gives a well-conditioned frame.
        let helper = if a.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() };
        let e1 = (helper - a * a.dot(&helper)).normalize();
        let e2 = a.cross(&e1);
        Wall {
            shape,
            origin,
            axis: a,
            e1,
            e2,
            motion: WallMotion::default(),
            eps_n: None,
            eps_t: None,
            sticky: false,
            absorbing: false,
        }
    }

    /// World vector → wall-frame components.
    pub fn to_local(&self, v: &Vec3) -> Vec3 {
        Vec3::new(v.dot(&self.e1), v.dot(&self.e2), v.dot(&self.axis))
    }

    /// Wall-frame components → world vector.
    pub fn to_world(&self, v: &Vec3) -> Vec3 {
        self.e1 * v.x + self.e2 * v.y + self.axis * v.z
    }

    /// The reference point at time `t` (m).
    pub fn origin_at(&self, t: f64) -> Vec3 {
        self.origin + self.motion.displacement(t)
    }

    /// Distance (m) from the world point `r` to the surface when the reference point is at `origin_now`, and the
    /// world unit normal from the nearest surface point towards `r`.
    pub fn nearest(&self, origin_now: &Vec3, r: &Vec3) -> (f64, Vec3) {
        let (dist, n) = self.shape.nearest(&self.to_local(&(r - origin_now)));
        (dist, self.to_world(&n))
    }

    /// Distance (m) from the world point `r` to the surface when the reference point is at `origin_now` (that of
    /// [`Wall::nearest`], without the normal).
    pub fn distance(&self, origin_now: &Vec3, r: &Vec3) -> f64 {
        self.shape.distance(&self.to_local(&(r - origin_now)))
    }

    /// Time (s, in `[0, t_max]`) until a sphere of radius `s` at `r` with velocity `v` touches the wall whose
    /// reference point is now at `origin_now` and moves with `wall_velocity`; `None` if not within `t_max`.
    /// A sphere already touching (gap ≤ [`TOUCH_TOLERANCE`]·s) or overlapping and approaching gives 0.
    pub fn time_of_impact(
        &self,
        origin_now: &Vec3,
        wall_velocity: &Vec3,
        r: &Vec3,
        v: &Vec3,
        s: f64,
        t_max: f64,
    ) -> Option<f64> {
        let p = self.to_local(&(r - origin_now));
        let d = self.to_local(&(v - wall_velocity));
        let (dist, n) = self.shape.nearest(&p);
        // Touching or overlapping: collide now if approaching; otherwise it is leaving this contact, and a later
        // entry (e.g. the far side of a cylinder) is still found below.
        if dist - s <= TOUCH_TOLERANCE * s && d.dot(&n) < 0.0 {
            return Some(0.0);
        }
        self.shape.toi(&p, &d, s, t_max)
    }

    /// Velocity (m/s) of the wall's material point at world position `x` for a step in which the reference point
    /// is at `origin_now` and translates with `wall_velocity`: translation plus the spin `Ω â × ρ`.
    pub fn surface_velocity(&self, origin_now: &Vec3, wall_velocity: &Vec3, x: &Vec3) -> Vec3 {
        wall_velocity + self.axis.cross(&(x - origin_now)) * self.motion.spin
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `distance` is the distance of `nearest` for every primitive, inside and outside, on and off the axis.
    #[test]
    fn distance_matches_nearest() {
        let shapes = [
            Shape::Plane,
            Shape::Disk { radius: 0.7 },
            Shape::Cylinder {
                radius: 0.8,
                length: None,
            },
            Shape::Cylinder {
                radius: 0.8,
                length: Some(1.3),
            },
            Shape::Ring { radius: 0.6 },
            Shape::Point,
            Shape::Line { length: None },
            Shape::Line { length: Some(0.9) },
        ];
        let mut seed = 99u64;
        let mut rnd = move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
        };
        for shape in shapes {
            let mut points: Vec<Vec3> = (0..500).map(|_| Vec3::new(rnd(), rnd(), rnd())).collect();
            points.extend([Vec3::zeros(), Vec3::new(0.0, 0.0, 1.5), Vec3::new(0.6, 0.0, 0.0)]);
            for p in points {
                let (d, _) = shape.nearest(&p);
                let e = shape.distance(&p);
                assert!((d - e).abs() <= 1e-14 * (1.0 + d), "{shape:?} at {p:?}: {e} vs {d}");
            }
        }
    }
}
