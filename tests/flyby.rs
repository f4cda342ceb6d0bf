//! The flyby tide (`[physics.flyby]`, `src/ellipsoid/tide.rs`) and its Kepler orbit (`src/gravity/kepler.rs`):
//! the exact tide against the linear tidal field far away, the orbit against the two-body invariants, a massless
//! planet leaving a run bit-identical, and the energy bookkeeping `H + E_tide` closing in a close flyby.

mod common;

use common::{Random, rubblepile, temp_dir};
use rubblepile::driver::{RunError, RunOptions, resume_run, run_scene};
use rubblepile::ellipsoid::scene::parse_scene;
use rubblepile::ellipsoid::tide::TideTerm;
use rubblepile::gravity::kepler::{KeplerOrbit, orientation_matrix, solve_elliptic, solve_hyperbolic};
use rubblepile::math::Vec3;

const GM_EARTH: f64 = 3.986004418e14;

fn rotation() -> rubblepile::math::Mat3 {
    orientation_matrix(0.3, 1.1, -0.7)
}

#[test]
fn distant_tide_matches_the_linear_tidal_field() {
    // q ≫ pile size: |x| ≤ 200 m, d = 1e9 m; the quadrupole term is O(|x|/d) = 2e-7 relative.
    let orbit = KeplerOrbit::hyperbolic(GM_EARTH, 1e9, 5800.0, 0.0, rotation()).unwrap();
    let tide = TideTerm {
        gm: GM_EARTH,
        radius: None,
        orbit,
        j2: None,
    };
    let mut rng = Random::new(7);
    for t in [-3e5, 0.0, 1e5] {
        let planet = tide.planet_position(t);
        let d = planet.norm();
        let dhat = planet / d;
        for _ in 0..20 {
            let x = rng.vec3(200.0);
            let exact = tide.acceleration(&x, &planet);
            let linear = GM_EARTH / (d * d * d) * (3.0 * x.dot(&dhat) * dhat - x);
            let rel = (exact - linear).norm() / linear.norm();
            assert!(rel < 1e-6, "t = {t}: relative difference {rel:e}");
        }
    }
    // The origin itself feels nothing (it falls freely).
    assert_eq!(
        tide.acceleration(&Vec3::zeros(), &tide.planet_position(0.0)),
        Vec3::zeros()
    );
}

#[test]
fn kepler_solvers_satisfy_their_equations() {
    for e in [0.0, 0.1, 0.5, 0.9, 0.999] {
        for m in [-20.0, -3.0, -0.1, 0.0, 1e-6, 0.5, 2.0, 3.1, 50.0] {
            let big_e = solve_elliptic(e, m);
            assert!(
                (big_e - e * big_e.sin() - m).abs() < 1e-12 * m.abs().max(1.0),
                "e {e} M {m}"
            );
        }
    }
    for e in [1.0001, 1.01, 1.5, 3.0, 100.0] {
        for m in [-1e4, -5.0, -1e-3, 0.0, 1e-8, 0.3, 7.0, 1e3, 1e6] {
            let h = solve_hyperbolic(e, m);
            let residual = e * h.sinh() - h - m;
            assert!(
                residual.abs() < 1e-11 * m.abs().max(1.0),
                "e {e} M {m}: residual {residual:e}"
            );
        }
    }
}

