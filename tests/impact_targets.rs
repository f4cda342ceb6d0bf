//! Rubble-pile targets and projectiles (Roig03 §3, Tables 1–2).

mod common;
use common::Random;
use rubblepile::analysis::rigid_rotation::fit_rigid_rotation;
use rubblepile::ellipsoid::equations::G_SI;
use rubblepile::ellipsoid::quaternion::rotation_matrix;
use rubblepile::geometry::ellipsoid_overlap::are_apart;
use rubblepile::impact::geometry::ImpactGeometry;
use rubblepile::impact::projectile::{ProjectileSpec, set_up_aimed_impact};
use rubblepile::impact::target::{
    TargetSpec, build_target, build_target_resumable, draw_sizes, drop_detached, first_round_spin, place_fragments,
    set_rigid_rotation,
};
use rubblepile::impact::target_checkpoint::BuildCheckpoint;
use rubblepile::math::{Mat3, Vec3};
use rubblepile::random::generator;
use std::f64::consts::PI;

fn sigma(b: &rubblepile::ellipsoid::body::Body) -> Mat3 {
    let r = rotation_matrix(&b.quaternion);
    r.transpose() * Mat3::from_diagonal(&b.shape.axes.component_mul(&b.shape.axes)) * r
}

/// Sizes: extremes exact, total mass within tolerance, and the N − 2 drawn radii follow the truncated
/// power law N(>R) ∝ R^−2.5 (Kolmogorov–Smirnov on u = (R^−2.5 − R_max^−2.5)/(R_min^−2.5 − R_max^−2.5), which
/// is uniform exactly when the slope is right).
#[test]
fn size_distribution_has_the_slope_extremes_and_mass() {
    for n in [30, 100, 200] {
        let spec = TargetSpec::table1(n, 4.0, 7).unwrap();
        let (radii, _) = draw_sizes(&spec, &mut generator(spec.seed)).unwrap();
        assert_eq!(radii.len(), n);
        assert_eq!(radii[0], spec.r_largest);
        assert_eq!(radii[n - 1], spec.r_smallest);
        let mass: f64 = radii.iter().map(|r| 3000.0 * 4.0 / 3.0 * PI * r.powi(3)).sum();
        assert!((mass / 1e19 - 1.0).abs() <= 0.005, "N{n}: mass {mass:e}");
        let (a, b) = (spec.r_largest.powf(-2.5), spec.r_smallest.powf(-2.5));
        let mut u: Vec<f64> = radii[1..n - 1].iter().map(|r| (r.powf(-2.5) - a) / (b - a)).collect();
        u.sort_by(f64::total_cmp);
        let m = u.len() as f64;
        let d = u
            .iter()
            .enumerate()
            .map(|(k, x)| ((k as f64 + 1.0) / m - x).max(x - k as f64 / m))
            .fold(0.0, f64::max);
        assert!(
            d < 1.63 / m.sqrt(),
            "N{n}: KS distance {d} (1 % critical {})",
            1.63 / m.sqrt()
        );
        // A wrong slope fails the same test: the radii read as a slope −1.5 law are far from uniform.
        let (a15, b15) = (spec.r_largest.powf(-1.5), spec.r_smallest.powf(-1.5));
        let mut w: Vec<f64> = radii[1..n - 1]
            .iter()
            .map(|r| (r.powf(-1.5) - a15) / (b15 - a15))
            .collect();
        w.sort_by(f64::total_cmp);
        let dw = w
            .iter()
            .enumerate()
            .map(|(k, x)| ((k as f64 + 1.0) / m - x).max(x - k as f64 / m))
            .fold(0.0, f64::max);
        if n >= 100 {
            assert!(
                dw > 1.63 / m.sqrt(),
                "N{n}: the KS test cannot tell slope 1.5 from 2.5 ({dw})"
            );
        }
    }
}

