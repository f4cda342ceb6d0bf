//! Rubble-pile projectiles (issue 20): a two-pile collision conserves E (with the dissipated work), P and L; the
//! set-up makes the piles first touch at `contact_time`; the random attitude is a rigid turn; the composition
//! analysis on constructed cases with known answers; the campaign's `projectile_pile` field.

mod common;
use common::temp_dir;
use std::path::{Path, PathBuf};

use rubblepile::analysis::clumps::{DEFAULT_GAP_FRACTION, analyse_clumps, clump_spin};
use rubblepile::analysis::composition::{Origin, composition};
use rubblepile::driver::RunOptions;
use rubblepile::ellipsoid::body::{Body, Ellipsoid};
use rubblepile::ellipsoid::quaternion::rotation_matrix;
use rubblepile::impact::campaign::parse_campaign;
use rubblepile::impact::geometry::ImpactGeometry;
use rubblepile::impact::pile::{ProjectilePile, set_up_aimed_pile_impact};
use rubblepile::impact::run::{ImpactConfig, read_target, run_impact};
use rubblepile::math::{Mat3, Vec3, Vec4};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn json(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
}

/// Whether any projectile body overlaps any target body (the ellipsoids' overlap test): the check that a
/// set-up starts with the piles apart.
fn piles_overlap(bodies: &[Body], n_target: usize) -> bool {
    let sigma = |b: &Body| {
        let r = rotation_matrix(&b.quaternion);
        r.transpose() * Mat3::from_diagonal(&b.shape.axes.component_mul(&b.shape.axes)) * r
    };
    let (target, projectile) = bodies.split_at(n_target);
    projectile.iter().any(|p| {
        target.iter().any(|t| {
            let d = p.position - t.position;
            d.norm() < p.shape.axes.x + t.shape.axes.x
                && !rubblepile::geometry::ellipsoid_overlap::are_apart(&d, &sigma(p), &sigma(t))
        })
    })
}

fn pile(file: &str, random_attitude: bool) -> ProjectilePile {
    ProjectilePile::read(&root().join(file), random_attitude).unwrap()
}

fn total_mass(bodies: &[Body]) -> f64 {
    bodies.iter().map(|b| b.shape.mass).sum()
}

fn barycentre_velocity(bodies: &[Body]) -> Vec3 {
    bodies.iter().map(|b| b.velocity * b.shape.mass).sum::<Vec3>() / total_mass(bodies)
}

/// N30_T12 thrown at N30_T4 at 5 km/s, ζ = 45°, to t = 200 s (contact at 90 s): the run's energy residual
/// (E + dissipated work `2∫F dt`), P and L errors, all relative, stay below 1e-8; the piles do not overlap at
/// t = 0 nor at 85 s and overlap at 95 s.
#[test]
fn two_pile_collision_conserves_energy_momentum_and_angular_momentum() {
    let out = temp_dir("pile_conservation");
    let p = pile("targets/N30_T12.csv", true);
    let mut cfg = ImpactConfig::new(root().join("targets/N30_T4.csv"), p.equivalent_spec(p.id(), 5000.0));
    cfg.pile = Some(p);
    cfg.t_end = 200.0;
    cfg.snapshots = vec![0.0, 85.0, 95.0, 200.0];
    let options = RunOptions {
        force: true,
        ..RunOptions::default()
    };
    run_impact(&cfg, &out, &options).unwrap();
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["status"], "completed");
    for key in ["energy_error", "linear_momentum_error", "angular_momentum_error"] {
        let e = summary[key].as_f64().unwrap();
        assert!(e.abs() <= 1e-8, "{key} = {e:e}");
    }
    // Dissipation did work: the bookkeeping was exercised, not idle.
    let series = std::fs::read_to_string(out.join("timeseries.csv")).unwrap();
    let header: Vec<&str> = series.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "dissipated").unwrap();
    let dissipated: f64 = series
        .lines()
        .last()
        .unwrap()
        .split(',')
        .nth(col)
        .unwrap()
        .parse()
        .unwrap();
    assert!(dissipated.abs() > 0.0, "no dissipated work recorded");

    let impact = json(&out.join("impact.json"));
    let record = &impact["projectile_pile"];
    assert_eq!(record["n"], 30);
    assert_eq!(record["target_bodies"], serde_json::json!([0, 30]));
    assert_eq!(record["projectile_bodies"], serde_json::json!([30, 60]));
    let m_p = record["mass_kg"].as_f64().unwrap();
    assert_eq!(impact["projectile_mass_kg"].as_f64().unwrap(), m_p);
    let m_t = impact["target_mass_kg"].as_f64().unwrap();
    let q = impact["q_j_per_kg"].as_f64().unwrap();
    assert!((q - 0.5 * m_p * 5000f64.powi(2) / m_t).abs() <= 1e-12 * q, "Q = {q}");

    let snapshot = |k: usize| read_target(&out.join(format!("snapshots/{k}.csv"))).unwrap();
    let initial = snapshot(0);
    assert_eq!(initial.len(), 60);
    assert!(barycentre_velocity(&initial).norm() < 1e-9, "not in the CM frame");
    assert!(!piles_overlap(&initial, 30), "piles overlap at t = 0");
    assert!(!piles_overlap(&snapshot(1), 30), "piles already overlap at 85 s");
    assert!(piles_overlap(&snapshot(2), 30), "piles do not touch at 95 s");
}

