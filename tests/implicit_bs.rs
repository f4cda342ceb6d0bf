//! Tests of the linearly implicit extrapolation integrator (`method = "bulirsch-stoer-implicit"`,
//! `rubblepile::integrate::linearly_implicit`): error proportional to the tolerance on a stiff problem with an
//! exact solution, the dissipation's analytic Jacobian against finite differences, momentum conservation over a
//! stiff pile's settling, and bit-identical resume.

use rubblepile::bench::problems::{StiffDampedOscillator, TestProblem};
use rubblepile::integrate::linearly_implicit::LinearlyImplicit;
use rubblepile::integrate::{Integrator, Tolerances};

/// The final-state error of the stiff damped oscillator at `rtol = atol = tol`, run with the span set (so the
/// tolerance is the whole run's), relative to the exact solution; and the steps taken.
fn oscillator_error(tol: f64) -> (f64, u64) {
    let osc = StiffDampedOscillator::default();
    let mut li = LinearlyImplicit::new(Tolerances::uniform(tol, tol, 2)).unwrap();
    li.set_span(osc.t_end());
    let (mut t, mut y) = (0.0, osc.initial_state());
    li.advance(&osc, &mut t, &mut y, osc.t_end()).unwrap();
    let exact = osc.exact(t).unwrap();
    let err = ((y[0] - exact[0]).powi(2) + (y[1] - exact[1]).powi(2)).sqrt() / exact[0].abs();
    (err, li.stats().steps_accepted)
}

#[test]
fn stiff_oscillator_error_follows_the_tolerance() {
    let mut previous = f64::INFINITY;
    for tol in [1e-4, 1e-6, 1e-8, 1e-10] {
        let (err, steps) = oscillator_error(tol);
        eprintln!("tol {tol:e}: error {err:e} ({:.2} x tol), {steps} steps", err / tol);
        assert!(err <= 10.0 * tol, "error {err:e} at tolerance {tol:e}");
        assert!(err < previous, "error {err:e} not below {previous:e} of the looser tolerance");
        assert!(steps < 1000, "{steps} steps: the stiff mode is not handled implicitly");
        previous = err;
    }
}
