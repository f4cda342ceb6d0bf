//! A cell grid of the neighbour list's anchors, kept up to date as single particles are re-listed, so that re-listing
//! one particle costs the cells around it instead of a pass over every particle (the cell method of molecular
//! dynamics, e.g. Rapaport, *The Art of Molecular Dynamics Simulation*, §3.4; Richardson11 §2.1 uses a tree for the
//! same search). Used by [`super::stepper`] for the Verlet list with skins.
//!
//! Every particle k has a reach `ρ_k = R_k + L_k` (radius plus travel allowance) around its anchor `a_k`; a pair is a
//! candidate when `|a_i − a_j| < ρ_i + ρ_j`. Particles with `ρ ≤ ρ_ref` live in cubic cells of side `2 ρ_ref`
//! (hashed by integer cell coordinates, so the grid needs no bounding box and particles may fly anywhere); the few
//! with a larger reach (fast particles) are kept in a separate list that every query scans. A query for particle k
//! visits the cells its cube of half-side `ρ_k + ρ_ref` overlaps (27 cells for `ρ_k ≤ ρ_ref`): any binned j with
//! `|a_j − a_k| < ρ_k + ρ_j ≤ ρ_k + ρ_ref` has its anchor in that cube, so nothing is missed. The order in which
//! partners are found depends on the history of the cells; the stepper's results never depend on that order (its
//! event queue orders events completely).

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use crate::math::Vec3;

/// A one-multiply hash of a packed cell key (the default SipHash costs more than the rest of a query).
#[derive(Default, Clone, Copy, Debug)]
pub struct CellHasher(u64);

impl Hasher for CellHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut b = [0u8; 8];
            b[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(b));
        }
    }
    fn write_u64(&mut self, v: u64) {
        // Rotate-xor-multiply (the FxHash recipe); the high bits, which the table uses, are well mixed.
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

/// Cells by packed key: 21 bits per coordinate, so cells 2²¹ apart share a key (and a list). That only adds
/// candidates, which the caller's exact test rejects.
type Cells = HashMap<u64, Vec<usize>, BuildHasherDefault<CellHasher>>;

/// The packed key of cell `(x, y, z)`.
fn pack(x: i64, y: i64, z: i64) -> u64 {
    const MASK: u64 = (1 << 21) - 1;
    ((x as u64 & MASK) << 42) | ((y as u64 & MASK) << 21) | (z as u64 & MASK)
}

/// `⌊q⌋` for the cell coordinates (saturating like `as`), without the library call that `f64::floor` costs on
/// the baseline x86-64 target.
fn floor_i64(q: f64) -> i64 {
    let i = q as i64;
    if (i as f64) > q { i - 1 } else { i }
}

/// Where a particle is filed.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Slot {
    /// Not filed (never listed).
    None,
    /// In the cell with this packed key.
    Cell(u64),
    /// In the list of particles with a reach above `ρ_ref`.
    Big,
}

/// The anchors filed by cell (module doc).
#[derive(Debug, Clone, Default)]
pub struct AnchorGrid {
    /// Largest reach `R + L` of a binned particle (m); cells have side `2 ρ_ref`.
    rho_ref: f64,
    cells: Cells,
    big: Vec<usize>,
    slots: Vec<Slot>,
}

impl AnchorGrid {
    /// A grid for `n` particles whose binned reach is at most `rho_ref` (> 0), with nothing filed.
    pub fn new(n: usize, rho_ref: f64) -> AnchorGrid {
        AnchorGrid {
            rho_ref,
            cells: Cells::default(),
            big: Vec::new(),
            slots: vec![Slot::None; n],
        }
    }

    /// The reference reach for a set of reaches: the largest, but at most twice the median, so that a few fast
    /// particles do not inflate the cells (they are filed apart).
    pub fn reference_reach(reaches: &[f64]) -> f64 {
        let mut r: Vec<f64> = reaches.iter().copied().filter(|x| x.is_finite() && *x > 0.0).collect();
        if r.is_empty() {
            return 1.0;
        }
        r.sort_by(f64::total_cmp);
        let median = r[r.len() / 2];
        r[r.len() - 1].min(2.0 * median)
    }

    fn coords(&self, p: &Vec3) -> [i64; 3] {
        let side = 4.0 * self.rho_ref;
        [floor_i64(p.x / side), floor_i64(p.y / side), floor_i64(p.z / side)]
    }

