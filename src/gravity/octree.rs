//! Barnes–Hut octree with quadrupole moments and a group walk (Zhang17 §2.1 uses pkdgrav's tree; group walk Barnes
//! 1990, J. Comput. Phys. 87, 161; opening criterion Barnes 1994; single-precision lists after pkdgrav3, Potter,
//! Stadel & Teyssier 2017, Comput. Astrophys. Cosmol. 4, 2).
//!
//! Particles sorted by 63-bit Morton key, nodes depth-first in flat arrays with a "next" index (a stackless walk),
//! split above [`LEAF_SIZE`] to depth 21. Per node: mass `M`, centre `c`, `Q = Σ m (3 d dᵀ − |d|² I)`, side `l`,
//! offset `δ` of `c` from the cube's centre; used whole at `r = p − c` when `|r| > l/θ + δ`, with
//! `φ = −G M/|r| − G rᵀQr / (2|r|⁵)`, `a = −G M r/|r|³ + G (Q r/|r|⁵ − 5/2 (rᵀQr) r/|r|⁷)`. Leaves are used whole
//! only from [`FAR_LEAF_MIN`] particles in trees from [`FAR_LEAVES_FROM`] (on a lattice the octupole small leaves
//! miss adds up coherently); others are summed directly. A bucket (≤ [`BUCKET_SIZE`]) shares one list, a node
//! accepted at the bucket's nearest point, so the error never exceeds the per-particle walk's; fixed-order sums make
//! results independent of the thread count. [`FrozenOctree`] keeps one configuration's lists with the moments
//! recomputed (smooth in the positions). Trees from [`FAR_LEAVES_FROM`] sum in f32 relative to the bucket's centre
//! in power-of-two units (adds ~1e-7 relative rounding only).

use crate::math::Vec3;
use crate::phase::{Kind, Phase};
use rayon::prelude::*;
use std::ops::{Add, AddAssign, Div, Mul, Sub, SubAssign};
use std::sync::atomic::{AtomicU32, Ordering};

// Where a tree evaluation's time goes (see [`crate::phase`]).
static PHASE_KEYS: Phase = Phase::new("gravity.tree_keys", Kind::Parallel);
static PHASE_SUBDIVIDE: Phase = Phase::new("gravity.tree_subdivide", Kind::Parallel);
static PHASE_MOMENTS: Phase = Phase::new("gravity.tree_moments", Kind::Parallel);
static PHASE_WALK: Phase = Phase::new("gravity.tree_walk_sum", Kind::Parallel);
static PHASE_UNSORT: Phase = Phase::new("gravity.tree_unsort", Kind::Parallel);

/// Most particles in a leaf, except at the deepest level.
pub const LEAF_SIZE: usize = 32;
/// Most particles in a bucket of the group walk (a node sharing one interaction list), except at the
/// deepest level.
pub const BUCKET_SIZE: usize = 64;
/// Fewest particles of a leaf that may be used whole (by its multipole); smaller leaves are always summed
/// directly (see the module header: lattice leaves of four would add their errors coherently).
pub const FAR_LEAF_MIN: usize = 5;
/// Fewest particles in a tree whose leaves may be used whole: below it every leaf is summed directly, which
/// costs little at that size and keeps the forces between neighbouring particles exactly pairwise.
pub const FAR_LEAVES_FROM: usize = 1000;
/// Bits of the Morton key per axis: the deepest level of subdivision.
const KEY_BITS: u32 = 21;

/// A sorted particle: x, y, z (m), mass (kg); in a bucket's list, relative to its centre and rescaled.
type Source<T = f64> = [T; 4];
/// A node's moments: centre of mass x, y, z (m), mass (kg), traceless quadrupole `xx, xy, xz, yy, yz, zz`
/// (kg m²); in a bucket's list, relative to its centre and rescaled.
type Moments<T = f64> = [T; 10];
/// Per-lane sums: ax, ay, az, φ (in units of G and of the bucket's scales).
type Sums<T, const N: usize> = [[T; N]; 4];

/// The floating-point type a list is summed in (f32 for large trees, f64 for small ones).
trait Real:
    Copy
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + AddAssign
    + SubAssign
    + Send
    + Sync
    + Default
{
    const ZERO: Self;
    fn of(x: f64) -> Self;
    fn f64(self) -> f64;
    fn sqrt(self) -> Self;
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    fn of(x: f64) -> Self {
        x as f32
    }
    fn f64(self) -> f64 {
        self as f64
    }
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    fn of(x: f64) -> Self {
        x
    }
    fn f64(self) -> f64 {
        self
    }
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
}

/// The power of two nearest `x` (> 0): rescaling by it is exact.
fn power_of_two_near(x: f64) -> f64 {
    if x > 0.0 && x.is_finite() {
        2f64.powi(x.log2().round() as i32)
    } else {
        1.0
    }
}

