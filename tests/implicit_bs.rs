//! Tests of the linearly implicit extrapolation integrator (`method = "bulirsch-stoer-implicit"`,
//! `rubblepile::integrate::linearly_implicit`): error proportional to the tolerance on a stiff problem with an
//! exact solution, momentum conservation over a stiff pile's settling, and bit-identical resume (the
//! dissipation's analytic Jacobian is checked against finite differences by `ellipsoid::equations`'s unit
//! tests).

use rubblepile::integrate::linearly_implicit::LinearlyImplicit;
use rubblepile::integrate::problems::{StiffDampedOscillator, TestProblem};
use rubblepile::integrate::{Integrator, Method, Tolerances, make_integrator};

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
        assert!(
            err < previous,
            "error {err:e} not below {previous:e} of the looser tolerance"
        );
        assert!(steps < 1000, "{steps} steps: the stiff mode is not handled implicitly");
        previous = err;
    }
}

mod common;
use common::{Random, rock};
use rubblepile::ellipsoid::body::Body;
use rubblepile::ellipsoid::equations::{EllipsoidSystem, ModelConfig, Physics};

/// Four ellipsoids of 400–1000 m, random attitudes, spins and velocities, their centres 800–1100 m apart so that
/// every neighbouring pair overlaps.
fn overlapping_four(seed: u64) -> Vec<Body> {
    let mut rng = Random::new(seed);
    let centres = [
        [0.0, 0.0, 0.0],
        [1000.0, 100.0, 0.0],
        [400.0, 900.0, 100.0],
        [500.0, 400.0, 850.0],
    ];
    centres
        .iter()
        .map(|&c| {
            let a = rng.range(700.0, 1000.0);
            let v = rng.vec3(0.1);
            let w = rng.vec3(1e-4);
            rock(
                [a, a * rng.range(0.6, 0.9), a * rng.range(0.4, 0.6)],
                c,
                [v.x, v.y, v.z],
                rng.unit_quaternion(),
                [w.x, w.y, w.z],
            )
        })
        .collect()
}

/// A stiff pile settling: four overlapping ellipsoids (gravity, contact, F0 = 100 s m⁻², damping rates up to
/// ~1e5 s⁻¹) integrated for 20 s by the implicit method. Total linear and angular momentum are conserved to 1e-13
/// of their scales (`momentum_scale`, `angular_momentum_scale` of the diagnostics: sums of the bodies' own
/// magnitudes, so the measure stays well posed where the totals are small), the energy balance `H − H0 − 2∫F`
/// holds, and the bodies come to rest relative to each other.
///
/// Why 1e-13 holds: each substep's increment is `(I − hJ')⁻¹ h f` with `J'` holding the dissipation's momentum
/// block *and* the kinematic rows `ṙ = u/m`, `q̇ = M⁻¹p`, so the positions and attitudes move with the *new* momenta
/// (`Δr = h u_new/m`), the structure of symplectic Euler, under which `Σ r × u` changes only by the torques of the
/// (momentum-conserving) forces. Without the kinematic rows `Δr` used the old momenta and `L` changed by
/// `h Σ (u/m) × Δu` per substep, a truncation error (8e-12 at rtol 1e-8, 0.6–1.2e-13 at 1e-10), not round-off.
#[test]
fn stiff_pile_settles_conserving_momenta() {
    let bodies = overlapping_four(11);
    let sys = EllipsoidSystem::new(&bodies, ModelConfig::gaussian_si(6.0), Physics::impact(100.0));
    let t_end = 20.0;
    let rtol = 1e-10;
    let mut integ = make_integrator(
        Method::BulirschStoerImplicit,
        Tolerances::scale_free(rtol, rtol, &sys),
        None,
    )
    .unwrap();
    integ.set_span(t_end);
    let mut y = sys.initial_state();
    let d0 = sys.diagnostics(&y);
    let (mut t, mut dp, mut dl, mut de) = (0.0, 0.0_f64, 0.0_f64, 0.0_f64);
    for k in 1..=20 {
        integ.advance(&sys, &mut t, &mut y, t_end * k as f64 / 20.0).unwrap();
        let d = sys.diagnostics(&y);
        dp = dp.max((d.momentum - d0.momentum).norm() / d0.momentum_scale);
        dl = dl.max((d.angular_momentum - d0.angular_momentum).norm() / d0.angular_momentum_scale);
        de = de.max((d.energy() - d0.energy() - d.dissipated).abs() / d0.energy_scale);
    }
    let d = sys.diagnostics(&y);
    let relative_ke =
        d.kinetic_translational - 0.5 * d.momentum.norm_squared() / bodies.iter().map(|b| b.shape.mass).sum::<f64>();
    let stats = integ.stats();
    eprintln!(
        "steps {} ({} rejected), RHS {}: |dP| {dp:e}, |dL| {dl:e}, energy {de:e}, dissipated {:e} J, KE left in relative motion {relative_ke:e} J of {:e}",
        stats.steps_accepted, stats.steps_rejected, stats.rhs_evaluations, -d.dissipated, d0.kinetic_translational
    );
    assert!(dp <= 1e-13, "linear momentum error {dp:e}");
    assert!(dl <= 1e-13, "angular momentum error {dl:e}");
    assert!(de <= 1e-8, "energy balance error {de:e}");
    assert!(
        -d.dissipated > 0.5 * d0.kinetic_translational,
        "the pile did not dissipate its relative motion"
    );
    assert!(
        stats.steps_accepted < 5000,
        "{} steps: the damping is not handled implicitly",
        stats.steps_accepted
    );
}

