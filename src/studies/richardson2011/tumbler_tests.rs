//! Centrifuging measures of the tumbler analysis (Richardson11 §3.2, [`super::tumbler`]) on synthetic
//! states whose answers are known exactly: a ring turning rigidly with the drum, a pile at rest, a half-full bed in
//! solid-body rotation, rings slipping by known amounts; the circular-segment fill and the threshold `R / r_in`
//! against their closed forms; and a synthetic run directory for the per-window means.

use super::tumbler::{
    Centrifuging, DrumParticle, analyse_tumbler_run, centrifuging, centrifuging_threshold, co_rotates,
    disc_fraction_below, initial_fill, mean_centrifuging, repose_fit,
};
use crate::test_dirs::temp_dir;
use rubblepile::math::Vec3;
use std::fmt::Write as _;

const OMEGA: f64 = 20.0;
const R_DRUM: f64 = 0.03;
const R_PART: f64 = 1e-3;

/// A particle at `(x, z)` (m) turning about `+y` at `spin` (rad/s).
fn turning(x: f64, z: f64, spin: f64) -> DrumParticle {
    DrumParticle {
        position: Vec3::new(x, 0.0, z),
        velocity: Vec3::new(spin * z, 0.0, -spin * x),
    }
}

/// `n` particles evenly round a ring of radius `rho`, half a spacing off the axis plane, turning at `spin`.
fn ring(n: usize, rho: f64, spin: f64) -> Vec<DrumParticle> {
    (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * (k as f64 + 0.5) / n as f64;
            turning(rho * a.cos(), rho * a.sin(), spin)
        })
        .collect()
}

