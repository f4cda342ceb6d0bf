//! Integrators for first-order systems `y' = f(t, y)`.
//!
//! One integrator per file behind the small [`Integrator`] trait (the REBOUND layout), the three of our own as one
//! step loop around a method's step:
//! - [`adaptive_loop`]: the loop (landing on output times, non-finite retries, compensated summation, budgets,
//!   statistics, the common part of a checkpoint state) and the trait a method implements to run in it;
//! - [`bulirsch_stoer`]: our own adaptive Gragg–Bulirsch–Stoer extrapolation integrator in the style of
//!   Hairer's ODEX (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.9), the method Roig03 §3 used;
//! - [`dop853`]: our own DOP853 of Dormand & Prince (order 8 with Hairer's 5th- and 3rd-order error estimators
//!   and step-size control, §II.10 of the same book), its vector work parallel and deterministic;
//! - [`ode_solvers_adapter`]: the same systems under `ode_solvers`' Dopri5 and Rk4 (and its Dop853, for
//!   cross-checks);
//! - [`linearly_implicit`]: linearly implicit Euler extrapolation (SEULEX of Hairer & Wanner, *Solving ODEs II*,
//!   §IV.9) for stiff systems, using the stiff part a system supplies ([`OdeSystem::stiff_part`]);
//! - [`elliptic`]: Jacobi elliptic functions and elliptic integrals (the torque-free top's exact solution);
//! - [`problems`]: canonical ODE problems with known solutions (Arenstorf orbit, Kepler, …), shared by the
//!   tests and the benchmarks.
//!
//! What they share (the system and integrator traits, methods, tolerances, statistics, errors and the states a
//! checkpoint keeps) is in `common.rs`, re-exported here: each method imports it from there, and only this file
//! names the methods ([`make_integrator`]), so the files form no circle. The work–precision measurements that
//! exercise these solvers are the `rubblepile bench` program's.

pub mod adaptive_loop;
pub mod bulirsch_stoer;
pub mod compensated;
pub mod dop853;
pub mod elliptic;
pub mod linearly_implicit;
pub mod ode_solvers_adapter;
pub mod problems;

mod common;
pub use common::*;

/// Builds the integrator for `method`. `step` is the fixed step (s) for `Rk4`, or an optional
/// initial step for the adaptive methods (`BulirschStoerImplicit` chooses its own).
pub fn make_integrator(
    method: Method,
    tolerances: Tolerances,
    step: Option<f64>,
) -> Result<Box<dyn Integrator + Send>, IntegrateError> {
    match method {
        Method::BulirschStoer => Ok(Box::new(bulirsch_stoer::BulirschStoer::new(tolerances, step)?)),
        Method::Dop853 => Ok(Box::new(dop853::Dop853::new(tolerances, step)?)),
        Method::BulirschStoerImplicit => Ok(Box::new(linearly_implicit::LinearlyImplicit::new(tolerances)?)),
        Method::Dopri5 => Ok(Box::new(ode_solvers_adapter::OdeSolversAdapter::new(
            method, tolerances, step,
        )?)),
        Method::Rk4 => match step {
            Some(h) if h > 0.0 && h.is_finite() => Ok(Box::new(ode_solvers_adapter::OdeSolversAdapter::new(
                method, tolerances, step,
            )?)),
            _ => Err(IntegrateError::Config("rk4 needs a positive finite `step` (s)".into())),
        },
    }
}
