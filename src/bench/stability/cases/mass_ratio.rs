//! Stability regime (c) mass ratio 1e-6: a tiny body orbiting and resting on a large one.

use super::*;

const BIG_R: f64 = 1000.0;
const TINY_R: f64 = 10.0;

/// Case (c1): a 10 m sphere on a circular orbit of radius 3 km around a 1 km sphere (mass ratio 1e-6),
/// gravity + contact, three orbits; compared with the Kepler circle.
pub fn tiny_orbit(id: &str) -> Case {
    let big = rock([BIG_R; 3], [0.0; 3], [0.0; 3], Vec4::w(), [0.0; 3]);
    let tiny = rock([TINY_R; 3], [3000.0, 0.0, 0.0], [0.0; 3], Vec4::w(), [0.0; 3]);
    let (m, mt) = (big.shape.mass, tiny.shape.mass);
    let r = 3000.0;
    let v_rel = (G_SI * (m + mt) / r).sqrt();
    let omega = v_rel / r;
    let period = TAU / omega;
    let bodies = [
        Body {
            velocity: Vec3::new(0.0, -v_rel * mt / (m + mt), 0.0),
            ..big
        },
        Body {
            velocity: Vec3::new(0.0, v_rel * m / (m + mt), 0.0),
            ..tiny
        },
    ];
    let spec = SceneSpec::calibrated(3.0 * period, 1.0, None, 30, 30);
    let description = format!(
        "mass ratio {:.1e}: 10 m sphere on a circular orbit (r = 3 km, period {period:.0} s) around a 1 km sphere, 3 orbits",
        mt / m
    );
    case(id, description, &spec, &bodies, move |run| {
        let snaps = run.snapshots()?;
        let (mut dr, mut dphi) = (0.0_f64, 0.0_f64);
        for (t, b) in &snaps {
            let rel = b[1].position - b[0].position;
            dr = dr.max((rel.norm() / r - 1.0).abs());
            let phase = (omega * t).rem_euclid(TAU);
            let got = rel.y.atan2(rel.x).rem_euclid(TAU);
            let mut d = (got - phase).abs();
            d = d.min(TAU - d);
            dphi = dphi.max(d);
        }
        let mut checks = run_checks(run, false);
        checks.push((false, dr <= 1e-7, format!("radius drift {dr:.1e} <= 1e-7")));
        checks.push((
            false,
            dphi <= 1e-6,
            format!("phase error vs Kepler {dphi:.1e} rad <= 1e-6 after 3 orbits"),
        ));
        checks.push((
            true,
            dr <= 1e-3 && dphi <= 1e-3,
            "radius and phase within 1e-3 (fail bound)".into(),
        ));
        Ok(judge(&checks))
    })
}

/// Case (c2): the 10 m sphere dropped from 10 m above the 1 km sphere's surface (mass ratio 1e-6), with
/// dissipation F0 = 0.1 s m⁻², left to settle at the contact minimum `R + r` (exact for spheres, Roig03 Eq. 11).
pub fn tiny_resting(id: &str) -> Case {
    let big = rock([BIG_R; 3], [0.0; 3], [0.0; 3], Vec4::w(), [0.0; 3]);
    let tiny = rock(
        [TINY_R; 3],
        [0.0, 0.0, BIG_R + TINY_R + 10.0],
        [0.0; 3],
        Vec4::w(),
        [0.0; 3],
    );
    let ratio = tiny.shape.mass / big.shape.mass;
    let t_end = 20_000.0;
    let spec = SceneSpec::calibrated(t_end, 1.0, Some(0.1), 40, 20);
    let description = format!(
        "mass ratio {ratio:.1e}: 10 m sphere dropped from 10 m onto a 1 km sphere (gravity, contact, F0 = 0.1 s/m^2), settling for {t_end} s"
    );
    case(id, description, &spec, &[big, tiny], |run| {
        let snaps = run.snapshots()?;
        let dist = |b: &[Body]| (b[1].position - b[0].position).norm();
        let (_, last) = snaps.last().ok_or("no snapshot")?;
        let half = &snaps[snaps.len() / 2].1;
        let d_end = dist(last);
        let rel = (last[1].velocity - last[0].velocity).norm();
        let off = d_end / (BIG_R + TINY_R) - 1.0;
        let drift = (d_end - dist(half)).abs();
        let mut checks = run_checks(run, true);
        checks.push((
            false,
            off.abs() < 1e-3,
            format!("rests at R + r: distance/(R + r) - 1 = {off:.1e} (|.| < 1e-3)"),
        ));
        checks.push((false, rel < 1e-5, format!("relative speed {rel:.1e} m/s < 1e-5")));
        checks.push((
            false,
            drift < 1e-3,
            format!("distance drift over the second half {drift:.1e} m < 1 mm"),
        ));
        checks.push((true, off.abs() < 0.05, "within 5% of R + r (fail bound)".into()));
        Ok(judge(&checks))
    })
}
