//! Equations of motion of N interacting ellipsoids (Roig03 Eqs. 28–37) as an [`OdeSystem`].
//!
//! API skeleton — bodies being filled in.

use crate::ellipsoid::body::{Body, InertiaModel};
use crate::integrate::OdeSystem;
use crate::math::Vec3;

/// Monopole gravity term (Roig03 Eq. 6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GravityTerm {
    /// Gravitational constant G (m³ kg⁻¹ s⁻²); SI default 6.674e-11.
    pub g: f64,
}

/// Gaussian-overlap contact term (Roig03 Eqs. 10–12).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactTerm {
    /// Pairs whose potential is provably below `cutoff × amplitude` are skipped (dimensionless, default 1e-16).
    pub cutoff: f64,
}

/// Point dissipation term (Roig03 Eqs. 40–41).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DissipationTerm {
    /// Dissipation coefficient F0 (s m⁻²): `F_ij = −F0 U_Cij [ … velocity² … ]`.
    pub f0: f64,
}

/// Which physics a scene enables; `None` = not computed at all.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Physics {
    /// Monopole gravity.
    pub gravity: Option<GravityTerm>,
    /// Contact potential.
    pub contact: Option<ContactTerm>,
    /// Dissipation (weights by the contact overlap; may be on without the contact force).
    pub dissipation: Option<DissipationTerm>,
}

/// Model constants shared by all pairs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelConfig {
    /// Width parameter κ of the Gaussian mass distribution (Roig03 Eq. 2), > 3/2.
    pub kappa: f64,
    /// Which moments of inertia the bodies get.
    pub inertia: InertiaModel,
    /// G used in `U0_ij` (Roig03 Eq. 11) — the gravity term's G, or the SI value when gravity is off.
    pub contact_g: f64,
}

/// Energies, momenta and constraint errors of a state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Diagnostics {
    /// Translational kinetic energy K_T (J).
    pub kinetic_translational: f64,
    /// Rotational kinetic energy K_R (J).
    pub kinetic_rotational: f64,
    /// Contact potential energy U_C (J).
    pub potential_contact: f64,
    /// Gravitational potential energy U_G (J).
    pub potential_gravity: f64,
    /// `2 ∫ F dt` so far (J, ≤ 0).
    pub dissipated: f64,
    /// Total linear momentum (kg m/s).
    pub momentum: Vec3,
    /// Total angular momentum about the origin, orbital + spin (kg m²/s).
    pub angular_momentum: Vec3,
    /// Scale for momentum errors: Σ m|v| (kg m/s).
    pub momentum_scale: f64,
    /// Scale for angular-momentum errors: Σ (|r × m v| + |I ω|) (kg m²/s).
    pub angular_momentum_scale: f64,
    /// Scale for energy errors: K + |U_C| + |U_G| (J).
    pub energy_scale: f64,
    /// max over bodies of ||q| − 1|.
    pub quaternion_norm_error: f64,
}

impl Diagnostics {
    /// Total mechanical energy H = K_T + K_R + U_C + U_G (J).
    pub fn energy(&self) -> f64 {
        self.kinetic_translational + self.kinetic_rotational + self.potential_contact + self.potential_gravity
    }
}

/// The N-ellipsoid system.
pub struct EllipsoidSystem {
    _private: (),
}

impl EllipsoidSystem {
    /// Builds the system from bodies (validated by the caller), model constants and physics.
    pub fn new(_bodies: &[Body], _model: ModelConfig, _physics: Physics) -> Self {
        todo!()
    }
    /// The packed initial state.
    pub fn initial_state(&self) -> Vec<f64> {
        todo!()
    }
    /// Whether attitudes are integrated (false for all-sphere scenes without dissipation).
    pub fn rotation_integrated(&self) -> bool {
        todo!()
    }
    /// Number of bodies.
    pub fn n_bodies(&self) -> usize {
        todo!()
    }
    /// The bodies' state at time `t` from the packed state `y`.
    pub fn bodies_at(&self, _t: f64, _y: &[f64]) -> Vec<Body> {
        todo!()
    }
    /// Diagnostics of the packed state `y`.
    pub fn diagnostics(&self, _y: &[f64]) -> Diagnostics {
        todo!()
    }
}

impl OdeSystem for EllipsoidSystem {
    fn dim(&self) -> usize {
        todo!()
    }
    fn rhs(&self, _t: f64, _y: &[f64], _dydt: &mut [f64]) {
        todo!()
    }
}