#[test]
fn placement_has_no_initial_contact_and_largest_at_centre() {
    let spec = TargetSpec::table1(100, 4.0, 3).unwrap();
    let mut rng = generator(spec.seed);
    let (radii, _) = draw_sizes(&spec, &mut rng).unwrap();
    let (bodies, radius) = place_fragments(&spec, &radii, &mut rng);
    assert_eq!(bodies[0].position, Vec3::zeros());
    assert!((bodies[0].shape.equivalent_radius() / 60e3 - 1.0).abs() < 1e-12);
    for (i, a) in bodies.iter().enumerate() {
        assert!(
            a.position.norm() + a.shape.axes.x <= radius * (1.0 + 1e-12),
            "body {i} outside the sphere"
        );
        let (b_over_a, c_over_a) = (a.shape.axes.y / a.shape.axes.x, a.shape.axes.z / a.shape.axes.x);
        assert!((b_over_a - 0.7).abs() < 1e-12 && (c_over_a - 0.5).abs() < 1e-12);
        for b in &bodies[i + 1..] {
            assert!(
                are_apart(&(a.position - b.position), &sigma(a), &sigma(b)),
                "initial contact"
            );
        }
    }
}

#[test]
fn rigid_rotation_fit_recovers_omega_and_zero_relative_energy() {
    let mut rng = Random::new(21);
    let spec = TargetSpec::table1(30, 4.0, 5).unwrap();
    let mut g = generator(5);
    let (radii, _) = draw_sizes(&spec, &mut g).unwrap();
    let (mut bodies, _) = place_fragments(&spec, &radii, &mut g);
    let omega = rng.vec3(1e-3);
    set_rigid_rotation(&mut bodies, &omega);
    let moments: Vec<Vec3> = bodies.iter().map(|b| b.shape.principal_moments(2.5)).collect();
    let fit = fit_rigid_rotation(&bodies, &moments);
    assert!((fit.omega - omega).norm() <= 1e-12 * omega.norm());
    assert!(fit.non_rigid_fraction() < 1e-20, "{}", fit.non_rigid_fraction());
    // one fragment knocked out of the rigid motion shows up in K_rel
    bodies[5].velocity += Vec3::new(10.0, 0.0, 0.0);
    let fit = fit_rigid_rotation(&bodies, &moments);
    assert!(fit.non_rigid_fraction() > 1e-6);
}

/// A small pile (12 fragments, 6→3 km) builds quickly: rigid at the end, spin period near the request,
/// in the centre-of-mass frame, and the same seed gives the same bodies and report bit for bit.
/// The 12-fragment pile (6→3 km) of the small-target tests.
fn small_spec() -> TargetSpec {
    common::small_pile_spec(11, 12, 6e3, 3e3, 0.05)
}

#[test]
fn small_target_relaxes_to_rigid_rotation_deterministically() {
    let spec = small_spec();
    let mut quiet = |_: usize, _: f64, _: f64, _: f64| {};
    let (bodies, report) = build_target(&spec, &mut quiet).unwrap();
    assert!(
        report.non_rigid_fraction < spec.rigidity,
        "K_rel/K = {}",
        report.non_rigid_fraction
    );
    assert!(
        (report.spin_period_hours / 6.0 - 1.0).abs() < 0.1,
        "period {} h",
        report.spin_period_hours
    );
    let com: Vec3 = bodies.iter().map(|b| b.position * b.shape.mass).sum::<Vec3>() / report.total_mass_kg;
    assert!(com.norm() < 1e-6 * report.apparent_radius_m);
    assert!(
        report.relaxation_energy_error < 1e-6,
        "{}",
        report.relaxation_energy_error
    );
    let (again, report2) = build_target(&spec, &mut quiet).unwrap();
    assert_eq!(bodies, again);
    assert_eq!(
        serde_json::to_string(&report).unwrap(),
        serde_json::to_string(&report2).unwrap()
    );
}