    /// Removes particle `k` from wherever it is filed.
    pub fn remove(&mut self, k: usize) {
        match self.slots[k] {
            Slot::None => {}
            Slot::Cell(key) => {
                if let Some(v) = self.cells.get_mut(&key) {
                    if let Some(at) = v.iter().position(|&x| x == k) {
                        v.swap_remove(at);
                    }
                    if v.is_empty() {
                        self.cells.remove(&key);
                    }
                }
            }
            Slot::Big => {
                if let Some(at) = self.big.iter().position(|&x| x == k) {
                    self.big.swap_remove(at);
                }
            }
        }
        self.slots[k] = Slot::None;
    }

    /// Files particle `k` with anchor `anchor` and reach `reach` (after removing it from its old place).
    pub fn insert(&mut self, k: usize, anchor: &Vec3, reach: f64) {
        self.remove(k);
        // A reach that is not finite or an anchor far beyond the integer cell range goes to the scanned list.
        let c = self.coords(anchor);
        if reach <= self.rho_ref && anchor.iter().all(|x| x.is_finite()) && c.iter().all(|c| c.abs() < 1 << 52) {
            let key = pack(c[0], c[1], c[2]);
            self.cells.entry(key).or_default().push(k);
            self.slots[k] = Slot::Cell(key);
        } else {
            self.big.push(k);
            self.slots[k] = Slot::Big;
        }
    }

    /// Calls `visit(j)` for every filed particle j that may satisfy `|a_j − a_k| < reach + ρ_j` for a particle at
    /// `anchor` with reach `reach`: every binned particle in the cells the cube of half-side `reach + ρ_ref` overlaps,
    /// and every particle filed apart. The caller applies the exact test.
    pub fn query(&self, anchor: &Vec3, reach: f64, mut visit: impl FnMut(usize)) {
        // A hair more than the exact half-side, so that rounding in the caller's squared-distance test cannot
        // accept a pair whose anchor fell just outside the cube.
        let half = (reach + self.rho_ref) * (1.0 + 1e-9);
        let lo = self.coords(&(anchor - Vec3::from_element(half)));
        let hi = self.coords(&(anchor + Vec3::from_element(half)));
        let span = |a: usize| hi[a] as f64 - lo[a] as f64 + 1.0;
        let cells = span(0) * span(1) * span(2);
        if !(cells.is_finite() && cells <= 4.0 * self.cells.len() as f64 + 27.0) {
            // A reach far larger than the cells: walking the occupied cells is cheaper than the empty ones.
            for v in self.cells.values() {
                v.iter().for_each(|&j| visit(j));
            }
        } else {
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        if let Some(v) = self.cells.get(&pack(x, y, z)) {
                            v.iter().for_each(|&j| visit(j));
                        }
                    }
                }
            }
        }
        self.big.iter().for_each(|&j| visit(j));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The grid's candidates contain every pair the exact criterion accepts, whatever the moves in between.
    #[test]
    fn query_finds_every_pair_after_moves() {
        let n = 200;
        let mut seed = 12345u64;
        let mut rnd = move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut anchors: Vec<Vec3> = (0..n)
            .map(|_| Vec3::new(rnd(), rnd(), rnd()) * 2.0 - Vec3::repeat(1.0))
            .collect();
        let mut reach: Vec<f64> = (0..n).map(|_| 0.02 + 0.08 * rnd()).collect();
        reach[7] = 0.9; // one filed apart
        let mut g = AnchorGrid::new(n, AnchorGrid::reference_reach(&reach));
        for k in 0..n {
            g.insert(k, &anchors[k], reach[k]);
        }
        for round in 0..400 {
            let k = round % n;
            anchors[k] += Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * 0.3;
            reach[k] = 0.02 + 0.15 * rnd();
            g.insert(k, &anchors[k], reach[k]);
            let mut found = Vec::new();
            g.query(&anchors[k], reach[k], |j| found.push(j));
            for j in 0..n {
                let r = reach[k] + reach[j];
                if j != k && (anchors[j] - anchors[k]).norm_squared() < r * r {
                    assert!(found.contains(&j), "round {round}: pair ({k}, {j}) missed");
                }
            }
        }
    }
}
