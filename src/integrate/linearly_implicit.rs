//! Linearly implicit Euler extrapolation (SEULEX) for stiff systems, `method = "bulirsch-stoer-implicit"`: Hairer &
//! Wanner, *Solving Ordinary Differential Equations II* (2nd ed., Springer 1996), §IV.9; an independent
//! implementation. This file supplies the base rule ([`LinearlyImplicitEuler`]) and SEULEX's constants; the
//! extrapolation and column/step control ([`Extrapolation`]) and the loop ([`Adaptive`]) are our ODEX's
//! ([`super::bulirsch_stoer`]), with its error per unit step ([`Integrator::set_span`]) and Kahan-compensated sum.
//!
//! A step `H` takes the system's stiff part `J ≈ ∂f/∂y` ([`OdeSystem::stiff_part`]) once; column `j` runs `n_j = j`
//! substeps `(I − h J) Δ_m = h f(t + m h, y_m)`, `y_{m+1} = y_m + Δ_m`, `T_{j,1} = y_{n_j}`, extrapolated by
//! `T_{j,k+1} = T_{j,k} + (T_{j,k} − T_{j−1,k}) / (n_j/n_{j−k} − 1)` (`T_{j,j}` of order `j`; a W-method: any `J`
//! keeps the order, only stability depends on it). Error `‖T_{j,j} − T_{j,j−1}‖` in the norm of [`Tolerances`]. A
//! step is halved when the error grows with the column or column 2's second increment exceeds twice its first (the
//! stiff part unresolved by `J`). With `J = 0` this is extrapolated explicit Euler: correct, slower than ODEX.

use nalgebra::{DMatrix, DVector};

pub use super::adaptive_loop::DEFAULT_MAX_STEPS;
use super::adaptive_loop::{
    Adaptive, Carried, Cause, FirstStep, all_finite, hinit_h0, validate_tolerances, wrong_state,
};
use super::bulirsch_stoer::{BaseRule, Column, ColumnControlState, Extrapolation, Strategy, Unpacked, rms};
#[cfg(doc)]
use super::common::Integrator;
use super::common::{IntegrateError, IntegratorState, Method, OdeSystem, Tolerances};
pub use super::common::{LinearlyImplicitState, StiffSolve};

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

/// SEULEX's step and order control (its `fac1 … fac4`, `safe1`, `safe2`).
const SEULEX: Strategy = Strategy {
    gragg: false,
    fac1: 0.1,
    fac2: 4.0,
    fac3: 0.7,
    fac4: 0.9,
    safe1: 0.6,
    safe2: 0.93,
};
/// Limit on `‖Δ_1‖ / ‖Δ_0‖` in the stability check of column 2.
const STABILITY_RATIO: f64 = 2.0;
/// Default maximum number of columns (SEULEX `km`): the highest order is `km`.
pub const DEFAULT_MAX_COLUMNS: usize = 12;

/// Linearly implicit Euler extrapolation (SEULEX strategy), see the [module documentation](self): the step loop
/// [`Adaptive`] around [`Extrapolation`] of [`LinearlyImplicitEuler`].
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
pub type LinearlyImplicit = Adaptive<Extrapolation<LinearlyImplicitEuler>>;

impl LinearlyImplicit {
    /// A new integrator with per-component `tolerances` (see [`Tolerances`]). Errors with
    /// [`IntegrateError::Config`] on tolerances of different lengths, negative, non-finite, or both zero.
    pub fn new(tolerances: Tolerances) -> Result<Self, IntegrateError> {
        validate_tolerances(&tolerances)?;
        let rule = LinearlyImplicitEuler::default();
        Adaptive::with_method(Extrapolation::new(tolerances, DEFAULT_MAX_COLUMNS, rule), None)
    }

    /// Linear solves `(I − h J) x = b` so far (one per substep).
    pub fn solves(&self) -> u64 {
        self.method.rule().solves
    }
}

/// The linearly implicit Euler method (the base rule of SEULEX) with the stiff part the system supplies, and its
/// work arrays.
#[derive(Debug, Clone, Default)]
pub struct LinearlyImplicitEuler {
    /// `f(t, y)` at the step's start.
    f0: Vec<f64>,
    /// The derivative at a trial state.
    f: Vec<f64>,
    /// The increment of a column's substeps from the step's start.
    d: Vec<f64>,
    /// One substep's increment `Δ_m`.
    delta: Vec<f64>,
    /// The trial state `y + d`.
    trial: Vec<f64>,
    evals: u64,
    solves: u64,
}

/// The identity solve of a system without a stiff part (`J = 0`).
struct NoStiffPart;