#[test]
fn kepler_orbits_keep_energy_and_angular_momentum() {
    let q = 3.8e7;
    for orbit in [
        KeplerOrbit::hyperbolic(GM_EARTH, q, 5800.0, 1234.0, rotation()).unwrap(),
        KeplerOrbit::hyperbolic(GM_EARTH, q, 12_000.0, -50.0, rotation()).unwrap(),
        KeplerOrbit::new(GM_EARTH, q, 0.6, 0.0, rotation()).unwrap(),
    ] {
        // Specific orbital energy −GM/(2a) (J/kg) and angular momentum |s × ṡ| = sqrt(GM q (1 + e)) (m²/s).
        let energy = -orbit.gm / (2.0 * orbit.semi_major_axis());
        let h = (orbit.gm * orbit.q * (1.0 + orbit.e)).sqrt();
        let normal = rotation().column(2).into_owned();
        for t in [-2e5, -1e4, -10.0, 0.0, 3.0, 5e3, 8e4, 1e6] {
            let (r, v) = orbit.state(orbit.t_perigee + t);
            let e_now = 0.5 * v.norm_squared() - GM_EARTH / r.norm();
            assert!(
                (e_now - energy).abs() < 1e-10 * (GM_EARTH / q),
                "t {t}: energy {e_now} vs {energy}"
            );
            let l = r.cross(&v);
            assert!(
                (l - h * normal).norm() < 1e-10 * h,
                "t {t}: angular momentum {l} vs {h} along {normal}"
            );
        }
        // Perigee: distance q along the perifocal x axis, velocity perpendicular to it.
        let (r, v) = orbit.state(orbit.t_perigee);
        assert!((r - q * rotation().column(0)).norm() < 1e-9 * q, "perigee at {r}");
        assert!(r.dot(&v).abs() < 1e-12 * q * v.norm());
        // Finite differences of the position give the velocity.
        let (t, dt) = (orbit.t_perigee + 3e4, 1e-2);
        let fd = (orbit.state(t + dt).0 - orbit.state(t - dt).0) / (2.0 * dt);
        assert!((fd - orbit.state(t).1).norm() < 1e-7 * fd.norm());
    }
    // Hyperbola: the speed tends to v_inf; the time to reach a distance inverts the orbit.
    let orbit = KeplerOrbit::hyperbolic(GM_EARTH, q, 5800.0, 0.0, rotation()).unwrap();
    let (r_far, v_far) = orbit.state(1e10);
    let far = v_far.norm();
    assert!((far - 5800.0).abs() < 1e-6 * 5800.0, "speed far away {far}");
    let vis_viva = (5800.0f64.powi(2) + 2.0 * GM_EARTH / r_far.norm()).sqrt();
    assert!((far - vis_viva).abs() < 1e-12 * far, "{far} vs vis-viva {vis_viva}");
    let t = orbit.time_from_perigee_at_distance(20.0 * q).unwrap();
    assert!((orbit.state(t).0.norm() - 20.0 * q).abs() < 1e-8 * q);
    // Ellipse: back to the same state after one period.
    let ellipse = KeplerOrbit::new(GM_EARTH, q, 0.6, 0.0, rotation()).unwrap();
    let period = 2.0 * std::f64::consts::PI / ellipse.mean_motion();
    let (a, b) = (ellipse.state(0.3 * period), ellipse.state(1.3 * period));
    assert!((a.0 - b.0).norm() < 1e-8 * q);
    assert!(KeplerOrbit::new(GM_EARTH, q, 1.0, 0.0, rotation()).is_err());
    assert!(KeplerOrbit::hyperbolic(GM_EARTH, -q, 5800.0, 0.0, rotation()).is_err());
}

/// Four touching ellipsoids (gravity, contact, dissipation) with `flyby` appended to `[physics]`.
fn pile_scene(flyby: &str, t_end: f64) -> String {
    format!(
        r#"[scene]
kind = "ellipsoids"
t_end = {t_end:?}
[model]
kappa = 10.0
[physics]
gravity = {{}}
contact = {{}}
dissipation = {{ F0 = 1e-3 }}
{flyby}
[integrator]
method = "bulirsch-stoer"
rtol = 1e-9
atol = 1e-9
[output]
times = [0.0, {half:?}, {t_end:?}]
every = {every:?}
[[body]]
axes = [60.0, 45.0, 35.0]
density = 3000.0
position = [-50.0, 0.0, 0.0]
spin_world = [0.0, 0.0, 5e-5]
velocity = [0.0, -0.0025, 0.0]
[[body]]
axes = [50.0, 40.0, 30.0]
density = 3000.0
position = [52.0, 3.0, 0.0]
quaternion = [0.0, 0.0, 0.3826834323650898, 0.9238795325112867]
velocity = [0.0, 0.0026, 0.0]
spin_world = [0.0, 0.0, 5e-5]
[[body]]
axes = [40.0, 30.0, 25.0]
density = 3000.0
position = [0.0, 70.0, 10.0]
velocity = [-0.0035, 0.0, 0.0]
spin_world = [0.0, 0.0, 5e-5]
[[body]]
axes = [35.0, 30.0, 20.0]
density = 3000.0
position = [0.0, -65.0, -8.0]
velocity = [0.0033, 0.0, 0.0]
spin_world = [0.0, 0.0, 5e-5]
"#,
        half = t_end / 2.0,
        every = t_end / 20.0,
    )
}

