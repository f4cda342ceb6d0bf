//! Integrators for first-order systems `y' = f(t, y)`, one per file behind the small [`Integrator`] trait (the
//! REBOUND layout); our own three are one step loop ([`adaptive_loop`]) around a method's step:
//! [`bulirsch_stoer`] (ODEX-style Gragg–Bulirsch–Stoer, Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.9; the method
//! of Roig03 §3), [`dop853`] (Dormand & Prince, §II.10), [`linearly_implicit`] (SEULEX, Hairer & Wanner, *Solving
//! ODEs II*, §IV.9, with the system's [`OdeSystem::stiff_part`]); [`ode_solvers_adapter`] runs the `ode_solvers`
//! crate's methods for cross-checks. [`elliptic`]: Jacobi elliptic functions and integrals (the torque-free top);
//! [`problems`]: canonical ODE problems with known solutions for tests and benchmarks.
//!
//! The shared traits, tolerances, statistics, errors and checkpoint states are in `common.rs`, re-exported here;
//! only this file names the methods ([`make_integrator`]), so the files form no circle.

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
