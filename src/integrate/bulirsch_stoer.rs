//! Adaptive Gragg–Bulirsch–Stoer extrapolation integrator.
//!
//! Source of the method: E. Hairer, S. P. Nørsett & G. Wanner, *Solving Ordinary Differential
//! Equations I: Nonstiff Problems* (2nd ed., Springer 1993), §II.9 "Extrapolation methods", and
//! the strategy of their Fortran code ODEX described there (harmonic step-number sequence,
//! order and step-size selection by work per unit step, convergence monitor, stability check).
//! This is an independent implementation written from that description.
//!
//! # The method
//!
//! One step of size `H` from `(t, y)` computes, for columns `j = 1, 2, …`, Gragg's modified
//! midpoint rule with `n_j = 2j` substeps of size `h_j = H/n_j`
//!
//! ```text
//! z_0 = y,  z_1 = z_0 + h_j f(t, z_0),  z_{m+1} = z_{m−1} + 2 h_j f(t + m h_j, z_m)   (m = 1 … n_j − 1)
//! T_{j,1} = ½ (z_{n_j − 1} + z_{n_j} + h_j f(t + H, z_{n_j}))                           (smoothing)
//! ```
//!
//! whose error has an expansion in even powers of `h_j`, and extrapolates it to `h → 0` with the
//! Aitken–Neville tableau
//! `T_{j,k+1} = T_{j,k} + (T_{j,k} − T_{j−1,k}) / ((n_j / n_{j−k})² − 1)`.
//! `T_{j,j}` has order `2j`; the error estimate of column `j` is `‖T_{j,j} − T_{j,j−1}‖` in the
//! scaled RMS norm of [`Tolerances`] with `sc_i = atol_i + rtol_i · max(|y_i|, |y_i + T_{j,j,i}|)` (the
//! tableau holds increments, see below).
//!
//! # Step and order control (as in ODEX)
//!
//! For every column `j ≥ 2` an optimal step `H_j = H / fac_j` is proposed, with
//! `fac_j = min(fac2/facmin, max(facmin, (err_j/safe1)^{1/(2j−1)} / safe2))`,
//! `facmin = fac1^{1/(2j−1)}` (`fac1 = 0.02, fac2 = 4, safe1 = 0.65, safe2 = 0.94`), and its work
//! per unit step `W_j = A_j / H_j` (`A_j` = RHS evaluations for `j` columns). The next target
//! column count `k` minimises the work (decrease when `W_{k−1} < 0.8 W_k`, increase when
//! `W_k < 0.9 W_{k−1}`). The convergence monitor rejects a step early when the error of column
//! `k − 1` is too large to hope for convergence in column `k + 1`.
//!
//! # Error per unit step (deviation from ODEX)
//!
//! ODEX bounds the error of every step by the tolerance, so the final error of a run grows with its number of
//! steps (to 1e4 × rtol on the outer Solar System, `analysis/work_precision/REPORT.md`), and the higher the order
//! (the longer the steps), the closer the true local error comes to its estimate. When the run's span `T` is known
//! ([`Integrator::set_span`], which the run driver and the benchmarks call), a step of length `H` is
//! accepted when `err ≤ s H / T` instead of `err ≤ 1` (with `s =` [`RUN_BUDGET`], and `s H / T` floored at
//! `10 ε / rtol`, below which round-off decides): the local errors of the whole run then add up to about
//! `s · rtol`, and the final error follows `rtol` (`bench tolerance`). The optimal step uses the exponent
//! `1/(2j − 2)` of the error per unit step. At high order this costs few steps (`(T/H)^{1/(2j−2)}`, about
//! 1.3× for 100 steps of order 16).
//!
//! # Increments and compensated summation (deviation from ODEX)
//!
//! The midpoint rule and the tableau run on the increments `d_m = z_m − y` from the step's start, not on the
//! states: the right-hand side is called at `y + d_m`, and the step ends with `y += T_{k,k}` summed with Kahan's
//! compensation, which carries what that addition rounded away into the next step (and into the next
//! [`Integrator::advance`] when the caller hands the returned state back unchanged; it is saved with
//! [`Integrator::save_state`], so a resumed run is bit-identical). Written on the states, every substep and
//! every tableau entry rounds at `ε |y|`, and the run's error stops following `rtol` near `1e-11`
//! (`bench tolerance`; `analysis/work_precision/REPORT.md`).
//!
//! # Safeguards
//!
//! * **Stability check** (ODEX): in the first midpoint substep of columns 1 and 2 the change of
//!   the derivative is compared with the derivative itself; if
//!   `‖f(z_1) − f(z_0)‖² > 4 ‖f(z_0)‖²` (scaled norms) the step is rejected and **`H` halved**
//!   (ODEX's default `safe3 = 0.5`). Deviation from ODEX: the check is skipped when `f(t, y)` is
//!   exactly zero (e.g. `y' = t` at `t = 0`), where ODEX would halve `H` some 60 times. Note that the
//!   check compares scaled norms, so it also fires when `f` is nearly zero in the tolerance scale
//!   (a state starting at rest with tiny velocity tolerances may see a few halvings at the start).
//!   The same halving happens when the error estimate diverges with the column index (`j > 2` and
//!   `err_j ≥ max(4 err_{j−1}, 1)`, ODEX's `ERROLD`) or is astronomically large (`err · ε ≥ 1`).
//! * **Non-finite values**: a NaN/∞ error estimate also halves `H`; after
//!   [`BulirschStoer::set_max_nonfinite_retries`] (default 10) consecutive such rejections, or when
//!   the step underflows right after one, [`IntegrateError::NonFinite`] is returned. A non-finite
//!   derivative at an *accepted* point fails at once (no step size can cure it).
//! * The caller's `t, y` are only ever overwritten by accepted states.

