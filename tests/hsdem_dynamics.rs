//! Acceptance: walls and stepping of the hard-sphere engine (Richardson11 §2; notes `shared/notes/hsdem.md`):
//! sticky and absorbing walls, energy pumped by an oscillating plate, spin-up by a spinning cylinder, the
//! inelastic-collapse guard, and 10⁵ collisions in a dense elastic box (overlap and energy).

mod common;

use rubblepile::geometry::walls::{Oscillation, Shape, Wall};
use rubblepile::granular::hard::particle::Particle;
use rubblepile::granular::hard::stepper::{StepError, StepperSettings, System};
use rubblepile::math::Vec3;

fn gravity() -> StepperSettings {
    StepperSettings {
        gravity: Some(Vec3::new(0.0, 0.0, -9.81)),
        ..Default::default()
    }
}

#[test]
fn sticky_wall_holds() {
    // A plane translating along x and oscillating along z; a ball falls onto it and must ride along, touching.
    let mut wall = Wall::new(Shape::Plane, Vec3::zeros(), Vec3::z());
    wall.sticky = true;
    wall.motion.velocity = Vec3::new(0.3, 0.0, 0.0);
    wall.motion.oscillation = Some(Oscillation {
        amplitude: 0.02,
        omega: 10.0,
        phase: 0.0,
        direction: Vec3::z(),
    });
    let ball = Particle::new(0, 1.0, 0.05, Vec3::new(0.0, 0.0, 0.5), Vec3::zeros(), Vec3::zeros());
    let mut sys = System::new(vec![ball], vec![wall], gravity());
    let mut stuck_dx = None;
    for k in 0..2000 {
        sys.step(1e-3).unwrap();
        let p = &sys.particles[0];
        if p.stuck.is_some() {
            stuck_dx.get_or_insert(p.position.x - sys.walls[0].origin_at(sys.t).x);
            let gap = p.position.z - sys.walls[0].origin_at(sys.t).z - p.radius;
            assert!(gap.abs() < 1e-12, "gap {gap:e} at step {k}");
        }
    }
    let dx0 = stuck_dx.expect("the ball reached the sticky plane");
    let p = &sys.particles[0];
    // Held: it moved along x with the plane since it stuck (same offset from the plane's reference point).
    let dx = p.position.x - sys.walls[0].origin_at(sys.t).x;
    assert!(
        (dx - dx0).abs() < 1e-12,
        "x offset from the plane moved from {dx0} to {dx}"
    );
    assert!((p.velocity.x - 0.3).abs() < 1e-9, "vx {}", p.velocity.x);
    assert_eq!(sys.counters.wall_collisions, 1);

    // A spinning sticky cylinder carries the particle round its axis at constant radius.
    let mut cyl = Wall::new(
        Shape::Cylinder {
            radius: 1.0,
            length: None,
        },
        Vec3::zeros(),
        Vec3::z(),
    );
    cyl.sticky = true;
    cyl.motion.spin = 2.0;
    let p = Particle::new(0, 1.0, 0.1, Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0), Vec3::zeros());
    let mut sys = System::new(vec![p], vec![cyl], StepperSettings::default());
    for _ in 0..1000 {
        sys.step(1e-3).unwrap();
    }
    let p = &sys.particles[0];
    let a = p.stuck.expect("stuck");
    let rho = (p.position.x.powi(2) + p.position.y.powi(2)).sqrt();
    assert!((rho - 0.9).abs() < 1e-12, "radius {rho}");
    let angle = p.position.y.atan2(p.position.x);
    let expect = 2.0 * (sys.t - a.t_stuck);
    assert!((angle - expect).abs() < 1e-9, "angle {angle} vs {expect}");
}

