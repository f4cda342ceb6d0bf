//! Impact geometry beyond ζ (issue 57): an impact parameter b, the impact angle θ to the surface normal, the
//! azimuth ψ, the projectile's spin and attitude (`rubblepile::impact::geometry`).
//!
//! Oracles: (a) on a spherical or ellipsoidal one-body target the straight line of the built projectile meets the
//! body's own surface (solved here from its semi-axes and attitude) where the normal makes θ with the velocity, and
//! a tight pile of seven spheres gets its bounding sphere as the surface; (b) the angular momentum the projectile
//! brings about the target's centre of mass is `−m v (b e(ψ) × n) + Rᵀ I R ω` (the definitions of b, ψ and n
//! written out again here) to 1e-12; (c) b = 0.7 R runs from the command line and from a campaign file;
//! (d) the default set-up is the ζ-only one, rebuilt here step by step, to the bit; (e) bad input names the flag
//! or the field.

mod common;
use common::{describe, rubblepile as bin, temp_dir};
use std::path::PathBuf;

use rubblepile::ellipsoid::body::{Body, Ellipsoid};
use rubblepile::ellipsoid::quaternion::rotation_matrix;
use rubblepile::impact::campaign::parse_campaign;
use rubblepile::impact::geometry::{Aim, ImpactGeometry, SurfaceEllipsoid};
use rubblepile::impact::projectile::{ProjectileSpec, contact_walk, set_up_aimed_impact, target_and_direction};
use rubblepile::impact::run::ImpactConfig;
use rubblepile::impact::target::{set_rigid_rotation, to_centre_of_mass_frame};
use rubblepile::math::{Mat3, Vec3, Vec4};
use rubblepile::random::{generator, random_quaternion};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A body of density 3000 kg/m³ with semi-axes `axes` (m) at `position`, at rest.
fn body(axes: [f64; 3], position: [f64; 3], quaternion: Vec4) -> Body {
    let axes = Vec3::from(axes);
    Body {
        shape: Ellipsoid {
            axes,
            mass: 3000.0 * 4.0 / 3.0 * std::f64::consts::PI * axes.product(),
        },
        position: Vec3::from(position),
        velocity: Vec3::zeros(),
        quaternion,
        spin_body: Vec3::zeros(),
    }
}

/// Seven touching spheres of radius `r`: one at the centre, six at ±2r on the axes (bounding sphere 3r).
fn seven_spheres(r: f64) -> Vec<Body> {
    let mut bodies = vec![body([r; 3], [0.0; 3], Vec4::new(0.0, 0.0, 0.0, 1.0))];
    for k in 0..3 {
        for sign in [-1.0, 1.0] {
            let mut p = [0.0; 3];
            p[k] = sign * 2.0 * r;
            bodies.push(body([r; 3], p, Vec4::new(0.0, 0.0, 0.0, 1.0)));
        }
    }
    bodies
}

fn projectile() -> ProjectileSpec {
    ProjectileSpec::custom("S".into(), 1e3, 200.0)
}

fn aimed(aim: Aim, azimuth_deg: f64) -> ImpactGeometry {
    ImpactGeometry {
        aim,
        azimuth_deg,
        ..ImpactGeometry::default()
    }
}

/// Where the projectile's straight line (relative to body `t`, the target) first meets body `t`'s ellipsoid, and
/// the angle (rad) between the outward normal there and the reversed velocity.
fn line_meets_body(bodies: &[Body], t: usize) -> (Vec3, f64) {
    let (target, p) = (&bodies[t], bodies.last().unwrap());
    let rot = rotation_matrix(&target.quaternion); // world → body
    let inv_a2 = Mat3::from_diagonal(&target.shape.axes.map(|a| 1.0 / (a * a)));
    let q = rot.transpose() * inv_a2 * rot;
    let (r, d) = (p.position - target.position, (p.velocity - target.velocity).normalize());
    let (a, b, c) = (d.dot(&(q * d)), r.dot(&(q * d)), r.dot(&(q * r)) - 1.0);
    let s = (-b - (b * b - a * c).sqrt()) / a; // the first root: the line coming in
    let hit = r + d * s;
    let normal = (q * hit).normalize();
    (hit, normal.dot(&-d).acos())
}

