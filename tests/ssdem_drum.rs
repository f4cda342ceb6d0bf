//! The soft-sphere cylinder wall (a drum) against oracles: a sphere at rest at the bottom of a horizontal drum (and
//! on top of one, the outer face) presses it by Hooke's `m g / k_N` at angle 0; an elastic, frictionless bounce
//! off the inner and the outer face keeps the kinetic energy to the leapfrog's order and reflects the velocity
//! about the surface normal; a sphere in a spinning drum comes to co-rotate (speed `Ω ρ`, spin `Ω â`, overlap
//! `m Ω² ρ / k_N`) with its energy book closed by the wall's work, couples included; and the example drum scene
//! runs.

mod common;

use rubblepile::geometry::walls::soft::{Cylinder, Wall};
use rubblepile::granular::soft::contact::Material;
use rubblepile::granular::soft::forces::{Gravity, SoftSystem};
use rubblepile::granular::soft::leapfrog;
use rubblepile::granular::soft::particle::Particle;
use rubblepile::math::Vec3;

const R_DRUM: f64 = 1.0;
const R_BALL: f64 = 0.1;

fn ball(position: Vec3, velocity: Vec3) -> Particle {
    Particle {
        mass: 4.0 / 3.0 * std::f64::consts::PI * R_BALL.powi(3) * 1000.0,
        radius: R_BALL,
        position,
        velocity,
        spin: Vec3::zeros(),
    }
}

/// A drum of radius 1 m about the y axis through the origin, infinite unless `length`, spinning at `spin` rad/s.
fn drum(length: Option<f64>, spin: f64) -> Wall {
    Wall::Cylinder(Cylinder {
        centre: Vec3::zeros(),
        axis: Vec3::y(),
        radius: R_DRUM,
        length,
        oscillation: None,
        spin,
    })
}

fn gravity(g: f64) -> Gravity {
    Gravity {
        uniform: Vec3::new(0.0, 0.0, -g),
        self_gravity: None,
        g: 6.674e-11,
    }
}

/// A system of one ball and one wall, its forces at t = 0 and the step for `steps_per_contact` steps per contact.
fn system(p: Particle, wall: Wall, material: Material, g: f64, steps_per_contact: f64) -> (SoftSystem, f64) {
    let dt = std::f64::consts::PI * (p.mass / material.k_n).sqrt() / steps_per_contact;
    let mut sys = SoftSystem::new(vec![p], vec![wall], material, gravity(g));
    sys.compute_forces(0.0, 0.0);
    (sys, dt)
}

fn run(sys: &mut SoftSystem, dt: f64, t: f64) {
    for k in 0..(t / dt).round() as u64 {
        leapfrog::step(sys, k as f64 * dt, dt);
    }
}

/// Hooke's law at the bottom of the drum (inner face) and on top of it (outer face): the ball settles with overlap
/// `m g / k_N`, its centre straight below (above) the axis.
#[test]
fn sphere_settles_at_the_bottom_of_a_drum_with_the_hookean_overlap() {
    let g = 9.81;
    let material = Material {
        eps_n: 0.3,
        ..Material::nominal(1e5)
    };
    for (side, start) in [
        ("inside", -(R_DRUM - R_BALL) - 0.002),
        ("outside", R_DRUM + R_BALL - 0.002),
    ] {
        let (mut sys, dt) = system(
            ball(Vec3::new(0.0, 0.3, start), Vec3::zeros()),
            drum(None, 0.0),
            material,
            g,
            50.0,
        );
        run(&mut sys, dt, 3.0);
        let p = &sys.particles[0];
        let hooke = p.mass * g / material.k_n;
        let overlap = R_BALL - (p.position.z.abs() - R_DRUM).abs();
        println!(
            "{side}: overlap {overlap:e} m, Hooke {hooke:e} m, x = {:e} m",
            p.position.x
        );
        assert!(
            (overlap - hooke).abs() < 1e-3 * hooke,
            "{side}: overlap {overlap} vs m g / k_n {hooke}"
        );
        assert_eq!(p.position.x, 0.0, "{side}: the ball left angle 0");
        assert!(p.velocity.norm() < 1e-6, "{side}: not at rest: {:?}", p.velocity);
    }
}

