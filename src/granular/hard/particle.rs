//! A hard sphere's state (Richardson11 §2: rigid, uniform spheres with spin).

use crate::math::Vec3;

/// Where a particle stuck to a sticky wall sits: its offset from the wall's reference point in the wall frame at the
/// moment it stuck, and that moment (the wall's spin turns the offset afterwards).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Attachment {
    /// Index of the wall.
    pub wall: usize,
    /// Offset from the wall's reference point (m), wall-frame components, at `t_stuck`.
    pub offset: Vec3,
    /// Time it stuck (s).
    pub t_stuck: f64,
}

/// One sphere. The moment of inertia is that of a uniform sphere, `I = (2/5) m R²`.
#[derive(Debug, Clone, PartialEq)]
pub struct Particle {
    /// Identifier (its index in the scene, kept in the outputs after removals).
    pub id: usize,
    /// Mass (kg).
    pub mass: f64,
    /// Radius (m).
    pub radius: f64,
    /// Centre position (m) at the particle's own clock `t_local`.
    pub position: Vec3,
    /// Velocity (m/s).
    pub velocity: Vec3,
    /// Spin (rad/s), world frame.
    pub spin: Vec3,
    /// Normal coefficient of restitution ε_n ∈ [0, 1].
    pub eps_n: f64,
    /// Tangential coefficient of restitution ε_t ∈ [−1, 1].
    pub eps_t: f64,
    /// The time at which `position` holds (s): during a drift particles are advanced lazily.
    pub t_local: f64,
    /// False once absorbed by an absorbing wall.
    pub alive: bool,
    /// Set once stuck to a sticky wall.
    pub stuck: Option<Attachment>,
}

impl Particle {
    /// A free particle at time 0.
    pub fn new(id: usize, mass: f64, radius: f64, position: Vec3, velocity: Vec3, spin: Vec3) -> Particle {
        Particle {
            id,
            mass,
            radius,
            position,
            velocity,
            spin,
            eps_n: 1.0,
            eps_t: 1.0,
            t_local: 0.0,
            alive: true,
            stuck: None,
        }
    }

    /// Moment of inertia (kg m²) of a uniform sphere.
    pub fn inertia(&self) -> f64 {
        0.4 * self.mass * self.radius * self.radius
    }

    /// Position at time `t` on the current straight-line drift.
    pub fn position_at(&self, t: f64) -> Vec3 {
        self.position + self.velocity * (t - self.t_local)
    }

    /// Moves the particle's clock to `t`.
    pub fn advance(&mut self, t: f64) {
        self.position = self.position_at(t);
        self.t_local = t;
    }

    /// Kinetic energy, translational plus rotational (J).
    pub fn kinetic_energy(&self) -> f64 {
        0.5 * self.mass * self.velocity.norm_squared() + 0.5 * self.inertia() * self.spin.norm_squared()
    }
}