fn run(text: &str, tag: &str) -> (std::path::PathBuf, rubblepile::driver::RunSummary) {
    let dir = temp_dir(tag);
    let scene = parse_scene(text, "flyby.toml", Some(&dir)).unwrap();
    let options = RunOptions {
        force: true,
        progress: false,
        checkpoint_every: None,
        ..RunOptions::default()
    };
    let out = dir.join("run");
    let summary = run_scene(&scene, &out, &options).unwrap();
    (out, summary)
}

#[test]
fn massless_planet_leaves_the_run_bit_identical() {
    let flyby =
        "[physics.flyby]\nmass = 0.0\nq = 2e7\nv_inf = 5800.0\nt_perigee = 1000.0\norientation_deg = [10, 20, 30]";
    let (plain, s0) = run(&pile_scene("", 2000.0), "flyby-plain");
    let (massless, s1) = run(&pile_scene(flyby, 2000.0), "flyby-massless");
    assert_eq!(s0.steps_accepted, s1.steps_accepted);
    for k in 0..3 {
        let a = std::fs::read(plain.join(format!("snapshots/{k}.csv"))).unwrap();
        let b = std::fs::read(massless.join(format!("snapshots/{k}.csv"))).unwrap();
        assert!(a == b, "snapshot {k} differs");
    }
    // The energy columns differ only by E_tide = P·V₀ (P ≈ 0 here): the residuals agree closely.
    assert!(
        (s0.energy_error - s1.energy_error).abs() < 1e-9,
        "{} vs {}",
        s0.energy_error,
        s1.energy_error
    );
}

#[test]
fn tidal_energy_bookkeeping_closes_in_a_close_flyby() {
    // A pile 100 m across passing 1.5 Earth radii from a planet of ten Earth masses at low speed, around perigee:
    // the tide does work of the order of the pile's binding energy, and H + E_tide must still be conserved.
    let flyby = "[physics.flyby]\nmass = 5.9722e25\nradius = 6.371e6\nq = 9.5e6\nv_inf = 3000.0\nt_perigee = 1500.0";
    let (dir, s) = run(&pile_scene(flyby, 3000.0), "flyby-energy");
    assert_eq!(s.status, "completed");
    assert!(s.energy_error < 1e-6, "energy error {:e}", s.energy_error);
    // The tide did work: H alone changed by much more than the tolerance (columns: energies in J).
    let rows = rubblepile::io::particles::read_particles(
        &dir.join("timeseries.csv"),
        &[
            "kinetic_translational",
            "kinetic_rotational",
            "potential_contact",
            "potential_gravity",
            "dissipated",
        ],
        &[],
    )
    .unwrap();
    let h = |r: &rubblepile::io::particles::ParticleRecord| {
        r.values[0] + r.values[1] + r.values[2] + r.values[3] - r.values[4]
    };
    let (first, last) = (&rows[0], &rows[rows.len() - 1]);
    let change = (h(last) - h(first)).abs() / s.scales.energy;
    assert!(
        change > 1e3 * s.energy_error.max(1e-12),
        "H changed by only {change:e} of the scale"
    );
}

