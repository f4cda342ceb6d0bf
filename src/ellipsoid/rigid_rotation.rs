//! The best-fit rigid rotation of a set of bodies, and how far their motion is from it.
//!
//! About the centre of mass, the rigid motion that carries the same angular momentum `L` is
//! `v = V + ω × (r − R_cm)` with every body spinning at `ω = I_tot⁻¹ L`, where `I_tot` is the inertia tensor
//! of the ensemble (orbital part plus each body's own tensor). It is the projection of the actual motion onto
//! rigid motions in the kinetic-energy metric, so the kinetic energy splits exactly as
//! `K = ½ ωᵀ I_tot ω + K_rel`; `K_rel / K` measures how far the ensemble is from moving as one rigid body
//! (the rigidity criterion of the target builder).

use crate::ellipsoid::body::Body;
use crate::ellipsoid::quaternion::rotation_matrix;
use crate::math::{Mat3, Vec3};

/// The best-fit rigid rotation of an ensemble.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidFit {
    /// Total mass (kg).
    pub mass: f64,
    /// Centre of mass (m).
    pub centre_of_mass: Vec3,
    /// Centre-of-mass velocity (m/s).
    pub velocity: Vec3,
    /// Angular momentum about the centre of mass, orbital + spin (kg m² s⁻¹).
    pub angular_momentum: Vec3,
    /// Inertia tensor about the centre of mass, orbital + spin (kg m²).
    pub inertia: Mat3,
    /// Angular velocity of the best-fit rigid rotation (rad/s, world frame).
    pub omega: Vec3,
    /// Kinetic energy in the centre-of-mass frame (J).
    pub kinetic: f64,
    /// Kinetic energy of the motion relative to the rigid rotation (J).
    pub kinetic_relative: f64,
}

impl RigidFit {
    /// `K_rel / K` (0 for an exactly rigid motion; 0 when nothing moves).
    pub fn non_rigid_fraction(&self) -> f64 {
        if self.kinetic > 0.0 {
            self.kinetic_relative / self.kinetic
        } else {
            0.0
        }
    }

    /// Spin period of the rigid rotation (s); infinite when ω = 0.
    pub fn period(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.omega.norm()
    }
}

/// Fits the rigid rotation to `bodies` whose principal moments are `moments` (kg m²).
pub fn fit_rigid_rotation(bodies: &[Body], moments: &[Vec3]) -> RigidFit {
    let mass: f64 = bodies.iter().map(|b| b.shape.mass).sum();
    let centre_of_mass = bodies.iter().map(|b| b.position * b.shape.mass).sum::<Vec3>() / mass;
    let velocity = bodies.iter().map(|b| b.velocity * b.shape.mass).sum::<Vec3>() / mass;
    let mut inertia = Mat3::zeros();
    let mut angular_momentum = Vec3::zeros();
    let mut kinetic = 0.0;
    // Per body: offset, relative velocity, world inertia tensor and world spin.
    let parts: Vec<(Vec3, Vec3, Mat3, Vec3)> = bodies
        .iter()
        .zip(moments)
        .map(|(b, i)| {
            let rot = rotation_matrix(&b.quaternion);
            let tensor = rot.transpose() * Mat3::from_diagonal(i) * rot;
            (
                b.position - centre_of_mass,
                b.velocity - velocity,
                tensor,
                rot.transpose() * b.spin_body,
            )
        })
        .collect();
    for ((d, v, tensor, w), b) in parts.iter().zip(bodies) {
        let m = b.shape.mass;
        inertia += m * (Mat3::identity() * d.norm_squared() - d * d.transpose()) + tensor;
        angular_momentum += m * d.cross(v) + tensor * w;
        kinetic += 0.5 * m * v.norm_squared() + 0.5 * w.dot(&(tensor * w));
    }
    let omega = inertia
        .try_inverse()
        .map_or(Vec3::zeros(), |inv| inv * angular_momentum);
    let kinetic_relative = parts
        .iter()
        .zip(bodies)
        .map(|((d, v, tensor, w), b)| {
            let dv = v - omega.cross(d);
            let dw = w - omega;
            0.5 * b.shape.mass * dv.norm_squared() + 0.5 * dw.dot(&(tensor * dw))
        })
        .sum();
    RigidFit {
        mass,
        centre_of_mass,
        velocity,
        angular_momentum,
        inertia,
        omega,
        kinetic,
        kinetic_relative,
    }
}
