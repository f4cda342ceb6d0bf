//! Grain masses from a bulk density (Zhang17 Table 2: the grain density follows from the nominal bulk density
//! 2100 kg/m³, the shape's volume and the grains' volume) and the bulk-density variants of §4.2,
//! `ρ_B = 2100 · M_a/M_P`: masses change, positions and shape do not.

use crate::granular::soft::particle::Particle;

/// Sets every mass so that the total mass over `shape_volume` (m³) is `bulk_density` (kg/m³); grain `i` has
/// grain density `ρ_g · weight[i]` (weights 1, or 1.5 in a denser core). Returns `ρ_g` (kg/m³).
pub fn assign_masses(particles: &mut [Particle], weights: &[f64], shape_volume: f64, bulk_density: f64) -> f64 {
    let weighted: f64 = particles
        .iter()
        .zip(weights)
        .map(|(p, w)| w * 4.0 / 3.0 * std::f64::consts::PI * p.radius.powi(3))
        .sum();
    let rho_g = bulk_density * shape_volume / weighted;
    for (p, w) in particles.iter_mut().zip(weights) {
        p.mass = rho_g * w * 4.0 / 3.0 * std::f64::consts::PI * p.radius.powi(3);
    }
    rho_g
}

/// The bulk-density variant: multiplies every mass by `bulk_density · shape_volume / M` so the total mass over
/// `shape_volume` (m³) becomes `bulk_density` (kg/m³); returns the factor.
///
/// ```
/// use rubblepile::aggregate::density::rescale_bulk_density;
/// use rubblepile::granular::soft::particle::Particle;
/// use rubblepile::math::Vec3;
/// let mut p = vec![Particle { mass: 2.0, radius: 1.0, position: Vec3::zeros(), velocity: Vec3::zeros(), spin: Vec3::zeros() }];
/// assert_eq!(rescale_bulk_density(&mut p, 1.0, 3.0), 1.5);
/// assert_eq!(p[0].mass, 3.0);
/// ```
pub fn rescale_bulk_density(particles: &mut [Particle], shape_volume: f64, bulk_density: f64) -> f64 {
    let total: f64 = particles.iter().map(|p| p.mass).sum();
    let factor = bulk_density * shape_volume / total;
    for p in particles.iter_mut() {
        p.mass *= factor;
    }
    factor
}