#[test]
fn absorbing_wall_removes_and_counts() {
    let mut wall = Wall::new(Shape::Disk { radius: 1.0 }, Vec3::new(0.0, 0.0, -1.0), Vec3::z());
    wall.absorbing = true;
    let mut ps = Vec::new();
    for k in 0..10 {
        let x = -0.9 + 0.2 * k as f64;
        ps.push(Particle::new(
            k,
            1.0,
            0.05,
            Vec3::new(x, 0.0, 0.0),
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::zeros(),
        ));
    }
    // Two that miss the disk (outside its rim).
    ps.push(Particle::new(
        10,
        1.0,
        0.05,
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::zeros(),
    ));
    ps.push(Particle::new(
        11,
        1.0,
        0.05,
        Vec3::new(0.0, 0.0, 0.5),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::zeros(),
    ));
    let mut sys = System::new(ps, vec![wall], StepperSettings::default());
    for _ in 0..300 {
        sys.step(1e-2).unwrap();
    }
    assert_eq!(sys.counters.absorbed, 10);
    assert_eq!(sys.particles.iter().filter(|p| p.alive).count(), 2);
    assert!(sys.particles[10].alive && sys.particles[11].alive);
    assert_eq!(sys.diagnostics().free, 2);
}

fn bouncing_ball(amplitude: f64) -> (f64, f64) {
    let mut plate = Wall::new(Shape::Plane, Vec3::zeros(), Vec3::z());
    plate.motion.oscillation = Some(Oscillation {
        amplitude,
        omega: 60.0,
        phase: 0.0,
        direction: Vec3::z(),
    });
    let ball = Particle::new(0, 1.0, 0.01, Vec3::new(0.0, 0.0, 0.0101), Vec3::zeros(), Vec3::zeros());
    let mut sys = System::new(vec![ball], vec![plate], gravity());
    let e0 = sys.diagnostics().energy();
    let mut max_height: f64 = 0.0;
    for _ in 0..5000 {
        sys.step(1e-3).unwrap();
        let p = &sys.particles[0];
        let gap = p.position.z - sys.walls[0].origin_at(sys.t).z - p.radius;
        assert!(gap > -1e-12, "ball inside the plate: {gap:e}");
        max_height = max_height.max(p.position.z);
    }
    (sys.diagnostics().energy() - e0, max_height)
}

#[test]
fn oscillating_plate_pumps_energy() {
    // A ω² = 36 m/s² > g: the plate throws the ball, which gains energy (elastic collisions).
    let (gain, height) = bouncing_ball(0.01);
    eprintln!("oscillating plate: energy gained {gain} J, highest centre {height} m");
    assert!(gain > 0.05, "energy gained {gain}");
    assert!(height > 0.05, "highest {height}");
    // A still plate: nothing gained.
    let (gain, _) = bouncing_ball(0.0);
    assert!(gain.abs() < 1e-12, "still plate changed the energy by {gain}");
}

#[test]
fn spinning_cylinder_spins_up_a_rough_particle() {
    let mut cyl = Wall::new(
        Shape::Cylinder {
            radius: 1.0,
            length: None,
        },
        Vec3::zeros(),
        Vec3::z(),
    );
    cyl.motion.spin = 5.0;
    cyl.eps_t = Some(0.0);
    let p = Particle::new(0, 1.0, 0.1, Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0), Vec3::zeros());
    let mut sys = System::new(vec![p], vec![cyl], StepperSettings::default());
    while sys.counters.wall_collisions == 0 {
        sys.step(1e-2).unwrap();
    }
    let p = &sys.particles[0];
    // ε_t = 0: the contact point moves with the wall after the hit (tangentially).
    let n = -p.position.normalize(); // from the wall contact towards the centre
    let contact = p.position - n * p.radius;
    let wall_v = Vec3::z().cross(&contact) * 5.0;
    let u = p.velocity + p.spin.cross(&(-n * p.radius)) - wall_v;
    let ut = u - n * u.dot(&n);
    assert!(ut.norm() < 1e-12, "tangential slip {ut:?}");
    // It spins now about +z (its outer side touches the wall, which moves counter-clockwise: ω_z R = (5/7) Ω R_c)
    // and orbits counter-clockwise.
    assert!(
        (p.spin.z * p.radius - 5.0 / 7.0 * 5.0).abs() < 1e-12,
        "spin {:?}",
        p.spin
    );
    let lz = p.position.cross(&p.velocity).z;
    assert!(lz > 0.1, "orbital angular momentum {lz}");
    // More collisions spin it up further towards rolling with the wall.
    for _ in 0..500 {
        sys.step(1e-2).unwrap();
    }
    assert!(sys.counters.wall_collisions > 3);
}

