//! Acceptance: every wall primitive's time of impact against brute-force bracketing of the distance function
//! (Richardson11 §2.2; notes `shared/notes/hsdem.md`), on 10⁵ random trajectories per primitive, starting inside
//! and outside, with static and moving walls. The distance functions here are written from the geometry alone,
//! independently of the crate's `nearest`.

mod common;

use common::Random;
use rubblepile::geometry::walls::{Shape, Wall};
use rubblepile::math::Vec3;

const TRAJECTORIES: usize = 100_000;
const SAMPLES: usize = 1000;
const H: f64 = 1.0;

/// Distance from `x` to the primitive placed at `o` with unit axis `a`.
fn distance(shape: &Shape, o: &Vec3, a: &Vec3, x: &Vec3) -> f64 {
    let q = x - o;
    let z = q.dot(a);
    let rho = (q - a * z).norm();
    match *shape {
        Shape::Plane => z.abs(),
        Shape::Disk { radius } => {
            if rho <= radius {
                z.abs()
            } else {
                ((rho - radius).powi(2) + z * z).sqrt()
            }
        }
        Shape::Ring { radius } => ((rho - radius).powi(2) + z * z).sqrt(),
        Shape::Cylinder { radius, length } => match length {
            Some(l) if z.abs() > 0.5 * l => ((rho - radius).powi(2) + (z.abs() - 0.5 * l).powi(2)).sqrt(),
            _ => (rho - radius).abs(),
        },
        Shape::Point => q.norm(),
        Shape::Line { length } => match length {
            Some(l) if z.abs() > 0.5 * l => (rho * rho + (z.abs() - 0.5 * l).powi(2)).sqrt(),
            _ => rho,
        },
    }
}

struct Case {
    shape: Shape,
    o: Vec3,
    a: Vec3,
    vw: Vec3,
    r: Vec3,
    v: Vec3,
    s: f64,
}

impl Case {
    fn f(&self, t: f64) -> f64 {
        distance(&self.shape, &(self.o + self.vw * t), &self.a, &(self.r + self.v * t)) - self.s
    }

    /// First time the gap becomes ≤ 0 in [0, H], by sampling, local-minimum search and bisection; with the
    /// deepest penetration found (for classifying grazing contacts).
    fn brute_force(&self) -> (Option<f64>, f64) {
        let dt = H / SAMPLES as f64;
        let fs: Vec<f64> = (0..=SAMPLES).map(|k| self.f(k as f64 * dt)).collect();
        let mut depth = fs.iter().cloned().fold(f64::INFINITY, f64::min);
        for k in 1..=SAMPLES {
            if fs[k] <= 0.0 {
                return (Some(self.bisect((k - 1) as f64 * dt, k as f64 * dt)), depth);
            }
            // A dip between samples: minimise around a sampled local minimum.
            if k < SAMPLES && fs[k] <= fs[k - 1] && fs[k] <= fs[k + 1] {
                let (tm, fm) = self.golden((k - 1) as f64 * dt, (k + 1) as f64 * dt);
                depth = depth.min(fm);
                if fm <= 0.0 {
                    let lo = (k - 1) as f64 * dt;
                    let first = if self.f(lo) > 0.0 { self.bisect(lo, tm) } else { lo };
                    return (Some(first), depth);
                }
            }
        }
        (None, depth)
    }

    fn bisect(&self, mut a: f64, mut b: f64) -> f64 {
        for _ in 0..200 {
            let m = 0.5 * (a + b);
            if m <= a || m >= b {
                break;
            }
            if self.f(m) > 0.0 {
                a = m;
            } else {
                b = m;
            }
        }
        b
    }

    fn golden(&self, mut a: f64, mut b: f64) -> (f64, f64) {
        let g = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..80 {
            let (c, d) = (b - g * (b - a), a + g * (b - a));
            if self.f(c) < self.f(d) {
                b = d;
            } else {
                a = c;
            }
        }
        let t = 0.5 * (a + b);
        (t, self.f(t))
    }
}

