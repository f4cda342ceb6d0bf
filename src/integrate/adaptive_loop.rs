//! The one adaptive step loop of our own integrators (`bulirsch_stoer`, `dop853`, `linearly_implicit`): a method
//! says how to attempt one step of size `h` from `(t, y)` — whether the step is accepted and which step to try next
//! ([`StepMethod`], in the spirit of russell_ode's `OdeSolverTrait` with its `step`, `accept` and `reject`) — and
//! [`Adaptive`] does the rest: it lands exactly on each output time, halves a step after non-finite values and
//! gives up after a run of them, sums accepted increments with compensation, keeps the step budget, the wall-clock
//! deadline and the statistics, and saves and restores the part of a checkpoint state all methods share.
//!
//! Source: E. Hairer, S. P. Nørsett & G. Wanner, *Solving Ordinary Differential Equations I* (2nd ed., Springer
//! 1993), §II.4 (step-size control, the initial step `hinit`) and the drivers of their codes ODEX and DOP853 (the
//! last step stretched by up to 1 % to land on the output time, its un-shortened proposal kept, `h` halved after
//! a failed stability check or non-finite values); W. Kahan, *Comm. ACM* 8 (1965) 40 (compensated summation,
//! [`Compensation`]). The `ode_solvers` adapter shares the [`Budget`] and the checks of a call.

use std::time::Instant;

use super::common::{
    Advanced, IntegrateError, Integrator, IntegratorState, Method, OdeSystem, Rejections, SavedStats, Stats,
    StepLimits, Tolerances, begin_advance,
};
use super::compensated::Compensation;

/// Step reduction after a failed stability check, a diverging or a non-finite error estimate (ODEX's `safe3`, and
/// DOP853's reduction after non-finite stages).
pub const HALVE: f64 = 0.5;
/// Default maximum number of step attempts per call to [`Integrator::advance`].
pub const DEFAULT_MAX_STEPS: u64 = 100_000_000;
/// Default number of consecutive non-finite rejections before giving up.
pub const DEFAULT_MAX_NONFINITE_RETRIES: u32 = 10;

/// Whether every value of `v` is finite.
pub fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Errors with [`IntegrateError::Config`] if the `rtol`/`atol` vectors differ in length or contain negative or
/// non-finite values, or if some component has `rtol = atol = 0`.
pub fn validate_tolerances(tol: &Tolerances) -> Result<(), IntegrateError> {
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

/// The first half of Hairer's initial step `hinit` (§II.4): `h0 = 0.01 ‖y‖ / ‖f(t, y)‖` from the two scaled RMS
/// norms `d0 = ‖y‖`, `d1 = ‖f‖` (`1e-6` when either is below `1e-5`).
pub fn hinit_h0(d0: f64, d1: f64) -> f64 {
    if d0 < 1e-5 || d1 < 1e-5 { 1e-6 } else { 0.01 * d0 / d1 }
}

/// The second half of `hinit`: from `h0`, `d1 = ‖f(t, y)‖` and `d2 = ‖f(t + h0, y + h0 f) − f(t, y)‖ / h0`, the step
/// `h1 = (0.01 / max(d1, d2))^expo` (`expo` = 1/(order + 1)), at most `100 h0`, the span and `h_max`; `h0` when `d2`
/// is not finite.
pub fn hinit_h1(h0: f64, d1: f64, d2: f64, expo: f64, span: f64, h_max: f64) -> f64 {
    if !d2.is_finite() {
        return h0;
    }
    let der = d1.max(d2);
    let h1 = if der <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / der).powf(expo)
    };
    (100.0 * h0).min(h1).min(span).min(h_max)
}

/// A call's step budget and wall-clock deadline (what a run's budgets set).
#[derive(Debug, Clone, Copy)]
pub struct Budget {
    /// Most step attempts in one call to [`Integrator::advance`].
    pub max_steps: u64,
    /// Wall-clock instant after which a call stops; not part of a saved state.
    pub deadline: Option<Instant>,
}

impl Budget {
    /// [`DEFAULT_MAX_STEPS`] attempts per call, no deadline.
    pub const DEFAULT: Budget = Budget {
        max_steps: DEFAULT_MAX_STEPS,
        deadline: None,
    };

