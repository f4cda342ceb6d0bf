//! The `ode_solvers` crate's (0.6.2) Dop853, Dopri5 and Rk4 behind our [`Integrator`] trait, for cross-checks
//! against [`super::bulirsch_stoer`]; `"dop853"` runs our own `dop853::Dop853`, the crate's stays reachable
//! through [`OdeSolversAdapter::new`] (and reads the checkpoints its runs wrote).
//!
//! How the crate is driven: one `rtol` and `atol` only, so with per-component `atol` alone ([`Tolerances::scale_free`])
//! the state is rescaled `z_i = y_i / c_i`, `c_i = atol_i / min_j atol_j` (same norm exactly), else the minimum of
//! each vector is used. `OutputType::Sparse` (dense output extrapolates near the end), in chunks of
//! [`OdeSolversAdapter::set_chunk_steps`] steps to bound memory; the end lands at `t = t_target` exactly (Rk4 with a
//! shortened last step). The crate's DOP853 tableau has `c₁₂ = 0` instead of `1`, wrong for non-autonomous systems,
//! so Dop853 runs on `(y, τ)` with `τ' = 1`, tolerances scaled by `√(n/(n+1))`. Stiffness detection is off. RHS
//! calls are counted here, rejections derived from them. Each `advance` is a new crate run started from the last
//! full step; only that step, counters and settings are carried ([`OdeSolversState`]: restores bit for bit).
//! [`Budget`] checks before each run; on error `t, y` hold the last accepted state.

use super::adaptive_loop::{Budget, wrong_state};
pub use super::common::OdeSolversState;
use super::common::{
    Advanced, IntegrateError, Integrator, IntegratorState, Method, OdeSystem, Stats, Tolerances, begin_advance,
};
use ode_solvers::dop_shared::IntegrationError;
use ode_solvers::{DVector, Dop853, Dopri5, OutputType, Rk4, System};
use std::cell::{Cell, RefCell};

/// Default per-chunk memory budget for stored step states (bytes).
const CHUNK_BYTES: usize = 64 << 20;

/// Our system seen as an `ode_solvers` system, with time rescaled as `t = t0 + scale · s`
/// (`scale = 1, t0 = 0` for the adaptive methods) and counting evaluations. With `time_in_state`
/// the last state component is the time `τ` (`τ' = 1`) and the solver's own time is ignored.
struct Wrapped<'a> {
    system: &'a dyn OdeSystem,
    t0: f64,
    scale: f64,
    time_in_state: bool,
    evals: &'a Cell<u64>,
    nonfinite: &'a Cell<bool>,
    /// Per-component state scale `c` (the solver sees `z = y / c`) and a buffer for `y`.
    units: Option<(&'a [f64], &'a RefCell<Vec<f64>>)>,
}

impl System<f64, DVector<f64>> for Wrapped<'_> {
    fn system(&self, x: f64, y: &DVector<f64>, dy: &mut DVector<f64>) {
        self.evals.set(self.evals.get() + 1);
        let dydt = dy.as_mut_slice();
        if let Some((c, buffer)) = self.units {
            // y = c z; dz/dt = f(y) / c (Dop853 carries τ as the last component, with c = 1 implied).
            let mut yb = buffer.borrow_mut();
            let n = c.len();
            let z = y.as_slice();
            for ((v, &zi), &ci) in yb.iter_mut().zip(z).zip(c) {
                *v = zi * ci;
            }
            let time = if self.time_in_state { z[n] } else { x };
            self.system.rhs(time, &yb, &mut dydt[..n]);
            for (d, &ci) in dydt[..n].iter_mut().zip(c) {
                *d /= ci;
            }
            if self.time_in_state {
                dydt[n] = 1.0;
            }
        } else if self.time_in_state {
            let y = y.as_slice();
            let n = y.len() - 1;
            self.system.rhs(y[n], &y[..n], &mut dydt[..n]);
            dydt[n] = 1.0;
        } else if self.scale == 1.0 && self.t0 == 0.0 {
            self.system.rhs(x, y.as_slice(), dydt);
        } else {
            self.system.rhs(self.t0 + self.scale * x, y.as_slice(), dydt);
            for d in dydt.iter_mut() {
                *d *= self.scale;
            }
        }
        if !dydt.iter().all(|v| v.is_finite()) {
            self.nonfinite.set(true);
        }
    }
}

