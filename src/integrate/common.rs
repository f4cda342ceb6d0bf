//! What every integrator of `integrate` shares, below all of them: the system trait [`OdeSystem`] (and the
//! stiff part [`StiffSolve`] it may supply), the [`Method`] names, [`Tolerances`], [`Stats`], the errors, the
//! [`Integrator`] trait and what each method saves into a checkpoint ([`IntegratorState`] and the state of each
//! method). Each method's file imports from here and nothing here imports a method, so that the methods and
//! `integrate/mod.rs` (which builds them) form no file circle.

use crate::bits::{exact_f64, exact_f64_opt, exact_f64_vec};

use std::fmt;

/// A first-order ODE system `dy/dt = f(t, y)` of fixed dimension.
pub trait OdeSystem: Sync {
    /// Number of state components.
    fn dim(&self) -> usize;
    /// Writes `f(t, y)` into `dydt` (both of length [`OdeSystem::dim`]).
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]);
    /// The *user unit* of each state component, in the component's own units: how much of the component one
    /// unit of the quantity a user thinks in amounts to. A momentum `u = m v` has unit `m` (so one unit is
    /// 1 m/s of velocity), a conjugate quaternion momentum has `2 I` (one unit is 1 rad/s of spin), a position or
    /// a quaternion has 1. [`Tolerances::scale_free`] multiplies `atol` by these, so that the error norm
    /// measures every block in user units and a tolerance means the same for a light and a heavy body.
    /// `None` (the default): every component is its own user unit.
    fn state_units(&self) -> Option<Vec<f64>> {
        None
    }
    /// Called by an integrator with the state `y` at time `t` from which it is about to take a step, before
    /// that step's first evaluation (once per step: retries after a rejection start from the same state and
    /// keep the choice). A system may fix here any discrete choice its right-hand side makes (which tree nodes
    /// are used whole), so that `f` is a smooth function of the state within the step and the choice changes
    /// only between steps. `bulirsch_stoer` and `dop853` call it; the `ode_solvers` methods cannot, and a
    /// system must then keep working without it. Default: nothing.
    fn begin_step(&self, _t: f64, _y: &[f64]) {}
    /// Called by an integrator that calls [`OdeSystem::begin_step`] when it returns from an advance (whether it
    /// reached its target or failed): the system drops the choice, so that evaluations outside the integrator
    /// (diagnostics, another integrator) do not keep it. Default: nothing.
    fn end_steps(&self) {}
    /// The stiff part `J ≈ ∂f/∂y` at `(t, y)`, as a solver of `(I − h J) x = b`, for the linearly implicit
    /// methods (`linearly_implicit`), which call it at the start of every step and keep it for the step. Any
    /// matrix gives a correct method of the same order (a W-method); the closer it is to the stiff part of the
    /// true Jacobian, the longer the stable steps. Default `None`: no stiff part (`J = 0`).
    fn stiff_part(&self, _t: f64, _y: &[f64]) -> Option<Box<dyn StiffSolve + '_>> {
        None
    }
}

/// Which integrator runs a system (the scene's `[integrator] method`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Adaptive Bulirsch–Stoer (ours), `"bulirsch-stoer"`: the default.
    #[default]
    BulirschStoer,
    /// Dormand–Prince 8(5,3) (ours, `dop853::Dop853`), `"dop853"`.
    Dop853,
    /// Dormand–Prince 5(4) from `ode_solvers`, `"dopri5"`.
    Dopri5,
    /// Classical fixed-step Runge–Kutta 4 from `ode_solvers`, `"rk4"` (needs a step).
    Rk4,
    /// Linearly implicit Euler extrapolation for stiff systems (ours, `linearly_implicit::LinearlyImplicit`),
    /// `"bulirsch-stoer-implicit"`.
    BulirschStoerImplicit,
}

impl crate::named::Named for Method {
    const ALL: &'static [Method] = &[
        Method::BulirschStoer,
        Method::Dop853,
        Method::Dopri5,
        Method::Rk4,
        Method::BulirschStoerImplicit,
    ];

    fn name(self) -> &'static str {
        match self {
            Method::BulirschStoer => "bulirsch-stoer",
            Method::Dop853 => "dop853",
            Method::Dopri5 => "dopri5",
            Method::Rk4 => "rk4",
            Method::BulirschStoerImplicit => "bulirsch-stoer-implicit",
        }
    }

    fn help(self) -> &'static str {
        match self {
            Method::BulirschStoer => "adaptive Bulirsch–Stoer (ours)",
            Method::Dop853 => "Dormand–Prince 8(5,3) (ours)",
            Method::Dopri5 => "Dormand–Prince 5(4) from ode_solvers",
            Method::Rk4 => "classical fixed-step Runge–Kutta 4 from ode_solvers (needs a step)",
            Method::BulirschStoerImplicit => "linearly implicit Euler extrapolation for stiff systems (ours)",
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(crate::named::Named::name(*self))
    }
}