/// (a) θ = 45° on one sphere, one rotated triaxial ellipsoid (where the surface ellipsoid is the body itself),
/// and the seven-sphere pile (whose surface is the bounding sphere of radius 3r).
#[test]
fn the_line_meets_the_surface_at_the_impact_angle() {
    let attitude = Vec4::new(0.3, -0.5, 0.2, 0.9).normalize();
    for (zeta, psi) in [(30.0, 60.0), (90.0, 200.0), (0.0, 0.0)] {
        for target in [
            vec![body([10e3; 3], [1e3, 2e3, -3e3], attitude)],
            vec![body([12e3, 8e3, 6e3], [0.0; 3], attitude)],
        ] {
            let (bodies, setup, hits) =
                set_up_aimed_impact(&target, &projectile(), &aimed(Aim::AngleDeg(45.0), psi), zeta, 90.0, 1);
            assert!(hits);
            let (_, angle) = line_meets_body(&bodies, 0);
            assert!(
                (angle.to_degrees() - 45.0).abs() < 1e-9,
                "ζ {zeta}, ψ {psi}: {}",
                angle.to_degrees()
            );
            let g = setup.geometry.unwrap();
            assert!((g.impact_angle_deg.unwrap() - 45.0).abs() < 1e-9);
            if target[0].shape.is_sphere() {
                let b = 10e3 * 45f64.to_radians().sin();
                assert!(
                    (g.impact_parameter_m - b).abs() < 1e-12 * b,
                    "{} vs {b}",
                    g.impact_parameter_m
                );
            }
        }
        // The pile: its surface is the sphere of radius 3r about its centre of mass.
        let r = 2e3;
        let surface = SurfaceEllipsoid::of(&seven_spheres(r));
        assert!(
            surface.axes.iter().all(|a| (a - 3.0 * r).abs() < 1e-12 * r),
            "{:?}",
            surface.axes
        );
        let (bodies, setup, hits) = set_up_aimed_impact(
            &seven_spheres(r),
            &projectile(),
            &aimed(Aim::AngleDeg(45.0), psi),
            zeta,
            90.0,
            1,
        );
        assert!(hits);
        let mut sphere = bodies.clone();
        sphere[0] = body([3.0 * r; 3], [0.0; 3], Vec4::new(0.0, 0.0, 0.0, 1.0));
        let com: Vec3 = bodies[..7].iter().map(|b| b.position).sum::<Vec3>() / 7.0;
        let vcm: Vec3 = bodies[..7].iter().map(|b| b.velocity).sum::<Vec3>() / 7.0;
        (sphere[0].position, sphere[0].velocity) = (com, vcm);
        let (hit, angle) = line_meets_body(&sphere[..1].iter().chain(bodies.last()).cloned().collect::<Vec<_>>(), 0);
        assert!((angle.to_degrees() - 45.0).abs() < 1e-9, "{}", angle.to_degrees());
        let aim = Vec3::from(setup.geometry.unwrap().aim_point_m.unwrap());
        assert!((hit - aim).norm() < 1e-9 * r, "{hit:?} vs {aim:?}");
    }
}

/// Total angular momentum of `bodies` about the point `x` moving at `v` (uniform-solid moments).
fn angular_momentum(bodies: &[Body], x: Vec3, v: Vec3) -> Vec3 {
    bodies
        .iter()
        .map(|b| {
            let rot = rotation_matrix(&b.quaternion);
            let spin = rot.transpose() * Mat3::from_diagonal(&b.shape.principal_moments(2.5)) * b.spin_body;
            (b.position - x).cross(&((b.velocity - v) * b.shape.mass)) + spin
        })
        .sum()
}

