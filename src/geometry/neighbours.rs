//! Neighbour search by bounding spheres on a uniform cell grid.
//!
//! Each body has a centre and an interaction radius `ρ`; the candidate pairs are those with
//! `|r_i − r_j| < ρ_i + ρ_j`. Bodies with `ρ ≤ ρ_ref = min(ρ_max, 2 × median ρ)` ("regular") are binned in
//! cells of side `ρ_ref`, sorted by `(z, y, x)` cell index so that a run of cells along x is contiguous;
//! each body scans the cell runs that its reach `ρ_i + ρ_ref` overlaps. The few larger bodies query the
//! same grid with their own reach and are paired with each other directly, so a wide size distribution
//! does not inflate the cells. Cost O(N + pairs) for piles of bounded density. Where the grid's bounding box
//! holds at most [`DENSE_CELLS_PER_BODY`] cells per body, a dense table of where each cell's run starts finds a
//! run in O(1); otherwise (sparse clouds, far debris) a binary search over the sorted keys does. The output is
//! sorted `(i, j)` with `i < j` and does not depend on the number of threads, so runs are deterministic.
//! [`sphere_pair_rows`] gives the same pairs as compressed rows by both indices (a Verlet list and its
//! transpose), built in parallel by tasks of consecutive bodies that each fill their own buffers.

use crate::math::Vec3;
use rayon::prelude::*;

/// Below this many bodies the plain O(N²) loop is used.
const BRUTE_FORCE_BELOW: usize = 24;
/// From this many bodies on, rows are built in parallel.
const PARALLEL_FROM: usize = 256;

/// Largest number of cells per binned body for which the dense start table is built.
pub const DENSE_CELLS_PER_BODY: usize = 16;

/// Cells of the regular bodies, in `(z, y, x)` order.
struct Grid {
    cell: f64,
    keys: Vec<[i64; 3]>,
    centres: Vec<Vec3>,
    radii: Vec<f64>,
    ids: Vec<usize>,
    dense: Option<DenseStarts>,
}

/// For a box of cells `lo..lo + dims` (in `(z, y, x)` order), the index in the sorted arrays where each cell's
/// bodies start (`starts[c]..starts[c + 1]`), `c` the cell's linear index in the same order as the sort.
struct DenseStarts {
    lo: [i64; 3],
    dims: [i64; 3],
    starts: Vec<u32>,
}

impl DenseStarts {
    /// The table for sorted `keys`, if the box holds at most `max_cells` cells.
    fn new(keys: &[[i64; 3]], max_cells: usize) -> Option<Self> {
        let (first, last) = (keys.first()?, keys.last()?);
        let (mut lo, mut hi) = (*first, *last);
        for k in keys {
            for a in 1..3 {
                lo[a] = lo[a].min(k[a]);
                hi[a] = hi[a].max(k[a]);
            }
        }
        let dims = [hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1];
        let cells = dims
            .iter()
            .try_fold(1usize, |acc, &d| acc.checked_mul(usize::try_from(d).ok()?))?;
        if cells > max_cells || keys.len() >= u32::MAX as usize {
            return None;
        }
        let mut starts = vec![0u32; cells + 1];
        // counts per cell, then running sums: starts[c] = bodies in cells before c
        for k in keys {
            starts[Self::linear(&lo, &dims, k) + 1] += 1;
        }
        for c in 1..=cells {
            starts[c] += starts[c - 1];
        }
        Some(DenseStarts { lo, dims, starts })
    }

    fn linear(lo: &[i64; 3], dims: &[i64; 3], k: &[i64; 3]) -> usize {
        (((k[0] - lo[0]) * dims[1] + (k[1] - lo[1])) * dims[2] + (k[2] - lo[2])) as usize
    }

    /// The sorted-array range of the cells `(kz, ky, x0..=x1)`, clipped to the box (empty outside it).
    fn row(&self, kz: i64, ky: i64, x0: i64, x1: i64) -> std::ops::Range<usize> {
        let inside = |v: i64, a: usize| v >= self.lo[a] && v < self.lo[a] + self.dims[a];
        let (x0, x1) = (x0.max(self.lo[2]), x1.min(self.lo[2] + self.dims[2] - 1));
        if !inside(kz, 0) || !inside(ky, 1) || x0 > x1 {
            return 0..0;
        }
        let a = Self::linear(&self.lo, &self.dims, &[kz, ky, x0]);
        let b = Self::linear(&self.lo, &self.dims, &[kz, ky, x1]);
        self.starts[a] as usize..self.starts[b + 1] as usize
    }
}