    /// Before an attempt, with `attempts` made in this call and `t` the last accepted time: the deadline's error
    /// once it has passed, else the step budget's once spent.
    pub fn check(&self, t: f64, attempts: u64) -> Result<(), IntegrateError> {
        if self.deadline.is_some_and(|d| Instant::now() >= d) {
            return Err(IntegrateError::Deadline { t });
        }
        if attempts >= self.max_steps {
            return Err(IntegrateError::TooManySteps {
                t,
                max_steps: self.max_steps,
            });
        }
        Ok(())
    }
}

/// The error of restoring `state` into an integrator of method `into`.
pub fn wrong_state(state: &IntegratorState, into: Method) -> IntegrateError {
    IntegrateError::Config(format!("cannot restore a {} state into {into}", state.method()))
}

/// The error of restoring an inconsistent state of `method`.
pub fn bad_state(method: Method, what: String) -> IntegrateError {
    IntegrateError::Config(format!("{method} state: {what}"))
}

/// One step attempt, as the loop asks a method for it.
#[derive(Debug, Clone, Copy)]
pub struct Trial {
    /// Start time (s).
    pub t: f64,
    /// Signed step (s).
    pub h: f64,
    /// End time (s): `t + h`, or exactly the output time on the landing step.
    pub t_end: f64,
    /// The step lands on the output time (shortened or stretched to do so).
    pub last: bool,
    /// A step has been rejected since the last accepted one in this call.
    pub after_rejection: bool,
    /// The largest step allowed (s).
    pub h_max: f64,
}

/// A call's first step, for a method's initial step guess.
#[derive(Debug, Clone, Copy)]
pub struct FirstStep {
    /// The call's start time (s).
    pub t: f64,
    /// The direction of time, ±1.
    pub dir: f64,
    /// `|t_target − t|` (s).
    pub span: f64,
    /// The largest step allowed (s).
    pub h_max: f64,
}

/// Why a step is retried with half its size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cause {
    /// A stability check failed.
    Stability,
    /// The error estimate diverged or was huge.
    Divergence,
    /// A trial value or derivative was NaN or infinite.
    NonFinite,
}

/// What a method says of one attempt.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Outcome {
    /// Accepted: [`StepMethod::commit`] moves the state to the step's end; `h_next` (s) is the next step.
    Accepted {
        /// The next step's size (s).
        h_next: f64,
    },
    /// Rejected by the error test: retry with `h_next` (s).
    Rejected {
        /// The retried step's size (s).
        h_next: f64,
    },
    /// Rejected for `Cause`: retry with half the step.
    Halve(Cause),
}

/// The loop's part of a checkpoint state, which each method lays out in its own [`IntegratorState`].
#[derive(Debug, Clone, PartialEq)]
pub struct Carried {
    /// Length of the tolerance vectors (the system's dimension).
    pub dim: usize,
    /// Step budget and step-size limits.
    pub limits: StepLimits,
    /// The configured initial step (s), if any.
    pub initial_step: Option<f64>,
    /// Proposed `|h|` for the next step (s); 0 = not yet known.
    pub h: f64,
    /// Cumulative statistics.
    pub stats: SavedStats,
    /// Cumulative rejections by cause.
    pub rejections: Rejections,
    /// What compensated summation carries into the next step (`dim` entries, or empty = zero).
    pub compensation: Vec<f64>,
}

impl Carried {
    /// Checks the loop's part of a state of `method` for an integrator of dimension `dim`.
    pub fn check(&self, method: Method, dim: usize) -> Result<(), IntegrateError> {
        let bad = |what: String| Err(bad_state(method, what));
        if self.dim != dim {
            return bad(format!("saved for dimension {}, tolerances have {dim}", self.dim));
        }
        let StepLimits { h_min, h_max, .. } = self.limits;
        if !(self.h.is_finite() && self.h >= 0.0) || h_min.is_nan() || h_max.is_nan() {
            return bad(format!(
                "bad step sizes (h = {}, h_min = {h_min}, h_max = {h_max})",
                self.h
            ));
        }
        if self.initial_step.is_some_and(|h| !(h.is_finite() && h > 0.0)) {
            return bad("bad initial step".into());
        }
        if !(self.compensation.is_empty() || self.compensation.len() == dim) || !all_finite(&self.compensation) {
            return bad(format!(
                "compensation must be empty or have {dim} finite entries, got {}",
                self.compensation.len()
            ));
        }
        Ok(())
    }
}

