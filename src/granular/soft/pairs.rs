//! The pair contacts of a force evaluation (Zhang17 Eq. 1, the contact law of Eqs. 1–12): a Verlet list in compressed
//! rows with the pair spring histories beside it, evaluated on one thread or many with the same bits.
//!
//! List: candidate pairs `i < j` within the radii sum plus a skin from [`crate::geometry::neighbours`], rebuilt (in
//! parallel) when a sphere moved more than half the skin; row `i` holds partners `j > i` ascending, each with a spring
//! slot, and touching pairs' springs carry over a rebuild. Order: rows are cut into blocks of [`ROWS_PER_BLOCK`];
//! sphere `p` sums its own block's pairs `(k, p)`, then its row, then earlier blocks from the nearest back, each by
//! ascending index. Serially (blocks last to first) each pair is added to both spheres as evaluated; in parallel,
//! pairs crossing a block store the partner's share (48 bytes) and a pass adds the shares in that order. So the
//! forces depend neither on the thread count nor on when the list was rebuilt (a non-touching pair adds +0). Scalar
//! sums (spring energy, dissipation) go per block in row order, then over blocks in order.

use crate::geometry::neighbours::sphere_pair_rows;
use crate::granular::soft::contact::{Kinematics, Law, Output, Springs, evaluate_inner};
use crate::granular::soft::ordered_sum::SUM_CHUNK;
use crate::granular::soft::particle::Particle;
use crate::math::Vec3;
use crate::phase::{Kind, Phase};
use rayon::prelude::*;

static PHASE_CHECK: Phase = Phase::new("soft.verlet_check", Kind::Parallel);
static PHASE_REBUILD: Phase = Phase::new("soft.verlet_rebuild", Kind::Parallel);
static PHASE_PAIRS: Phase = Phase::new("soft.pairs", Kind::Parallel);
static PHASE_FINISH: Phase = Phase::new("soft.pair_finish", Kind::Parallel);
static PHASE_TOTALS: Phase = Phase::new("soft.pair_totals", Kind::Serial);

/// Rows (spheres) per block of the parallel evaluation, and per partial sum of the scalar totals. Fixed, so that
/// the totals do not depend on the number of threads; 128 rows give 300 blocks at 40 000 spheres, ~20 per thread
/// at 16 threads, for the work stealing to balance.
pub const ROWS_PER_BLOCK: usize = 128;

/// A pair contact's record at the last force evaluation (for tests and diagnostics).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactRecord {
    /// Particle `i`.
    pub i: usize,
    /// Partner: particle index, or `n_particles + wall index` for a wall.
    pub j: usize,
    /// Overlap (m).
    pub overlap: f64,
    /// The law's output.
    pub output: Output,
}

/// A list entry's springs, or none (the pair did not touch at the last evaluation). "None" is a NaN twist angle
/// rather than an `Option`, so that a slot is 80 and not 88 bytes; a touching pair's twist is always finite (a NaN
/// anywhere in the state stops the run first).
#[derive(Debug, Clone, Copy)]
struct Slot(Springs);

impl Slot {
    /// The empty slot.
    fn empty() -> Self {
        Slot(Springs {
            twist: f64::NAN,
            ..Springs::default()
        })
    }

    /// The springs, if any.
    #[inline(always)]
    fn get(&self) -> Option<Springs> {
        (!self.0.twist.is_nan()).then_some(self.0)
    }
}

/// What sphere `j` of a pair `(k, j)` evaluated in an earlier block receives: minus `force`, plus `torque`.
#[derive(Debug, Clone, Copy, Default)]
struct Share {
    force: Vec3,
    torque: Vec3,
}

/// What one touching pair contributes at one evaluation.
#[derive(Debug, Clone, Copy)]
struct PairHit {
    /// Overlap (m).
    overlap: f64,
    /// The smaller radius (m).
    r_small: f64,
    /// The law's output.
    out: Output,
}

/// The scalar sums of the pair contacts of one evaluation (or one block of rows).
#[derive(Debug, Clone, Default)]
pub struct PairTotals {
    /// Energy stored in the pair springs (J; 0 unless asked for).
    pub spring_energy: f64,
    /// Energy dissipated by the pairs over the step (J).
    pub dissipated: f64,
    /// Largest overlap over the smaller radius (dimensionless).
    pub max_overlap_fraction: f64,
    /// Touching pairs.
    pub contacts: usize,
    /// Per-contact records, in key order `(i, j)` (when asked for).
    pub records: Vec<ContactRecord>,
    /// `Σ base(p).1` over the spheres ([`PairList::evaluate`]; J).
    pub base_energy: f64,
}