/// An elastic (`ε_n = 1`), frictionless bounce off the inner face and off the outer face: the kinetic energy after
/// the contact is the energy before to the leapfrog's order, and the velocity is reflected about the normal at the
/// contact (its axial and tangential components kept).
#[test]
fn elastic_bounce_off_a_drum_keeps_the_energy_and_reflects_the_velocity() {
    let material = Material {
        eps_n: 1.0,
        mu_s: 0.0,
        beta: 0.0,
        ..Material::nominal(1e5)
    };
    // From near the axis outwards (inner face), and from outside inwards (outer face); both at 30° to the radius
    // in the plane normal to the axis, with an axial drift.
    let dir = Vec3::new(30f64.to_radians().sin(), 0.0, 30f64.to_radians().cos());
    for (side, start, velocity) in [
        ("inner", Vec3::new(0.0, 0.0, 0.2), Vec3::new(0.5, 0.3, 1.0)),
        (
            "outer",
            dir * 1.3 - Vec3::new(0.2, 0.0, 0.0),
            -dir * 1.0 + Vec3::new(0.0, 0.3, 0.0),
        ),
    ] {
        let (mut sys, dt) = system(ball(start, velocity), drum(None, 0.0), material, 0.0, 100.0);
        let e0 = sys.kinetic_energy();
        let mut touched = false;
        let mut normal = Vec3::zeros();
        for k in 0..2_000_000u64 {
            leapfrog::step(&mut sys, k as f64 * dt, dt);
            if sys.stats.wall_contacts > 0 {
                touched = true;
                let p = &sys.particles[0];
                normal = Vec3::new(p.position.x, 0.0, p.position.z).normalize();
            } else if touched {
                break;
            }
        }
        assert!(
            touched && sys.stats.wall_contacts == 0,
            "{side}: the bounce did not complete"
        );
        let p = &sys.particles[0];
        let e1 = sys.kinetic_energy();
        let reflected = velocity - normal * (2.0 * velocity.dot(&normal));
        println!(
            "{side}: relative energy change {:e}, velocity {:?} vs reflected {reflected:?}",
            (e1 - e0) / e0,
            p.velocity
        );
        assert!(((e1 - e0) / e0).abs() < 1e-3, "{side}: energy {e0} -> {e1}");
        assert!(
            (p.velocity - reflected).norm() < 1e-2 * velocity.norm(),
            "{side}: {:?}",
            p.velocity
        );
        assert_eq!(p.velocity.y, velocity.y, "{side}: the axial velocity changed");
        assert!(
            p.spin.norm() < 1e-12,
            "{side}: a frictionless wall spun the ball: {:?}",
            p.spin
        );
    }
}

/// A ball touching the inside of a drum spinning at Ω (no gravity) is dragged along until it co-rotates: speed
/// `Ω ρ` about the axis, spin `Ω â` (the wall's spin enters the rolling law: a wall taken as still would brake it),
/// pressed out by `m Ω² ρ / k_N`.
#[test]
fn sphere_in_a_spinning_drum_comes_to_corotate() {
    let omega = 2.0;
    let material = Material::nominal(1e5);
    let start = Vec3::new(0.0, 0.0, -(R_DRUM - R_BALL) - 1e-3);
    let (mut sys, dt) = system(ball(start, Vec3::zeros()), drum(Some(1.0), omega), material, 0.0, 200.0);
    run(&mut sys, dt, 20.0);
    let p = &sys.particles[0];
    let rho = Vec3::new(p.position.x, 0.0, p.position.z).norm();
    let overlap = rho + R_BALL - R_DRUM;
    let centripetal = p.mass * omega * omega * rho / material.k_n;
    println!(
        "speed {:.6} (Omega rho {:.6}), spin {:?}, overlap {overlap:e} (m Omega^2 rho / k_n {centripetal:e})",
        p.velocity.norm(),
        omega * rho,
        p.spin
    );
    assert!((p.velocity.norm() - omega * rho).abs() < 1e-4 * omega * rho);
    assert!((p.spin - Vec3::y() * omega).norm() < 1e-3 * omega, "spin {:?}", p.spin);
    assert!(
        (overlap - centripetal).abs() < 1e-2 * centripetal,
        "{overlap} vs {centripetal}"
    );
    assert!(p.position.y.abs() < 1e-12, "drifted along the axis: {}", p.position.y);
}

