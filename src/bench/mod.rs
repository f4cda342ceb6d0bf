//! Benchmarks, canonical test problems and timed systems (the russell_ode layout: one module of problems shared by
//! the tests and the benchmarks):
//! - [`problems`]: canonical ODE problems with known solutions (Arenstorf orbit, Kepler, …);
//! - [`ellipsoid_problems`]: canonical problems of the ellipsoid model (free top, bouncing pair, N30 impact, N-body
//!   tests);
//! - [`work_precision`]: work–precision measurements (timed runs, final-state and energy errors);
//! - [`stability`]: the stability suite of stiff and extreme cases (`rubblepile bench stability`).

pub mod ellipsoid_problems;
pub mod problems;
pub mod stability;
pub mod work_precision;