/// An octree over point masses (positions in m, masses in kg).
#[derive(Debug, Clone, Default)]
pub struct Octree {
    /// Input index of each sorted particle.
    order: Vec<u32>,
    /// Sorted index of each input particle (the inverse of `order`).
    rank: Vec<u32>,
    /// Sorted particles.
    particles: Vec<Source>,
    /// Nodes in depth-first order: moments.
    moments: Vec<Moments>,
    /// Side of the node's cube (m).
    side: Vec<f64>,
    /// Distance from the centre of mass to the cube's centre (m).
    delta: Vec<f64>,
    /// The node's particles: sorted indices `start..end`.
    start: Vec<u32>,
    end: Vec<u32>,
    /// First node after the node's subtree.
    next: Vec<u32>,
    /// Whether the node is a leaf.
    leaf: Vec<bool>,
    /// Bucket node indices, in order (they cover the sorted particles in order).
    buckets: Vec<u32>,
    /// Whether leaves may be used whole and lists are summed in f32 (at least [`FAR_LEAVES_FROM`] particles).
    far_leaves: bool,
}

/// Spreads the low 21 bits of `v` to every third bit.
fn spread(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// Buffers reused from bucket to bucket: the interaction lists, as the walk finds them.
#[derive(Debug, Clone, Default)]
struct Lists {
    /// Nodes used whole.
    cells: Vec<u32>,
    /// Leaves summed directly: their runs `start..end` of sorted particles.
    leaves: Vec<(u32, u32)>,
}

/// A bucket's interaction lists gathered for summing: relative to the bucket's centre, in its scales.
#[derive(Debug, Clone, Default)]
struct Local<T> {
    /// Moments of the nodes used whole.
    cells: Vec<Moments<T>>,
    /// The particles of the leaves summed directly.
    sources: Vec<Source<T>>,
}

/// Adds the monopole and quadrupole of every node in `cells` to the sums of points `x, y, z`.
fn add_cells<T: Real, const N: usize>(cells: &[Moments<T>], x: &[T; N], y: &[T; N], z: &[T; N], f: &mut Sums<T, N>) {
    let [ax, ay, az, phi] = f;
    let (one, half, five_halves) = (T::of(1.0), T::of(0.5), T::of(2.5));
    for &[cx, cy, cz, m, qxx, qxy, qxz, qyy, qyz, qzz] in cells {
        for l in 0..N {
            let (rx, ry, rz) = (x[l] - cx, y[l] - cy, z[l] - cz);
            let r2 = rx * rx + ry * ry + rz * rz;
            let inv = one / r2.sqrt();
            let inv2 = inv * inv;
            let inv3 = inv * inv2;
            let inv5 = inv3 * inv2;
            let qx = qxx * rx + qxy * ry + qxz * rz;
            let qy = qxy * rx + qyy * ry + qyz * rz;
            let qz = qxz * rx + qyz * ry + qzz * rz;
            let rqr = rx * qx + ry * qy + rz * qz;
            let radial = m * inv3 + five_halves * rqr * inv5 * inv2;
            ax[l] += qx * inv5 - rx * radial;
            ay[l] += qy * inv5 - ry * radial;
            az[l] += qz * inv5 - rz * radial;
            phi[l] -= m * inv + half * rqr * inv5;
        }
    }
}

/// Adds the particles `sources` to the sums of points `x, y, z` directly, skipping a source at distance zero.
fn add_sources<T: Real, const N: usize>(sources: &[Source<T>], x: &[T; N], y: &[T; N], z: &[T; N], f: &mut Sums<T, N>) {
    let [ax, ay, az, phi] = f;
    let one = T::of(1.0);
    for &[xj, yj, zj, mj] in sources {
        for l in 0..N {
            let (dx, dy, dz) = (xj - x[l], yj - y[l], zj - z[l]);
            let r2 = dx * dx + dy * dy + dz * dz;
            // A source at the point itself (r = 0) adds nothing. Computing 1/√r² first and then selecting
            // (not branching) lets the lanes vectorise; for r > 0 the value is the same.
            let inv = one / r2.sqrt();
            let inv = if r2 > T::ZERO { inv } else { T::ZERO };
            let minv = mj * inv;
            let minv3 = minv * inv * inv;
            ax[l] += dx * minv3;
            ay[l] += dy * minv3;
            az[l] += dz * minv3;
            phi[l] -= minv;
        }
    }
}

/// A bucket's frame: its centre (m), length unit (m) and mass unit (kg), both powers of two.
#[derive(Debug, Clone, Copy)]
struct Frame {
    origin: Vec3,
    length: f64,
    mass: f64,
}

impl Frame {
    /// A position (m) in the frame.
    fn point<T: Real>(&self, x: f64, y: f64, z: f64) -> [T; 3] {
        let s = 1.0 / self.length;
        [
            T::of((x - self.origin.x) * s),
            T::of((y - self.origin.y) * s),
            T::of((z - self.origin.z) * s),
        ]
    }
}

/// The smallest box `lo..hi` (m) holding `points`.
fn bounding_box(points: &[Source]) -> (Vec3, Vec3) {
    let mut lo = Vec3::new(points[0][0], points[0][1], points[0][2]);
    let mut hi = lo;
    for p in points {
        let p = Vec3::new(p[0], p[1], p[2]);
        lo = lo.inf(&p);
        hi = hi.sup(&p);
    }
    (lo, hi)
}

/// The nodes of a subtree in depth-first order, as [`Octree`] stores them, with node indices (`next`, `buckets`)
/// counted from the subtree's root.
#[derive(Debug, Default)]
struct Nodes {
    start: Vec<u32>,
    end: Vec<u32>,
    next: Vec<u32>,
    leaf: Vec<bool>,
    /// Cube (centre, side) of each node.
    cubes: Vec<(Vec3, f64)>,
    buckets: Vec<u32>,
}

/// Nodes of at least this many particles build their children's subtrees in parallel (and append them in
/// octant order, so the layout is the serial one).
const PARALLEL_NODE: usize = 2048;

impl Nodes {
    /// The subtree of sorted particles `s..e` (cube `centre ± half`, at `level`); its root is a bucket unless it
    /// lies `in_bucket` already.
    fn subtree(keys: &[u64], s: usize, e: usize, centre: Vec3, half: f64, level: u32, in_bucket: bool) -> Nodes {
        let mut nodes = Nodes::default();
        nodes.add(keys, s, e, centre, half, level, in_bucket);
        nodes
    }

    /// Appends `other`, shifting its node indices past ours.
    fn append(&mut self, other: Nodes) {
        let offset = self.start.len() as u32;
        self.start.extend(other.start);
        self.end.extend(other.end);
        self.next.extend(other.next.into_iter().map(|k| k + offset));
        self.leaf.extend(other.leaf);
        self.cubes.extend(other.cubes);
        self.buckets.extend(other.buckets.into_iter().map(|k| k + offset));
    }

    /// Adds the node of sorted particles `s..e` (cube `centre ± half`, at `level`) and its subtree; the node
    /// is a bucket unless it lies `in_bucket` already.
    #[allow(clippy::too_many_arguments)]
    fn add(&mut self, keys: &[u64], s: usize, e: usize, centre: Vec3, half: f64, level: u32, in_bucket: bool) {
        let idx = self.start.len();
        self.start.push(s as u32);
        self.end.push(e as u32);
        self.next.push(0);
        let is_leaf = e - s <= LEAF_SIZE || level >= KEY_BITS;
        self.leaf.push(is_leaf);
        self.cubes.push((centre, 2.0 * half));
        let is_bucket = !in_bucket && (e - s <= BUCKET_SIZE || is_leaf);
        if is_bucket {
            self.buckets.push(idx as u32);
        }
        if !is_leaf {
            // The three key bits of this level give the octant (bit 0: x, bit 1: y, bit 2: z).
            let shift = 3 * (KEY_BITS - 1 - level);
            let mut children = Vec::with_capacity(8);
            let mut lo = s;
            for octant in 0..8u64 {
                let hi = lo + keys[lo..e].partition_point(|&k| (k >> shift) & 7 <= octant);
                if hi > lo {
                    let sign = |bit: u64| if octant & bit != 0 { 0.5 } else { -0.5 };
                    children.push((lo, hi, centre + Vec3::new(sign(1), sign(2), sign(4)) * half));
                }
                lo = hi;
            }
            let inside = in_bucket || is_bucket;
            if e - s >= PARALLEL_NODE {
                let subtrees: Vec<Nodes> = children
                    .into_par_iter()
                    .map(|(lo, hi, c)| Nodes::subtree(keys, lo, hi, c, 0.5 * half, level + 1, inside))
                    .collect();
                for t in subtrees {
                    self.append(t);
                }
            } else {
                for (lo, hi, c) in children {
                    self.add(keys, lo, hi, c, 0.5 * half, level + 1, inside);
                }
            }
        }
        self.next[idx] = self.start.len() as u32;
    }
}

/// Where each bucket's interaction lists come from when the tree is summed.
enum Walk<'a> {
    /// A fresh walk at the current positions, with these `(l/θ + δ)²` ([`Octree::reach2`]).
    Open(Vec<f64>),
    /// The lists found when the tree was frozen, one per bucket in bucket order ([`FrozenOctree`]).
    Frozen(&'a [Lists]),
}

impl Octree {
    /// Builds the tree (positions in m, masses in kg). Empty input gives an empty tree.
    pub fn build(positions: &[Vec3], masses: &[f64]) -> Self {
        let n = positions.len();
        if n == 0 {
            return Octree::default();
        }
        let (lo, hi) = PHASE_KEYS.time(|| {
            positions
                .par_iter()
                .with_min_len(4096)
                .fold(|| (positions[0], positions[0]), |(lo, hi), p| (lo.inf(p), hi.sup(p)))
                .reduce(|| (positions[0], positions[0]), |a, b| (a.0.inf(&b.0), a.1.sup(&b.1)))
        });
        let centre = (lo + hi) * 0.5;
        let half = ((hi - lo).max() * 0.5).max(f64::MIN_POSITIVE) * (1.0 + 1e-12);
        let corner = centre - Vec3::repeat(half);
        let cells = (1u64 << KEY_BITS) as f64;
        let scale = cells / (2.0 * half);
        let quantise = |x: f64, c: f64| (((x - c) * scale).max(0.0) as u64).min((1 << KEY_BITS) - 1);
        let keyed: Vec<(u64, u32)> = PHASE_KEYS.time(|| {
            let mut keyed: Vec<(u64, u32)> = positions
                .par_iter()
                .with_min_len(1024)
                .enumerate()
                .map(|(i, p)| {
                    let key = spread(quantise(p.x, corner.x))
                        | spread(quantise(p.y, corner.y)) << 1
                        | spread(quantise(p.z, corner.z)) << 2;
                    (key, i as u32)
                })
                .collect();
            // Pairs are distinct (the index breaks ties), so the order does not depend on the sort's scheduling.
            keyed.par_sort_unstable();
            keyed
        });
        let (mut tree, cubes) = PHASE_SUBDIVIDE.time(|| {
            let keys: Vec<u64> = keyed.par_iter().with_min_len(4096).map(|k| k.0).collect();
            let order: Vec<u32> = keyed.par_iter().with_min_len(4096).map(|k| k.1).collect();
            let rank: Vec<AtomicU32> = (0..n)
                .into_par_iter()
                .with_min_len(4096)
                .map(|_| AtomicU32::new(0))
                .collect();
            order
                .par_iter()
                .with_min_len(4096)
                .enumerate()
                .for_each(|(k, &i)| rank[i as usize].store(k as u32, Ordering::Relaxed));
            let particles = order
                .par_iter()
                .with_min_len(4096)
                .map(|&i| {
                    let p = positions[i as usize];
                    [p.x, p.y, p.z, masses[i as usize]]
                })
                .collect();
            // the nodes, built in parallel from the top (their layout is the serial one)
            let nodes = Nodes::subtree(&keys, 0, n, centre, half, 0, false);
            let tree = Octree {
                particles,
                order,
                rank: rank
                    .into_par_iter()
                    .with_min_len(4096)
                    .map(AtomicU32::into_inner)
                    .collect(),
                start: nodes.start,
                end: nodes.end,
                next: nodes.next,
                leaf: nodes.leaf,
                buckets: nodes.buckets,
                far_leaves: n >= FAR_LEAVES_FROM,
                ..Octree::default()
            };
            (tree, nodes.cubes)
        });
        tree.moments = PHASE_MOMENTS.time(|| tree.node_moments(|k| cubes[k].0));
        PHASE_MOMENTS.time(|| {
            tree.side = cubes.par_iter().with_min_len(1024).map(|c| c.1).collect();
            tree.delta = tree
                .moments
                .par_iter()
                .zip(&cubes)
                .with_min_len(1024)
                .map(|(m, (cube, _))| (Vec3::new(m[0], m[1], m[2]) - cube).norm())
                .collect();
        });
        tree
    }

    /// Moments of every node (`fallback(k)` as node `k`'s centre if it is massless).
    fn node_moments(&self, fallback: impl Fn(usize) -> Vec3 + Sync) -> Vec<Moments> {
        (0..self.start.len())
            .into_par_iter()
            .with_min_len(32)
            .map(|k| self.moments_of(self.start[k] as usize, self.end[k] as usize, fallback(k)))
            .collect()
    }

    /// Moments of sorted particles `s..e` (`fallback` as centre if massless).
    fn moments_of(&self, s: usize, e: usize, fallback: Vec3) -> Moments {
        let (mut m, mut wx, mut wy, mut wz) = (0.0, 0.0, 0.0, 0.0);
        for &[x, y, z, mj] in &self.particles[s..e] {
            m += mj;
            wx += mj * x;
            wy += mj * y;
            wz += mj * z;
        }
        let c = if m > 0.0 { Vec3::new(wx, wy, wz) / m } else { fallback };
        let mut q = [0.0; 6];
        for &[x, y, z, mj] in &self.particles[s..e] {
            let (dx, dy, dz) = (x - c.x, y - c.y, z - c.z);
            let d2 = dx * dx + dy * dy + dz * dz;
            q[0] += mj * (3.0 * dx * dx - d2);
            q[1] += mj * 3.0 * dx * dy;
            q[2] += mj * 3.0 * dx * dz;
            q[3] += mj * (3.0 * dy * dy - d2);
            q[4] += mj * 3.0 * dy * dz;
            q[5] += mj * (3.0 * dz * dz - d2);
        }
        [c.x, c.y, c.z, m, q[0], q[1], q[2], q[3], q[4], q[5]]
    }

    /// `(l/θ + δ)²` of every node: a node is used whole beyond this squared distance.
    fn reach2(&self, theta: f64) -> Vec<f64> {
        self.side
            .par_iter()
            .zip(&self.delta)
            .with_min_len(1024)
            .map(|(l, d)| (l / theta + d).powi(2))
            .collect()
    }

    /// Fills `lists` for points whose bounding box is `lo..hi`: nodes used whole, and leaves summed directly.
    fn walk(&self, reach2: &[f64], lo: Vec3, hi: Vec3, lists: &mut Lists) {
        lists.cells.clear();
        lists.leaves.clear();
        let count = self.next.len() as u32;
        let mut k = 0u32;
        while k < count {
            let kk = k as usize;
            let c = &self.moments[kk];
            let gap = |c: f64, l: f64, h: f64| (l - c).max(c - h).max(0.0);
            let (gx, gy, gz) = (gap(c[0], lo.x, hi.x), gap(c[1], lo.y, hi.y), gap(c[2], lo.z, hi.z));
            let far = gx * gx + gy * gy + gz * gz > reach2[kk];
            if self.leaf[kk] {
                if far && self.far_leaves && (self.end[kk] - self.start[kk]) as usize >= FAR_LEAF_MIN {
                    lists.cells.push(k);
                } else {
                    lists.leaves.push((self.start[kk], self.end[kk]));
                }
                k = self.next[kk];
            } else if far {
                lists.cells.push(k);
                k = self.next[kk];
            } else {
                k += 1;
            }
        }
    }

    /// Gathers the walk's `lists` into `local`, in `frame`.
    fn gather<T: Real>(&self, lists: &Lists, frame: &Frame, local: &mut Local<T>) {
        let mu = 1.0 / frame.mass;
        // the quadrupole carries mass × length²
        let q_unit = mu / (frame.length * frame.length);
        local.cells.clear();
        local.cells.extend(lists.cells.iter().map(|&c| {
            let m = &self.moments[c as usize];
            let [x, y, z] = frame.point::<T>(m[0], m[1], m[2]);
            let q = |k: usize| T::of(m[k] * q_unit);
            [x, y, z, T::of(m[3] * mu), q(4), q(5), q(6), q(7), q(8), q(9)]
        }));
        local.sources.clear();
        for &(s, e) in &lists.leaves {
            local
                .sources
                .extend(self.particles[s as usize..e as usize].iter().map(|&[x, y, z, m]| {
                    let [x, y, z] = frame.point::<T>(x, y, z);
                    [x, y, z, T::of(m * mu)]
                }));
        }
    }

    /// The field at `N` points `x, y, z` (in the list's frame) from a gathered list: cells first, then the
    /// directly summed particles, each in list order.
    ///
    /// The list is summed in runs of [`RUN`] entries, each run in `T` and the runs' totals in f64, so that
    /// the rounding of a single-precision sum grows with the run, not with the whole list (the potential,
    /// whose terms all have one sign, would otherwise lose ~1e-6 over a few thousand entries).
    fn sum<T: Real, const N: usize>(local: &Local<T>, x: &[T; N], y: &[T; N], z: &[T; N]) -> Sums<f64, N> {
        const RUN: usize = 64;
        let mut total = [[0.0; N]; 4];
        let mut add = |f: Sums<T, N>| {
            for (t, f) in total.iter_mut().zip(f) {
                for (t, f) in t.iter_mut().zip(f) {
                    *t += f.f64();
                }
            }
        };
        for cells in local.cells.chunks(RUN) {
            let mut f = [[T::ZERO; N]; 4];
            add_cells(cells, x, y, z, &mut f);
            add(f);
        }
        for sources in local.sources.chunks(RUN) {
            let mut f = [[T::ZERO; N]; 4];
            add_sources(sources, x, y, z, &mut f);
            add(f);
        }
        total
    }

    /// Accelerations and potentials (`g` times the sums, back in SI units) of up to `N` particles `block`
    /// into `out`; unused lanes repeat the last particle.
    fn block<T: Real, const N: usize>(local: &Local<T>, frame: &Frame, block: &[Source], out: &mut [[f64; 4]], g: f64) {
        let points: [[T; 3]; N] = std::array::from_fn(|l| {
            let [x, y, z, _] = block[l.min(block.len() - 1)];
            frame.point(x, y, z)
        });
        let lane = |c: usize| std::array::from_fn(|l| points[l][c]);
        let f = Self::sum::<T, N>(local, &lane(0), &lane(1), &lane(2));
        let phi_unit = g * frame.mass / frame.length;
        let a_unit = phi_unit / frame.length;
        for (l, o) in out.iter_mut().enumerate() {
            *o = [f[0][l] * a_unit, f[1][l] * a_unit, f[2][l] * a_unit, f[3][l] * phi_unit];
        }
    }

    /// The frame of points around `origin` spanning about `side` (m).
    fn frame(&self, origin: Vec3, side: f64) -> Frame {
        Frame {
            origin,
            length: power_of_two_near(side),
            mass: power_of_two_near(self.moments[0][3]),
        }
    }

    /// Accelerations (m/s²) and potentials (J/kg) of every particle, in input order.
    ///
    /// ```
    /// use rubblepile::gravity::{direct, octree::Octree};
    /// use rubblepile::math::Vec3;
    /// let x: Vec<Vec3> = (0..100).map(|k| Vec3::new((k % 5) as f64, (k / 5 % 5) as f64, (k / 25) as f64)).collect();
    /// let m = vec![1.0; 100];
    /// let (tree, _) = Octree::build(&x, &m).accelerations(0.3, 1.0);
    /// let (exact, _) = direct(&x, &m, 1.0);
    /// assert!((tree[7] - exact[7]).norm() < 1e-3 * exact[7].norm());
    /// ```
    pub fn accelerations(&self, theta: f64, g: f64) -> (Vec<Vec3>, Vec<f64>) {
        let n = self.order.len();
        // Sorted-order results, one disjoint chunk per bucket (buckets cover the sorted particles in order).
        let mut sorted = vec![[0.0; 4]; n];
        let open = Walk::Open(self.reach2(theta));
        PHASE_WALK.time(|| {
            if self.far_leaves {
                self.sum_buckets::<f32, 8, 4>(&open, g, &mut sorted);
            } else {
                self.sum_buckets::<f64, 4, 2>(&open, g, &mut sorted);
            }
        });
        PHASE_UNSORT.time(|| self.unsort(&sorted))
    }

    /// Per-particle results in sorted order back in input order: accelerations and potentials (in parallel).
    fn unsort(&self, sorted: &[[f64; 4]]) -> (Vec<Vec3>, Vec<f64>) {
        self.rank
            .par_iter()
            .with_min_len(4096)
            .map(|&k| {
                let r = &sorted[k as usize];
                (Vec3::new(r[0], r[1], r[2]), r[3])
            })
            .unzip()
    }

    /// Fills `sorted` (per sorted particle: acceleration, potential) bucket by bucket, summing in `T`, `W`
    /// particles at a time against one list (a last `H = W/2` or fewer as a half block).
    fn sum_buckets<T: Real, const W: usize, const H: usize>(&self, walk: &Walk, g: f64, sorted: &mut [[f64; 4]]) {
        let mut chunks = Vec::with_capacity(self.buckets.len());
        let mut rest = sorted;
        for (k, &b) in self.buckets.iter().enumerate() {
            let (s, e) = (self.start[b as usize] as usize, self.end[b as usize] as usize);
            let (chunk, tail) = rest.split_at_mut(e - s);
            chunks.push((k, b as usize, s, chunk));
            rest = tail;
        }
        let init = || (Lists::default(), Local::<T>::default());
        chunks
            .into_par_iter()
            .for_each_init(init, |(buffer, local), (k, b, s, out)| {
                let points = &self.particles[s..s + out.len()];
                let (lo, hi) = bounding_box(points);
                let lists = match walk {
                    Walk::Open(reach2) => {
                        self.walk(reach2, lo, hi, buffer);
                        &*buffer
                    }
                    Walk::Frozen(lists) => &lists[k],
                };
                let frame = self.frame((lo + hi) * 0.5, self.side[b]);
                self.gather(lists, &frame, local);
                let (w, h, len): (usize, usize, usize) = (W, H, points.len());
                let split = if len % w <= h { len / w * w } else { len };
                let (out_w, out_h) = out.split_at_mut(split);
                for (block, out) in points[..split].chunks(W).zip(out_w.chunks_mut(W)) {
                    Self::block::<T, W>(local, &frame, block, out, g);
                }
                for (block, out) in points[split..].chunks(H).zip(out_h.chunks_mut(H)) {
                    Self::block::<T, H>(local, &frame, block, out, g);
                }
            });
    }
}

/// An octree whose interaction lists were found once, at the configuration it was built from, and are summed
/// again at nearby configurations of the same particles (the lists of a step, see
/// [`crate::integrate::OdeSystem::begin_step`]).
///
/// A freshly walked tree's field jumps, by about its multipole error, wherever a particle crosses a node's
/// opening distance, and that happens all the time in a moving system. Keeping the node membership and the
/// lists and recomputing only the nodes' moments at the new positions makes the field an analytic function of
/// the positions: a sum of the same monopole, quadrupole and pair terms. An extrapolation integrator then sees
/// a smooth right-hand side within a step, and the lists change only between steps. The lists stay accurate
/// while the particles move little against the node sizes (a step's motion); the sums are always in double
/// precision, whose rounding, unlike single precision's, stays far below any step's error budget.
///
/// ```
/// use rubblepile::gravity::{direct, octree::Octree};
/// use rubblepile::math::Vec3;
/// let x: Vec<Vec3> = (0..1200).map(|k| Vec3::new((k % 11) as f64, (k / 11 % 11) as f64, (k / 121) as f64)).collect();
/// let m = vec![1.0; x.len()];
/// let frozen = Octree::build(&x, &m).freeze(0.5);
/// // a small motion: the frozen lists still give the field to the tree's accuracy
/// let moved: Vec<Vec3> = x.iter().map(|p| p + Vec3::new(0.01, -0.02, 0.005)).collect();
/// let (tree, _) = frozen.accelerations(&moved, &m, 1.0);
/// let (exact, _) = direct(&moved, &m, 1.0);
/// assert!((tree[600] - exact[600]).norm() < 1e-3 * exact[600].norm());
/// ```
#[derive(Debug, Clone)]
pub struct FrozenOctree {
    tree: Octree,
    /// Each bucket's lists, in bucket order.
    lists: Vec<Lists>,
}

impl Octree {
    /// Fixes this tree's interaction lists at opening angle `theta` (dimensionless): see [`FrozenOctree`].
    pub fn freeze(self, theta: f64) -> FrozenOctree {
        let reach2 = self.reach2(theta);
        let lists = self
            .buckets
            .par_iter()
            .map(|&b| {
                let (s, e) = (self.start[b as usize] as usize, self.end[b as usize] as usize);
                let (lo, hi) = bounding_box(&self.particles[s..e]);
                let mut lists = Lists::default();
                self.walk(&reach2, lo, hi, &mut lists);
                lists
            })
            .collect();
        FrozenOctree { tree: self, lists }
    }
}

impl FrozenOctree {
    /// Number of particles.
    pub fn len(&self) -> usize {
        self.tree.order.len()
    }

    /// Whether the tree holds no particle.
    pub fn is_empty(&self) -> bool {
        self.tree.order.is_empty()
    }

    /// Accelerations (m/s²) and potentials (J/kg) of every particle, in input order, at `positions` (m) with
    /// `masses` (kg), both in the input order of the build and of its length, by the frozen lists with the
    /// nodes' moments recomputed there; `g` is the gravitational constant. The frozen tree is only read (the
    /// particles and moments at `positions` go into a copy of the tree's arrays, O(N), beside the lists' O(N log N)
    /// sums), so that several evaluations may share it without a lock held across their parallel work (a rayon
    /// worker blocked on such a lock can wait for a job of its own).
    pub fn accelerations(&self, positions: &[Vec3], masses: &[f64], g: f64) -> (Vec<Vec3>, Vec<f64>) {
        let mut tree = self.tree.clone();
        tree.particles
            .par_iter_mut()
            .zip(&tree.order)
            .with_min_len(4096)
            .for_each(|(p, &i)| {
                let (x, m) = (positions[i as usize], masses[i as usize]);
                *p = [x.x, x.y, x.z, m];
            });
        // A node without mass keeps the centre it had when the tree was built (the moments are otherwise
        // those of the particles alone).
        let built = &self.tree.moments;
        tree.moments = tree.node_moments(|k| Vec3::new(built[k][0], built[k][1], built[k][2]));
        let mut sorted = vec![[0.0; 4]; self.len()];
        tree.sum_buckets::<f64, 4, 2>(&Walk::Frozen(&self.lists), g, &mut sorted);
        tree.unsort(&sorted)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::{generator, point_in_ball};

    /// Sorted-order sums of `tree` in `T`.
    fn sums<T: Real, const W: usize, const H: usize>(tree: &Octree, theta: f64) -> Vec<[f64; 4]> {
        let mut out = vec![[0.0; 4]; tree.order.len()];
        tree.sum_buckets::<T, W, H>(&Walk::Open(tree.reach2(theta)), 1.0, &mut out);
        out
    }

    /// The single-precision lists of a large tree differ from the same lists summed in double precision by
    /// rounding (~1e-7), far below the multipole error (~1e-4): RMS relative change of the acceleration
    /// ≤ 1e-6, largest ≤ 1e-5, potential ≤ 1e-6. Masses of 1e12 kg at 1 km keep it there (the rescaling).
    #[test]
    fn single_precision_changes_the_field_by_rounding_only() {
        let mut rng = generator(11);
        let x: Vec<Vec3> = (0..5000).map(|_| point_in_ball(&mut rng, 1000.0)).collect();
        let m = vec![1e12; x.len()];
        let tree = Octree::build(&x, &m);
        assert!(tree.far_leaves);
        let (single, double) = (sums::<f32, 8, 4>(&tree, 0.5), sums::<f64, 4, 2>(&tree, 0.5));
        let (mut sq, mut worst, mut worst_phi) = (0.0, 0.0f64, 0.0f64);
        for (s, d) in single.iter().zip(&double) {
            let a = Vec3::new(d[0], d[1], d[2]);
            let e = (Vec3::new(s[0], s[1], s[2]) - a).norm() / a.norm();
            sq += e * e;
            worst = worst.max(e);
            worst_phi = worst_phi.max(((s[3] - d[3]) / d[3]).abs());
        }
        let rms = (sq / x.len() as f64).sqrt();
        println!("f32 vs f64 lists: RMS {rms:.2e}, largest {worst:.2e}, potential {worst_phi:.2e}");
        assert!(
            rms <= 1e-6 && worst <= 1e-5 && worst_phi <= 1e-6,
            "{rms:e} {worst:e} {worst_phi:e}"
        );
    }

    /// Frozen lists make the field smooth along a motion, where fresh walks make it jump. On a jittered
    /// 13³ lattice (spacing 1, jitter ±0.2, so no pair is closer than 0.6) every particle moves along a straight
    /// line by up to 1e-3 over 100 samples of the path. The second difference of the frozen tree's field is
    /// then the smooth path's curvature (measured 2.6e-9 of the field at most; bound 1e-7); the freshly walked
    /// tree's, summed in the same double precision, jumps where lists change (measured 9.1e-4; bound: above
    /// 1e-5, so the test can tell the two apart).
    /// At the frozen configuration the frozen field equals the fresh double-precision one bit for bit.
    #[test]
    fn frozen_lists_give_a_smooth_field_along_a_motion() {
        let mut rng = generator(5);
        let mut x = Vec::new();
        for k in 0..13usize.pow(3) {
            let jitter = point_in_ball(&mut rng, 0.2);
            x.push(Vec3::new((k % 13) as f64, (k / 13 % 13) as f64, (k / 169) as f64) + jitter);
        }
        let v: Vec<Vec3> = (0..x.len()).map(|_| point_in_ball(&mut rng, 1e-3)).collect();
        let m: Vec<f64> = (0..x.len()).map(|k| 1.0 + (k % 3) as f64).collect();
        let at = |s: f64| -> Vec<Vec3> { x.iter().zip(&v).map(|(p, d)| p + d * s).collect() };
        let frozen = Octree::build(&x, &m).freeze(0.5);
        let fresh = |p: &[Vec3]| {
            let tree = Octree::build(p, &m);
            tree.unsort(&sums::<f64, 4, 2>(&tree, 0.5)).0
        };
        assert!(frozen.accelerations(&x, &m, 1.0).0 == fresh(&x));
        let samples = 101;
        let path = |field: &mut dyn FnMut(&[Vec3]) -> Vec<Vec3>| -> f64 {
            let a: Vec<Vec<Vec3>> = (0..samples)
                .map(|k| field(&at(k as f64 / (samples - 1) as f64)))
                .collect();
            let mut worst = 0.0f64;
            for w in a.windows(3) {
                for ((before, now), after) in w[0].iter().zip(&w[1]).zip(&w[2]) {
                    worst = worst.max((after - now * 2.0 + before).norm() / now.norm());
                }
            }
            worst
        };
        let smooth = path(&mut |p| frozen.accelerations(p, &m, 1.0).0);
        let jumpy = path(&mut |p| fresh(p));
        println!("largest relative second difference: frozen {smooth:.2e}, fresh {jumpy:.2e}");
        assert!(smooth < 1e-7, "frozen lists: {smooth:e}");
        assert!(
            jumpy > 1e-5,
            "fresh walks never changed a list here ({jumpy:e}): nothing is tested"
        );
    }

    impl Octree {
        /// Field at point `p`: acceleration (m/s²) and potential (J/kg), skipping any particle at `p` itself,
        /// with opening angle `theta` and gravitational constant `g`.
        fn field_at(&self, p: &Vec3, theta: f64, g: f64) -> (Vec3, f64) {
            let mut lists = Lists::default();
            self.walk(&self.reach2(theta), *p, *p, &mut lists);
            // a length unit of 1/128 of the root side: the point's list spans a few leaves around it
            let frame = self.frame(*p, self.side[0] / (1u64 << (KEY_BITS / 3)) as f64);
            let mut out = [[0.0; 4]];
            if self.far_leaves {
                let mut local = Local::<f32>::default();
                self.gather(&lists, &frame, &mut local);
                Self::block::<f32, 1>(&local, &frame, &[[p.x, p.y, p.z, 0.0]], &mut out, g);
            } else {
                let mut local = Local::<f64>::default();
                self.gather(&lists, &frame, &mut local);
                Self::block::<f64, 1>(&local, &frame, &[[p.x, p.y, p.z, 0.0]], &mut out, g);
            }
            (Vec3::new(out[0][0], out[0][1], out[0][2]), out[0][3])
        }
    }

    /// A cubic lattice (spacing h, mass 1) inside radius 16 h: density 1/h³. Its interior field at points at
    /// cell centres, where the nearest lattice sites cancel by symmetry, is `g = 4/3 π G ρ r` within 1 %.
    #[test]
    fn interior_field_of_a_uniform_ball() {
        let h = 1.0;
        let big = 16.0;
        let mut x = Vec::new();
        let n = big as i64 + 1;
        for i in -n..=n {
            for j in -n..=n {
                for k in -n..=n {
                    let p = Vec3::new(i as f64, j as f64, k as f64) * h;
                    if p.norm() < big * h {
                        x.push(p);
                    }
                }
            }
        }
        let m = vec![1.0; x.len()];
        let tree = Octree::build(&x, &m);
        let rho = 1.0 / h.powi(3);
        let mut worst: f64 = 0.0;
        for (a, b, c) in [(2, 1, 0), (4, -3, 2), (-6, 5, 3), (8, 2, -5), (-9, -6, 4), (3, 10, -2)] {
            let p = Vec3::new(a as f64 + 0.5, b as f64 + 0.5, c as f64 + 0.5) * h;
            let (g, _) = tree.field_at(&p, 0.3, 1.0);
            let expect = 4.0 / 3.0 * std::f64::consts::PI * rho * p.norm();
            let radial = -g.dot(&p.normalize());
            let err = (radial - expect).abs() / expect;
            worst = worst.max(err);
        }
        println!(
            "interior field of a uniform ball ({} points): worst relative error {worst:.2e}",
            x.len()
        );
        assert!(worst < 0.01, "interior field off by {worst}");
    }

    /// The frame's rescaling is by powers of two, so it is exact.
    #[test]
    fn frame_units_are_powers_of_two() {
        for x in [1e-9, 0.3, 1.0, 7.5, 1e12, 3e24] {
            let p = power_of_two_near(x);
            assert_eq!(p.log2().fract(), 0.0, "{x}");
            assert!(p / x < 1.5 && x / p < 1.5, "{x} -> {p}");
        }
        assert_eq!(power_of_two_near(0.0), 1.0);
    }
}