/// `ode_solvers`' Dop853, Dopri5 or Rk4 as an [`Integrator`] (see the [module docs](self)).
///
/// ```
/// use rubblepile::integrate::{Integrator, Method, Tolerances, ode_solvers_adapter::OdeSolversAdapter};
/// use rubblepile::integrate::problems::{HarmonicOscillator, TestProblem};
///
/// let osc = HarmonicOscillator::new(1.0);
/// let mut dop = OdeSolversAdapter::new(Method::Dop853, Tolerances::uniform(1e-10, 1e-10, 2), None).unwrap();
/// let (mut t, mut y) = (0.0, osc.initial_state());
/// dop.advance(&osc, &mut t, &mut y, 1.0).unwrap();
/// assert_eq!(t, 1.0);
/// assert!((y[0] - 1f64.cos()).abs() < 1e-8);
/// ```
#[derive(Debug, Clone)]
pub struct OdeSolversAdapter {
    method: Method,
    rtol: f64,
    atol: f64,
    /// `c_i = atol_i / atol` when only `atol` varies between components (see the module docs).
    units: Option<Vec<f64>>,
    n_tol: usize,
    step: Option<f64>,
    /// Step to start the next call with (adaptive methods); 0 = automatic.
    h_next: f64,
    budget: Budget,
    chunk_steps: Option<usize>,
    stats: Stats,
}

impl OdeSolversAdapter {
    /// A new adapter for `method` (Dop853, Dopri5 or Rk4).
    ///
    /// `step` is the fixed step of Rk4 (required, > 0), or an optional initial step for
    /// Dop853/Dopri5 (`None` = the crate's automatic guess). The tolerances are reduced to scalars
    /// (minimum over components; see the module docs); their length must still equal the system's
    /// dimension at [`Integrator::advance`]. `Method::BulirschStoer` is a configuration error.
    pub fn new(method: Method, tolerances: Tolerances, step: Option<f64>) -> Result<Self, IntegrateError> {
        if method == Method::BulirschStoer {
            return Err(IntegrateError::Config(
                "the ode_solvers adapter runs dop853, dopri5 or rk4, not bulirsch-stoer".into(),
            ));
        }
        if tolerances.rtol.len() != tolerances.atol.len() {
            return Err(IntegrateError::Config(format!(
                "rtol has {} components but atol has {}",
                tolerances.rtol.len(),
                tolerances.atol.len()
            )));
        }
        let rtol = tolerances.rtol.iter().copied().fold(f64::INFINITY, f64::min);
        let atol = tolerances.atol.iter().copied().fold(f64::INFINITY, f64::min);
        let ok = |v: f64| v.is_finite() && v >= 0.0;
        if !tolerances.rtol.is_empty() && !(ok(rtol) && ok(atol) && (rtol > 0.0 || atol > 0.0)) {
            return Err(IntegrateError::Config(format!(
                "tolerances must be finite, non-negative and not both zero (min rtol = {rtol}, \
                 min atol = {atol})"
            )));
        }
        match (method, step) {
            (Method::Rk4, Some(h)) if h > 0.0 && h.is_finite() => {}
            (Method::Rk4, _) => {
                return Err(IntegrateError::Config("rk4 needs a positive finite `step` (s)".into()));
            }
            (_, Some(h)) if !(h.is_finite() && h != 0.0) => {
                return Err(IntegrateError::Config(format!(
                    "initial step must be non-zero and finite, got {h}"
                )));
            }
            _ => {}
        }
        let uniform_rtol = tolerances.rtol.iter().all(|&r| r == rtol);
        let units: Option<Vec<f64>> = (uniform_rtol && atol > 0.0)
            .then(|| tolerances.atol.iter().map(|&a| a / atol).collect::<Vec<f64>>())
            .filter(|c| c.iter().any(|&ci| ci != 1.0));
        Ok(OdeSolversAdapter {
            method,
            rtol,
            atol,
            units,
            n_tol: tolerances.rtol.len(),
            step: step.map(f64::abs),
            h_next: if method == Method::Rk4 {
                0.0
            } else {
                step.map_or(0.0, f64::abs)
            },
            budget: Budget::DEFAULT,
            chunk_steps: None,
            stats: Stats::initial(),
        })
    }