/// The set-up itself: moving the projectile bodies rigidly with the pile's barycentric velocity relative to the
/// target (the ballistic estimate the placement uses), the piles are apart 0.01 s before `contact_time` and
/// overlap 0.01 s after it (50 m of travel at 5 km/s), for three angles; the mass and momentum bookkeeping holds.
#[test]
fn pile_set_up_touches_at_contact_time() {
    let target = read_target(&root().join("targets/N30_T4.csv")).unwrap();
    let p = pile("targets/N30_T12.csv", true);
    let spec = p.equivalent_spec(p.id(), 5000.0);
    for angle in [0.0, 45.0, 120.0] {
        let geometry = ImpactGeometry::default();
        let (bodies, setup, _) = set_up_aimed_pile_impact(&target, &p, &spec, &geometry, angle, 90.0, 3);
        assert_eq!(bodies.len(), 60);
        assert_eq!(setup.projectile_index, 30);
        assert!((total_mass(&bodies[30..]) - p.mass()).abs() <= 1e-12 * p.mass());
        assert!(barycentre_velocity(&bodies).norm() < 1e-9);
        let relative = barycentre_velocity(&bodies[30..]) - barycentre_velocity(&bodies[..30]);
        assert!(
            (relative.norm() - 5000.0).abs() < 1e-6,
            "relative speed {}",
            relative.norm()
        );
        let zeta = f64::to_radians(angle);
        let n = Vec3::new(0.0, zeta.sin(), zeta.cos());
        assert!((relative.normalize() + n).norm() < 1e-12, "not aimed along -n");
        let moved = |t: f64| {
            let mut b = bodies.clone();
            for x in &mut b[30..] {
                x.position += relative * t;
            }
            b
        };
        assert!(!piles_overlap(&bodies, 30), "ζ = {angle}: overlap at t = 0");
        assert!(!piles_overlap(&moved(89.99), 30), "ζ = {angle}: overlap before contact");
        assert!(
            piles_overlap(&moved(90.01), 30),
            "ζ = {angle}: no contact after contact_time"
        );
    }
}

