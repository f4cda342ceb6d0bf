//! Linearly implicit Euler extrapolation (SEULEX) for stiff systems: `method = "bulirsch-stoer-implicit"`.
//!
//! Source of the method: E. Hairer & G. Wanner, *Solving Ordinary Differential Equations II: Stiff and
//! Differential-Algebraic Problems* (2nd ed., Springer 1996), §IV.9 "Extrapolation methods" (the linearly implicit
//! Euler method, its h-expansion for an arbitrary matrix `J`, and the strategy of their code SEULEX: harmonic
//! step-number sequence, order and step-size selection by work per unit step, stability check). This is an
//! independent implementation written from that description, in the structure of our [`super::bulirsch_stoer`].
//!
//! # The method
//!
//! At the start `(t, y)` of a step of size `H` the system supplies its stiff part, a matrix `J ≈ ∂f/∂y`
//! ([`OdeSystem::stiff_part`]), which is kept for every substep of the step. Column `j` takes `n_j = j` substeps of
//! `h = H/n_j` of the linearly implicit Euler method
//!
//! ```text
//! (I − h J) Δ_m = h f(t + m h, y_m),   y_{m+1} = y_m + Δ_m,   T_{j,1} = y_{n_j}
//! ```
//!
//! whose error has an expansion in powers of `h` for any fixed `J` (a W-method: `J` need not be the exact
//! Jacobian, only the stability depends on how well it represents the stiff part), and extrapolates it with the
//! Aitken–Neville tableau `T_{j,k+1} = T_{j,k} + (T_{j,k} − T_{j−1,k}) / (n_j/n_{j−k} − 1)`; `T_{j,j}` has order `j`.
//! The error estimate of column `j` is `‖T_{j,j} − T_{j,j−1}‖` in the scaled RMS norm of [`Tolerances`]. A system
//! without a stiff part (`J = 0`) is integrated by extrapolated explicit Euler — correct, but slower than
//! [`super::bulirsch_stoer`].
//!
//! # Tolerances, step and order control
//!
//! As in [`super::bulirsch_stoer`]: with the run's span known ([`Integrator::set_span`]) a step of length `H` is
//! accepted when `err ≤ s H / T` (`s =` [`super::bulirsch_stoer::RUN_BUDGET`]), so `rtol` and `atol` (scale-free,
//! in m, m/s, rad/s) bound the error of the whole run; without it, of each step. The next step and column count
//! minimise the work per unit step `A_j / H_j` (`A_j = n_1 + … + n_j` substeps, each one evaluation and one linear
//! solve) over the columns `k − 1, k, k + 1`, with SEULEX's safety factors; a step whose error estimate grows with
//! the column, or whose second substep increment in column 2 exceeds twice the first (the stiff part left
//! unresolved by `J`), is retried with half the step. Output times are landed on exactly by shortening the last
//! step, and the un-shortened proposal is kept for the next call. The increments are summed into the state with
//! Kahan's compensation, saved with the checkpoint state, so a resumed run is bit-identical.

use nalgebra::{DMatrix, DVector};

use super::bulirsch_stoer::{RUN_BUDGET, validate_tolerances};
use super::common::{
    IntegrateError, Integrator, IntegratorState, Method, OdeSystem, Rejections, Stats, Tolerances, begin_advance,
};
pub use super::common::{LinearlyImplicitState, StiffSolve};
use super::compensated::Compensation;

/// A dense `J` (row-major `n × n`) solved by LU, refactorised when `h` changes: for small systems and tests.
#[derive(Debug, Clone)]
pub struct DenseStiff {
    n: usize,
    jacobian: Vec<f64>,
    factor: Option<(u64, nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>)>,
}

impl DenseStiff {
    /// `J` of dimension `n` from its entries row by row (`jacobian.len() == n²`, units of `1/s`).
    pub fn new(n: usize, jacobian: Vec<f64>) -> Self {
        assert_eq!(jacobian.len(), n * n, "DenseStiff: jacobian must have n² entries");
        DenseStiff {
            n,
            jacobian,
            factor: None,
        }
    }
}

