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
                let mut f = Vec3::zeros();
                let mut u = 0.0;
                for j in 0..n {
                    if j == i {
                        continue;
                    }
                    let d = positions[j] - positions[i];
                    let r2 = d.norm_squared();
                    let r = r2.sqrt();
                    let gm = g * masses[i] * masses[j];
                    u -= gm / r;
                    f += d * (gm / (r2 * r));
                }
                *fi = f;
                u
            })
            .collect();
        0.5 * potentials.iter().sum::<f64>()
    }
}
