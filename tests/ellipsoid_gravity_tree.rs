//! Gravity among ellipsoid centres (Roig03 Eq. 6) by the octree against the exact pair sum, the choice of
//! method by N, and a `method = "tree"` scene's energy conservation.

use std::path::Path;

use rubblepile::ellipsoid::equations::EllipsoidSystem;
use rubblepile::ellipsoid::gravity::gravity_forces;
use rubblepile::ellipsoid::gravity_tree::{DEFAULT_THETA, GravityMethod, tree_gravity_forces};
use rubblepile::ellipsoid::output::read_bodies_csv;
use rubblepile::ellipsoid::scene::parse_scene;
use rubblepile::integrate::{Method, OdeSystem, Tolerances, make_integrator};
use rubblepile::math::Vec3;

fn targets() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("targets")
}

/// Centres and masses of a committed target.
fn target_points(name: &str) -> (Vec<Vec3>, Vec<f64>) {
    let bodies: Vec<_> = read_bodies_csv(&targets().join(name))
        .unwrap()
        .iter()
        .map(|r| r.to_body())
        .collect();
    (
        bodies.iter().map(|b| b.position).collect(),
        bodies.iter().map(|b| b.shape.mass).collect(),
    )
}

/// RMS over bodies of |F_tree − F_exact| / |F_exact|, and the relative potential error.
fn tree_error(x: &[Vec3], m: &[f64], theta: f64) -> (f64, f64) {
    let g = 6.674e-11;
    let mut exact = vec![Vec3::zeros(); x.len()];
    let u = gravity_forces(g, x, m, &mut exact);
    let mut tree = Vec::new();
    let ut = tree_gravity_forces(g, theta, x, m, &mut tree);
    let sq: f64 = tree
        .iter()
        .zip(&exact)
        .map(|(a, b)| ((a - b).norm() / b.norm()).powi(2))
        .sum();
    ((sq / x.len() as f64).sqrt(), ((ut - u) / u).abs())
}

/// On the relaxed N200_T4 pile (power-law sizes, a 59 km fragment at the centre) the tree at the default
/// θ = 0.5 opens every node (a pile is only a few leaves of 32 across), so its forces are the pair sum's to
/// rounding: a small pile loses nothing by being run with the tree.
#[test]
fn tree_gravity_is_exact_to_rounding_on_the_n200_target() {
    let (x, m) = target_points("N200_T4.csv");
    let (rms, pot) = tree_error(&x, &m, DEFAULT_THETA);
    println!("N200_T4: theta 0.5 RMS force error {rms:.2e}, potential {pot:.2e}");
    assert!(rms < 1e-12 && pot < 1e-12, "theta 0.5: RMS {rms:e}, potential {pot:e}");
}

/// On a 2000-body jittered lattice of ellipsoids (`bench rhs`'s packing, radii 1–5 km) the tree at θ = 0.5 gives
/// the forces to an RMS relative error below 1e-3 and the potential to 1e-4; θ = 0.3 does better.
#[test]
fn tree_gravity_matches_pair_sum_on_a_2000_body_packing() {
    use rubblepile::ellipsoid::cloud::{CloudParams, random_cloud};
    let bodies = random_cloud(2000, 1, &CloudParams::default());
    let x: Vec<Vec3> = bodies.iter().map(|b| b.position).collect();
    let m: Vec<f64> = bodies.iter().map(|b| b.shape.mass).collect();
    let (rms, pot) = tree_error(&x, &m, DEFAULT_THETA);
    let (rms_fine, _) = tree_error(&x, &m, 0.3);
    println!(
        "2000-body packing: theta 0.5 RMS force error {rms:.2e}, potential {pot:.2e}; theta 0.3 RMS {rms_fine:.2e}"
    );
    assert!(rms < 1e-3 && pot < 1e-4, "theta 0.5: RMS {rms:e}, potential {pot:e}");
    assert!(rms_fine < rms, "theta 0.3 ({rms_fine:e}) not better than 0.5 ({rms:e})");
}

