//! Helpers shared by the integration tests: a seeded random source and random bodies.
#![allow(dead_code)]

use rand_core::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use rubblepile::math::{Vec3, Vec4};

/// Seeded uniform random numbers for reproducible tests.
pub struct Random(Pcg64);

impl Random {
    pub fn new(seed: u64) -> Self {
        Random(Pcg64::seed_from_u64(seed))
    }
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }
    pub fn vec3(&mut self, scale: f64) -> Vec3 {
        Vec3::new(
            self.range(-scale, scale),
            self.range(-scale, scale),
            self.range(-scale, scale),
        )
    }
    /// A random unit quaternion (scalar last).
    pub fn unit_quaternion(&mut self) -> Vec4 {
        loop {
            let q = Vec4::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            let n = q.norm();
            if n > 0.2 && n < 1.0 {
                return q / n;
            }
        }
    }
    /// Semi-axes A ≥ B ≥ C with A in [a_lo, a_hi].
    pub fn axes(&mut self, a_lo: f64, a_hi: f64) -> Vec3 {
        let a = self.range(a_lo, a_hi);
        let b = a * self.range(0.4, 1.0);
        let c = b * self.range(0.4, 1.0);
        Vec3::new(a, b, c)
    }
}

/// Relative error of `approx` against `exact`, by vector norm, with a floor on the scale.
pub fn rel_err(approx: &[f64], exact: &[f64], floor: f64) -> f64 {
    let diff: f64 = approx
        .iter()
        .zip(exact)
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f64>()
        .sqrt();
    let scale: f64 = exact.iter().map(|b| b * b).sum::<f64>().sqrt().max(floor);
    diff / scale
}

use rubblepile::ellipsoid::body::{Body, Ellipsoid};
use rubblepile::ellipsoid::equations::{Diagnostics, EllipsoidSystem};
use rubblepile::integrate::{Method, OdeSystem, Stats, Tolerances, make_integrator};

/// A body of density 3000 kg/m³.
pub fn rock(axes: [f64; 3], position: [f64; 3], velocity: [f64; 3], quaternion: Vec4, spin_body: [f64; 3]) -> Body {
    let axes = Vec3::from(axes);
    let mass = 3000.0 * 4.0 / 3.0 * std::f64::consts::PI * axes.x * axes.y * axes.z;
    Body {
        shape: Ellipsoid { axes, mass },
        position: Vec3::from(position),
        velocity: Vec3::from(velocity),
        quaternion,
        spin_body: Vec3::from(spin_body),
    }
}

/// Maxima over a run of the conservation errors, relative to the scales at t = 0.
#[derive(Debug, Clone, Copy, Default)]
pub struct RunErrors {
    pub energy: f64,
    pub momentum: f64,
    pub angular_momentum: f64,
    pub quaternion_norm: f64,
    /// −2∫F dt at the end over the initial kinetic energy.
    pub dissipated_fraction: f64,
}

/// Integrates `sys` to `t_end` with `samples` equally spaced checks; returns the final state, errors, stats.
pub fn integrate(
    sys: &EllipsoidSystem,
    method: Method,
    rtol: f64,
    t_end: f64,
    samples: usize,
) -> (Vec<f64>, RunErrors, Stats) {
    let mut y = sys.initial_state();
    let mut integ = make_integrator(method, Tolerances::uniform(rtol, rtol, sys.dim()), None).unwrap();
    let d0: Diagnostics = sys.diagnostics(&y);
    let mut e = RunErrors::default();
    let mut t = 0.0;
    for k in 1..=samples {
        let target = t_end * k as f64 / samples as f64;
        integ.advance(sys, &mut t, &mut y, target).unwrap();
        let d = sys.diagnostics(&y);
        e.energy = e
            .energy
            .max((d.energy() - d0.energy() - d.dissipated).abs() / d0.energy_scale);
        e.momentum = e.momentum.max((d.momentum - d0.momentum).norm() / d0.momentum_scale);
        e.angular_momentum = e
            .angular_momentum
            .max((d.angular_momentum - d0.angular_momentum).norm() / d0.angular_momentum_scale);
        e.quaternion_norm = e.quaternion_norm.max(d.quaternion_norm_error);
        e.dissipated_fraction = -d.dissipated / (d0.kinetic_translational + d0.kinetic_rotational);
    }
    (y, e, integ.stats())
}