pub use super::common::{BulirschStoerState, Rejections};
use super::common::{IntegrateError, Integrator, IntegratorState, Method, OdeSystem, Stats, Tolerances, begin_advance};
use super::compensated::Compensation;

/// Step-size factor bound parameter (ODEX `fac1`).
const FAC1: f64 = 0.02;
/// Step-size factor bound parameter (ODEX `fac2`).
const FAC2: f64 = 4.0;
/// Order decrease threshold on the work ratio (ODEX `fac3`).
const FAC3: f64 = 0.8;
/// Order increase threshold on the work ratio (ODEX `fac4`).
const FAC4: f64 = 0.9;
/// Safety factor on the error (ODEX `safe1`).
const SAFE1: f64 = 0.65;
/// Safety factor on the step (ODEX `safe2`).
const SAFE2: f64 = 0.94;
/// Step reduction after a failed stability check, a growing or non-finite error (ODEX `safe3`).
const SAFE3: f64 = 0.5;
/// Columns in which the stability check runs (ODEX `jstab`).
const STABILITY_COLUMNS: usize = 2;
/// Limit on `‖Δf‖² / ‖f‖²` in the stability check.
const STABILITY_RATIO: f64 = 4.0;
/// Share of the tolerance the local errors of a whole run may add up to under error-per-unit-step control
/// ([`Integrator::set_span`]). Measured on the outer Solar System: at the largest steps the order chooses,
/// `‖T_{j,j} − T_{j,j−1}‖` underestimates the true local error of `T_{j,j}` by 2–3× (a one-step tableau against
/// a Dop853 1e-15 reference), and Kepler shear turns an along-track error into a growing one. With a budget of
/// 1 the final error reached 240 × rtol, with 1/3 106 ×, with 1/4 at most 77 × over rtol 1e-6…1e-11
/// (`bench tolerance`).
pub const RUN_BUDGET: f64 = 0.25;
/// Default maximum number of columns (ODEX `km`).
pub const DEFAULT_MAX_COLUMNS: usize = 9;
/// Default maximum number of step attempts per call to [`Integrator::advance`].
pub const DEFAULT_MAX_STEPS: u64 = 100_000_000;
/// Default number of consecutive non-finite rejections before giving up.
pub const DEFAULT_MAX_NONFINITE_RETRIES: u32 = 10;

