//! Stability regime (a) head-on impacts at and above the calibrated speed (Roig03 Eqs. 13–14).

use super::*;

/// Calibrated speed of case (a) (m/s).
pub const HEAD_ON_V_CAL: f64 = 5.0;

/// Case (a): a spectator (body 0, 20 km away) and the largest (body 1, 1000 × 700 × 500 m) and smallest
/// (body 2, 600 × 450 × 300 m) body meeting tip to tip along x at `factor` × the calibrated speed of
/// `calibrate = { beta = 10, v = 5 }` (so the colliding pair is exactly Eq. 14's pair k, l).
pub fn head_on(id: &str, factor: f64) -> Case {
    let v = factor * HEAD_ON_V_CAL;
    let spectator = rock(
        [800.0, 560.0, 400.0],
        [0.0, 20_000.0, 0.0],
        [0.0; 3],
        Vec4::w(),
        [0.0; 3],
    );
    let [large, small] = tip_to_tip(v);
    // Eq. 14's barrier is β ½ m_l v_cal², the collision's energy ½ μ v²: through above v² > β (m_k + m_l)/m_k v_cal².
    let through_factor2 = 10.0 * (small.shape.mass + large.shape.mass) / small.shape.mass;
    let bodies = [spectator, large, small];
    // surfaces 800 m apart: contact after 800/v s; contact + rebound within 1600/v s more.
    let t_end = (2400.0 / v).ceil() + 200.0;
    let spec = SceneSpec::calibrated(t_end, HEAD_ON_V_CAL, None, 40, 4);
    let every = spec.every;
    let description = format!(
        "head-on tip-to-tip impact of bodies 1 and 2 at {factor} x the calibrated {HEAD_ON_V_CAL} m/s (beta = 10), gravity + contact, no dissipation"
    );
    case(id, description, &spec, &bodies, move |run| {
        let (ratio, sep) = run.contact_extremes(every / 10.0)?;
        let pairs = run
            .summary
            .barrier
            .as_ref()
            .map(|b| b.pairs.clone())
            .unwrap_or_default();
        let named = pairs.len() == 1 && pairs[0].i == 1 && pairs[0].j == 2;
        let measured = format!("max speed/calibrated {ratio:.3}, centres down to {sep:.3} of touching");
        if factor < SPEED_MARGIN {
            let mut checks = run_checks(run, false);
            checks.push((
                true,
                run.overrun_pairs() == 0,
                format!("no overrun reported ({measured})"),
            ));
            let rebound = final_bodies(run).map(|b| {
                let (d, dv) = (b[1].position - b[2].position, b[1].velocity - b[2].velocity);
                d.dot(&dv) > 0.0
            });
            checks.push((true, rebound == Ok(true), "rebounded (separating at t_end)".into()));
            Ok(judge(&checks))
        } else {
            let through = pairs.first().is_some_and(|p| p.broke_through);
            let expect_through = factor * factor > through_factor2;
            let mut checks = vec![(
                true,
                named,
                format!(
                    "overrun reported for exactly bodies 1 and 2 ({} pairs listed; {measured})",
                    pairs.len()
                ),
            )];
            if let Some(p) = pairs.first() {
                checks.push((
                    true,
                    (p.worst_speed / v - 1.0).abs() < 0.05,
                    format!("reported speed {:.3} m/s within 5% of {v} m/s", p.worst_speed),
                ));
            }
            checks.push((
                true,
                through == expect_through,
                format!("broke through: {through} (expected {expect_through})"),
            ));
            match &run.failure {
                None => checks.extend(energy_check(run, false)),
                Some(cause) => checks.push((
                    true,
                    expect_through && cause.contains("broke through") && cause.contains("bodies 1 and 2"),
                    "a stop names the break-through of bodies 1 and 2".into(),
                )),
            }
            Ok(judge(&checks))
        }
    })
}