/// The random attitude turns the pile rigidly: pairwise distances, speeds relative to the barycentre, body-frame
/// spins and kinetic energy are kept, and every body's world-frame shape matrix is turned by the same rotation
/// (`Σ' = Q Σ Qᵀ`, the convention check of the quaternion composition).
#[test]
fn random_attitude_is_a_rigid_turn_of_the_pile() {
    let fixed = pile("targets/N30_T4.csv", false).oriented_bodies(7);
    let turned = pile("targets/N30_T4.csv", true).oriented_bodies(7);
    let sigma = |b: &Body| {
        let r = rotation_matrix(&b.quaternion);
        r.transpose() * Mat3::from_diagonal(&b.shape.axes.component_mul(&b.shape.axes)) * r
    };
    // The turn Q from the first two non-parallel position vectors (and their cross product).
    let basis = |b: &[Body]| {
        let (u, v) = (b[0].position, b[1].position);
        Mat3::from_columns(&[u, v, u.cross(&v)])
    };
    let q = basis(&turned) * basis(&fixed).try_inverse().unwrap();
    assert!((q.transpose() * q - Mat3::identity()).norm() < 1e-9, "not a rotation");
    assert!((q - Mat3::identity()).norm() > 1e-3, "seed 7 did not turn the pile");
    let scale = fixed[0].shape.axes.x.powi(2);
    for (a, b) in fixed.iter().zip(&turned) {
        assert!((q * a.position - b.position).norm() < 1e-6 * a.position.norm().max(1.0));
        assert!((q * a.velocity - b.velocity).norm() < 1e-9 * a.velocity.norm().max(1e-6));
        assert_eq!(a.spin_body, b.spin_body);
        assert!((q * sigma(a) * q.transpose() - sigma(b)).norm() < 1e-9 * scale);
    }
}

/// The clumps of `bodies` as `analyze`'s `largest remnant:` line finds them (default gap, self-gravity `g`).
fn clumps_of(bodies: &[Body], g: f64) -> Vec<Vec<usize>> {
    analyse_clumps(bodies, DEFAULT_GAP_FRACTION, Some(g), |b| {
        b.shape.principal_moments(2.5)
    })
    .clumps
    .into_iter()
    .map(|c| c.members)
    .collect()
}

/// Spheres of radius 1 (G = 100): clump A = {T0, T1, P2} (masses 2, 2, 1; in contact), clump B = {P3, T4}
/// (1, 3; 0.05 apart, inside the clump finder's gap), both at rest 50 apart; P5 (0.01) alone and fast. Known answers:
/// A is the largest remnant (mass 5, projectile fraction 0.2, bound), B the other bound clump (projectile
/// fraction 0.25, mixed), P5 escapes.
#[test]
fn composition_of_a_constructed_outcome() {
    let sphere = |mass: f64, x: f64, y: f64, vz: f64| Body {
        shape: Ellipsoid {
            axes: Vec3::new(1.0, 1.0, 1.0),
            mass,
        },
        position: Vec3::new(x, y, 0.0),
        velocity: Vec3::new(0.0, 0.0, vz),
        quaternion: Vec4::new(0.0, 0.0, 0.0, 1.0),
        spin_body: Vec3::zeros(),
    };
    const {
        assert!(
            DEFAULT_GAP_FRACTION > 0.05,
            "B's 0.05 gap must fall inside the finder's gap"
        )
    };
    let bodies = [
        sphere(2.0, 0.0, 0.0, 0.0),    // T0
        sphere(2.0, 1.9, 0.0, 0.0),    // T1
        sphere(1.0, 0.0, 1.9, 0.0),    // P2
        sphere(1.0, 50.0, 0.0, 0.0),   // P3
        sphere(3.0, 52.05, 0.0, 0.0),  // T4
        sphere(0.01, -50.0, 0.0, 1e3), // P5
    ];
    let projectile = [2usize, 3, 5];
    // Reorder so the projectile bodies are the contiguous range 3..6: T0 T1 T4 | P2 P3 P5.
    let order = [0usize, 1, 4, 2, 3, 5];
    let bodies: Vec<Body> = order.iter().map(|&i| bodies[i].clone()).collect();
    let clumps = clumps_of(&bodies, 100.0);
    let c = composition(&bodies, 3..6, &clumps, 100.0, |b| b.shape.principal_moments(2.5)).unwrap();
    for (k, &i) in order.iter().enumerate() {
        let expected = if projectile.contains(&i) {
            Origin::Projectile
        } else {
            Origin::Target
        };
        assert_eq!(c.origins[k], expected);
    }
    assert_eq!(c.n_clumps, 3);
    assert_eq!(c.n_bound_clumps, 2);
    let lr = &c.largest_remnant;
    assert_eq!(lr.n_bodies, 3);
    assert_eq!(lr.mass_kg, 5.0);
    assert!((lr.projectile_fraction - 0.2).abs() < 1e-15);
    assert!(lr.bound);
    assert!((lr.mass_over_target - 5.0 / 7.0).abs() < 1e-15);
    assert_eq!(c.clumps[0].bodies, vec![0, 1, 3]);
    assert_eq!(c.clumps[1].bodies, vec![2, 4]);
    assert_eq!(c.n_other_bound, 1);
    assert_eq!(c.other_bound_mass_kg, 4.0);
    assert!((c.other_bound_projectile_fraction.unwrap() - 0.25).abs() < 1e-15);
    assert_eq!(c.other_bound_mixed, 1);
    assert!(!c.clumps[2].bound, "the fast body must escape");
    assert!((c.bound_target_fraction - 1.0).abs() < 1e-15);
    assert!((c.bound_projectile_fraction - 2.0 / 2.01).abs() < 1e-14);
    assert!((c.projectile_in_largest_remnant - 1.0 / 2.01).abs() < 1e-14);
    assert_eq!(c.clump_of, vec![0, 0, 1, 0, 1, 2]);
    // Everything a target: no composition.
    assert!(composition(&bodies, 0..6, &clumps, 100.0, |b| b.shape.principal_moments(2.5)).is_none());
    assert!(composition(&bodies, 3..3, &clumps, 100.0, |b| b.shape.principal_moments(2.5)).is_none());
}

