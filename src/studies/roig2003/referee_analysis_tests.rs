//! Exact answers for the referee post-processing of Roig03: the Fig. 4 fits above a Δv floor and on the
//! escaping fragments ([`super::ejection_fits`]), the split of K_R into the targets' own spin and the impact's
//! ([`super::rotational_split`]), a pile's drift from its rigid rotation ([`super::pile_equilibrium`]).

use super::ejection_fits::{ejected_sites, ejection_fits, fit_above_floor, fit_selected};
use super::pile_equilibrium::pile_drift;
use super::rotational_split::rotational_split;
use rubblepile::analysis::fits::FitError;
use rubblepile::analysis::fragments::{FragmentAnalysis, RotationMode};
use rubblepile::ellipsoid::body::{Body, Ellipsoid};
use rubblepile::math::{Vec3, Vec4};

/// A target fragment (or the projectile) with only the fields the fits and the site measure read.
fn fragment(index: usize, size: f64, speed: f64, escaping: bool, cosine: f64, is_projectile: bool) -> FragmentAnalysis {
    FragmentAnalysis {
        index,
        is_projectile,
        mass: 1.0,
        equivalent_radius: size,
        size,
        ejection_velocity: [speed, 0.0, 0.0],
        ejection_speed: speed,
        kinetic_energy: 0.0,
        rotational_energy: 0.0,
        binding_energy: 0.0,
        escaping,
        spin_rate: 0.0,
        spin_period_h: None,
        spin_rate_corrected: 0.0,
        spin_period_corrected_h: None,
        moments: [1.0; 3],
        effective_inertia: None,
        rotation_mode_measure: None,
        rotation_mode: RotationMode::None,
        impact_site_cosine: cosine,
    }
}

/// 20 fragments on `Δv = 30 size^−0.4` (all above 10 m/s, all escaping), 15 larger ones on a flat 2 m/s floor
/// (bound), and a projectile far off the law.
fn power_law_and_floor() -> Vec<FragmentAnalysis> {
    let mut out: Vec<FragmentAnalysis> = (0..20)
        .map(|k| {
            let size = 0.05 * 10f64.powf(k as f64 / 19.0);
            fragment(k, size, 30.0 * size.powf(-0.4), true, 0.0, false)
        })
        .collect();
    out.extend((0..15).map(|k| fragment(20 + k, 0.2 + 0.03 * k as f64, 2.0, false, 0.0, false)));
    out.push(fragment(35, 0.01, 5000.0, true, 0.0, true));
    out
}

#[test]
fn the_floor_fit_recovers_the_power_law_that_the_slow_floor_hides() {
    let fits = ejection_fits(&power_law_and_floor(), 10.0);
    let above = fits.above_floor.unwrap();
    assert_eq!(above.points, 20);
    assert!((above.alpha + 0.4).abs() < 1e-12, "alpha {}", above.alpha);
    assert!(above.sigma_alpha < 1e-12, "noise-free: sigma {}", above.sigma_alpha);
    assert!((above.c - 30.0).abs() < 1e-9, "prefactor {}", above.c);
    // the floor of large slow fragments steepens the fit over everything (and the projectile is left out)
    let all = fits.all.unwrap();
    assert_eq!(all.points, 35);
    assert!(all.alpha < -0.9, "all fragments: alpha {}", all.alpha);
}

#[test]
fn the_escaping_fit_uses_the_escaping_target_fragments_only() {
    let escaping = ejection_fits(&power_law_and_floor(), 10.0).escaping.unwrap();
    assert_eq!(escaping.points, 20);
    assert!((escaping.alpha + 0.4).abs() < 1e-12, "alpha {}", escaping.alpha);
}

#[test]
fn the_selection_must_match_the_data_and_the_floor_be_finite() {
    assert!(matches!(
        fit_selected(&[1.0, 2.0], &[1.0, 2.0], &[true]),
        Err(FitError::InvalidInput(_))
    ));
    assert!(matches!(
        fit_above_floor(&[1.0, 2.0, 3.0], &[1.0, 2.0, 3.0], f64::NAN),
        Err(FitError::InvalidInput(_))
    ));
    // a floor above every speed leaves nothing to fit
    assert!(matches!(
        fit_above_floor(&[1.0, 2.0, 3.0], &[1.0, 2.0, 3.0], 10.0),
        Err(FitError::TooFewPoints { points: 0, needed: 3 })
    ));
}