/// A build stopped after any relaxation check and resumed from its checkpoint (through its JSON form) ends
/// with the same bodies and report, bit for bit, as the build that was never stopped; a checkpoint of other
/// inputs is refused, naming them.
#[test]
fn resumed_target_build_is_bit_identical() {
    let spec = small_spec();
    let mut quiet = |_: usize, _: f64, _: f64, _: f64| {};
    let mut saved: Vec<String> = Vec::new();
    let mut keep = |c: &BuildCheckpoint| saved.push(serde_json::to_string(c).unwrap());
    let (bodies, report) = build_target_resumable(&spec, None, &mut quiet, &mut keep).unwrap();
    assert!(saved.len() >= 3, "only {} checkpoints", saved.len());
    let rounds: Vec<usize> = saved
        .iter()
        .map(|s| serde_json::from_str::<BuildCheckpoint>(s).unwrap().round)
        .collect();
    // one checkpoint early in the first round, one in the last round
    for pick in [1, saved.len() - 1] {
        let checkpoint: BuildCheckpoint = serde_json::from_str(&saved[pick]).unwrap();
        let (again, report2) = build_target_resumable(&spec, Some(checkpoint), &mut quiet, &mut |_| {}).unwrap();
        assert_eq!(bodies, again, "resumed from checkpoint {pick} (round {})", rounds[pick]);
        assert_eq!(
            serde_json::to_string(&report).unwrap(),
            serde_json::to_string(&report2).unwrap()
        );
    }
    let mut other = spec.clone();
    other.seed += 1;
    let checkpoint: BuildCheckpoint = serde_json::from_str(&saved[1]).unwrap();
    let err = build_target_resumable(&other, Some(checkpoint), &mut quiet, &mut |_| {}).unwrap_err();
    assert!(
        err.to_string()
            .contains("checkpoint: it was written by a build with other inputs"),
        "{err}"
    );
}

/// `--drop-detached`: a relaxed pile (the committed N30_T4) is one clump, so nothing is removed; a fragment moved
/// 1000 km out is removed, and only it, with its placement index dropped from `kept`. Without the option the
/// spec's JSON has no `drop_detached` key, so the committed targets' files are unchanged.
#[test]
fn drop_detached_removes_only_fragments_outside_the_main_clump() {
    let pile = rubblepile::impact::run::read_target(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/targets/N30_T4.csv"
    )))
    .unwrap();
    let mut bodies = pile.clone();
    let mut kept: Vec<usize> = (0..bodies.len()).collect();
    assert_eq!(drop_detached(&mut bodies, &mut kept), 0);
    assert_eq!(bodies, pile);
    bodies[7].position += Vec3::new(1.0e6, 0.0, 0.0);
    let lost = bodies[7].clone();
    assert_eq!(drop_detached(&mut bodies, &mut kept), 1);
    assert_eq!(bodies.len(), pile.len() - 1);
    assert!(!bodies.contains(&lost));
    assert_eq!(kept, (0..pile.len()).filter(|&i| i != 7).collect::<Vec<_>>());
    let spec = TargetSpec::table1(30, 4.0, 1).unwrap();
    assert!(!serde_json::to_string(&spec).unwrap().contains("drop_detached"));
    let mut dropping = spec.clone();
    dropping.drop_detached = true;
    let back: TargetSpec = serde_json::from_str(&serde_json::to_string(&dropping).unwrap()).unwrap();
    assert_eq!(back, dropping);
}