/// Relative and absolute tolerances, one pair per state component.
///
/// The error of a step is measured in the scaled RMS norm
/// `err = sqrt( (1/n) Σ_i (e_i / (atol_i + rtol_i · max(|y_i(t)|, |y_i(t+h)|)))² )`
/// and a step is accepted when `err ≤ 1`.
///
/// **Scale-free norm.** [`Tolerances::scale_free`] sets `atol_i = atol · unit_i` with the system's
/// [`OdeSystem::state_units`]. Dividing numerator and denominator by `unit_i` shows that this is the same norm
/// applied to the state expressed in user units (`e_i / unit_i` against `atol + rtol |y_i / unit_i|`): the
/// relative part is unit-free anyway, and the absolute part then reads in m, m/s, rad/s, … whatever the masses.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Tolerances {
    /// Relative tolerance per component (dimensionless, > 0).
    pub rtol: Vec<f64>,
    /// Absolute tolerance per component (units of that component, ≥ 0).
    pub atol: Vec<f64>,
}

impl Tolerances {
    /// The scale-free tolerances of `system`: `rtol` for every component and `atol` in user units, i.e.
    /// `atol_i = atol · unit_i` with [`OdeSystem::state_units`] (uniform when the system gives none).
    ///
    /// ```
    /// use rubblepile::integrate::{OdeSystem, Tolerances};
    /// /// A particle of mass 1e6 kg on a line: state (x, u = m v).
    /// struct Heavy;
    /// impl OdeSystem for Heavy {
    ///     fn dim(&self) -> usize { 2 }
    ///     fn rhs(&self, _t: f64, y: &[f64], d: &mut [f64]) { d[0] = y[1] / 1e6; d[1] = 0.0; }
    ///     fn state_units(&self) -> Option<Vec<f64>> { Some(vec![1.0, 1e6]) }
    /// }
    /// let tol = Tolerances::scale_free(1e-9, 1e-9, &Heavy);
    /// assert_eq!(tol.atol, vec![1e-9, 1e-3]); // 1e-9 m and 1e-9 m/s
    /// assert_eq!(tol.rtol, vec![1e-9, 1e-9]);
    /// ```
    pub fn scale_free(rtol: f64, atol: f64, system: &dyn OdeSystem) -> Self {
        let n = system.dim();
        match system.state_units() {
            Some(units) if units.len() == n => Tolerances {
                rtol: vec![rtol; n],
                atol: units.iter().map(|u| atol * u).collect(),
            },
            _ => Tolerances::uniform(rtol, atol, n),
        }
    }

    /// The same `rtol` and `atol` for all `n` components.
    pub fn uniform(rtol: f64, atol: f64, n: usize) -> Self {
        Tolerances {
            rtol: vec![rtol; n],
            atol: vec![atol; n],
        }
    }
}

/// Counters every integrator keeps (cumulative over its life).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct Stats {
    /// Accepted steps.
    pub steps_accepted: u64,
    /// Rejected steps (error too large, stability check, non-finite trial values).
    pub steps_rejected: u64,
    /// Evaluations of the right-hand side.
    pub rhs_evaluations: u64,
    /// Smallest accepted step size (s); `f64::INFINITY` before the first step.
    pub smallest_step: f64,
}

impl Stats {
    /// The statistics before the first step: all zero, `smallest_step` infinite.
    pub fn initial() -> Self {
        Stats {
            smallest_step: f64::INFINITY,
            ..Stats::default()
        }
    }
}

/// [`Stats`] as stored in a checkpoint (`smallest_step` as exact bits, so `∞` survives).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SavedStats {
    /// Accepted steps.
    pub steps_accepted: u64,
    /// Rejected steps.
    pub steps_rejected: u64,
    /// Evaluations of the right-hand side.
    pub rhs_evaluations: u64,
    /// Smallest accepted step size (s), exact.
    #[serde(with = "crate::bits::exact_f64")]
    pub smallest_step: f64,
}