/// Two touching spheres of radius 1 km and 2000 kg m⁻³ (κ = 10, SI gravity, contact) at `f0`, integrated by
/// `method`: a scene's text.
fn touching_spheres(f0: f64, method: &str) -> String {
    format!(
        "[scene]\nkind = \"ellipsoids\"\nt_end = 1000.0\n[model]\nkappa = 10.0\n[physics]\ngravity = {{}}\n\
         contact = {{}}\ndissipation = {{ F0 = {f0:e} }}\n[integrator]\nmethod = \"{method}\"\nrtol = 1e-8\n\
         atol = 1e-8\n[output]\ntimes = [0.0, 1000.0]\nevery = 100.0\n\
         [[body]]\naxes = [1000.0, 1000.0, 1000.0]\ndensity = 2000.0\nposition = [0.0, 0.0, 0.0]\n\
         [[body]]\naxes = [1000.0, 1000.0, 1000.0]\ndensity = 2000.0\nposition = [2000.0, 0.0, 0.0]\n"
    )
}

/// `check`'s stiffness advice: the contact period `2π √(R C²/(G m κ))` over the damping time `4κR/(F0 G m)`
/// against the hand computation for the two spheres (`T/τ = (π/2) F0 √(G m R) / κ^{3/2}` = 37.2 F0 here), the
/// advice given at F0 = 1 s m⁻² (ratio 37 > 10) with an explicit method, and not at F0 = 0.1 (ratio 3.7), nor with
/// the implicit method.
#[test]
fn check_advises_the_implicit_method_for_stiff_damping() {
    use rubblepile::ellipsoid::scene::{STIFF_ADVICE_RATIO, contact_stiffness, parse_scene};
    let advice = |w: &[String]| w.iter().any(|l| l.contains("bulirsch-stoer-implicit"));
    let stiff = parse_scene(&touching_spheres(1.0, "bulirsch-stoer"), "stiff.toml", None).unwrap();
    let s = contact_stiffness(&stiff.bodies, &stiff.model, &stiff.physics).expect("contact and dissipation");
    let (r, kappa, g) = (1000.0_f64, 10.0_f64, 6.674e-11_f64);
    let m = 2000.0 * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
    let expected = std::f64::consts::FRAC_PI_2 * (g * m * r).sqrt() / kappa.powf(1.5);
    assert!(
        (s.ratio - expected).abs() <= 1e-3 * expected,
        "ratio {} against {expected} by hand",
        s.ratio
    );
    assert!(
        s.ratio > STIFF_ADVICE_RATIO,
        "F0 = 1 should be stiff: ratio {}",
        s.ratio
    );
    assert!(
        advice(&stiff.warnings),
        "no advice at ratio {}: {:?}",
        s.ratio,
        stiff.warnings
    );
    let mild = parse_scene(&touching_spheres(0.1, "bulirsch-stoer"), "mild.toml", None).unwrap();
    let sm = contact_stiffness(&mild.bodies, &mild.model, &mild.physics).unwrap();
    assert!(
        (sm.ratio - 0.1 * expected).abs() <= 1e-3 * expected,
        "the ratio is linear in F0"
    );
    assert!(
        !advice(&mild.warnings),
        "advice at ratio {}: {:?}",
        sm.ratio,
        mild.warnings
    );
    let implicit = parse_scene(&touching_spheres(1.0, "bulirsch-stoer-implicit"), "stiff.toml", None).unwrap();
    assert!(!advice(&implicit.warnings), "advice although the method is implicit");
}