impl PairTotals {
    /// Adds pair `(i, j)`'s contribution.
    #[inline(always)]
    fn add(&mut self, i: usize, j: usize, hit: &PairHit, records: bool) {
        let out = &hit.out;
        self.spring_energy += out.stored_energy;
        self.dissipated += out.dissipated;
        // max(m, x/r) with the division only when x/r may exceed m (rounding of m r is far below 1e-12); the
        // result is the exact largest quotient, whatever the order.
        let max = &mut self.max_overlap_fraction;
        if hit.overlap >= *max * hit.r_small * (1.0 - 1e-12) {
            *max = max.max(hit.overlap / hit.r_small);
        }
        self.contacts += 1;
        if records {
            self.records.push(ContactRecord {
                i,
                j,
                overlap: hit.overlap,
                output: *out,
            });
        }
    }
}

/// Where the sums of a block's spheres live, and where a pair's partner share goes.
trait Sink {
    /// Sphere `i`'s sums so far.
    fn get(&mut self, i: usize) -> (Vec3, Vec3);
    /// Sets sphere `i`'s sums.
    fn set(&mut self, i: usize, sums: (Vec3, Vec3));
    /// List entry `q` = `(i, j)`: the pair's output if it touches.
    fn partner(&mut self, q: usize, j: usize, out: Option<&Output>);
}

/// Adds every pair to both spheres at once (one thread).
struct Direct<'a> {
    load: &'a mut [(Vec3, Vec3)],
}

impl Sink for Direct<'_> {
    #[inline(always)]
    fn get(&mut self, i: usize) -> (Vec3, Vec3) {
        self.load[i]
    }

    #[inline(always)]
    fn set(&mut self, i: usize, sums: (Vec3, Vec3)) {
        self.load[i] = sums;
    }

    #[inline(always)]
    fn partner(&mut self, _q: usize, j: usize, out: Option<&Output>) {
        if let Some(out) = out {
            let l = &mut self.load[j];
            l.0 -= out.force_i;
            l.1 += out.torque_j;
        }
    }
}

/// One block of rows `first..end` on its own thread: partners inside it at once, partners beyond it stored.
struct Blocked<'a> {
    /// The block's spheres' sums (`first..end`).
    load: &'a mut [(Vec3, Vec3)],
    first: usize,
    end: usize,
    /// The shares of the block's list entries, from entry `q0` on.
    shares: &'a mut [Share],
    q0: usize,
}

impl Sink for Blocked<'_> {
    #[inline(always)]
    fn get(&mut self, i: usize) -> (Vec3, Vec3) {
        self.load[i - self.first]
    }

    #[inline(always)]
    fn set(&mut self, i: usize, sums: (Vec3, Vec3)) {
        self.load[i - self.first] = sums;
    }

    #[inline(always)]
    fn partner(&mut self, q: usize, j: usize, out: Option<&Output>) {
        if j < self.end {
            if let Some(out) = out {
                let l = &mut self.load[j - self.first];
                l.0 -= out.force_i;
                l.1 += out.torque_j;
            }
        } else {
            self.shares[q - self.q0] = out.map_or_else(Share::default, |o| Share {
                force: o.force_i,
                torque: o.torque_j,
            });
        }
    }
}

/// The kinematics of spheres `a` (i) and `b` (j) if they overlap.
#[inline(always)]
fn pair_kinematics(a: &Particle, b: &Particle) -> Option<Kinematics> {
    let d = b.position - a.position;
    let reach = a.radius + b.radius;
    let dist2 = d.norm_squared();
    if dist2 >= reach * reach {
        return None;
    }
    let dist = dist2.sqrt();
    let overlap = reach - dist;
    if overlap <= 0.0 || dist <= 0.0 {
        return None;
    }
    let n = d * (1.0 / dist);
    let (li, lj) = (a.radius - 0.5 * overlap, b.radius - 0.5 * overlap);
    let inv = 1.0 / (reach * (a.mass + b.mass));
    let u = b.velocity - a.velocity - b.spin.cross(&n) * lj - a.spin.cross(&n) * li;
    Some(Kinematics {
        normal: n,
        overlap,
        lever_i: li,
        lever_j: lj,
        relative_velocity: u,
        spin_i: a.spin,
        spin_j: b.spin,
        // R = r_i r_j/(r_i + r_j) and μ = m_i m_j/(m_i + m_j) with one division.
        r_eff: a.radius * b.radius * (a.mass + b.mass) * inv,
        mass_eff: a.mass * b.mass * reach * inv,
    })
}