impl Grid {
    fn key(&self, p: &Vec3) -> [i64; 3] {
        [p.z, p.y, p.x].map(|v| (v / self.cell).floor() as i64)
    }

    /// Calls `visit(id)` for every binned body whose sphere overlaps the sphere (`c`, `r`), given the
    /// largest binned radius `r_ref`.
    fn query(&self, c: &Vec3, r: f64, r_ref: f64, mut visit: impl FnMut(usize)) {
        let reach = r + r_ref;
        let lo = self.key(&(c - Vec3::from_element(reach)));
        let hi = self.key(&(c + Vec3::from_element(reach)));
        // A sphere far larger than the cells (a wild trial state of the integrator can give one) would walk more
        // cell rows than there are bodies: scanning the bodies is then cheaper, and finishes.
        let rows = (hi[0] as f64 - lo[0] as f64 + 1.0) * (hi[1] as f64 - lo[1] as f64 + 1.0);
        let mut check = |m: usize| {
            let reach_ij = r + self.radii[m];
            if (self.centres[m] - c).norm_squared() < reach_ij * reach_ij {
                visit(self.ids[m]);
            }
        };
        if rows > self.keys.len() as f64 {
            (0..self.keys.len()).for_each(check);
            return;
        }
        for kz in lo[0]..=hi[0] {
            for ky in lo[1]..=hi[1] {
                let run = match &self.dense {
                    Some(d) => d.row(kz, ky, lo[2], hi[2]),
                    None => {
                        let first = [kz, ky, lo[2]];
                        let last = [kz, ky, hi[2]];
                        self.keys.partition_point(|k| *k < first)..self.keys.partition_point(|k| *k <= last)
                    }
                };
                run.for_each(&mut check);
            }
        }
    }
}

/// All pairs `(i, j)`, `i < j`, with `|r_i − r_j| < ρ_i + ρ_j`, sorted.
///
/// ```
/// use rubblepile::geometry::neighbours::sphere_pairs;
/// use rubblepile::math::Vec3;
/// let c = [Vec3::zeros(), Vec3::new(1.5, 0.0, 0.0), Vec3::new(5.0, 0.0, 0.0)];
/// assert_eq!(sphere_pairs(&c, &[1.0, 1.0, 1.0]), vec![(0, 1)]);
/// ```
pub fn sphere_pairs(centres: &[Vec3], radii: &[f64]) -> Vec<(usize, usize)> {
    let rows = sphere_pair_rows(centres, radii);
    let mut pairs = Vec::with_capacity(rows.upper.len());
    for i in 0..centres.len() {
        pairs.extend(rows.upper(i).iter().map(|&j| (i, j as usize)));
    }
    pairs
}

/// The pairs of [`sphere_pairs`] in compressed rows, by each of their two bodies: body `i`'s partners of higher
/// index (its "row") and of lower index (its "column"), both ascending. Indices are 32-bit (a system of 2³²
/// bodies would not fit in memory anyway).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PairRows {
    /// `upper_start[i]..upper_start[i + 1]` is the range of `upper` holding body `i`'s partners `j > i`
    /// (`n + 1` entries).
    pub upper_start: Vec<usize>,
    /// The partners `j > i` of every body `i`, row after row, each row ascending.
    pub upper: Vec<u32>,
    /// `lower_start[j]..lower_start[j + 1]` is the range of `lower` holding body `j`'s partners `i < j`.
    pub lower_start: Vec<usize>,
    /// The partners `i < j` of every body `j`, column after column, each ascending.
    pub lower: Vec<u32>,
}

impl PairRows {
    /// Body `i`'s partners of higher index, ascending.
    pub fn upper(&self, i: usize) -> &[u32] {
        &self.upper[self.upper_start[i]..self.upper_start[i + 1]]
    }