/// (b) What the projectile brings: the orbital `r × p` of its offset trajectory plus its spin, to 1e-12.
#[test]
fn the_delivered_angular_momentum_is_r_cross_p_plus_the_spin() {
    let r = 2e3;
    let mut target = seven_spheres(r);
    set_rigid_rotation(&mut target, &Vec3::new(0.0, 0.0, 1e-4));
    let own = angular_momentum(&target, Vec3::zeros(), Vec3::zeros());
    let attitude = Vec4::new(0.1, 0.7, -0.2, 0.4);
    let omega = Vec3::new(0.01, -0.02, 0.005);
    for (zeta, psi, frac) in [(60.0, 30.0, 0.7), (0.0, 0.0, 0.3), (135.0, 300.0, 0.5)] {
        for spin in [Vec3::zeros(), omega] {
            let geometry = ImpactGeometry {
                aim: Aim::ParameterFrac(frac),
                azimuth_deg: psi,
                spin_rad_s: spin,
                attitude: Some(attitude),
            };
            let p = projectile();
            let (bodies, setup, hits) = set_up_aimed_impact(&target, &p, &geometry, zeta, 90.0, 1);
            assert!(hits, "ζ {zeta} ψ {psi} f {frac}");
            let mass: f64 = bodies[..7].iter().map(|b| b.shape.mass).sum();
            let com = bodies[..7].iter().map(|b| b.position * b.shape.mass).sum::<Vec3>() / mass;
            let vcm = bodies[..7].iter().map(|b| b.velocity * b.shape.mass).sum::<Vec3>() / mass;
            let delivered = angular_momentum(&bodies, com, vcm) - own;
            // The oracle, from the definitions: n = (0, sin ζ, cos ζ), e(ψ) = cos ψ x̂ + sin ψ (n × x̂), b = f R.
            let (z, s) = (f64::to_radians(zeta), f64::to_radians(psi));
            let n = Vec3::new(0.0, z.sin(), z.cos());
            let e = Vec3::new(s.cos(), s.sin() * z.cos(), -s.sin() * z.sin());
            let b = frac * 3.0 * r;
            let m = p.shape().mass;
            let rot = rotation_matrix(&attitude.normalize());
            let spin_l = rot.transpose() * Mat3::from_diagonal(&p.shape().principal_moments(2.5)) * rot * spin;
            let expected = -(e * b).cross(&n) * (m * p.speed) + spin_l;
            let error = (delivered - expected).norm() / expected.norm();
            assert!(
                error < 1e-12,
                "ζ {zeta} ψ {psi} f {frac}: {delivered:?} vs {expected:?} ({error:e})"
            );
            let g = setup.geometry.unwrap();
            assert!((g.impact_parameter_m - b).abs() < 1e-12 * b);
        }
    }
}

/// (d) The default set-up is the ζ-only one of Roig03 §3, rebuilt here step by step, to the bit; an explicit
/// b = 0 moves nothing either.
#[test]
fn the_default_is_the_zeta_only_set_up() {
    let file = root().join("targets/N30_T4.csv");
    let target = rubblepile::impact::run::read_target(&file).unwrap();
    for (angle, seed) in [(45.0, 1), (0.0, 7), (90.0, 3)] {
        let mut cfg = ImpactConfig::new(file.clone(), ProjectileSpec::preset("P2").unwrap());
        (cfg.angle_deg, cfg.seed) = (angle, seed);
        let plan = cfg.plan(&target).unwrap();
        assert!(plan.setup.geometry.is_none());
        // The ζ-only set-up.
        let (mut bodies, _, n) = target_and_direction(&target, angle);
        let quaternion = random_quaternion(&mut generator(seed));
        let shape = cfg.projectile.shape();
        let incoming = [Body {
            shape,
            position: Vec3::zeros(),
            velocity: Vec3::zeros(),
            quaternion,
            spin_body: Vec3::zeros(),
        }];
        let start = contact_walk(&bodies, &incoming, &n).0 + cfg.projectile.speed * cfg.contact_time;
        bodies.push(Body {
            shape,
            position: n * start,
            velocity: -n * cfg.projectile.speed,
            quaternion,
            spin_body: Vec3::zeros(),
        });
        to_centre_of_mass_frame(&mut bodies);
        let bits = |b: &[Body]| -> Vec<u64> {
            b.iter()
                .flat_map(|b| {
                    b.position
                        .iter()
                        .chain(&b.velocity)
                        .chain(&b.quaternion)
                        .chain(&b.spin_body)
                })
                .map(|x| x.to_bits())
                .collect()
        };
        assert_eq!(bits(&plan.bodies), bits(&bodies));
        cfg.geometry.aim = Aim::ParameterM(0.0);
        let zero = cfg.plan(&target).unwrap();
        assert_eq!(bits(&zero.bodies), bits(&bodies));
        assert_eq!(zero.setup.geometry.unwrap().impact_parameter_m, 0.0);
        // the aimed title only adds the aim: b, which R, ψ
        let (from, to) = (
            zero.title.find(", b = 0.000 km = 0.000 R (R = "),
            zero.title.find("psi = 0 deg"),
        );
        let (from, to) = (from.expect(&zero.title), to.expect(&zero.title) + "psi = 0 deg".len());
        assert!(
            zero.title[from..to].contains("of the target's surface ellipsoid"),
            "{}",
            zero.title
        );
        assert_eq!(format!("{}{}", &zero.title[..from], &zero.title[to..]), plan.title);
    }
}

