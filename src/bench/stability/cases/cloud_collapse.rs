//! Stability regime (g) cloud collapse.

use super::*;

/// End time of the quick cloud (s): a full collapse (free-fall time ≈ 2500 s).
pub const CLOUD_T_END: f64 = 3000.0;

/// End time of the N = 2000 cloud (s), set so that the bench case takes about 1–2 minutes on 2 cores: the
/// infall and the first contacts (the compaction after ≈ 1700 s costs ~10 × more per simulated second).
pub const CLOUD_T_END_N2000: f64 = 1500.0;

/// Escape speed (m/s) from the surface of a cloud: `√(2 G M / R)`, with `R` the largest centre distance from
/// the centre of mass.
pub fn cloud_escape_speed(bodies: &[Body]) -> f64 {
    let m: f64 = bodies.iter().map(|b| b.shape.mass).sum();
    let com = bodies.iter().map(|b| b.position * b.shape.mass).sum::<Vec3>() / m;
    let r = bodies.iter().map(|b| (b.position - com).norm()).fold(0.0, f64::max);
    (2.0 * G_SI * m / r).sqrt()
}

/// Case (g): `n` ellipsoids (equivalent radii 1–1.5 km, axis ratios ≥ 0.7) on a jittered cubic lattice with
/// spacing 2.6 × the mean radius, nearly at rest (±0.05 m/s, spins ±1e-5 rad/s), collapsing under their
/// gravity with contact and dissipation F0 = 1e-3 s m⁻² for `t_end` s (free-fall time ≈ 2500 s). κ is
/// calibrated with β = 10 and `v` = 1.5 × the cloud's escape speed (the collapse brings fragments together
/// at up to about that speed) or, `naive`, `v` = 2 m/s (a fragment pair's escape speed), under which the
/// collapse must produce overruns that the detector reports.
pub fn cloud_collapse(id: &str, n: usize, t_end: f64, naive: bool) -> Case {
    let params = CloudParams {
        density: DENSITY,
        r_min: 1000.0,
        r_max: 1500.0,
        spacing_factor: 2.6,
        jitter: 0.1,
        speed: 0.05,
        spin: 1e-5,
        min_axis_ratio: 0.7,
    };
    let bodies = random_cloud(n, 7, &params);
    let v_esc = cloud_escape_speed(&bodies);
    let v_cal = if naive {
        2.0
    } else {
        (1.5 * v_esc * 100.0).ceil() / 100.0
    };
    let spec = SceneSpec::calibrated(t_end, v_cal, Some(1e-3), 10, 1);
    let description = format!(
        "cloud collapse: N = {n} ellipsoids (R_eq 1-1.5 km, spacing 2.6 R, near rest; escape speed {v_esc:.2} m/s) under gravity + contact + F0 = 1e-3 s/m^2, calibrate beta = 10, v = {v_cal} m/s{}, {t_end} s",
        if naive {
            " (a fragment pair's speed)"
        } else {
            " (1.5 x escape)"
        }
    );
    case(id, description, &spec, &bodies, move |run| {
        let snaps = run.snapshots()?;
        let settings = rubblepile::ellipsoid::barrier::BarrierSettings::for_kappa_source(&run.scene.kappa_source);
        let count = |b: &[Body]| rubblepile::ellipsoid::barrier::contacts(&run.scene.model, &settings, b).len();
        let (c0, c1) = (
            snaps.first().map_or(0, |(_, b)| count(b)),
            snaps.last().map_or(0, |(_, b)| count(b)),
        );
        let broke = run.summary.barrier.as_ref().map_or(0, |b| b.broke_through_pairs);
        let overruns = run.overrun_pairs();
        let mut checks = run_checks(run, true);
        checks.push(quaternion_check(run));
        checks.push((true, broke == 0, format!("no break-through ({broke} pairs)")));
        let contacts_text = format!("touching pairs {c0} at t = 0, {c1} at t_end");
        if naive {
            checks.push((
                true,
                overruns > 0,
                format!("overruns reported: {overruns} pairs (expected > 0); {contacts_text}"),
            ));
        } else {
            checks.push((
                false,
                overruns == 0,
                format!("overruns {overruns} (expected 0); {contacts_text}"),
            ));
        }
        Ok(judge(&checks))
    })
}