#[test]
fn flyby_run_resumed_from_a_checkpoint_matches_the_whole_run() {
    let flyby = "[physics.flyby]\nmass = 5.9722e25\nradius = 6.371e6\nq = 9.5e6\nv_inf = 3000.0\nt_perigee = 1500.0";
    let text = pile_scene(flyby, 3000.0);
    let (whole, s_whole) = run(&text, "flyby-whole");
    let dir = temp_dir("flyby-split");
    let scene = parse_scene(&text, "flyby.toml", Some(&dir)).unwrap();
    let quiet = RunOptions {
        force: true,
        progress: false,
        checkpoint_every: None,
        ..RunOptions::default()
    };
    let stopping = RunOptions {
        checkpoint_every_sim: Some(1000.0),
        stop_after_checkpoints: Some(1),
        ..quiet
    };
    let split = dir.join("run");
    match run_scene(&scene, &split, &stopping) {
        Err(RunError::Stopped { .. }) => {}
        other => panic!("expected a stop after the checkpoint, got {other:?}"),
    }
    let resumed = resume_run(&split, &quiet).unwrap();
    assert_eq!(resumed.energy_error, s_whole.energy_error);
    let read = |p: &std::path::Path| std::fs::read(p.join("snapshots/2.csv")).unwrap();
    assert!(read(&split) == read(&whole), "the resumed run's last snapshot differs");
}

/// With an oblate planet (J2 exaggerated to 0.05 so that its work is large, pole tilted), `H + E_tide` with the
/// zonal energy `Σ m Φ_J2` still closes, and the J2 really acts: the pile ends elsewhere than under a point mass.
#[test]
fn j2_energy_bookkeeping_closes_with_a_tilted_pole() {
    let point = "[physics.flyby]\nmass = 5.9722e25\nradius = 6.371e6\nq = 9.5e6\nv_inf = 3000.0\nt_perigee = 1500.0";
    let oblate = format!("{point}\nj2 = 0.05\npole = [0.3, 0.5, 1.0]");
    let (point_dir, s0) = run(&pile_scene(point, 3000.0), "flyby-point");
    let (oblate_dir, s1) = run(&pile_scene(&oblate, 3000.0), "flyby-j2");
    assert_eq!(s1.status, "completed");
    assert!(s1.energy_error < 1e-6, "energy error {:e}", s1.energy_error);
    let positions = |dir: &std::path::Path| {
        rubblepile::io::particles::read_particles(&dir.join("snapshots/2.csv"), &["x", "y", "z"], &[])
            .unwrap()
            .iter()
            .map(|r| Vec3::new(r.values[0], r.values[1], r.values[2]))
            .collect::<Vec<_>>()
    };
    let (a, b) = (positions(&point_dir), positions(&oblate_dir));
    let shift = a.iter().zip(&b).map(|(p, q)| (p - q).norm()).fold(0.0, f64::max);
    // J2 (R/q)² ≈ 0.02 of the planet's pull: the pile's centre drifts by metres over the 3000 s
    assert!(shift > 0.1, "largest shift {shift} m");
    assert!(s0.energy_error < 1e-6);
}

/// `j2 = 0` is a point mass: the run is bit-identical to one without `j2`; `j2` without `radius` and `pole`
/// without `j2` are refused, naming the field.
#[test]
fn zero_j2_leaves_the_run_bit_identical_and_bad_j2_input_is_refused() {
    let point = "[physics.flyby]\nmass = 5.9722e24\nradius = 6.371e6\nq = 2e7\nv_inf = 5800.0\nt_perigee = 500.0";
    let (a, _) = run(&pile_scene(point, 1000.0), "flyby-nozonal");
    let (b, _) = run(
        &pile_scene(&format!("{point}\nj2 = 0.0\npole = [1.0, 0.0, 0.0]"), 1000.0),
        "flyby-zerozonal",
    );
    for k in 0..3 {
        let sa = std::fs::read(a.join(format!("snapshots/{k}.csv"))).unwrap();
        let sb = std::fs::read(b.join(format!("snapshots/{k}.csv"))).unwrap();
        assert!(sa == sb, "snapshot {k} differs");
    }
    let no_radius = "[physics.flyby]\nmass = 5.9722e24\nq = 2e7\nv_inf = 5800.0\nt_perigee = 500.0\nj2 = 1e-3";
    let pole_alone = format!("{point}\npole = [0.0, 0.0, 1.0]");
    for (text, field) in [
        (no_radius.to_string(), "physics.flyby.radius"),
        (pole_alone, "physics.flyby.pole"),
    ] {
        let Err(err) = parse_scene(&pile_scene(&text, 1000.0), "bad.toml", None) else {
            panic!("{field}: the scene was accepted");
        };
        assert!(err.to_string().contains(field), "{err}");
    }
}

