//! Sums over the spheres in a fixed order: terms summed in chunks of [`SUM_CHUNK`] (each chunk in order, the chunks
//! in parallel) and the chunks' totals combined in order, so that a total has the same bits on any number of
//! threads (the reproducibility rule of the soft spheres, Zhang17's runs being compared across thread counts).
//! Used by the forces, the pair contacts, the r-RESPA gravity blocks and the spin-up forcing.

use rayon::prelude::*;

/// Spheres per partial sum of [`ordered_sum`], and per parallel task of the per-sphere passes.
pub(crate) const SUM_CHUNK: usize = 1024;

/// `Σ term(k)` over `k < n`, summed in chunks of [`SUM_CHUNK`] (each in order, in parallel) and the chunks'
/// totals in order: the same bits on any number of threads (and, up to `SUM_CHUNK` terms, those of a plain
/// loop from 0).
pub(crate) fn ordered_sum(n: usize, term: impl Fn(usize) -> f64 + Sync) -> f64 {
    ordered_reduce(n, 0.0, |s, k| *s += term(k), |s, c| *s += c)
}

/// A reduction over `k < n` in the order of [`ordered_sum`]: each chunk of [`SUM_CHUNK`] starts from `zero` and
/// takes `add_term(acc, k)` for its `k` in order (chunks in parallel); the chunks' results are then combined by
/// `add(total, chunk)` in order, starting from `zero`.
pub(crate) fn ordered_reduce<T: Copy + Send + Sync>(
    n: usize,
    zero: T,
    add_term: impl Fn(&mut T, usize) + Sync,
    add: impl Fn(&mut T, T),
) -> T {
    let chunks: Vec<T> = (0..n.div_ceil(SUM_CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut acc = zero;
            for k in c * SUM_CHUNK..((c + 1) * SUM_CHUNK).min(n) {
                add_term(&mut acc, k);
            }
            acc
        })
        .collect();
    let mut total = zero;
    for c in chunks {
        add(&mut total, c);
    }
    total
}