/// A checkpoint taken after fragments were dropped records which placement bodies remain (`kept`): its round
/// starts from their shapes, it survives JSON, and a `kept` out of range or out of order is refused.
#[test]
fn checkpoint_after_dropping_fragments_keeps_their_shapes() {
    let spec = small_spec();
    let mut quiet = |_: usize, _: f64, _: f64, _: f64| {};
    let mut saved: Option<BuildCheckpoint> = None;
    let mut keep = |c: &BuildCheckpoint| {
        saved.get_or_insert_with(|| c.clone());
    };
    let _ = build_target_resumable(&spec, None, &mut quiet, &mut keep).unwrap();
    let first = saved.unwrap();
    assert!(first.kept.is_none());
    let (radii, _) = draw_sizes(&spec, &mut generator(spec.seed)).unwrap();
    let placed = place_fragments(&spec, &radii, &mut generator(spec.seed)).0;
    let all = first.round_start_bodies(&placed);
    // the same round start without body 4
    let kept: Vec<usize> = (0..spec.fragments).filter(|&i| i != 4).collect();
    let start: Vec<_> = kept.iter().map(|&i| all[i].clone()).collect();
    let cut = BuildCheckpoint::new(&spec, first.round, &start, &kept, 0.0, 0.0, first.state.clone());
    let back: BuildCheckpoint = serde_json::from_str(&serde_json::to_string(&cut).unwrap()).unwrap();
    assert_eq!(back, cut);
    assert!(back.check(&spec).is_ok());
    assert_eq!(back.round_start_bodies(&placed), start);
    let mut bad = back.clone();
    bad.kept = Some((1..spec.fragments).rev().collect());
    assert!(bad.check(&spec).unwrap_err().to_string().contains("kept"));
}

/// The first round's spin keeps the placement sphere's equator bound: unchanged where `Ω² R_p³ ≤ G M` (Table 1's
/// targets), otherwise centrifugal acceleration at `R_p` equal to half of gravity (the N = 2000 pile's case,
/// whose outer fragments flew off at 4 h and kept K_rel/K rising).
#[test]
fn first_round_spin_keeps_the_placement_equator_bound() {
    let (mass, radius) = (1.0e19, 145.66e3);
    let omega = Vec3::new(0.0, 0.0, 2.0 * PI / (4.0 * 3600.0));
    assert_eq!(first_round_spin(&omega, mass, radius), omega);
    let loose = 159.16e3;
    let first = first_round_spin(&omega, mass, loose);
    assert!(first.norm() < omega.norm() && first.cross(&omega).norm() == 0.0);
    let ratio = first.norm_squared() * loose / (G_SI * mass / loose.powi(2));
    assert!((ratio - 0.5).abs() < 1e-12, "centrifugal / gravity = {ratio}");
}