/// Evaluates the pair of spheres `a`, `b` with the springs of its slot, and updates the slot (emptied if they do
/// not touch).
#[inline(always)]
fn pair_contact<const SIZES: bool, const STORED: bool>(
    a: &Particle,
    b: &Particle,
    law: &Law,
    slot: &mut Slot,
    dt: f64,
) -> Option<PairHit> {
    let Some(kin) = pair_kinematics(a, b) else {
        *slot = Slot::empty();
        return None;
    };
    let mut springs = slot.get().unwrap_or_else(|| Springs::new(kin.normal));
    let out = evaluate_inner::<SIZES, STORED>(law, &kin, &mut springs, dt);
    *slot = Slot(springs);
    Some(PairHit {
        overlap: kin.overlap,
        r_small: a.radius.min(b.radius),
        out,
    })
}

/// A vector laid out in rows (`start[i]..start[i + 1]` is row `i`), every entry `value` until `fill(i, row)` fills
/// row `i`; rows are filled in parallel, in tasks of [`ROWS_PER_BLOCK`] rows.
fn fill_rows<T: Copy + Send + Sync>(start: &[usize], value: T, fill: impl Fn(usize, &mut [T]) + Sync) -> Vec<T> {
    let rows = start.len().saturating_sub(1);
    let mut out = vec![value; start.last().copied().unwrap_or(0)];
    let mut pieces = Vec::with_capacity(rows.div_ceil(ROWS_PER_BLOCK));
    let mut rest = &mut out[..];
    for first in (0..rows).step_by(ROWS_PER_BLOCK) {
        let end = (first + ROWS_PER_BLOCK).min(rows);
        let (piece, tail) = std::mem::take(&mut rest).split_at_mut(start[end] - start[first]);
        pieces.push((first..end, piece));
        rest = tail;
    }
    pieces.into_par_iter().for_each(|(block, piece)| {
        let offset = start[block.start];
        for i in block {
            fill(i, &mut piece[start[i] - offset..start[i + 1] - offset]);
        }
    });
    out
}

/// The list and what an evaluation needs of it.
struct Rows<'a> {
    particles: &'a [Particle],
    law: &'a Law,
    dt: f64,
    row_start: &'a [usize],
    cols: &'a [u32],
    records: bool,
}

impl Rows<'_> {
    /// Evaluates the block of rows `rows` in order (their slots from list entry `q0` on), each pair in row order,
    /// handing the pairs to `sink`; returns the block's scalar sums. Nothing is added to the block's spheres
    /// before: rows of later blocks only add to partners beyond them.
    #[inline(always)]
    fn block<const SIZES: bool, const STORED: bool>(
        &self,
        rows: std::ops::Range<usize>,
        slots: &mut [Slot],
        q0: usize,
        sink: &mut impl Sink,
    ) -> PairTotals {
        let mut totals = PairTotals::default();
        for i in rows.clone() {
            sink.set(i, (Vec3::zeros(), Vec3::zeros()));
        }
        for i in rows {
            let a = &self.particles[i];
            // sphere i's sums so far (pairs (k, i) of this block) held in registers over its row
            let (mut force, mut torque) = sink.get(i);
            for q in self.row_start[i]..self.row_start[i + 1] {
                let j = self.cols[q] as usize;
                let hit = pair_contact::<SIZES, STORED>(a, &self.particles[j], self.law, &mut slots[q - q0], self.dt);
                if let Some(hit) = &hit {
                    force += hit.out.force_i;
                    torque += hit.out.torque_i;
                    totals.add(i, j, hit, self.records);
                }
                sink.partner(q, j, hit.as_ref().map(|h| &h.out));
            }
            sink.set(i, (force, torque));
        }
        totals
    }
}

