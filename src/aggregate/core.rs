//! Core variants (Zhang17 §2.3.2): RCPC, a 200-m-radius HCP core inside a random shell of equal grains ("obtained
//! from a similar procedure combining the HCP structure with a random granular assembly"), and PPC, PP1 whose grains
//! with centres inside a 200 m core have 1.5 times the grain density of the rest. The paper's core radius is
//! 200 m in a body of volume-equivalent radius 390 m; [`default_core_radius`] keeps that proportion.

use crate::aggregate::hcp::rotate;
use crate::aggregate::random_packing::Insert;
use crate::geometry::lattice::hcp_centres;
use crate::math::{Mat3, Vec3};

/// Zhang17's core radius relative to the body's volume-equivalent radius, 200 m / 390 m.
pub const CORE_FRACTION: f64 = 200.0 / 390.0;
/// Grain-density ratio of PPC's core to its shell.
pub const PPC_CORE_DENSITY_RATIO: f64 = 1.5;

/// The paper's proportion applied to a body of volume-equivalent diameter `d_eq` (m): `CORE_FRACTION · d_eq/2`.
pub fn default_core_radius(d_eq: f64) -> f64 {
    CORE_FRACTION * 0.5 * d_eq
}

/// The HCP core of RCPC: lattice sites (a site at the origin) within `core_radius` (m) for grains of radius `r`;
/// the random heap's grains inside `core_radius` or touching the core are removed before settling. The lattice is
/// turned by `rotation` (lattice → body; [`crate::aggregate::lattice_orientation`]).
pub fn hcp_core(r: f64, core_radius: f64, rotation: &Mat3) -> Insert {
    let centres: Vec<Vec3> = hcp_centres(r, core_radius)
        .into_iter()
        .map(|p| rotate(rotation, p))
        .collect();
    Insert {
        radii: vec![r; centres.len()],
        centres,
        clear_radius: core_radius,
    }
}

/// Grain-density weights: `ratio` for grains whose centres are within `core_radius` (m) of the origin, 1 otherwise.
pub fn core_weights(centres: &[Vec3], core_radius: f64, ratio: f64) -> Vec<f64> {
    centres
        .iter()
        .map(|c| if c.norm() <= core_radius { ratio } else { 1.0 })
        .collect()
}
