//! Projection of the attitudes back onto `|q| = 1` (`EllipsoidSystem::project_attitudes`, scene option
//! `integrator.project_attitudes`): what it keeps, and that it lets Dop853 carry a fast tumbler for hundreds of
//! turns where the multiplier of Roig03 Eq. 35 alone lets `|q|` drift past the run's limit.

mod common;
use common::{Random, rock, temp_dir};
use rubblepile::driver::{RunError, RunOptions, run_scene};
use rubblepile::ellipsoid::body::InertiaModel;
use rubblepile::ellipsoid::equations::{EllipsoidSystem, G_SI, ModelConfig, Physics};
use rubblepile::ellipsoid::quaternion::{body_spin, extended_inertia, inverse_mass_apply};
use rubblepile::ellipsoid::scene::parse_scene;
use rubblepile::math::{Vec3, Vec4};

const STRIDE: usize = 14;

/// `(q, q̇, ω_b)` of body `i` in the packed state, computed from the definitions (Roig03 Eqs. 23, 25).
fn attitude(sys: &EllipsoidSystem, y: &[f64], i: usize) -> (Vec4, Vec4, Vec3) {
    let s = &y[i * STRIDE..(i + 1) * STRIDE];
    let q = Vec4::new(s[3], s[4], s[5], s[6]);
    let p = Vec4::new(s[10], s[11], s[12], s[13]);
    let q_dot = inverse_mass_apply(&q, &extended_inertia(&sys.principal_moments()[i]), &p);
    (q, q_dot, body_spin(&q, &q_dot))
}

fn three_rocks(rng: &mut Random) -> EllipsoidSystem {
    let bodies = [
        rock(
            [3.0, 2.0, 1.0],
            [0.0; 3],
            [0.1, 0.0, 0.0],
            rng.unit_quaternion(),
            [0.02, 0.05, 0.5],
        ),
        rock(
            [2.0, 1.5, 1.2],
            [20.0, 0.0, 0.0],
            [0.0, 0.2, 0.0],
            rng.unit_quaternion(),
            [-0.3, 0.1, 0.0],
        ),
        rock(
            [1.5, 1.0, 0.7],
            [0.0, 20.0, 0.0],
            [0.0, 0.0, -0.1],
            rng.unit_quaternion(),
            [0.0, 1.0, -0.2],
        ),
    ];
    let model = ModelConfig {
        kappa: 10.0,
        inertia: InertiaModel::Gaussian,
        contact_g: G_SI,
    };
    EllipsoidSystem::new(&bodies, model, Physics::default())
}

#[test]
fn projection_keeps_each_bodys_spin_and_attitude_and_leaves_translation_bit_identical() {
    let mut rng = Random::new(29);
    let sys = three_rocks(&mut rng);
    assert!(sys.rotation_integrated());
    let mut y = sys.initial_state();
    // Break both constraints: |q| = 1 + δ_i, and a radial part c q in p (q·q̇ ≠ 0; it leaves ω_b unchanged).
    let deltas = [3e-4, -7e-4, 1e-5];
    for (i, d) in deltas.iter().enumerate() {
        let s = &mut y[i * STRIDE..(i + 1) * STRIDE];
        let q = Vec4::new(s[3], s[4], s[5], s[6]) * (1.0 + d);
        s[3..7].copy_from_slice(q.as_slice());
        for k in 0..4 {
            s[10 + k] += 0.05 * q[k];
        }
    }
    let before = y.clone();
    let drift = sys.project_attitudes(&mut y);
    assert!(
        (drift - 7e-4).abs() < 1e-12,
        "largest ||q| - 1| before projection: {drift:e}"
    );
    for i in 0..3 {
        let (q0, _, spin0) = attitude(&sys, &before, i);
        let (q, q_dot, spin) = attitude(&sys, &y, i);
        assert_eq!(q, q0.normalize(), "body {i}: the attitude's direction is kept");
        assert!(
            (q.norm() - 1.0).abs() < 1e-15,
            "body {i}: |q| - 1 = {:e}",
            q.norm() - 1.0
        );
        let tangent = q.dot(&q_dot) / q_dot.norm();
        assert!(tangent.abs() < 1e-14, "body {i}: q·q̇ / |q̇| = {tangent:e}");
        let spin_change = (spin - spin0).norm() / spin0.norm();
        assert!(
            spin_change < 1e-14,
            "body {i}: body-frame spin changed by {spin_change:e}"
        );
        let s = i * STRIDE;
        assert_eq!(y[s..s + 3], before[s..s + 3], "body {i}: position");
        assert_eq!(y[s + 7..s + 10], before[s + 7..s + 10], "body {i}: momentum u");
    }
    // Once on the constraint, projecting again changes nothing beyond round-off.
    let once = y.clone();
    let drift_again = sys.project_attitudes(&mut y);
    assert!(drift_again < 1e-15, "{drift_again:e}");
    let change = y
        .iter()
        .zip(&once)
        .map(|(a, b)| (a - b).abs() / b.abs().max(1e-300))
        .fold(0.0, f64::max);
    assert!(
        change < 1e-14,
        "a second projection moved the state by {change:e} (relative)"
    );
}

