//! A cell grid of the neighbour list's anchors, kept up to date as single particles are re-listed, so that re-listing
//! one particle costs the cells around it instead of a pass over every particle (the cell method of molecular
//! dynamics, e.g. Rapaport, *The Art of Molecular Dynamics Simulation*, §3.4; Richardson11 §2.1 uses a tree for the
//! same search). Used by the stepper (`hard::stepper`) for the Verlet list with skins.
//!
//! Every particle k has a reach `ρ_k = R_k + L_k` (radius plus travel allowance) around its anchor `a_k`; a pair is a
//! candidate when `|a_i − a_j| < ρ_i + ρ_j`. Particles with `ρ ≤ ρ_ref` are filed in cubic cells of side at least
//! `4 ρ_ref` covering a box around the anchors; the others (fast particles with a long allowance, or anchors outside
//! the box) are kept loose in a list that every query scans, and when that list grows the box is laid out again
//! around the current anchors. A query for particle k visits the cells its cube of half-side `ρ_k + ρ_ref` overlaps
//! (at most 8 for `ρ_k ≤ ρ_ref`): any filed j with `|a_j − a_k| < ρ_k + ρ_j ≤ ρ_k + ρ_ref` has its anchor in that
//! cube, so nothing is missed. Each entry carries the anchor, radius and allowance, so the exact test reads only the
//! cell. The order in which partners are found depends on the history of the cells; the stepper's results never
//! depend on that order (its event queue orders events completely).

use crate::math::Vec3;

/// What the grid holds of one particle: its anchor, radius and allowance (m) when it was filed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Entry {
    /// Anchor (m).
    pub anchor: Vec3,
    /// Radius (m).
    pub radius: f64,
    /// Travel allowance (m).
    pub allowance: f64,
    /// Particle index.
    pub k: usize,
}

impl Entry {
    /// The reach `R + L` (m).
    pub fn reach(&self) -> f64 {
        self.radius + self.allowance
    }
}

/// Where a particle is filed.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Slot {
    /// Not filed.
    None,
    /// In the cell with this linear index.
    Cell(usize),
    /// In the loose list.
    Loose,
}

/// `⌊q⌋` as an integer (saturating like `as`), without the library call that `f64::floor` costs on the baseline
/// x86-64 target.
pub(crate) fn floor_i64(q: f64) -> i64 {
    let i = q as i64;
    if (i as f64) > q { i - 1 } else { i }
}

/// The anchors filed by cell (module doc).
#[derive(Debug, Clone, Default)]
pub struct AnchorGrid {
    /// Largest reach of a particle filed in a cell (m).
    rho_ref: f64,
    /// Cell side (m), at least `4 ρ_ref`.
    side: f64,
    /// Corner of the box of cells (m).
    lo: Vec3,
    /// Cells along x, y, z.
    dims: [i64; 3],
    /// Entries per cell, x fastest.
    cells: Vec<Vec<Entry>>,
    /// Entries outside the box or with a reach above `ρ_ref`.
    loose: Vec<Entry>,
    /// Loose entries right after the last lay-out.
    loose_after_lay_out: usize,
    slots: Vec<Slot>,
}

impl AnchorGrid {
    /// A grid holding `entries` for particles with indices below `n`: `ρ_ref` is the largest reach but at most twice
    /// the median (a few fast particles do not inflate the cells; they are kept loose), and the box covers the anchors
    /// with a margin.
    pub fn new(n: usize, entries: impl IntoIterator<Item = Entry>) -> AnchorGrid {
        let mut g = AnchorGrid {
            slots: vec![Slot::None; n],
            ..Default::default()
        };
        g.lay_out(entries.into_iter().collect());
        g
    }

    /// Chooses `ρ_ref` and the box for `entries` and files them all.
    fn lay_out(&mut self, entries: Vec<Entry>) {
        let mut r: Vec<f64> = entries
            .iter()
            .map(Entry::reach)
            .filter(|x| x.is_finite() && *x > 0.0)
            .collect();
        r.sort_by(f64::total_cmp);
        self.rho_ref = match r.last() {
            Some(&max) => max.min(2.0 * r[r.len() / 2]),
            None => 1.0,
        };
        let fits = |e: &Entry| e.reach() <= self.rho_ref && e.anchor.iter().all(|x| x.is_finite());
        let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
        for e in entries.iter().filter(|e| fits(e)) {
            lo = lo.inf(&e.anchor);
            hi = hi.sup(&e.anchor);
        }
        let mut side = 4.0 * self.rho_ref;
        if lo.x > hi.x {
            (lo, hi) = (Vec3::zeros(), Vec3::zeros());
        }
        // A quarter of the extent and two cells of margin, so that particles wandering off are rarely loose.
        let pad = (hi - lo) * 0.25 + Vec3::repeat(2.0 * side);
        let (lo, hi) = (lo - pad, hi + pad);
        let max_cells = 8.0 * self.slots.len() as f64 + 4096.0;
        let count = |side: f64| {
            let d = (hi - lo) / side;
            (d.x.ceil().max(1.0), d.y.ceil().max(1.0), d.z.ceil().max(1.0))
        };
        let (x, y, z) = count(side);
        if x * y * z > max_cells {
            // Spread-out anchors: larger cells rather than a huge, empty box.
            side *= (x * y * z / max_cells).cbrt();
        }
        let (x, y, z) = count(side);
        self.side = side;
        self.lo = lo;
        self.dims = [x as i64, y as i64, z as i64];
        self.cells = vec![Vec::new(); (x * y * z) as usize];
        self.loose.clear();
        self.slots.iter_mut().for_each(|s| *s = Slot::None);
        for e in entries {
            self.file(e);
        }
        self.loose_after_lay_out = self.loose.len();
    }

