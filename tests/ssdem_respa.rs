//! Self-gravity every k steps (r-RESPA, `src/granular/soft/respa.rs`) against every-step gravity: a
//! gravity-only cloud converges at second order in `k dt`; a spinning self-gravitating aggregate's trajectory
//! with k = 10 stays close to k = 1 and the gap falls with k; with direct gravity and k > 1 linear and
//! angular momentum hold to 1e-10 and the energy residual stays bounded; a run cut by a checkpoint in the
//! middle of a block resumes bit for bit; bad `interval_steps` give one-line errors naming the field.

mod common;
use common::{rubblepile, temp_dir};
use rubblepile::granular::soft::contact::Material;
use rubblepile::granular::soft::forces::{Gravity, SoftSystem};
use rubblepile::granular::soft::leapfrog;
use rubblepile::granular::soft::particle::Particle;
use rubblepile::granular::soft::scene::{parse_soft_scene, scene_advice};
use rubblepile::gravity::SelfGravity;
use rubblepile::math::Vec3;
use rubblepile::random::{generator, symmetric};
use std::path::Path;

fn direct_gravity(g: f64) -> Gravity {
    Gravity {
        uniform: Vec3::zeros(),
        self_gravity: Some(SelfGravity::Direct),
        g,
    }
}

/// Runs `steps` steps of `dt` with self-gravity every `k` steps; returns the final positions.
fn positions_after(mut sys: SoftSystem, k: u64, dt: f64, steps: u64) -> Vec<Vec3> {
    sys.gravity_interval = k;
    sys.compute_forces(0.0, 0.0);
    for s in 0..steps {
        leapfrog::step(&mut sys, s as f64 * dt, dt);
    }
    assert_eq!(sys.gravity_phase, 0, "the run must end on a block boundary");
    sys.particles.iter().map(|p| p.position).collect()
}

fn show(v: &[f64]) -> String {
    v.iter().map(|x| format!("{x:.3e}")).collect::<Vec<_>>().join(", ")
}

/// Largest gap in final positions between self-gravity every `k` steps and every step, over the largest
/// displacement of the every-step run, for each `k` of `ks`.
fn relative_gaps(sys: &SoftSystem, dt: f64, steps: u64, ks: &[u64]) -> Vec<f64> {
    let reference = positions_after(sys.clone(), 1, dt, steps);
    let start: Vec<Vec3> = sys.particles.iter().map(|p| p.position).collect();
    let moved = largest_gap(&reference, &start);
    ks.iter()
        .map(|&k| largest_gap(&positions_after(sys.clone(), k, dt, steps), &reference) / moved)
        .collect()
}

fn largest_gap(a: &[Vec3], b: &[Vec3]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).norm()).fold(0.0, f64::max)
}

#[test]
fn gravity_only_cloud_converges_at_second_order_in_the_block_length() {
    // 27 small spheres 1 m apart (never touching over the run), G = 1, collapsing from rest: with no fast
    // force, k fast steps are one leapfrog step of k dt for gravity, whose error is O((k dt)²).
    let mut rng = generator(5);
    let mut particles = Vec::new();
    for i in 0..27 {
        let p = Vec3::new((i % 3) as f64, (i / 3 % 3) as f64, (i / 9) as f64)
            + Vec3::new(
                symmetric(&mut rng, 0.1),
                symmetric(&mut rng, 0.1),
                symmetric(&mut rng, 0.1),
            );
        particles.push(Particle {
            mass: 1.0,
            radius: 0.01,
            position: p,
            velocity: Vec3::zeros(),
            spin: Vec3::zeros(),
        });
    }
    let sys = SoftSystem::new(particles, Vec::new(), Material::nominal(1e3), direct_gravity(1.0));
    let (dt, steps) = (1e-3, 192);
    let gaps = relative_gaps(&sys, dt, steps, &[4, 8, 16]);
    println!(
        "gravity-only cloud, largest position gap / largest displacement at k = 4, 8, 16: {}",
        show(&gaps)
    );
    for w in gaps.windows(2) {
        let order = (w[1] / w[0]).log2();
        assert!((1.7..2.4).contains(&order), "order {order} (gaps {gaps:?})");
    }
    assert!(gaps[2] < 1e-2, "k = 16: {}", gaps[2]);
}

/// The spinning 120-sphere aggregate of `ssdem_conservation.rs` (real G), with direct gravity.
fn spinning_aggregate() -> (SoftSystem, f64) {
    let particles = common::spinning_aggregate_particles();
    let g = direct_gravity(6.674e-11);
    let a = scene_advice(&particles, &g, 0.0);
    assert_eq!(a.gravity_interval, 10, "advised k at the advised step");
    (
        SoftSystem::new(particles, Vec::new(), Material::nominal(a.k_n), g),
        a.dt,
    )
}

#[test]
fn aggregate_trajectory_with_k_steps_approaches_every_step_gravity() {
    let (sys, dt) = spinning_aggregate();
    let steps = 600;
    let gaps = relative_gaps(&sys, dt, steps, &[10, 5, 2]);
    println!(
        "aggregate, largest position gap / largest displacement at k = 10, 5, 2: {}",
        show(&gaps)
    );
    assert!(
        gaps[0] > gaps[1] && gaps[1] > gaps[2],
        "gap does not fall with k: {gaps:?}"
    );
    assert!(gaps[0] < 1e-2, "k = 10: {}", gaps[0]);
}

