//! Adaptive Gragg–Bulirsch–Stoer extrapolation after ODEX: Hairer, Nørsett & Wanner, *Solving Ordinary
//! Differential Equations I* (2nd ed., Springer 1993), §II.9; an independent implementation of that description.
//!
//! A step `H` runs Gragg's midpoint rule ([`Midpoint`]) with `n_j = 2j` substeps and a smoothed end value, and
//! extrapolates to `h → 0` with the Aitken–Neville tableau `T_{j,k+1} = T_{j,k} + (T_{j,k} − T_{j−1,k}) /
//! ((n_j / n_{j−k})² − 1)` (`T_{j,j}` of order `2j`); the error is `‖T_{j,j} − T_{j,j−1}‖` in the scaled RMS norm
//! of [`Tolerances`]. Step and order control, convergence monitor and stability check (halve `H` when
//! `‖f(z_1) − f(z_0)‖² > 4 ‖f(z_0)‖²`, `safe3 = 0.5`) are ODEX's; the same control ([`Extrapolation`],
//! [`Strategy`]) drives SEULEX in `linearly_implicit.rs`, and the loop around the steps is [`Adaptive`]'s.
//!
//! Deviations from ODEX: (1) with the span `T` known ([`Integrator::set_span`]) a step is accepted when
//! `err ≤ s H / T` (`s =` [`RUN_BUDGET`], floored at `10 ε / rtol`) and the optimal step uses the exponent
//! `1/(2j − 2)`, so a run's final error follows `rtol` instead of growing with its step count; (2) rule and tableau
//! run on increments `d_m = z_m − y`, and `y += T_{k,k}` is Kahan-compensated (the compensation crosses
//! [`Integrator::advance`] and is saved by [`Integrator::save_state`]: a resume is bit-identical); (3) the stability
//! check is skipped when `f(t, y)` is exactly zero. A NaN/∞ estimate halves `H`; after
//! [`Adaptive::set_max_nonfinite_retries`] such rejections in a row, [`IntegrateError::NonFinite`].

use super::adaptive_loop::{
    Adaptive, Carried, Cause, FirstStep, Outcome, StepMethod, Trial, all_finite, bad_state, hinit_h0, hinit_h1,
    validate_tolerances, wrong_state,
};
pub use super::adaptive_loop::{DEFAULT_MAX_NONFINITE_RETRIES, DEFAULT_MAX_STEPS};
#[cfg(doc)]
use super::common::Integrator;
pub use super::common::{BulirschStoerState, ColumnControlState, Rejections};
use super::common::{IntegrateError, IntegratorState, Method, OdeSystem, Tolerances};
use super::compensated::Compensation;

/// ODEX's step and order control (its `fac1 … fac4`, `safe1`, `safe2`).
const ODEX: Strategy = Strategy {
    gragg: true,
    fac1: 0.02,
    fac2: 4.0,
    fac3: 0.8,
    fac4: 0.9,
    safe1: 0.65,
    safe2: 0.94,
};
/// Columns in which the stability check runs (ODEX `jstab`).
const STABILITY_COLUMNS: usize = 2;
/// Limit on `‖Δf‖² / ‖f‖²` in the stability check.
const STABILITY_RATIO: f64 = 4.0;
/// Share of the tolerance the local errors of a whole run may add up to under error-per-unit-step control
/// ([`Integrator::set_span`]). Below 1 because at the largest steps `‖T_{j,j} − T_{j,j−1}‖` underestimates the true
/// local error of `T_{j,j}`, and Kepler shear turns an along-track error into a growing one (the values tried:
/// `analysis/work_precision/NOTES.md`).
pub const RUN_BUDGET: f64 = 0.25;
/// Default maximum number of columns (ODEX `km`).
pub const DEFAULT_MAX_COLUMNS: usize = 9;