/// A square grid (spacing 2r) of particles below the axis inside radius `R − 3r`, turning at `spin`.
fn half_bed(spin: f64) -> Vec<DrumParticle> {
    let inner = R_DRUM - 3.0 * R_PART;
    let mut bed = Vec::new();
    for i in -14..=14 {
        for k in -14..=-1 {
            let (x, z) = (2.0 * R_PART * i as f64, 2.0 * R_PART * k as f64 + R_PART);
            if x.hypot(z) < inner {
                bed.push(turning(x, z, spin));
            }
        }
    }
    bed
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

#[test]
fn a_ring_turning_with_the_drum_is_fully_centrifuged_and_a_resting_pile_not_at_all() {
    let c = centrifuging(&ring(40, 0.027, OMEGA), OMEGA);
    assert_eq!(c.co_rotating, 1.0, "{c:?}");
    assert!(close(c.spin_ratio, 1.0, 1e-12), "{c:?}");
    assert_eq!(c.above_axis, 0.5, "{c:?}");
    let c = centrifuging(&half_bed(0.0), OMEGA);
    assert_eq!(
        c,
        Centrifuging {
            co_rotating: 0.0,
            spin_ratio: 0.0,
            above_axis: 0.0
        }
    );
}

#[test]
fn a_half_full_bed_in_solid_body_rotation_co_rotates_but_stays_below_the_axis() {
    // Why the above-axis fraction is reported beside the co-rotating one: a bed carried rigidly in the bottom of the
    // drum moves with the wall everywhere, yet nothing is carried over the top.
    let c = centrifuging(&half_bed(OMEGA), OMEGA);
    assert_eq!(c.co_rotating, 1.0, "{c:?}");
    assert!(close(c.spin_ratio, 1.0, 1e-12), "{c:?}");
    assert_eq!(c.above_axis, 0.0, "{c:?}");
}

#[test]
fn slipping_rings_give_their_spin_ratio_and_co_rotate_only_within_ten_percent() {
    for (spin, co) in [(0.5, 0.0), (0.95, 1.0), (1.05, 1.0), (1.2, 0.0), (-1.0, 0.0)] {
        let c = centrifuging(&ring(36, 0.025, spin * OMEGA), OMEGA);
        assert!(close(c.spin_ratio, spin, 1e-12), "spin {spin}: {c:?}");
        assert_eq!(c.co_rotating, co, "spin {spin}: {c:?}");
    }
    // The tolerance is on the whole velocity difference: a radial or axial slip counts too.
    let rho = 0.02;
    let mut p = turning(0.0, -rho, OMEGA);
    p.velocity.z += 0.09 * OMEGA * rho;
    assert!(co_rotates(&p, OMEGA));
    p.velocity.z += 0.02 * OMEGA * rho;
    assert!(!co_rotates(&p, OMEGA));
    p = turning(0.0, -rho, OMEGA);
    p.velocity.y = 0.11 * OMEGA * rho;
    assert!(!co_rotates(&p, OMEGA));
    // Nothing co-rotates with a drum at rest, nor on the axis.
    assert!(!co_rotates(&turning(0.0, -rho, 0.0), 0.0));
    assert!(!co_rotates(&turning(0.0, 0.0, OMEGA), OMEGA));
}

#[test]
fn segment_fill_and_threshold_match_their_closed_forms() {
    let a = 0.028;
    assert!(close(disc_fraction_below(0.0, a), 0.5, 1e-15));
    assert!(close(disc_fraction_below(a, a), 1.0, 1e-15));
    assert!(close(disc_fraction_below(-2.0 * a, a), 0.0, 1e-15));
    // Midpoint sum of chord widths 2 √(a² − z²) below z = 0.3 a.
    let (h, n) = (0.3 * a, 200_000);
    let dz = (h + a) / n as f64;
    let area: f64 = (0..n)
        .map(|k| {
            let z = -a + (k as f64 + 0.5) * dz;
            2.0 * (a * a - z * z).sqrt() * dz
        })
        .sum();
    let f = disc_fraction_below(h, a);
    assert!(close(f, area / (std::f64::consts::PI * a * a), 1e-7), "{f}");
    // Half full with point particles: r_in = R / √2; a quarter: R / √(3/4).
    assert!(close(centrifuging_threshold(0.5, R_DRUM, 0.0), 2f64.sqrt(), 1e-12));
    assert!(close(
        centrifuging_threshold(0.25, R_DRUM, 0.0),
        (4.0f64 / 3.0).sqrt(),
        1e-12
    ));
    // With the lining's thickness 2r taken off the radius.
    assert!(close(
        centrifuging_threshold(0.0, R_DRUM, R_PART),
        R_DRUM / (R_DRUM - 2.0 * R_PART),
        1e-12
    ));
    // A bed whose highest particle tops out at the axis fills half the disc inside the lining.
    let bed = half_bed(0.0);
    assert!(close(initial_fill(&bed, R_DRUM, R_PART), 0.5, 1e-12));
}

#[test]
fn mean_centrifuging_averages_each_field() {
    let a = Centrifuging {
        co_rotating: 0.0,
        spin_ratio: 0.2,
        above_axis: 0.1,
    };
    let b = Centrifuging {
        co_rotating: 1.0,
        spin_ratio: 1.0,
        above_axis: 0.5,
    };
    let m = mean_centrifuging(&[a, b]);
    assert!(close(m.co_rotating, 0.5, 1e-15) && close(m.spin_ratio, 0.6, 1e-15) && close(m.above_axis, 0.3, 1e-15));
    assert!(mean_centrifuging(&[]).co_rotating.is_nan());
}

/// Writes a snapshot of `particles` (free) plus one stuck lining particle at time `t`.
fn snapshot(path: &std::path::Path, t: f64, particles: &[DrumParticle]) {
    let mut s = String::from("t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz,stuck_to\n");
    let _ = writeln!(
        s,
        "{t},0,1e-5,{R_PART},0,0,{},{},0,0,0,0,0,0",
        -(R_DRUM - R_PART),
        OMEGA * -(R_DRUM - R_PART)
    );
    for (k, p) in particles.iter().enumerate() {
        let (x, v) = (p.position, p.velocity);
        let _ = writeln!(
            s,
            "{t},{},1e-5,{R_PART},{},{},{},{},{},{},0,0,0,-1",
            k + 1,
            x.x,
            x.y,
            x.z,
            v.x,
            v.y,
            v.z
        );
    }
    std::fs::write(path, s).unwrap();
}

#[test]
fn a_run_is_averaged_over_its_second_half_and_each_quarter_of_it() {
    // Snapshots at 0, 0.5, 1, 1.5, 2 s of a 2 s run: at rest until 1 s, then a ring turning with the drum. The
    // windows are 50–75 % = {1 s} and 75–100 % = {1.5 s, 2 s}; the second half holds all three.
    let dir = temp_dir("tumbler");
    std::fs::write(
        dir.join("scene.toml"),
        format!(
            "[gravity]\nuniform = [0.0, 0.0, -9.81]\n[[wall]]\nkind = \"cylinder\"\nradius = {R_DRUM:?}\nspin = {OMEGA:?}\n"
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("summary.json"),
        r#"{"status": "completed", "t_reached": 2.0, "events_per_second": 1.0, "wall_seconds": 1.0, "collisions": 3}"#,
    )
    .unwrap();
    std::fs::create_dir_all(dir.join("snapshots")).unwrap();
    for (k, t) in [0.0, 0.5, 1.0, 1.5, 2.0].into_iter().enumerate() {
        let state = if t < 1.5 { half_bed(0.0) } else { ring(40, 0.027, OMEGA) };
        snapshot(&dir.join(format!("snapshots/{k}.csv")), t, &state);
    }
    let run = analyse_tumbler_run(&dir).unwrap();
    assert_eq!(run.centrifuging.len(), 5);
    assert_eq!(run.late_halves[0].co_rotating, 0.0);
    assert_eq!(run.late_halves[1].co_rotating, 1.0);
    assert!(close(run.late.co_rotating, 2.0 / 3.0, 1e-12), "{:?}", run.late);
    assert!(close(run.late.above_axis, 1.0 / 3.0, 1e-12), "{:?}", run.late);
    assert!(close(run.froude, OMEGA * OMEGA * R_DRUM / 9.81, 1e-12));
    assert!(close(run.fill, 0.5, 1e-12), "fill {}", run.fill);
    assert!(close(
        run.threshold,
        R_DRUM / ((R_DRUM - 2.0 * R_PART) * 0.5f64.sqrt()),
        1e-12
    ));
    assert_eq!((run.free, run.stuck), (ring(40, 0.027, OMEGA).len(), 1));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_fit_error_of_an_angle_is_the_slope_standard_error_carried_through_atan() {
    // (0, 0), (1, 1), (2, 0): slope 0, residuals −1/3, 2/3, −1/3, s² = rss / (N − 2) = 2/3, Sxx = 2, so
    // σ_slope = √(1/3) and, at slope 0, σ_θ = σ_slope rad.
    let (a, e) = repose_fit(&[(0.0, 0.0), (1.0, 1.0), (2.0, 0.0)], -1.0, 3.0).unwrap();
    assert!(a.abs() < 1e-12, "angle {a}");
    assert!((e - (1.0f64 / 3.0).sqrt().to_degrees()).abs() < 1e-9, "error {e}");
    // The same residuals about the line z = −x: 45°, and σ_θ = σ_slope / (1 + 1).
    let (a, e) = repose_fit(&[(0.0, 0.0), (1.0, 0.0), (2.0, -2.0)], -1.0, 3.0).unwrap();
    assert!((a - 45.0).abs() < 1e-9, "angle {a}");
    assert!((e - (1.0f64 / 3.0).sqrt().to_degrees() / 2.0).abs() < 1e-9, "error {e}");
    // Points on an exact line have no fit error; fewer than three points give no fit.
    let (a, e) = repose_fit(&[(-3.0, 3.0), (-2.0, 2.0), (-1.0, 1.0)], -4.0, 0.0).unwrap();
    assert!((a - 45.0).abs() < 1e-9 && e.abs() < 1e-9, "{a} {e}");
    assert!(repose_fit(&[(0.0, 0.0), (1.0, 1.0)], -1.0, 3.0).is_none());
}