/// Adaptive Gragg–Bulirsch–Stoer extrapolation integrator (ODEX strategy), see the
/// [module documentation](self).
///
/// The step size and column count are carried from one [`Integrator::advance`] call to the next,
/// so a sequence of output times does not restart the step control; when a step is shortened to
/// land exactly on an output time, the un-shortened proposal is kept for the next call. Call
/// [`BulirschStoer::reset`] after a discontinuity of the state or of the equations.
///
/// Statistics ([`Integrator::stats`]) count every RHS call (including the initial-step guess and
/// the derivative at the start of each `advance`); `smallest_step` leaves out steps shortened
/// only to land on an output time. [`BulirschStoer::rejections`] splits the rejected steps by cause.
///
/// All work arrays are allocated once (at the first call and whenever the dimension changes);
/// a step allocates nothing.
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
#[derive(Debug, Clone)]
pub struct BulirschStoer {
    tol: Tolerances,
    initial_step: Option<f64>,
    km: usize,
    max_steps: u64,
    /// Wall-clock instant after which an advance stops ([`IntegrateError::Deadline`]); not part of the saved state.
    deadline: Option<std::time::Instant>,
    h_min: f64,
    h_max: f64,
    max_nonfinite_retries: u32,
    /// Span of the whole run (s) for error-per-unit-step control ([`Integrator::set_span`]); `None` = error per
    /// step (ODEX).
    span: Option<f64>,

    // Step control carried between steps and calls.
    /// Proposed |H| for the next step; 0 = unknown (initial guess needed).
    h: f64,
    /// Target column count `k` (ODEX `K`), `2 ..= km − 1`.
    k: usize,
    /// The previous attempt was rejected.
    reject: bool,
    /// At least one step has been attempted (ODEX `nstep > 0`).
    started: bool,

    // Step-number sequence and per-column data, 1-based (index 0 unused).
    nj: Vec<f64>,
    a: Vec<f64>,
    hh: Vec<f64>,
    w: Vec<f64>,

    // Work arrays, length `n` (tab: km rows of n).
    n: usize,
    dz: Vec<f64>,
    yh1: Vec<f64>,
    yh2: Vec<f64>,
    /// The trial state `y + yh2` handed to the right-hand side.
    ytrial: Vec<f64>,
    /// Compensated summation of the accepted increments ([`Compensation`]): carried into the next call only if
    /// the caller passes back the state the last `advance` returned.
    comp: Compensation,
    dy: Vec<f64>,
    scal: Vec<f64>,
    tab: Vec<f64>,

    stats: Stats,
    rejections: Rejections,
}

/// Why a step has to be retried with a halved step.
#[derive(Clone, Copy)]
enum Shrink {
    Stability,
    Divergence,
    NonFinite,
}

/// Result of one column of the extrapolation tableau.
enum Column {
    /// Column computed; the error estimate (0 for the first column).
    Done(f64),
    /// Step must be retried with a halved step.
    Shrink(Shrink),
}

/// Result of one step attempt.
enum Attempt {
    Accepted,
    Rejected,
    Shrink(Shrink),
}

fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

impl BulirschStoer {
    /// A new integrator with per-component `tolerances` and an optional initial step `step`
    /// (|step| is used for the very first step only, and again after [`BulirschStoer::reset`];
    /// `None` = automatic guess from `f(t0, y0)` and one more evaluation, Hairer's `hinit`).
    ///
    /// Errors with [`IntegrateError::Config`] if the `rtol`/`atol` vectors differ in length or
    /// contain negative or non-finite values, if some component has `rtol = atol = 0`, or if
    /// `step` is not positive and finite. The vectors' length must equal the dimension of the
    /// systems later passed to [`Integrator::advance`].
    pub fn new(tolerances: Tolerances, step: Option<f64>) -> Result<Self, IntegrateError> {
        validate_tolerances(&tolerances)?;
        if let Some(h) = step
            && !(h.is_finite() && h != 0.0)
        {
            return Err(IntegrateError::Config(format!(
                "bulirsch-stoer initial step must be non-zero and finite, got {h}"
            )));
        }
        let mut bs = BulirschStoer {
            tol: tolerances,
            initial_step: step.map(f64::abs),
            km: DEFAULT_MAX_COLUMNS,
            max_steps: DEFAULT_MAX_STEPS,
            deadline: None,
            h_min: 0.0,
            h_max: f64::INFINITY,
            max_nonfinite_retries: DEFAULT_MAX_NONFINITE_RETRIES,
            span: None,
            h: 0.0,
            k: 2,
            reject: false,
            started: false,
            nj: Vec::new(),
            a: Vec::new(),
            hh: Vec::new(),
            w: Vec::new(),
            n: 0,
            dz: Vec::new(),
            yh1: Vec::new(),
            yh2: Vec::new(),
            ytrial: Vec::new(),
            comp: Compensation::default(),
            dy: Vec::new(),
            scal: Vec::new(),
            tab: Vec::new(),
            stats: Stats {
                smallest_step: f64::INFINITY,
                ..Stats::default()
            },
            rejections: Rejections::default(),
        };
        bs.setup_sequence();
        bs.k = bs.initial_columns();
        Ok(bs)
    }