/// `rubblepile flyby --planet-j2 … --planet-pole …` writes the J2 term into the run's scene and `flyby.json`;
/// a pole without J2 is refused, naming the flag's field.
#[test]
fn flyby_command_writes_the_planet_j2() {
    let dir = temp_dir("flyby-cli-j2");
    let target = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("targets/N30_T4.csv");
    let flyby = |extra: &[&str], out: &str| {
        let mut args = vec![
            "flyby",
            "--target",
            target.to_str().unwrap(),
            "--q-m",
            "3.8e7",
            "--no-run",
            "--out",
            out,
        ];
        args.extend_from_slice(extra);
        rubblepile(&dir, &args)
    };
    let out = flyby(
        &[
            "--planet-j2",
            "1.0826e-3",
            "--planet-radius-m",
            "6378137",
            "--planet-pole",
            "1,0,0",
        ],
        "j2",
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let scene = std::fs::read_to_string(dir.join("j2/scene.toml")).unwrap();
    assert!(
        scene.contains("j2 = 0.0010826") && scene.contains("pole = [1.0, 0.0, 0.0]"),
        "{scene}"
    );
    // the scene values: the control's scene is the run's without the planet's mass
    let parse = |p: &str| rubblepile::ellipsoid::scene::parse_toml(&std::fs::read_to_string(dir.join(p)).unwrap(), p);
    let (run, mut control) = (parse("j2/scene.toml").unwrap(), parse("j2/control/scene.toml").unwrap());
    let tide = run.physics.flyby.unwrap();
    assert_eq!(
        (tide.j2, tide.pole, tide.radius),
        (Some(1.0826e-3), Some([1.0, 0.0, 0.0]), Some(6378137.0))
    );
    control.physics.flyby.as_mut().unwrap().mass = tide.mass;
    assert_eq!(control, run);
    let setup = std::fs::read_to_string(dir.join("j2/flyby.json")).unwrap();
    assert!(setup.contains("\"j2\": 0.0010826"), "{setup}");
    // the point-mass default writes no J2
    assert!(flyby(&[], "point").status.success());
    assert!(
        !std::fs::read_to_string(dir.join("point/scene.toml"))
            .unwrap()
            .contains("j2")
    );
    let refused = flyby(&["--planet-pole", "0,0,1"], "pole-alone");
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("error: --planet-pole: "));
}

/// `rubblepile analyze DIR` recognises a flyby run (a scene with `[physics.flyby]`) and writes its remnant analysis;
/// it does not overwrite that analysis without `--force`.
#[test]
fn analyze_command_handles_flyby_runs() {
    let flyby = "[physics.flyby]\nmass = 5.9722e25\nradius = 6.371e6\nq = 9.5e6\nv_inf = 3000.0\nt_perigee = 500.0";
    let (dir, _) = run(&pile_scene(flyby, 1000.0), "flyby-analyze");
    let dir_arg = dir.to_str().unwrap();
    let analyze = |extra: &[&str]| rubblepile(&dir, &[&["analyze", dir_arg], extra].concat());
    let first = analyze(&[]);
    assert!(first.status.success(), "{}", String::from_utf8_lossy(&first.stderr));
    assert!(String::from_utf8_lossy(&first.stdout).contains("flyby: "));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("analysis/flyby.json")).unwrap()).unwrap();
    let lost = json["mass_lost"].as_f64().unwrap();
    assert!((0.0..=1.0).contains(&lost), "{json}");
    let again = analyze(&[]);
    assert_eq!(again.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&again.stderr).contains("--force"));
    assert!(analyze(&["--force"]).status.success());
}