/// Runs the comparison for one primitive family; returns (hits, grazing ambiguities, worst |Δt|/H).
fn check(name: &str, seed: u64, make: impl Fn(&mut Random) -> Shape) -> (usize, usize, f64) {
    let mut rng = Random::new(seed);
    let (mut hits, mut grazing, mut worst) = (0usize, 0usize, 0.0f64);
    let mut n = 0;
    while n < TRAJECTORIES {
        let shape = make(&mut rng);
        let a = loop {
            let a = rng.vec3(1.0);
            if a.norm() > 0.2 {
                break a.normalize();
            }
        };
        let moving = n % 2 == 1;
        let (o, r) = (rng.vec3(0.5), rng.vec3(2.5));
        let vw = if moving { rng.vec3(1.5) } else { Vec3::zeros() };
        // Two trajectories in three are aimed near the wall so that small primitives get hit often.
        let v = if n % 3 == 0 {
            rng.vec3(3.0)
        } else {
            (o + rng.vec3(1.0) - r) * rng.range(0.5, 2.0) + vw + rng.vec3(0.3)
        };
        let case = Case {
            shape,
            o,
            a,
            vw,
            r,
            v,
            s: rng.range(0.05, 0.5),
        };
        if case.f(0.0) <= 1e-9 {
            continue; // start outside the contact
        }
        n += 1;
        let mut wall = Wall::new(shape, case.o, case.a);
        wall.motion.velocity = case.vw;
        let toi = wall.time_of_impact(&case.o, &case.vw, &case.r, &case.v, case.s, H);
        let (bf, depth) = case.brute_force();
        match (toi, bf) {
            (Some(t), Some(b)) => {
                hits += 1;
                let err = (t - b).abs() / H;
                if err > 1e-10 {
                    // Allowed only for a grazing first contact the sampling can place either side of.
                    assert!(
                        depth > -1e-9,
                        "{name}: |Δt| = {err:e} (toi {t}, brute force {b}, depth {depth:e}) shape {shape:?} case r {:?} v {:?} s {} o {:?} a {:?} vw {:?}",
                        case.r,
                        case.v,
                        case.s,
                        case.o,
                        case.a,
                        case.vw
                    );
                    grazing += 1;
                } else {
                    worst = worst.max(err);
                }
            }
            (None, None) => {}
            (Some(t), None) => {
                // Spurious unless the gap really closes to (round-off) zero there.
                assert!(
                    case.f(t).abs() < 1e-9 && depth > -1e-9,
                    "{name}: spurious hit at {t} (gap {:e}) shape {shape:?} r {:?} v {:?} s {} o {:?} a {:?} vw {:?}",
                    case.f(t),
                    case.r,
                    case.v,
                    case.s,
                    case.o,
                    case.a,
                    case.vw
                );
                grazing += 1;
            }
            (None, Some(b)) => {
                assert!(
                    depth > -1e-9,
                    "{name}: missed hit at {b} (depth {depth:e}) shape {shape:?} r {:?} v {:?} s {} o {:?} a {:?} vw {:?}",
                    case.r,
                    case.v,
                    case.s,
                    case.o,
                    case.a,
                    case.vw
                );
                grazing += 1;
            }
        }
    }
    eprintln!("{name}: {TRAJECTORIES} trajectories, {hits} hits, {grazing} grazing, worst |Δt|/h = {worst:e}");
    assert!(
        hits > TRAJECTORIES / 20,
        "{name}: too few hits ({hits}) to test anything"
    );
    assert!(grazing * 1000 < TRAJECTORIES, "{name}: {grazing} grazing ambiguities");
    (hits, grazing, worst)
}

#[test]
fn plane_toi_matches_brute_force() {
    check("plane", 1, |_| Shape::Plane);
}

#[test]
fn disk_toi_matches_brute_force() {
    check("disk", 2, |r| Shape::Disk {
        radius: r.range(0.3, 1.5),
    });
}

#[test]
fn infinite_cylinder_toi_matches_brute_force() {
    check("cylinder", 3, |r| Shape::Cylinder {
        radius: r.range(0.3, 2.0),
        length: None,
    });
}

#[test]
fn finite_cylinder_toi_matches_brute_force() {
    check("finite cylinder", 4, |r| Shape::Cylinder {
        radius: r.range(0.3, 2.0),
        length: Some(r.range(0.2, 3.0)),
    });
}

#[test]
fn ring_toi_matches_brute_force() {
    // Radii both above and below the particle radii (spindle tori included).
    check("ring", 5, |r| Shape::Ring {
        radius: r.range(0.02, 1.5),
    });
}

#[test]
fn point_toi_matches_brute_force() {
    check("point", 6, |_| Shape::Point);
}

#[test]
fn line_toi_matches_brute_force() {
    check("line", 7, |_| Shape::Line { length: None });
    check("segment", 8, |r| Shape::Line {
        length: Some(r.range(0.2, 3.0)),
    });
}

#[test]
fn touching_and_approaching_collides_now() {
    let wall = Wall::new(Shape::Plane, Vec3::zeros(), Vec3::z());
    // Overlapping by 1e-13 and approaching: t = 0.
    let r = Vec3::new(0.0, 0.0, 0.1 - 1e-13);
    let t = wall.time_of_impact(&Vec3::zeros(), &Vec3::zeros(), &r, &Vec3::new(0.0, 0.0, -1.0), 0.1, 1.0);
    assert_eq!(t, Some(0.0));
    // Overlapping and leaving: no event.
    let t = wall.time_of_impact(&Vec3::zeros(), &Vec3::zeros(), &r, &Vec3::new(0.0, 0.0, 1.0), 0.1, 1.0);
    assert_eq!(t, None);
    // Inside a cylinder, just bounced off the wall and leaving it: the far side is found.
    let cyl = Wall::new(
        Shape::Cylinder {
            radius: 1.0,
            length: None,
        },
        Vec3::zeros(),
        Vec3::z(),
    );
    let r = Vec3::new(0.9, 0.0, 0.0);
    let t = cyl
        .time_of_impact(
            &Vec3::zeros(),
            &Vec3::zeros(),
            &r,
            &Vec3::new(-1.0, 0.0, 0.0),
            0.1,
            10.0,
        )
        .unwrap();
    assert!((t - 1.8).abs() < 1e-14, "{t}");
}
