//! Stability regime (h) a resting contact held for 1e6 s.

use super::*;

/// Absolute tolerance of the resting-contact cases (h1, h2): 1e-6 (m for positions, kg m/s for momenta).
/// For these ~1e12 kg bodies that is 1e-18 m/s in velocity; the default 1e-10 asks for 1e-22 m/s, below the
/// rounding noise of the ~1e9 N contact and gravity forces that cancel at rest, and Bulirsch–Stoer then
/// crawls (case h0).
pub const RESTING_ATOL: f64 = 1e-6;

/// Case (h): an 800 × 600 × 400 m ellipsoid resting on a 1000 × 700 × 500 m one, C axes along z (flat faces
/// together), for `t_end` s under their mutual gravity and contact: `damped` (F0 = 1e-2 s m⁻², dropped from
/// 50 m above touching, must settle and stay) or free (F0 off, released at rest 5 m above touching, must
/// oscillate without drifting: the separation can never exceed the release point while energy is conserved).
/// `atol` is the absolute tolerance ([`RESTING_ATOL`], or the default 1e-10 for case h0, which shows the crawl).
pub fn resting(id: &str, damped: bool, atol: f64, t_end: f64) -> Case {
    let gap = if damped { 50.0 } else { 5.0 };
    let low = rock([1000.0, 700.0, 500.0], [0.0; 3], [0.0; 3], Vec4::w(), [0.0; 3]);
    let high = rock(
        [800.0, 600.0, 400.0],
        [0.0, 0.0, 900.0 + gap],
        [0.0; 3],
        Vec4::w(),
        [0.0; 3],
    );
    let spec = SceneSpec {
        atol,
        ..SceneSpec::calibrated(t_end, 2.0, damped.then_some(1e-2), 100, 100)
    };
    let crawl_demo = atol < RESTING_ATOL;
    let description = if damped {
        format!(
            "resting contact, damped: 800x600x400 m ellipsoid dropped 50 m onto a 1000x700x500 m one (gravity, contact, F0 = 1e-2 s/m^2), held {t_end:e} s, atol = {atol:e}"
        )
    } else {
        format!(
            "resting contact, free: the same pair released at rest 5 m above touching, no dissipation, oscillating for {t_end:e} s, atol = {atol:e}"
        )
    };
    case(id, description, &spec, &[low, high], move |run| {
        let snaps = run.snapshots()?;
        let dist = |b: &[Body]| (b[1].position - b[0].position).norm();
        let n = snaps.len();
        if n < 3 {
            return Err("fewer than 3 snapshots".into());
        }
        let d0 = dist(&snaps[0].1);
        let mut checks = run_checks(run, damped);
        if damped {
            let (d_half, d_end) = (dist(&snaps[n / 2].1), dist(&snaps[n - 1].1));
            let drift = (d_end - d_half).abs();
            let (dv, sep) = pair_state(&snaps[n - 1].1, 0, 1);
            checks.push((
                false,
                drift < 1e-3,
                format!("separation drift over the second half {drift:.1e} m < 1 mm (centres {d_end:.3} m apart)"),
            ));
            checks.push((
                false,
                dv < 1e-6 && sep < 1.0,
                format!("at rest in contact: relative speed {dv:.1e} m/s < 1e-6, separation ratio {sep:.4} < 1"),
            ));
        } else {
            let d_max = snaps.iter().map(|(_, b)| dist(b)).fold(0.0, f64::max);
            let d_min = snaps.iter().map(|(_, b)| dist(b)).fold(f64::INFINITY, f64::min);
            let over = d_max - d0;
            checks.push((
                false,
                over <= 1e-3,
                format!(
                    "no drift: separation never above the release point by more than 1 mm (max excess {over:.1e} m; range {d_min:.2}-{d_max:.2} m)"
                ),
            ));
        }
        if crawl_demo {
            let profile = wall_profile(run).unwrap_or_default();
            let rate = |from: f64, to: f64| {
                let pick = |t: f64| profile.iter().find(|(pt, _)| *pt >= t).map(|p| p.1);
                match (pick(from), pick(to)) {
                    (Some(a), Some(b)) => (b - a) / (to - from),
                    _ => f64::NAN,
                }
            };
            let (early, late) = (rate(0.0, 0.5 * t_end), rate(0.9 * t_end, t_end));
            checks.push((
                false,
                late <= 10.0 * early,
                format!(
                    "no crawl at rest: wall time per simulated second {late:.1e} over the last 10% <= 10 x {early:.1e} over the first half"
                ),
            ));
        }
        checks.push(quaternion_check(run));
        checks.push(no_overrun_check(run));
        Ok(judge(&checks))
    })
}