/// The Verlet list of the pair contacts, their springs and the buffers of an evaluation.
#[derive(Debug, Clone, Default)]
pub struct PairList {
    /// The skin (m): pairs closer than the sum of the radii plus the skin are listed.
    skin: f64,
    /// `row_start[i]..row_start[i + 1]`: the list entries of row `i` (`n + 1` values; empty before a build).
    row_start: Vec<usize>,
    /// Per entry: the partner `j`.
    cols: Vec<u32>,
    /// Per entry: the springs if the pair touched at the last evaluation.
    slots: Vec<Slot>,
    /// `cross_start[p]..cross_start[p + 1]`: sphere `p`'s entries `(k, p)` with `k` in an earlier block, in
    /// `cross`, in the order they are added: by block from the nearest to the first, ascending `k` in each.
    cross_start: Vec<usize>,
    /// Entry indices (see `cross_start`).
    cross: Vec<u32>,
    /// Per entry: the partner's share, stored by the parallel evaluation for entries that cross a block.
    shares: Vec<Share>,
    /// Per sphere: the contact force and torque of the evaluation under way.
    load: Vec<(Vec3, Vec3)>,
    /// The centres at the last build.
    origin: Vec<Vec3>,
    /// Whether the list is stale, as found by a pass that already compared every sphere's current position with
    /// `origin` ([`PairList::moved_too_far`]); taken by the next evaluation instead of checking again.
    checked: Option<bool>,
}

impl PairList {
    /// The bytes its buffers hold (capacity, not length): the list's part of `SoftSystem::heap_bytes`.
    pub fn heap_bytes(&self) -> usize {
        use crate::math::vec_bytes;
        vec_bytes(&self.row_start)
            + vec_bytes(&self.cols)
            + vec_bytes(&self.slots)
            + vec_bytes(&self.cross_start)
            + vec_bytes(&self.cross)
            + vec_bytes(&self.shares)
            + vec_bytes(&self.load)
            + vec_bytes(&self.origin)
    }

    /// An empty list with skin `skin` (m).
    pub fn new(skin: f64) -> Self {
        PairList {
            skin,
            ..PairList::default()
        }
    }

    /// Entries of the list.
    pub fn len(&self) -> usize {
        self.cols.len()
    }

    /// Whether the list has no entry.
    pub fn is_empty(&self) -> bool {
        self.cols.is_empty()
    }