/// Adaptive Gragg–Bulirsch–Stoer extrapolation integrator (ODEX strategy), see the [module documentation](self):
/// the step loop [`Adaptive`] (which carries the step size, and here the column count, from one call to the next
/// and counts every RHS call, the initial-step guess included) around [`Extrapolation`] of Gragg's rule.
/// [`Adaptive::rejections`] splits the rejected steps by cause. The work arrays are allocated at the first call and
/// whenever the dimension changes; a step allocates nothing.
///
/// ```
/// use rubblepile::integrate::{Integrator, Tolerances, bulirsch_stoer::BulirschStoer};
/// use rubblepile::integrate::problems::{HarmonicOscillator, TestProblem};
///
/// let osc = HarmonicOscillator::new(1.0);
/// let mut bs = BulirschStoer::new(Tolerances::uniform(1e-12, 1e-12, 2), None).unwrap();
/// let (mut t, mut y) = (0.0, osc.initial_state());
/// for &t_out in &[0.5, 1.0, 2.5, 2.0 * std::f64::consts::PI] {
///     bs.advance(&osc, &mut t, &mut y, t_out).unwrap();
///     assert_eq!(t, t_out); // lands exactly on every output time
/// }
/// assert!((y[0] - 1.0).abs() < 1e-10 && y[1].abs() < 1e-10);
/// assert!(bs.stats().steps_accepted > 0);
/// ```
pub type BulirschStoer = Adaptive<Extrapolation<Midpoint>>;

impl BulirschStoer {
    /// A new integrator with per-component `tolerances` (of the dimension of the systems later passed to
    /// [`Integrator::advance`]) and an optional initial step `step` (|step| for the very first step, and again after
    /// [`Adaptive::reset`]; `None`: Hairer's `hinit` from `f(t0, y0)` and one more evaluation). Errors with
    /// [`IntegrateError::Config`] for tolerances [`validate_tolerances`] refuses or a `step` not non-zero and finite.
    pub fn new(tolerances: Tolerances, step: Option<f64>) -> Result<Self, IntegrateError> {
        validate_tolerances(&tolerances)?;
        Adaptive::with_method(
            Extrapolation::new(tolerances, DEFAULT_MAX_COLUMNS, Midpoint::default()),
            step,
        )
    }
}

impl<R: BaseRule> Adaptive<Extrapolation<R>> {
    /// Sets the maximum number of extrapolation columns `km` (`3 ≤ km ≤ 20`; ODEX's default 9, SEULEX's 12).
    /// The highest order reached is `2 km` with Gragg's rule, `km` with the Euler rule.
    pub fn set_max_columns(&mut self, km: usize) -> Result<(), IntegrateError> {
        if !(3..=20).contains(&km) {
            return Err(IntegrateError::Config(format!(
                "{} max columns must be in 3..=20, got {km}",
                R::METHOD
            )));
        }
        self.method.set_max_columns(km);
        Ok(())
    }

    /// The current target number of extrapolation columns `k` (order `2k` with Gragg's rule, `k` with the Euler
    /// rule).
    pub fn columns(&self) -> usize {
        self.method.k
    }
}

/// The constants and choices of an extrapolation code's step and order control: ODEX's for Gragg's rule (this
/// file), SEULEX's for the linearly implicit Euler rule (`linearly_implicit.rs`).
#[derive(Debug, Clone, Copy)]
pub struct Strategy {
    /// Gragg's rule (ODEX): `n_j = 2j` substeps, an error expansion in `h²`, the work `A_1 = n_1 + 1` (counting
    /// `f(t, y)`), ODEX's order choice after a step accepted in column `k + 1`, and an infinite error of a non-finite
    /// tableau counted as non-finite values; otherwise the Euler rule (SEULEX): `n_j = j`, an expansion in `h`,
    /// `A_1 = n_1`, the order chosen as after column `k`, an infinite error always a divergence.
    pub gragg: bool,
    /// Lower bound on the step-size factor (`fac1`).
    pub fac1: f64,
    /// Upper bound on the step-size factor (`fac2`).
    pub fac2: f64,
    /// Order decrease threshold on the work ratio (`fac3`).
    pub fac3: f64,
    /// Order increase threshold on the work ratio (`fac4`).
    pub fac4: f64,
    /// Safety factor on the error (`safe1`).
    pub safe1: f64,
    /// Safety factor on the step (`safe2`).
    pub safe2: f64,
}