/// One adaptive method as [`Adaptive`] drives it: how to attempt a step, and what to do with an accepted one.
pub trait StepMethod {
    /// What the method takes from the system at the start of each step and keeps for all its attempts (the
    /// linearly implicit method's stiff part; `()` for the others).
    type Frozen<'s>;
    /// The method's name.
    const METHOD: Method;
    /// The tolerances in use; their length is the dimension of the systems it integrates.
    fn tolerances(&self) -> &Tolerances;
    /// Sizes the work arrays for a system of dimension `n` (allocating only when it changes).
    fn prepare(&mut self, n: usize);
    /// Before a call's first step, with the caller's state: by default the compensation starts (keeping what it
    /// carries when the caller passes back the state the last call returned).
    fn enter(&mut self, y: &[f64], comp: &mut Compensation) {
        comp.begin(y);
    }
    /// At the start of every step from `(t, y)` (a call's start and each accepted state): calls
    /// [`OdeSystem::begin_step`], evaluates the derivative, and returns what the method keeps for the step, or
    /// `None` when the derivative is not finite.
    fn start<'s>(&mut self, system: &'s dyn OdeSystem, t: f64, y: &[f64]) -> Option<Self::Frozen<'s>>;
    /// The first step's `|h|` from the state `y` when none is carried or configured, with the derivative
    /// [`StepMethod::start`] took.
    fn initial_step(&mut self, system: &dyn OdeSystem, y: &[f64], first: &FirstStep) -> f64;
    /// One attempt of `trial` from the state `y`.
    fn attempt(&mut self, system: &dyn OdeSystem, frozen: &mut Self::Frozen<'_>, y: &[f64], trial: &Trial) -> Outcome;
    /// Moves the state to the end of the step just accepted.
    fn commit(&mut self, y: &mut [f64], comp: &mut Compensation);
    /// When a call returns, whatever its result, with the caller's state: by default the compensation remembers
    /// the state returned.
    fn leave(&mut self, y: &mut [f64], comp: &mut Compensation) {
        comp.end(y);
    }
    /// The order control kept across a step shortened only to land on an output time (the extrapolation methods'
    /// column count); 0 for a method of fixed order.
    fn order(&self) -> usize {
        0
    }
    /// Restores what [`StepMethod::order`] returned.
    fn set_order(&mut self, _order: usize) {}
    /// Right-hand side evaluations so far.
    fn evaluations(&self) -> u64;
    /// Sets the evaluation count (a restored state's).
    fn set_evaluations(&mut self, n: u64);
    /// The run's span for error-per-unit-step control ([`Integrator::set_span`]); by default ignored.
    fn set_span(&mut self, _span: Option<f64>) {}
    /// Forgets the order history (after a discontinuity of the state or of the equations).
    fn reset(&mut self) {}
    /// The method's checkpoint state, holding the loop's part `carried`.
    fn save(&self, carried: Carried) -> IntegratorState;
    /// Reads `state`: sets the loop's part into `carried` and checks it ([`Carried::check`]), checks the method's
    /// part, and only then restores the method's part. Errors with [`IntegrateError::Config`] for another method's
    /// state or an inconsistent one, leaving `self` as it was.
    fn restore(&mut self, state: &IntegratorState, carried: &mut Carried) -> Result<(), IntegrateError>;
}

/// An adaptive integrator: the step loop around the method `M` (see the [module documentation](self)).
///
/// The step size is carried from one [`Integrator::advance`] call to the next, so a sequence of output times does
/// not restart the step control; when a step is shortened to land exactly on an output time, the un-shortened
/// proposal (and the method's order) is kept for the next call. Statistics ([`Integrator::stats`]) count every RHS
/// call; `smallest_step` leaves out steps shortened only to land on an output time.
#[derive(Debug, Clone)]
pub struct Adaptive<M> {
    pub(super) method: M,
    initial_step: Option<f64>,
    budget: Budget,
    h_min: f64,
    h_max: f64,
    max_nonfinite_retries: u32,
    /// Proposed `|h|` for the next step; 0 = unknown (initial guess needed).
    h: f64,
    /// Accepted and rejected steps and the smallest step; the evaluations are the method's count.
    stats: Stats,
    rejections: Rejections,
    /// Compensated summation of the accepted increments: carried into the next call only if the caller passes back
    /// the state the last call returned.
    comp: Compensation,
}