impl From<Stats> for SavedStats {
    fn from(s: Stats) -> Self {
        SavedStats {
            steps_accepted: s.steps_accepted,
            steps_rejected: s.steps_rejected,
            rhs_evaluations: s.rhs_evaluations,
            smallest_step: s.smallest_step,
        }
    }
}

impl From<SavedStats> for Stats {
    fn from(s: SavedStats) -> Self {
        Stats {
            steps_accepted: s.steps_accepted,
            steps_rejected: s.steps_rejected,
            rhs_evaluations: s.rhs_evaluations,
            smallest_step: s.smallest_step,
        }
    }
}

/// Everything an integrator carries from one [`Integrator::advance`] call to the next (step-size
/// and order control, counters, settings), as saved by [`Integrator::save_state`] into a checkpoint.
/// Serialisable with exact floats: restoring it into a fresh integrator of the same method and
/// tolerances continues bit for bit like the original. The tolerances are not saved (the `ode_solvers`
/// adapter's scalar ones only to check them): that integrator must be built with the same ones, and
/// only their length is checked.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum IntegratorState {
    /// State of a `bulirsch_stoer::BulirschStoer`.
    BulirschStoer(BulirschStoerState),
    /// State of an `ode_solvers_adapter::OdeSolversAdapter` (Dopri5, Rk4; Dop853 in checkpoints written before
    /// `dop853::Dop853` ran `"dop853"`, which the latter refuses).
    OdeSolvers(OdeSolversState),
    /// State of a `dop853::Dop853`.
    Dop853(Dop853State),
    /// State of a `linearly_implicit::LinearlyImplicit`.
    LinearlyImplicit(LinearlyImplicitState),
}

impl IntegratorState {
    /// The method whose state this is.
    pub fn method(&self) -> Method {
        match self {
            IntegratorState::BulirschStoer(_) => Method::BulirschStoer,
            IntegratorState::OdeSolvers(s) => s.method,
            IntegratorState::Dop853(_) => Method::Dop853,
            IntegratorState::LinearlyImplicit(_) => Method::BulirschStoerImplicit,
        }
    }
}

/// Why an integration stopped early. The state passed to the integrator is left at the last good
/// (accepted) point `t`, so the caller can save it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IntegrateError {
    /// The state or its derivative became NaN or infinite and step reduction did not cure it.
    #[error("non-finite state or derivative at t = {t} s (last good state kept)")]
    NonFinite {
        /// Last good time (s).
        t: f64,
    },
    /// The step size fell below the resolvable limit `|h| < 10 ε |t|` (or below `h_min`).
    #[error("step size underflow at t = {t} s: h = {h:e} s (last good state kept)")]
    StepUnderflow {
        /// Last good time (s).
        t: f64,
        /// The step that was too small (s).
        h: f64,
    },
    /// More steps than the configured maximum.
    #[error("more than {max_steps} steps before t = {t} s (last good state kept)")]
    TooManySteps {
        /// Last good time (s).
        t: f64,
        /// The limit.
        max_steps: u64,
    },
    /// The wall-clock deadline set by [`Integrator::set_deadline`] passed (a run's wall-clock budget).
    #[error("the wall-clock deadline passed at t = {t} s (last good state kept)")]
    Deadline {
        /// Last good time (s).
        t: f64,
    },
    /// A configuration error (e.g. rk4 without a step, tolerances of the wrong length).
    #[error("integrator configuration: {0}")]
    Config(String),
}

/// What [`Integrator::advance`] returns: `Ok` once landed on the target time, else why it stopped.
pub type Advanced = Result<(), IntegrateError>;