    /// Sets the number of steps per `ode_solvers` run (see the module docs); `None` = automatic
    /// (about 64 MiB of stored states).
    pub fn set_chunk_steps(&mut self, chunk: Option<usize>) {
        self.chunk_steps = chunk.map(|c| c.max(1));
    }

    fn chunk(&self, n: usize) -> usize {
        self.chunk_steps
            .unwrap_or_else(|| (CHUNK_BYTES / (8 * (n + 1))).clamp(16, 1 << 20))
    }

    /// Dop853 / Dopri5.
    fn advance_adaptive(&mut self, system: &dyn OdeSystem, t: &mut f64, y: &mut [f64], t_target: f64) -> Advanced {
        let n = y.len();
        let chunk = self.chunk(n);
        let evals = Cell::new(0u64);
        let nonfinite = Cell::new(false);
        let mut x = *t;
        // Dop853 integrates (y, τ), see the module docs.
        let time_in_state = self.method == Method::Dop853;
        let units = self.units.clone();
        let buffer = RefCell::new(vec![0.0; n]);
        // The solver's state: z = y / c (or y itself), then τ for Dop853.
        let mut z: Vec<f64> = match &units {
            Some(c) => y.iter().zip(c).map(|(yi, ci)| yi / ci).collect(),
            None => y.to_vec(),
        };
        let to_user = |z: &[f64], y: &mut [f64]| match &units {
            Some(c) => {
                for ((yi, &zi), &ci) in y.iter_mut().zip(z).zip(c) {
                    *yi = zi * ci;
                }
            }
            None => y.copy_from_slice(&z[..y.len()]),
        };
        let (rtol, atol, mut state) = if time_in_state {
            let c = (n as f64 / (n + 1) as f64).sqrt();
            z.push(x);
            (self.rtol * c, self.atol * c, DVector::from_vec(z))
        } else {
            (self.rtol, self.atol, DVector::from_vec(z))
        };
        let mut steps: u64 = 0;
        let dir = if t_target > x { 1.0 } else { -1.0 };

        let result = loop {
            if let Err(e) = self.budget.check(x, steps) {
                break Err(e);
            }
            let n_max = (chunk as u64).min(self.budget.max_steps - steps).min(u32::MAX as u64) as u32;
            let f = Wrapped {
                system,
                t0: 0.0,
                scale: 1.0,
                time_in_state,
                evals: &evals,
                nonfinite: &nonfinite,
                units: units.as_deref().map(|c| (c, &buffer)),
            };
            let h0 = dir * self.h_next;
            let evals_before = evals.get();
            let h_max = (t_target - x).abs();
            // One run of the crate's `$solver` with its controller's safety factor, β, and smallest and largest step
            // ratios; its accepted steps' times, the last finite state and its index.
            macro_rules! run {
                ($solver:ident, $safety:expr, $beta:expr, $fac_min:expr, $fac_max:expr) => {{
                    let mut s = $solver::from_param(
                        f,
                        x,
                        t_target,
                        t_target - x,
                        state.clone(),
                        rtol,
                        atol,
                        $safety,
                        $beta,
                        $fac_min,
                        $fac_max,
                        h_max,
                        h0,
                        n_max,
                        u32::MAX,
                        OutputType::Sparse,
                    );
                    let res = s.integrate();
                    let (xs, ys) = s.results().get();
                    let (last, last_state) = last_finite(ys);
                    (res, xs.clone(), last, last_state)
                }};
            }
            let (res, xs, last, last_state) = match self.method {
                Method::Dop853 => run!(Dop853, 0.9, 0.0, 0.333, 6.0),
                _ => run!(Dopri5, 0.9, 0.04, 0.2, 10.0),
            };
            // xs[0] is the chunk's start; xs[1..=last] are accepted steps with finite states.
            let finite_end = last == xs.len() - 1;
            for i in 1..=last {
                self.stats.smallest_step = self.stats.smallest_step.min((xs[i] - xs[i - 1]).abs());
            }
            if last >= 2 {
                // The last step of a successful run is shortened to land; the one before is a
                // genuine proposal of the step control.
                self.h_next = (xs[last - 1] - xs[last - 2]).abs();
            } else if last == 1 && res.is_err() {
                self.h_next = (xs[1] - xs[0]).abs();
            }
            // ode_solvers returns its statistics only on success, and does not count rejections
            // before the first accepted step: derive both from the output and the evaluations.
            let accepted = (xs.len() - 1) as u64;
            let rejected = attempts_from_evals(self.method, evals.get() - evals_before, h0 == 0.0, accepted)
                .map(|attempts| attempts - accepted)
                .or_else(|| res.as_ref().ok().map(|st| st.rejected_steps as u64))
                .unwrap_or(0);
            self.stats.steps_accepted += accepted;
            self.stats.steps_rejected += rejected;
            steps += (xs.len() - 1) as u64;
            x = xs[last];
            state = last_state;
            if time_in_state {
                state[n] = x;
            }
            match res {
                Ok(_) if finite_end => {
                    to_user(&state.as_slice()[..n], y);
                    *t = t_target;
                    break Ok(());
                }
                Ok(_) => break Err(IntegrateError::NonFinite { t: x }),
                Err(IntegrationError::MaxNumStepReached { .. }) => {
                    if !finite_end {
                        break Err(IntegrateError::NonFinite { t: x });
                    }
                    if last == 0 {
                        // A whole chunk without progress: count it against the step budget.
                        steps += n_max as u64;
                    }
                    continue;
                }
                Err(IntegrationError::StepSizeUnderflow { .. }) => {
                    break Err(if nonfinite.get() || !finite_end {
                        IntegrateError::NonFinite { t: x }
                    } else {
                        // ode_solvers does not report the failing step; give the last accepted.
                        IntegrateError::StepUnderflow {
                            t: x,
                            h: dir * self.h_next,
                        }
                    });
                }
                Err(e @ IntegrationError::StiffnessDetected { .. }) => {
                    break Err(IntegrateError::Config(format!("ode_solvers: {e}")));
                }
            }
        };
        self.stats.rhs_evaluations += evals.get();
        if result.is_err() {
            // Leave the caller at the last accepted state.
            *t = x;
            to_user(&state.as_slice()[..n], y);
        }
        result
    }