/// The base rule an [`Extrapolation`] extrapolates — Gragg's modified midpoint rule ([`Midpoint`]) or the linearly
/// implicit Euler method (`linearly_implicit.rs`) — with the checkpoint layout of its method.
pub trait BaseRule: Default {
    /// What the rule takes from the system at the start of each step ([`StepMethod::Frozen`]).
    type Frozen<'s>;
    /// The method's name.
    const METHOD: Method;
    /// The step and order control of the code the rule comes from.
    const STRATEGY: Strategy;
    /// Sizes the rule's work arrays for dimension `n`.
    fn resize(&mut self, n: usize);
    /// Right-hand side evaluations so far.
    fn evaluations(&self) -> u64;
    /// [`StepMethod::start`]: the derivative at `(t, y)` and what the rule keeps for the step.
    fn start<'s>(&mut self, system: &'s dyn OdeSystem, t: f64, y: &[f64]) -> Option<Self::Frozen<'s>>;
    /// [`StepMethod::initial_step`], with `scal` the error scale at `y` and `k` the target column count.
    fn initial_step(&mut self, system: &dyn OdeSystem, y: &[f64], scal: &[f64], k: usize, first: &FirstStep) -> f64;
    /// Writes `T_{j,1}` of `column`, the rule's result with `n_j` substeps, as an increment from its `y` into `row`.
    fn column(
        &mut self,
        system: &dyn OdeSystem,
        frozen: &mut Self::Frozen<'_>,
        column: &Column<'_>,
        row: &mut [f64],
    ) -> Result<(), Cause>;
    /// Sets the evaluation count (a restored state's).
    fn set_evaluations(&mut self, n: u64);
    /// The method's checkpoint state from the column control's part.
    fn save(&self, km: usize, columns: ColumnControlState, carried: Carried) -> IntegratorState;
    /// The dimension, the number of columns, the column control's part and the compensation of `state`, with the
    /// loop's other settings it holds set into `carried`; [`IntegrateError::Config`] for another method's state.
    fn unpack<'a>(state: &'a IntegratorState, carried: &mut Carried) -> Unpacked<'a>;
    /// Restores the rule's own part of `state` (after every check passed).
    fn restore_own(&mut self, _state: &IntegratorState) {}
}

/// Column `j` of the step `trial` from `y`, as [`BaseRule::column`] is asked for it.
pub struct Column<'a> {
    /// The state at the step's start.
    pub y: &'a [f64],
    /// The step.
    pub trial: &'a Trial,
    /// The column (1-based).
    pub j: usize,
    /// The error scale `atol_i + rtol_i |y_i|` (for the stability checks).
    pub scal: &'a [f64],
}

/// What [`BaseRule::unpack`] reads of a state: its dimension, number of columns, column control and compensation.
pub type Unpacked<'a> = Result<(usize, usize, &'a ColumnControlState, &'a [f64]), IntegrateError>;

/// An extrapolation step: the base rule `R` in columns `j = 1, 2, …` extrapolated by Aitken–Neville, with the
/// column (order) and step control of ODEX or SEULEX ([`BaseRule::STRATEGY`]).
#[derive(Debug, Clone, Default)]
pub struct Extrapolation<R> {
    tol: Tolerances,
    /// Maximum number of columns `km`.
    km: usize,
    /// Target column count `k` (ODEX `K`), `2 ..= km − 1`.
    k: usize,
    /// The previous attempt was rejected.
    reject: bool,
    /// At least one step has been attempted (ODEX `nstep > 0`).
    started: bool,
    /// Span of the whole run (s) for error-per-unit-step control; `None` = error per step.
    span: Option<f64>,
    // Step-number sequence and per-column data, 1-based (index 0 unused).
    nj: Vec<f64>,
    a: Vec<f64>,
    hh: Vec<f64>,
    w: Vec<f64>,
    n: usize,
    /// `atol_i + rtol_i |y_i|` at the step's start.
    scal: Vec<f64>,
    /// The tableau, `km` rows of `n` (increments from the step's start).
    tab: Vec<f64>,
    rule: R,
}

/// The scaled RMS norm of `v` against `scal`.
pub(super) fn rms(v: &[f64], scal: &[f64]) -> f64 {
    let sum: f64 = v.iter().zip(scal).map(|(x, s)| (x / s).powi(2)).sum();
    (sum / v.len() as f64).sqrt()
}

impl<R: BaseRule> Extrapolation<R> {
    /// The step of `rule` with `km` columns (`3 ≤ km ≤ 20`) for per-component `tol` (validated).
    pub(super) fn new(tol: Tolerances, km: usize, rule: R) -> Self {
        let mut e = Extrapolation {
            tol,
            km,
            rule,
            ..Extrapolation::default()
        };
        e.setup_sequence();
        e.k = e.initial_columns();
        e
    }