    /// The rows as `(i, entries)`.
    fn rows(&self) -> impl Iterator<Item = (usize, std::ops::Range<usize>)> + '_ {
        self.row_start.windows(2).enumerate().map(|(i, w)| (i, w[0]..w[1]))
    }

    /// The pairs `(i, j)` that touched at the last evaluation, in key order.
    pub fn touching(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.rows().flat_map(move |(i, r)| {
            r.filter(move |&q| self.slots[q].get().is_some())
                .map(move |q| (i, self.cols[q] as usize))
        })
    }

    /// Calls `f(i, j)` for every pair that touched at the last evaluation, in parallel (blocks of rows), in no
    /// particular order.
    pub fn for_each_touching(&self, f: impl Fn(usize, usize) + Sync) {
        let rows = self.row_start.len().saturating_sub(1);
        (0..rows.div_ceil(ROWS_PER_BLOCK)).into_par_iter().for_each(|b| {
            for i in b * ROWS_PER_BLOCK..((b + 1) * ROWS_PER_BLOCK).min(rows) {
                for q in self.row_start[i]..self.row_start[i + 1] {
                    if self.slots[q].get().is_some() {
                        f(i, self.cols[q] as usize);
                    }
                }
            }
        });
    }

    /// The spring histories of the pairs that touched at the last evaluation, in key order `(i, j)`.
    pub fn springs(&self) -> Vec<((usize, usize), Springs)> {
        self.rows()
            .flat_map(|(i, r)| r.filter_map(move |q| self.slots[q].get().map(|s| ((i, self.cols[q] as usize), s))))
            .collect()
    }

    /// Replaces the springs by `springs` (keys `(i, j)`, `i < j < n`; others are dropped) for `n` spheres; the next
    /// evaluation rebuilds the list and carries them over.
    pub fn set_springs(&mut self, n: usize, mut springs: Vec<((usize, usize), Springs)>) {
        springs.retain(|((i, j), _)| i < j && *j < n);
        springs.sort_by_key(|e| e.0);
        springs.dedup_by_key(|e| e.0);
        let mut row_start = vec![0; n + 1];
        for ((i, _), _) in &springs {
            row_start[i + 1] += 1;
        }
        for i in 0..n {
            row_start[i + 1] += row_start[i];
        }
        self.row_start = row_start;
        self.cols = springs.iter().map(|((_, j), _)| *j as u32).collect();
        self.slots = springs.into_iter().map(|(_, s)| Slot(s)).collect();
        self.cross_start.clear();
        self.cross.clear();
        self.origin.clear();
    }

    /// Rebuilds the list if a sphere has moved more than half the skin since the last build (or the spheres are
    /// not those of the last build).
    fn refresh(&mut self, particles: &[Particle]) {
        let limit = 0.25 * self.skin * self.skin;
        let checked = self.checked.take();
        let stale = self.origin.len() != particles.len()
            || checked.unwrap_or_else(|| {
                PHASE_CHECK.time(|| {
                    particles
                        .par_iter()
                        .with_min_len(4096)
                        .zip(&self.origin)
                        .any(|(p, o)| (p.position - o).norm_squared() > limit)
                })
            });
        if stale {
            PHASE_REBUILD.time(|| self.rebuild(particles));
        }
    }

    fn rebuild(&mut self, particles: &[Particle]) {
        let n = particles.len();
        let half_skin = 0.5 * self.skin;
        let (centres, reach): (Vec<Vec3>, Vec<f64>) =
            particles.par_iter().map(|p| (p.position, p.radius + half_skin)).unzip();
        let rows = sphere_pair_rows(&centres, &reach);
        // Carry the springs of touching pairs over, row by row: old and new rows are both ascending.
        let old_rows = self.row_start.len().saturating_sub(1);
        let slots = fill_rows(&rows.upper_start, Slot::empty(), |i, out| {
            if i >= old_rows {
                return;
            }
            let r = self.row_start[i]..self.row_start[i + 1];
            let (old_cols, old_slots) = (&self.cols[r.clone()], &self.slots[r]);
            let mut k = 0;
            for (slot, &j) in out.iter_mut().zip(rows.upper(i)) {
                while k < old_cols.len() && old_cols[k] < j {
                    k += 1;
                }
                if k < old_cols.len() && old_cols[k] == j {
                    *slot = old_slots[k];
                }
            }
        });
        // Per sphere p, the entries (k, p) with k in an earlier block than p's, in the order they are added: by
        // block from the nearest to the first, ascending k in each.
        let crossing = |p: usize| {
            let lower = rows.lower(p);
            &lower[..lower.partition_point(|&k| (k as usize) < p / ROWS_PER_BLOCK * ROWS_PER_BLOCK)]
        };
        let mut cross_start = Vec::with_capacity(n + 1);
        cross_start.push(0);
        let mut total = 0;
        for p in 0..n {
            total += crossing(p).len();
            cross_start.push(total);
        }
        let cross = fill_rows(&cross_start, 0u32, |p, out| {
            let ks = crossing(p);
            let mut filled = 0;
            let mut end = ks.len();
            while end > 0 {
                let block = ks[end - 1] as usize / ROWS_PER_BLOCK;
                let start = ks[..end].partition_point(|&k| (k as usize) / ROWS_PER_BLOCK < block);
                for &k in &ks[start..end] {
                    let k = k as usize;
                    let at = rows
                        .upper(k)
                        .binary_search(&(p as u32))
                        .expect("the columns are the rows' transpose");
                    out[filled] = (rows.upper_start[k] + at) as u32;
                    filled += 1;
                }
                end = start;
            }
        });
        self.row_start = rows.upper_start;
        self.cols = rows.upper;
        self.slots = slots;
        self.cross_start = cross_start;
        self.cross = cross;
        self.origin = centres;
    }

    /// Whether sphere `k`, now at `position` (m), has moved more than half the skin since the last build (true
    /// for a sphere the list has not seen). A pass that asks this of every sphere at its final position hands the
    /// answer on with [`PairList::set_checked`], which saves the evaluation a pass over the spheres.
    #[inline(always)]
    pub fn moved_too_far(&self, k: usize, position: &Vec3) -> bool {
        self.origin
            .get(k)
            .is_none_or(|o| (position - o).norm_squared() > 0.25 * self.skin * self.skin)
    }

    /// Hands on whether any sphere has moved too far ([`PairList::moved_too_far`]); valid until the positions
    /// change, which the caller guarantees (the next evaluation takes it).
    pub fn set_checked(&mut self, stale: bool) {
        self.checked = Some(stale);
    }

    /// Evaluates every listed pair for a step of `dt` (s) with the constants `law`, refreshing the list first:
    /// sets `forces[p] = base(p).0 + (contact force on p)` and `torques[p]` (the contact torque) for every sphere,
    /// and returns the scalar sums, with `Σ base(p).1` (the non-contact potential energy) summed by
    /// `ordered_sum`'s chunks in `PairTotals::base_energy`. `SIZES`: the outputs' `|M_R|`, `|M_T|` and per-contact records (only samples want
    /// them); `STORED`: the springs' stored energy.
    pub fn evaluate<const SIZES: bool, const STORED: bool>(
        &mut self,
        particles: &[Particle],
        law: &Law,
        dt: f64,
        base: impl Fn(usize) -> (Vec3, f64) + Sync,
        forces: &mut Vec<Vec3>,
        torques: &mut Vec<Vec3>,
    ) -> PairTotals {
        self.refresh(particles);
        let n = particles.len();
        let parallel = rayon::current_num_threads() > 1 && n > ROWS_PER_BLOCK;
        self.load.resize(n, (Vec3::zeros(), Vec3::zeros()));
        let rows = Rows {
            particles,
            law,
            dt,
            row_start: &self.row_start,
            cols: &self.cols,
            records: SIZES,
        };
        let blocks = n.div_ceil(ROWS_PER_BLOCK);
        let block_rows = |b: usize| b * ROWS_PER_BLOCK..((b + 1) * ROWS_PER_BLOCK).min(n);
        let mut partial: Vec<PairTotals> = PHASE_PAIRS.time(|| {
            if parallel {
                self.shares.resize(self.cols.len(), Share::default());
                // Cut slots, shares and sums at the blocks' boundaries: each block owns its pieces.
                let mut pieces = Vec::with_capacity(blocks);
                let (mut slots, mut shares, mut load) = (&mut self.slots[..], &mut self.shares[..], &mut self.load[..]);
                for b in 0..blocks {
                    let r = block_rows(b);
                    let entries = rows.row_start[r.end] - rows.row_start[r.start];
                    let (s, s_rest) = std::mem::take(&mut slots).split_at_mut(entries);
                    let (h, h_rest) = std::mem::take(&mut shares).split_at_mut(entries);
                    let (l, l_rest) = std::mem::take(&mut load).split_at_mut(r.len());
                    (slots, shares, load) = (s_rest, h_rest, l_rest);
                    pieces.push((r, s, h, l));
                }
                pieces
                    .into_par_iter()
                    .map(|(r, slots, shares, load)| {
                        let q0 = rows.row_start[r.start];
                        let mut sink = Blocked {
                            load,
                            first: r.start,
                            end: r.end,
                            shares,
                            q0,
                        };
                        rows.block::<SIZES, STORED>(r, slots, q0, &mut sink)
                    })
                    .collect()
            } else {
                let mut sink = Direct { load: &mut self.load };
                let mut partial: Vec<PairTotals> = (0..blocks)
                    .rev()
                    .map(|b| rows.block::<SIZES, STORED>(block_rows(b), &mut self.slots, 0, &mut sink))
                    .collect();
                partial.reverse();
                partial
            }
        });
        let base_energy = PHASE_FINISH.time(|| {
            forces.resize(n, Vec3::zeros());
            torques.resize(n, Vec3::zeros());
            let (load, shares, cross_start, cross) = (&self.load, &self.shares, &self.cross_start, &self.cross);
            // chunks of SUM_CHUNK spheres, so that the energy is summed as `ordered_sum` sums
            let chunks: Vec<f64> = forces
                .par_chunks_mut(SUM_CHUNK)
                .zip(torques.par_chunks_mut(SUM_CHUNK))
                .enumerate()
                .map(|(c, (fs, ts))| {
                    let mut energy = 0.0;
                    for (k, (f, t)) in fs.iter_mut().zip(ts).enumerate() {
                        let p = c * SUM_CHUNK + k;
                        let (mut force, mut torque) = load[p];
                        if parallel {
                            // the pairs (k, p) of earlier blocks: the end of p's order
                            for &q in &cross[cross_start[p]..cross_start[p + 1]] {
                                let s = &shares[q as usize];
                                force -= s.force;
                                torque += s.torque;
                            }
                        }
                        let (b, e) = base(p);
                        *f = b + force;
                        *t = torque;
                        energy += e;
                    }
                    energy
                })
                .collect();
            chunks.into_iter().fold(0.0, |s, c| s + c)
        });
        PHASE_TOTALS.time(|| {
            let mut totals = PairTotals {
                base_energy,
                ..PairTotals::default()
            };
            for p in &mut partial {
                totals.spring_energy += p.spring_energy;
                totals.dissipated += p.dissipated;
                totals.max_overlap_fraction = totals.max_overlap_fraction.max(p.max_overlap_fraction);
                totals.contacts += p.contacts;
                // blocks in order, rows in order: key order
                totals.records.append(&mut p.records);
            }
            totals
        })
    }
}