impl StiffSolve for DenseStiff {
    fn solve(&mut self, h: f64, b: &mut [f64]) {
        let n = self.n;
        if self.factor.as_ref().is_none_or(|(bits, _)| *bits != h.to_bits()) {
            let a = DMatrix::from_fn(n, n, |r, c| f64::from(u8::from(r == c)) - h * self.jacobian[r * n + c]);
            self.factor = Some((h.to_bits(), a.lu()));
        }
        let (_, lu) = self.factor.as_ref().expect("factor set above");
        let x = lu
            .solve(&DVector::from_column_slice(b))
            .unwrap_or_else(|| DVector::from_element(n, f64::NAN));
        b.copy_from_slice(x.as_slice());
    }
}

/// Lower bound on the step-size factor (SEULEX `fac1`).
const FAC1: f64 = 0.1;
/// Upper bound on the step-size factor (SEULEX `fac2`).
const FAC2: f64 = 4.0;
/// Order decrease threshold on the work ratio (SEULEX `fac3`).
const FAC3: f64 = 0.7;
/// Order increase threshold on the work ratio (SEULEX `fac4`).
const FAC4: f64 = 0.9;
/// Safety factor on the error (SEULEX `safe1`).
const SAFE1: f64 = 0.6;
/// Safety factor on the step (SEULEX `safe2`).
const SAFE2: f64 = 0.93;
/// Step reduction after a failed stability check or a growing or non-finite error.
const SAFE3: f64 = 0.5;
/// Limit on `‖Δ_1‖ / ‖Δ_0‖` in the stability check of column 2.
const STABILITY_RATIO: f64 = 2.0;
/// Default maximum number of columns (SEULEX `km`): the highest order is `km`.
pub const DEFAULT_MAX_COLUMNS: usize = 12;
/// Default maximum number of step attempts per call to [`Integrator::advance`].
pub const DEFAULT_MAX_STEPS: u64 = 100_000_000;
/// Consecutive non-finite rejections before giving up.
const MAX_NONFINITE_RETRIES: u32 = 10;

/// Linearly implicit Euler extrapolation (SEULEX strategy), see the [module documentation](self).
///
/// ```
/// use rubblepile::integrate::{Integrator, Tolerances, linearly_implicit::LinearlyImplicit};
/// use rubblepile::integrate::problems::{StiffDampedOscillator, TestProblem};
///
/// let osc = StiffDampedOscillator::default(); // damping 1000 times faster than the slow mode
/// let mut li = LinearlyImplicit::new(Tolerances::uniform(1e-8, 1e-8, 2)).unwrap();
/// let (mut t, mut y) = (0.0, osc.initial_state());
/// li.advance(&osc, &mut t, &mut y, osc.t_end()).unwrap();
/// let exact = osc.exact(t).unwrap();
/// assert!((y[0] - exact[0]).abs() < 1e-6);
/// assert!(li.stats().steps_accepted < 200); // an explicit method needs ~1e6 steps here
/// ```
#[derive(Debug, Clone)]
pub struct LinearlyImplicit {
    tol: Tolerances,
    km: usize,
    max_steps: u64,
    /// Wall-clock instant after which an advance stops ([`IntegrateError::Deadline`]); not part of the saved state.
    deadline: Option<std::time::Instant>,
    span: Option<f64>,
    /// Proposed |H| for the next step; 0 = unknown.
    h: f64,
    /// Target column count `k`, `2 ..= km − 1`.
    k: usize,
    reject: bool,
    started: bool,
    /// Step numbers `n_j = j` and cumulative work `A_j`, 1-based.
    nj: Vec<f64>,
    a: Vec<f64>,
    /// Optimal step and work per unit step per column of the last attempt, 1-based.
    hh: Vec<f64>,
    w: Vec<f64>,
    n: usize,
    /// `f(t, y)` at the step's start.
    f0: Vec<f64>,
    /// The derivative at a trial state.
    f: Vec<f64>,
    /// The increment of a column's substeps from the step's start.
    d: Vec<f64>,
    delta: Vec<f64>,
    trial: Vec<f64>,
    scal: Vec<f64>,
    /// The tableau, `km` rows of `n` (increments from the step's start).
    tab: Vec<f64>,
    /// Compensated summation of the accepted increments ([`Compensation`]).
    comp: Compensation,
    stats: Stats,
    rejections: Rejections,
    solves: u64,
}