impl<M: StepMethod> Adaptive<M> {
    /// The loop around `method`, with an optional initial step `step` (|step| is used for the very first step only,
    /// and again after [`Adaptive::reset`]; `None` = the method's automatic guess). Errors with
    /// [`IntegrateError::Config`] if `step` is not non-zero and finite.
    pub(super) fn with_method(method: M, step: Option<f64>) -> Result<Self, IntegrateError> {
        if let Some(h) = step
            && !(h.is_finite() && h != 0.0)
        {
            return Err(IntegrateError::Config(format!(
                "{} initial step must be non-zero and finite, got {h}",
                M::METHOD
            )));
        }
        Ok(Adaptive {
            method,
            initial_step: step.map(f64::abs),
            budget: Budget::DEFAULT,
            h_min: 0.0,
            h_max: f64::INFINITY,
            max_nonfinite_retries: DEFAULT_MAX_NONFINITE_RETRIES,
            h: 0.0,
            stats: Stats::initial(),
            rejections: Rejections::default(),
            comp: Compensation::default(),
        })
    }

    /// Sets the smallest allowed step size (default 0): a proposed `|h| < max(h_min, 10 ε |t|)` gives
    /// [`IntegrateError::StepUnderflow`].
    pub fn set_h_min(&mut self, h_min: f64) {
        self.h_min = h_min.abs();
    }

    /// Sets the largest allowed step size (default ∞). With a loose tolerance it makes a method run at a fixed step.
    pub fn set_h_max(&mut self, h_max: f64) {
        self.h_max = h_max.abs();
        if self.h > self.h_max {
            self.h = self.h_max;
        }
    }

    /// Sets how many consecutive rejections caused by NaN/∞ trial values are retried (each with a halved step)
    /// before [`IntegrateError::NonFinite`] is returned (default 10).
    pub fn set_max_nonfinite_retries(&mut self, retries: u32) {
        self.max_nonfinite_retries = retries;
    }

    /// Forgets the step-size and order history: the next step starts like the first one. Use after a
    /// discontinuity in the state or the equations.
    pub fn reset(&mut self) {
        self.comp = Compensation::default();
        self.h = 0.0;
        self.method.reset();
    }

    /// The step size the next step will try (`None` before the first step or after [`Adaptive::reset`]).
    pub fn proposed_step(&self) -> Option<f64> {
        (self.h > 0.0).then_some(self.h)
    }

    /// The tolerances in use.
    pub fn tolerances(&self) -> &Tolerances {
        self.method.tolerances()
    }

    /// Rejected steps by cause (cumulative).
    pub fn rejections(&self) -> Rejections {
        self.rejections
    }

