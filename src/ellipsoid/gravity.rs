//! Monopole gravity between fragments, `U_Gij = −G m_i m_j / |r_i − r_j|` (Roig03 Eq. 6): exact pair sum.
//!
//! Small systems use the symmetric half loop (Newton's third law bitwise); large ones compute each
//! body's row in parallel with rayon (twice the flops, but no reduction, so the result does not depend on
//! the number of threads: the same scene gives the same bits on 1 or many cores).

use crate::math::Vec3;
use rayon::prelude::*;

/// Above this many bodies the parallel row-wise sum is used.
pub const PARALLEL_THRESHOLD: usize = 256;

/// Fewest blocks of the half loop (rows cut into [`blocks`] blocks of about equal work, each summed into its own
/// buffer and reduced in block order, so the bits depend on N only, not on the number of threads).
const MIN_BLOCKS: usize = 8;

/// Most blocks: each costs a force buffer of N entries, and the per-body sum adds them all.
const MAX_BLOCKS: usize = 64;

/// Bodies per block: about two blocks per thread on 16 threads at 2000 bodies, so that no thread idles.
const BODIES_PER_BLOCK: usize = 64;

/// The number of blocks of the half loop over `n` bodies: `n / 64`, between 8 and 64.
pub fn blocks(n: usize) -> usize {
    (n / BODIES_PER_BLOCK).clamp(MIN_BLOCKS, MAX_BLOCKS)
}

/// Below this many bodies the half loop runs serially into `forces` directly.
pub const BLOCKED_FROM: usize = 64;

/// Positions split into coordinate arrays, so that the pair forces of a row vectorise.
struct Columns {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
}

impl Columns {
    fn of(positions: &[Vec3]) -> Self {
        Columns {
            x: positions.iter().map(|p| p.x).collect(),
            y: positions.iter().map(|p| p.y).collect(),
            z: positions.iter().map(|p| p.z).collect(),
        }
    }

    fn zeros(n: usize) -> Self {
        Columns {
            x: vec![0.0; n],
            y: vec![0.0; n],
            z: vec![0.0; n],
        }
    }
}

/// The half loop over rows `rows` (pairs `(i, j)`, `i ∈ rows`, `j > i`), adding `G m_i m_j d/|d|³` to body `i`
/// and subtracting it from body `j` in `out`. One square root and one division per pair, computed for a whole
/// row first over coordinate arrays (the compiler vectorises that loop), then added pair by pair.
fn half_loop(g: f64, pos: &Columns, masses: &[f64], rows: std::ops::Range<usize>, out: &mut [Vec3]) {
    let n = masses.len();
    let mut f = Columns::zeros(n);
    for i in rows {
        let (xi, yi, zi, gmi) = (pos.x[i], pos.y[i], pos.z[i], g * masses[i]);
        let len = n - i - 1;
        let (fx, fy, fz) = (&mut f.x[..len], &mut f.y[..len], &mut f.z[..len]);
        let (xs, ys, zs, ms) = (&pos.x[i + 1..], &pos.y[i + 1..], &pos.z[i + 1..], &masses[i + 1..]);
        for k in 0..len {
            let (dx, dy, dz) = (xs[k] - xi, ys[k] - yi, zs[k] - zi);
            let r2 = dx * dx + dy * dy + dz * dz;
            let inv_r = 1.0 / r2.sqrt();
            let s = gmi * ms[k] * inv_r * inv_r * inv_r;
            fx[k] = dx * s;
            fy[k] = dy * s;
            fz[k] = dz * s;
        }
        let mut fi = Vec3::zeros();
        for (k, o) in out[i + 1..].iter_mut().enumerate() {
            let fk = Vec3::new(fx[k], fy[k], fz[k]);
            fi += fk;
            *o -= fk;
        }
        out[i] += fi;
    }
}

/// Row boundaries that split the half loop's `n(n−1)/2` pairs into [`blocks`] parts of about equal size.
fn block_bounds(n: usize) -> Vec<usize> {
    let total = (n * n.saturating_sub(1) / 2) as f64;
    let mut bounds = vec![0];
    let (mut done, mut row) = (0.0, 0);
    let count = blocks(n);
    for b in 1..count {
        let goal = total * b as f64 / count as f64;
        while row < n && done < goal {
            done += (n - 1 - row) as f64;
            row += 1;
        }
        bounds.push(row);
    }
    bounds.push(n);
    bounds
}

/// The half loop on a packed state: body `i`'s position is `y[i·stride..i·stride+3]`, and its force is added to
/// `out[i·stride + offset..+3]`. For the translational-only right-hand side of small systems, where gathering
/// positions into vectors would cost more than the sum. Same pair order and arithmetic as [`add_gravity_forces`]
/// below [`BLOCKED_FROM`] bodies, so the bits agree.
pub fn add_gravity_forces_packed(g: f64, y: &[f64], stride: usize, masses: &[f64], out: &mut [f64], offset: usize) {
    let n = masses.len();
    let at = |i: usize| Vec3::new(y[i * stride], y[i * stride + 1], y[i * stride + 2]);
    for i in 0..n {
        let (pi, gmi) = (at(i), g * masses[i]);
        let mut fi = Vec3::zeros();
        for (j, &mj) in masses.iter().enumerate().skip(i + 1) {
            let d = at(j) - pi;
            let r2 = d.norm_squared();
            let inv_r = 1.0 / r2.sqrt();
            let f = d * (gmi * mj * inv_r * inv_r * inv_r);
            fi += f;
            let o = j * stride + offset;
            out[o] -= f.x;
            out[o + 1] -= f.y;
            out[o + 2] -= f.z;
        }
        let o = i * stride + offset;
        out[o] += fi.x;
        out[o + 1] += fi.y;
        out[o + 2] += fi.z;
    }
}

/// Gravitational forces `−∂U_G/∂r_i` (N) added to `forces`, without the potential: the right-hand side's
/// version (Roig03 Eq. 6). The symmetric half loop; from [`BLOCKED_FROM`] bodies on, its rows are cut into
/// [`blocks`] blocks of equal work computed in parallel into separate buffers and added in block order, so
/// the result is the same on any number of threads.
pub fn add_gravity_forces(g: f64, positions: &[Vec3], masses: &[f64], forces: &mut [Vec3]) {
    let n = positions.len();
    if n < BLOCKED_FROM {
        half_loop(g, &Columns::of(positions), masses, 0..n, forces);
        return;
    }
    let mut blocks = Vec::new();
    gravity_blocks(g, positions, masses, &mut blocks);
    for block in blocks {
        for (f, p) in forces.iter_mut().zip(block) {
            *f += p;
        }
    }
}

/// The blocked half loop of [`add_gravity_forces`] (for [`BLOCKED_FROM`] bodies or more) without the final
/// sum, into `blocks` (its buffers reused): one force buffer per block, computed in parallel. Adding them to the
/// other forces in block order gives the bits of [`add_gravity_forces`], while the caller computes those forces.
pub fn gravity_blocks(g: f64, positions: &[Vec3], masses: &[f64], blocks: &mut Vec<Vec<Vec3>>) {
    let n = positions.len();
    let bounds = block_bounds(n);
    let columns = Columns::of(positions);
    blocks.resize_with(self::blocks(n), Vec::new);
    blocks.par_iter_mut().enumerate().for_each(|(b, out)| {
        out.clear();
        out.resize(n, Vec3::zeros());
        half_loop(g, &columns, masses, bounds[b]..bounds[b + 1], out);
    });
}

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