/// The work of a spinning wall includes that of the twisting couple it exerts: a ball bouncing elastically on the
/// rim of a finite drum spinning about the vertical (the contact normal along the axis, so the drum's spin twists
/// the contact), with every law conservative (ε = 1, caps out of reach, no rolling resistance), keeps
/// `E − W_wall = E₀` while it touches, to the first order in the step at which the wall's work is summed — far
/// closer than the couple's share of the work.
#[test]
fn spinning_drum_work_includes_its_twisting_couple() {
    let omega = 2.0;
    let material = Material {
        eps_n: 1.0,
        eps_t: 1.0,
        mu_s: 1e6,
        mu_t: 1e6,
        mu_r: 0.0,
        beta: 1.0,
        ..Material::nominal(1e5)
    };
    let wall = Wall::Cylinder(Cylinder {
        centre: Vec3::zeros(),
        axis: Vec3::z(),
        radius: R_DRUM,
        length: Some(1.0),
        oscillation: None,
        spin: omega,
    });
    let start = Vec3::new(R_DRUM, 0.0, 0.5 + R_BALL - 0.01);
    let (mut sys, dt) = system(ball(start, Vec3::zeros()), wall, material, 0.0, 2000.0);
    sys.keep_records = true;
    let e0 = sys.energy();
    let (mut worst, mut couple, mut touched): (f64, f64, bool) = (0.0, 0.0, false);
    for k in 0..1_000_000u64 {
        leapfrog::step(&mut sys, k as f64 * dt, dt);
        // The work of the couple the wall exerts: the opposite of the one on it, `torque_j`, at its spin.
        couple -= sys
            .records
            .iter()
            .map(|r| r.output.torque_j.dot(&(Vec3::z() * omega)))
            .sum::<f64>()
            * dt;
        if sys.stats.wall_contacts == 0 && touched {
            break;
        }
        touched |= sys.stats.wall_contacts > 0;
        // Contacts that end drop their springs' energy: the book is read while the ball touches.
        if touched {
            worst = worst.max((sys.energy() + sys.dissipated - sys.wall_work - e0).abs());
        }
    }
    println!(
        "residual {worst:e} J, wall work {:e} J, of which the twisting couple's {couple:e} J",
        sys.wall_work
    );
    assert!(
        sys.particles[0].spin.z > 0.0,
        "the drum did not twist the ball: {:?}",
        sys.particles[0].spin
    );
    assert!(couple > 0.05, "the couple's work is too small to test: {couple}");
    assert!(
        worst < 0.2 * couple,
        "residual {worst} J against the couple's {couple} J"
    );
}

/// The example drum (`targets/examples/soft_drum.toml`) passes `rubblepile check` without a warning and runs
/// to its end, its bed carried up the side the drum's surface rises on.
#[test]
fn example_soft_drum_runs() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = root.join("targets/examples/soft_drum.toml");
    let dir = common::temp_dir("soft-drum");
    let check = common::rubblepile(&dir, &["check", scene.to_str().unwrap()]);
    assert!(check.status.success(), "{}", String::from_utf8_lossy(&check.stderr));
    assert!(
        !String::from_utf8_lossy(&check.stderr).contains("warning"),
        "{}",
        String::from_utf8_lossy(&check.stderr)
    );
    let out = common::rubblepile(&dir, &["run", scene.to_str().unwrap(), "--out", "run", "--no-progress"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("run/summary.json")).unwrap()).unwrap();
    assert_eq!(summary["status"], "completed", "{summary}");
    assert_eq!(summary["n_walls"], 3, "{summary}");
    // Its energy residual is above 1 % with a k_N and a step off the advice: the done line says so, with the
    // summary's own ratios.
    let stdout = String::from_utf8_lossy(&out.stdout);
    let f = |k: &str| summary[k].as_f64().unwrap();
    assert!(f("energy_error") > 1e-2, "{summary}");
    let k_ratio = format!("k_N is {:.1}x below", f("advised_k_n") / f("k_n"));
    let dt_ratio = format!("dt is {:.1}x the step advised", f("dt") / f("advised_dt"));
    assert!(
        stdout.contains(&k_ratio) && stdout.contains(&dt_ratio) && stdout.contains("rubblepile ssdem advise"),
        "{stdout}"
    );
    // The drum turns about +y, its bottom moving towards -x: the bed is carried up the -x side.
    let last = std::fs::read_to_string(dir.join("run/snapshots/2.csv")).unwrap();
    let rows: Vec<Vec<f64>> = last
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    let mean = |k: usize| rows.iter().map(|r| r[k]).sum::<f64>() / rows.len() as f64;
    let (x, z) = (mean(4), mean(6));
    println!("bed's centre at x = {x:.4} m, z = {z:.4} m");
    assert!(
        x < -0.01 && z > -0.02,
        "the bed was not carried up the rising side: x = {x}, z = {z}"
    );
}

/// Guards the accuracy hint's threshold: the example soft-sphere scene (energy residual below 1 %) ends on the plain
/// done line, without a hint.
#[test]
fn a_resolved_soft_scene_prints_no_accuracy_hint() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = root.join("targets/examples/soft_spheres.toml");
    let dir = common::temp_dir("soft-no-hint");
    let out = common::rubblepile(&dir, &["run", scene.to_str().unwrap(), "--out", "run", "--no-progress"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("run/summary.json")).unwrap()).unwrap();
    assert!(summary["energy_error"].as_f64().unwrap() <= 1e-2, "{summary}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("completed: ") && !stdout.contains("energy residual above"),
        "{stdout}"
    );
}