/// `flyby --snapshots N` wrote `t_end·k/(N − 1)`, whose last value rounds one ulp above `t_end` for some N (147 of
/// N = 2…1201 at q = 6 R_E, v∞ = 12 km/s), and the scene check refused the run. The output times are clamped: every
/// one lies in `[0, t_end]`, increasing, the last exactly `t_end` (and the unclamped formula does fail here, so the
/// case is one that catches the bug).
#[test]
fn flyby_output_times_never_pass_t_end() {
    use rubblepile::impact::flyby::{DEFAULT_START_Q, EARTH_MASS_KG, EARTH_RADIUS_M, flyby_orbit};
    use rubblepile::io::output_times::evenly_spaced as output_times;
    let gm = rubblepile::ellipsoid::equations::G_SI * EARTH_MASS_KG;
    let (_, t_perigee) = flyby_orbit(gm, 6.0 * EARTH_RADIUS_M, 12_000.0, DEFAULT_START_Q).unwrap();
    let t_end = 2.0 * t_perigee;
    let mut unclamped_over = 0;
    for n in 2..=1201usize {
        let times = output_times(t_end, n);
        assert_eq!(times.len(), n);
        assert_eq!(times[0], 0.0);
        assert_eq!(times[n - 1], t_end, "N = {n}");
        assert!(times.windows(2).all(|w| w[0] < w[1]), "N = {n}: not increasing");
        if (0..n).any(|k| t_end * k as f64 / (n - 1) as f64 > t_end) {
            unclamped_over += 1;
        }
    }
    assert!(
        unclamped_over > 0,
        "the unclamped times never passed t_end: the case no longer tests the clamp"
    );
}

/// A control flyby (planet mass 0) of a rescaled, re-spun pile is classed unaffected (issue 41's acceptance): the
/// pile is settled first, the tide's effect (run minus control) is below the thresholds, and so are the run's own
/// changes of period and shape (before the settling existed this case printed "reshaped: P 30.5 → 28.2 h, b/a
/// 0.924 → 0.856").
#[test]
fn control_flyby_is_classed_unaffected() {
    use rubblepile::analysis::flyby::{RESHAPE_THRESHOLD, SPIN_CHANGE_THRESHOLD};
    let dir = temp_dir("flyby-control-acceptance");
    let target = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("targets/N30_T4.csv");
    let out = rubblepile(
        &dir,
        &[
            "flyby",
            "--target",
            target.to_str().unwrap(),
            "--radius-m",
            "170",
            "--period-h",
            "30.5",
            "--q-m",
            "3.8e7",
            "--planet-mass-kg",
            "0",
            "--out",
            "run",
        ],
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("settled in"), "{stdout}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("run/analysis/flyby.json")).unwrap()).unwrap();
    assert_eq!(json["class"], "unaffected", "{json}");
    assert_eq!(json["rbl98_class"], "N");
    assert_eq!(json["tide"]["from_control"], true);
    assert_eq!(json["settling"]["capped"], false, "{json}");
    let p_before = json["before"]["spin"]["invariant_period_hours"].as_f64().unwrap();
    for (what, source) in [("tide", &json["tide"]), ("run", &json)] {
        let (dp, db) = match what {
            "tide" => (
                source["delta_invariant_period_hours"].as_f64().unwrap(),
                source["delta_b_over_a"].as_f64().unwrap(),
            ),
            _ => (
                source["after"]["spin"]["invariant_period_hours"].as_f64().unwrap() - p_before,
                source["after"]["b_over_a"].as_f64().unwrap() - source["before"]["b_over_a"].as_f64().unwrap(),
            ),
        };
        assert!(
            (dp / p_before).abs() < SPIN_CHANGE_THRESHOLD,
            "{what}: dP {dp} h of {p_before} h"
        );
        assert!(db.abs() < RESHAPE_THRESHOLD, "{what}: d(b/a) {db}");
    }
    // The control ran beside the run: same duration, its own summary.
    let control: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("run/control/summary.json")).unwrap()).unwrap();
    assert_eq!(control["status"], "completed");
    assert!(dir.join("run/prepared_bodies.csv").is_file());
}

