//! The `rubblepile` binary end to end: output directory handling, output file contract,
//! determinism, bodies files and lossless snapshots. Small scenes so the suite stays quick in debug.

mod common;
use common::{rubblepile, temp_dir};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Output;

use rubblepile::ellipsoid::output::{SNAPSHOT_COLUMNS, TIMESERIES_COLUMNS, read_bodies_csv};
use rubblepile::ellipsoid::scene::load_scene;

/// Two ellipsoids drifting into contact: gravity + contact + dissipation.
const SCENE: &str = r#"[scene]
kind = "ellipsoids"
t_end = 20.0
seed = 1

[model]
kappa = 10.0

[physics]
gravity = {}
contact = {}
dissipation = { F0 = 0.01 }

[integrator]
method = "bulirsch-stoer"
rtol = 1e-8
atol = 1e-8

[output]
times = [0.0, 7.5, 20.0]
every = 5.0

[[body]]
axes = [3.0, 2.0, 1.5]
mass = 30000.0
position = [0.0, 0.0, 0.0]
velocity = [0.05, 0.0, 0.0]
spin_body = [0.01, 0.02, 0.05]

[[body]]
axes = [2.0, 1.5, 1.0]
mass = 12000.0
position = [5.5, 0.5, 0.0]
velocity = [-0.1, 0.0, 0.0]
quaternion = [0.0, 0.0, 0.6, 0.8]
spin_body = [0.0, -0.03, 0.01]
"#;

/// The same bodies as `SCENE`'s [[body]] tables, as a bodies file (mass given, same numbers).
const BODIES_CSV: &str = "t,id,mass,a,b,c,x,y,z,vx,vy,vz,qa,qb,qc,qd,wx,wy,wz
0,0,30000,3,2,1.5,0,0,0,0.05,0,0,0,0,0,1,0.01,0.02,0.05
0,1,12000,2,1.5,1,5.5,0.5,0,-0.1,0,0,0,0,0.6,0.8,0,-0.03,0.01
";

fn assert_ok(out: &Output, what: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{what}: exit {:?}\nstdout: {stdout}\nstderr: {stderr}",
        out.status.code()
    );
    assert!(!stderr.contains("panicked"), "{what}: {stderr}");
}