/// `copies` copies of the N200_T4 pile on a ring of radius 400 km (in the z = 0 plane).
fn ring_of_piles(copies: usize) -> Vec<rubblepile::ellipsoid::body::Body> {
    let pile: Vec<_> = read_bodies_csv(&targets().join("N200_T4.csv"))
        .unwrap()
        .iter()
        .map(|r| r.to_body())
        .collect();
    let mut out = Vec::new();
    for k in 0..copies {
        let a = k as f64 * std::f64::consts::TAU / copies as f64;
        let shift = Vec3::new(4e5 * a.cos(), 4e5 * a.sin(), 0.0);
        out.extend(pile.iter().map(|b| {
            let mut b = b.clone();
            b.position += shift;
            b
        }));
    }
    out
}

/// The same at N = 2000 (the N200 pile replicated as ten copies on a ring of 400 km, so leaves are used whole
/// and sums run in single precision).
#[test]
fn tree_gravity_matches_pair_sum_when_leaves_are_used_whole() {
    let bodies = ring_of_piles(10);
    let x: Vec<Vec3> = bodies.iter().map(|b| b.position).collect();
    let m: Vec<f64> = bodies.iter().map(|b| b.shape.mass).collect();
    assert!(x.len() >= rubblepile::gravity::octree::FAR_LEAVES_FROM);
    let (rms, pot) = tree_error(&x, &m, DEFAULT_THETA);
    println!("10 x N200_T4: theta 0.5 RMS force error {rms:.2e}, potential {pot:.2e}");
    assert!(rms < 1e-3 && pot < 1e-4, "RMS {rms:e}, potential {pot:e}");
}

/// A scene of the N200_T4 pile, gravity summed by `method`, contact on, no dissipation.
fn pile_scene(method: &str) -> rubblepile::ellipsoid::scene::LoadedScene {
    scene_of(&targets(), "N200_T4.csv", method)
}

/// A scene of the bodies file `dir/file`, gravity summed by `method`, contact on, no dissipation.
fn scene_of(dir: &Path, file: &str, method: &str) -> rubblepile::ellipsoid::scene::LoadedScene {
    let text = format!(
        "[scene]\nkind = \"ellipsoids\"\nt_end = 200.0\nbodies_file = \"{file}\"\n\n[model]\nkappa = 16.94\n\n\
         [physics]\ngravity = {{ {method} }}\ncontact = {{}}\n\n[output]\nevery = 50.0\n"
    );
    parse_scene(&text, "pile.toml", Some(dir)).unwrap()
}

/// Small scenes keep the exact sum by default: a 200-body scene with `gravity = {}` is `auto`, which does not
/// use the tree below the threshold, and its right-hand side equals the `direct` one bit for bit.
#[test]
fn small_scenes_use_the_direct_sum_by_default() {
    let auto = pile_scene("");
    let direct = pile_scene("method = \"direct\"");
    let method = auto.physics.gravity.unwrap().method;
    assert_eq!(method, GravityMethod::Auto { theta: DEFAULT_THETA });
    assert_eq!(method.tree_theta(auto.bodies.len()), None);
    let rhs = |s: &rubblepile::ellipsoid::scene::LoadedScene| {
        let sys = EllipsoidSystem::new(&s.bodies, s.model, s.physics);
        let y = sys.initial_state();
        let mut dydt = vec![0.0; sys.dim()];
        sys.rhs(0.0, &y, &mut dydt);
        dydt
    };
    let (a, d) = (rhs(&auto), rhs(&direct));
    assert!(a.iter().zip(&d).all(|(p, q)| p.to_bits() == q.to_bits()));
}

/// The tree's right-hand side has the same bits on 1 and 2 threads.
#[test]
fn tree_rhs_is_deterministic_across_thread_counts() {
    let s = pile_scene("method = \"tree\"");
    let sys = EllipsoidSystem::new(&s.bodies, s.model, s.physics);
    let y = sys.initial_state();
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let mut dydt = vec![0.0; sys.dim()];
        pool.install(|| sys.rhs(0.0, &y, &mut dydt));
        dydt
    };
    let (one, two) = (on(1), on(2));
    assert!(one.iter().zip(&two).all(|(p, q)| p.to_bits() == q.to_bits()));
}