enum Column {
    Done(f64),
    Shrink(Shrink),
}

#[derive(Clone, Copy)]
enum Shrink {
    Stability,
    Divergence,
    NonFinite,
}

enum Attempt {
    Accepted,
    Rejected,
    Shrink(Shrink),
}

/// The identity solve of a system without a stiff part (`J = 0`).
struct NoStiffPart;

impl StiffSolve for NoStiffPart {
    fn solve(&mut self, _h: f64, _b: &mut [f64]) {}
}

impl LinearlyImplicit {
    /// A new integrator with per-component `tolerances` (see [`Tolerances`]). Errors with
    /// [`IntegrateError::Config`] on tolerances of different lengths, negative, non-finite, or both zero.
    pub fn new(tolerances: Tolerances) -> Result<Self, IntegrateError> {
        validate_tolerances(&tolerances)?;
        let km = DEFAULT_MAX_COLUMNS;
        let nj: Vec<f64> = (0..=km).map(|j| j as f64).collect();
        let mut a = vec![0.0; km + 1];
        for j in 1..=km {
            a[j] = a[j - 1] + nj[j];
        }
        let rtol = tolerances.rtol.iter().copied().fold(f64::INFINITY, f64::min);
        // SEULEX's initial column count from the tolerance: about one order per decade of it.
        let k0 = (-(rtol + f64::EPSILON).log10() * 0.6 + 1.5).floor();
        let k = if k0.is_finite() {
            (k0.max(0.0) as usize).clamp(2, km - 1)
        } else {
            2
        };
        Ok(LinearlyImplicit {
            tol: tolerances,
            km,
            max_steps: DEFAULT_MAX_STEPS,
            deadline: None,
            span: None,
            h: 0.0,
            k,
            reject: false,
            started: false,
            nj,
            a,
            hh: vec![0.0; km + 1],
            w: vec![0.0; km + 1],
            n: 0,
            f0: Vec::new(),
            f: Vec::new(),
            d: Vec::new(),
            delta: Vec::new(),
            trial: Vec::new(),
            scal: Vec::new(),
            tab: Vec::new(),
            comp: Compensation::default(),
            stats: Stats {
                smallest_step: f64::INFINITY,
                ..Stats::default()
            },
            rejections: Rejections::default(),
            solves: 0,
        })
    }

    /// Rejected steps by cause (cumulative).
    pub fn rejections(&self) -> Rejections {
        self.rejections
    }

    /// Linear solves `(I − h J) x = b` so far (one per substep).
    pub fn solves(&self) -> u64 {
        self.solves
    }

    /// The current target column count `k` (order `k`).
    pub fn columns(&self) -> usize {
        self.k
    }

    fn ensure_workspace(&mut self, n: usize) {
        if self.n == n && self.f0.len() == n {
            return;
        }
        self.n = n;
        for v in [
            &mut self.f0,
            &mut self.f,
            &mut self.d,
            &mut self.delta,
            &mut self.trial,
            &mut self.scal,
        ] {
            *v = vec![0.0; n];
        }
        self.tab = vec![0.0; self.km * n];
    }

    /// The scaled RMS norm of `v` against `scal`.
    fn norm(&self, v: &[f64]) -> f64 {
        let sum: f64 = v.iter().zip(&self.scal).map(|(x, s)| (x / s).powi(2)).sum();
        (sum / self.n as f64).sqrt()
    }