/// An integrator that advances a state to requested times, landing on each exactly.
pub trait Integrator {
    /// Advances `y` from `*t` to `t_target` (> `*t`), landing exactly on `t_target`.
    /// On success `*t == t_target`. On error `*t, y` hold the last accepted point.
    fn advance(&mut self, system: &dyn OdeSystem, t: &mut f64, y: &mut [f64], t_target: f64) -> Advanced;
    /// Cumulative statistics.
    fn stats(&self) -> Stats;
    /// Tells the integrator the span of the whole run (s), so that a method that can control the error per unit
    /// step does (Bulirsch–Stoer; see its module docs): the local errors of the run then add up to a share of
    /// the tolerance instead of one tolerance per step. A span that is not positive and finite switches it
    /// off. The default does nothing (the Dormand–Prince methods control the error per step).
    fn set_span(&mut self, _span: f64) {}
    /// Caps the step attempts of each later [`Integrator::advance`] call at `max_steps` (beyond it the call fails
    /// with [`IntegrateError::TooManySteps`], the last accepted point kept): a run's step budget
    /// ([`crate::io::run_budget`]). The default does nothing.
    fn set_max_steps(&mut self, _max_steps: u64) {}
    /// Makes each later [`Integrator::advance`] stop with [`IntegrateError::Deadline`] (the last accepted point kept)
    /// once the wall clock passes `deadline` (`None`: never): a run's wall-clock budget. The default does nothing.
    fn set_deadline(&mut self, _deadline: Option<std::time::Instant>) {}
    /// Which method this is.
    fn method(&self) -> Method;
    /// Everything that influences later calls to [`Integrator::advance`] (see [`IntegratorState`]).
    /// Taken between `advance` calls; the integrator is not changed.
    fn save_state(&self) -> IntegratorState;
    /// Restores a state saved by [`Integrator::save_state`] of an integrator of the same method, built
    /// with the same tolerances for a system of the same dimension; afterwards `advance` continues
    /// exactly (bit for bit) as the saved integrator would have. Errors with
    /// [`IntegrateError::Config`] (leaving `self` unchanged) for another method's state or an
    /// inconsistent one.
    fn restore_state(&mut self, state: &IntegratorState) -> Result<(), IntegrateError>;
}

/// The step limits a `BulirschStoer` and a `Dop853` save (flattened into their states).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StepLimits {
    /// Maximum step attempts per `advance`.
    pub max_steps: u64,
    /// Smallest allowed step (s).
    #[serde(with = "exact_f64")]
    pub h_min: f64,
    /// Largest allowed step (s).
    #[serde(with = "exact_f64")]
    pub h_max: f64,
    /// Consecutive non-finite rejections retried.
    pub max_nonfinite_retries: u32,
}

/// The step and column control both extrapolation methods save (flattened into their states): the proposed step,
/// the target column count, the per-column proposals and work of the last attempt, the counters.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ColumnControlState {
    /// The run's span for error-per-unit-step control (s), if set.
    #[serde(with = "exact_f64_opt")]
    pub span: Option<f64>,
    /// Proposed `|H|` for the next step (s); 0 = not yet known. After landing on an output time
    /// this is the un-shortened proposal.
    #[serde(with = "exact_f64")]
    pub h: f64,
    /// Target column count `k`.
    pub k: usize,
    /// The previous attempt was rejected.
    pub reject: bool,
    /// At least one step has been attempted.
    pub started: bool,
    /// Optimal step per column of the last attempt (s; index 0 unused, length `km + 1`).
    #[serde(with = "exact_f64_vec")]
    pub hh: Vec<f64>,
    /// Work per unit step per column of the last attempt (index 0 unused, length `km + 1`).
    #[serde(with = "exact_f64_vec")]
    pub w: Vec<f64>,
    /// Cumulative statistics.
    pub stats: SavedStats,
    /// Cumulative rejections by cause.
    pub rejections: Rejections,
}

/// Everything a `BulirschStoer` carries between [`Integrator::advance`] calls
/// ([`Integrator::save_state`]): the step-size and column control, the per-column proposals and
/// work of the last attempt, the counters and the settings. The work arrays are not saved: every
/// call recomputes them before reading them.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BulirschStoerState {
    /// Length of the tolerance vectors (the system's dimension).
    pub dim: usize,
    /// Maximum number of columns `km`.
    pub km: usize,
    /// Step budget and step-size limits.
    #[serde(flatten)]
    pub limits: StepLimits,
    /// The configured initial step (s), if any.
    #[serde(with = "exact_f64_opt")]
    pub initial_step: Option<f64>,
    /// Step and column control, counters.
    #[serde(flatten)]
    pub columns: ColumnControlState,
    /// What compensated summation carries into the next step (length `dim`, or empty = zero; states saved before
    /// the compensation existed have none).
    #[serde(default, with = "exact_f64_vec")]
    pub compensation: Vec<f64>,
}

/// Rejected steps of an adaptive integrator by cause (cumulative); their sum is
/// [`Stats::steps_rejected`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Rejections {
    /// Error estimate too large (ordinary step-size control, including the convergence monitor).
    pub error: u64,
    /// The stability check in the first substep of columns 1–2 failed (step halved).
    pub stability: u64,
    /// The error estimate diverged with the column index (`err_j ≥ max(4 err_{j−1}, 1)`), or was huge
    /// (step halved).
    pub divergence: u64,
    /// NaN/∞ in a trial value or derivative (step halved).
    pub nonfinite: u64,
}