    /// Body `j`'s partners of lower index, ascending.
    pub fn lower(&self, j: usize) -> &[u32] {
        &self.lower[self.lower_start[j]..self.lower_start[j + 1]]
    }

    /// Rows from blocks of consecutive bodies, each block's rows back to back (`Block`), in block order.
    fn from_blocks(blocks: Vec<Block>) -> Self {
        let n: usize = blocks.iter().map(|b| b.upper_len.len()).sum();
        let starts = |lens: &mut dyn Iterator<Item = usize>| -> Vec<usize> {
            let mut start = Vec::with_capacity(n + 1);
            start.push(0);
            let mut total = 0;
            for l in lens {
                total += l;
                start.push(total);
            }
            start
        };
        let upper_start = starts(&mut blocks.iter().flat_map(|b| b.upper_len.iter().map(|&l| l as usize)));
        let lower_start = starts(&mut blocks.iter().flat_map(|b| b.lower_len.iter().map(|&l| l as usize)));
        let mut upper = Vec::with_capacity(upper_start[n]);
        let mut lower = Vec::with_capacity(lower_start[n]);
        for b in &blocks {
            upper.extend_from_slice(&b.upper);
            lower.extend_from_slice(&b.lower);
        }
        PairRows {
            upper_start,
            upper,
            lower_start,
            lower,
        }
    }
}

/// The rows of a block of consecutive bodies: partners back to back, and each row's length.
#[derive(Default)]
struct Block {
    upper: Vec<u32>,
    upper_len: Vec<u32>,
    lower: Vec<u32>,
    lower_len: Vec<u32>,
}

impl Block {
    /// Appends the next body's row and column (sorted here) from its partners `partners` (in any order) and the
    /// extra partners of higher and lower index `up`, `down`.
    fn push(&mut self, i: u32, partners: &mut Vec<u32>, up: &[u32], down: &[u32]) {
        let (u0, l0) = (self.upper.len(), self.lower.len());
        for &j in partners.iter() {
            if j > i {
                self.upper.push(j);
            } else if j < i {
                self.lower.push(j);
            }
        }
        partners.clear();
        self.upper.extend_from_slice(up);
        self.lower.extend_from_slice(down);
        self.upper[u0..].sort_unstable();
        self.lower[l0..].sort_unstable();
        self.upper_len.push((self.upper.len() - u0) as u32);
        self.lower_len.push((self.lower.len() - l0) as u32);
    }
}

/// Bodies per parallel task of the neighbour search.
const BODIES_PER_TASK: usize = 256;