#[test]
fn direct_gravity_every_k_steps_conserves_momenta_and_bounds_energy() {
    let (sys0, dt) = spinning_aggregate();
    let mut residuals = Vec::new();
    for k in [1, 10] {
        let mut sys = sys0.clone();
        sys.gravity_interval = k;
        sys.compute_forces(0.0, 0.0);
        let (p0, l0, e0) = (sys.momentum(), sys.angular_momentum(), sys.energy());
        let p_scale: f64 = sys.particles.iter().map(|p| p.mass * p.velocity.norm()).sum();
        let (mut worst_l, mut worst_p, mut worst_e): (f64, f64, f64) = (0.0, 0.0, 0.0);
        for s in 0..3000 {
            leapfrog::step(&mut sys, s as f64 * dt, dt);
            worst_l = worst_l.max((sys.angular_momentum() - l0).norm() / l0.norm());
            worst_p = worst_p.max((sys.momentum() - p0).norm() / p_scale);
            if sys.gravity_phase == 0 {
                worst_e = worst_e.max(((sys.energy() + sys.dissipated - e0) / e0).abs());
            }
        }
        assert!(sys.stats.pair_contacts > 100, "the aggregate has too few contacts");
        println!("k = {k}: angular momentum {worst_l:.2e}, momentum {worst_p:.2e}, energy residual {worst_e:.2e}");
        assert!(worst_l <= 1e-10, "k = {k}: angular momentum {worst_l}");
        assert!(worst_p <= 1e-10, "k = {k}: momentum {worst_p}");
        residuals.push(worst_e);
    }
    assert!(
        residuals[1] <= 2.0 * residuals[0] + 1e-6,
        "energy residual with k = 10 ({}) far above k = 1 ({})",
        residuals[1],
        residuals[0]
    );
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Ten spheres at rest in a loose self-gravitating clump (G = 1e-3) inside a spherical container.
fn scene(gravity_extra: &str) -> String {
    let mut s = format!(
        "[scene]\nkind = \"soft-spheres\"\nt_end = 0.5\nseed = 1\n\n[stepping]\ndt = 2e-4\n\n[material]\nk_n = 2e5\n\n\
         [gravity]\nself = \"direct\"\nG = 1e-3\n{gravity_extra}\n\n[output]\nevery = 0.05\n\n\
         [[wall]]\nkind = \"sphere\"\ncentre = [0.0, 0.0, 0.0]\nradius = 0.6\n"
    );
    for k in 0..10 {
        let (x, y, z) = (
            -0.3 + 0.2 * (k % 4) as f64,
            -0.2 + 0.2 * (k / 4) as f64,
            0.03 * k as f64,
        );
        s += &format!(
            "\n[[particle]]\nradius = 0.08\ndensity = 2500.0\nposition = [{x}, {y}, {z}]\nvelocity = [0.0, {}, 0.0]\n",
            0.05 * (k % 3) as f64
        );
    }
    s
}

fn run(dir: &Path, out: &str, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["run", "s.toml", "--out", out, "--no-progress"];
    args.extend_from_slice(extra);
    rubblepile(dir, &args)
}

#[test]
fn run_cut_by_a_checkpoint_inside_a_gravity_block_resumes_bit_for_bit() {
    let dir = temp_dir("ssdem-respa");
    // 2500 steps in blocks of 7: rows every 250 steps and the checkpoint at step 500 fall inside blocks.
    std::fs::write(dir.join("s.toml"), scene("interval_steps = 7")).unwrap();
    let a = run(&dir, "a", &[]);
    assert!(a.status.success(), "{}", String::from_utf8_lossy(&a.stderr));
    let summary: serde_json::Value = serde_json::from_str(&read(&dir.join("a/summary.json"))).unwrap();
    assert_eq!(summary["self_gravity"], "direct, every 7 steps");
    let c = run(
        &dir,
        "c",
        &["--checkpoint-every-sim-s", "0.1", "--stop-after-checkpoints", "1"],
    );
    assert_eq!(c.status.code(), Some(3), "{}", String::from_utf8_lossy(&c.stderr));
    let ck: serde_json::Value = serde_json::from_str(&read(&dir.join("c/checkpoint.json"))).unwrap();
    assert_eq!(ck["engine"]["step"], 500);
    assert_eq!(
        ck["engine"]["gravity_phase"],
        500 % 7,
        "the checkpoint is not inside a block"
    );
    let r = rubblepile(&dir, &["resume", "c", "--no-progress"]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let strip = |d: &str| -> Vec<String> {
        read(&dir.join(d).join("timeseries.csv"))
            .lines()
            .map(|l| l.rsplit_once(',').unwrap().0.to_string())
            .collect()
    };
    assert_eq!(strip("a"), strip("c"), "time series differs after resume");
    assert_eq!(
        read(&dir.join("a/snapshots/1.csv")),
        read(&dir.join("c/snapshots/1.csv")),
        "final snapshot differs after resume"
    );
}

#[test]
fn bad_interval_steps_name_the_field() {
    for (extra, expect) in [
        ("interval_steps = 0", "must be an integer >= 1 (steps), got 0"),
        ("interval_steps = -3", "got -3"),
    ] {
        let err = parse_soft_scene(&scene(extra), "s.toml", None).unwrap_err().to_string();
        assert!(err.contains("gravity.interval_steps") && err.contains(expect), "{err}");
    }
    let no_self = scene("interval_steps = 4").replace("self = \"direct\"\n", "");
    let err = parse_soft_scene(&no_self, "s.toml", None).unwrap_err().to_string();
    assert!(
        err.contains("gravity.interval_steps") && err.contains("only used with self"),
        "{err}"
    );
    let ok = parse_soft_scene(&scene("interval_steps = 5"), "s.toml", None).unwrap();
    assert_eq!(ok.gravity_interval, 5);
    assert!(ok.warnings.is_empty(), "{:?}", ok.warnings);
}