    /// The cell coordinates of `p` (may lie outside the box).
    fn coords(&self, p: &Vec3) -> [i64; 3] {
        let q = (p - self.lo) / self.side;
        [floor_i64(q.x), floor_i64(q.y), floor_i64(q.z)]
    }

    /// The linear index of the cell at `c`, if inside the box.
    fn index(&self, c: [i64; 3]) -> Option<usize> {
        let inside = (0..3).all(|a| c[a] >= 0 && c[a] < self.dims[a]);
        inside.then(|| ((c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]) as usize)
    }

    fn file(&mut self, e: Entry) {
        let cell = (e.reach() <= self.rho_ref && e.anchor.iter().all(|x| x.is_finite()))
            .then(|| self.index(self.coords(&e.anchor)))
            .flatten();
        match cell {
            Some(c) => {
                self.cells[c].push(e);
                self.slots[e.k] = Slot::Cell(c);
            }
            None => {
                self.loose.push(e);
                self.slots[e.k] = Slot::Loose;
            }
        }
    }

    /// Removes particle `k` from wherever it is filed.
    pub fn remove(&mut self, k: usize) {
        let list = match self.slots.get(k).copied().unwrap_or(Slot::None) {
            Slot::None => return,
            Slot::Cell(c) => &mut self.cells[c],
            Slot::Loose => &mut self.loose,
        };
        if let Some(at) = list.iter().position(|e| e.k == k) {
            list.swap_remove(at);
        }
        self.slots[k] = Slot::None;
    }

    /// Files `e` in place of whatever was filed for its particle. When the loose list has grown well beyond its size
    /// after the last lay-out (anchors have left the box, or allowances have grown), the grid is laid out again
    /// around the current entries (amortised: that takes many insertions).
    pub fn insert(&mut self, e: Entry) {
        self.remove(e.k);
        self.file(e);
        if self.loose.len() > 2 * self.loose_after_lay_out + 64 + self.slots.len() / 16 {
            let all: Vec<Entry> = self.cells.iter().flatten().chain(&self.loose).copied().collect();
            self.lay_out(all);
        }
    }

    /// Calls `visit(e)` for every filed entry that may satisfy `|a_j − anchor| < reach + ρ_j`: every entry in the
    /// cells that the cube of half-side `reach + ρ_ref` around `anchor` overlaps, and every loose one. The caller
    /// applies the exact test.
    pub fn query(&self, anchor: &Vec3, reach: f64, mut visit: impl FnMut(&Entry)) {
        // A hair more than the exact half-side, so that rounding in the caller's squared-distance test cannot
        // accept a pair whose anchor fell just outside the cube.
        let half = (reach + self.rho_ref) * (1.0 + 1e-9);
        let lo = self.coords(&(anchor - Vec3::repeat(half)));
        let hi = self.coords(&(anchor + Vec3::repeat(half)));
        // Clipped to the box: anchors outside it are loose.
        let (x0, x1) = (lo[0].max(0), hi[0].min(self.dims[0] - 1));
        let (y0, y1) = (lo[1].max(0), hi[1].min(self.dims[1] - 1));
        let (z0, z1) = (lo[2].max(0), hi[2].min(self.dims[2] - 1));
        for z in z0..=z1 {
            for y in y0..=y1 {
                let row = ((z * self.dims[1] + y) * self.dims[0]) as usize;
                for x in x0..=x1 {
                    self.cells[row + x as usize].iter().for_each(&mut visit);
                }
            }
        }
        self.loose.iter().for_each(visit);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The grid's candidates contain every pair the exact criterion accepts, whatever the moves in between
    /// (anchors wandering out of the box, one very long allowance).
    #[test]
    fn query_finds_every_pair_after_moves() {
        let n = 200;
        let mut seed = 12345u64;
        let mut rnd = move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let entry = |k: usize, anchor: Vec3, allowance: f64| Entry {
            anchor,
            radius: 0.02,
            allowance,
            k,
        };
        let mut e: Vec<Entry> = (0..n)
            .map(|k| {
                entry(
                    k,
                    Vec3::new(rnd(), rnd(), rnd()) * 2.0 - Vec3::repeat(1.0),
                    0.08 * rnd(),
                )
            })
            .collect();
        e[7].allowance = 0.9;
        let mut g = AnchorGrid::new(n, e.clone());
        for round in 0..2000 {
            let k = round % n;
            // A drift upwards, so that anchors leave the box and it is laid out again.
            let step = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.2) * 0.3;
            e[k] = entry(k, e[k].anchor + step, 0.15 * rnd());
            g.insert(e[k]);
            let mut found = Vec::new();
            g.query(&e[k].anchor, e[k].reach(), |x| found.push(x.k));
            for j in 0..n {
                let r = e[k].reach() + e[j].reach();
                if j != k && (e[j].anchor - e[k].anchor).norm_squared() < r * r {
                    assert!(found.contains(&j), "round {round}: pair ({k}, {j}) missed");
                }
            }
            if round % 500 == 0 {
                g.remove(k);
                let mut found = Vec::new();
                g.query(&e[k].anchor, e[k].reach(), |x| found.push(x.k));
                assert!(!found.contains(&k), "removed entries are gone");
                g.insert(e[k]);
            }
        }
    }
}
