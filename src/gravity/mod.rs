//! Self-gravity of point masses (the spheres of the soft-sphere engine): exact direct summation and a
//! Barnes–Hut octree with quadrupole moments ([`octree`]). Zhang17 §2.1 (pkdgrav uses a tree code); our
//! notes ask for at least quadrupole order, checked against direct summation.
//!
//! Both return, per particle, the acceleration (m/s²) and the potential φ (J/kg, the particle itself
//! excluded), each summed in a fixed order per particle, so results do not depend on the number of threads.
//!
//! [`kepler`]: two-body orbits (Kepler's equation, elliptic and hyperbolic) for an external body on a prescribed
//! orbit (the flyby tide). [`zonal`]: the J2 field of an oblate planet (the flyby tide's optional term).

pub mod kepler;
pub mod octree;
pub mod zonal;

use crate::math::Vec3;
use rayon::prelude::*;

/// How self-gravity is computed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SelfGravity {
    /// Exact O(N²) summation.
    Direct,
    /// Octree with opening angle θ (dimensionless, > 0): a node of side `l` whose centre of mass is `δ` from
    /// its cube's centre is used whole at distance `d > l/θ + δ` ([`octree`]).
    Tree {
        /// Opening angle θ.
        theta: f64,
    },
}

/// Accelerations (m/s²) and potentials (J/kg) by exact direct summation, `G` in m³ kg⁻¹ s⁻².
///
/// ```
/// use rubblepile::gravity::direct;
/// use rubblepile::math::Vec3;
/// let (acc, pot) = direct(&[Vec3::zeros(), Vec3::new(2.0, 0.0, 0.0)], &[1.0, 4.0], 1.0);
/// assert!((acc[0].x - 1.0).abs() < 1e-15 && (pot[1] + 0.5).abs() < 1e-15);
/// ```
pub fn direct(positions: &[Vec3], masses: &[f64], g: f64) -> (Vec<Vec3>, Vec<f64>) {
    let one = |i: usize| {
        let mut a = Vec3::zeros();
        let mut phi = 0.0;
        for (j, (xj, &mj)) in positions.iter().zip(masses).enumerate() {
            if j == i {
                continue;
            }
            let d = xj - positions[i];
            let r2 = d.norm_squared();
            let inv_r = 1.0 / r2.sqrt();
            a += d * (mj * inv_r * inv_r * inv_r);
            phi -= mj * inv_r;
        }
        (a * g, phi * g)
    };
    (0..positions.len()).into_par_iter().with_min_len(16).map(one).unzip()
}

/// Accelerations and potentials by `mode`.
pub fn accelerations(mode: SelfGravity, positions: &[Vec3], masses: &[f64], g: f64) -> (Vec<Vec3>, Vec<f64>) {
    match mode {
        SelfGravity::Direct => direct(positions, masses, g),
        SelfGravity::Tree { theta } => octree::Octree::build(positions, masses).accelerations(theta, g),
    }
}