/// A `method = "tree"` scene where the tree really approximates: five copies of the N200_T4 pile on a ring
/// (1000 bodies, so leaves are used whole; RMS force error above 1e-6 at θ = 0.5), contact on, no
/// dissipation. It runs 100 s with Bulirsch–Stoer at rtol 1e-9 and conserves H = K + U_C + U_G (U_G the
/// tree's) to 1e-6 of K + |U_C| + |U_G|; its bodies stay within 10 m of the direct run's.
#[test]
fn tree_scene_conserves_energy_over_a_short_span() {
    let bodies = ring_of_piles(5);
    let x: Vec<Vec3> = bodies.iter().map(|b| b.position).collect();
    let m: Vec<f64> = bodies.iter().map(|b| b.shape.mass).collect();
    let (rms, _) = tree_error(&x, &m, DEFAULT_THETA);
    let dir = std::env::temp_dir().join(format!("rubblepile-tree-scene-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    rubblepile::ellipsoid::output::write_snapshot(&dir.join("ring.csv"), 0.0, &bodies).unwrap();
    let run = |method: &str| {
        let s = scene_of(&dir, "ring.csv", method);
        let sys = EllipsoidSystem::new(&s.bodies, s.model, s.physics);
        let mut y = sys.initial_state();
        let mut integ = make_integrator(Method::BulirschStoer, Tolerances::scale_free(1e-9, 1e-9, &sys), None).unwrap();
        let d0 = sys.diagnostics(&y);
        let (mut t, mut worst) = (0.0, 0.0f64);
        for k in 1..=4 {
            integ.advance(&sys, &mut t, &mut y, 25.0 * k as f64).unwrap();
            let d = sys.diagnostics(&y);
            worst = worst.max((d.energy() - d0.energy()).abs() / d0.energy_scale);
        }
        (worst, sys.bodies_at(t, &y))
    };
    let (tree_error, tree_bodies) = run("method = \"tree\"");
    let (direct_error, direct_bodies) = run("method = \"direct\"");
    let _ = std::fs::remove_dir_all(&dir);
    let moved = tree_bodies
        .iter()
        .zip(&direct_bodies)
        .map(|(a, b)| (a.position - b.position).norm())
        .fold(0.0, f64::max);
    println!(
        "1000 bodies, theta 0.5: RMS force error {rms:.2e}; 100 s: energy error tree {tree_error:.2e}, \
         direct {direct_error:.2e}; largest offset {moved:.2e} m"
    );
    assert!(
        rms > 1e-6,
        "the tree does not approximate on this scene ({rms:e}): the test would test nothing"
    );
    assert!(tree_error < 1e-6, "tree energy error {tree_error:e}");
    assert!(moved < 10.0, "tree and direct bodies {moved} m apart");
}

/// Tree forces jump where interaction lists change, so a scene summing gravity by the tree reports its forces
/// as not smooth for integrators that do not fix the lists per step (Bulirsch–Stoer does: see
/// `frozen_tree_lists_let_bulirsch_stoer_keep_the_run_budget`), while the exact sum and `auto` below its
/// threshold (5000 bodies) stay smooth.
#[test]
fn tree_forces_are_not_smooth_without_frozen_lists() {
    let system = |method: &str| {
        let s = pile_scene(method);
        EllipsoidSystem::new(&s.bodies, s.model, s.physics)
    };
    assert!(!system("method = \"tree\"").forces_are_smooth());
    assert!(system("method = \"direct\"").forces_are_smooth());
    assert!(system("").forces_are_smooth());
    assert_eq!(
        GravityMethod::default().tree_theta(2000),
        None,
        "auto must sum the N2000 impact exactly"
    );
}

/// The system without its `begin_step`: every evaluation walks a fresh tree, as under an integrator that does
/// not fix the lists per step.
struct FreshWalks<'a>(&'a EllipsoidSystem);

impl OdeSystem for FreshWalks<'_> {
    fn dim(&self) -> usize {
        self.0.dim()
    }
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        self.0.rhs(t, y, dydt)
    }
    fn state_units(&self) -> Option<Vec<f64>> {
        self.0.state_units()
    }
}