/// Two touching spheres in rigid rotation ω about z through their barycentre (velocities ω × r, body spins ω):
/// the aggregate's spin `I⁻¹ L` is ω, and the largest remnant's period 2π/|ω|.
#[test]
fn clump_spin_of_a_rigid_rotation_is_its_rate() {
    let omega = Vec3::new(0.0, 0.0, 3e-4);
    let body = |x: f64, mass: f64| Body {
        shape: Ellipsoid {
            axes: Vec3::new(1.2, 1.0, 0.8),
            mass,
        },
        position: Vec3::new(x, 0.0, 0.0),
        velocity: omega.cross(&Vec3::new(x, 0.0, 0.0)),
        quaternion: Vec4::new(0.0, 0.0, 0.0, 1.0),
        spin_body: omega,
    };
    // Barycentre at 0: masses 1 and 2 at 1 and −0.5 (overlapping: one clump).
    let bodies = vec![body(1.0, 1.0), body(-0.5, 2.0)];
    let moments = |b: &Body| b.shape.principal_moments(2.5);
    let spin = clump_spin(&bodies, &[0, 1], moments);
    assert!((spin - omega).norm() < 1e-12 * omega.norm(), "spin {spin:?}");
    let c = composition(&bodies, 1..2, &clumps_of(&bodies, 1e-3), 1e-3, moments).unwrap();
    let period = c.largest_remnant.spin_period_h.unwrap();
    let expected = 2.0 * std::f64::consts::PI / 3e-4 / 3600.0;
    assert!(
        (period - expected).abs() < 1e-9 * expected,
        "{period} h against {expected} h"
    );
    assert!((c.largest_remnant.projectile_fraction - 2.0 / 3.0).abs() < 1e-15);
}

