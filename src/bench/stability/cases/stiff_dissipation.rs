//! Stability regime (e) stiff dissipation, F0 = 100 s m⁻² (Roig03 Eqs. 40–41).

use super::*;

/// Case (e1): two spinning ellipsoids meeting off-centre (impact parameter 300 m) at 1 m/s with
/// F0 = 100 s m⁻² (10⁸ × the Roig03 campaign's value): they must be captured (no rebound), the bookkeeping
/// `H − H0 − 2∫F` must hold and the run must not stall. Since `F_ij ∝ U_Cij` is nonzero wherever the Gaussians
/// overlap, such an F0 brakes the bodies in the tails of the overlap, before their surfaces touch: the soft
/// criterion "captured in contact" is expected to miss (a warning about the model, not the integrator).
pub fn sticking(id: &str) -> Case {
    let a = rock(
        [1000.0, 700.0, 500.0],
        [-1200.0, -150.0, 0.0],
        [0.0; 3],
        axis_angle([0.0, 0.0, 1.0], 0.3),
        [1e-4, 0.0, 3e-4],
    );
    let b = rock(
        [800.0, 600.0, 400.0],
        [1200.0, 150.0, 0.0],
        [0.0; 3],
        axis_angle([1.0, 1.0, 0.0], 0.5),
        [0.0, -2e-4, 1e-4],
    );
    let bodies = approaching(a, b, 1.0);
    let spec = SceneSpec::calibrated(3000.0, 2.0, Some(100.0), 30, 30);
    let description = "F0 = 100 s/m^2: two spinning ellipsoids meet off-centre at 1 m/s (gravity, contact, calibrate beta = 10, v = 2 m/s) and stick, 3000 s".to_string();
    case(id, description, &spec, &bodies, |run| {
        let bodies = final_bodies(run)?;
        let d = bodies[0].position - bodies[1].position;
        let radial = (bodies[0].velocity - bodies[1].velocity).dot(&d) / d.norm();
        let (_, sep) = pair_state(&bodies, 0, 1);
        let mut checks = run_checks(run, true);
        checks.push(no_stall_check(run));
        checks.push((
            true,
            radial.abs() < 1e-2,
            format!(
                "captured: radial relative speed {:.1e} m/s < 1% of the 1 m/s approach",
                radial.abs()
            ),
        ));
        checks.push((
            false,
            sep < 1.0,
            format!("captured in contact: separation ratio {sep:.3} < 1"),
        ));
        checks.push(quaternion_check(run));
        Ok(judge(&checks))
    })
}

/// Case (e2): F0 = 100 s m⁻² on a pair already touching: the ellipsoids of case (h) stacked at the touching
/// distance (900 m, flat faces together) closing at 0.1 m/s. Here the damping rate `2 F0 U_C/μ` is ≈ 4 s⁻¹,
/// so an explicit integrator needs steps of ~0.1 s: the run must still finish (≤ 1e6 step attempts for
/// 2000 s) and keep its energy bookkeeping.
pub fn sticking_in_contact(id: &str) -> Case {
    let low = rock([1000.0, 700.0, 500.0], [0.0; 3], [0.0; 3], Vec4::w(), [1e-5, 0.0, 2e-5]);
    let high = rock(
        [800.0, 600.0, 400.0],
        [0.0, 0.0, 900.0],
        [0.0, 0.0, -0.1],
        Vec4::w(),
        [0.0, -1e-5, 0.0],
    );
    let spec = SceneSpec::calibrated(2000.0, 2.0, Some(100.0), 20, 20);
    let description = "F0 = 100 s/m^2 in contact: 800x600x400 m ellipsoid touching a 1000x700x500 m one, closing at 0.1 m/s (gravity, contact), 2000 s".to_string();
    case(id, description, &spec, &[low, high], |run| {
        let (_, sep) = pair_state(&final_bodies(run)?, 0, 1);
        let mut checks = run_checks(run, true);
        checks.push(no_stall_check(run));
        checks.push(settled_check(run));
        checks.push((
            false,
            sep < 1.0,
            format!("stuck in contact: separation ratio {sep:.4} < 1"),
        ));
        checks.push(quaternion_check(run));
        Ok(judge(&checks))
    })
}
