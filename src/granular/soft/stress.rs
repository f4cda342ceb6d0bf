//! Stresses in a soft-sphere aggregate (Zhang17 Eqs. 15–16): the mean stress of a particle from its contact forces,
//! the volume average over a representative volume element, and the principal stresses with the Mohr–Coulomb
//! measures built from them (Zhang17 Eqs. 20–21). Stresses in Pa, compression negative (as the paper).

use crate::math::{Mat3, Vec3};

/// Zhang17 Eq. 15: the average stress in a particle of volume `volume` (its Voronoi cell, m³) from its contacts,
/// `σ = (1/V) Σ_c x_c ⊗ f_c`, with `x_c` the branch vector from the particle's centre to the contact point (m) and
/// `f_c` the contact force on the particle (N). Compression comes out negative. Symmetrised.
pub fn particle_stress(volume: f64, contacts: &[(Vec3, Vec3)]) -> Mat3 {
    let mut s = Mat3::zeros();
    for (x, f) in contacts {
        s += x * f.transpose();
    }
    let s = 0.5 * (s + s.transpose());
    s / volume
}

/// Zhang17 Eq. 16: the volume-weighted average of particle stresses over a representative volume element.
pub fn rve_stress(particles: &[(f64, Mat3)]) -> Mat3 {
    let (mut s, mut v) = (Mat3::zeros(), 0.0);
    for (vol, sigma) in particles {
        s += sigma * *vol;
        v += vol;
    }
    if v > 0.0 { s / v } else { Mat3::zeros() }
}

/// Principal stresses and the Mohr–Coulomb measures of a stress tensor (Zhang17 Eqs. 20–21).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct StressState {
    /// Principal stresses σ₁ ≥ σ₂ ≥ σ₃ (Pa; compression negative).
    pub principal: [f64; 3],
    /// Deviatoric measure `s = (σ₁ − σ₃)/2` (Pa).
    pub deviatoric: f64,
    /// Pressure `p = (σ₁ + σ₂ + σ₃)/3` (Pa).
    pub pressure: f64,
    /// Mobilized friction angle `θ = arcsin((σ₃ − σ₁)/(σ₁ + σ₃))` (degrees); `None` unless both extreme principal
    /// stresses are compressive (σ₁ + σ₃ < 0), where the Mohr circle lies in compression.
    pub friction_angle_deg: Option<f64>,
}

/// [`StressState`] of the symmetric tensor `sigma`.
pub fn stress_state(sigma: &Mat3) -> StressState {
    let eig = nalgebra::SymmetricEigen::new(0.5 * (sigma + sigma.transpose()));
    let mut p = [eig.eigenvalues[0], eig.eigenvalues[1], eig.eigenvalues[2]];
    p.sort_by(|a, b| b.total_cmp(a));
    let (s1, s3) = (p[0], p[2]);
    let friction_angle_deg = (s1 + s3 < 0.0).then(|| ((s3 - s1) / (s1 + s3)).clamp(-1.0, 1.0).asin().to_degrees());
    StressState {
        principal: p,
        deviatoric: 0.5 * (s1 - s3),
        pressure: (p[0] + p[1] + p[2]) / 3.0,
        friction_angle_deg,
    }
}
