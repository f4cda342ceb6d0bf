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
    /// Q levels below Q*_D.
    pub levels_below: usize,
    /// Q levels above Q*_D.
    pub levels_above: usize,
    /// The two adjacent Q levels Q*_D falls between (erg/g); `None` when it lies outside them all.
    pub bracket: Option<[f64; 2]>,
    /// Whether fewer than two Q levels lie on either side of Q*_D: the line's crossing, and its interval, then rest
    /// on too few energies to be trusted.
    pub underdetermined: bool,
}

impl QStarBootstrap {
    /// The warning to print when [`Self::underdetermined`]; it adds when the interval lies inside the gap between
    /// the two Q values Q*_D falls between (no run there: the straight line, not the data, places it).
    pub fn warning(&self) -> Option<String> {
        self.underdetermined.then(|| {
            let gap = match self.bracket {
                Some([a, b]) if a <= self.low && self.high <= b => format!(
                    "; its bootstrap interval ({:.3e} to {:.3e}) lies inside the gap between the runs' Q = {a:.3e} \
                     and {b:.3e}, so it reflects the straight line, not the data",
                    self.low, self.high
                ),
                _ => String::new(),
            };
            format!(
                "Q*_D = {:.3e} erg/g is underdetermined: {} Q value(s) below it and {} above (of {}), fewer than two \
                 on each side{gap}; add projectiles or speeds around it",
                self.q_star, self.levels_below, self.levels_above, self.q_levels
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
    let level_q: Vec<f64> = groups.iter().map(|g| q[g[0]]).collect();
    let below = level_q.iter().filter(|&&x| x < q_star).count();
    let above = level_q.iter().filter(|&&x| x > q_star).count();
    let bracket = (below > 0 && above > 0).then(|| [level_q[below - 1], level_q[level_q.len() - above]]);
    Ok(QStarBootstrap {
        q_star,
        low: quantile(&found, 0.025),
        high: quantile(&found, 0.975),
        resamples,
        crossings: found.len(),
        seed,
        q_levels: groups.len(),
        levels_below: below,
        levels_above: above,
        bracket,
        underdetermined: below < 2 || above < 2,
    })
}
