//! A soft sphere's state (Zhang17 §2.1: particles are rigid spheres that may overlap slightly; their
//! translation and spin are integrated with Eq. 1's forces and torques).

use crate::math::Vec3;

/// One sphere: mass (kg), radius (m), centre position (m), velocity (m/s) and spin (rad/s), world frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Particle {
    /// Mass (kg, > 0).
    pub mass: f64,
    /// Radius (m, > 0).
    pub radius: f64,
    /// Centre position (m).
    pub position: Vec3,
    /// Centre velocity (m/s).
    pub velocity: Vec3,
    /// Spin (angular velocity, rad/s).
    pub spin: Vec3,
}

impl Particle {
    /// Moment of inertia of a uniform sphere, `2/5 m r²` (kg m²).
    ///
    /// ```
    /// use rubblepile::granular::soft::particle::Particle;
    /// use rubblepile::math::Vec3;
    /// let p = Particle { mass: 5.0, radius: 2.0, position: Vec3::zeros(), velocity: Vec3::zeros(), spin: Vec3::zeros() };
    /// assert_eq!(p.inertia(), 8.0);
    /// ```
    pub fn inertia(&self) -> f64 {
        0.4 * self.mass * self.radius * self.radius
    }

    /// Translational plus rotational kinetic energy (J).
    pub fn kinetic_energy(&self) -> f64 {
        0.5 * self.mass * self.velocity.norm_squared() + 0.5 * self.inertia() * self.spin.norm_squared()
    }

    /// Whether every component is finite.
    pub fn is_finite(&self) -> bool {
        [self.position, self.velocity, self.spin]
            .iter()
            .all(|v| v.iter().all(|x| x.is_finite()))
    }
}