/// [`sphere_pairs`] as [`PairRows`], built in parallel (tasks of consecutive bodies, each filling its own
/// buffers); the result does not depend on the number of threads.
///
/// ```
/// use rubblepile::geometry::neighbours::sphere_pair_rows;
/// use rubblepile::math::Vec3;
/// let c = [Vec3::zeros(), Vec3::new(1.5, 0.0, 0.0), Vec3::new(3.0, 0.0, 0.0)];
/// let rows = sphere_pair_rows(&c, &[1.0, 1.0, 1.0]);
/// assert_eq!((rows.upper(0), rows.upper(1), rows.lower(2)), (&[1][..], &[2][..], &[1][..]));
/// ```
pub fn sphere_pair_rows(centres: &[Vec3], radii: &[f64]) -> PairRows {
    let n = centres.len();
    assert!(n < u32::MAX as usize, "{n} bodies: indices must fit in 32 bits");
    let finite =
        centres.iter().all(|c| c.iter().all(|x| x.is_finite())) && radii.iter().all(|r| r.is_finite() && *r > 0.0);
    // Pairs found outside the grid (all of them on the brute-force path; those of large bodies otherwise), as
    // (i, j) and (j, i) lists sorted by their first index.
    let mut extra: Vec<(u32, u32)> = Vec::new();
    let mut grid = None;
    if n < BRUTE_FORCE_BELOW || !finite {
        extra = brute_force_pairs(centres, radii)
            .into_iter()
            .map(|(i, j)| (i as u32, j as u32))
            .collect();
    } else {
        let mut sorted = radii.to_vec();
        sorted.par_sort_unstable_by(f64::total_cmp);
        let r_ref = sorted[n - 1].min(2.0 * sorted[n / 2]);
        let (regular, large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| radii[i] <= r_ref);
        let mut g = Grid {
            cell: r_ref,
            keys: Vec::new(),
            centres: Vec::new(),
            radii: Vec::new(),
            ids: Vec::new(),
            dense: None,
        };
        let mut binned: Vec<([i64; 3], usize)> = regular.par_iter().map(|&i| (g.key(&centres[i]), i)).collect();
        // (key, index) pairs are distinct, so the order does not depend on the sort's scheduling
        binned.par_sort_unstable();
        g.keys = binned.iter().map(|b| b.0).collect();
        g.ids = binned.iter().map(|b| b.1).collect();
        g.centres = g.ids.iter().map(|&i| centres[i]).collect();
        g.radii = g.ids.iter().map(|&i| radii[i]).collect();
        g.dense = DenseStarts::new(&g.keys, DENSE_CELLS_PER_BODY * g.keys.len().max(1));
        // Pairs with a large body: large–regular through the grid, large–large directly.
        for (a, &l) in large.iter().enumerate() {
            g.query(&centres[l], radii[l], r_ref, |j| {
                extra.push((l.min(j) as u32, l.max(j) as u32))
            });
            for &m in &large[a + 1..] {
                if (centres[l] - centres[m]).norm() < radii[l] + radii[m] {
                    extra.push((l as u32, m as u32));
                }
            }
        }
        grid = Some((g, r_ref));
    }
    let mut extra_down: Vec<(u32, u32)> = extra.iter().map(|&(i, j)| (j, i)).collect();
    extra.sort_unstable();
    extra_down.sort_unstable();
    let partners_of = |list: &[(u32, u32)], i: u32| -> Vec<u32> {
        let a = list.partition_point(|e| e.0 < i);
        let b = list.partition_point(|e| e.0 <= i);
        list[a..b].iter().map(|e| e.1).collect()
    };
    // Each body's regular partners from the grid (a regular body lists every regular body near it), then its extra
    // partners.
    let block = |k: usize| -> Block {
        let mut out = Block::default();
        let mut partners = Vec::new();
        for i in k * BODIES_PER_TASK..((k + 1) * BODIES_PER_TASK).min(n) {
            if let Some((g, r_ref)) = &grid
                && radii[i] <= *r_ref
            {
                g.query(&centres[i], radii[i], *r_ref, |j| partners.push(j as u32));
            }
            let (up, down) = (partners_of(&extra, i as u32), partners_of(&extra_down, i as u32));
            out.push(i as u32, &mut partners, &up, &down);
        }
        out
    };
    let tasks = n.div_ceil(BODIES_PER_TASK);
    let blocks: Vec<Block> = if n >= PARALLEL_FROM {
        (0..tasks).into_par_iter().map(block).collect()
    } else {
        (0..tasks).map(block).collect()
    };
    PairRows::from_blocks(blocks)
}