#[test]
fn small_fragments_from_the_impact_side_give_a_correlation_of_minus_one() {
    let mut frags = Vec::new();
    for k in 0..3 {
        frags.push(fragment(k, 0.05, 50.0, false, 0.8, false)); // small, thrown, impact side
        frags.push(fragment(3 + k, 0.2, 50.0, false, -0.8, false)); // large, thrown, antipode
        frags.push(fragment(6 + k, 0.5, 1.0, false, 0.9, false)); // large, below the floor: not counted
    }
    frags.push(fragment(9, 0.01, 5000.0, true, 1.0, true));
    let sites = ejected_sites(&frags, 10.0);
    assert_eq!(
        (sites.fast_fragments, sites.impact_side, sites.antipodal_side),
        (6, 3, 3)
    );
    assert_eq!(sites.impact_side_median_size, Some(0.05));
    assert_eq!(sites.antipodal_side_median_size, Some(0.2));
    let r = sites.size_cosine_correlation.unwrap();
    assert!((r + 1.0).abs() < 1e-12, "correlation {r}");
}

fn ellipsoid(mass: f64, axes: [f64; 3], position: Vec3, velocity: Vec3, angle: f64, spin: Vec3) -> Body {
    Body {
        shape: Ellipsoid {
            axes: Vec3::from(axes),
            mass,
        },
        position,
        velocity,
        // a turn by `angle` about z: a spin about z is the same vector in the body and the world frame
        quaternion: Vec4::new(0.0, 0.0, (angle / 2.0).sin(), (angle / 2.0).cos()),
        spin_body: spin,
    }
}

const OMEGA: f64 = 4.0e-4; // rad/s

/// Four ellipsoids turning rigidly about z at OMEGA, at time t (positions and attitudes turned by OMEGA t),
/// and a projectile (index 4) passing by with a spin of its own.
fn rigid_pile(t: f64) -> Vec<Body> {
    let turn = nalgebra::Rotation3::from_axis_angle(&Vec3::z_axis(), OMEGA * t);
    let omega = Vec3::new(0.0, 0.0, OMEGA);
    let offsets = [
        ([3.0e3, 2.0e3, 1.5e3], Vec3::new(5.0e3, 0.0, 1.0e3), 2.0e13),
        ([2.5e3, 2.0e3, 1.0e3], Vec3::new(-4.0e3, 3.0e3, 0.0), 1.0e13),
        ([2.0e3, 1.5e3, 1.0e3], Vec3::new(0.0, -6.0e3, -2.0e3), 8.0e12),
        ([4.0e3, 3.0e3, 2.0e3], Vec3::new(-1.0e3, 2.0e3, 3.0e3), 3.0e13),
    ];
    let mut bodies: Vec<Body> = offsets
        .iter()
        .enumerate()
        .map(|(k, (axes, r0, mass))| {
            let r = turn * r0;
            ellipsoid(*mass, *axes, r, omega.cross(&r), 0.3 * k as f64 + OMEGA * t, omega)
        })
        .collect();
    bodies.push(ellipsoid(
        1.0e12,
        [1.0e3, 1.0e3, 1.0e3],
        Vec3::new(5.0e4, 0.0, 0.0),
        Vec3::new(-5.0e3, 0.0, 0.0),
        0.0,
        Vec3::new(0.1, 0.2, 0.3),
    ));
    bodies
}

const KAPPA: f64 = 10.0;

#[test]
fn a_rigidly_turning_target_has_all_its_rotational_energy_from_before() {
    let (initial, later) = (rigid_pile(0.0), rigid_pile(400.0));
    let split = rotational_split(&initial, &later, KAPPA, |i| i != 4).unwrap();
    let expected: f64 = initial[..4]
        .iter()
        .map(|b| 0.5 * b.shape.principal_moments(KAPPA).z * OMEGA * OMEGA)
        .sum();
    assert!((split.rotational - expected).abs() < 1e-12 * expected);
    assert!((split.rotational_initial - expected).abs() < 1e-12 * expected);
    assert!(
        split.added_spin_frame < 1e-20 * expected,
        "added {}",
        split.added_spin_frame
    );
    assert!(split.added_per_fragment < 1e-20 * expected);
    assert!((split.pre_existing_fraction() - 1.0).abs() < 1e-12);
    assert!((split.initial_spin_rate - OMEGA).abs() < 1e-15);
}

