//! Regression: pair certificates kept across steps (`src/granular/hard/certificates.rs`) and near-wall lists change
//! no result. Uniform kicks leave relative velocities alone, so a pair's certificate (the earliest time it can come
//! within reach) stays valid across steps and a drift start predicts only the pairs whose certificates came due, and
//! only the walls near each particle. Runs so pruned must give the same bits, collisions and counters as runs that
//! predict every listed pair and every wall at every drift start (`prune_predictions = false`), on a gas under gravity
//! with spin exchange, and on a scene with sticky, absorbing, moving, spinning and curved walls (stuck particles are
//! not kicked, so their pairs are predicted at every step).

mod common;

use rubblepile::geometry::walls::{Oscillation, Shape, Wall};
use rubblepile::granular::hard::particle::Particle;
use rubblepile::granular::hard::stepper::{StepperSettings, System};
use rubblepile::math::Vec3;

fn settings(prune_predictions: bool, skin_steps: f64) -> StepperSettings {
    StepperSettings {
        gravity: Some(Vec3::new(0.0, 0.0, -9.81)),
        skin_steps,
        prune_predictions,
        ..Default::default()
    }
}

/// Steps both systems and checks that every particle's state and every counter agree to the bit.
fn same_bits(mut a: System, mut b: System, steps: usize, h: f64) -> System {
    for _ in 0..steps {
        a.step(h).unwrap();
        b.step(h).unwrap();
    }
    for (p, q) in a.particles.iter().zip(&b.particles) {
        assert_eq!(
            (p.position, p.velocity, p.spin, p.alive, p.stuck),
            (q.position, q.velocity, q.spin, q.alive, q.stuck),
            "particle {}",
            p.id
        );
    }
    assert_eq!(a.counters, b.counters, "counters");
    a
}

/// 300 elastic, rough spheres (ε_t = −1) in the unit box under gravity, as in `tests/hsdem_neighbours.rs`.
#[test]
fn pair_certificates_survive_uniform_kicks() {
    for skin in [2.0, 16.0] {
        let (ps, walls) = common::hard_sphere_box(11, 300, 2.0);
        let with = System::new(ps.clone(), walls.clone(), settings(true, skin));
        let without = System::new(ps, walls, settings(false, skin));
        let run = same_bits(with, without, 400, 1e-3);
        let c = run.counters;
        eprintln!(
            "skin {skin}: {} pair + {} wall collisions, {} re-listings",
            c.pair_collisions, c.wall_collisions, c.reanchors
        );
        assert!(c.pair_collisions > 1000, "too few collisions: {}", c.pair_collisions);
    }
}

/// Two sizes of spheres in a cylinder standing on a sticky floor, with an absorbing disk above them and an
/// oscillating plane below the disk's level on one side: stuck particles (not kicked), absorbed ones (the list's
/// floor changes), moving walls (always near) and curved ones.
#[test]
fn certificates_with_stuck_absorbed_and_moving_walls() {
    let mut seed = 7u64;
    let mut rnd = move || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut ps = Vec::new();
    for k in 0..240 {
        let (i, j, l) = (k % 6, (k / 6) % 6, k / 36);
        let r = if k % 3 == 0 { 0.03 } else { 0.02 };
        let c = Vec3::new(-0.3 + 0.12 * i as f64, -0.3 + 0.12 * j as f64, 0.15 + 0.1 * l as f64);
        let v = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * 4.0;
        let mut p = Particle::new(k, 1.0 + rnd(), r, c, v, Vec3::new(rnd(), rnd(), rnd()) * 3.0);
        p.eps_n = 0.9;
        p.eps_t = 0.5;
        ps.push(p);
    }
    let mut floor = Wall::new(Shape::Plane, Vec3::zeros(), Vec3::z());
    floor.sticky = true;
    let mut cylinder = Wall::new(
        Shape::Cylinder {
            radius: 0.5,
            length: None,
        },
        Vec3::zeros(),
        Vec3::z(),
    );
    // Spinning: its surface does not move, so it is listed as a fixed wall, but it drags particles round.
    cylinder.motion.spin = 3.0;
    let mut lid = Wall::new(Shape::Disk { radius: 0.25 }, Vec3::new(0.1, 0.0, 0.9), Vec3::z());
    lid.absorbing = true;
    let mut shaker = Wall::new(Shape::Disk { radius: 0.2 }, Vec3::new(-0.25, 0.0, 0.05), Vec3::z());
    shaker.motion.oscillation = Some(Oscillation {
        amplitude: 0.02,
        omega: 40.0,
        phase: 0.0,
        direction: Vec3::z(),
    });
    let walls = vec![floor, cylinder, lid, shaker];
    let with = System::new(ps.clone(), walls.clone(), settings(true, 16.0));
    let without = System::new(ps, walls, settings(false, 16.0));
    let run = same_bits(with, without, 600, 1e-3);
    let stuck = run.particles.iter().filter(|p| p.alive && p.stuck.is_some()).count();
    let c = run.counters;
    eprintln!(
        "{} pair + {} wall collisions, {stuck} stuck, {} absorbed",
        c.pair_collisions, c.wall_collisions, c.absorbed
    );
    assert!(
        stuck > 20 && c.absorbed > 0 && c.pair_collisions > 200,
        "the scene must exercise every case"
    );
}