impl StiffSolve for NoStiffPart {
    fn solve(&mut self, _h: f64, _b: &mut [f64]) {}
}

impl BaseRule for LinearlyImplicitEuler {
    type Frozen<'s> = Box<dyn StiffSolve + 's>;
    const METHOD: Method = Method::BulirschStoerImplicit;
    const STRATEGY: Strategy = SEULEX;

    fn resize(&mut self, n: usize) {
        for v in [&mut self.f0, &mut self.f, &mut self.d, &mut self.delta, &mut self.trial] {
            *v = vec![0.0; n];
        }
    }

    fn evaluations(&self) -> u64 {
        self.evals
    }

    fn set_evaluations(&mut self, n: u64) {
        self.evals = n;
    }

    /// The derivative at the step's start, and the stiff part linearised there.
    fn start<'s>(&mut self, system: &'s dyn OdeSystem, t: f64, y: &[f64]) -> Option<Box<dyn StiffSolve + 's>> {
        system.begin_step(t, y);
        self.evals += 1;
        system.rhs(t, y, &mut self.f0);
        if !all_finite(&self.f0) {
            return None;
        }
        Some(system.stiff_part(t, y).unwrap_or_else(|| Box::new(NoStiffPart)))
    }

    /// The first half of Hairer's `hinit`, `0.01 ‖y‖ / ‖f‖`: the step control grows it by up to `fac2` per step.
    fn initial_step(&mut self, _system: &dyn OdeSystem, y: &[f64], scal: &[f64], _k: usize, first: &FirstStep) -> f64 {
        let h0 = hinit_h0(rms(y, scal), rms(&self.f0, scal));
        if h0.is_finite() && h0 > 0.0 {
            h0.min(first.span)
        } else {
            1e-6f64.min(first.span)
        }
    }

    /// `n_j = j` substeps `(I − h_j J) Δ_m = h_j f(t + m h_j, y + d_m)` of `h_j = H/n_j`, with SEULEX's stability
    /// check in column 2 (the second increment at most twice the first).
    fn column(
        &mut self,
        system: &dyn OdeSystem,
        stiff: &mut Box<dyn StiffSolve + '_>,
        column: &Column<'_>,
        row: &mut [f64],
    ) -> Result<(), Cause> {
        let &Column { y, trial, j, scal } = column;
        let hj = trial.h / j as f64;
        self.d.fill(0.0);
        let mut first_norm = 0.0;
        for m in 0..j {
            if m == 0 {
                self.delta.copy_from_slice(&self.f0);
            } else {
                for ((z, &yi), &di) in self.trial.iter_mut().zip(y).zip(&self.d) {
                    *z = yi + di;
                }
                self.evals += 1;
                system.rhs(trial.t + hj * m as f64, &self.trial, &mut self.f);
                self.delta.copy_from_slice(&self.f);
            }
            for x in self.delta.iter_mut() {
                *x *= hj;
            }
            stiff.solve(hj, &mut self.delta);
            self.solves += 1;
            if !all_finite(&self.delta) {
                return Err(Cause::NonFinite);
            }
            if j == 2 {
                let size = rms(&self.delta, scal);
                if m == 0 {
                    first_norm = size;
                } else if first_norm > 0.0 && size > STABILITY_RATIO * first_norm {
                    return Err(Cause::Stability);
                }
            }
            for (di, &x) in self.d.iter_mut().zip(&self.delta) {
                *di += x;
            }
        }
        row.copy_from_slice(&self.d);
        Ok(())
    }

    fn save(&self, km: usize, columns: ColumnControlState, carried: Carried) -> IntegratorState {
        IntegratorState::LinearlyImplicit(LinearlyImplicitState {
            dim: carried.dim,
            km,
            max_steps: carried.limits.max_steps,
            columns,
            solves: self.solves,
            compensation: carried.compensation,
        })
    }

    /// Of the loop's settings the state keeps the step budget: `h_min`, `h_max` and the non-finite retries stay the
    /// integrator's own (its layout predates them).
    fn unpack<'a>(state: &'a IntegratorState, carried: &mut Carried) -> Unpacked<'a> {
        let IntegratorState::LinearlyImplicit(s) = state else {
            return Err(wrong_state(state, Self::METHOD));
        };
        carried.limits.max_steps = s.max_steps;
        Ok((s.dim, s.km, &s.columns, &s.compensation))
    }

    fn restore_own(&mut self, state: &IntegratorState) {
        if let IntegratorState::LinearlyImplicit(s) = state {
            self.solves = s.solves;
        }
    }
}