/// The tide's torque changes L by much more than the integration's error: the summary reports its impulse
/// `|∫τ dt|` apart, and the angular-momentum error is the residual `|L − L0 − ∫τ dt|`, at the tolerance's level.
#[test]
fn tidal_torque_impulse_is_reported_apart_from_the_angular_momentum_residual() {
    let flyby = "[physics.flyby]\nmass = 5.9722e25\nradius = 6.371e6\nq = 9.5e6\nv_inf = 3000.0\nt_perigee = 1500.0";
    let (dir, s) = run(&pile_scene(flyby, 3000.0), "flyby-torque-impulse");
    let impulse = s
        .tidal_torque_impulse
        .expect("a flyby reports the tidal torque impulse");
    assert!(s.tidal_impulse.is_some());
    let rows =
        rubblepile::io::particles::read_particles(&dir.join("timeseries.csv"), &["lx", "ly", "lz"], &[]).unwrap();
    let l = |r: &rubblepile::io::particles::ParticleRecord| Vec3::new(r.values[0], r.values[1], r.values[2]);
    let raw = (l(&rows[rows.len() - 1]) - l(&rows[0])).norm() / s.scales.angular_momentum;
    assert!(
        raw > 1e-4,
        "the tide hardly changed L ({raw:e}): the case tests nothing"
    );
    assert!(
        s.angular_momentum_error < 1e-4 * raw,
        "residual {:e} vs raw change {raw:e}",
        s.angular_momentum_error
    );
    // The impulse is the largest |∫τ dt| over the run; at the end it equals the change of L up to the residual.
    assert!(impulse >= raw * (1.0 - 1e-6), "impulse {impulse:e}, raw change {raw:e}");
    // Without a planet there is no impulse to report.
    let (_, plain) = run(&pile_scene("", 500.0), "flyby-no-impulse");
    assert_eq!(plain.tidal_torque_impulse, None);
}

/// The settling's cap is kept and said (a warning line, `settling.capped` in `flyby.json`), `--no-control`
/// runs no control: no `control/`, and the outcome says its changes are the run's own; `--format` and
/// `--progress-every-s` reach the run.
#[test]
fn capped_settling_is_reported_and_no_control_skips_the_control() {
    let dir = temp_dir("flyby-capped");
    let target = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("targets/N30_T4.csv");
    let out = rubblepile(
        &dir,
        &[
            "flyby",
            "--target",
            target.to_str().unwrap(),
            "--radius-m",
            "170",
            "--period-h",
            "30.5",
            "--q-m",
            "3.8e7",
            "--v-inf-km-s",
            "12",
            "--settle-max-h",
            "0.5",
            "--no-control",
            "--snapshots",
            "2",
            "--format",
            "xyz",
            "--progress-every-s",
            "0.1",
            "--out",
            "run",
        ],
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // `--format` and `--progress-every-s` as for `run`: an XYZ beside each CSV snapshot, progress lines in the log.
    assert!(dir.join("run/snapshots/1.xyz").exists());
    // the progress lines name the run (a flyby runs its control after it, from 0 to 100 % again)
    assert!(String::from_utf8_lossy(&out.stderr).contains("progress: run: t = "));
    flyby_printout_names_each_quantity_once(&stdout);
    assert!(
        stdout.contains("warning: settling stopped at its cap of 0.50 h"),
        "{stdout}"
    );
    let setup: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("run/flyby.json")).unwrap()).unwrap();
    assert_eq!(setup["settling"]["capped"], true, "{setup}");
    assert_eq!(setup["settling"]["time"].as_f64(), Some(1800.0), "{setup}");
    assert_eq!(setup["control"], false);
    assert!(!dir.join("run/control").exists());
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("run/analysis/flyby.json")).unwrap()).unwrap();
    assert_eq!(json["tide"]["from_control"], false, "{json}");
    assert!(json["control"].is_null());
    // A cap that is not a positive time is refused, naming the flag's field.
    let bad = rubblepile(
        &dir,
        &[
            "flyby",
            "--target",
            target.to_str().unwrap(),
            "--q-m",
            "3.8e7",
            "--settle-max-h",
            "0",
            "--no-run",
            "--out",
            "bad",
        ],
    );
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("error: --settle-max-h: "));
    // flyby errors name the flag, not the field (`q_m:` once)
    for (flag, value, said) in [
        ("--q-m", "5e6", "error: --q-m: must exceed the planet radius"),
        ("--v-inf-km-s", "0", "error: --v-inf-km-s: must be > 0"),
        ("--period-h", "0", "error: --period-h: must be > 0"),
        ("--planet-mass-kg=-1", "", "error: --planet-mass-kg: must be >= 0"),
    ] {
        let mut args = vec![
            "flyby",
            "--target",
            target.to_str().unwrap(),
            "--no-run",
            "--out",
            "bad_flag",
        ];
        if value.is_empty() {
            args.extend(["--q-m", "3.8e7", flag]);
        } else {
            args.extend([flag, value]);
            if flag != "--q-m" {
                args.extend(["--q-m", "3.8e7"]);
            }
        }
        let bad = rubblepile(&dir, &args);
        let stderr = String::from_utf8_lossy(&bad.stderr);
        assert!(stderr.contains(said), "{flag}: {stderr}");
    }
}