    /// Initial step from `‖y‖/‖f‖` (the first half of Hairer's `hinit`): the step control grows it by up to
    /// `FAC2` per step.
    fn initial_step(&self, y: &[f64], span: f64) -> f64 {
        let d0 = self.norm(y);
        let d1 = self.norm(&self.f0);
        let h0 = if d0 < 1e-5 || d1 < 1e-5 { 1e-6 } else { 0.01 * d0 / d1 };
        if h0.is_finite() && h0 > 0.0 {
            h0.min(span)
        } else {
            1e-6f64.min(span)
        }
    }

    /// Column `j` of the tableau for the step `(t, y) → t + h` with the stiff part `stiff`.
    #[allow(clippy::too_many_arguments)]
    fn column(
        &mut self,
        system: &dyn OdeSystem,
        stiff: &mut dyn StiffSolve,
        t: f64,
        y: &[f64],
        h: f64,
        j: usize,
        err_prev: &mut f64,
    ) -> Column {
        let n = self.n;
        let nsub = j;
        let hj = h / self.nj[j];
        self.d.fill(0.0);
        let mut first_norm = 0.0;
        for m in 0..nsub {
            if m == 0 {
                self.delta.copy_from_slice(&self.f0);
            } else {
                for ((z, &yi), &di) in self.trial.iter_mut().zip(y).zip(&self.d) {
                    *z = yi + di;
                }
                self.stats.rhs_evaluations += 1;
                system.rhs(t + hj * m as f64, &self.trial, &mut self.f);
                self.delta.copy_from_slice(&self.f);
            }
            for x in self.delta.iter_mut() {
                *x *= hj;
            }
            stiff.solve(hj, &mut self.delta);
            self.solves += 1;
            if !self.delta.iter().all(|x| x.is_finite()) {
                return Column::Shrink(Shrink::NonFinite);
            }
            if j == 2 {
                let size = self.norm(&self.delta);
                if m == 0 {
                    first_norm = size;
                } else if first_norm > 0.0 && size > STABILITY_RATIO * first_norm {
                    return Column::Shrink(Shrink::Stability);
                }
            }
            for (di, &x) in self.d.iter_mut().zip(&self.delta) {
                *di += x;
            }
        }
        self.tab[(j - 1) * n..j * n].copy_from_slice(&self.d);
        if j == 1 {
            return Column::Done(0.0);
        }
        // Aitken–Neville in h: row r (0-based) becomes T_{j, j−r}.
        for l in (2..=j).rev() {
            let inv = 1.0 / (self.nj[j] / self.nj[l - 1] - 1.0);
            let (lo, hi) = self.tab.split_at_mut((l - 1) * n);
            for (dst, &src) in lo[(l - 2) * n..].iter_mut().zip(&hi[..n]) {
                *dst = src + (src - *dst) * inv;
            }
        }
        let mut sum = 0.0;
        {
            let (r0, r1) = self.tab.split_at(n);
            for i in 0..n {
                let sc =
                    (self.tol.atol[i] + self.tol.rtol[i] * y[i].abs().max((y[i] + r0[i]).abs())).max(f64::MIN_POSITIVE);
                sum += ((r0[i] - r1[i]) / sc).powi(2);
            }
        }
        let mut err = (sum / n as f64).sqrt();
        if let Some(span) = self.span {
            let rtol = self.tol.rtol.iter().copied().fold(f64::INFINITY, f64::min);
            let floor = (10.0 * f64::EPSILON / rtol).min(1.0);
            err /= (RUN_BUDGET * h.abs() / span).clamp(floor, 1.0);
        }
        if err.is_nan() {
            return Column::Shrink(Shrink::NonFinite);
        }
        if err * f64::EPSILON >= 1.0 || (j > 2 && err >= *err_prev) {
            return Column::Shrink(Shrink::Divergence);
        }
        *err_prev = (4.0 * err).max(1.0);
        // T_{j,j−1} has order j − 1: its local error is O(H^j), per unit step O(H^{j−1}).
        let expo = if self.span.is_some() {
            1.0 / (j - 1) as f64
        } else {
            1.0 / j as f64
        };
        let facmin = FAC1.powf(expo);
        let fac = (FAC2 / facmin).min(facmin.max((err / SAFE1).powf(expo) / SAFE2));
        self.hh[j] = h.abs() / fac;
        self.w[j] = self.a[j] / self.hh[j];
        Column::Done(err)
    }