    /// Sets the maximum number of extrapolation columns `km` (ODEX default 9; `3 ≤ km ≤ 20`).
    /// The highest order reached is `2 km`.
    pub fn set_max_columns(&mut self, km: usize) -> Result<(), IntegrateError> {
        if !(3..=20).contains(&km) {
            return Err(IntegrateError::Config(format!(
                "bulirsch-stoer max columns must be in 3..=20, got {km}"
            )));
        }
        self.km = km;
        self.setup_sequence();
        self.k = self.k.clamp(2, km - 1);
        if self.n > 0 {
            self.tab = vec![0.0; km * self.n];
        }
        Ok(())
    }

    /// Sets the maximum number of step attempts (accepted + rejected) in one call to
    /// [`Integrator::advance`] (default 10⁸); more gives [`IntegrateError::TooManySteps`].
    pub fn set_max_steps(&mut self, max_steps: u64) {
        self.max_steps = max_steps;
    }

    /// Sets the smallest allowed step size (default 0): a proposed `|h| < max(h_min, 10 ε |t|)`
    /// gives [`IntegrateError::StepUnderflow`].
    pub fn set_h_min(&mut self, h_min: f64) {
        self.h_min = h_min.abs();
    }

    /// Sets the largest allowed step size (default ∞).
    pub fn set_h_max(&mut self, h_max: f64) {
        self.h_max = h_max.abs();
        if self.h > self.h_max {
            self.h = self.h_max;
        }
    }

    /// Sets how many consecutive rejections caused by NaN/∞ trial values are retried (each with a
    /// halved step) before [`IntegrateError::NonFinite`] is returned (default 10).
    pub fn set_max_nonfinite_retries(&mut self, retries: u32) {
        self.max_nonfinite_retries = retries;
    }

    /// Forgets the step-size and order history: the next step starts like the first one (initial
    /// step guess, initial column count). Use after a discontinuity in the state or equations.
    pub fn reset(&mut self) {
        self.comp = Compensation::default();
        self.h = 0.0;
        self.k = self.initial_columns();
        self.reject = false;
        self.started = false;
    }

    /// The step size the next step will try (`None` before the first step or after [`reset`]).
    ///
    /// [`reset`]: BulirschStoer::reset
    pub fn proposed_step(&self) -> Option<f64> {
        (self.h > 0.0).then_some(self.h)
    }

    /// The current target number of extrapolation columns `k` (order `2k`).
    pub fn columns(&self) -> usize {
        self.k
    }

    /// Rejected steps by cause (cumulative).
    pub fn rejections(&self) -> Rejections {
        self.rejections
    }

    /// The tolerances in use.
    pub fn tolerances(&self) -> &Tolerances {
        &self.tol
    }

    /// Step-number sequence `n_j = 2j` and cumulative work `A_j = 1 + n_1 + … + n_j`.
    fn setup_sequence(&mut self) {
        let km = self.km;
        self.nj = (0..=km).map(|j| 2.0 * j as f64).collect();
        self.a = vec![0.0; km + 1];
        self.a[1] = self.nj[1] + 1.0;
        for j in 2..=km {
            self.a[j] = self.a[j - 1] + self.nj[j];
        }
        self.hh = vec![0.0; km + 1];
        self.w = vec![0.0; km + 1];
    }

    /// ODEX's initial column count from the tightest relative tolerance.
    fn initial_columns(&self) -> usize {
        let rtol = self.tol.rtol.iter().copied().fold(f64::INFINITY, f64::min);
        let guess = (-(rtol + f64::EPSILON).log10() * 0.6 + 1.5).floor();
        let guess = if guess.is_finite() { guess.max(0.0) as usize } else { 2 };
        guess.min(self.km - 1).max(2)
    }

    fn ensure_workspace(&mut self, n: usize) {
        if self.n == n && self.dz.len() == n {
            return;
        }
        self.n = n;
        self.dz = vec![0.0; n];
        self.yh1 = vec![0.0; n];
        self.yh2 = vec![0.0; n];
        self.ytrial = vec![0.0; n];
        self.dy = vec![0.0; n];
        self.scal = vec![0.0; n];
        self.tab = vec![0.0; self.km * n];
    }

