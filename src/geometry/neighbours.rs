//! Neighbour search by bounding spheres on a uniform cell grid.
//!
//! Each body has a centre and an interaction radius `ρ`; the candidate pairs are those with
//! `|r_i − r_j| < ρ_i + ρ_j`. With cell size `2 max ρ` every such pair lies in adjacent cells, so the
//! cost is O(N + pairs) for bodies of comparable size. The output is sorted `(i, j)` with `i < j`,
//! independent of thread count, so runs are deterministic.

use crate::math::Vec3;
use rayon::prelude::*;

/// All pairs `(i, j)`, `i < j`, with `|r_i − r_j| < ρ_i + ρ_j`, sorted.
///
/// ```
/// use rubblepile::geometry::neighbours::sphere_pairs;
/// use rubblepile::math::Vec3;
/// let c = [Vec3::zeros(), Vec3::new(1.5, 0.0, 0.0), Vec3::new(5.0, 0.0, 0.0)];
/// assert_eq!(sphere_pairs(&c, &[1.0, 1.0, 1.0]), vec![(0, 1)]);
/// ```
pub fn sphere_pairs(centres: &[Vec3], radii: &[f64]) -> Vec<(usize, usize)> {
    let n = centres.len();
    let mut pairs = Vec::new();
    if n < 2 {
        return pairs;
    }
    let rmax = radii.iter().cloned().fold(0.0_f64, f64::max);
    if rmax.is_nan() || rmax <= 0.0 || !rmax.is_finite() || n <= 16 {
        for i in 0..n {
            for j in (i + 1)..n {
                if (centres[i] - centres[j]).norm() < radii[i] + radii[j] {
                    pairs.push((i, j));
                }
            }
        }
        return pairs;
    }
    let cell = 2.0 * rmax;
    let key = |p: &Vec3| -> [i64; 3] {
        [
            (p.x / cell).floor() as i64,
            (p.y / cell).floor() as i64,
            (p.z / cell).floor() as i64,
        ]
    };
    let keys: Vec<[i64; 3]> = centres.iter().map(key).collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_unstable_by(|&a, &b| keys[a].cmp(&keys[b]).then(a.cmp(&b)));
    // Bodies laid out contiguously in cell order, so the inner loop streams through memory.
    let sorted_keys: Vec<[i64; 3]> = order.iter().map(|&k| keys[k]).collect();
    let sorted_centres: Vec<Vec3> = order.iter().map(|&k| centres[k]).collect();
    let sorted_radii: Vec<f64> = order.iter().map(|&k| radii[k]).collect();
    let row_of = |i: usize| -> Vec<usize> {
        let mut row = Vec::new();
        let (k, ci, ri) = (keys[i], centres[i], radii[i]);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let target = [k[0] + dx, k[1] + dy, k[2] + dz];
                    let mut m = sorted_keys.partition_point(|c| *c < target);
                    while m < n && sorted_keys[m] == target {
                        let reach = ri + sorted_radii[m];
                        if (sorted_centres[m] - ci).norm_squared() < reach * reach && order[m] > i {
                            row.push(order[m]);
                        }
                        m += 1;
                    }
                }
            }
        }
        row.sort_unstable();
        row
    };
    // Rows are independent; collecting them in index order keeps the output deterministic.
    let rows: Vec<Vec<usize>> = if n >= 256 {
        (0..n).into_par_iter().map(row_of).collect()
    } else {
        (0..n).map(row_of).collect()
    };
    for (i, row) in rows.into_iter().enumerate() {
        pairs.extend(row.into_iter().map(|j| (i, j)));
    }
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The grid search must find exactly the pairs of the brute-force search (polydisperse, clustered).
    #[test]
    fn grid_search_equals_brute_force() {
        let mut state = 12345u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for n in [17, 300, 1200] {
            let centres: Vec<Vec3> = (0..n)
                .map(|_| Vec3::new(next(), next(), next() * 0.4) * 4.0 * (n as f64).cbrt())
                .collect();
            let radii: Vec<f64> = (0..n).map(|_| 0.5 + 4.0 * next() * next()).collect();
            let mut brute = Vec::new();
            for i in 0..n {
                for j in (i + 1)..n {
                    if (centres[i] - centres[j]).norm() < radii[i] + radii[j] {
                        brute.push((i, j));
                    }
                }
            }
            assert!(!brute.is_empty());
            assert_eq!(sphere_pairs(&centres, &radii), brute, "n = {n}");
        }
    }
}
