//! The rotation state of `src/ellipsoid/spin_state.rs` against analytic answers: the symmetric tops' precession
//! periods (`2π I₁/L` oblate, `2π I₃/L` prolate) and body periods, an asymmetric tumbler's body period against
//! Euler's equations integrated step by step, principal-axis rotation, and `--settle-to-principal`'s rotation
//! about the largest moment keeping `|L|`.

use rubblepile::ellipsoid::rigid_rotation::fit_rigid_rotation;
use rubblepile::ellipsoid::spin_state::{free_rotation, spin_state};
use rubblepile::impact::settle::set_principal_axis_rotation;
use rubblepile::math::{Mat3, Vec3};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

#[test]
fn symmetric_oblate_top_precesses_at_l_over_i1() {
    let (i1, i3) = (1.0, 2.0);
    let inertia = Mat3::from_diagonal(&Vec3::new(i1, i1, i3));
    let omega = Vec3::new(0.3, 0.0, 1.0);
    let l = inertia * omega;
    let s = spin_state(&inertia, &l);
    assert_eq!(s.mode, "short-axis mode");
    let p_phi = s.precession_period_hours.unwrap() * 3600.0;
    let exact = TWO_PI * i1 / l.norm();
    assert!((p_phi - exact).abs() < 1e-12 * exact, "P_phi {p_phi} vs {exact}");
    // The body-frame rotation of ω about the symmetry axis: rate (I₃ − I₁) ω₃ / I₁.
    let p_psi = s.rotation_period_hours.unwrap() * 3600.0;
    let exact_psi = TWO_PI * i1 / ((i3 - i1) * omega.z);
    assert!(
        (p_psi - exact_psi).abs() < 1e-12 * exact_psi,
        "P_psi {p_psi} vs {exact_psi}"
    );
    // |ω| is constant for a symmetric top.
    let [lo, hi] = s.spin_period_range_hours.unwrap();
    assert!((hi - lo).abs() < 1e-12 * hi);
    assert!((lo * 3600.0 - TWO_PI / omega.norm()).abs() < 1e-12 * lo * 3600.0);
    // L and ω apart: tan⁻¹(0.3) = 16.7° from the axis for ω, tan⁻¹(0.15) = 8.53° for L.
    assert!((s.angle_l_omega_deg - (0.3f64.atan() - 0.15f64.atan()).to_degrees()).abs() < 1e-9);
}

#[test]
fn symmetric_prolate_top_is_a_long_axis_mode_precessing_at_l_over_i3() {
    let (i1, i3) = (1.0, 3.0);
    let inertia = Mat3::from_diagonal(&Vec3::new(i1, i3, i3));
    let l = inertia * Vec3::new(1.0, 0.2, 0.1);
    let s = spin_state(&inertia, &l);
    assert_eq!(s.mode, "long-axis mode");
    let p_phi = s.precession_period_hours.unwrap() * 3600.0;
    let exact = TWO_PI * i3 / l.norm();
    assert!((p_phi - exact).abs() < 1e-12 * exact, "P_phi {p_phi} vs {exact}");
}

/// Euler's equations `I ω̇ = (I ω) × ω` in the body frame, by RK4 with `steps` steps over `t`.
fn euler(moments: Vec3, omega: Vec3, t: f64, steps: usize) -> (Vec3, f64, f64) {
    let f = |w: &Vec3| moments.component_mul(w).cross(w).component_div(&moments);
    let h = t / steps as f64;
    let (mut w, mut lo, mut hi) = (omega, omega.norm(), omega.norm());
    for _ in 0..steps {
        let k1 = f(&w);
        let k2 = f(&(w + 0.5 * h * k1));
        let k3 = f(&(w + 0.5 * h * k2));
        let k4 = f(&(w + h * k3));
        w += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        lo = lo.min(w.norm());
        hi = hi.max(w.norm());
    }
    (w, lo, hi)
}

#[test]
fn asymmetric_tumbler_returns_after_its_body_period_in_both_modes() {
    let moments = Vec3::new(1.0, 1.6, 2.1);
    let inertia = Mat3::from_diagonal(&moments);
    for (omega, mode) in [
        (Vec3::new(0.2, 0.1, 1.0), "short-axis mode"),
        (Vec3::new(1.0, 0.25, 0.2), "long-axis mode"),
    ] {
        let s = spin_state(&inertia, &(inertia * omega));
        assert_eq!(s.mode, mode);
        let p = s.rotation_period_hours.unwrap() * 3600.0;
        let (w, lo, hi) = euler(moments, omega, p, 200_000);
        assert!(
            (w - omega).norm() < 1e-9 * omega.norm(),
            "{mode}: ω after P_psi {w} vs {omega}"
        );
        // Half a period on, ω is elsewhere: P_psi is the period, not a multiple of it.
        let (half, _, _) = euler(moments, omega, 0.5 * p, 100_000);
        assert!(
            (half - omega).norm() > 1e-2 * omega.norm(),
            "{mode}: back after half a period"
        );
        let [p_lo, p_hi] = s.spin_period_range_hours.unwrap().map(|h| h * 3600.0);
        assert!(
            (p_lo - TWO_PI / hi).abs() < 1e-5 * p_lo,
            "{mode}: {p_lo} vs {}",
            TWO_PI / hi
        );
        assert!(
            (p_hi - TWO_PI / lo).abs() < 1e-5 * p_hi,
            "{mode}: {p_hi} vs {}",
            TWO_PI / lo
        );
        // D = L²/2E sits on the mode's side of I₂.
        assert_eq!(s.l2_over_2e > moments.y, mode == "short-axis mode");
    }
    // Rotation about a principal axis is no tumble.
    let s = spin_state(&inertia, &(inertia * Vec3::new(0.0, 0.0, 0.7)));
    assert_eq!(s.mode, "principal-axis");
    assert!(s.precession_period_hours.is_none());
    assert!((s.spin_period_hours * 3600.0 - TWO_PI / 0.7).abs() < 1e-12);
    assert!((s.invariant_period_hours - s.spin_period_hours).abs() < 1e-12 * s.spin_period_hours);
    // Outside (I₁, I₃) there is no tumble to describe.
    assert!(free_rotation([1.0, 1.6, 2.1], 1.0, 0.1).is_none());
}

#[test]
fn settle_to_principal_spins_the_pile_about_its_largest_moment_with_the_same_l() {
    let target = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("targets/N30_T4.csv");
    let mut bodies = rubblepile::impact::run::read_target(&target).unwrap();
    let moments: Vec<Vec3> = bodies.iter().map(|b| b.shape.principal_moments(2.5)).collect();
    // Tilt the pile's spin off its axes first, so that it tumbles.
    for b in &mut bodies {
        b.velocity += Vec3::new(3e-4, -2e-4, 1e-4).cross(&b.position);
    }
    let before = fit_rigid_rotation(&bodies, &moments);
    assert_ne!(
        spin_state(&before.inertia, &before.angular_momentum).mode,
        "principal-axis"
    );
    set_principal_axis_rotation(&mut bodies, &moments);
    let after = fit_rigid_rotation(&bodies, &moments);
    let s = spin_state(&after.inertia, &after.angular_momentum);
    assert_eq!(s.mode, "principal-axis");
    assert!(
        s.angle_l_omega_deg < 1e-6 && s.angle_omega_largest_axis_deg < 1e-6,
        "{s:?}"
    );
    let (l0, l1) = (before.angular_momentum.norm(), after.angular_momentum.norm());
    assert!((l1 - l0).abs() < 1e-12 * l0, "|L| {l0} -> {l1}");
    assert!(after.non_rigid_fraction() < 1e-20);
}