    /// [`StepMethod::start`], failing with the time `t` when the derivative is not finite.
    fn start<'s>(&mut self, system: &'s dyn OdeSystem, t: f64, y: &[f64]) -> Result<M::Frozen<'s>, IntegrateError> {
        self.method.start(system, t, y).ok_or(IntegrateError::NonFinite { t })
    }

    /// The stepping loop of [`Integrator::advance`], after its checks.
    fn steps(&mut self, system: &dyn OdeSystem, t: &mut f64, y: &mut [f64], t_target: f64) -> Advanced {
        let dir = if t_target > *t { 1.0 } else { -1.0 };
        let mut frozen = self.start(system, *t, y)?;
        if self.h == 0.0 {
            let span = (t_target - *t).abs();
            let first = FirstStep {
                t: *t,
                dir,
                span,
                h_max: self.h_max,
            };
            self.h = match self.initial_step {
                Some(h) => h.min(self.h_max),
                None => self.method.initial_step(system, y, &first),
            };
        }
        let mut attempts: u64 = 0;
        let mut nonfinite_run: u32 = 0;
        // No rejection since the last accepted step.
        let mut clean = true;
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
            self.budget.check(*t, attempts)?;
            attempts += 1;
            let h_abs = if last { remaining } else { self.h };
            let (proposed, order) = (self.h, self.method.order());
            let trial = Trial {
                t: *t,
                h: dir * h_abs,
                t_end: if last { t_target } else { *t + dir * h_abs },
                last,
                after_rejection: !clean,
                h_max: self.h_max,
            };
            match self.method.attempt(system, &mut frozen, y, &trial) {
                Outcome::Accepted { h_next } => {
                    self.method.commit(y, &mut self.comp);
                    self.stats.steps_accepted += 1;
                    // Steps shortened only to land on an output time say nothing about the problem.
                    let landing = last && h_abs < proposed;
                    if !landing {
                        self.stats.smallest_step = self.stats.smallest_step.min(h_abs);
                    }
                    nonfinite_run = 0;
                    self.h = h_next;
                    *t = trial.t_end;
                    if last {
                        if clean && landing {
                            // Keep the proposal from before the shortening.
                            self.h = self.h.max(proposed);
                            self.method.set_order(order);
                        }
                        return Ok(());
                    }
                    clean = true;
                    frozen = self.start(system, *t, y)?;
                }
                Outcome::Rejected { h_next } => {
                    self.stats.steps_rejected += 1;
                    self.rejections.error += 1;
                    self.h = h_next;
                    nonfinite_run = 0;
                    clean = false;
                }
                Outcome::Halve(cause) => {
                    self.stats.steps_rejected += 1;
                    self.h = h_abs * HALVE;
                    clean = false;
                    let counter = match cause {
                        Cause::Stability => &mut self.rejections.stability,
                        Cause::Divergence => &mut self.rejections.divergence,
                        Cause::NonFinite => &mut self.rejections.nonfinite,
                    };
                    *counter += 1;
                    if cause == Cause::NonFinite {
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

    /// The loop's part of the state.
    fn carried(&self) -> Carried {
        Carried {
            dim: self.method.tolerances().rtol.len(),
            limits: StepLimits {
                max_steps: self.budget.max_steps,
                h_min: self.h_min,
                h_max: self.h_max,
                max_nonfinite_retries: self.max_nonfinite_retries,
            },
            initial_step: self.initial_step,
            h: self.h,
            stats: self.stats().into(),
            rejections: self.rejections,
            compensation: self.comp.carry.clone(),
        }
    }
}

impl<M: StepMethod> Integrator for Adaptive<M> {
    fn method(&self) -> Method {
        M::METHOD
    }

    fn advance(&mut self, system: &dyn OdeSystem, t: &mut f64, y: &mut [f64], t_target: f64) -> Advanced {
        let n = system.dim();
        if !begin_advance(n, self.method.tolerances().rtol.len(), t, y, t_target)? {
            return Ok(());
        }
        self.method.prepare(n);
        self.method.enter(y, &mut self.comp);
        let result = self.steps(system, t, y, t_target);
        system.end_steps();
        // The method's state is the last accepted one, whatever the result.
        self.method.leave(y, &mut self.comp);
        result
    }

    fn stats(&self) -> Stats {
        Stats {
            rhs_evaluations: self.method.evaluations(),
            ..self.stats
        }
    }

    fn set_span(&mut self, span: f64) {
        self.method.set_span((span.is_finite() && span > 0.0).then_some(span));
    }

    fn set_deadline(&mut self, deadline: Option<Instant>) {
        self.budget.deadline = deadline;
    }

    fn set_max_steps(&mut self, max_steps: u64) {
        self.budget.max_steps = max_steps.max(1);
    }

    fn save_state(&self) -> IntegratorState {
        self.method.save(self.carried())
    }

    fn restore_state(&mut self, state: &IntegratorState) -> Result<(), IntegrateError> {
        let mut c = self.carried();
        self.method.restore(state, &mut c)?;
        let StepLimits {
            max_steps,
            h_min,
            h_max,
            max_nonfinite_retries,
        } = c.limits;
        self.budget.max_steps = max_steps;
        (self.h_min, self.h_max, self.max_nonfinite_retries) = (h_min, h_max, max_nonfinite_retries);
        self.initial_step = c.initial_step;
        self.h = c.h;
        self.stats = c.stats.into();
        self.method.set_evaluations(c.stats.rhs_evaluations);
        self.rejections = c.rejections;
        self.comp.carry = c.compensation;
        // The saved state is the caller's: the compensation belongs to whatever state it passes next.
        self.comp.forget_output();
        Ok(())
    }
}
