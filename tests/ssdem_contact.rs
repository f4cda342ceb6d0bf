//! SSDEM contact law (Zhang17 Eqs. 1–12): restitution of head-on collisions, sliding → rolling at 5/7 v0, rolling
//! resistance stopping a sphere within the torque cap.

use rubblepile::geometry::walls::soft::{Plane, Wall};
use rubblepile::granular::soft::contact::Material;
use rubblepile::granular::soft::forces::{Gravity, SoftSystem};
use rubblepile::granular::soft::leapfrog;
use rubblepile::granular::soft::particle::Particle;
use rubblepile::math::Vec3;

fn sphere(radius: f64, density: f64, position: Vec3, velocity: Vec3) -> Particle {
    Particle {
        mass: 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3) * density,
        radius,
        position,
        velocity,
        spin: Vec3::zeros(),
    }
}

fn no_gravity() -> Gravity {
    Gravity {
        uniform: Vec3::zeros(),
        self_gravity: None,
        g: 6.674e-11,
    }
}

/// Head-on collision of two unequal spheres; returns the measured restitution.
fn restitution(eps_n: f64) -> f64 {
    let a = sphere(1.0, 2000.0, Vec3::new(-1.05, 0.0, 0.0), Vec3::new(0.3, 0.0, 0.0));
    let b = sphere(0.7, 3000.0, Vec3::new(0.75, 0.0, 0.0), Vec3::new(-0.2, 0.0, 0.0));
    let material = Material {
        eps_n,
        ..Material::nominal(1e7)
    };
    let mu = a.mass * b.mass / (a.mass + b.mass);
    let dt = std::f64::consts::PI * (mu / material.k_n).sqrt() / 200.0;
    let mut sys = SoftSystem::new(vec![a, b], Vec::new(), material, no_gravity());
    sys.compute_forces(0.0, 0.0);
    let before = sys.particles[1].velocity.x - sys.particles[0].velocity.x;
    let mut touched = false;
    for k in 0..200_000 {
        leapfrog::step(&mut sys, k as f64 * dt, dt);
        let touching = sys.stats.pair_contacts > 0;
        touched |= touching;
        if touched && !touching {
            break;
        }
    }
    assert!(touched && sys.stats.pair_contacts == 0, "collision did not complete");
    let after = sys.particles[1].velocity.x - sys.particles[0].velocity.x;
    -after / before
}

#[test]
fn head_on_collision_returns_the_requested_restitution() {
    for eps in [0.2, 0.55, 0.9] {
        let measured = restitution(eps);
        let rel = (measured - eps).abs() / eps;
        println!("eps_n = {eps}: measured {measured:.6} (relative error {rel:.2e})");
        assert!(rel < 0.01, "eps_n = {eps}: measured {measured}");
    }
}

/// A sphere on a floor under 1 g, launched at `v0` along x without spin; returns the system after `t` seconds
/// and the largest ratio of rolling torque to its cap seen.
fn slide(material: Material, v0: f64, t: f64) -> (SoftSystem, f64) {
    let r = 0.1;
    let mut p = sphere(r, 2500.0, Vec3::zeros(), Vec3::new(v0, 0.0, 0.0));
    let g = 9.81;
    p.position.z = r - p.mass * g / material.k_n; // resting overlap: no bounce
    let floor = Wall::Plane(Plane {
        point: Vec3::zeros(),
        normal: Vec3::z(),
        oscillation: None,
    });
    let gravity = Gravity {
        uniform: Vec3::new(0.0, 0.0, -g),
        ..no_gravity()
    };
    let dt = std::f64::consts::PI * (p.mass / material.k_n).sqrt() / 50.0;
    let mut sys = SoftSystem::new(vec![p], vec![floor], material, gravity);
    sys.keep_records = true;
    sys.compute_forces(0.0, 0.0);
    let mut worst: f64 = 0.0;
    let steps = (t / dt) as u64;
    for k in 0..steps {
        leapfrog::step(&mut sys, k as f64 * dt, dt);
        for rec in &sys.records {
            let cap = material.mu_r * material.beta * r * rec.output.normal_force;
            if cap > 0.0 {
                worst = worst.max(rec.output.rolling_torque / cap);
            }
        }
    }
    (sys, worst)
}

#[test]
fn sliding_sphere_ends_rolling_at_five_sevenths() {
    for mu_s in [1.0, 10.0] {
        let material = Material {
            mu_s,
            beta: 0.0,
            ..Material::nominal(1e6)
        };
        let (sys, _) = slide(material, 1.0, 1.0);
        let p = &sys.particles[0];
        let v = p.velocity.x;
        let rolling = p.spin.y * (p.radius - 1e-5);
        println!(
            "mu_s = {mu_s}: v = {v:.6} (5/7 = {:.6}), omega r = {rolling:.6}",
            5.0 / 7.0
        );
        assert!((v - 5.0 / 7.0).abs() < 0.01 * 5.0 / 7.0, "mu_s = {mu_s}: v = {v}");
        assert!(
            (rolling - v).abs() < 0.01 * v,
            "not rolling: omega r = {rolling}, v = {v}"
        );
    }
}

#[test]
fn rolling_resistance_stops_the_sphere_within_its_torque_cap() {
    let material = Material {
        mu_s: 1.0,
        ..Material::nominal(1e6)
    };
    let (sys, worst) = slide(material, 1.0, 1.5);
    let p = &sys.particles[0];
    println!(
        "with rolling resistance: v = {:.3e} m/s, spin = {:.3e} rad/s, max M_R / (mu_R beta R |F_N|) = {worst:.12}",
        p.velocity.x, p.spin.y
    );
    assert!(p.velocity.x.abs() < 1e-3, "still moving: v = {}", p.velocity.x);
    assert!(p.spin.norm() < 1e-2, "still spinning: {}", p.spin.norm());
    assert!(worst <= 1.0 + 1e-12, "rolling torque exceeded its cap by {worst}");
    assert!(
        worst > 0.99,
        "the cap was never reached ({worst}): the test would not catch an excess"
    );
}