    /// The rule itself.
    pub(super) fn rule(&self) -> &R {
        &self.rule
    }

    fn set_max_columns(&mut self, km: usize) {
        self.km = km;
        self.setup_sequence();
        self.k = self.k.clamp(2, km - 1);
        if self.n > 0 {
            self.tab = vec![0.0; km * self.n];
        }
    }

    /// Step-number sequence `n_j` and cumulative work `A_j = A_1 + n_2 + … + n_j`.
    fn setup_sequence(&mut self) {
        let km = self.km;
        let gragg = R::STRATEGY.gragg;
        self.nj = (0..=km)
            .map(|j| if gragg { 2.0 * j as f64 } else { j as f64 })
            .collect();
        self.a = vec![0.0; km + 1];
        self.a[1] = self.nj[1] + if gragg { 1.0 } else { 0.0 };
        for j in 2..=km {
            self.a[j] = self.a[j - 1] + self.nj[j];
        }
        self.hh = vec![0.0; km + 1];
        self.w = vec![0.0; km + 1];
    }

    /// The initial column count from the tightest relative tolerance (ODEX, SEULEX).
    fn initial_columns(&self) -> usize {
        let rtol = self.tol.rtol.iter().copied().fold(f64::INFINITY, f64::min);
        let guess = (-(rtol + f64::EPSILON).log10() * 0.6 + 1.5).floor();
        let guess = if guess.is_finite() { guess.max(0.0) as usize } else { 2 };
        guess.min(self.km - 1).max(2)
    }

    /// `scal_i = atol_i + rtol_i |y_i|` (floored at the smallest positive normal number).
    fn fill_scal(&mut self, y: &[f64]) {
        for (((sc, &yi), &a), &r) in self.scal.iter_mut().zip(y).zip(&self.tol.atol).zip(&self.tol.rtol) {
            *sc = (a + r * yi.abs()).max(f64::MIN_POSITIVE);
        }
    }

    /// `((n_{k+1} n_k / 4)²` (Gragg) or `4 n_{k+1} n_k` (Euler): above it column `k − 1`'s error leaves no hope of
    /// convergence in column `k + 1` (the convergence monitor).
    fn monitor_limit(&self, k: usize) -> f64 {
        if R::STRATEGY.gragg {
            let lim = self.nj[k + 1] * self.nj[k] / 4.0;
            lim * lim
        } else {
            self.nj[k + 1] * self.nj[k] * 4.0
        }
    }

    /// `(n_{k+1} / 2)²` (Gragg) or `2 n_{k+1}` (Euler): above it column `k`'s error leaves no hope of convergence in
    /// column `k + 1`.
    fn hope_limit(&self, k: usize) -> f64 {
        if R::STRATEGY.gragg {
            let lim = self.nj[k + 1] / 2.0;
            lim * lim
        } else {
            self.nj[k + 1] * 2.0
        }
    }