    /// Fixed-step Rk4 landing exactly on `t_target`.
    fn advance_rk4(&mut self, system: &dyn OdeSystem, t: &mut f64, y: &mut [f64], t_target: f64) -> Advanced {
        let h = self.step.expect("rk4 step checked in new");
        let t_start = *t;
        let span = t_target - t_start;
        let dir = span.signum();
        let n_total = ((span.abs() / h) * (1.0 - 1e-12)).ceil().max(1.0);
        if n_total > self.budget.max_steps as f64 {
            return Err(IntegrateError::TooManySteps {
                t: t_start,
                max_steps: self.budget.max_steps,
            });
        }
        let n_total = n_total as u64;
        let n_full = n_total - 1;
        let chunk = self.chunk(y.len()) as u64;
        let evals = Cell::new(0u64);
        let nonfinite = Cell::new(false);
        let mut state = DVector::from_column_slice(y);
        let mut done: u64 = 0;
        let mut x = t_start;
        let result = loop {
            // Next segment: `m` steps of length `scale` (the final one shortened to land).
            let (m, scale, t0) = if done < n_full {
                let m = chunk.min(n_full - done);
                (m, dir * h, t_start + dir * h * done as f64)
            } else {
                (1, t_target - x, x)
            };
            let f = Wrapped {
                system,
                t0,
                scale,
                time_in_state: false,
                evals: &evals,
                nonfinite: &nonfinite,
                units: None,
            };
            let mut s = Rk4::new(f, 0.0, state.clone(), m as f64, 1.0);
            // Rk4::integrate never fails.
            let _ = s.integrate();
            // ys[0] is the segment's start; keep the states before the first non-finite one.
            let (last, last_state) = last_finite(s.y_out());
            let is_final = done >= n_full;
            self.stats.steps_accepted += last as u64;
            if last > 0 {
                self.stats.smallest_step = self.stats.smallest_step.min(scale.abs());
            }
            state = last_state;
            done += last as u64;
            if last as u64 != m {
                x = if is_final { x } else { t_start + dir * h * done as f64 };
                break Err(IntegrateError::NonFinite { t: x });
            }
            if is_final {
                x = t_target;
                break Ok(());
            }
            x = t_start + dir * h * done as f64;
        };
        self.stats.rhs_evaluations += evals.get();
        *t = x;
        y.copy_from_slice(state.as_slice());
        result
    }
}