fn collapse_system(collapse_speed: f64) -> System {
    // Three spheres in a row closing in, ε_n = 0: the classic inelastic collapse (infinitely many collisions at one
    // instant as the velocities converge).
    let mut ps = Vec::new();
    for (k, (x, v)) in [(-0.5, 1.0), (0.0, 0.0), (0.5, -0.8)].into_iter().enumerate() {
        let mut p = Particle::new(
            k,
            1.0,
            0.1,
            Vec3::new(x, 0.0, 0.0),
            Vec3::new(v, 0.0, 0.0),
            Vec3::zeros(),
        );
        p.eps_n = 0.0;
        ps.push(p);
    }
    System::new(
        ps,
        vec![],
        StepperSettings {
            gravity: None,
            collapse_speed,
            max_events_per_step: 5000,
            ..Default::default()
        },
    )
}

#[test]
fn inelastic_collapse_guard() {
    let mut guarded = collapse_system(1e-6);
    for _ in 0..100 {
        guarded.step(0.01).unwrap();
    }
    eprintln!(
        "guarded: {} events, {} made elastic",
        guarded.counters.events, guarded.counters.guarded
    );
    assert!(guarded.counters.guarded > 0);
    assert!(guarded.counters.events < 200, "{} events", guarded.counters.events);
    // Without the guard the same system needs many more events, or stalls.
    let mut bare = collapse_system(0.0);
    let mut stalled = false;
    for _ in 0..100 {
        match bare.step(0.01) {
            Ok(()) => {}
            Err(StepError::Stalled { .. }) => {
                stalled = true;
                break;
            }
            Err(e) => panic!("{e}"),
        }
    }
    eprintln!("unguarded: {} events, stalled {stalled}", bare.counters.events);
    // (Three spheres: round-off ends the collapse once the velocities agree to the last bit, after ~60 events.)
    assert!(stalled || bare.counters.events > 2 * guarded.counters.events);
}

#[test]
fn dense_elastic_box_overlap_and_energy() {
    // 400 rough elastic spheres (ε_n = 1, ε_t = −1) of radius 0.04 in the unit box bounded by six planes,
    // volume fraction 0.27.
    let r = 0.04;
    let (ps, walls) = common::hard_sphere_box(3, 400, 1.0);
    let mut sys = System::new(ps, walls, StepperSettings::default());
    let d0 = sys.diagnostics();
    let start = std::time::Instant::now();
    while sys.counters.pair_collisions + sys.counters.wall_collisions < 100_000 {
        sys.step(0.01).unwrap();
    }
    let secs = start.elapsed().as_secs_f64();
    let d = sys.diagnostics();
    let de = (d.energy() - d0.energy()).abs() / d0.energy();
    // Every particle stays inside the box and no pair overlaps (beyond round-off).
    let mut overlap: f64 = 0.0;
    for (a, p) in sys.particles.iter().enumerate() {
        for c in 0..3 {
            overlap = overlap.max((r - p.position[c]) / r).max((p.position[c] + r - 1.0) / r);
        }
        for q in &sys.particles[a + 1..] {
            overlap = overlap.max((2.0 * r - (p.position - q.position).norm()) / r);
        }
    }
    eprintln!(
        "dense box: {} collisions ({} pair) in {:.2} s ({:.3e} events/s), energy error {de:e}, max overlap at collisions {:e}, final {overlap:e}, rebuilds {}",
        sys.counters.pair_collisions + sys.counters.wall_collisions,
        sys.counters.pair_collisions,
        secs,
        sys.counters.events as f64 / secs,
        sys.counters.max_overlap,
        sys.counters.rebuilds
    );
    assert!(de <= 1e-10, "energy error {de:e}");
    assert!(
        sys.counters.max_overlap <= 1e-9,
        "max overlap {:e}",
        sys.counters.max_overlap
    );
    assert!(overlap <= 1e-9, "final overlap {overlap:e}");
}