    /// Computes column `j` (1-based) of the tableau for the step `trial` from `y`, extrapolates, and for `j ≥ 2`
    /// estimates the error and the optimal step `hh[j]` and work `w[j]`. `err_prev` holds the (floored) error of
    /// the previous column.
    fn column(
        &mut self,
        system: &dyn OdeSystem,
        frozen: &mut R::Frozen<'_>,
        y: &[f64],
        trial: &Trial,
        j: usize,
        err_prev: &mut f64,
    ) -> Result<f64, Cause> {
        let n = self.n;
        let column = Column {
            y,
            trial,
            j,
            scal: &self.scal,
        };
        self.rule
            .column(system, frozen, &column, &mut self.tab[(j - 1) * n..j * n])?;
        if j == 1 {
            return Ok(0.0);
        }
        let gragg = R::STRATEGY.gragg;
        // Aitken–Neville: row r (0-based) becomes T_{j, j−r}.
        for l in (2..=j).rev() {
            let ratio = self.nj[j] / self.nj[l - 1];
            let inv = if gragg {
                1.0 / (ratio * ratio - 1.0)
            } else {
                1.0 / (ratio - 1.0)
            };
            let (lo, hi) = self.tab.split_at_mut((l - 1) * n);
            for (d, &s) in lo[(l - 2) * n..].iter_mut().zip(&hi[..n]) {
                *d = s + (s - *d) * inv;
            }
        }
        // Error estimate ‖T_{j,j} − T_{j,j−1}‖.
        let mut sum = 0.0;
        {
            let (r0, r1) = self.tab.split_at(n);
            for i in 0..n {
                let sc =
                    (self.tol.atol[i] + self.tol.rtol[i] * y[i].abs().max((y[i] + r0[i]).abs())).max(f64::MIN_POSITIVE);
                sum += ((r0[i] - r1[i]) / sc).powi(2);
            }
        }
        let h = trial.h;
        let mut err = (sum / n as f64).sqrt();
        if let Some(span) = self.span {
            // Error per unit step: this step may spend the share RUN_BUDGET·|h|/span of the tolerance. Below
            // 10 ε / rtol the share would ask for less than round-off can deliver.
            let rtol = self.tol.rtol.iter().copied().fold(f64::INFINITY, f64::min);
            let floor = (10.0 * f64::EPSILON / rtol).min(1.0);
            err /= (RUN_BUDGET * h.abs() / span).clamp(floor, 1.0);
        }
        if err.is_nan() || (gragg && err.is_infinite() && !all_finite(&self.tab[..n])) {
            return Err(Cause::NonFinite);
        }
        if err * f64::EPSILON >= 1.0 || (j > 2 && err >= *err_prev) {
            return Err(Cause::Divergence);
        }
        // ODEX: ERROLD = MAX(4*ERR, 1). A column only counts as diverging when its error is both above 1
        // (not converged) and more than four times the previous one; a smaller floor would reject steps
        // whose columns have converged to round-off noise (err ≪ 1 but not monotone), halving H forever.
        *err_prev = (4.0 * err).max(1.0);
        // The error of T_{j,j−1} is O(H^{p+1}), p = 2j − 2 (Gragg) or j − 1 (Euler); per unit step it is O(H^p).
        let order = if gragg { 2 * j - 1 } else { j };
        let expo = if self.span.is_some() {
            1.0 / (order - 1) as f64
        } else {
            1.0 / order as f64
        };
        let s = R::STRATEGY;
        let facmin = s.fac1.powf(expo);
        let fac = (s.fac2 / facmin).min(facmin.max((err / s.safe1).powf(expo) / s.safe2));
        self.hh[j] = (h.abs() / fac).min(trial.h_max);
        self.w[j] = self.a[j] / self.hh[j];
        Ok(err)
    }

    /// The columns of one attempt (ODEX's and SEULEX's strategy with the convergence monitor); `special` = first
    /// or last step, where the column count grows until convergence. On acceptance the increment `T_{k,k}` is in
    /// `tab[0..n]`.
    fn columns(
        &mut self,
        system: &dyn OdeSystem,
        frozen: &mut R::Frozen<'_>,
        y: &[f64],
        trial: &Trial,
        special: bool,
    ) -> Outcome {
        let (k, h_abs) = (self.k, trial.h.abs());
        let mut err_prev = f64::INFINITY;
        let mut err = 0.0;
        macro_rules! column {
            ($j:expr) => {
                match self.column(system, frozen, y, trial, $j, &mut err_prev) {
                    Ok(e) => err = e,
                    Err(why) => return Outcome::Halve(why),
                }
            };
        }
        if special {
            for j in 1..=k {
                column!(j);
                if j > 1 && err <= 1.0 {
                    return self.accept(j, h_abs, trial.h_max);
                }
            }
        } else {
            for j in 1..k {
                column!(j);
            }
            // Convergence monitor.
            if !(k == 2 || self.reject) {
                if err <= 1.0 {
                    return self.accept(k - 1, h_abs, trial.h_max);
                }
                if err > self.monitor_limit(k) {
                    return self.reject_step(k - 1);
                }
            }
            column!(k);
            if err <= 1.0 {
                return self.accept(k, h_abs, trial.h_max);
            }
        }
        // Hope for convergence in column k + 1.
        if err > self.hope_limit(k) {
            return self.reject_step(k);
        }
        column!(k + 1);
        if err > 1.0 {
            self.reject_step(k + 1)
        } else {
            self.accept(k + 1, h_abs, trial.h_max)
        }
    }