/// Step attempts of one Dop853/Dopri5 run of `ode_solvers` 0.6.2, from its RHS evaluations:
/// 1 initial derivative, 2 more for the automatic initial step (`h0 = 0`), then Dop853 uses 11 per
/// attempt plus 1 per accepted step, Dopri5 6 per attempt (FSAL). `None` if inconsistent.
fn attempts_from_evals(method: Method, evals: u64, auto_h0: bool, accepted: u64) -> Option<u64> {
    let base = 1 + if auto_h0 { 2 } else { 0 };
    let (per_attempt, per_accept) = match method {
        Method::Dop853 => (11, 1),
        Method::Dopri5 => (6, 0),
        _ => return None,
    };
    let rest = evals.checked_sub(base + per_accept * accepted)?;
    (rest % per_attempt == 0 && rest / per_attempt >= accepted).then_some(rest / per_attempt)
}

/// Index of the last state before the first non-finite one, and a copy of it.
fn last_finite(ys: &[DVector<f64>]) -> (usize, DVector<f64>) {
    let last = match ys.iter().position(|v| !v.iter().all(|c| c.is_finite())) {
        Some(bad) => bad.saturating_sub(1),
        None => ys.len() - 1,
    };
    (last, ys[last].clone())
}

impl Integrator for OdeSolversAdapter {
    fn advance(&mut self, system: &dyn OdeSystem, t: &mut f64, y: &mut [f64], t_target: f64) -> Advanced {
        if !begin_advance(system.dim(), self.n_tol, t, y, t_target)? {
            return Ok(());
        }
        match self.method {
            Method::Rk4 => self.advance_rk4(system, t, y, t_target),
            _ => self.advance_adaptive(system, t, y, t_target),
        }
    }

    fn set_deadline(&mut self, deadline: Option<std::time::Instant>) {
        self.budget.deadline = deadline;
    }

    fn set_max_steps(&mut self, max_steps: u64) {
        self.budget.max_steps = max_steps.max(1);
    }

    fn stats(&self) -> Stats {
        self.stats
    }

    fn method(&self) -> Method {
        self.method
    }

    fn save_state(&self) -> IntegratorState {
        IntegratorState::OdeSolvers(OdeSolversState {
            method: self.method,
            dim: self.n_tol,
            rtol: self.rtol,
            atol: self.atol,
            step: self.step,
            h_next: self.h_next,
            max_steps: self.budget.max_steps,
            chunk_steps: self.chunk_steps,
            stats: self.stats.into(),
        })
    }

    fn restore_state(&mut self, state: &IntegratorState) -> Result<(), IntegrateError> {
        let s = match state {
            IntegratorState::OdeSolvers(s) if s.method == self.method => s,
            other => return Err(wrong_state(other, self.method)),
        };
        let same = |a: f64, b: f64| a.to_bits() == b.to_bits();
        if s.dim != self.n_tol || !same(s.rtol, self.rtol) || !same(s.atol, self.atol) {
            return Err(IntegrateError::Config(format!(
                "{} state saved for dimension {} with rtol {:e}, atol {:e}; this integrator has {}, {:e}, {:e}",
                self.method, s.dim, s.rtol, s.atol, self.n_tol, self.rtol, self.atol
            )));
        }
        if !(s.h_next.is_finite() && s.h_next >= 0.0) || s.step.is_some_and(|h| !(h.is_finite() && h > 0.0)) {
            return Err(IntegrateError::Config(format!(
                "{} state: bad step sizes (h_next = {}, step = {:?})",
                self.method, s.h_next, s.step
            )));
        }
        if self.method == Method::Rk4 && s.step.is_none() {
            return Err(IntegrateError::Config("rk4 state without a step".into()));
        }
        self.step = s.step;
        self.h_next = s.h_next;
        self.budget.max_steps = s.max_steps;
        self.chunk_steps = s.chunk_steps.map(|c| c.max(1));
        self.stats = s.stats.into();
        Ok(())
    }
}
