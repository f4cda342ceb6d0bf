//! Monopole gravity between fragments, `U_Gij = −G m_i m_j / |r_i − r_j|` (Roig03 Eq. 6): exact pair sum.
//!
//! Small systems use the symmetric half loop (Newton's third law bitwise); large ones compute each
//! body's row in parallel with rayon (twice the flops, but no reduction, so the result does not depend on
//! the number of threads: the same scene gives the same bits on 1 or many cores).

use crate::math::Vec3;
use rayon::prelude::*;

/// Above this many bodies the parallel row-wise sum is used.
pub const PARALLEL_THRESHOLD: usize = 256;

/// Gravitational forces `−∂U_G/∂r_i` (N) on each body, and the total potential `U_G` (J).
/// `forces` is overwritten.
pub fn gravity_forces(g: f64, positions: &[Vec3], masses: &[f64], forces: &mut [Vec3]) -> f64 {
    let n = positions.len();
    if n < PARALLEL_THRESHOLD {
        forces.iter_mut().for_each(|f| *f = Vec3::zeros());
        let mut potential = 0.0;
        for i in 0..n {
            for j in (i + 1)..n {
                let d = positions[j] - positions[i];
                let r2 = d.norm_squared();
                let r = r2.sqrt();
                let gm = g * masses[i] * masses[j];
                potential -= gm / r;
                let f = d * (gm / (r2 * r));
                forces[i] += f;
                forces[j] -= f;
            }
        }
        potential
    } else {
        let potentials: Vec<f64> = forces
            .par_iter_mut()
            .enumerate()
            .map(|(i, fi)| {
                // Σ_j m_j d/r³ and Σ_j m_j/r over j ≠ i, in index order (two branch-free ranges).
                let (mut acc, mut phi) = (Vec3::zeros(), 0.0);
                let pi = positions[i];
                for range in [0..i, i + 1..n] {
                    for (pj, &mj) in positions[range.clone()].iter().zip(&masses[range]) {
                        let d = pj - pi;
                        let inv_r = 1.0 / d.norm_squared().sqrt();
                        let w = mj * inv_r;
                        phi += w;
                        acc += d * (w * inv_r * inv_r);
                    }
                }
                let gm = g * masses[i];
                *fi = acc * gm;
                -gm * phi
            })
            .collect();
        0.5 * potentials.iter().sum::<f64>()
    }
}