    /// Step accepted after `kc` columns: choose the next column count and step (ODEX, SEULEX).
    fn accept(&mut self, kc: usize, h_abs: f64, h_max: f64) -> Outcome {
        let s = R::STRATEGY;
        let (km, k, w) = (self.km, self.k, &self.w);
        let kopt = if kc == 2 {
            if self.reject { 2 } else { 3.min(km - 1) }
        } else if kc <= k || !s.gragg {
            let mut kopt = kc;
            if w[kc - 1] < w[kc] * s.fac3 {
                kopt = kc - 1;
            }
            if w[kc] < w[kc - 1] * s.fac4 {
                kopt = (kc + 1).min(km - 1);
            }
            kopt
        } else {
            let mut kopt = kc - 1;
            if kc > 3 && w[kc - 2] < w[kc - 1] * s.fac3 {
                kopt = kc - 2;
            }
            if w[kc] < w[kopt] * s.fac4 {
                kopt = kc.min(km - 1);
            }
            kopt
        };
        // Accepted in column km (one past the target k = km − 1): the target stays below km.
        let kopt = kopt.min(km - 1);
        let h_next = if self.reject {
            self.k = kopt.min(kc);
            self.reject = false;
            h_abs.min(self.hh[self.k])
        } else {
            let h_new = if kopt <= kc {
                self.hh[kopt]
            } else if s.gragg && kc < k && w[kc] < w[kc - 1] * s.fac4 {
                self.hh[kc] * self.a[kopt + 1] / self.a[kc]
            } else {
                self.hh[kc] * self.a[kopt] / self.a[kc]
            };
            self.k = kopt;
            h_new.min(h_max)
        };
        Outcome::Accepted { h_next }
    }

    /// Step rejected by the error test after `kc` columns: reduce `k` and the step (ODEX, SEULEX).
    fn reject_step(&mut self, kc: usize) -> Outcome {
        let mut k = self.k.min(kc).min(self.km - 1);
        if k > 2 && self.w[k - 1] < self.w[k] * R::STRATEGY.fac3 {
            k -= 1;
        }
        self.k = k;
        self.reject = true;
        Outcome::Rejected { h_next: self.hh[k] }
    }
}

impl<R: BaseRule> StepMethod for Extrapolation<R> {
    type Frozen<'s> = R::Frozen<'s>;
    const METHOD: Method = R::METHOD;

    fn tolerances(&self) -> &Tolerances {
        &self.tol
    }

    fn prepare(&mut self, n: usize) {
        if self.n == n && self.scal.len() == n {
            return;
        }
        self.n = n;
        self.scal = vec![0.0; n];
        self.tab = vec![0.0; self.km * n];
        self.rule.resize(n);
    }