/// Writes `scene` into `dir/name` and runs it into `dir/out_name`.
fn run_scene_text(dir: &Path, name: &str, scene: &str, out_name: &str, extra: &[&str]) -> Output {
    std::fs::write(dir.join(name), scene).unwrap();
    let mut args = vec!["run", name, "--out", out_name, "--no-progress"];
    args.extend_from_slice(extra);
    rubblepile(dir, &args)
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// All files under `dir` with their contents (relative path -> bytes), lock files aside (every writer, a refused one
/// too, writes its pid into them).
fn tree(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    common::files_below(dir)
        .into_iter()
        .map(|p| {
            let bytes = std::fs::read(dir.join(&p)).unwrap();
            (p, bytes)
        })
        .collect()
}

/// The time series without its wall_seconds column.
fn timeseries_without_wall(path: &Path) -> Vec<String> {
    read(path)
        .lines()
        .map(|l| l.rsplit_once(',').unwrap().0.to_string())
        .collect()
}

#[test]
fn refuses_non_empty_output_dir_without_force() {
    // Needs no physics: the check comes before anything is built.
    let dir = temp_dir("refuse");
    let out_dir = dir.join("out");
    std::fs::create_dir_all(&out_dir).unwrap();
    std::fs::write(out_dir.join("keep.txt"), "precious").unwrap();
    let before = tree(&out_dir);
    let out = run_scene_text(&dir, "scene.toml", SCENE, "out", &[]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with("error: output directory out exists and is not empty"),
        "{stderr}"
    );
    assert!(stderr.contains("--force"), "{stderr}");
    assert_eq!(tree(&out_dir), before, "files changed");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn output_path_that_is_a_file_is_refused() {
    let dir = temp_dir("file");
    std::fs::write(dir.join("out"), "x").unwrap();
    let out = run_scene_text(&dir, "scene.toml", SCENE, "out", &["--force"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("not a directory"), "{stderr}");
    assert_eq!(read(&dir.join("out")), "x");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_arguments_exit_2() {
    let dir = temp_dir("args");
    let out = rubblepile(&dir, &["run"]); // no --out
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(stderr.starts_with("error: ") && stderr.contains("--out"), "{stderr}");
    let out = rubblepile(&dir, &["bench", "rhs", "--bodies", "0"]);
    assert_eq!(out.status.code(), Some(2));
    let out = rubblepile(&dir, &["frobnicate"]);
    assert_eq!(out.status.code(), Some(2));
    let out = rubblepile(&dir, &["check", "--print-default"]);
    assert_ok(&out, "print default");
    assert!(String::from_utf8_lossy(&out.stdout).contains("kind = \"ellipsoids\""));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Needs the physics.
#[test]
fn force_overwrites_and_refusal_leaves_first_run_untouched() {
    let dir = temp_dir("force");
    let out = run_scene_text(&dir, "scene.toml", SCENE, "out", &[]);
    assert_ok(&out, "first run");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.starts_with("done: t = 20 s, wall "), "{stdout}");
    assert!(stdout.contains("energy error"), "{stdout}");
    let first = tree(&dir.join("out"));

    // A longer scene: without --force nothing changes.
    let longer = SCENE.replace("times = [0.0, 7.5, 20.0]", "times = [0.0, 1.0, 2.0, 7.5, 20.0]");
    let out = run_scene_text(&dir, "scene2.toml", &longer, "out", &[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--force"));
    assert_eq!(tree(&dir.join("out")), first, "refused run changed files");

    // With --force it runs, and the old outputs are replaced.
    let out = run_scene_text(&dir, "scene2.toml", &longer, "out", &["--force"]);
    assert_ok(&out, "forced run");
    assert_eq!(read(&dir.join("out/scene.toml")), longer);
    for k in 0..5 {
        assert!(dir.join(format!("out/snapshots/{k}.csv")).exists());
    }

    // And a shorter scene with --force leaves no stale snapshots behind.
    let out = run_scene_text(&dir, "scene.toml", SCENE, "out", &["--force"]);
    assert_ok(&out, "forced run 2");
    let snaps: BTreeSet<String> = std::fs::read_dir(dir.join("out/snapshots"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        snaps,
        ["0.csv", "1.csv", "2.csv"].iter().map(|s| s.to_string()).collect()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Needs the physics.
#[test]
fn output_files_follow_the_contract() {
    let dir = temp_dir("contract");
    let out = run_scene_text(&dir, "scene.toml", SCENE, "out", &[]);
    assert_ok(&out, "run");
    let o = dir.join("out");
    assert_eq!(read(&o.join("scene.toml")), SCENE);

    // timeseries.csv: exactly the columns; times = every-grid ∪ snapshot times, sorted, no duplicates.
    let ts = read(&o.join("timeseries.csv"));
    let mut lines = ts.lines();
    assert_eq!(lines.next().unwrap(), TIMESERIES_COLUMNS.join(","));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse::<f64>().unwrap()).collect())
        .collect();
    assert!(rows.iter().all(|r| r.len() == TIMESERIES_COLUMNS.len()));
    let times: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    assert_eq!(times, vec![0.0, 5.0, 7.5, 10.0, 15.0, 20.0]);
    assert_eq!(rows[0][6], 0.0, "energy residual at t = 0");
    assert!(rows.iter().all(|r| r.iter().all(|x| x.is_finite())));

    // snapshots/<k>.csv: exactly the columns, one row per body, t = the k-th time.
    for (k, t) in [0.0, 7.5, 20.0].into_iter().enumerate() {
        let s = read(&o.join(format!("snapshots/{k}.csv")));
        let mut lines = s.lines();
        assert_eq!(lines.next().unwrap(), SNAPSHOT_COLUMNS.join(","));
        let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
        assert_eq!(rows.len(), 2);
        for (id, r) in rows.iter().enumerate() {
            assert_eq!(r.len(), SNAPSHOT_COLUMNS.len());
            assert_eq!(r[0].parse::<f64>().unwrap(), t);
            assert_eq!(r[1], id.to_string());
        }
    }
    assert!(!o.join("last_good_state.csv").exists());

    // summary.json: the contract's keys.
    let summary: serde_json::Value = serde_json::from_str(&read(&o.join("summary.json"))).unwrap();
    for key in [
        "wall_seconds",
        "final_time",
        "steps_accepted",
        "steps_rejected",
        "rhs_evaluations",
        "energy_error",
        "linear_momentum_error",
        "angular_momentum_error",
        "quaternion_norm_error",
        "kappa",
        "integrator",
        "status",
        "scales",
        "n_bodies",
        "rotation_integrated",
        "smallest_step",
        "physics",
    ] {
        assert!(summary.get(key).is_some(), "summary.json lacks {key}: {summary}");
    }
    assert_eq!(summary["status"], "completed");
    assert_eq!(summary["final_time"], 20.0);
    assert_eq!(summary["n_bodies"], 2);
    assert_eq!(summary["kappa"], 10.0);
    assert_eq!(summary["integrator"], "bulirsch-stoer");
    assert!(summary["physics"]["gravity"]["G"].is_number());
    assert!(summary["physics"]["dissipation"]["F0"].is_number());
    for s in ["energy", "momentum", "angular_momentum"] {
        assert!(summary["scales"][s].as_f64().unwrap() > 0.0, "{s}");
        assert!(summary["scales"][format!("{s}_definition")].is_string());
    }
    assert!(summary["steps_accepted"].as_u64().unwrap() > 0);
    // Bulirsch–Stoer's rejections by cause add up to the rejected steps.
    let by_cause: u64 = ["error", "stability", "divergence", "nonfinite"]
        .iter()
        .map(|c| {
            summary["rejections"][c]
                .as_u64()
                .unwrap_or_else(|| panic!("rejections.{c}: {summary}"))
        })
        .sum();
    assert_eq!(by_cause, summary["steps_rejected"].as_u64().unwrap());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Needs the physics.
#[test]
fn same_scene_twice_gives_identical_results() {
    let dir = temp_dir("determinism");
    assert_ok(&run_scene_text(&dir, "scene.toml", SCENE, "a", &[]), "run a");
    assert_ok(&run_scene_text(&dir, "scene.toml", SCENE, "b", &[]), "run b");
    for k in 0..3 {
        let p = format!("snapshots/{k}.csv");
        assert_eq!(
            read(&dir.join("a").join(&p)),
            read(&dir.join("b").join(&p)),
            "{p} differs"
        );
    }
    assert_eq!(
        timeseries_without_wall(&dir.join("a/timeseries.csv")),
        timeseries_without_wall(&dir.join("b/timeseries.csv"))
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Needs the physics.
#[test]
fn bodies_file_gives_the_same_result_as_body_tables() {
    let dir = temp_dir("bodiesfile");
    std::fs::create_dir_all(dir.join("data")).unwrap();
    std::fs::write(dir.join("data/bodies.csv"), BODIES_CSV).unwrap();
    let head = &SCENE[..SCENE.find("[[body]]").unwrap()];
    let with_file = head.replacen("seed = 1", "seed = 1\nbodies_file = \"data/bodies.csv\"", 1);

    // Same bodies, bit for bit, from the library.
    std::fs::write(dir.join("tables.toml"), SCENE).unwrap();
    std::fs::write(dir.join("file.toml"), &with_file).unwrap();
    let a = load_scene(&dir.join("tables.toml")).unwrap();
    let b = load_scene(&dir.join("file.toml")).unwrap();
    assert_eq!(a.bodies, b.bodies);

    // Same outputs from the binary (the bodies file resolved relative to the scene file, not the cwd).
    assert_ok(&run_scene_text(&dir, "tables.toml", SCENE, "a", &[]), "tables");
    let sub = dir.join("elsewhere");
    std::fs::create_dir_all(&sub).unwrap();
    let out = rubblepile(&sub, &["run", "../file.toml", "--out", "../b", "--no-progress"]);
    assert_ok(&out, "bodies file");
    for k in 0..3 {
        let p = format!("snapshots/{k}.csv");
        assert_eq!(
            read(&dir.join("a").join(&p)),
            read(&dir.join("b").join(&p)),
            "{p} differs"
        );
    }
    assert_eq!(
        timeseries_without_wall(&dir.join("a/timeseries.csv")),
        timeseries_without_wall(&dir.join("b/timeseries.csv"))
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Needs the physics.
#[test]
fn snapshot_reread_as_bodies_file_is_lossless() {
    let dir = temp_dir("lossless");
    assert_ok(&run_scene_text(&dir, "scene.toml", SCENE, "out", &[]), "run");
    for k in 0..3 {
        let snap = dir.join(format!("out/snapshots/{k}.csv"));
        let records = read_bodies_csv(&snap).unwrap();
        // Re-read through a scene (as a restart would) and compare every number's bits.
        let head = &SCENE[..SCENE.find("[[body]]").unwrap()];
        let restart = head.replacen(
            "seed = 1",
            &format!("seed = 1\nbodies_file = \"out/snapshots/{k}.csv\""),
            1,
        );
        std::fs::write(dir.join("restart.toml"), &restart).unwrap();
        let scene = load_scene(&dir.join("restart.toml")).unwrap();
        assert_eq!(scene.bodies.len(), records.len());
        for (b, r) in scene.bodies.iter().zip(&records) {
            let got: Vec<u64> = [b.shape.mass]
                .into_iter()
                .chain(b.shape.axes.iter().copied())
                .chain(b.position.iter().copied())
                .chain(b.velocity.iter().copied())
                .chain(b.quaternion.iter().copied())
                .chain(b.spin_body.iter().copied())
                .map(f64::to_bits)
                .collect();
            let want: Vec<u64> = [r.mass]
                .into_iter()
                .chain(r.axes)
                .chain(r.position)
                .chain(r.velocity)
                .chain(r.quaternion)
                .chain(r.spin_body)
                .map(f64::to_bits)
                .collect();
            assert_eq!(got, want, "snapshot {k}");
        }
        // And the snapshot text itself re-formats identically.
        let rewritten = rubblepile::ellipsoid::output::snapshot_records(
            read(&snap)
                .lines()
                .nth(1)
                .unwrap()
                .split(',')
                .next()
                .unwrap()
                .parse()
                .unwrap(),
            &scene.bodies,
        );
        let original: Vec<Vec<String>> = read(&snap)
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(str::to_string).collect())
            .collect();
        assert_eq!(rewritten, original, "snapshot {k}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Needs the physics: two point masses falling head-on into each other (strong gravity, no contact term) drive
/// the integrator to a step-size underflow at their collision. (Two bodies at the same place at t = 0 used to be
/// this test's failure; since issue 38 such a start is refused before the run, exit 2, naming both bodies.)
#[test]
fn failed_run_writes_last_good_state_and_exits_1() {
    let dir = temp_dir("fail");
    let coincident = SCENE.replace("position = [5.5, 0.5, 0.0]", "position = [0.0, 0.0, 0.0]");
    let refused = run_scene_text(&dir, "coincident.toml", &coincident, "refused", &[]);
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(refused.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("body[1].position: coincides with body[0]"), "{stderr}");
    let broken = SCENE
        .replace("gravity = {}", "gravity = { G = 1e-3 }")
        .replace("contact = {}\ndissipation = { F0 = 0.01 }\n", "")
        .replace("position = [5.5, 0.5, 0.0]", "position = [5.5, 0.0, 0.0]");
    let out = run_scene_text(&dir, "scene.toml", &broken, "out", &[]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(stderr.starts_with("error: run failed: "), "{stderr}");
    assert!(stderr.contains("last good state (t = "), "{stderr}");
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("stopped: t = "));
    assert!(dir.join("out/last_good_state.csv").exists());
    let summary: serde_json::Value = serde_json::from_str(&read(&dir.join("out/summary.json"))).unwrap();
    assert_ne!(summary["status"], "completed");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Needs the physics (calibration).
#[test]
fn default_scene_checks() {
    let dir = temp_dir("default");
    let out = rubblepile(&dir, &["check"]);
    assert_ok(&out, "check default");
    assert!(String::from_utf8_lossy(&out.stdout).contains("calibrated"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `bench rhs` over several sizes writes one CSV row per (N, threads) and the SVG plot, and refuses to
/// overwrite them without `--force`.
#[test]
fn bench_rhs_writes_csv_and_plot() {
    let dir = temp_dir("bench");
    let args = [
        "bench",
        "rhs",
        "--bodies",
        "8,30",
        "--repeats",
        "3",
        "--threads",
        "2",
        "--out",
        "bench",
    ];
    let out = rubblepile(&dir, &args);
    assert_ok(&out, "bench");
    let csv = read(&dir.join("bench/bench_rhs.csv"));
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "bodies,threads,median_us,min_us,repeats,gravity,packing,candidate_pairs,interacting_pairs,touching_pairs"
    );
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 4);
    assert!(
        rows[0].starts_with("8,1,") && rows[0].contains(",3,auto,lattice,"),
        "{}",
        rows[0]
    );
    assert!(rows[1].starts_with("8,2,"), "{}", rows[1]);
    assert!(rows[3].starts_with("30,2,"), "{}", rows[3]);
    let svg = read(&dir.join("bench/bench_rhs.svg"));
    assert!(
        svg.contains("<svg") && svg.contains("number of bodies N"),
        "plot lacks its axis label"
    );
    // The x ticks are the benchmarked sizes (plotters' own log ticks vanish over less than a decade).
    let texts: Vec<&str> = svg.lines().map(str::trim).collect();
    assert!(
        texts.contains(&"8") && texts.contains(&"30"),
        "the sizes are not the x ticks"
    );
    // Every tick label is a plain number with one significant digit (y: 1–2–5 per decade, or 1–9 over a narrow
    // range), not plotters' own crowded "9000.0" labels; the times of a few bodies' RHS are above 1 µs.
    let numbers: Vec<f64> = texts.iter().filter_map(|t| t.parse::<f64>().ok()).collect();
    assert!(numbers.len() >= 4, "too few tick labels: {numbers:?}");
    for t in texts.iter().filter(|t| t.parse::<f64>().is_ok()) {
        let v: f64 = t.parse().unwrap();
        let mantissa = v / 10f64.powf(v.log10().floor());
        assert!(
            !t.contains('.') && (v == 30.0 || (mantissa - mantissa.round()).abs() < 1e-9),
            "tick label {t} is not a plain round number"
        );
    }
    let again = rubblepile(&dir, &args);
    assert_eq!(again.status.code(), Some(2), "overwrote a benchmark without --force");
    assert_eq!(
        read(&dir.join("bench/bench_rhs.csv")),
        csv,
        "first benchmark's CSV changed"
    );
    let mut forced = args.to_vec();
    forced.push("--force");
    assert_ok(&rubblepile(&dir, &forced), "bench --force");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `bench rhs --targets` times a relaxed pile (its N from the file, its κ from `FILE.json`) in rows labelled by
/// the file's stem, also with a Bulirsch–Stoer step's frozen tree lists (`tree-step`), and a target without its
/// report is refused naming the flag.
#[test]
fn bench_rhs_times_relaxed_targets() {
    let dir = temp_dir("bench_targets");
    let target = Path::new(env!("CARGO_MANIFEST_DIR")).join("targets/N30_T4.csv");
    let target = target.to_str().unwrap();
    let args = [
        "bench",
        "rhs",
        "--targets",
        target,
        "--repeats",
        "2",
        "--threads",
        "1",
        "--gravity",
        "auto,none,tree-step",
        "--out",
        "b",
    ];
    assert_ok(&rubblepile(&dir, &args), "bench --targets");
    let csv = read(&dir.join("b/bench_rhs.csv"));
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 3, "{csv}");
    for (row, gravity) in rows.iter().zip(["auto", "none", "tree-step"]) {
        assert_eq!(
            (row[0], row[1], row[4], row[5], row[6]),
            ("30", "1", "2", gravity, "N30_T4"),
            "{csv}"
        );
        // the relaxed pile's pair counts: candidates ≥ interacting ≥ touching > 0, the same for both rows
        let counts: Vec<usize> = row[7..10].iter().map(|c| c.parse().unwrap()).collect();
        assert!(
            counts[0] >= counts[1] && counts[1] >= counts[2] && counts[2] > 0,
            "{csv}"
        );
    }
    assert_eq!(rows[0][7..], rows[1][7..], "{csv}");
    assert_eq!(rows[0][7..], rows[2][7..], "{csv}");
    std::fs::copy(target, dir.join("lonely.csv")).unwrap();
    let out = rubblepile(&dir, &["bench", "rhs", "--targets", "lonely.csv", "--repeats", "1"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("--targets") && stderr.contains("lonely.json"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every example scene under `targets/examples/` is valid for its engine (`rubblepile check` accepts it).
#[test]
fn example_scenes_are_valid() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("targets/examples");
    let mut kinds = Vec::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let text = std::fs::read_to_string(&path).unwrap();
            let kind = rubblepile::io::scene_file::peek_kind(&text).unwrap_or_default();
            if kind == "ellipsoids" {
                load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
            }
            let out = std::process::Command::new(env!("CARGO_BIN_EXE_rubblepile"))
                .arg("check")
                .arg(&path)
                .output()
                .unwrap();
            assert!(
                out.status.success(),
                "{}: {}",
                path.display(),
                String::from_utf8_lossy(&out.stderr)
            );
            kinds.push(kind);
        }
    }
    for k in ["ellipsoids", "soft-spheres", "hard-spheres"] {
        assert!(kinds.iter().any(|x| x == k), "no {k} example: {kinds:?}");
    }
}

/// `report roig2003|zhang2017|richardson2011` and the old hyphenated spellings (hidden aliases) all parse.
#[test]
fn report_verb_and_its_old_spellings_parse() {
    let dir = common::temp_dir("report-verb");
    for args in [
        &["report", "roig2003", "--help"][..],
        &["report", "zhang2017", "--help"],
        &["report", "richardson2011", "--help"],
        &["report-roig2003", "--help"],
        &["report-zhang2017", "--help"],
        &["report-richardson2011", "--help"],
    ] {
        let out = common::rubblepile(&dir, args);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let help = common::rubblepile(&dir, &["--help"]);
    let text = String::from_utf8_lossy(&help.stdout);
    assert!(text.contains("report "), "{text}");
    assert!(!text.contains("report-roig2003"), "old spellings are hidden: {text}");
}