/// Table 2: Q for P1/P2/P3 on a 1e19 kg target at 5 km/s is 0.44, 1.49, 3.54 × 10⁹ erg/g.
/// The projectile moves in the y–z plane toward the centre of mass at ζ to z, apart from every fragment at
/// t = 0 and touching one after `contact_time` of straight flight.
#[test]
fn projectiles_have_table2_energies_and_impact_geometry() {
    let spec = TargetSpec::table1(30, 4.0, 2).unwrap();
    let mut g = generator(2);
    let (radii, _) = draw_sizes(&spec, &mut g).unwrap();
    let (target, _) = place_fragments(&spec, &radii, &mut g);
    let m_target: f64 = target.iter().map(|b| b.shape.mass).sum();
    for (id, q_paper) in [("P1", 0.44e9), ("P2", 1.49e9), ("P3", 3.54e9)] {
        let p = ProjectileSpec::preset(id).unwrap();
        for angle in [0.0, 45.0, 90.0] {
            let (bodies, setup, _) = set_up_aimed_impact(&target, &p, &ImpactGeometry::default(), angle, 90.0, 4);
            let q_1e19 = setup.q_erg_per_g * m_target / 1e19;
            assert!(
                (q_1e19 / q_paper - 1.0).abs() < 0.01,
                "{id}: Q = {q_1e19:e} erg/g vs {q_paper:e}"
            );
            let proj = bodies.last().unwrap();
            assert_eq!(proj.spin_body, Vec3::zeros());
            // centre-of-mass frame
            let m: f64 = bodies.iter().map(|b| b.shape.mass).sum();
            let p_tot: Vec3 = bodies.iter().map(|b| b.velocity * b.shape.mass).sum();
            assert!(p_tot.norm() < 1e-9 * proj.shape.mass * 5000.0);
            let com: Vec3 = bodies.iter().map(|b| b.position * b.shape.mass).sum::<Vec3>() / m;
            assert!(com.norm() < 1e-6);
            // relative velocity along −n, n = (0, sin ζ, cos ζ); the path passes through the target's centre
            let target_v = bodies[0..bodies.len() - 1]
                .iter()
                .map(|b| b.velocity * b.shape.mass)
                .sum::<Vec3>()
                / m_target;
            let v_rel = proj.velocity - target_v;
            let z = angle.to_radians();
            let n = Vec3::new(0.0, z.sin(), z.cos());
            assert!(
                (v_rel + n * 5000.0).norm() < 1e-9 * 5000.0,
                "{id} ζ = {angle}: velocity {v_rel}"
            );
            let target_com = bodies[0..bodies.len() - 1]
                .iter()
                .map(|b| b.position * b.shape.mass)
                .sum::<Vec3>()
                / m_target;
            let offset = proj.position - target_com;
            assert!(
                offset.cross(&n).norm() < 1e-9 * offset.norm(),
                "not aimed at the centre of mass"
            );
            // apart now and after flying 89.99 s; in contact just after 90 s
            let s_p = sigma(proj);
            let touching = |dt: f64| {
                let pos = proj.position + proj.velocity * dt;
                bodies[..bodies.len() - 1]
                    .iter()
                    .any(|b| !are_apart(&(pos - (b.position + target_v * dt)), &s_p, &sigma(b)))
            };
            assert!(
                !touching(0.0) && !touching(89.99) && touching(90.01),
                "{id} ζ = {angle}: contact not at 90 s"
            );
        }
    }
}

/// `kappa_reading` sets the κ the pile is relaxed with: Eq. 14 under that reading over the pile's smallest and
/// largest fragments; the printed default stays out of the spec's JSON (the committed targets' files) and is
/// what a spec without the key reads as.
#[test]
fn the_kappa_reading_sets_the_relaxation_kappa() {
    use rubblepile::ellipsoid::calibration::{KappaReading, calibrate_kappa_read};
    let mut spec = small_spec();
    let printed = serde_json::to_value(&spec).unwrap();
    assert!(printed.get("kappa_reading").is_none());
    let back: TargetSpec = serde_json::from_value(printed).unwrap();
    assert_eq!(back.kappa_reading, KappaReading::Printed);
    spec.kappa_reading = KappaReading::Reduced;
    assert_eq!(serde_json::to_value(&spec).unwrap()["kappa_reading"], "reduced");
    let mut quiet = |_: usize, _: f64, _: f64, _: f64| {};
    let (bodies, report) = build_target(&spec, &mut quiet).unwrap();
    let by_mass = |pick: fn(f64, f64) -> bool| {
        let b = bodies
            .iter()
            .reduce(|a, b| if pick(b.shape.mass, a.shape.mass) { b } else { a })
            .unwrap();
        (b.shape.equivalent_radius(), b.shape.mass)
    };
    let (small, large) = (by_mass(|a, b| a < b), by_mass(|a, b| a > b));
    let expected = calibrate_kappa_read(KappaReading::Reduced, 10.0, 5000.0, small, large, G_SI).unwrap();
    assert!(
        (report.kappa - expected).abs() < 1e-12 * expected,
        "{} vs {expected}",
        report.kappa
    );
    let printed = calibrate_kappa_read(KappaReading::Printed, 10.0, 5000.0, small, large, G_SI).unwrap();
    assert!(
        report.kappa < printed - 1.0,
        "reduced {} against printed {printed}",
        report.kappa
    );
}