#[test]
fn a_doubled_spin_adds_exactly_the_energy_of_the_extra_spin() {
    let initial = rigid_pile(0.0);
    let mut later = rigid_pile(400.0);
    later[2].spin_body.z = 2.0 * OMEGA;
    let split = rotational_split(&initial, &later, KAPPA, |i| i != 4).unwrap();
    let iz = later[2].shape.principal_moments(KAPPA).z;
    let added = 0.5 * iz * OMEGA * OMEGA;
    assert!((split.added_spin_frame - added).abs() < 1e-12 * added);
    assert!((split.added_per_fragment - added).abs() < 1e-12 * added);
    // K_R grows by ½ I (2Ω)² − ½ I Ω² = 3 × added; the cross term 2 × added counts as pre-existing
    assert!((split.rotational - split.rotational_initial - 3.0 * added).abs() < 1e-12 * added);
    let pre = 1.0 - added / split.rotational;
    assert!((split.pre_existing_fraction() - pre).abs() < 1e-12);
}

#[test]
fn the_targets_recoil_is_translational_energy_only_in_the_systems_frame() {
    // a non-spinning target of two bodies recoiling at u, a projectile carrying the opposite momentum
    let u = Vec3::new(3.0, 0.0, 0.0);
    let body = |m: f64, x: f64, v: Vec3| ellipsoid(m, [1.0, 1.0, 1.0], Vec3::new(x, 0.0, 0.0), v, 0.0, Vec3::zeros());
    let initial = vec![
        body(2.0, 0.0, Vec3::zeros()),
        body(1.0, 10.0, Vec3::zeros()),
        body(1.0, 50.0, Vec3::zeros()),
    ];
    let later = vec![body(2.0, 0.0, u), body(1.0, 10.0, u), body(1.0, 50.0, -3.0 * u)];
    let split = rotational_split(&initial, &later, KAPPA, |i| i < 2).unwrap();
    assert!((split.translational_system - 0.5 * 3.0 * u.norm_squared()).abs() < 1e-12);
    assert!(split.translational_target.abs() < 1e-12);
    assert_eq!(split.rotational, 0.0);
    assert_eq!(split.share(), 0.0);
    assert!(rotational_split(&initial, &later[..2], KAPPA, |i| i < 2).is_none());
}

#[test]
fn a_rigidly_turning_pile_has_not_drifted() {
    let (initial, later) = (rigid_pile(0.0), rigid_pile(400.0));
    let drift = pile_drift(&initial[..4], &later[..4], 400.0, KAPPA).unwrap();
    assert!(drift.rms_displacement < 1e-9, "rms {}", drift.rms_displacement);
    assert!(drift.max_displacement < 1e-9);
    assert!(drift.non_rigid_fraction < 1e-20, "K_rel/K {}", drift.non_rigid_fraction);
}

#[test]
fn one_moved_body_of_four_drifts_by_three_quarters_and_the_others_by_a_quarter() {
    let d = 100.0;
    let still = |x: f64| {
        ellipsoid(
            1.0e12,
            [1.0e3, 1.0e3, 1.0e3],
            Vec3::new(x, 1.0e4, 0.0),
            Vec3::zeros(),
            0.0,
            Vec3::zeros(),
        )
    };
    let initial: Vec<Body> = (0..4).map(|k| still(1.0e4 * k as f64)).collect();
    let mut later = initial.clone();
    later[1].position.x += d;
    let drift = pile_drift(&initial, &later, 400.0, KAPPA).unwrap();
    assert!((drift.rms_displacement - d * 3f64.sqrt() / 4.0).abs() < 1e-9);
    assert!((drift.max_displacement - 0.75 * d).abs() < 1e-9);
    assert!(pile_drift(&initial, &later[..3], 400.0, KAPPA).is_none());
}
