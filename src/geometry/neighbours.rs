//! Neighbour search by bounding spheres on a uniform cell grid.
//!
//! Each body has a centre and an interaction radius `ρ`; the candidate pairs are those with
//! `|r_i − r_j| < ρ_i + ρ_j`. With cell size `2 max ρ` every such pair lies in adjacent cells, so the
//! cost is O(N + pairs) for bodies of comparable size. The output is sorted `(i, j)` with `i < j`,
//! independent of thread count, so runs are deterministic.

use crate::math::Vec3;

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
    let sorted_keys: Vec<[i64; 3]> = order.iter().map(|&k| keys[k]).collect();
    let mut row = Vec::new();
    for i in 0..n {
        row.clear();
        let k = keys[i];
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let target = [k[0] + dx, k[1] + dy, k[2] + dz];
                    let start = sorted_keys.partition_point(|c| *c < target);
                    let mut m = start;
                    while m < n && sorted_keys[m] == target {
                        let j = order[m];
                        if j > i && (centres[i] - centres[j]).norm() < radii[i] + radii[j] {
                            row.push(j);
                        }
                        m += 1;
                    }
                }
            }
        }
        row.sort_unstable();
        pairs.extend(row.iter().map(|&j| (i, j)));
    }
    pairs
}