    fn start<'s>(&mut self, system: &'s dyn OdeSystem, t: f64, y: &[f64]) -> Option<Self::Frozen<'s>> {
        self.rule.start(system, t, y)
    }

    fn initial_step(&mut self, system: &dyn OdeSystem, y: &[f64], first: &FirstStep) -> f64 {
        self.fill_scal(y);
        self.rule.initial_step(system, y, &self.scal, self.k, first)
    }

    fn attempt(&mut self, system: &dyn OdeSystem, frozen: &mut Self::Frozen<'_>, y: &[f64], trial: &Trial) -> Outcome {
        let special = !self.started || trial.last;
        self.started = true;
        self.fill_scal(y);
        let outcome = match self.columns(system, frozen, y, trial, special) {
            // Never hand a non-finite state to the caller (a non-finite value makes the error NaN, so this takes
            // an error scale without a relative part at least).
            Outcome::Accepted { .. } if !all_finite(&self.tab[..self.n]) => Outcome::Halve(Cause::NonFinite),
            outcome => outcome,
        };
        if let Outcome::Halve(_) = outcome {
            self.reject = true;
        }
        outcome
    }

    fn commit(&mut self, y: &mut [f64], comp: &mut Compensation) {
        comp.add(y, &self.tab[..self.n]);
    }

    fn evaluations(&self) -> u64 {
        self.rule.evaluations()
    }

    fn order(&self) -> usize {
        self.k
    }

    fn set_order(&mut self, order: usize) {
        self.k = order;
    }

    fn set_evaluations(&mut self, n: u64) {
        self.rule.set_evaluations(n);
    }

    fn set_span(&mut self, span: Option<f64>) {
        self.span = span;
    }

    fn reset(&mut self) {
        self.k = self.initial_columns();
        self.reject = false;
        self.started = false;
    }

    fn save(&self, carried: Carried) -> IntegratorState {
        let columns = ColumnControlState {
            span: self.span,
            h: carried.h,
            k: self.k,
            reject: self.reject,
            started: self.started,
            hh: self.hh.clone(),
            w: self.w.clone(),
            stats: carried.stats,
            rejections: carried.rejections,
        };
        self.rule.save(self.km, columns, carried)
    }

    fn restore(&mut self, state: &IntegratorState, carried: &mut Carried) -> Result<(), IntegrateError> {
        let (dim, km, s, compensation) = R::unpack(state, carried)?;
        carried.dim = dim;
        carried.compensation.clear();
        carried.compensation.extend_from_slice(compensation);
        (carried.h, carried.stats, carried.rejections) = (s.h, s.stats, s.rejections);
        carried.check(R::METHOD, self.tol.rtol.len())?;
        let bad = |what: String| Err(bad_state(R::METHOD, what));
        if !(3..=20).contains(&km) {
            return bad(format!("max columns {km} not in 3..=20"));
        }
        if !(2..km).contains(&s.k) {
            return bad(format!("column count {} not in 2..{km}", s.k));
        }
        if s.hh.len() != km + 1 || s.w.len() != km + 1 {
            return bad(format!("per-column arrays must have {} entries", km + 1));
        }
        if s.span.is_some_and(|t| !(t.is_finite() && t > 0.0)) {
            return bad("bad span".into());
        }
        if km != self.km {
            self.set_max_columns(km);
        }
        self.span = s.span;
        self.k = s.k;
        self.reject = s.reject;
        self.started = s.started;
        self.hh.copy_from_slice(&s.hh);
        self.w.copy_from_slice(&s.w);
        self.rule.restore_own(state);
        Ok(())
    }
}

/// Gragg's modified midpoint rule with smoothing (the base rule of ODEX), and its work arrays.
#[derive(Debug, Clone, Default)]
pub struct Midpoint {
    /// `f(t, y)` at the step's start.
    dz: Vec<f64>,
    /// The increments `d_{m−1}`, `d_m` from the step's start.
    yh1: Vec<f64>,
    yh2: Vec<f64>,
    /// The trial state `y + d_m` handed to the right-hand side.
    ytrial: Vec<f64>,
    /// The derivative at the trial state.
    dy: Vec<f64>,
    evals: u64,
}

impl Midpoint {
    /// `dy = f(t, ytrial)`, the derivative at the trial state `y + d_m`.
    fn eval_trial(&mut self, system: &dyn OdeSystem, t: f64) {
        self.evals += 1;
        system.rhs(t, &self.ytrial, &mut self.dy);
    }
}

impl BaseRule for Midpoint {
    type Frozen<'s> = ();
    const METHOD: Method = Method::BulirschStoer;
    const STRATEGY: Strategy = ODEX;

    fn resize(&mut self, n: usize) {
        for v in [
            &mut self.dz,
            &mut self.yh1,
            &mut self.yh2,
            &mut self.ytrial,
            &mut self.dy,
        ] {
            *v = vec![0.0; n];
        }
    }

    fn start(&mut self, system: &dyn OdeSystem, t: f64, y: &[f64]) -> Option<()> {
        system.begin_step(t, y);
        self.evals += 1;
        system.rhs(t, y, &mut self.dz);
        all_finite(&self.dz).then_some(())
    }