/// A campaign's `[[projectile]]` with `projectile_pile`: the grid point's configuration carries the pile
/// (random attitude by default, off with `random_attitude = false`), its plan holds N_t + N_p bodies and its id
/// names the runs; a wrong combination names the field.
#[test]
fn campaign_reads_projectile_pile_entries() {
    let text = r#"
[campaign]
out = "runs/c"
targets = ["targets/N30_T4.csv"]
projectiles = ["pile30", "P1"]
angles = [45.0]

[impact]
t_end = 100.0

[[projectile]]
id = "pile30"
projectile_pile = "targets/N30_T12.csv"
random_attitude = false
speed_km_s = 3.0
"#;
    let c = parse_campaign(text, "c.toml", &root()).unwrap();
    assert_eq!(c.points.len(), 2);
    let point = &c.points[0];
    assert_eq!(point.name, "N30_T4_pile30_z45_s1");
    let pile = point.config.pile.as_ref().expect("the pile");
    assert_eq!(pile.bodies.len(), 30);
    assert!(!pile.random_attitude);
    assert_eq!(point.config.projectile.speed, 3000.0);
    assert_eq!(point.plan.bodies.len(), 60);
    assert_eq!(
        point.plan.setup.projectile_pile.as_ref().unwrap().projectile_bodies,
        [30, 60]
    );
    assert!(c.points[1].config.pile.is_none());
    assert_eq!(c.points[1].plan.bodies.len(), 31);

    let error = |replace: (&str, &str)| {
        let text = text.replace(replace.0, replace.1);
        parse_campaign(&text, "c.toml", &root()).unwrap_err().to_string()
    };
    let e = error(("random_attitude = false", "radius_km = 3.0"));
    assert!(e.contains("projectile[0].projectile_pile"), "{e}");
    let e = error(("projectile_pile = \"targets/N30_T12.csv\"", ""));
    assert!(e.contains("projectile[0].radius_km"), "{e}");
    let e = error(("N30_T12.csv", "missing.csv"));
    assert!(
        e.contains("projectile[0].projectile_pile") && e.contains("missing.csv"),
        "{e}"
    );
    let e = error(("random_attitude = false", "random_attitude = 3"));
    assert!(e.contains("random_attitude"), "{e}");
    let e = error((
        "projectile_pile = \"targets/N30_T12.csv\"\nrandom_attitude = false",
        "radius_km = 2.0\nrandom_attitude = true",
    ));
    assert!(e.contains("projectile[0].random_attitude"), "{e}");
}

/// A pile-projectile run's `analyze` names one largest remnant: the `composition:` line and `analysis.json`'s
/// `composition.largest_remnant` are the clump of the `largest remnant:` line (same member count, same mass), and
/// counts of one print with a singular noun ("(1 body)", never "(1 bodies)").
#[test]
fn composition_and_largest_remnant_line_name_the_same_clump() {
    let dir = temp_dir("pile-one-lr");
    let target = root().join("targets/N30_T4.csv");
    let pile = root().join("targets/N30_T12.csv");
    let (target, pile) = (target.to_str().unwrap(), pile.to_str().unwrap());
    let o = common::rubblepile(
        &dir,
        &[
            "impact",
            "--target",
            target,
            "--projectile-pile",
            pile,
            "--projectile-speed-km-s",
            "0.3",
            "--t-end-s",
            "400",
            "--out",
            "run",
            "--no-progress",
        ],
    );
    assert!(o.status.success(), "{}", common::describe(&o));
    let o = common::rubblepile(&dir, &["analyze", "run"]);
    assert!(o.status.success(), "{}", common::describe(&o));
    let a = json(&dir.join("run/analysis/analysis.json"));
    let (lr, c) = (&a["largest_remnant"], &a["composition"]["largest_remnant"]);
    assert!(
        lr["n_members"].as_u64().unwrap() > 1,
        "a merger must leave a clump of several bodies: {lr}"
    );
    assert_eq!(lr["n_members"], c["n_bodies"], "{lr} vs {c}");
    assert_eq!(lr["mass_kg"], c["mass_kg"], "{lr} vs {c}");
    let stdout = String::from_utf8_lossy(&o.stdout);
    let members = lr["n_members"].as_u64().unwrap();
    let line = |start: &str| {
        stdout
            .lines()
            .find(|l| l.starts_with(start))
            .unwrap_or_else(|| panic!("{stdout}"))
    };
    assert!(
        line("largest remnant:").contains(&format!("({members} bodies,")),
        "{stdout}"
    );
    assert!(
        line("composition:").contains(&format!("largest remnant {members} bodies,")),
        "{stdout}"
    );
    assert!(
        !stdout.contains("(1 bodies)") && !stdout.contains(" 1 clumps"),
        "{stdout}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
