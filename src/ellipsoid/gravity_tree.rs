//! Monopole gravity among ellipsoid centres (Roig03 Eq. 6, `U_Gij = −G m_i m_j / |r_i − r_j|`) by a Barnes–Hut
//! octree with quadrupole moments ([`crate::gravity::octree`]; Barnes & Hut 1986, Nature 324, 446), and the
//! choice between it and the exact pair sum of [`crate::ellipsoid::gravity`].
//!
//! The tree treats each ellipsoid as a point mass at its centre, exactly as Eq. 6 does, so the only error is
//! the multipole truncation of far groups, set by the opening angle θ. Its sums are done per body in a fixed
//! order, so the forces do not depend on the number of threads. Tree forces are not exactly pairwise: momentum
//! and energy are conserved only to the force error. [`GravityMethod::Auto`] (the default) uses the exact sum
//! below [`TREE_FROM`] bodies and the tree from there on.

use crate::gravity::octree::{FrozenOctree, Octree};
use crate::math::Vec3;

/// Default opening angle θ (dimensionless; `tests/ellipsoid_gravity_tree.rs` bounds its RMS force error by 1e-3).
pub const DEFAULT_THETA: f64 = 0.5;

/// Bodies from which [`GravityMethod::Auto`] uses the tree: below it the exact blocked pair sum costs at most
/// about what the tree saves, and it is exactly pairwise.
pub const TREE_FROM: usize = 5000;

/// Largest opening angle accepted (dimensionless): above `2/√3` a node could be used whole for a point inside
/// its own cube ([`crate::gravity::octree`]); 1 keeps a margin.
pub const MAX_THETA: f64 = 1.0;

/// How gravity among centres is summed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GravityMethod {
    /// Exact pair sum, O(N²).
    Direct,
    /// Octree with opening angle θ (dimensionless, in (0, [`MAX_THETA`]]), O(N log N), at any N.
    Tree {
        /// Opening angle θ.
        theta: f64,
    },
    /// Exact sum below [`TREE_FROM`] bodies, tree with opening angle θ from there on.
    Auto {
        /// Opening angle θ of the tree when it is used.
        theta: f64,
    },
}

impl Default for GravityMethod {
    fn default() -> Self {
        GravityMethod::Auto { theta: DEFAULT_THETA }
    }
}

impl GravityMethod {
    /// The opening angle when a system of `n` bodies uses the tree, `None` when it uses the exact sum.
    pub fn tree_theta(&self, n: usize) -> Option<f64> {
        match *self {
            GravityMethod::Direct => None,
            GravityMethod::Tree { theta } => Some(theta),
            GravityMethod::Auto { theta } => (n >= TREE_FROM).then_some(theta),
        }
    }

    /// Short name for summaries: `direct`, `tree` or `auto`.
    pub fn name(&self) -> &'static str {
        match self {
            GravityMethod::Direct => "direct",
            GravityMethod::Tree { .. } => "tree",
            GravityMethod::Auto { .. } => "auto",
        }
    }
}

/// Gravitational forces `−∂U_G/∂r_i` (N) of every body by the tree, written into `forces` (resized to the
/// number of bodies), and the tree's total potential `U_G = ½ Σ m_i φ_i` (J; from 1000 bodies on summed in
/// single precision, ~1e-6 relative noise, so the diagnostics use the exact sum instead). `g` in m³ kg⁻¹ s⁻², positions
/// in m, masses in kg.
pub fn tree_gravity_forces(g: f64, theta: f64, positions: &[Vec3], masses: &[f64], forces: &mut Vec<Vec3>) -> f64 {
    let (acc, phi) = Octree::build(positions, masses).accelerations(theta, g);
    forces.clear();
    forces.extend(acc.iter().zip(masses).map(|(a, m)| a * *m));
    0.5 * phi.iter().zip(masses).map(|(p, m)| p * m).sum::<f64>()
}

/// The same as [`tree_gravity_forces`] by the lists of a [`FrozenOctree`] (built from these bodies, in this
/// order), summed at `positions` in double precision: smooth in the positions while the lists are kept (see
/// `begin_step` of the ellipsoid system in `ellipsoid::equations`).
pub fn frozen_tree_gravity_forces(
    g: f64,
    tree: &FrozenOctree,
    positions: &[Vec3],
    masses: &[f64],
    forces: &mut Vec<Vec3>,
) -> f64 {
    let (acc, phi) = tree.accelerations(positions, masses, g);
    forces.clear();
    forces.extend(acc.iter().zip(masses).map(|(a, m)| a * *m));
    0.5 * phi.iter().zip(masses).map(|(p, m)| p * m).sum::<f64>()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ellipsoid::gravity::gravity_forces;
    use crate::random::{generator, point_in_ball};

    /// On 1500 random points the tree's forces at θ = 0.5 agree with the exact sum to an RMS relative error
    /// below 1e-3, and its potential to 1e-4; at θ = 0.2 both errors are smaller.
    #[test]
    fn tree_forces_and_potential_converge_to_the_pair_sum() {
        let mut rng = generator(3);
        let x: Vec<Vec3> = (0..1500).map(|_| point_in_ball(&mut rng, 1e5)).collect();
        let m: Vec<f64> = (0..x.len()).map(|k| 1e15 * (1.0 + (k % 7) as f64)).collect();
        let mut exact = vec![Vec3::zeros(); x.len()];
        let u = gravity_forces(6.674e-11, &x, &m, &mut exact);
        let error = |theta: f64| {
            let mut f = Vec::new();
            let ut = tree_gravity_forces(6.674e-11, theta, &x, &m, &mut f);
            let sq: f64 = f
                .iter()
                .zip(&exact)
                .map(|(a, b)| ((a - b).norm() / b.norm()).powi(2))
                .sum();
            ((sq / x.len() as f64).sqrt(), ((ut - u) / u).abs())
        };
        let (coarse, fine) = (error(0.5), error(0.2));
        assert!(coarse.0 < 1e-3 && coarse.1 < 1e-4, "{coarse:?}");
        assert!(fine.0 < coarse.0 && fine.1 < 1e-5, "{fine:?} vs {coarse:?}");
    }

    /// Auto uses the exact sum below the threshold and the tree from it on; Direct never uses the tree.
    #[test]
    fn auto_switches_at_the_threshold() {
        let auto = GravityMethod::default();
        assert_eq!(auto.tree_theta(TREE_FROM - 1), None);
        assert_eq!(auto.tree_theta(TREE_FROM), Some(DEFAULT_THETA));
        assert_eq!(GravityMethod::Direct.tree_theta(1_000_000), None);
        assert_eq!(GravityMethod::Tree { theta: 0.3 }.tree_theta(2), Some(0.3));
    }
}