/// Bulirsch–Stoer fixes the tree's lists at each step's start (`begin_step`), so a tree scene keeps the run's
/// error budget (error per unit step, as the run driver sets it): on the 1000-body ring (tree used, leaves
/// whole) 100 s at rtol 1e-9 take few steps, and the energy error stays at the tree's level. With fresh walks
/// at every evaluation the same run drowns in rejected steps (the stall of the first N2000 impact): it is
/// stopped at ten times the frozen run's steps.
#[test]
fn frozen_tree_lists_let_bulirsch_stoer_keep_the_run_budget() {
    // The piles fall toward the ring's centre at 500 m/s, so bodies cross the nodes' opening distances.
    let mut bodies = ring_of_piles(5);
    for b in &mut bodies {
        let inward = -Vec3::new(b.position.x, b.position.y, 0.0).normalize();
        b.velocity += inward * 500.0;
    }
    let dir = std::env::temp_dir().join(format!("rubblepile-tree-budget-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    rubblepile::ellipsoid::output::write_snapshot(&dir.join("ring.csv"), 0.0, &bodies).unwrap();
    let s = scene_of(&dir, "ring.csv", "method = \"tree\"");
    let _ = std::fs::remove_dir_all(&dir);
    let sys = EllipsoidSystem::new(&s.bodies, s.model, s.physics);
    let run = |system: &dyn OdeSystem, max_steps: u64| {
        let mut integ =
            rubblepile::integrate::bulirsch_stoer::BulirschStoer::new(Tolerances::scale_free(1e-6, 1e-6, &sys), None)
                .unwrap();
        integ.set_max_steps(max_steps);
        use rubblepile::integrate::Integrator;
        integ.set_span(10_000.0);
        let mut y = sys.initial_state();
        let d0 = sys.diagnostics(&y);
        let mut t = 0.0;
        let done = integ.advance(system, &mut t, &mut y, 100.0).is_ok();
        let d = sys.diagnostics(&y);
        let stats = integ.stats();
        (
            done,
            stats.steps_accepted + stats.steps_rejected,
            (d.energy() - d0.energy()).abs() / d0.energy_scale,
        )
    };
    let (done, steps, energy) = run(&sys, 100_000);
    // After the advance `sys` holds no lists (`end_steps`), so the wrapper walks fresh trees.
    let (fresh_done, fresh_steps, _) = run(&FreshWalks(&sys), 10 * steps);
    println!(
        "frozen lists: {steps} steps, energy error {energy:.2e}; fresh walks: {fresh_steps} steps, done {fresh_done}"
    );
    assert!(
        done && energy < 1e-6,
        "frozen lists: done {done}, energy error {energy:e}"
    );
    assert!(
        !fresh_done,
        "fresh walks finished too ({fresh_steps} steps against {steps}): nothing is tested"
    );
}

/// Dop853 calls `begin_step` too, so on the same falling ring its steps sum the lists fixed at their start: with
/// its per-step tolerance the run finishes either way, but the frozen lists' forces are smooth within a step,
/// while fresh walks' forces jump where a list changes and the step control pays for it in shorter steps.
#[test]
fn dop853_sums_the_frozen_lists_of_each_step() {
    let mut bodies = ring_of_piles(5);
    for b in &mut bodies {
        let inward = -Vec3::new(b.position.x, b.position.y, 0.0).normalize();
        b.velocity += inward * 500.0;
    }
    let dir = std::env::temp_dir().join(format!("rubblepile-tree-dop853-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    rubblepile::ellipsoid::output::write_snapshot(&dir.join("ring.csv"), 0.0, &bodies).unwrap();
    let s = scene_of(&dir, "ring.csv", "method = \"tree\"");
    let _ = std::fs::remove_dir_all(&dir);
    let sys = EllipsoidSystem::new(&s.bodies, s.model, s.physics);
    let run = |system: &dyn OdeSystem| {
        let mut integ = make_integrator(Method::Dop853, Tolerances::scale_free(1e-8, 1e-8, &sys), None).unwrap();
        let mut y = sys.initial_state();
        let d0 = sys.diagnostics(&y);
        let mut t = 0.0;
        integ.advance(system, &mut t, &mut y, 100.0).unwrap();
        let d = sys.diagnostics(&y);
        (integ.stats(), (d.energy() - d0.energy()).abs() / d0.energy_scale)
    };
    let (frozen, energy) = run(&sys);
    let (fresh, fresh_energy) = run(&FreshWalks(&sys));
    println!("Dop853 frozen lists: {frozen:?}, energy error {energy:.2e}; fresh walks: {fresh:?}, {fresh_energy:.2e}");
    assert!(energy < 1e-6, "frozen lists: energy error {energy:e}");
    // Measured: 319 RHS evaluations (21 steps, 6 rejected) with frozen lists, 487 (35, 6) with fresh walks.
    assert!(
        frozen.rhs_evaluations * 10 <= fresh.rhs_evaluations * 9,
        "frozen lists {frozen:?}, fresh walks {fresh:?}"
    );
}