/// The O(N²) reference search.
pub fn brute_force_pairs(centres: &[Vec3], radii: &[f64]) -> Vec<(usize, usize)> {
    let n = centres.len();
    let mut pairs = Vec::new();
    for i in 0..n {
        for j in (i + 1)..n {
            if (centres[i] - centres[j]).norm() < radii[i] + radii[j] {
                pairs.push((i, j));
            }
        }
    }
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniform numbers in [0, 1) from a 64-bit linear congruential generator seeded with `seed`.
    fn uniform(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// The grid search must find exactly the pairs of the brute-force search (polydisperse, clustered).
    #[test]
    fn grid_search_equals_brute_force() {
        let mut next = uniform(12345);
        for n in [17, 300, 1200] {
            let centres: Vec<Vec3> = (0..n)
                .map(|_| Vec3::new(next(), next(), next() * 0.4) * 4.0 * (n as f64).cbrt())
                .collect();
            // a wide size distribution: a few bodies far above twice the median radius
            let radii: Vec<f64> = (0..n).map(|_| 0.5 + 4.0 * next().powi(6) * 8.0).collect();
            let brute = brute_force_pairs(&centres, &radii);
            assert!(!brute.is_empty());
            assert_eq!(sphere_pairs(&centres, &radii), brute, "n = {n}");
        }
    }

    /// The rows' columns are their transpose, on the grid (with large bodies) and on the brute-force path.
    #[test]
    fn lower_rows_are_the_transpose_of_the_upper_rows() {
        let mut next = uniform(3);
        for n in [17, 1500] {
            let centres: Vec<Vec3> = (0..n)
                .map(|_| Vec3::new(next(), next(), next()) * 2.5 * (n as f64).cbrt())
                .collect();
            let radii: Vec<f64> = (0..n).map(|_| 0.5 + 4.0 * next().powi(8) * 8.0).collect();
            let rows = sphere_pair_rows(&centres, &radii);
            let mut from_lower: Vec<(usize, usize)> = (0..n)
                .flat_map(|j| rows.lower(j).iter().map(move |&i| (i as usize, j)))
                .collect();
            from_lower.sort_unstable();
            let brute = brute_force_pairs(&centres, &radii);
            assert!(brute.len() > n / 2, "n = {n}: too few pairs to test");
            assert_eq!(sphere_pairs(&centres, &radii), brute, "n = {n}");
            assert_eq!(from_lower, brute, "n = {n}");
            assert!((0..n).all(|j| rows.lower(j).windows(2).all(|w| w[0] < w[1])));
        }
    }

    /// A sphere of radius 1e12 cells (an integrator's wild trial state: an attitude quaternion of huge norm) among
    /// a pile: the search finishes at once (a cell scan would walk 1e24 cell rows) and finds the brute-force pairs.
    #[test]
    fn huge_sphere_scans_the_bodies_instead_of_the_cells() {
        let mut next = uniform(7);
        let n = 300;
        let centres: Vec<Vec3> = (0..n).map(|_| Vec3::new(next(), next(), next()) * 20.0).collect();
        let mut radii: Vec<f64> = (0..n).map(|_| 0.5 + 0.3 * next()).collect();
        radii[17] = 1e12;
        let pairs = sphere_pairs(&centres, &radii);
        assert_eq!(pairs, brute_force_pairs(&centres, &radii));
        assert_eq!(pairs.iter().filter(|p| p.0 == 17 || p.1 == 17).count(), n - 1);
    }

    /// Both ways of finding a cell run give the brute-force pairs: the dense start table on a compact pile, the
    /// binary search once two far bodies make the grid's box too large for the table.
    #[test]
    fn dense_table_and_binary_search_both_equal_brute_force() {
        let mut next = uniform(99);
        let n = 2000;
        let mut centres: Vec<Vec3> = (0..n).map(|_| Vec3::new(next(), next(), next()) * 22.0).collect();
        let mut radii: Vec<f64> = (0..n).map(|_| 0.5 + 0.3 * next()).collect();
        let cell = 2.0 * 0.65;
        let key = |p: &Vec3| {
            [
                (p.z / cell).floor() as i64,
                (p.y / cell).floor() as i64,
                (p.x / cell).floor() as i64,
            ]
        };
        let mut keys: Vec<[i64; 3]> = centres.iter().map(key).collect();
        keys.sort_unstable();
        assert!(
            DenseStarts::new(&keys, DENSE_CELLS_PER_BODY * n).is_some(),
            "compact pile: dense table"
        );
        assert_eq!(sphere_pairs(&centres, &radii), brute_force_pairs(&centres, &radii));
        centres.push(Vec3::new(5e4, -3e4, 1e4));
        centres.push(Vec3::new(5e4 + 1.0, -3e4, 1e4));
        radii.extend([0.6, 0.6]);
        keys.extend([key(&centres[n]), key(&centres[n + 1])]);
        keys.sort_unstable();
        assert!(
            DenseStarts::new(&keys, DENSE_CELLS_PER_BODY * (n + 2)).is_none(),
            "far bodies: no table"
        );
        let pairs = sphere_pairs(&centres, &radii);
        assert!(pairs.contains(&(n, n + 1)));
        assert_eq!(pairs, brute_force_pairs(&centres, &radii));
    }
}
