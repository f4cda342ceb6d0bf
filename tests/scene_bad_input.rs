//! Bad scene input gives a one-line error naming the field, never a panic — both from the library
//! (`parse_scene`) and from the binary (`rubblepile run bad.toml --out DIR`: exit code 2, one line on
//! stderr, no output directory created).

mod common;
use common::temp_dir;
use std::path::Path;
use std::process::Command;

use rubblepile::ellipsoid::scene::parse_scene;
use rubblepile::io::scene_file::SceneError;

const BASE: &str = r#"[scene]
kind = "ellipsoids"
t_end = 200.0
seed = 1

[model]
kappa = 10.0
inertia = "gaussian"

[physics]
gravity = { G = 6.674e-11 }
contact = {}
dissipation = { F0 = 1.0 }

[integrator]
method = "bulirsch-stoer"
rtol = 1e-10
atol = 1e-10

[output]
times = [0.0, 100.0, 200.0]
every = 1.0

[[body]]
axes = [3.0, 2.0, 1.0]
mass = 1000.0
position = [0.0, 0.0, 0.0]
velocity = [0.0, 0.0, 0.0]
quaternion = [0.0, 0.0, 0.0, 1.0]
spin_body = [0.01, 0.5, 0.02]

[[body]]
axes = [2.0, 2.0, 2.0]
density = 3000.0
position = [10.0, 0.0, 0.0]
velocity = [-0.1, 0.0, 0.0]
"#;

/// `BASE` with the first occurrence of `from` replaced by `to` (which must exist).
fn with(from: &str, to: &str) -> String {
    assert!(BASE.contains(from), "test bug: {from:?} not in BASE");
    BASE.replacen(from, to, 1)
}

/// Only the second body's line `from` replaced.
fn with_body1(from: &str, to: &str) -> String {
    let split = BASE.rfind("[[body]]").unwrap();
    let (head, tail) = BASE.split_at(split);
    assert!(tail.contains(from), "test bug: {from:?} not in body[1]");
    format!("{head}{}", tail.replacen(from, to, 1))
}

/// A `[physics.flyby]` table (placed before `[integrator]`) with the planet line(s) `planet` and orbit line(s) `orbit`.
fn flyby(planet: &str, orbit: &str) -> String {
    format!("[physics.flyby]\n{planet}\nq = 1e7\n{orbit}\nt_perigee = 100.0\n\n[integrator]")
}