static TEMP_COUNTER: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// A fresh, empty directory under the system temp dir, unique per process, call and time.
pub fn temp_dir(tag: &str) -> std::path::PathBuf {
    let n = TEMP_COUNTER.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .subsec_nanos();
    let dir = std::env::temp_dir().join(format!("rubblepile-test-{tag}-{}-{n}-{nanos}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Every file below `dir` but rubblepile's lock files (every writer, a refused one too, writes its pid into them),
/// as paths relative to `dir`, sorted.
pub fn files_below(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let e = e.unwrap();
            if rubblepile::io::run_lock::is_lock_file(&e.file_name()) {
                continue;
            }
            if e.file_type().unwrap().is_dir() {
                stack.push(e.path());
            } else {
                out.push(e.path().strip_prefix(dir).unwrap().to_path_buf());
            }
        }
    }
    out.sort();
    out
}

/// Runs the `rubblepile` binary with `args` in `cwd`.
pub fn rubblepile(cwd: &std::path::Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_rubblepile"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("run the binary")
}

/// `n` (≤ 512) rough elastic hard spheres (ε_n = 1, ε_t = −1) of radius 0.04 with masses in [0.5, 2), on a jittered
/// 8³ lattice in the unit box, random velocities up to `speed` and spins up to 5 per component, and the box's six
/// plane walls.
pub fn hard_sphere_box(
    seed: u64,
    n: usize,
    speed: f64,
) -> (
    Vec<rubblepile::granular::hard::particle::Particle>,
    Vec<rubblepile::geometry::walls::Wall>,
) {
    use rubblepile::geometry::walls::{Shape, Wall};
    use rubblepile::granular::hard::particle::Particle;
    let mut rng = Random::new(seed);
    let r = 0.04;
    let m = 8; // lattice spacing 1/8 = 0.125 > 2r
    let mut ps = Vec::new();
    for i in 0..m {
        for j in 0..m {
            for k in 0..m {
                if ps.len() == n {
                    continue;
                }
                let c = Vec3::new(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5) / m as f64 + rng.vec3(0.02);
                let mut p = Particle::new(ps.len(), rng.range(0.5, 2.0), r, c, rng.vec3(speed), rng.vec3(5.0));
                p.eps_t = -1.0;
                ps.push(p);
            }
        }
    }
    let corner = Vec3::new(1.0, 1.0, 1.0);
    let walls = [
        (Vec3::zeros(), Vec3::x()),
        (Vec3::zeros(), Vec3::y()),
        (Vec3::zeros(), Vec3::z()),
        (corner, Vec3::x()),
        (corner, Vec3::y()),
        (corner, Vec3::z()),
    ]
    .into_iter()
    .map(|(o, n)| Wall::new(Shape::Plane, o, n))
    .collect();
    (ps, walls)
}

/// The spinning aggregate of the soft-sphere conservation tests: 120 touching spheres of 10 m (grain density
/// 2000 kg/m³, escape speed ~ 2 cm/s) on an FCC lattice, spinning at a tenth of the breakup rate with random
/// jiggles (seed 11), so that contacts slide, roll and twist.
pub fn spinning_aggregate_particles() -> Vec<rubblepile::granular::soft::particle::Particle> {
    use rubblepile::random::{generator, symmetric};
    let mut particles = rubblepile::granular::soft::packing::fcc_ball(120, 10.0, 2000.0, 0.0);
    let mut rng = generator(11);
    let omega = Vec3::new(0.0, 2e-5, 3e-5);
    for p in particles.iter_mut() {
        p.velocity = omega.cross(&p.position) + Vec3::new(symmetric(&mut rng, 1e-3), symmetric(&mut rng, 1e-3), 0.0);
        p.spin = Vec3::new(
            symmetric(&mut rng, 1e-4),
            symmetric(&mut rng, 1e-4),
            symmetric(&mut rng, 1e-4),
        );
    }
    particles
}

/// The files of `dir/snapshots` (name -> bytes), sorted by name.
pub fn snapshots(dir: &std::path::Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir.join("snapshots"))
        .unwrap()
        .map(|e| {
            let p = e.unwrap().path();
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

/// A process's exit code, stdout and stderr, for assertion messages.
pub fn describe(o: &std::process::Output) -> String {
    format!(
        "exit {:?}\nstdout: {}\nstderr: {}",
        o.status.code(),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// A small Table-1-style pile spec for the impact tests: `fragments` of 3000 kg/m³ between `r_largest` and
/// `r_smallest` (m), seed `seed`, its total mass the expected mass of such a draw (the two end radii plus the mean
/// r³ of the Roig03 size law for the others), so that a draw within `mass_tolerance` comes quickly.
pub fn small_pile_spec(
    seed: u64,
    fragments: usize,
    r_largest: f64,
    r_smallest: f64,
    mass_tolerance: f64,
) -> rubblepile::impact::target::TargetSpec {
    let mut spec = rubblepile::impact::target::TargetSpec::table1(30, 6.0, seed).unwrap();
    spec.fragments = fragments;
    spec.r_largest = r_largest;
    spec.r_smallest = r_smallest;
    let (a, b) = (r_largest.powf(-2.5), r_smallest.powf(-2.5));
    let mean_r3 = (0..1000)
        .map(|k| (a + (k as f64 + 0.5) / 1000.0 * (b - a)).powf(-1.2))
        .sum::<f64>()
        / 1000.0;
    spec.total_mass = 3000.0 * 4.0 / 3.0
        * std::f64::consts::PI
        * (r_largest.powi(3) + r_smallest.powi(3) + (fragments - 2) as f64 * mean_r3);
    spec.mass_tolerance = mass_tolerance;
    spec
}
