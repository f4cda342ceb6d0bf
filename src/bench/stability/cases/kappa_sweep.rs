//! Stability regime (f) the κ sweep.

use super::*;

/// Relative speed of the κ sweep's collision (m/s).
pub const SWEEP_SPEED: f64 = 0.8;

/// Case (f): the head-on pair of case (a) (here bodies 0 and 1) meeting tip to tip at [`SWEEP_SPEED`] m/s,
/// with κ calibrated (β = 10, `v` = the speed for which Eq. 14 gives `kappa`). Where 0.8 m/s exceeds 1.25 ×
/// that speed the detector must report the overrun, and stay silent elsewhere. Without `gravity` the
/// barrier alone stops the bodies (an elastic rebound); with it, κ = 1.6 cannot hold them: the pair's
/// barrier is only ≈ 3.9 × their gravitational binding at contact (`e^{κλ}/(2κλ)`), point-mass gravity
/// diverges as the centres meet, and the bodies fall through each other, which must be reported as a
/// break-through (and the run then stops at the singularity with a message naming the pair).
pub fn kappa_sweep(id: &str, kappa: f64, gravity: bool) -> Case {
    let bodies = tip_to_tip(SWEEP_SPEED);
    let v_cal = speed_for_kappa(kappa, 10.0, &bodies[1], &bodies[0]);
    let t_end = 4000.0;
    let spec = SceneSpec {
        gravity,
        ..SceneSpec::calibrated(t_end, v_cal, None, 20, 4)
    };
    let expect_overrun = SWEEP_SPEED > SPEED_MARGIN * v_cal;
    let description = format!(
        "kappa = {kappa}: head-on tip-to-tip impact at {SWEEP_SPEED} m/s, kappa calibrated with beta = 10, v = {v_cal:.3e} m/s, contact{}, {t_end} s",
        if gravity { " + gravity" } else { " only (no gravity)" }
    );
    case(id, description, &spec, &bodies, move |run| {
        let (ratio, sep) = run.contact_extremes(2.0)?;
        let report = run.summary.barrier.clone();
        let got = run.overrun_pairs() > 0;
        let named = report
            .as_ref()
            .is_some_and(|b| b.pairs.len() == 1 && (b.pairs[0].i, b.pairs[0].j) == (0, 1));
        let through = report.as_ref().is_some_and(|b| b.broke_through_pairs > 0);
        let mut checks = vec![(
            true,
            (run.summary.kappa / kappa - 1.0).abs() < 1e-9,
            format!("kappa {:.6}", run.summary.kappa),
        )];
        checks.push((
            true,
            got == expect_overrun && (!got || named),
            format!(
                "overrun reported: {got}{} (expected {expect_overrun}: speed/calibrated {:.3}; max over contacts {ratio:.3}); centres down to {sep:.3} of touching",
                if named { " for bodies 0 and 1" } else { "" },
                SWEEP_SPEED / v_cal
            ),
        ));
        if gravity && through {
            checks.push((true, true, "broke through (gravity pulls the centres together)".into()));
            if let Some(cause) = &run.failure {
                checks.push((
                    true,
                    cause.contains("broke through") && cause.contains("bodies 0 and 1"),
                    "the stop names the break-through of bodies 0 and 1".into(),
                ));
            }
        } else {
            checks.extend(run_checks(run, false));
            checks.push((true, !through, format!("no break-through ({through})")));
        }
        Ok(judge(&checks))
    })
}