/// Everything a `Dop853` carries between [`Integrator::advance`] calls ([`Integrator::save_state`]): the
/// proposed step, the settings and the counters. The derivative at the start of a call is recomputed by every call,
/// so it is not part of the state; nor is the parallel threshold, on which no bit of the results depends.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Dop853State {
    /// Length of the tolerance vectors (the system's dimension).
    pub dim: usize,
    /// The configured initial step (s), if any.
    #[serde(with = "exact_f64_opt")]
    pub initial_step: Option<f64>,
    /// Step budget and step-size limits.
    #[serde(flatten)]
    pub limits: StepLimits,
    /// Proposed `|h|` for the next step (s); 0 = not yet known. After landing on an output time this is the
    /// proposal from before the shortened last step.
    #[serde(with = "exact_f64")]
    pub h: f64,
    /// Cumulative statistics.
    pub stats: SavedStats,
}

/// The stiff part `J` of a system at the start of a step, as the solver of `(I − h J) x = b` that the linearly
/// implicit methods need ([`OdeSystem::stiff_part`]).
pub trait StiffSolve {
    /// Overwrites `b` with the solution `x` of `(I − h J) x = b` (`h` in s; `b` of the system's dimension).
    /// `J` is the same for every call on one value.
    fn solve(&mut self, h: f64, b: &mut [f64]);
}

/// Everything a `LinearlyImplicit` carries between [`Integrator::advance`] calls ([`Integrator::save_state`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LinearlyImplicitState {
    /// The system's dimension.
    pub dim: usize,
    /// Maximum number of columns.
    pub km: usize,
    /// Maximum step attempts per advance.
    pub max_steps: u64,
    /// Step and column control, counters.
    #[serde(flatten)]
    pub columns: ColumnControlState,
    /// Linear solves so far.
    pub solves: u64,
    /// What the compensated summation carries into the next step (`dim` entries, or empty = zero).
    #[serde(with = "exact_f64_vec")]
    pub compensation: Vec<f64>,
}

/// Everything an `OdeSolversAdapter` carries between [`Integrator::advance`] calls
/// ([`Integrator::save_state`]). The scalar tolerances are saved only to check that the adapter the
/// state is restored into was built with the same ones.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OdeSolversState {
    /// Dop853, Dopri5 or Rk4.
    pub method: Method,
    /// Length of the tolerance vectors (the system's dimension).
    pub dim: usize,
    /// Scalar relative tolerance in use.
    #[serde(with = "exact_f64")]
    pub rtol: f64,
    /// Scalar absolute tolerance in use.
    #[serde(with = "exact_f64")]
    pub atol: f64,
    /// Rk4's fixed step or the adaptive methods' configured initial step (s).
    #[serde(with = "exact_f64_opt")]
    pub step: Option<f64>,
    /// The step the next `advance` starts with (adaptive methods; 0 = automatic).
    #[serde(with = "exact_f64")]
    pub h_next: f64,
    /// Maximum steps per `advance`.
    pub max_steps: u64,
    /// Steps per `ode_solvers` run (`None` = automatic).
    pub chunk_steps: Option<usize>,
    /// Cumulative statistics.
    pub stats: SavedStats,
}

/// The checks every [`Integrator::advance`] makes before its first step, for a system of dimension `n` with
/// `n_tol` tolerances: the state and tolerances have the system's dimension, the times are finite, the state is
/// finite. Returns whether there is anything to integrate (`false` when `t_target == t`, or for an empty system,
/// whose time is then set to `t_target`).
pub(crate) fn begin_advance(
    n: usize,
    n_tol: usize,
    t: &mut f64,
    y: &[f64],
    t_target: f64,
) -> Result<bool, IntegrateError> {
    if y.len() != n || n_tol != n {
        return Err(IntegrateError::Config(format!(
            "dimension mismatch: system {n}, state {}, tolerances {n_tol}",
            y.len()
        )));
    }
    if !t.is_finite() || !t_target.is_finite() {
        return Err(IntegrateError::Config(format!(
            "times must be finite (t = {}, t_target = {t_target})",
            *t
        )));
    }
    if t_target == *t {
        return Ok(false);
    }
    if n == 0 {
        *t = t_target;
        return Ok(false);
    }
    if !y.iter().all(|v| v.is_finite()) {
        return Err(IntegrateError::NonFinite { t: *t });
    }
    Ok(true)
}
