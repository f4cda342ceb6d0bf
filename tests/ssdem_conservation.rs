//! Conservation and settling: an elastic frictionless gas in a spherical container keeps its energy (drift
//! ≤ 1e-4 over 10⁴ steps); an isolated self-gravitating aggregate keeps its angular momentum (≤ 1e-10 relative
//! with direct gravity, ≤ 1e-5 with the tree); a 2 000-sphere self-gravitating aggregate settles with its
//! largest overlap below 1 % of the radius at the advised k_N and dt.

mod common;
use rubblepile::geometry::walls::soft::{SphereContainer, Wall};
use rubblepile::granular::soft::advise::{AdviceInput, advise};
use rubblepile::granular::soft::contact::Material;
use rubblepile::granular::soft::forces::{Gravity, SoftSystem};
use rubblepile::granular::soft::leapfrog;
use rubblepile::granular::soft::packing::fcc_ball;
use rubblepile::granular::soft::particle::Particle;
use rubblepile::granular::soft::scene::scene_advice;
use rubblepile::gravity::SelfGravity;
use rubblepile::math::Vec3;
use rubblepile::random::{generator, point_in_ball, symmetric};

#[test]
fn elastic_frictionless_gas_conserves_energy() {
    let mut rng = generator(3);
    let r: f64 = 0.1;
    let mass = 4.0 / 3.0 * std::f64::consts::PI * r.powi(3) * 1000.0;
    let mut particles: Vec<Particle> = Vec::new();
    while particles.len() < 150 {
        let x = point_in_ball(&mut rng, 1.0 - r);
        if particles.iter().all(|p| (p.position - x).norm() > 2.0 * r) {
            particles.push(Particle {
                mass,
                radius: r,
                position: x,
                velocity: Vec3::new(
                    symmetric(&mut rng, 2.0),
                    symmetric(&mut rng, 2.0),
                    symmetric(&mut rng, 2.0),
                ),
                spin: Vec3::zeros(),
            });
        }
    }
    let a = advise(&AdviceInput {
        r_min: r,
        m_min: mass,
        m_max: mass,
        speed: 4.0,
        body: None,
        spin_period: None,
        max_overlap: 0.01,
        g: 6.674e-11,
    });
    let material = Material {
        eps_n: 1.0,
        eps_t: 1.0,
        mu_s: 0.0,
        beta: 0.0,
        ..Material::nominal(a.k_n)
    };
    let wall = Wall::Sphere(SphereContainer {
        centre: Vec3::zeros(),
        radius: 1.0,
        oscillation: None,
    });
    let gravity = Gravity {
        uniform: Vec3::zeros(),
        self_gravity: None,
        g: 6.674e-11,
    };
    let mut sys = SoftSystem::new(particles, vec![wall], material, gravity);
    sys.compute_forces(0.0, 0.0);
    let e0 = sys.energy();
    let mut worst: f64 = 0.0;
    let mut contacts = 0;
    let dt = a.dt;
    for k in 0..10_000 {
        leapfrog::step(&mut sys, k as f64 * dt, dt);
        contacts += sys.stats.pair_contacts + sys.stats.wall_contacts;
        worst = worst.max((sys.energy() - e0).abs() / e0);
    }
    let end = (sys.energy() - e0) / e0;
    println!(
        "gas: 10^4 steps of {dt:.3e} s, {contacts} contact-steps, max |dE/E| = {worst:.2e}, final {end:.2e}, dissipated {}",
        sys.dissipated
    );
    assert!(
        contacts > 5_000,
        "too few collisions ({contacts}) for a meaningful test"
    );
    assert!(worst <= 1e-4, "energy drift {worst}");
}

fn spinning_aggregate(gravity: SelfGravity) -> f64 {
    let particles = common::spinning_aggregate_particles();
    let g = Gravity {
        uniform: Vec3::zeros(),
        self_gravity: Some(gravity),
        g: 6.674e-11,
    };
    let a = scene_advice(&particles, &g, 0.0);
    let mut sys = SoftSystem::new(particles, Vec::new(), Material::nominal(a.k_n), g);
    sys.compute_forces(0.0, 0.0);
    let l0 = sys.angular_momentum();
    let mut worst: f64 = 0.0;
    for k in 0..3000 {
        leapfrog::step(&mut sys, k as f64 * a.dt, a.dt);
        worst = worst.max((sys.angular_momentum() - l0).norm() / l0.norm());
    }
    assert!(sys.stats.pair_contacts > 100, "the aggregate has too few contacts");
    worst
}

#[test]
fn isolated_aggregate_conserves_angular_momentum() {
    let direct = spinning_aggregate(SelfGravity::Direct);
    let tree = spinning_aggregate(SelfGravity::Tree { theta: 0.5 });
    println!("angular momentum over 3000 steps: direct {direct:.2e}, tree {tree:.2e}");
    assert!(direct <= 1e-10, "direct: {direct}");
    assert!(tree <= 1e-5, "tree: {tree}");
}

#[test]
fn aggregate_of_2000_settles_within_one_percent_overlap() {
    // Touching spheres on an FCC lattice (Zhang17's HCP aggregate has the same density); gravity compresses
    // the body, the compression wave crosses it in ~ 20 contact times.
    let particles = fcc_ball(2000, 10.0, 2000.0, 0.0);
    let g = Gravity {
        uniform: Vec3::zeros(),
        self_gravity: Some(SelfGravity::Tree { theta: 0.7 }),
        g: 6.674e-11,
    };
    let a = scene_advice(&particles, &g, 0.0);
    let mut sys = SoftSystem::new(particles, Vec::new(), Material::nominal(a.k_n), g);
    sys.compute_forces(0.0, 0.0);
    let start = std::time::Instant::now();
    let mut max_overlap: f64 = 0.0;
    let steps = 1200;
    for k in 0..steps {
        leapfrog::step(&mut sys, k as f64 * a.dt, a.dt);
        max_overlap = max_overlap.max(sys.stats.max_overlap_fraction);
    }
    let ke = sys.kinetic_energy();
    let binding = sys.stats.gravitational_energy.abs();
    println!(
        "2000 spheres, k_N = {:.3e} N/m, dt = {:.3e} s, {steps} steps ({:.1} contact times) in {:.1} s: max overlap {max_overlap:.3e} of r, coordination {:.2}, KE/|U| = {:.2e}",
        a.k_n,
        a.dt,
        steps as f64 * a.dt / a.contact_time,
        start.elapsed().as_secs_f64(),
        sys.coordination_number(),
        ke / binding
    );
    assert!(max_overlap < 0.01, "max overlap {max_overlap}");
    assert!(
        max_overlap > 0.0 && sys.coordination_number() > 9.0,
        "the aggregate is not in contact"
    );
    assert!(ke < 1e-6 * binding, "not settled: KE {ke} vs |U| {binding}");
}