/// (case name, scene text, text the one-line error must contain)
fn cases() -> Vec<(&'static str, String, &'static str)> {
    let mut v: Vec<(&'static str, String, &'static str)> = vec![
        ("malformed toml", with("[physics]", "[physics"), "line 10"),
        ("malformed value", with("t_end = 200.0", "t_end = "), "line 3"),
        (
            "unknown key in [physics]",
            with("contact = {}", "contact = {}\nfoo = 1"),
            "unknown field `foo` in [physics]",
        ),
        (
            "unknown key in [scene]",
            with("seed = 1", "seed = 1\nname = \"x\""),
            "unknown field `name` in [scene]",
        ),
        (
            "unknown top-level table",
            format!("{BASE}\n[extra]\nx = 1\n"),
            "unknown field `extra`",
        ),
        (
            "unknown key in a term",
            with("contact = {}", "contact = { cutof = 1e-10 }"),
            "unknown field `cutof` in [physics.contact]",
        ),
        (
            "unknown key in a body",
            with_body1("density = 3000.0", "density = 3000.0\ncolour = \"red\""),
            "unknown field `colour` in body[1]",
        ),
        ("wrong type", with("t_end = 200.0", "t_end = \"long\""), "scene.t_end"),
        (
            "axes of wrong length",
            with("axes = [3.0, 2.0, 1.0]", "axes = [3.0, 2.0]"),
            "body[0].axes",
        ),
        ("missing t_end", with("t_end = 200.0\n", ""), "scene.t_end: missing"),
        ("missing every", with("every = 1.0\n", ""), "output.every: missing"),
        (
            "missing [model]",
            with("[model]\nkappa = 10.0\ninertia = \"gaussian\"\n", ""),
            "model: missing",
        ),
        (
            "missing position",
            with("position = [0.0, 0.0, 0.0]\n", ""),
            "body[0].position: missing",
        ),
        (
            "unknown method",
            with("\"bulirsch-stoer\"", "\"euler\""),
            "integrator.method",
        ),
        ("unknown inertia", with("\"gaussian\"", "\"hollow\""), "model.inertia"),
        (
            "A < B",
            with("[3.0, 2.0, 1.0]", "[1.0, 2.0, 3.0]"),
            "body[0].axes: need A >= B >= C > 0, got [1, 2, 3]",
        ),
        (
            "B < C",
            with("[3.0, 2.0, 1.0]", "[3.0, 1.0, 2.0]"),
            "body[0].axes: need A >= B >= C > 0",
        ),
        (
            "zero axis",
            with_body1("[2.0, 2.0, 2.0]", "[2.0, 2.0, 0.0]"),
            "body[1].axes: need A >= B >= C > 0",
        ),
        (
            "negative axes",
            with("[3.0, 2.0, 1.0]", "[-1.0, -2.0, -3.0]"),
            "body[0].axes",
        ),
        (
            "non-finite axis",
            with("[3.0, 2.0, 1.0]", "[inf, 2.0, 1.0]"),
            "body[0].axes: non-finite value",
        ),
        (
            "negative mass",
            with("mass = 1000.0", "mass = -5.0"),
            "body[0].mass: must be > 0 and finite, got -5",
        ),
        (
            "zero mass",
            with("mass = 1000.0", "mass = 0.0"),
            "body[0].mass: must be > 0",
        ),
        ("nan mass", with("mass = 1000.0", "mass = nan"), "body[0].mass"),
        (
            "negative density",
            with("density = 3000.0", "density = -3000.0"),
            "body[1].density: must be > 0",
        ),
        (
            "zero density",
            with("density = 3000.0", "density = 0.0"),
            "body[1].density: must be > 0",
        ),
        (
            "mass and density",
            with("mass = 1000.0", "mass = 1000.0\ndensity = 2.0"),
            "body[0]: give exactly one of `mass` or `density`",
        ),
        (
            "neither mass nor density",
            with("mass = 1000.0\n", ""),
            "body[0]: give exactly one of `mass` or `density`",
        ),
        (
            "non-finite position",
            with_body1("[10.0, 0.0, 0.0]", "[10.0, inf, 0.0]"),
            "body[1].position: non-finite value",
        ),
        (
            "nan velocity",
            with_body1("[-0.1, 0.0, 0.0]", "[nan, 0.0, 0.0]"),
            "body[1].velocity: non-finite value",
        ),
        (
            "non-finite spin",
            with("[0.01, 0.5, 0.02]", "[0.01, -inf, 0.02]"),
            "body[0].spin_body: non-finite value",
        ),
        (
            "non-finite quaternion",
            with("[0.0, 0.0, 0.0, 1.0]", "[0.0, 0.0, nan, 1.0]"),
            "body[0].quaternion",
        ),
        (
            "quaternion not unit",
            with("[0.0, 0.0, 0.0, 1.0]", "[0.0, 0.0, 0.0, 2.0]"),
            "body[0].quaternion: must have unit norm",
        ),
        (
            "spin_body and spin_world",
            with(
                "spin_body = [0.01, 0.5, 0.02]",
                "spin_body = [0.01, 0.5, 0.02]\nspin_world = [0.0, 0.0, 1.0]",
            ),
            "body[0]: give at most one of `spin_body` or `spin_world`",
        ),
        (
            "rtol zero",
            with("rtol = 1e-10", "rtol = 0.0"),
            "integrator.rtol: must be in [1e-15, 1)",
        ),
        (
            "rtol negative",
            with("rtol = 1e-10", "rtol = -1"),
            "integrator.rtol: must be in [1e-15, 1), got -1e0",
        ),
        ("rtol nan", with("rtol = 1e-10", "rtol = nan"), "integrator.rtol"),
        (
            "atol negative",
            with("atol = 1e-10", "atol = -1e-10"),
            "integrator.atol: must be >= 0",
        ),
        ("atol inf", with("atol = 1e-10", "atol = inf"), "integrator.atol"),
        (
            "step negative",
            with("atol = 1e-10", "atol = 1e-10\nstep = -1.0"),
            "integrator.step: must be > 0",
        ),
        (
            "rk4 without step",
            with("\"bulirsch-stoer\"", "\"rk4\""),
            "integrator.step",
        ),
        (
            "kappa 1.5",
            with("kappa = 10.0", "kappa = 1.5"),
            "model.kappa: must be > 1.5",
        ),
        (
            "kappa 1",
            with("kappa = 10.0", "kappa = 1.0"),
            "model.kappa: must be > 1.5",
        ),
        ("kappa inf", with("kappa = 10.0", "kappa = inf"), "model.kappa"),
        (
            "kappa and calibrate",
            with("kappa = 10.0", "kappa = 10.0\ncalibrate = { beta = 10.0, v = 1.0 }"),
            "model: give exactly one of `kappa` or `calibrate`",
        ),
        (
            "neither kappa nor calibrate",
            with("kappa = 10.0\n", ""),
            "model: give exactly one of `kappa` or `calibrate`",
        ),
        (
            "calibrate reading unknown",
            with("kappa = 10.0", "calibrate = { beta = 10.0, v = 1.0, reading = \"mu\" }"),
            "unknown variant `mu`, expected one of `printed`, `impactor`, `reduced`",
        ),
        (
            "calibrate beta negative",
            with("kappa = 10.0", "calibrate = { beta = -1.0, v = 1.0 }"),
            "model.calibrate.beta: must be > 0",
        ),
        (
            "calibrate v zero",
            with("kappa = 10.0", "calibrate = { beta = 10.0, v = 0.0 }"),
            "model.calibrate.v: must be > 0",
        ),
        (
            "calibrate unknown key",
            with("kappa = 10.0", "calibrate = { beta = 10.0, speed = 1.0 }"),
            "unknown field `speed` in [model.calibrate]",
        ),
        (
            "t_end zero",
            with("t_end = 200.0", "t_end = 0.0"),
            "scene.t_end: must be > 0",
        ),
        (
            "t_end negative",
            with("t_end = 200.0", "t_end = -5.0"),
            "scene.t_end: must be > 0",
        ),
        ("t_end inf", with("t_end = 200.0", "t_end = inf"), "scene.t_end"),
        (
            "every zero",
            with("every = 1.0", "every = 0.0"),
            "output.every: must be > 0",
        ),
        (
            "every negative",
            with("every = 1.0", "every = -1.0"),
            "output.every: must be > 0",
        ),
        (
            "every too small",
            with("every = 1.0", "every = 1e-12"),
            "output.every: too small",
        ),
        (
            "time negative",
            with("[0.0, 100.0, 200.0]", "[-1.0, 100.0, 200.0]"),
            "output.times[0]: must be in [0, t_end = 200]",
        ),
        (
            "time beyond t_end",
            with("[0.0, 100.0, 200.0]", "[0.0, 100.0, 300.0]"),
            "output.times[2]: must be in [0, t_end = 200], got 300",
        ),
        (
            "time nan",
            with("[0.0, 100.0, 200.0]", "[0.0, nan, 200.0]"),
            "output.times[1]",
        ),
        (
            "times unsorted",
            with("[0.0, 100.0, 200.0]", "[0.0, 150.0, 100.0]"),
            "output.times: must be strictly increasing",
        ),
        (
            "times duplicated",
            with("[0.0, 100.0, 200.0]", "[0.0, 100.0, 100.0]"),
            "output.times: must be strictly increasing",
        ),
        (
            "track out of range",
            with("every = 1.0", "every = 1.0\ntrack = [7]"),
            "output.track[0]: must be a body index below",
        ),
        (
            "track listed twice",
            with("every = 1.0", "every = 1.0\ntrack = [0, 0]"),
            "output.track[1]: body 0 is listed twice",
        ),
        (
            "track negative",
            with("every = 1.0", "every = 1.0\ntrack = [-1]"),
            "output.track",
        ),
        (
            "kind",
            with("\"ellipsoids\"", "\"spheres\""),
            "scene.kind: must be one of \"ellipsoids\", \"soft-spheres\", \"hard-spheres\", got \"spheres\"",
        ),
        (
            "no bodies",
            BASE[..BASE.find("[[body]]").unwrap()].to_string(),
            "no bodies",
        ),
        (
            "bodies_file and bodies",
            with("seed = 1", "seed = 1\nbodies_file = \"b.csv\""),
            "scene.bodies_file: give either",
        ),
        (
            "bodies_file missing",
            {
                let head = &BASE[..BASE.find("[[body]]").unwrap()];
                head.replacen("seed = 1", "seed = 1\nbodies_file = \"does-not-exist.csv\"", 1)
            },
            "scene.bodies_file: cannot read",
        ),
        (
            "F0 negative",
            with("F0 = 1.0", "F0 = -1.0"),
            "physics.dissipation.F0: must be >= 0",
        ),
        ("F0 nan", with("F0 = 1.0", "F0 = nan"), "physics.dissipation.F0"),
        (
            "F0 missing",
            with("dissipation = { F0 = 1.0 }", "dissipation = {}"),
            "physics.dissipation.F0: missing",
        ),
        (
            "G zero",
            with("G = 6.674e-11", "G = 0.0"),
            "physics.gravity.G: must be > 0",
        ),
        (
            "G negative",
            with("G = 6.674e-11", "G = -1.0"),
            "physics.gravity.G: must be > 0",
        ),
        ("G inf", with("G = 6.674e-11", "G = inf"), "physics.gravity.G"),
        (
            "gravity theta zero",
            with("G = 6.674e-11", "G = 6.674e-11, method = \"tree\", theta = 0.0"),
            "physics.gravity.theta: must be in (0, 1], got 0",
        ),
        (
            "gravity theta large",
            with("G = 6.674e-11", "G = 6.674e-11, theta = 1.5"),
            "physics.gravity.theta: must be in (0, 1]",
        ),
        (
            "gravity method unknown",
            with("G = 6.674e-11", "G = 6.674e-11, method = \"fast\""),
            "physics.gravity.method",
        ),
        (
            "cutoff zero",
            with("contact = {}", "contact = { cutoff = 0.0 }"),
            "physics.contact.cutoff: must be in (0, 1), got 0",
        ),
        (
            "cutoff one",
            with("contact = {}", "contact = { cutoff = 1.0 }"),
            "physics.contact.cutoff: must be in (0, 1)",
        ),
        (
            "cutoff large",
            with("contact = {}", "contact = { cutoff = 2.0 }"),
            "physics.contact.cutoff: must be in (0, 1)",
        ),
        (
            "cutoff nan",
            with("contact = {}", "contact = { cutoff = nan }"),
            "physics.contact.cutoff",
        ),
        (
            "flyby negative mass",
            with("[integrator]", &flyby("mass = -1.0", "v_inf = 5800.0")),
            "physics.flyby.mass: must be >= 0",
        ),
        (
            "flyby perigee inside the planet",
            with("[integrator]", &flyby("mass = 6e24\nradius = 2e7", "v_inf = 5800.0")),
            "physics.flyby.q: must exceed the planet's radius",
        ),
        (
            "flyby both v_inf and eccentricity",
            with(
                "[integrator]",
                &flyby("mass = 6e24", "v_inf = 5800.0\neccentricity = 2.0"),
            ),
            "physics.flyby: give exactly one of `v_inf` or `eccentricity`, got both",
        ),
        (
            "flyby neither v_inf nor eccentricity",
            with("[integrator]", &flyby("mass = 6e24", "")),
            "physics.flyby: give exactly one of `v_inf` or `eccentricity`, got neither",
        ),
        (
            "flyby parabolic",
            with("[integrator]", &flyby("mass = 6e24", "eccentricity = 1.0")),
            "physics.flyby.eccentricity: must be >= 0 and != 1",
        ),
        (
            "flyby zero v_inf",
            with("[integrator]", &flyby("mass = 6e24", "v_inf = 0.0")),
            "physics.flyby.v_inf: must be > 0",
        ),
        (
            "flyby missing q",
            with(
                "[integrator]",
                &flyby("mass = 6e24", "v_inf = 5800.0").replace("q = 1e7\n", ""),
            ),
            "q",
        ),
        (
            "flyby unknown key",
            with("[integrator]", &flyby("mass = 6e24\nJ2 = 1e-3", "v_inf = 5800.0")),
            "unknown field `J2`",
        ),
        (
            "flyby massless with eccentricity",
            with("[integrator]", &flyby("mass = 0.0", "eccentricity = 0.5")),
            "physics.flyby.mass: must be > 0 kg with `eccentricity`",
        ),
    ];
    v.sort_by_key(|c| c.0);
    v
}