    /// One step attempt (SEULEX's column strategy with its convergence monitor); `special` = first or last step,
    /// where the column count grows until convergence.
    fn attempt(
        &mut self,
        system: &dyn OdeSystem,
        stiff: &mut dyn StiffSolve,
        t: f64,
        y: &[f64],
        h: f64,
        special: bool,
    ) -> Attempt {
        for ((sc, &yi), (&a, &r)) in self
            .scal
            .iter_mut()
            .zip(y)
            .zip(self.tol.atol.iter().zip(&self.tol.rtol))
        {
            *sc = (a + r * yi.abs()).max(f64::MIN_POSITIVE);
        }
        let k = self.k;
        let mut err_prev = f64::INFINITY;
        let mut err = 0.0;
        macro_rules! column {
            ($j:expr) => {
                match self.column(system, stiff, t, y, h, $j, &mut err_prev) {
                    Column::Done(e) => err = e,
                    Column::Shrink(why) => return Attempt::Shrink(why),
                }
            };
        }
        if special {
            for j in 1..=k {
                column!(j);
                if j > 1 && err <= 1.0 {
                    return self.accept(j, h.abs());
                }
            }
        } else {
            for j in 1..k {
                column!(j);
            }
            if !(k == 2 || self.reject) {
                if err <= 1.0 {
                    return self.accept(k - 1, h.abs());
                }
                if err > self.nj[k + 1] * self.nj[k] * 4.0 {
                    return self.reject_step(k - 1);
                }
            }
            column!(k);
            if err <= 1.0 {
                return self.accept(k, h.abs());
            }
        }
        if err > self.nj[k + 1] * 2.0 {
            return self.reject_step(k);
        }
        column!(k + 1);
        if err > 1.0 {
            self.reject_step(k + 1)
        } else {
            self.accept(k + 1, h.abs())
        }
    }

    /// Step accepted after `kc` columns: the next column count minimises the work per unit step.
    fn accept(&mut self, kc: usize, h_abs: f64) -> Attempt {
        let km = self.km;
        let w = &self.w;
        let kopt = if kc == 2 {
            if self.reject { 2 } else { 3.min(km - 1) }
        } else {
            let mut kopt = kc;
            if w[kc - 1] < w[kc] * FAC3 {
                kopt = kc - 1;
            }
            if w[kc] < w[kc - 1] * FAC4 {
                kopt = (kc + 1).min(km - 1);
            }
            kopt
        };
        // Accepted in column km (one past the target k = km − 1): the target stays below km.
        let kopt = kopt.min(km - 1);
        // The tableau's answer is column kc: put T_{kc,kc} in row 0 (it is there already).
        if self.reject {
            self.k = kopt.min(kc);
            self.h = h_abs.min(self.hh[self.k]);
            self.reject = false;
        } else {
            self.h = if kopt <= kc {
                self.hh[kopt]
            } else {
                self.hh[kc] * self.a[kopt] / self.a[kc]
            };
            self.k = kopt;
        }
        Attempt::Accepted
    }

    /// Step rejected by the error test after `kc` columns: reduce the column count and the step.
    fn reject_step(&mut self, kc: usize) -> Attempt {
        let mut k = self.k.min(kc).min(self.km - 1);
        if k > 2 && self.w[k - 1] < self.w[k] * FAC3 {
            k -= 1;
        }
        self.k = k;
        self.h = self.hh[k];
        self.reject = true;
        Attempt::Rejected
    }

