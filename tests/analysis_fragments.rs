//! Known answers for the post-impact fragment analysis (Roig03 §4).

use rubblepile::analysis::fragments::{
    FragmentError, FragmentParams, RotationMode, analyse_fragments, binding_energies, effective_inertia,
    ejection_velocities, escape_velocity, read_snapshot_bodies, rotation_mode, rotation_mode_measure, spin_correction,
};
use rubblepile::ellipsoid::body::{Body, Ellipsoid, InertiaModel};
use rubblepile::ellipsoid::output::write_snapshot;
use rubblepile::math::{Vec3, Vec4};

fn body(mass: f64, axes: [f64; 3], position: [f64; 3], velocity: [f64; 3], spin: [f64; 3]) -> Body {
    Body {
        shape: Ellipsoid {
            axes: Vec3::from(axes),
            mass,
        },
        position: Vec3::from(position),
        velocity: Vec3::from(velocity),
        quaternion: Vec4::new(0.0, 0.0, 0.0, 1.0),
        spin_body: Vec3::from(spin),
    }
}

fn sphere(mass: f64, position: [f64; 3], velocity: [f64; 3]) -> Body {
    body(mass, [1.0, 1.0, 1.0], position, velocity, [0.0; 3])
}

fn params(projectile: usize) -> FragmentParams {
    FragmentParams {
        kappa: 2.5,
        inertia: InertiaModel::Gaussian,
        g: 1.0,
        projectile,
        projectile_count: 1,
    }
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

/// Triaxial body with axes (3, 2, 1), m = 1, κ = 5/2: I = (1, 2, 2.6).
fn triaxial_moments() -> Vec3 {
    let e = Ellipsoid {
        axes: Vec3::new(3.0, 2.0, 1.0),
        mass: 1.0,
    };
    let m = e.principal_moments(2.5);
    assert!(close(m.x, 1.0, 1e-15) && close(m.y, 2.0, 1e-15) && close(m.z, 2.6, 1e-15));
    m
}

#[test]
fn pure_axis_rotations_give_principal_moments_and_unit_measures() {
    let m = triaxial_moments();
    for (omega, i_expected, s_expected, mode) in [
        (Vec3::new(0.0, 0.0, 0.7), m.z, 1.0, RotationMode::Sam),
        (Vec3::new(-0.3, 0.0, 0.0), m.x, -1.0, RotationMode::Lam),
        (Vec3::new(0.0, 2.0, 0.0), m.y, 0.0, RotationMode::Intermediate),
    ] {
        let i_eff = effective_inertia(&m, &omega).unwrap();
        assert!(
            close(i_eff, i_expected, 1e-14),
            "{omega:?}: I_eff {i_eff} vs {i_expected}"
        );
        let s = rotation_mode_measure(&m, i_eff);
        assert!((s - s_expected).abs() < 1e-12, "{omega:?}: measure {s}");
        assert_eq!(rotation_mode(Some(s)), mode);
    }
    assert_eq!(effective_inertia(&m, &Vec3::zeros()), None);
    assert_eq!(rotation_mode(None), RotationMode::None);
}

#[test]
fn mixed_rotations_fall_strictly_between() {
    let m = triaxial_moments();
    // ω = (0, 1, 1): I_eff = (2² + 2.6²)/(2 + 2.6) = 10.76/4.6 > I₂ → (I_eff − 2)/(2.6 − 2).
    let i_eff = effective_inertia(&m, &Vec3::new(0.0, 1.0, 1.0)).unwrap();
    assert!(close(i_eff, 10.76 / 4.6, 1e-14));
    let s = rotation_mode_measure(&m, i_eff);
    assert!(close(s, (10.76 / 4.6 - 2.0) / 0.6, 1e-12) && s > 0.0 && s < 1.0, "{s}");
    assert_eq!(rotation_mode(Some(s)), RotationMode::Sam);
    // ω = (1, 1, 0): I_eff = (1 + 4)/(1 + 2) = 5/3 < I₂ → (5/3 − 2)/(2 − 1) = −1/3.
    let i_eff = effective_inertia(&m, &Vec3::new(1.0, 1.0, 0.0)).unwrap();
    let s = rotation_mode_measure(&m, i_eff);
    assert!(close(s, -1.0 / 3.0, 1e-12), "{s}");
    assert_eq!(rotation_mode(Some(s)), RotationMode::Lam);
    // All three axes: strictly inside (−1, 1).
    for omega in [Vec3::new(1.0, 0.2, 0.3), Vec3::new(0.1, 0.2, 1.0)] {
        let s = rotation_mode_measure(&m, effective_inertia(&m, &omega).unwrap());
        assert!(s > -1.0 && s < 1.0 && s != 0.0, "{s}");
    }
    // Independent of the order the moments are given in.
    let shuffled = Vec3::new(m.z, m.x, m.y);
    assert_eq!(
        rotation_mode_measure(&shuffled, 10.76 / 4.6),
        rotation_mode_measure(&m, 10.76 / 4.6)
    );
}

#[test]
fn analysis_reports_tumbling_and_corrected_spins() {
    let at = vec![
        body(1.0, [3.0, 2.0, 1.0], [0.0; 3], [0.0; 3], [0.0, 0.0, 1e-3]),
        body(1.0, [3.0, 2.0, 1.0], [10.0, 0.0, 0.0], [0.0; 3], [1e-3, 0.0, 0.0]),
        body(1.0, [3.0, 2.0, 1.0], [0.0, 10.0, 0.0], [0.0; 3], [0.0; 3]),
    ];
    let initial: Vec<Body> = at
        .iter()
        .map(|b| Body {
            spin_body: Vec3::zeros(),
            ..b.clone()
        })
        .collect();
    let mut p = params(2);
    p.kappa = 10.0;
    let r = analyse_fragments(&initial, &at, &p).unwrap();
    let f = &r.fragments;
    // Moments use κ = 10 (Gaussian): Eq. 4 → m/(2κ)(B²+C², …) = (5, 10, 13)/20.
    assert!(close(f[0].moments[2], 13.0 / 20.0, 1e-15));
    assert_eq!(f[0].rotation_mode, RotationMode::Sam);
    assert!(close(f[0].effective_inertia.unwrap(), 13.0 / 20.0, 1e-14));
    assert!((f[0].rotation_mode_measure.unwrap() - 1.0).abs() < 1e-12);
    assert_eq!(f[1].rotation_mode, RotationMode::Lam);
    assert!((f[1].rotation_mode_measure.unwrap() + 1.0).abs() < 1e-12);
    assert_eq!(f[2].rotation_mode, RotationMode::None);
    assert_eq!(f[2].spin_period_h, None);
    // Spin 1e-3 rad/s: P = 2π/1e-3 s; corrected with √(5/20) = 1/2 → rate halved, period doubled.
    let period_h = 2.0 * std::f64::consts::PI / 1e-3 / 3600.0;
    assert!(close(f[0].spin_period_h.unwrap(), period_h, 1e-14));
    assert!(close(f[0].spin_rate_corrected, 0.5e-3, 1e-14));
    assert!(close(f[0].spin_period_corrected_h.unwrap(), 2.0 * period_h, 1e-14));
    assert!(close(r.summary.spin_correction, 0.5, 1e-15));
    // Uniform inertia: no correction whatever κ.
    p.inertia = InertiaModel::Uniform;
    let r = analyse_fragments(&initial, &at, &p).unwrap();
    assert_eq!(r.fragments[0].spin_rate_corrected, r.fragments[0].spin_rate);
    assert!(close(r.fragments[0].moments[2], 13.0 / 5.0, 1e-15));
}

#[test]
fn spin_correction_factor() {
    assert!(close(spin_correction(InertiaModel::Gaussian, 2.5), 1.0, 1e-15));
    assert!(close(spin_correction(InertiaModel::Uniform, 10.0), 1.0, 1e-15));
    assert!(close(spin_correction(InertiaModel::Uniform, 2.5), 1.0, 1e-15));
    assert!(close(spin_correction(InertiaModel::Gaussian, 10.0), 0.5, 1e-15));
    assert!(close(
        spin_correction(InertiaModel::Gaussian, 5.0),
        0.5f64.sqrt(),
        1e-15
    ));
}

/// A (m = 1) at the origin and B (m = 1) at (1, 0, 0) bound; C (m = 0.5) at (0, 10, 0) moving along x with
/// speed u; A and B move at −u/4 so that the total momentum vanishes (system barycentre at rest).
fn three_bodies(u: f64) -> Vec<Body> {
    vec![
        sphere(1.0, [0.0, 0.0, 0.0], [-u / 4.0, 0.0, 0.0]),
        sphere(1.0, [1.0, 0.0, 0.0], [-u / 4.0, 0.0, 0.0]),
        sphere(0.5, [0.0, 10.0, 0.0], [u, 0.0, 0.0]),
    ]
}

#[test]
fn binding_energy_and_escape_by_hand() {
    let g = 1.0;
    let s101 = 101f64.sqrt();
    let u_a = 1.0 + 0.5 / 10.0;
    let u_b = 1.0 + 0.5 / s101;
    let u_c = 0.5 / 10.0 + 0.5 / s101;
    let u = binding_energies(g, &three_bodies(0.0));
    for (got, want) in u.iter().zip([u_a, u_b, u_c]) {
        assert!(close(*got, want, 1e-14), "{got} vs {want}");
    }
    // G scales linearly.
    assert!(close(binding_energies(3.0, &three_bodies(0.0))[2], 3.0 * u_c, 1e-14));

    // K_C = ½ · 0.5 · u² = u²/4. Projectile: body 0 (A); the target is B and C.
    let speed_for = |ratio: f64| (4.0 * u_c * ratio).sqrt();
    for (ratio, c_escapes, bound) in [(4.0, true, 1.0 / 1.5), (1.01, true, 1.0 / 1.5), (0.99, false, 1.0)] {
        let u = speed_for(ratio);
        let at = three_bodies(u);
        let r = analyse_fragments(&three_bodies(0.0), &at, &params(0)).unwrap();
        let f = &r.fragments;
        assert!(close(f[2].kinetic_energy, u * u / 4.0, 1e-14));
        assert!(close(f[2].kinetic_energy / f[2].binding_energy, ratio, 1e-12));
        assert!(close(f[1].binding_energy, u_b, 1e-14));
        assert_eq!(f[2].escaping, c_escapes, "ratio {ratio}");
        // A and B: K = u²/32 ≪ 1.
        assert!(!f[0].escaping && !f[1].escaping);
        assert!(f[0].is_projectile && !f[1].is_projectile);
        assert!(close(r.summary.bound_mass_fraction, bound, 1e-15), "ratio {ratio}");
        assert_eq!(r.summary.n_escaping, usize::from(c_escapes));
        assert!(close(r.summary.largest_fragment_fraction, 1.0 / 1.5, 1e-15));
    }
    // Every fragment escaping: a bound fraction of +0, which prints "0.000" (an empty sum is −0.0: "-0.000").
    let mut at = three_bodies(speed_for(4.0));
    at[1].velocity.y = -1e3;
    let r = analyse_fragments(&three_bodies(0.0), &at, &params(0)).unwrap();
    assert_eq!(r.summary.n_escaping, 2);
    assert!(r.summary.bound_mass_fraction == 0.0 && r.summary.bound_mass_fraction.is_sign_positive());
    assert_eq!(format!("{:.3}", r.summary.bound_mass_fraction), "0.000");
}

#[test]
fn rigid_translation_gives_zero_ejection() {
    let initial = vec![
        sphere(2.0, [0.0; 3], [1.0, -2.0, 0.5]),
        sphere(3.0, [5.0, 0.0, 0.0], [0.3, 0.1, -0.7]),
        sphere(5.0, [0.0, 5.0, 0.0], [-1.0, 0.4, 2.0]),
        sphere(1.0, [0.0, 0.0, 50.0], [0.0, 0.0, -100.0]),
    ];
    let shift = Vec3::new(12.0, -7.0, 3.0);
    let at: Vec<Body> = initial
        .iter()
        .map(|b| Body {
            velocity: b.velocity + shift,
            ..b.clone()
        })
        .collect();
    for dv in ejection_velocities(&initial, &at, |i| i != 3) {
        assert!(dv.norm() < 1e-12, "{dv:?}");
    }
}

#[test]
fn single_kick_minus_barycentre_shift() {
    let masses = [2.0, 3.0, 5.0];
    let m_t = 10.0;
    let initial = vec![
        sphere(masses[0], [0.0; 3], [1.0, -2.0, 0.5]),
        sphere(masses[1], [5.0, 0.0, 0.0], [0.3, 0.1, -0.7]),
        sphere(masses[2], [0.0, 5.0, 0.0], [-1.0, 0.4, 2.0]),
        sphere(1.0, [0.0, 0.0, 50.0], [0.0, 0.0, -100.0]),
    ];
    let kick = Vec3::new(4.0, -1.0, 2.0);
    let w = Vec3::new(0.0, 30.0, 60.0);
    let mut at = initial.clone();
    at[1].velocity += kick;
    at[3].velocity += w; // the projectile's change must not move the target barycentre
    let shift = kick * masses[1] / m_t;
    let dv = ejection_velocities(&initial, &at, |i| i != 3);
    let expected = [-shift, kick - shift, -shift, w - shift];
    for (got, want) in dv.iter().zip(expected) {
        assert!((got - want).norm() < 1e-12, "{got:?} vs {want:?}");
    }
    let r = analyse_fragments(&initial, &at, &params(3)).unwrap();
    assert!(close(r.fragments[1].ejection_speed, (kick - shift).norm(), 1e-14));
    assert_eq!(r.fragments[1].ejection_velocity, <[f64; 3]>::from(kick - shift));
}

#[test]
fn energy_partition_by_hand() {
    // Two unit spheres (m = 1) at rest, projectile (m = 0.5) at 10 m/s along x: K_p = ½·0.5·100 = 25.
    let initial = vec![
        sphere(1.0, [5.0, 0.0, 0.0], [0.0; 3]),
        sphere(1.0, [-5.0, 0.0, 0.0], [0.0; 3]),
        sphere(0.5, [-100.0, 0.0, 0.0], [10.0, 0.0, 0.0]),
    ];
    // After: momentum (5, 0, 0) conserved, V_sys = (2, 0, 0); the first fragment spins at 1 rad/s about z.
    let at = vec![
        body(1.0, [1.0; 3], [9.0, 1.0, 0.0], [3.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
        sphere(1.0, [-4.0, -1.0, 0.0], [1.0, -1.0, 0.0]),
        sphere(0.5, [-2.0, 0.0, 0.0], [2.0, 0.0, 0.0]),
    ];
    let r = analyse_fragments(&initial, &at, &params(2)).unwrap();
    let s = &r.summary;
    assert!(close(s.projectile_speed, 10.0, 1e-15));
    assert!(close(s.projectile_kinetic_energy, 25.0, 1e-15));
    assert!(close(s.specific_energy, 12.5, 1e-15));
    // Translational: ½|(1,1,0)|² + ½|(−1,−1,0)|² = 2; rotational: ½ · (2/5 · 1 · 1²) · 1² = 0.2.
    assert!(close(s.fragment_kinetic_translational, 2.0, 1e-14));
    assert!(close(s.fragment_kinetic_rotational, 0.2, 1e-14));
    assert!(close(s.f_ke, 2.2 / 25.0, 1e-14));
    assert!(close(s.rotational_share, 0.2 / 2.2, 1e-14));
    // At t = 0, V_sys = (2, 0, 0): each target body carries ½·1·2² = 2.
    assert!(close(s.fragment_kinetic_initial, 4.0, 1e-14));
    // Ejection: V_T goes 0 → (2, 0, 0): Δv = (1, 1, 0), (−1, −1, 0), projectile (−10, 0, 0).
    assert!(close(s.ejection_speed_median, 2f64.sqrt(), 1e-14));
    assert!(close(s.ejection_speed_mean, 2f64.sqrt(), 1e-14));
    assert!(close(s.ejection_speed_median_relative, 2f64.sqrt() / 10.0, 1e-14));
    assert_eq!(r.fragments[2].ejection_velocity, [-10.0, 0.0, 0.0]);
    // Parent body: two unit spheres → R_eff = 2^{1/3}; v_esc² = 1.64 G M / R_eff.
    assert!(close(s.target_radius, 2f64.cbrt(), 1e-14));
    assert!(close(r.fragments[0].size, 1.0 / 2f64.cbrt(), 1e-14));
    assert!(close(s.escape_velocity, (1.64 * 2.0 / 2f64.cbrt()).sqrt(), 1e-14));
    assert!(close(
        escape_velocity(6.674e-11, 1e19, 1e5),
        (1.64f64 * 6.674e-11 * 1e19 / 1e5).sqrt(),
        1e-15
    ));
    assert_eq!(s.n_fragments, 2);
    // A spinning sphere has I₁ = I₂ = I₃: the measure is 0 (intermediate); a non-spinning one has no mode.
    let json = serde_json::to_string(&r).unwrap();
    assert!(json.contains("\"rotation_mode\":\"intermediate\"") && json.contains("\"rotation_mode\":\"none\""));
}

#[test]
fn median_of_odd_and_even_counts() {
    let initial: Vec<Body> = (0..5)
        .map(|i| sphere(1.0, [10.0 * i as f64, 0.0, 0.0], [0.0; 3]))
        .collect();
    // Odd: targets 0, 1, 2 (projectile 3); V_T(t) = (0, 1, 0) → Δv = (1, −1, 0), (−1, −1, 0), (0, 2, 0).
    let mut at = initial.clone();
    at[0].velocity = Vec3::new(1.0, 0.0, 0.0);
    at[1].velocity = Vec3::new(-1.0, 0.0, 0.0);
    at[2].velocity = Vec3::new(0.0, 3.0, 0.0);
    at[3].velocity = Vec3::new(0.0, -3.0, 5.0);
    let r = analyse_fragments(&initial[..4], &at[..4], &params(3)).unwrap();
    assert!(close(r.summary.ejection_speed_median, 2f64.sqrt(), 1e-14));
    assert!(close(
        r.summary.ejection_speed_mean,
        (2.0 * 2f64.sqrt() + 2.0) / 3.0,
        1e-14
    ));
    // Even: targets 0–3 with zero net momentum (V_T = 0), projectile 4 at rest: speeds 1, 2, 4, √21.
    let mut at = initial.clone();
    at[0].velocity = Vec3::new(1.0, 0.0, 0.0);
    at[1].velocity = Vec3::new(0.0, 2.0, 0.0);
    at[2].velocity = Vec3::new(0.0, 0.0, 4.0);
    at[3].velocity = Vec3::new(-1.0, -2.0, -4.0);
    let r = analyse_fragments(&initial, &at, &params(4)).unwrap();
    assert!(close(r.summary.ejection_speed_median, 3.0, 1e-14));
    assert!(close(r.summary.ejection_speed_mean, (7.0 + 21f64.sqrt()) / 4.0, 1e-14));
}

#[test]
fn bad_inputs_are_refused() {
    let b = three_bodies(1.0);
    assert_eq!(
        analyse_fragments(&b, &b[..2], &params(0)),
        Err(FragmentError::CountMismatch { initial: 3, at: 2 })
    );
    assert_eq!(
        analyse_fragments(&b, &b, &params(3)),
        Err(FragmentError::Projectile { index: 3, count: 3 })
    );
    assert!(matches!(
        analyse_fragments(&b[..1], &b[..1], &params(0)),
        Err(FragmentError::Projectile { .. })
    ));
    let mut p = params(0);
    p.g = 0.0;
    assert!(matches!(
        analyse_fragments(&b, &b, &p),
        Err(FragmentError::Parameters { .. })
    ));
}

#[test]
fn snapshot_csv_round_trip() {
    let dir = std::env::temp_dir().join(format!("rubblepile-fragments-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("snap.csv");
    let bodies = vec![
        body(
            2.0,
            [3.0, 2.0, 1.0],
            [1.0, 2.0, 3.0],
            [0.1, 0.2, 0.3],
            [1e-3, 0.0, 2e-3],
        ),
        sphere(1.0, [-4.0, 0.0, 0.0], [0.0, 5.0, 0.0]),
    ];
    write_snapshot(&path, 400.0, &bodies).unwrap();
    let back = read_snapshot_bodies(&path).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(back.len(), 2);
    for (a, b) in back.iter().zip(&bodies) {
        assert!((a.position - b.position).norm() < 1e-12 && (a.velocity - b.velocity).norm() < 1e-12);
        assert!((a.spin_body - b.spin_body).norm() < 1e-15 && a.shape.mass == b.shape.mass);
    }
}

/// §4.2 "small fragments from the impact point, large ones from the antipode": a hand-made target whose two
/// small fragments sit on the impact side (+z, toward the projectile) and two large ones at the antipode.
#[test]
fn ejection_sites_separate_impact_side_from_antipode() {
    let small = |z: f64, x: f64| body(1.0, [1.0, 1.0, 1.0], [x, 0.0, z], [0.0; 3], [0.0; 3]);
    let large = |z: f64, x: f64| body(27.0, [3.0, 3.0, 3.0], [x, 0.0, z], [0.0; 3], [0.0; 3]);
    let initial = vec![
        body(64.0, [4.0, 4.0, 4.0], [0.0, 0.0, 0.0], [0.0; 3], [0.0; 3]), // slow core
        small(10.0, 1.0),
        small(10.0, -1.0),
        large(-10.0, 1.0),
        large(-10.0, -1.0),
        sphere(0.1, [0.0, 0.0, 100.0], [0.0, 0.0, -50.0]), // projectile along −z, from +z
    ];
    let mut at = initial.clone();
    for (i, v) in [(1, 8.0), (2, 9.0), (3, -5.0), (4, -6.0)] {
        at[i].velocity = Vec3::new(0.0, 0.0, v);
    }
    let r = analyse_fragments(&initial, &at, &params(5)).unwrap();
    // positions relative to the target barycentre (z_c = (20 − 540)/120 = −13/3): cosines by hand
    let zc = (2.0 * 10.0 - 2.0 * 27.0 * 10.0) / 120.0;
    let cos = |x: f64, z: f64| (z - zc) / (x * x + (z - zc) * (z - zc)).sqrt();
    assert!(close(r.fragments[1].impact_site_cosine, cos(1.0, 10.0), 1e-12));
    assert!(close(r.fragments[3].impact_site_cosine, cos(1.0, -10.0), 1e-12));
    assert_eq!(r.fragments[5].impact_site_cosine, 0.0, "projectile");
    let s = &r.summary.ejection_sites;
    // the target barycentre recoils by −280/120 m/s along z, so |Δv| = 2.33, 10.33, 11.33, 2.67, 3.67 m/s:
    // the median is 3.67 and the fast ones are fragments 1, 2 (impact side) and 4 (antipode)
    assert_eq!((s.fast_fragments, s.impact_side, s.antipodal_side), (3, 2, 1), "{s:?}");
    let size = |i: usize| r.fragments[i].size;
    assert!(close(s.impact_side_median_size.unwrap(), size(1), 1e-12));
    assert!(close(s.antipodal_side_median_size.unwrap(), size(4), 1e-12));
    assert!(s.size_cosine_correlation.unwrap() < -0.9, "{s:?}");
}