fn check_message(case: &str, msg: &str, expected: &str) {
    assert!(!msg.contains('\n'), "{case}: error is not one line: {msg:?}");
    assert!(
        msg.starts_with("scene.toml: "),
        "{case}: error does not name the file: {msg:?}"
    );
    assert!(
        msg.contains(expected),
        "{case}: error {msg:?} does not contain {expected:?}"
    );
}

#[test]
fn base_scene_is_valid() {
    let s = parse_scene(BASE, "scene.toml", None).expect("BASE must be valid");
    assert_eq!(s.bodies.len(), 2);
}

#[test]
fn bad_input_from_strings() {
    let dir = temp_dir("strings");
    for (case, text, expected) in cases() {
        let err: SceneError = match parse_scene(&text, "scene.toml", Some(&dir)) {
            Ok(_) => panic!("{case}: accepted"),
            Err(e) => e,
        };
        check_message(case, &err.to_string(), expected);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

fn run_binary(scene: &Path, out: &Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_rubblepile"))
        .arg("run")
        .arg(scene)
        .arg("--out")
        .arg(out)
        .arg("--no-progress")
        .current_dir(scene.parent().unwrap())
        .output()
        .expect("run the binary")
}

fn check_cli(case: &str, out: &std::process::Output, out_dir: &Path, expected: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(2),
        "{case}: exit code {:?}, stderr {stderr:?}",
        out.status.code()
    );
    assert!(!stderr.contains("panicked"), "{case}: panicked: {stderr}");
    let stderr = stderr.trim_end();
    assert_eq!(stderr.lines().count(), 1, "{case}: stderr is not one line: {stderr:?}");
    let msg = stderr
        .strip_prefix("error: ")
        .unwrap_or_else(|| panic!("{case}: no `error: ` prefix: {stderr:?}"));
    check_message(case, msg, expected);
    assert!(!out_dir.exists(), "{case}: output directory created for a bad scene");
}

#[test]
fn bad_input_via_cli() {
    let dir = temp_dir("cli");
    for (k, (case, text, expected)) in cases().into_iter().enumerate() {
        let case_dir = dir.join(format!("case{k}"));
        std::fs::create_dir_all(&case_dir).unwrap();
        let scene = case_dir.join("scene.toml");
        std::fs::write(&scene, &text).unwrap();
        let out_dir = case_dir.join("out");
        // Run with the path relative to the case directory so the message names `scene.toml`.
        let out = Command::new(env!("CARGO_BIN_EXE_rubblepile"))
            .args(["run", "scene.toml", "--out", "out", "--no-progress"])
            .current_dir(&case_dir)
            .output()
            .expect("run the binary");
        check_cli(case, &out, &out_dir, expected);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn missing_scene_file_is_one_line_exit_2() {
    let dir = temp_dir("missing");
    let out = run_binary(&dir.join("nope.toml"), &dir.join("out"));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(stderr.contains("nope.toml: cannot read"), "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_bodies_file_names_line_and_column() {
    let dir = temp_dir("bodies");
    let header = "t,id,mass,a,b,c,x,y,z,vx,vy,vz,qa,qb,qc,qd,wx,wy,wz\n";
    let head = &BASE[..BASE.find("[[body]]").unwrap()];
    let scene = head.replacen("seed = 1", "seed = 1\nbodies_file = \"b.csv\"", 1);
    let cases = [
        (
            "negative mass",
            format!("{header}0,0,-5,3,2,1,0,0,0,0,0,0,0,0,0,1,0,0,0\n"),
            "body[0] (b.csv line 2).mass: must be > 0",
        ),
        (
            "axes order",
            format!("{header}0,0,1,3,2,1,0,0,0,0,0,0,0,0,0,1,0,0,0\n0,1,1,1,2,3,0,0,0,0,0,0,0,0,0,1,0,0,0\n"),
            "body[1] (b.csv line 3).axes: need A >= B >= C > 0, got [1, 2, 3]",
        ),
        (
            "not a number",
            format!("{header}0,0,1,3,2,1,0,0,0,0,0,0,0,0,0,1,0,0,abc\n"),
            "line 2: column `wz`: not a number",
        ),
        (
            "inf",
            format!("{header}0,0,1,3,2,1,0,inf,0,0,0,0,0,0,0,1,0,0,0\n"),
            "body[0] (b.csv line 2).position: non-finite value",
        ),
        (
            "missing column",
            "mass,a,b,c\n1,1,1,1\n".to_string(),
            "missing column `x`",
        ),
        (
            "unknown column",
            format!("{}mass2\n", header.trim_end().to_string() + ","),
            "unknown column `mass2`",
        ),
        ("no rows", header.to_string(), "no bodies"),
        (
            "quaternion",
            format!("{header}0,0,1,3,2,1,0,0,0,0,0,0,0,0,0,1.1,0,0,0\n"),
            "body[0] (b.csv line 2).quaternion: must have unit norm",
        ),
    ];
    for (case, csv, expected) in cases {
        std::fs::write(dir.join("b.csv"), csv).unwrap();
        let err = parse_scene(&scene, "scene.toml", Some(&dir))
            .err()
            .unwrap_or_else(|| panic!("{case}: accepted"));
        check_message(case, &err.to_string(), expected);
        std::fs::write(dir.join("scene.toml"), &scene).unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_rubblepile"))
            .args(["run", "scene.toml", "--out", "out", "--no-progress"])
            .current_dir(&dir)
            .output()
            .unwrap();
        check_cli(case, &out, &dir.join("out"), expected);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `model.calibrate.reading` reaches the κ of the run: the reduced reading gives the softer κ of
/// `calibrate_kappa_read` for the scene's lightest and heaviest bodies, and the default is the printed one.
#[test]
fn calibrate_reading_sets_the_scenes_kappa() {
    use rubblepile::ellipsoid::calibration::{KappaReading, calibrate_kappa_read};
    let kappa = |reading: &str| {
        let text = with(
            "kappa = 10.0",
            &format!("calibrate = {{ beta = 10.0, v = 20.0{reading} }}"),
        );
        let scene = parse_scene(&text, "scene.toml", None).expect("valid scene");
        let m = |f: fn(f64, f64) -> f64| scene.bodies.iter().map(|b| b.shape.mass).fold(f64::NAN, f);
        let body = |mass: f64| {
            let b = scene.bodies.iter().find(|b| b.shape.mass == mass).unwrap();
            (b.shape.equivalent_radius(), b.shape.mass)
        };
        (
            scene.model.kappa,
            scene.model.contact_g,
            body(m(f64::min)),
            body(m(f64::max)),
        )
    };
    let (printed, g, small, large) = kappa("");
    let (reduced, ..) = kappa(", reading = \"reduced\"");
    let expect = |r| calibrate_kappa_read(r, 10.0, 20.0, small, large, g).unwrap();
    assert_eq!(printed, expect(KappaReading::Printed));
    assert_eq!(reduced, expect(KappaReading::Reduced));
    assert!(reduced < printed, "reduced {reduced}, printed {printed}");
}

/// Needs `calibrate_kappa` (the physics).
#[test]
fn unreachable_kappa() {
    let text = with("kappa = 10.0", "calibrate = { beta = 10.0, v = 1e-12 }");
    let err = parse_scene(&text, "scene.toml", None).expect_err("accepted an unreachable kappa");
    check_message("unreachable kappa", &err.to_string(), "model.calibrate");
    let dir = temp_dir("kappa");
    std::fs::write(dir.join("scene.toml"), &text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_rubblepile"))
        .args(["run", "scene.toml", "--out", "out", "--no-progress"])
        .current_dir(&dir)
        .output()
        .unwrap();
    check_cli("unreachable kappa", &out, &dir.join("out"), "model.calibrate");
    let _ = std::fs::remove_dir_all(&dir);
}