    /// Hairer's `hinit` with the order `2k`: `f(t, y)` is in `dz`, one more evaluation.
    fn initial_step(&mut self, system: &dyn OdeSystem, y: &[f64], scal: &[f64], k: usize, first: &FirstStep) -> f64 {
        let &FirstStep { t, dir, span, h_max } = first;
        let (d0, d1) = (rms(y, scal), rms(&self.dz, scal));
        let h0 = hinit_h0(d0, d1).min(span).min(h_max);
        if h0.is_nan() || h0 <= 0.0 {
            return 1e-6f64.min(h_max);
        }
        // Explicit Euler trial step into ytrial, derivative into dy.
        for ((z, &yi), &fi) in self.ytrial.iter_mut().zip(y).zip(&self.dz) {
            *z = yi + dir * h0 * fi;
        }
        self.eval_trial(system, t + dir * h0);
        let mut d2 = 0.0;
        for ((&f1, &f0), &sc) in self.dy.iter().zip(&self.dz).zip(scal) {
            d2 += ((f1 - f0) / sc).powi(2);
        }
        let d2 = (d2 / y.len() as f64).sqrt() / h0;
        let order = 2.0 * k as f64;
        hinit_h1(h0, d1, d2, 1.0 / (order + 1.0), span, h_max)
    }

    /// Gragg's rule with `n_j = 2j` substeps of `h_j = H/n_j`, on the increments `d_m = z_m − y`, with ODEX's
    /// stability check in the first substep of columns 1 and 2, and the smoothing step.
    fn column(
        &mut self,
        system: &dyn OdeSystem,
        _frozen: &mut (),
        column: &Column<'_>,
        row: &mut [f64],
    ) -> Result<(), Cause> {
        let &Column { y, trial, j, scal } = column;
        let (t, h) = (trial.t, trial.h);
        let nj = 2.0 * j as f64;
        let nsub = 2 * j;
        let hj = h / nj;
        let two_hj = 2.0 * hj;
        // Increments from the step's start: d_0 = 0 (yh1), d_1 = hj f(t, y) (yh2); the trial state z_1 = y + d_1.
        for (((a, b), z), (&yi, &fi)) in self
            .yh1
            .iter_mut()
            .zip(self.yh2.iter_mut())
            .zip(self.ytrial.iter_mut())
            .zip(y.iter().zip(self.dz.iter()))
        {
            *a = 0.0;
            *b = hj * fi;
            *z = yi + *b;
        }
        for m in 1..nsub {
            self.eval_trial(system, t + hj * m as f64);
            if m == 1 && j <= STABILITY_COLUMNS {
                let (mut del1, mut del2) = (0.0, 0.0);
                for ((&f0, &f1), &sc) in self.dz.iter().zip(&self.dy).zip(scal) {
                    del1 += (f0 / sc).powi(2);
                    del2 += ((f1 - f0) / sc).powi(2);
                }
                // ODEX floors ‖f‖² at ε; we skip the check when f(t, y) vanishes exactly
                // (nothing to compare with), otherwise it would halve H down to ~1e-20.
                if del1 > 0.0 && del2 > STABILITY_RATIO * del1.max(f64::EPSILON) {
                    return Err(Cause::Stability);
                }
            }
            // d_{m+1} = d_{m-1} + 2 hj f(z_m), stored over d_{m-1} (then swap roles), and z_{m+1} = y + d_{m+1}.
            for ((a, z), (&yi, &d)) in self
                .yh1
                .iter_mut()
                .zip(self.ytrial.iter_mut())
                .zip(y.iter().zip(self.dy.iter()))
            {
                *a += two_hj * d;
                *z = yi + *a;
            }
            std::mem::swap(&mut self.yh1, &mut self.yh2);
        }
        // Smoothing step.
        self.eval_trial(system, t + h);
        for (((r, &a), &b), &d) in row.iter_mut().zip(&self.yh1).zip(&self.yh2).zip(&self.dy) {
            *r = 0.5 * (a + b + hj * d);
        }
        Ok(())
    }

    fn evaluations(&self) -> u64 {
        self.evals
    }

    fn set_evaluations(&mut self, n: u64) {
        self.evals = n;
    }

    fn save(&self, km: usize, columns: ColumnControlState, carried: Carried) -> IntegratorState {
        IntegratorState::BulirschStoer(BulirschStoerState {
            dim: carried.dim,
            km,
            limits: carried.limits,
            initial_step: carried.initial_step,
            columns,
            compensation: carried.compensation,
        })
    }

    fn unpack<'a>(state: &'a IntegratorState, carried: &mut Carried) -> Unpacked<'a> {
        let IntegratorState::BulirschStoer(s) = state else {
            return Err(wrong_state(state, Self::METHOD));
        };
        (carried.limits, carried.initial_step) = (s.limits, s.initial_step);
        Ok((s.dim, s.km, &s.columns, &s.compensation))
    }
}