/// Spheres under gravity alone take the packed right-hand side; with a planet the state also carries the tide's six
/// impulse components after the bodies, which that path once walked as a body of its own (an index panic). The
/// pair's momentum residual must be an error (the tide's impulse reported apart), and the run must complete.
#[test]
fn spheres_under_gravity_alone_pass_a_planet() {
    let text = r#"[scene]
kind = "ellipsoids"
t_end = 3000.0
[model]
kappa = 10.0
[physics]
gravity = {}
[physics.flyby]
mass = 5.9722e25
radius = 6.371e6
q = 9.5e6
v_inf = 3000.0
t_perigee = 1500.0
[integrator]
method = "bulirsch-stoer"
rtol = 1e-10
atol = 1e-10
[output]
times = [0.0, 3000.0]
every = 500.0
[[body]]
axes = [40.0, 40.0, 40.0]
density = 2000.0
position = [-300.0, 0.0, 0.0]
velocity = [0.0, -0.01, 0.0]
[[body]]
axes = [30.0, 30.0, 30.0]
density = 2000.0
position = [300.0, 0.0, 0.0]
velocity = [0.0, 0.02, 0.0]
"#;
    let (_, s) = run(text, "flyby-point-masses");
    assert_eq!(s.status, "completed");
    assert!(s.energy_error < 1e-8, "energy error {:e}", s.energy_error);
    assert!(
        s.linear_momentum_error < 1e-8,
        "momentum residual {:e}",
        s.linear_momentum_error
    );
    assert!(
        s.tidal_impulse.is_some_and(|j| j > 1e3 * s.linear_momentum_error),
        "{:?}",
        s.tidal_impulse
    );
}

/// The flyby printout: "dP" is the momentum error only (the period change is `d(period)`), the tide's impulses carry
/// N s and N m s, mass lost says of what, and the end time has at most six significant digits (an adaptive step's
/// end once printed as `t = 48234.652155108546 s`).
fn flyby_printout_names_each_quantity_once(stdout: &str) {
    let words = |line: &str| line.split([' ', ',', '(', ')']).filter(|w| *w == "dP").count();
    for line in stdout.lines() {
        assert!(words(line) == 0, "dP as a word: {line}");
    }
    assert!(stdout.contains("|dP| "), "{stdout}");
    let flyby = stdout
        .lines()
        .find(|l| l.starts_with("flyby: "))
        .expect("the flyby line");
    assert!(
        flyby.contains(" d(period) ") && flyby.contains(" of the target's, "),
        "{flyby}"
    );
    let done = stdout
        .lines()
        .find(|l| l.starts_with("run: done: t = "))
        .expect("the run's done line");
    assert!(done.contains(" N s (") && done.contains(" N m s ("), "{done}");
    let t = done["run: done: t = ".len()..].split(' ').next().unwrap();
    let digits = t.chars().filter(char::is_ascii_digit).collect::<String>();
    assert!(digits.trim_start_matches('0').len() <= 6 || !t.contains('.'), "{done}");
}
