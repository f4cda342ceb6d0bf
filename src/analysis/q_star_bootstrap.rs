//! Q*_D (the Q at which the bound-fraction line crosses 0.5, Roig03 Fig. 5) with a bootstrap interval: the runs are
//! resampled with replacement within each Q level (so every resample keeps the design's Q values), the line refitted
//! and crossed each time, and the 2.5 and 97.5 percentiles of those crossings are the 95 % interval.

use crate::analysis::fits::{FitError, fit_line, line_crossing};

/// Resamples drawn by default.
pub const DEFAULT_RESAMPLES: usize = 2000;

/// Q values within this relative distance of a level's smallest belong to it.
const LEVEL_TOLERANCE: f64 = 1e-6;

/// Q*_D with its bootstrap interval.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct QStarBootstrap {
    /// Q*_D of the line through all runs (erg/g).
    pub q_star: f64,
    /// 2.5 percentile of the resampled Q*_D (erg/g).
    pub low: f64,
    /// 97.5 percentile of the resampled Q*_D (erg/g).
    pub high: f64,
    /// Resamples drawn.
    pub resamples: usize,
    /// Resamples whose line crossed 0.5 (a flat resampled line does not).
    pub crossings: usize,
    /// Seed of the resampling ([`crate::random::generator`]).
    pub seed: u64,
    /// Distinct Q values (levels) among the runs.
    pub q_levels: usize,
    /// Whether fewer than three Q levels bracket Q*_D (fewer than three levels, or Q*_D outside their range): the line
    /// and its interval then rest on too few energies to be trusted.
    pub underdetermined: bool,
}

impl QStarBootstrap {
    /// The warning to print when [`Self::underdetermined`].
    pub fn warning(&self) -> Option<String> {
        self.underdetermined.then(|| {
            format!(
                "Q*_D = {:.3e} erg/g rests on {} Q value(s){}: fewer than three bracket it, so its interval is not \
                 trustworthy; add projectiles or speeds around it",
                self.q_star,
                self.q_levels,
                if self.q_levels >= 3 {
                    ", and lies outside them"
                } else {
                    ""
                }
            )
        })
    }
}

/// Groups of run indices with (relatively within 1e-6) equal `q`, by increasing Q.
fn levels(q: &[f64]) -> Vec<Vec<usize>> {
    let mut order: Vec<usize> = (0..q.len()).collect();
    order.sort_by(|&a, &b| q[a].total_cmp(&q[b]));
    let mut out: Vec<Vec<usize>> = Vec::new();
    for i in order {
        match out.last_mut() {
            Some(l) if (q[i] - q[l[0]]).abs() <= LEVEL_TOLERANCE * q[l[0]].abs() => l.push(i),
            _ => out.push(vec![i]),
        }
    }
    out
}

/// The `p` quantile (0 ≤ p ≤ 1) of sorted `xs`, linearly interpolated between order statistics.
fn quantile(xs: &[f64], p: f64) -> f64 {
    let h = p * (xs.len() - 1) as f64;
    let (lo, hi) = (h.floor() as usize, h.ceil() as usize);
    xs[lo] + (h - lo as f64) * (xs[hi] - xs[lo])
}

/// Q*_D of bound fractions `bound` at `q` (erg/g), with the percentile interval of `resamples` stratified resamples
/// drawn from `seed`. Errors as [`fit_line`] and [`line_crossing`] for the line through all runs, or
/// [`FitError::TooFewPoints`] when no resample crosses 0.5.
pub fn q_star_bootstrap(q: &[f64], bound: &[f64], resamples: usize, seed: u64) -> Result<QStarBootstrap, FitError> {
    let q_star = line_crossing(&fit_line(q, bound)?, 0.5)?.x;
    let groups = levels(q);
    let mut rng = crate::random::generator(seed);
    let (mut x, mut y) = (Vec::with_capacity(q.len()), Vec::with_capacity(q.len()));
    let mut found = Vec::with_capacity(resamples);
    for _ in 0..resamples {
        x.clear();
        y.clear();
        for g in &groups {
            for _ in 0..g.len() {
                let k = g[((crate::random::uniform(&mut rng) * g.len() as f64) as usize).min(g.len() - 1)];
                x.push(q[k]);
                y.push(bound[k]);
            }
        }
        if let Ok(c) = fit_line(&x, &y).and_then(|l| line_crossing(&l, 0.5))
            && c.x.is_finite()
        {
            found.push(c.x);
        }
    }
    if found.is_empty() {
        return Err(FitError::TooFewPoints { points: 0, needed: 1 });
    }
    found.sort_by(f64::total_cmp);
    let (q_min, q_max) = (q[groups[0][0]], q[groups[groups.len() - 1][0]]);
    Ok(QStarBootstrap {
        q_star,
        low: quantile(&found, 0.025),
        high: quantile(&found, 0.975),
        resamples,
        crossings: found.len(),
        seed,
        q_levels: groups.len(),
        underdetermined: groups.len() < 3 || !(q_min..=q_max).contains(&q_star),
    })
}