    fn advance_steps(
        &mut self,
        system: &dyn OdeSystem,
        t: &mut f64,
        y: &mut [f64],
        t_target: f64,
    ) -> Result<(), IntegrateError> {
        let n = self.n;
        let dir = if t_target > *t { 1.0 } else { -1.0 };
        system.begin_step(*t, y);
        self.stats.rhs_evaluations += 1;
        system.rhs(*t, y, &mut self.f0);
        if !self.f0.iter().all(|x| x.is_finite()) {
            return Err(IntegrateError::NonFinite { t: *t });
        }
        let mut stiff = system.stiff_part(*t, y).unwrap_or_else(|| Box::new(NoStiffPart));
        if self.h == 0.0 {
            for (sc, (&yi, (&a, &r))) in self
                .scal
                .iter_mut()
                .zip(y.iter().zip(self.tol.atol.iter().zip(&self.tol.rtol)))
            {
                *sc = (a + r * yi.abs()).max(f64::MIN_POSITIVE);
            }
            self.h = self.initial_step(y, (t_target - *t).abs());
        }
        let mut attempts: u64 = 0;
        let mut nonfinite_run: u32 = 0;
        let mut clean = true;
        loop {
            let remaining = (t_target - *t).abs();
            let last = self.h * 1.01 >= remaining;
            if !last && (self.h.is_nan() || self.h < 10.0 * f64::EPSILON * t.abs() || self.h == 0.0) {
                return Err(if nonfinite_run > 0 {
                    IntegrateError::NonFinite { t: *t }
                } else {
                    IntegrateError::StepUnderflow { t: *t, h: dir * self.h }
                });
            }
            if self.deadline.is_some_and(|d| std::time::Instant::now() >= d) {
                return Err(IntegrateError::Deadline { t: *t });
            }
            if attempts >= self.max_steps {
                return Err(IntegrateError::TooManySteps {
                    t: *t,
                    max_steps: self.max_steps,
                });
            }
            attempts += 1;
            let h_abs = if last { remaining } else { self.h };
            let (saved_h, saved_k) = (self.h, self.k);
            let special = !self.started || last;
            self.started = true;
            match self.attempt(system, stiff.as_mut(), *t, y, dir * h_abs, special) {
                Attempt::Accepted => {
                    self.comp.add(y, &self.tab[..n]);
                    self.stats.steps_accepted += 1;
                    if !(last && h_abs < saved_h) {
                        self.stats.smallest_step = self.stats.smallest_step.min(h_abs);
                    }
                    nonfinite_run = 0;
                    if last {
                        *t = t_target;
                        if clean && h_abs < saved_h {
                            self.h = self.h.max(saved_h);
                            self.k = saved_k;
                        }
                        return Ok(());
                    }
                    *t += dir * h_abs;
                    clean = true;
                    system.begin_step(*t, y);
                    self.stats.rhs_evaluations += 1;
                    system.rhs(*t, y, &mut self.f0);
                    if !self.f0.iter().all(|x| x.is_finite()) {
                        return Err(IntegrateError::NonFinite { t: *t });
                    }
                    // The stiff part of the next step, linearised at its start.
                    stiff = system.stiff_part(*t, y).unwrap_or_else(|| Box::new(NoStiffPart));
                }
                Attempt::Rejected => {
                    self.stats.steps_rejected += 1;
                    self.rejections.error += 1;
                    nonfinite_run = 0;
                    clean = false;
                }
                Attempt::Shrink(why) => {
                    self.stats.steps_rejected += 1;
                    self.h = h_abs * SAFE3;
                    self.reject = true;
                    clean = false;
                    match why {
                        Shrink::Stability => self.rejections.stability += 1,
                        Shrink::Divergence => self.rejections.divergence += 1,
                        Shrink::NonFinite => self.rejections.nonfinite += 1,
                    }
                    if let Shrink::NonFinite = why {
                        nonfinite_run += 1;
                        if nonfinite_run > MAX_NONFINITE_RETRIES {
                            return Err(IntegrateError::NonFinite { t: *t });
                        }
                    } else {
                        nonfinite_run = 0;
                    }
                }
            }
        }
    }
}