    /// `scal_i = atol_i + rtol_i |y_i|` (floored at the smallest positive normal number).
    fn fill_scal(&mut self, y: &[f64]) {
        for (((sc, &yi), &a), &r) in self.scal.iter_mut().zip(y).zip(&self.tol.atol).zip(&self.tol.rtol) {
            *sc = (a + r * yi.abs()).max(f64::MIN_POSITIVE);
        }
    }

    /// `dy = f(t, ytrial)`, the derivative at the trial state `y + d_m` of the midpoint rule.
    fn eval_trial(&mut self, system: &dyn OdeSystem, t: f64) {
        let z = std::mem::take(&mut self.ytrial);
        self.eval(system, t, &z, Out::Dy);
        self.ytrial = z;
    }

    fn eval(&mut self, system: &dyn OdeSystem, t: f64, y: &[f64], out: Out) {
        self.stats.rhs_evaluations += 1;
        let dst = match out {
            Out::Dz => &mut self.dz,
            Out::Dy => &mut self.dy,
        };
        system.rhs(t, y, dst);
    }

    /// Initial step guess in the style of Hairer's `hinit` (uses `f(t, y)` already in `dz` and one
    /// more evaluation). Returns |h|.
    fn initial_step_guess(&mut self, system: &dyn OdeSystem, t: f64, y: &[f64], dir: f64, span: f64) -> f64 {
        let n = self.n as f64;
        self.fill_scal(y);
        let (mut d0, mut d1) = (0.0, 0.0);
        for ((&yi, &fi), &sc) in y.iter().zip(&self.dz).zip(&self.scal) {
            d0 += (yi / sc).powi(2);
            d1 += (fi / sc).powi(2);
        }
        let (d0, d1) = ((d0 / n).sqrt(), (d1 / n).sqrt());
        let mut h0 = if d0 < 1e-5 || d1 < 1e-5 { 1e-6 } else { 0.01 * d0 / d1 };
        h0 = h0.min(span).min(self.h_max);
        if h0.is_nan() || h0 <= 0.0 {
            return 1e-6f64.min(self.h_max);
        }
        // Explicit Euler trial step into yh1, derivative into dy.
        for ((z, &yi), &fi) in self.yh1.iter_mut().zip(y).zip(&self.dz) {
            *z = yi + dir * h0 * fi;
        }
        let yh1 = std::mem::take(&mut self.yh1);
        self.eval(system, t + dir * h0, &yh1, Out::Dy);
        self.yh1 = yh1;
        let mut d2 = 0.0;
        for ((&f1, &f0), &sc) in self.dy.iter().zip(&self.dz).zip(&self.scal) {
            d2 += ((f1 - f0) / sc).powi(2);
        }
        let d2 = (d2 / n).sqrt() / h0;
        if !d2.is_finite() {
            return h0;
        }
        let order = 2.0 * self.k as f64;
        let h1 = if d1.max(d2) <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / d1.max(d2)).powf(1.0 / (order + 1.0))
        };
        (100.0 * h0).min(h1).min(span).min(self.h_max)
    }

    /// Computes column `j` (1-based) of the tableau for the step `(t, y) → t + h`, extrapolates,
    /// and for `j ≥ 2` estimates the error and the optimal step `hh[j]` and work `w[j]`.
    /// `err_prev` holds the (floored) error of the previous column.
    fn column(&mut self, system: &dyn OdeSystem, t: f64, y: &[f64], h: f64, j: usize, err_prev: &mut f64) -> Column {
        let n = self.n;
        let nsub = self.nj[j] as usize;
        let hj = h / self.nj[j];
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
                for i in 0..n {
                    let sc = self.scal[i];
                    del1 += (self.dz[i] / sc).powi(2);
                    del2 += ((self.dy[i] - self.dz[i]) / sc).powi(2);
                }
                // ODEX floors ‖f‖² at ε; we skip the check when f(t, y) vanishes exactly
                // (nothing to compare with), otherwise it would halve H down to ~1e-20.
                if del1 > 0.0 && del2 > STABILITY_RATIO * del1.max(f64::EPSILON) {
                    return Column::Shrink(Shrink::Stability);
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
        {
            let row = &mut self.tab[(j - 1) * n..j * n];
            for (((r, &a), &b), &d) in row
                .iter_mut()
                .zip(self.yh1.iter())
                .zip(self.yh2.iter())
                .zip(self.dy.iter())
            {
                *r = 0.5 * (a + b + hj * d);
            }
        }
        if j == 1 {
            return Column::Done(0.0);
        }
        // Aitken–Neville: row r (0-based) becomes T_{j, j−r}.
        for l in (2..=j).rev() {
            let ratio = self.nj[j] / self.nj[l - 1];
            let inv = 1.0 / (ratio * ratio - 1.0);
            let (lo, hi) = self.tab.split_at_mut((l - 1) * n);
            let dst = &mut lo[(l - 2) * n..];
            let src = &hi[..n];
            for (d, &s) in dst.iter_mut().zip(src.iter()) {
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
        let mut err = (sum / n as f64).sqrt();
        if let Some(span) = self.span {
            // Error per unit step: this step may spend the share RUN_BUDGET·|h|/span of the tolerance. Below
            // 10 ε / rtol the share would ask for less than round-off can deliver.
            let rtol = self.tol.rtol.iter().copied().fold(f64::INFINITY, f64::min);
            let floor = (10.0 * f64::EPSILON / rtol).min(1.0);
            err /= (RUN_BUDGET * h.abs() / span).clamp(floor, 1.0);
        }
        if err.is_nan() || (err.is_infinite() && !all_finite(&self.tab[..n])) {
            return Column::Shrink(Shrink::NonFinite);
        }
        if err * f64::EPSILON >= 1.0 || (j > 2 && err >= *err_prev) {
            return Column::Shrink(Shrink::Divergence);
        }
        // ODEX: ERROLD = MAX(4*ERR, 1). A column only counts as diverging when its error is both above 1
        // (not converged) and more than four times the previous one; a smaller floor would reject steps
        // whose columns have converged to round-off noise (err ≪ 1 but not monotone), halving H forever.
        *err_prev = (4.0 * err).max(1.0);
        // The error of T_{j,j−1} is O(H^{2j−1}); per unit step it is O(H^{2j−2}).
        let expo = if self.span.is_some() {
            1.0 / (2 * j - 2) as f64
        } else {
            1.0 / (2 * j - 1) as f64
        };
        let facmin = FAC1.powf(expo);
        let fac = (FAC2 / facmin).min(facmin.max((err / SAFE1).powf(expo) / SAFE2));
        self.hh[j] = (h.abs() / fac).min(self.h_max);
        self.w[j] = self.a[j] / self.hh[j];
        Column::Done(err)
    }

    /// One step attempt from `(t, y)` with signed step `h`; `special` selects ODEX's handling of
    /// the first and the last step. On acceptance the increment `T_{k,k}` is in `tab[0..n]` and `self.h`,
    /// `self.k` hold the proposal for the next step.
    fn attempt(&mut self, system: &dyn OdeSystem, t: f64, y: &[f64], h: f64, special: bool) -> Attempt {
        self.fill_scal(y);
        let k = self.k;
        let mut err_prev = f64::INFINITY;
        let mut err = 0.0;
        macro_rules! column {
            ($j:expr) => {
                match self.column(system, t, y, h, $j, &mut err_prev) {
                    Column::Done(e) => err = e,
                    Column::Shrink(why) => return Attempt::Shrink(why),
                }
            };
        }
        if special {
            // First or last step: increase the column count until convergence.
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
            // Convergence monitor.
            if !(k == 2 || self.reject) {
                if err <= 1.0 {
                    return self.accept(k - 1, h.abs());
                }
                let lim = self.nj[k + 1] * self.nj[k] / 4.0;
                if err > lim * lim {
                    return self.reject_step(k - 1);
                }
            }
            column!(k);
            if err <= 1.0 {
                return self.accept(k, h.abs());
            }
        }
        // Hope for convergence in column k + 1.
        let lim = self.nj[k + 1] / 2.0;
        if err > lim * lim {
            return self.reject_step(k);
        }
        column!(k + 1);
        if err > 1.0 {
            self.reject_step(k + 1)
        } else {
            self.accept(k + 1, h.abs())
        }
    }

    /// Step accepted after `kc` columns: choose the next column count and step (ODEX).
    fn accept(&mut self, kc: usize, h_abs: f64) -> Attempt {
        let km = self.km;
        let k = self.k;
        let w = &self.w;
        let kopt = if kc == 2 {
            if self.reject { 2 } else { 3.min(km - 1) }
        } else if kc <= k {
            let mut kopt = kc;
            if w[kc - 1] < w[kc] * FAC3 {
                kopt = kc - 1;
            }
            if w[kc] < w[kc - 1] * FAC4 {
                kopt = (kc + 1).min(km - 1);
            }
            kopt
        } else {
            let mut kopt = kc - 1;
            if kc > 3 && w[kc - 2] < w[kc - 1] * FAC3 {
                kopt = kc - 2;
            }
            if w[kc] < w[kopt] * FAC4 {
                kopt = kc.min(km - 1);
            }
            kopt
        };
        if self.reject {
            self.k = kopt.min(kc);
            self.h = h_abs.min(self.hh[self.k]);
            self.reject = false;
        } else {
            let h_new = if kopt <= kc {
                self.hh[kopt]
            } else if kc < k && w[kc] < w[kc - 1] * FAC4 {
                self.hh[kc] * self.a[kopt + 1] / self.a[kc]
            } else {
                self.hh[kc] * self.a[kopt] / self.a[kc]
            };
            self.k = kopt;
            self.h = h_new.min(self.h_max);
        }
        Attempt::Accepted
    }

    /// Step rejected by the error test after `kc` columns: reduce `k` and the step (ODEX).
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
}

#[derive(Clone, Copy)]
enum Out {
    Dz,
    Dy,
}

pub(super) fn validate_tolerances(tol: &Tolerances) -> Result<(), IntegrateError> {
    if tol.rtol.len() != tol.atol.len() {
        return Err(IntegrateError::Config(format!(
            "rtol has {} components but atol has {}",
            tol.rtol.len(),
            tol.atol.len()
        )));
    }
    for (i, (&r, &a)) in tol.rtol.iter().zip(tol.atol.iter()).enumerate() {
        if !(r.is_finite() && a.is_finite() && r >= 0.0 && a >= 0.0 && (r > 0.0 || a > 0.0)) {
            return Err(IntegrateError::Config(format!(
                "tolerances of component {i} must be finite, non-negative and not both zero \
                 (rtol = {r}, atol = {a})"
            )));
        }
    }
    Ok(())
}

impl BulirschStoer {
    /// The stepping loop of [`Integrator::advance`], after its checks: `y`'s dimension is the workspace's and
    /// the compensation is set up.
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
        self.eval(system, *t, y, Out::Dz);
        if !all_finite(&self.dz) {
            return Err(IntegrateError::NonFinite { t: *t });
        }
        if self.h == 0.0 {
            let span = (t_target - *t).abs();
            self.h = match self.initial_step {
                Some(h) => h.min(self.h_max),
                None => self.initial_step_guess(system, *t, y, dir, span),
            };
        }

        let mut attempts: u64 = 0;
        let mut nonfinite_run: u32 = 0;
        let mut clean = true; // no rejection since the last accepted step
        loop {
            let remaining = (t_target - *t).abs();
            let last = self.h * 1.01 >= remaining;
            if !last {
                let floor = self.h_min.max(10.0 * f64::EPSILON * t.abs());
                if self.h.is_nan() || self.h < floor || self.h == 0.0 {
                    return Err(if nonfinite_run > 0 {
                        IntegrateError::NonFinite { t: *t }
                    } else {
                        IntegrateError::StepUnderflow { t: *t, h: dir * self.h }
                    });
                }
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
            match self.attempt(system, *t, y, dir * h_abs, special) {
                Attempt::Accepted => {
                    if !all_finite(&self.tab[..n]) {
                        // Cannot happen with rtol > 0 (a non-finite value makes err NaN), but
                        // never hand a non-finite state to the caller.
                        self.stats.steps_rejected += 1;
                        self.rejections.nonfinite += 1;
                        self.h = h_abs * SAFE3;
                        self.reject = true;
                        nonfinite_run += 1;
                        clean = false;
                        if nonfinite_run > self.max_nonfinite_retries {
                            return Err(IntegrateError::NonFinite { t: *t });
                        }
                        continue;
                    }
                    self.comp.add(y, &self.tab[..self.n]);
                    self.stats.steps_accepted += 1;
                    if !(last && h_abs < saved_h) {
                        // Steps shortened only to land on an output time say nothing about stiffness.
                        self.stats.smallest_step = self.stats.smallest_step.min(h_abs);
                    }
                    nonfinite_run = 0;
                    if last {
                        *t = t_target;
                        if clean && h_abs < saved_h {
                            // Shortened to land on t_target: keep the un-shortened proposal.
                            self.h = self.h.max(saved_h);
                            self.k = saved_k;
                        }
                        return Ok(());
                    }
                    *t += dir * h_abs;
                    clean = true;
                    system.begin_step(*t, y);
                    self.eval(system, *t, y, Out::Dz);
                    if !all_finite(&self.dz) {
                        return Err(IntegrateError::NonFinite { t: *t });
                    }
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
                        if nonfinite_run > self.max_nonfinite_retries {
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

impl Integrator for BulirschStoer {
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
        Method::BulirschStoer
    }

    fn save_state(&self) -> IntegratorState {
        IntegratorState::BulirschStoer(BulirschStoerState {
            dim: self.tol.rtol.len(),
            km: self.km,
            max_steps: self.max_steps,
            h_min: self.h_min,
            h_max: self.h_max,
            max_nonfinite_retries: self.max_nonfinite_retries,
            initial_step: self.initial_step,
            span: self.span,
            h: self.h,
            k: self.k,
            reject: self.reject,
            started: self.started,
            hh: self.hh.clone(),
            w: self.w.clone(),
            stats: self.stats.into(),
            rejections: self.rejections,
            compensation: self.comp.carry.clone(),
        })
    }

    fn restore_state(&mut self, state: &IntegratorState) -> Result<(), IntegrateError> {
        let s = match state {
            IntegratorState::BulirschStoer(s) => s,
            other => {
                return Err(IntegrateError::Config(format!(
                    "cannot restore a {} state into bulirsch-stoer",
                    other.method()
                )));
            }
        };
        let bad = |what: String| Err(IntegrateError::Config(format!("bulirsch-stoer state: {what}")));
        if s.dim != self.tol.rtol.len() {
            return bad(format!(
                "saved for dimension {}, tolerances have {}",
                s.dim,
                self.tol.rtol.len()
            ));
        }
        if !(3..=20).contains(&s.km) {
            return bad(format!("max columns {} not in 3..=20", s.km));
        }
        if !(2..s.km).contains(&s.k) {
            return bad(format!("column count {} not in 2..{}", s.k, s.km));
        }
        if s.hh.len() != s.km + 1 || s.w.len() != s.km + 1 {
            return bad(format!("per-column arrays must have {} entries", s.km + 1));
        }
        if !(s.h.is_finite() && s.h >= 0.0) || s.h_min.is_nan() || s.h_max.is_nan() {
            return bad(format!(
                "bad step sizes (h = {}, h_min = {}, h_max = {})",
                s.h, s.h_min, s.h_max
            ));
        }
        if s.initial_step.is_some_and(|h| !(h.is_finite() && h > 0.0)) {
            return bad("bad initial step".into());
        }
        if s.km != self.km {
            self.set_max_columns(s.km)?;
        }
        self.max_steps = s.max_steps;
        self.h_min = s.h_min;
        self.h_max = s.h_max;
        self.max_nonfinite_retries = s.max_nonfinite_retries;
        self.initial_step = s.initial_step;
        if s.span.is_some_and(|t| !(t.is_finite() && t > 0.0)) {
            return bad("bad span".into());
        }
        self.span = s.span;
        self.h = s.h;
        self.k = s.k;
        self.reject = s.reject;
        self.started = s.started;
        self.hh.copy_from_slice(&s.hh);
        self.w.copy_from_slice(&s.w);
        if !(s.compensation.is_empty() || s.compensation.len() == s.dim) || !all_finite(&s.compensation) {
            return bad(format!(
                "compensation must be empty or have {} finite entries, got {}",
                s.dim,
                s.compensation.len()
            ));
        }
        self.stats = s.stats.into();
        self.rejections = s.rejections;
        self.comp.carry.clone_from(&s.compensation);
        // The saved state is the caller's: the compensation belongs to whatever state it passes next.
        self.comp.forget_output();
        Ok(())
    }
}