fn text(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned() + &String::from_utf8_lossy(&o.stdout)
}

/// (c) b = 0.7 R from the command line and from a two-run campaign file, to a short end.
#[test]
fn an_offset_impact_runs_from_the_command_line_and_from_a_campaign() {
    let dir = temp_dir("impact-geometry");
    let target = root().join("targets/N30_T4.csv");
    let out = dir.join("cli");
    let o = bin(
        &dir,
        &[
            "impact",
            "--target",
            target.to_str().unwrap(),
            "--impact-parameter-frac",
            "0.7",
            "--aim-azimuth-deg",
            "90",
            "--projectile-spin-rad-s",
            "0.001,0,-0.002",
            "--projectile-attitude",
            "0,0,0,1",
            "--contact-time-s",
            "1",
            "--t-end-s",
            "3",
            "--out",
            out.to_str().unwrap(),
            "--no-progress",
        ],
    );
    assert!(o.status.success(), "{}", describe(&o));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("impact.json")).unwrap()).unwrap();
    let g = &json["geometry"];
    let (b, r) = (
        g["impact_parameter_m"].as_f64().unwrap(),
        g["target_radius_m"].as_f64().unwrap(),
    );
    assert!((b / r - 0.7).abs() < 1e-12, "{g}");
    assert_eq!(g["projectile_attitude"], serde_json::json!([0.0, 0.0, 0.0, 1.0]));
    let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
    assert!(summary.contains("completed"), "{summary}");

    let campaign = format!(
        r#"
[campaign]
out = "camp"
targets = ["{}"]
projectiles = ["P1"]
angles = [45.0]
seeds = [1, 2]
parallel = 1

[impact]
t_end = 3.0
contact_time = 1.0
every = 1.0
impact_parameter_frac = 0.7
aim_azimuth_deg = 45.0
projectile_spin_rad_s = [0.0, 0.0, 0.001]
"#,
        target.display()
    );
    std::fs::write(dir.join("c.toml"), campaign).unwrap();
    let o = bin(&dir, &["campaign", "c.toml", "--no-progress"]);
    assert!(o.status.success(), "{}", describe(&o));
    let index = std::fs::read_to_string(dir.join("camp/campaign.csv")).unwrap();
    assert_eq!(index.matches(",completed,").count(), 2, "{index}");
    for seed in [1, 2] {
        let path = dir.join(format!("camp/N30_T4_P1_z45_s{seed}/impact.json"));
        let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
        let g = &json["geometry"];
        let b = g["impact_parameter_m"].as_f64().unwrap();
        assert!((b / g["target_radius_m"].as_f64().unwrap() - 0.7).abs() < 1e-12, "{g}");
        assert_eq!(g["aim_azimuth_deg"], 45.0);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// (e) Bad input: one-line errors naming the flag (command line) or the field (library, campaign file).
#[test]
fn bad_geometry_names_the_flag_or_the_field() {
    let dir = temp_dir("impact-geometry-bad");
    let target = root().join("targets/N30_T4.csv");
    let t = target.to_str().unwrap();
    let out = dir.join("x");
    let o = out.to_str().unwrap();
    let cases: [(&[&str], &[&str]); 8] = [
        (&["--impact-angle-deg", "90"], &["--impact-angle-deg", "[0, 90)"]),
        (
            &["--impact-angle-deg", "30", "--impact-parameter-m", "5"],
            &["--impact-angle-deg", "--impact-parameter-m"],
        ),
        (
            &["--impact-parameter-frac", "0.5", "--impact-parameter-m", "5"],
            &["--impact-parameter-frac", "--impact-parameter-m"],
        ),
        (
            &["--impact-parameter-frac", "1"],
            &["--impact-parameter-frac", "[0, 1)"],
        ),
        (
            &["--impact-parameter-m", "1e9"],
            &["--impact-parameter-m", "misses the target"],
        ),
        (
            &["--impact-parameter-m", "1e3", "--aim-azimuth-deg", "360"],
            &["--aim-azimuth-deg", "[0, 360)"],
        ),
        (&["--projectile-spin-rad-s", "1,2"], &["--projectile-spin-rad-s", "3"]),
        (
            &["--projectile-attitude", "0,0,0,0"],
            &["--projectile-attitude", "norm > 0"],
        ),
    ];
    for (flags, expected) in cases {
        let args: Vec<&str> = ["impact", "--target", t, "--out", o]
            .iter()
            .chain(flags)
            .copied()
            .collect();
        let result = bin(&dir, &args);
        let message = text(&result);
        assert_eq!(result.status.code(), Some(2), "{flags:?}: {message}");
        assert!(expected.iter().all(|e| message.contains(e)), "{flags:?}: {message}");
        assert!(!out.exists(), "{flags:?} wrote {}", out.display());
    }
    let pile = root().join("targets/N30_T4.csv");
    let args = [
        "impact",
        "--target",
        t,
        "--out",
        o,
        "--projectile-pile",
        pile.to_str().unwrap(),
        "--projectile-spin-rad-s",
        "1,0,0",
    ];
    assert!(text(&bin(&dir, &args)).contains("--projectile-spin-rad-s: not for a rubble-pile projectile"));

    let campaign = |impact: &str| {
        let file = format!(
            "[campaign]\nout = \"o\"\ntargets = [\"{}\"]\nprojectiles = [\"P1\"]\nangles = [45.0]\n[impact]\n{impact}\n",
            target.display()
        );
        parse_campaign(&file, "c.toml", &dir)
            .map(|_| ())
            .unwrap_err()
            .to_string()
    };
    let e = campaign("impact_angle_deg = 95.0");
    assert!(e.contains("impact.impact_angle_deg") && e.contains("[0, 90)"), "{e}");
    let e = campaign("impact_angle_deg = 30.0\nimpact_parameter_m = 10.0");
    assert!(
        e.contains("impact_parameter_m") && e.contains("impact_angle_deg"),
        "{e}"
    );
    let e = campaign("impact_parameter_m = 1e9");
    assert!(
        e.contains("impact.impact_parameter_m") && e.contains("misses the target"),
        "{e}"
    );
    let e = campaign("aim_azimuth_deg = 10.0");
    assert!(e.contains("impact.aim_azimuth_deg") && e.contains("needs"), "{e}");
    let e = campaign("projectile_spin_rad_s = [1.0, 0.0]");
    assert!(e.contains("projectile_spin_rad_s"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// ψ means the same for a θ aim as for a b aim: on a rotated triaxial ellipsoid (its own surface ellipsoid), θ aims
/// at ψ = 0 and 60° put the trajectory's offset at azimuth ψ about the approach direction (ψ = 0 along x̂, 90°
/// along n × x̂) to 1e-9 rad, the normal where the line meets the body makes θ with it to 1e-9 rad, and the record
/// says that ψ and θ. The committed N30_T4 target aimed at θ = 45° prints θ and says which R; an angle below the
/// smallest the azimuth offers is refused, naming the field.
#[test]
fn an_angle_aim_goes_in_at_the_recorded_azimuth() {
    let attitude = Vec4::new(0.3, -0.5, 0.2, 0.9).normalize();
    let target = vec![body([12e3, 8e3, 6e3], [0.0; 3], attitude)];
    for zeta in [30.0, 75.0] {
        for psi in [0.0, 60.0] {
            for theta in [30.0, 45.0, 70.0] {
                let (bodies, setup, hits) =
                    set_up_aimed_impact(&target, &projectile(), &aimed(Aim::AngleDeg(theta), psi), zeta, 90.0, 1);
                assert!(hits);
                let (t, p) = (&bodies[0], &bodies[1]);
                let n = -(p.velocity - t.velocity).normalize();
                let r = p.position - t.position;
                let offset = r - n * r.dot(&n);
                let x = Vec3::x();
                let azimuth = offset.dot(&n.cross(&x)).atan2(offset.dot(&x));
                let want = psi.to_radians();
                let gap =
                    (azimuth - want + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
                assert!(
                    gap.abs() < 1e-9,
                    "ζ {zeta}, ψ {psi}, θ {theta}: offset azimuth {} deg",
                    azimuth.to_degrees()
                );
                let (_, angle) = line_meets_body(&bodies, 0);
                assert!(
                    (angle - theta.to_radians()).abs() < 1e-9,
                    "ζ {zeta}, ψ {psi}: normal at {} deg",
                    angle.to_degrees()
                );
                let g = setup.geometry.unwrap();
                assert_eq!(g.aim_azimuth_deg, psi);
                assert!((g.impact_angle_deg.unwrap() - theta).abs() < 1e-7);
                assert!((g.impact_parameter_m - offset.norm()).abs() < 1e-6 * offset.norm());
            }
        }
    }
    // the committed target from the configuration: θ echoed, R named; θ = 0 off the point whose normal is n is refused
    let file = root().join("targets/N30_T4.csv");
    let rubble = rubblepile::impact::run::read_target(&file).unwrap();
    let mut cfg = ImpactConfig::new(file, ProjectileSpec::preset("P2").unwrap());
    cfg.geometry = aimed(Aim::AngleDeg(45.0), 0.0);
    let plan = cfg.plan(&rubble).unwrap();
    for part in [
        ", theta = 45 deg, b = ",
        " R (R = ",
        " km, of the target's surface ellipsoid), psi = 0 deg",
    ] {
        assert!(plan.title.contains(part), "{part:?} not in {}", plan.title);
    }
    // θ = 0 is the head-on point (normal n), recorded at its own azimuth
    cfg.geometry = aimed(Aim::AngleDeg(0.0), 90.0);
    let head_on = cfg.plan(&rubble).unwrap();
    let g = head_on.setup.geometry.unwrap();
    assert!(g.impact_angle_deg.unwrap().abs() < 1e-6, "{g:?}");
    let p = head_on.bodies.last().unwrap();
    let n = -p.velocity.normalize();
    let com: Vec3 = head_on.bodies[..30]
        .iter()
        .map(|b| b.position * b.shape.mass)
        .sum::<Vec3>()
        / head_on.bodies[..30].iter().map(|b| b.shape.mass).sum::<f64>();
    let r = p.position - com;
    let offset = r - n * r.dot(&n);
    let azimuth = offset
        .dot(&n.cross(&Vec3::x()))
        .atan2(offset.dot(&Vec3::x()))
        .to_degrees()
        .rem_euclid(360.0);
    assert!((azimuth - g.aim_azimuth_deg).abs() < 1e-6, "{azimuth} vs {g:?}");
    // a θ just above 0 off the head-on point's azimuth is out of reach there
    cfg.geometry = aimed(Aim::AngleDeg(1e-3), (g.aim_azimuth_deg + 90.0).rem_euclid(360.0));
    let e = cfg.plan(&rubble).map(|_| ()).unwrap_err().to_string();
    assert!(e.contains("impact_angle_deg") && e.contains("smallest there"), "{e}");
}