impl Integrator for LinearlyImplicit {
    fn set_max_steps(&mut self, max_steps: u64) {
        self.max_steps = max_steps.max(1);
    }

    fn set_deadline(&mut self, deadline: Option<std::time::Instant>) {
        self.deadline = deadline;
    }

    fn advance(
        &mut self,
        system: &dyn OdeSystem,
        t: &mut f64,
        y: &mut [f64],
        t_target: f64,
    ) -> Result<(), IntegrateError> {
        let n = system.dim();
        if !begin_advance(n, self.tol.rtol.len(), t, y, t_target)? {
            return Ok(());
        }
        self.ensure_workspace(n);
        self.comp.begin(y);
        let result = self.advance_steps(system, t, y, t_target);
        system.end_steps();
        self.comp.end(y);
        result
    }

    fn stats(&self) -> Stats {
        self.stats
    }

    fn set_span(&mut self, span: f64) {
        self.span = (span.is_finite() && span > 0.0).then_some(span);
    }

    fn method(&self) -> Method {
        Method::BulirschStoerImplicit
    }

    fn save_state(&self) -> IntegratorState {
        IntegratorState::LinearlyImplicit(LinearlyImplicitState {
            dim: self.tol.rtol.len(),
            km: self.km,
            max_steps: self.max_steps,
            span: self.span,
            h: self.h,
            k: self.k,
            reject: self.reject,
            started: self.started,
            hh: self.hh.clone(),
            w: self.w.clone(),
            stats: self.stats.into(),
            rejections: self.rejections,
            solves: self.solves,
            compensation: self.comp.carry.clone(),
        })
    }

    fn restore_state(&mut self, state: &IntegratorState) -> Result<(), IntegrateError> {
        let s = match state {
            IntegratorState::LinearlyImplicit(s) => s,
            other => {
                return Err(IntegrateError::Config(format!(
                    "cannot restore a {} state into bulirsch-stoer-implicit",
                    other.method()
                )));
            }
        };
        let bad = |what: String| Err(IntegrateError::Config(format!("bulirsch-stoer-implicit state: {what}")));
        if s.dim != self.tol.rtol.len() {
            return bad(format!(
                "saved for dimension {}, tolerances have {}",
                s.dim,
                self.tol.rtol.len()
            ));
        }
        if s.km != self.km || !(2..s.km).contains(&s.k) {
            return bad(format!("columns {} of {} (expected at most {})", s.k, s.km, self.km));
        }
        if s.hh.len() != s.km + 1 || s.w.len() != s.km + 1 {
            return bad(format!("per-column arrays must have {} entries", s.km + 1));
        }
        if !(s.h.is_finite() && s.h >= 0.0) || s.span.is_some_and(|t| !(t.is_finite() && t > 0.0)) {
            return bad(format!("bad step size {} or span {:?}", s.h, s.span));
        }
        if !(s.compensation.is_empty() || s.compensation.len() == s.dim)
            || !s.compensation.iter().all(|c| c.is_finite())
        {
            return bad(format!("compensation must be empty or {} finite entries", s.dim));
        }
        self.max_steps = s.max_steps;
        self.span = s.span;
        self.h = s.h;
        self.k = s.k;
        self.reject = s.reject;
        self.started = s.started;
        self.hh.copy_from_slice(&s.hh);
        self.w.copy_from_slice(&s.w);
        self.stats = s.stats.into();
        self.rejections = s.rejections;
        self.solves = s.solves;
        self.comp.carry.clone_from(&s.compensation);
        self.comp.forget_output();
        Ok(())
    }
}
