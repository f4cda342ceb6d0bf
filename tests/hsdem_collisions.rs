//! Acceptance: particle–particle resolution (Richardson11 §2.1, ≈Eq. 4; notes `shared/notes/hsdem.md`) conserves
//! linear and angular momentum to round-off for any ε, energy for ε_n = 1 with ε_t = ±1, and otherwise loses exactly
//! `½μ(1−ε_n²)u_n² + ½μβ(1−ε_t²)|u_t|²` (written here independently of the crate).

mod common;

use common::Random;
use rubblepile::granular::hard::collision::{Body, Restitution, resolve_pair};
use rubblepile::math::Vec3;

fn random_pair(rng: &mut Random) -> (Body, Body) {
    let (m1, m2) = (rng.range(0.1, 10.0), rng.range(0.1, 10.0));
    let (r1, r2) = (rng.range(0.1, 2.0), rng.range(0.1, 2.0));
    let n = loop {
        let n = rng.vec3(1.0);
        if n.norm() > 0.2 {
            break n.normalize();
        }
    };
    let p1 = rng.vec3(5.0);
    let b1 = Body {
        mass: m1,
        radius: r1,
        inertia: 0.4 * m1 * r1 * r1,
        position: p1,
        velocity: rng.vec3(2.0),
        spin: rng.vec3(3.0),
    };
    let b2 = Body {
        mass: m2,
        radius: r2,
        inertia: 0.4 * m2 * r2 * r2,
        position: p1 + n * (r1 + r2),
        velocity: rng.vec3(2.0),
        spin: rng.vec3(3.0),
    };
    (b1, b2)
}

fn momentum(b: &[&Body]) -> Vec3 {
    b.iter().map(|b| b.velocity * b.mass).sum()
}
fn angular(b: &[&Body]) -> Vec3 {
    b.iter()
        .map(|b| b.position.cross(&b.velocity) * b.mass + b.spin * b.inertia)
        .sum()
}
fn energy(b: &[&Body]) -> f64 {
    b.iter()
        .map(|b| 0.5 * b.mass * b.velocity.norm_squared() + 0.5 * b.inertia * b.spin.norm_squared())
        .sum()
}

#[test]
fn momenta_conserved_energy_loss_closed_form() {
    let mut rng = Random::new(11);
    let (mut worst_p, mut worst_l, mut worst_e, mut worst_elastic) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut done = 0;
    while done < 20_000 {
        let (mut b1, mut b2) = random_pair(&mut rng);
        let n = (b2.position - b1.position).normalize();
        let u = (b2.velocity + b2.spin.cross(&(-n * b2.radius))) - (b1.velocity + b1.spin.cross(&(n * b1.radius)));
        let un = u.dot(&n);
        if un >= 0.0 {
            continue;
        }
        done += 1;
        let r = match done % 4 {
            0 => Restitution { eps_n: 1.0, eps_t: 1.0 },
            1 => Restitution {
                eps_n: 1.0,
                eps_t: -1.0,
            },
            _ => Restitution {
                eps_n: rng.range(0.0, 1.0),
                eps_t: rng.range(-1.0, 1.0),
            },
        };
        let (p0, l0, e0) = (momentum(&[&b1, &b2]), angular(&[&b1, &b2]), energy(&[&b1, &b2]));
        let out = resolve_pair(&mut b1, &mut b2, r, 0.0);
        assert!(out.applied);
        let (p1, l1, e1) = (momentum(&[&b1, &b2]), angular(&[&b1, &b2]), energy(&[&b1, &b2]));
        let pscale = b1.mass * 2.0 + b2.mass * 2.0;
        worst_p = worst_p.max((p1 - p0).norm() / pscale);
        let lscale = pscale * 10.0 + (b1.inertia + b2.inertia) * 3.0;
        worst_l = worst_l.max((l1 - l0).norm() / lscale);
        // Closed form: μ = m1 m2/M, β = 1/(1 + μ Σ R²/I) = 2/7 for uniform spheres.
        let mu = b1.mass * b2.mass / (b1.mass + b2.mass);
        let beta = 2.0 / 7.0;
        let ut2 = (u - n * un).norm_squared();
        let loss = 0.5 * mu * (1.0 - r.eps_n * r.eps_n) * un * un + 0.5 * mu * beta * (1.0 - r.eps_t * r.eps_t) * ut2;
        let err = ((e0 - e1) - loss).abs() / e0;
        if r.eps_n == 1.0 && r.eps_t.abs() == 1.0 {
            worst_elastic = worst_elastic.max((e1 - e0).abs() / e0);
        } else {
            worst_e = worst_e.max(err);
        }
        // The contact velocity afterwards: normal reversed and scaled by ε_n, tangential scaled by ε_t.
        let u1 = (b2.velocity + b2.spin.cross(&(-n * b2.radius))) - (b1.velocity + b1.spin.cross(&(n * b1.radius)));
        assert!((u1.dot(&n) + r.eps_n * un).abs() < 1e-12 * u.norm());
        assert!(((u1 - n * u1.dot(&n)) - (u - n * un) * r.eps_t).norm() < 1e-12 * u.norm());
    }
    eprintln!("P {worst_p:e}, L {worst_l:e}, elastic energy {worst_elastic:e}, closed-form loss {worst_e:e}");
    assert!(worst_p < 1e-15, "momentum {worst_p:e}");
    assert!(worst_l < 1e-15, "angular momentum {worst_l:e}");
    assert!(worst_elastic < 1e-14, "elastic energy {worst_elastic:e}");
    assert!(worst_e < 1e-13, "energy loss vs closed form {worst_e:e}");
}
