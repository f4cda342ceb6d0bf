//! Stability regime (b) needles and plates, C/A = 0.05.

use super::*;

/// Case (b): two C/A = 0.05 bodies (`plates`: A = B; else needles, B = C) dropped onto each other (centres
/// 260 m apart, 0.3 m/s) with gravity, contact and dissipation F0 = 0.1 s m⁻², spinning slowly about all
/// axes, left to settle. κ is calibrated with β = 10 and `v` above the speed they reach at contact: monopole
/// gravity between centres 200 m apart accelerates the 5e12 kg plates to ≈ 1.3 m/s (the needles, 2.5e11 kg,
/// to ≈ 0.6 m/s), so the plates need `v = 2` m/s (with `v = 1` the detector reports their overrun).
pub fn flat_pair(id: &str, plates: bool) -> Case {
    let (axes, offset, turn) = if plates {
        ([2000.0, 2000.0, 100.0], [300.0, -200.0, 260.0], PI / 6.0)
    } else {
        ([2000.0, 100.0, 100.0], [200.0, 100.0, 260.0], PI / 2.0)
    };
    let a = rock(axes, [0.0; 3], [0.0; 3], Vec4::w(), [2e-4, -1e-4, 5e-5]);
    let b = rock(
        axes,
        offset,
        [0.0, 0.0, -0.3],
        axis_angle([0.0, 0.0, 1.0], turn),
        [-1e-4, 2e-4, -5e-5],
    );
    let t_end = 10_000.0;
    let v_cal = if plates { 2.0 } else { 1.0 };
    let spec = SceneSpec::calibrated(t_end, v_cal, Some(0.1), 40, 20);
    let shape = if plates {
        "plates A = B = 2000 m"
    } else {
        "needles B = C = 100 m"
    };
    let description = format!(
        "two {shape}, C/A = 0.05, dropped onto each other at 0.3 m/s (gravity, contact, F0 = 0.1 s/m^2, calibrate beta = 10, v = {v_cal} m/s), settling for {t_end} s"
    );
    case(id, description, &spec, &[a, b], |run| {
        let (_, sep) = pair_state(&final_bodies(run)?, 0, 1);
        let mut checks = run_checks(run, true);
        checks.push(quaternion_check(run));
        checks.push(settled_check(run));
        checks.push((
            false,
            sep < 1.0,
            format!(
                "in contact: separation ratio {sep:.3} < 1 (centre distance / touching distance, sphere-equivalent)"
            ),
        ));
        checks.push(no_overrun_check(run));
        Ok(judge(&checks))
    })
}