/// One fast, strongly tumbling ellipsoid (period 2π/|ω| ≈ 6.2 s), no forces: `turns` turns at `rtol` under
/// `method`, with `project` for `integrator.project_attitudes` (`None`: the default).
fn tumbler_scene(method: &str, rtol: f64, turns: f64, project: Option<bool>) -> String {
    let period = 2.0 * std::f64::consts::PI / Vec3::new(0.3, 0.2, 0.9).norm();
    let t_end = turns * period;
    let project = project.map_or(String::new(), |p| format!("project_attitudes = {p}\n"));
    format!(
        r#"[scene]
kind = "ellipsoids"
t_end = {t_end}

[model]
kappa = 10.0

[physics]

[integrator]
method = "{method}"
rtol = {rtol:e}
atol = {rtol:e}
{project}
[output]
times = [0.0, {t_end}]
every = {every}

[[body]]
axes = [3.0, 2.0, 1.0]
mass = 75000.0
position = [0.0, 0.0, 0.0]
velocity = [0.0, 0.0, 0.0]
quaternion = [0.1, 0.7, 0.1, 0.7]
spin_body = [0.3, 0.2, 0.9]
"#,
        every = t_end / 100.0
    )
}

fn run_tumbler(
    text: &str,
    tag: &str,
) -> Result<rubblepile::driver::RunSummary, RunError<rubblepile::driver::RunSummary>> {
    let dir = temp_dir(tag);
    let scene = parse_scene(text, "tumbler.toml", Some(&dir)).unwrap();
    let options = RunOptions {
        force: true,
        progress: false,
        checkpoint_every: None,
        ..RunOptions::default()
    };
    run_scene(&scene, &dir.join("run"), &options)
}

#[test]
fn dop853_keeps_a_fast_tumbler_on_the_constraint_only_with_projection() {
    const RTOL: f64 = 1e-4;
    const TURNS: f64 = 400.0;
    // Without projection, the multiplier alone lets |q| drift past the run's limit of 1e-3: the run stops and names
    // the cause and the option.
    match run_tumbler(&tumbler_scene("dop853", RTOL, TURNS, Some(false)), "tumbler-free") {
        Err(RunError::Failed { cause, t, .. }) => {
            assert!(cause.contains("quaternion norm constraint broken"), "{cause}");
            assert!(cause.contains("project_attitudes"), "{cause}");
            eprintln!("without projection: stopped at t = {t} s: {cause}");
        }
        other => panic!("expected the constraint to break without projection, got {other:?}"),
    }
    // Dop853's default projects at every output sample: the run finishes, and the drift it removed at each sample
    // (the summary's quaternion error) stays far below the limit.
    let s = run_tumbler(&tumbler_scene("dop853", RTOL, TURNS, None), "tumbler-projected").unwrap();
    eprintln!(
        "with projection: max ||q|-1| before each projection {:e}, energy error {:e}, |dL| {:e}",
        s.quaternion_norm_error, s.energy_error, s.angular_momentum_error
    );
    assert!(s.project_attitudes, "the summary says the attitudes were projected");
    assert!(s.quaternion_norm_error < 1e-4, "{:e}", s.quaternion_norm_error);
    // Projection keeps ω_b and the attitude's direction, so the world angular momentum R(q)ᵀ I ω_b, which the
    // free top conserves, is kept to round-off over its 100 projections (a wrong rescaling of p would move it by
    // about the drift removed, 1e-5). Measured: 6.4e-13 (without projection, 1e-3 by the time |q| breaks).
    assert!(s.angular_momentum_error < 1e-9, "{:e}", s.angular_momentum_error);
    // Bulirsch–Stoer keeps the constraint without it, so by default it does not project (its runs stay as they
    // were): the same turns end 1000 times further from the limit (measured 1.1e-6).
    let bs = run_tumbler(&tumbler_scene("bulirsch-stoer", RTOL, TURNS, None), "tumbler-bs").unwrap();
    assert!(!bs.project_attitudes);
    assert!(bs.quaternion_norm_error < 1e-5, "{:e}", bs.quaternion_norm_error);
}

#[test]
fn project_attitudes_defaults_to_on_for_dormand_prince_and_off_for_bulirsch_stoer() {
    let resolved = |method: &str, project: Option<bool>| {
        let text = tumbler_scene(method, 1e-8, 1.0, project);
        parse_scene(&text, "tumbler.toml", None)
            .unwrap()
            .integrator
            .project_attitudes
    };
    assert!(!resolved("bulirsch-stoer", None));
    assert!(resolved("dop853", None));
    assert!(resolved("dopri5", None));
    assert!(resolved("bulirsch-stoer", Some(true)));
    assert!(!resolved("dop853", Some(false)));
    let bad = tumbler_scene("dop853", 1e-8, 1.0, None).replace("[output]", "project_attitudes = 1\n[output]");
    let err = parse_scene(&bad, "tumbler.toml", None).unwrap_err().to_string();
    assert!(err.contains("project_attitudes"), "{err}");
}
