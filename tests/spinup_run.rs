//! Spin-up runs through the command line (Zhang17 §2.3.4): the central body follows the period path to
//! round-off while forced (the default period target), `spinup.csv` is written at every output sample, a run interrupted after a checkpoint
//! resumes bit for bit with the driver's state, and bad `[spinup]` input gives a one-line error naming the field.

mod common;
use common::{rubblepile, snapshots, temp_dir};
use rubblepile::analysis::spinup_diagnostics::read_spinup_csv;
use rubblepile::geometry::lattice::hcp_centres;
use std::path::Path;

/// A ball of ~90 spheres (r = 1 m, 1000 kg/m³) cut from an HCP lattice, stiff contacts (static overlaps ~0.05 %
/// of a radius) so that it stays nearly rigid, spun from 8 h to 6 h (its critical period is about 4 h).
fn scene(dir: &Path, spinup: &str) -> String {
    let mut csv = String::from("t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz\n");
    let m = 1000.0 * 4.0 / 3.0 * std::f64::consts::PI;
    for (k, p) in hcp_centres(1.0, 5.0).iter().enumerate() {
        csv += &format!("0,{k},{m},1.0,{},{},{},0,0,0,0,0,0\n", p.x, p.y, p.z);
    }
    std::fs::write(dir.join("ball.csv"), csv).unwrap();
    format!(
        r#"[scene]
kind = "soft-spheres"
t_end = 2400.0
seed = 7
particles_file = "ball.csv"

[stepping]
dt = 1.2

[material]
k_n = 15.0

[gravity]
self = "direct"

[output]
every = 120.0
times = [0.0, 1200.0, 2400.0]

{spinup}
"#
    )
}

const PATH: &str = r#"[spinup]
T_start = 8.0
T_inter = 7.0
T_final = 6.0
t_start = 600.0
t_inter = 1200.0
t_final = 2000.0
rve_particles = 30
"#;

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn forced_body_follows_the_path_and_resumes_bit_identically() {
    let dir = temp_dir("spinup-run");
    std::fs::write(dir.join("s.toml"), scene(&dir, PATH)).unwrap();
    let a = rubblepile(&dir, &["run", "s.toml", "--out", "a", "--no-progress"]);
    assert!(a.status.success(), "{}", String::from_utf8_lossy(&a.stderr));
    let rows = read_spinup_csv(&dir.join("a/spinup.csv")).unwrap();
    assert_eq!(rows.len(), 21, "one row per time-series sample");
    for r in &rows {
        assert!(r.forcing, "released at t = {} s although the body holds", r.t);
        let err = (r.period_h / r.path_period_h - 1.0).abs();
        assert!(
            err < 1e-9,
            "t = {} s: period {} h vs path {} h",
            r.t,
            r.period_h,
            r.path_period_h
        );
        assert_eq!(r.body_particles, rows[0].body_particles, "the ball lost members");
        assert!(r.rves >= 2 && r.coordination_number > 3.0, "{r:?}");
        // force-floored contacts are a subset of all contacts; in a settled ball nearly all of them carry load
        assert!(
            r.coordination_loaded <= r.coordination_number && r.coordination_loaded > 0.9 * r.coordination_number,
            "{r:?}"
        );
    }
    // the path itself: T_start until t_start, linear to T_inter, then to T_final, then held
    let at = |t: f64| rows.iter().find(|r| (r.t - t).abs() < 1e-6).unwrap().path_period_h;
    assert_eq!(at(600.0), 8.0);
    assert!((at(960.0) - 7.4).abs() < 1e-12);
    assert!((at(1560.0) - 6.55).abs() < 1e-12);
    assert_eq!(at(2400.0), 6.0);

    // interrupted after the second checkpoint and resumed: the same bits as the uninterrupted run
    let c = rubblepile(
        &dir,
        &[
            "run",
            "s.toml",
            "--out",
            "c",
            "--no-progress",
            "--checkpoint-every-sim-s",
            "500",
            "--stop-after-checkpoints",
            "2",
        ],
    );
    assert_eq!(c.status.code(), Some(3), "{}", String::from_utf8_lossy(&c.stderr));
    let r = rubblepile(&dir, &["resume", "c", "--no-progress"]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert_eq!(read(&dir.join("a/spinup.csv")), read(&dir.join("c/spinup.csv")));
    for f in ["snapshots/1.csv", "snapshots/2.csv"] {
        assert_eq!(read(&dir.join("a").join(f)), read(&dir.join("c").join(f)), "{f}");
    }
}

/// The forcing's work and angular momentum are booked, so a spin-up run's residuals measure the integration
/// error: with direct gravity the angular momentum balances to round-off, and the energy to the leapfrog's error,
/// while the forcing raises the kinetic energy by 78 % (8 h → 6 h: (8/6)² − 1), which the booked work matches.
#[test]
fn spinup_residuals_account_for_the_forcing() {
    let dir = temp_dir("spinup-residuals");
    std::fs::write(dir.join("s.toml"), scene(&dir, PATH)).unwrap();
    let a = rubblepile(&dir, &["run", "s.toml", "--out", "a", "--no-progress"]);
    assert!(a.status.success(), "{}", String::from_utf8_lossy(&a.stderr));
    let v: serde_json::Value = serde_json::from_str(&read(&dir.join("a/summary.json"))).unwrap();
    let (e, l) = (
        v["energy_error"].as_f64().unwrap(),
        v["angular_momentum_error"].as_f64().unwrap(),
    );
    assert!(l < 1e-10, "angular momentum residual {l}");
    assert!(e < 1e-3, "energy residual {e}");
    let ts = read(&dir.join("a/timeseries.csv"));
    let header: Vec<&str> = ts.lines().next().unwrap().split(',').collect();
    let col = header
        .iter()
        .position(|h| *h == "forcing_work")
        .expect("forcing_work column");
    let row = |l: &str| -> Vec<f64> { l.split(',').map(|x| x.parse().unwrap()).collect() };
    let (first, last) = (row(ts.lines().nth(1).unwrap()), row(ts.lines().last().unwrap()));
    let k = header.iter().position(|h| *h == "kinetic_energy").unwrap();
    let gained = last[k] - first[k];
    assert!(gained > 0.5 * first[k], "kinetic energy {} → {} J", first[k], last[k]);
    assert!(
        (last[col] / gained - 1.0).abs() < 0.01,
        "forcing work {} J, kinetic energy gained {gained} J",
        last[col]
    );
}

fn bad(spinup: &str, expect: &str) {
    let dir = temp_dir("spinup-bad");
    std::fs::write(dir.join("s.toml"), scene(&dir, spinup)).unwrap();
    let out = rubblepile(&dir, &["check", "s.toml"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "not one line: {err}");
    assert!(err.contains(expect), "expected {expect:?} in {err}");
}

#[test]
fn bad_spinup_input_names_the_field() {
    bad(
        &PATH.replace("T_final = 6.0", "T_final = 7.5"),
        "spinup.T_final: must be <= T_inter = 7 h, got 7.5",
    );
    bad(
        &PATH.replace("T_start = 8.0", "T_start = -8.0"),
        "spinup.T_start: must be > 0 and finite, got -8",
    );
    bad(
        &PATH.replace("t_final = 2000.0", "t_final = 1000.0"),
        "spinup.t_final: must be >= t_inter = 1200 s, got 1000",
    );
    bad(
        &PATH.replace("rve_particles = 30", "rests = 2\nrest_length = 500.0"),
        "spinup.rest_length: rests x rest_length must be < t_final - t_inter = 800 s",
    );
    bad(
        &format!("{PATH}axis = [0.0, 0.0, 0.0]\n"),
        "spinup.axis: must be a finite non-zero vector",
    );
    bad(&format!("{PATH}period = 3.0\n"), "unknown field `period`");
    bad(
        &format!("{PATH}target = \"spin\"\n"),
        "spinup.target: must be \"period\" or \"angular_momentum\", got \"spin\"",
    );
    bad(&PATH.replace("T_inter = 7.0\n", ""), "missing field `T_inter`");
}

/// `spinup critical --all-holds` runs every hold of the grid whatever the verdicts (the default search may stop
/// once both criteria have a stable hold): three holds, three rows in `critical.csv`, in grid order.
#[test]
fn all_holds_runs_the_whole_grid() {
    let dir = temp_dir("spinup-all-holds");
    let path = PATH.replace("T_final = 6.0", "T_final = 5.0");
    std::fs::write(dir.join("s.toml"), scene(&dir, &path)).unwrap();
    let c = rubblepile(
        &dir,
        &[
            "spinup",
            "critical",
            "--scene",
            "s.toml",
            "--from-h",
            "5.8",
            "--to-h",
            "6.0",
            "--step-h",
            "0.1",
            "--branch",
            "--hold-s",
            "600",
            "--all-holds",
            "--out",
            "crit",
        ],
    );
    assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stderr));
    let csv = read(&dir.join("crit/critical.csv"));
    let periods: Vec<&str> = csv.lines().skip(1).map(|l| l.split(',').next().unwrap()).collect();
    assert_eq!(periods, ["5.80", "5.90", "6.00"], "{csv}");
    // Every branched hold is a whole run directory (`check DIR`). T = 5.8 h starts at an output sample (1680 s),
    // where its own grid puts a snapshot the base run's grid has not: it is written from the checkpoint, the state
    // the branch continues from. The base path reaches 5.8 h there by interpolation, the hold path exactly, so the
    // hold scene run from t = 0 has the same positions but velocities and spins a few ulps apart (the branch is
    // bit-identical only where the paths' periods are, as for T = 6 h below, so the snapshots after it are not
    // compared); the snapshots before it are copied from the base run and bit-identical.
    for p in &periods {
        let c = rubblepile(&dir, &["check", &format!("crit/T{p}")]);
        assert!(c.status.success(), "T{p}: {}", String::from_utf8_lossy(&c.stdout));
    }
    std::fs::copy(dir.join("crit/T5.80/scene.toml"), dir.join("h.toml")).unwrap();
    let h = rubblepile(&dir, &["run", "h.toml", "--out", "h", "--no-progress"]);
    assert!(h.status.success(), "{}", String::from_utf8_lossy(&h.stderr));
    assert_same_snapshots(&dir.join("crit/T5.80"), &dir.join("h"), &["2.csv"], &["3.csv"]);
}

/// Asserts that two run directories hold the same snapshot files, byte for byte but for those named in `close`,
/// whose vectors (position, velocity, spin: the columns after `t,id,mass,radius` in threes) must agree to 1e-12 of
/// the largest such vector component in the file, and other columns exactly; those in `skip` are not compared.
fn assert_same_snapshots(a: &Path, b: &Path, close: &[&str], skip: &[&str]) {
    let (sa, sb) = (snapshots(a), snapshots(b));
    let names = |s: &[(String, Vec<u8>)]| s.iter().map(|x| x.0.clone()).collect::<Vec<_>>();
    assert_eq!(
        names(&sa),
        names(&sb),
        "snapshot files of {} and {}",
        a.display(),
        b.display()
    );
    let numbers = |bytes: &[u8]| -> Vec<Vec<f64>> {
        String::from_utf8_lossy(bytes)
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
            .collect()
    };
    for ((name, x), (_, y)) in sa.iter().zip(&sb) {
        if skip.contains(&name.as_str()) {
            continue;
        }
        if !close.contains(&name.as_str()) {
            assert!(
                x == y,
                "snapshots/{name} of {} differs from {}'s",
                a.display(),
                b.display()
            );
            continue;
        }
        let (nx, ny) = (numbers(x), numbers(y));
        assert_eq!(nx.len(), ny.len(), "snapshots/{name}: rows");
        let group = |c: usize| {
            if c < 4 {
                c..c + 1
            } else {
                4 + (c - 4) / 3 * 3..7 + (c - 4) / 3 * 3
            }
        };
        for c in 0..nx[0].len() {
            let scale = nx
                .iter()
                .flat_map(|r| r[group(c)].iter().map(|v| v.abs()))
                .fold(0.0, f64::max);
            let tol = if c < 4 { 0.0 } else { 1e-12 * scale };
            for (rx, ry) in nx.iter().zip(&ny) {
                assert!(
                    (rx[c] - ry[c]).abs() <= tol,
                    "snapshots/{name}: column {c}: {} vs {}",
                    rx[c],
                    ry[c]
                );
            }
        }
    }
}

/// `spinup critical --branch`: a hold run branched off the shared path run gives the same `spinup.csv` and the
/// same time series (wall-clock column aside) as the hold scene run from t = 0. The path's numbers make the
/// shortened path's periods bit-identical to the full one's (T_final = 6 h at t_X = 1600 s halves the span).
#[test]
fn branched_hold_equals_the_hold_run_from_the_start() {
    let dir = temp_dir("spinup-branch");
    let path = PATH.replace("T_final = 6.0", "T_final = 5.0");
    std::fs::write(dir.join("s.toml"), scene(&dir, &path)).unwrap();
    let c = rubblepile(
        &dir,
        &[
            "spinup", "critical", "--scene", "s.toml", "--from-h", "6", "--to-h", "6", "--branch", "--hold-s", "600",
            "--out", "crit",
        ],
    );
    assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stderr));
    let hold = dir.join("crit/T6.00");
    let scene_text = read(&hold.join("scene.toml"));
    assert!(scene_text.contains("t_final = 1600.0"), "{scene_text}");
    std::fs::write(dir.join("h.toml"), &scene_text).unwrap();
    let h = rubblepile(&dir, &["run", "h.toml", "--out", "h", "--no-progress"]);
    assert!(h.status.success(), "{}", String::from_utf8_lossy(&h.stderr));
    assert_eq!(read(&hold.join("spinup.csv")), read(&dir.join("h/spinup.csv")));
    let without_wall = |p: &Path| -> Vec<String> {
        let text = read(p);
        let wall = text
            .lines()
            .next()
            .unwrap()
            .split(',')
            .position(|h| h == "wall_seconds")
            .unwrap();
        text.lines()
            .map(|l| {
                l.split(',')
                    .enumerate()
                    .filter(|(k, _)| *k != wall)
                    .map(|(_, c)| c)
                    .collect::<Vec<_>>()
                    .join(",")
            })
            .collect()
    };
    let (a, b) = (
        without_wall(&hold.join("timeseries.csv")),
        without_wall(&dir.join("h/timeseries.csv")),
    );
    assert_eq!(a.len(), b.len());
    assert_eq!(a, b);
    assert_same_snapshots(&hold, &dir.join("h"), &[], &[]);
    // The base run reached the hold's start (1560 s) in checkpointed legs of an eighth of its span, each a resume
    // of the last, and still gives the bit-identical hold above: a search stopped on the way loses one leg only.
    let base: serde_json::Value = serde_json::from_str(&read(&dir.join("crit/base/checkpoint.json"))).unwrap();
    assert!(base["checkpoints"].as_u64().unwrap() >= 6, "{base:#}");
    assert_eq!(base["t_seconds"].as_f64(), Some(1560.0));
    let json = read(&dir.join("crit/critical.json"));
    assert!(json.contains("\"t_final_hours\": 6.0"), "{json}");
    // both creep criteria are judged and recorded per hold, the paper's selected by default (Zhang17 §3.3.3)
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["criterion"]["kind"], "paper", "{json}");
    assert_eq!(v["paper"]["criterion"]["kind"], "paper", "{json}");
    assert_eq!(v["ours"]["criterion"]["kind"], "ours", "{json}");
    assert_eq!(v["paper_tolerance"]["criterion"]["kind"], "paper-tolerance", "{json}");
    let run = &v["runs"][0];
    assert!(run["drift"]["coordination"].is_f64(), "{json}");
    assert!(
        run["paper"]["stable"].is_boolean() && run["ours"]["stable"].is_boolean(),
        "{json}"
    );
    assert_eq!(run["stable"], run["paper"]["stable"], "{json}");
    let out = String::from_utf8_lossy(&c.stdout);
    assert!(out.contains("T_final = 6.00 h (600 s judged): paper "), "{out}");
    let csv = read(&dir.join("crit/critical.csv"));
    assert!(
        csv.starts_with("t_final_h,hold_s,released,release_s,theta_max_deg,"),
        "{csv}"
    );
    assert!(csv.lines().nth(1).unwrap().starts_with("6.00,"), "{csv}");
}

/// `--creep-criterion` takes `paper`, `paper-tolerance` or `ours`; anything else is refused with the expected
/// values.
#[test]
fn creep_criterion_option_names_the_expected_values() {
    let dir = temp_dir("spinup-criterion");
    std::fs::write(dir.join("s.toml"), scene(&dir, PATH)).unwrap();
    let c = rubblepile(
        &dir,
        &[
            "spinup",
            "critical",
            "--scene",
            "s.toml",
            "--from-h",
            "6",
            "--to-h",
            "6",
            "--creep-criterion",
            "Paper",
            "--out",
            "crit",
        ],
    );
    assert!(!c.status.success());
    let err = String::from_utf8_lossy(&c.stderr);
    assert!(
        err.contains("expected `paper`, `paper-tolerance` or `ours`, got `Paper`"),
        "{err}"
    );
    assert!(!dir.join("crit").exists(), "nothing is written for a refused option");
}

/// `--branch` refuses a path with rests (a shorter path with rests is not a prefix of the longer one).
#[test]
fn branch_refuses_a_path_with_rests() {
    let dir = temp_dir("spinup-branch-rests");
    let path = PATH.replace(
        "rve_particles = 30",
        "rve_particles = 30\nrests = 1\nrest_length = 100.0",
    );
    std::fs::write(dir.join("s.toml"), scene(&dir, &path)).unwrap();
    let c = rubblepile(
        &dir,
        &[
            "spinup", "critical", "--scene", "s.toml", "--from-h", "6.5", "--to-h", "6.5", "--branch", "--out", "crit",
        ],
    );
    assert!(!c.status.success());
    let err = String::from_utf8_lossy(&c.stderr);
    assert!(err.contains("spinup.rests = 1"), "{err}");
}

/// Files of a search directory that must not depend on how its holds were scheduled: `critical.json` and
/// `critical.csv` (the run directories' paths aside) and every hold's `spinup.csv` and snapshots.
fn search_outputs(dir: &Path) -> Vec<(String, String)> {
    let mut out = vec![
        ("critical.csv".to_string(), read(&dir.join("critical.csv"))),
        (
            "critical.json".to_string(),
            read(&dir.join("critical.json")).replace(&dir.display().to_string(), "DIR"),
        ),
    ];
    let mut holds: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir() && p.file_name().unwrap().to_string_lossy().starts_with('T'))
        .collect();
    holds.sort();
    for h in holds {
        let name = h.file_name().unwrap().to_string_lossy().to_string();
        out.push((format!("{name}/spinup.csv"), read(&h.join("spinup.csv"))));
        for (f, bytes) in snapshots(&h) {
            out.push((
                format!("{name}/snapshots/{f}"),
                String::from_utf8_lossy(&bytes).to_string(),
            ));
        }
    }
    out
}

/// Acceptance (issue 55, item 4): the holds of a search run two at once (`--parallel 2`), or as two shards of a job
/// array judged afterwards, give the same `critical.csv`, `critical.json` and hold runs as one after another.
#[test]
fn parallel_and_sharded_searches_equal_the_sequential_one() {
    let dir = temp_dir("spinup-parallel");
    let path = PATH.replace("T_final = 6.0", "T_final = 5.0");
    std::fs::write(dir.join("s.toml"), scene(&dir, &path)).unwrap();
    // the search's own arguments, then what each call adds
    let args = |out: &'static str, extra: &[&'static str]| -> Vec<&'static str> {
        let mut a = vec![
            "spinup",
            "critical",
            "--scene",
            "s.toml",
            "--from-h",
            "5.7",
            "--to-h",
            "6.0",
            "--step-h",
            "0.1",
            "--branch",
            "--hold-s",
            "600",
            "--all-holds",
            "--out",
            out,
        ];
        a.extend_from_slice(extra);
        a
    };
    let search = |out: &'static str, extra: &[&'static str]| {
        let c = rubblepile(&dir, &args(out, extra));
        assert!(c.status.success(), "{out}: {}", String::from_utf8_lossy(&c.stderr));
        String::from_utf8_lossy(&c.stdout).to_string()
    };
    let seq = search("seq", &[]);
    let par = search("par", &["--parallel", "2", "--threads-per-hold", "1"]);
    assert_eq!(seq.replace("seq/", ""), par.replace("par/", ""));
    // a shard refuses to make the base run; --prepare-only makes it and the branches
    let early = rubblepile(&dir, &args("sh", &["--shard", "0/2"]));
    assert_eq!(early.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&early.stderr).contains("--prepare-only"),
        "{early:?}"
    );
    let prepared = search("sh", &["--prepare-only"]);
    assert!(prepared.contains("4 holds prepared"), "{prepared}");
    for shard in ["0/2", "1/2"] {
        let out = search("sh", &["--shard", shard]);
        assert!(out.contains(&format!("shard {shard} ran 2 of 4 holds")), "{out}");
    }
    assert!(!dir.join("sh/critical.json").exists(), "a shard judges nothing");
    search("sh", &[]);
    // `spinup judge` reads the search again from its holds' runs: the same verdicts as the search printed
    let judged = rubblepile(&dir, &["spinup", "judge", "seq"]);
    assert!(judged.status.success(), "{}", String::from_utf8_lossy(&judged.stderr));
    let judged = String::from_utf8_lossy(&judged.stdout).to_string();
    for line in seq.lines().filter(|l| l.starts_with("T_final")) {
        assert!(judged.contains(line), "{line}\nnot in\n{judged}");
    }
    // … and writes them as the search's own critical.csv (a running search's compact copy), never over a file
    let csv = dir.join("judged_critical.csv");
    let csv_arg = csv.to_string_lossy().to_string();
    let written = rubblepile(&dir, &["spinup", "judge", "seq", "--csv", &csv_arg]);
    assert!(written.status.success(), "{}", String::from_utf8_lossy(&written.stderr));
    assert_eq!(
        std::fs::read_to_string(&csv).unwrap(),
        std::fs::read_to_string(dir.join("seq/critical.csv")).unwrap()
    );
    let again = rubblepile(&dir, &["spinup", "judge", "seq", "--csv", &csv_arg]);
    assert_eq!(again.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&again.stderr).contains("--csv"), "{again:?}");
    let reference = search_outputs(&dir.join("seq"));
    assert_eq!(reference.len(), 2 + 4 * (1 + snapshots(&dir.join("seq/T6.00")).len()));
    for other in ["par", "sh"] {
        let o = search_outputs(&dir.join(other));
        assert_eq!(o.len(), reference.len());
        for ((na, a), (nb, b)) in reference.iter().zip(&o) {
            assert_eq!(na, nb);
            assert!(a == &b.replace(&format!("{other}/"), "seq/"), "{other}: {na} differs");
        }
    }
}

/// A hold whose forcing is released stops at the next release check (2000 simulated seconds) instead of running
/// to its end, and is judged released; `--finish-released` runs it to the end with the same verdict. The release
/// thresholds are set so low that every sample after t_start trips them, and 12 consecutive samples (1440 s) are
/// asked for, so the path reaches the hold's start (1560 s) forced and the release comes inside the hold.
#[test]
fn a_released_hold_stops_early_unless_asked_to_finish() {
    let dir = temp_dir("spinup-release-stop");
    let path = PATH.replace("T_final = 6.0", "T_final = 5.0").replace(
        "rve_particles = 30",
        "rve_particles = 30\nrelease_packing = 1e-12\nrelease_axis_ratio = 1e-12\nrelease_samples = 12",
    );
    std::fs::write(dir.join("s.toml"), scene(&dir, &path)).unwrap();
    let search = |out: &str, extra: &[&str]| {
        let mut args = vec![
            "spinup", "critical", "--scene", "s.toml", "--from-h", "6", "--to-h", "6", "--branch", "--hold-s", "6000",
            "--out", out,
        ];
        args.extend_from_slice(extra);
        let c = rubblepile(&dir, &args);
        assert!(c.status.success(), "{out}: {}", String::from_utf8_lossy(&c.stderr));
    };
    search("early", &[]);
    search("full", &["--finish-released"]);
    let last_t = |d: &str| {
        read_spinup_csv(&dir.join(d).join("T6.00/spinup.csv"))
            .unwrap()
            .last()
            .unwrap()
            .t
    };
    // the hold branches off the base run at 1560 s (its t_final is 1600 s) and releases inside it; the first leg
    // ends at the first sample at least 2000 s on (3600 s), where the hold stops; the full hold ends at 7600 s
    let released = read_spinup_csv(&dir.join("full/T6.00/spinup.csv")).unwrap();
    let release_t = released.iter().find(|r| !r.forcing).unwrap().t;
    assert!(release_t > 1560.0 && release_t < 3560.0, "{release_t}");
    assert!((last_t("early") - 3600.0).abs() < 1.0, "{}", last_t("early"));
    assert!((last_t("full") - 7600.0).abs() < 1.0, "{}", last_t("full"));
    for d in ["early", "full"] {
        let csv = read(&dir.join(d).join("critical.csv"));
        assert!(csv.lines().nth(1).unwrap().starts_with("6.00,"), "{csv}");
        assert_eq!(
            csv.lines().nth(1).unwrap().split(',').nth(2),
            Some("true"),
            "{d}: {csv}"
        );
    }
    // the early rows are the full run's up to the stop, bit for bit
    let (a, b) = (
        read(&dir.join("early/T6.00/spinup.csv")),
        read(&dir.join("full/T6.00/spinup.csv")),
    );
    assert!(b.starts_with(&a), "the stopped hold is a prefix of the finished one");
}

/// `bench critical` times the holds of one prepared search one at a time and two at once, checks that both judge
/// alike, and writes its CSV (one row per setting, with the speed-up and the load) and plot; `--reuse-prepared`
/// keeps the base run; `--single-thread` adds the one-thread baseline.
#[test]
fn bench_critical_times_both_settings_on_one_prepared_base() {
    let dir = temp_dir("bench-critical");
    let path = PATH.replace("T_final = 6.0", "T_final = 5.0");
    std::fs::write(dir.join("s.toml"), scene(&dir, &path)).unwrap();
    // two threads whatever the machine, so that the settings are (1 x 2, [1 x 1,] 2 x 1)
    let bench = |extra: &[&str]| {
        let c = std::process::Command::new(env!("CARGO_BIN_EXE_rubblepile"))
            .args([
                "bench", "critical", "--scene", "s.toml", "--from-h", "5.8", "--to-h", "6.0", "--step-h", "0.1",
                "--hold-s", "600", "--out", "b", "--force",
            ])
            .args(extra)
            .env("RAYON_NUM_THREADS", "2")
            .current_dir(&dir)
            .output()
            .unwrap();
        assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stderr));
        String::from_utf8_lossy(&c.stdout).to_string()
    };
    let out = bench(&[]);
    assert!(out.contains("speed-up of --parallel 2"), "{out}");
    let csv = read(&dir.join("b/bench_critical.csv"));
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(
        rows[0],
        "parallel,threads_per_hold,holds_wall_s,speedup,load_before,load_after"
    );
    assert!(
        rows[1].starts_with("1,") && rows[2].starts_with("2,") && rows.len() == 3,
        "{csv}"
    );
    assert!(dir.join("b/bench_critical.svg").is_file());
    let base_checkpoint = read(&dir.join("b/searches/prepared/base/checkpoint.json"));
    let again = bench(&["--reuse-prepared"]);
    assert!(again.contains("(reused)"), "{again}");
    assert_eq!(
        read(&dir.join("b/searches/prepared/base/checkpoint.json")),
        base_checkpoint
    );
    // --single-thread adds the one-thread, one-at-a-time row between the reference and --parallel 2
    bench(&["--reuse-prepared", "--single-thread"]);
    let csv = read(&dir.join("b/bench_critical.csv"));
    let settings: Vec<String> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').take(2).collect::<Vec<_>>().join(","))
        .collect();
    assert_eq!(settings, ["1,2", "1,1", "2,1"], "{csv}");
    assert!(dir.join("b/searches/parallel1_threads1/critical.csv").is_file());
}

/// `spinup critical --branch` resumed over a base run whose `scene.toml` an older build wrote (the base scene's
/// TOML table edited and printed whole, another layout than the scene value's): the same values are accepted and
/// the missing hold is branched again; other values (another range of T_final) are refused.
#[test]
fn a_resumed_search_accepts_a_base_scene_of_the_old_layout_with_the_same_values() {
    let dir = temp_dir("spinup-old-base");
    let path = PATH.replace("T_final = 6.0", "T_final = 5.0");
    std::fs::write(dir.join("s.toml"), scene(&dir, &path)).unwrap();
    let args = [
        "spinup",
        "critical",
        "--scene",
        "s.toml",
        "--from-h",
        "6",
        "--to-h",
        "6.5",
        "--step-h",
        "0.5",
        "--branch",
        "--hold-s",
        "600",
        "--out",
        "crit",
        "--prepare-only",
    ];
    let c = rubblepile(&dir, &args);
    assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stderr));
    let base = dir.join("crit/base/scene.toml");
    // the base scene as the text path of earlier builds wrote it: the scene file's table with an absolute
    // particles_file, the base run's t_end and output times, printed by `toml::to_string`
    let written: toml::Table = read(&base).parse().unwrap();
    let old_layout = |t_end: &toml::Value| -> String {
        let mut table: toml::Table = read(&dir.join("s.toml")).parse().unwrap();
        let abs = std::path::absolute(dir.join("ball.csv")).unwrap().display().to_string();
        table["scene"]["particles_file"] = toml::Value::String(abs);
        table["scene"]["t_end"] = t_end.clone();
        table["output"]["times"] = written["output"]["times"].clone();
        toml::to_string(&table).unwrap()
    };
    let old = old_layout(&written["scene"]["t_end"]);
    assert_ne!(old, read(&base), "the layouts differ");
    std::fs::write(&base, &old).unwrap();
    // the later hold (T = 6.0 h) is branched again from the base run's checkpoint
    let hold = read(&dir.join("crit/T6.00/scene.toml"));
    std::fs::remove_dir_all(dir.join("crit/T6.00")).unwrap();
    let again = rubblepile(&dir, &args);
    assert!(again.status.success(), "{}", String::from_utf8_lossy(&again.stderr));
    assert_eq!(read(&dir.join("crit/T6.00/scene.toml")), hold);
    // a base run made for another span is refused as before
    let t_end = written["scene"]["t_end"].as_float().unwrap();
    std::fs::write(&base, old_layout(&toml::Value::Float(t_end + 120.0))).unwrap();
    std::fs::remove_dir_all(dir.join("crit/T6.00")).unwrap();
    let refused = rubblepile(&dir, &args);
    assert_eq!(refused.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&refused.stderr).contains("the base run was made for another range of T_final"),
        "{}",
        String::from_utf8_lossy(&refused.stderr)
    );
}

/// Issue 57: `spinup critical --branch` on a scene whose snapshots are given by `[output] snapshot_every` (not
/// `times`) branches its hold (it used to fail on the missing `times` list); the hold scene lists the base
/// run's cadence samples up to the branch point and the hold's own start and end.
#[test]
fn branch_accepts_a_scene_with_snapshot_every() {
    let dir = temp_dir("spinup-branch-every");
    let path = PATH.replace("T_final = 6.0", "T_final = 5.0");
    let text = scene(&dir, &path).replace("times = [0.0, 1200.0, 2400.0]", "snapshot_every = 1200.0");
    std::fs::write(dir.join("s.toml"), text).unwrap();
    let c = rubblepile(
        &dir,
        &[
            "spinup", "critical", "--scene", "s.toml", "--from-h", "6", "--to-h", "6", "--branch", "--hold-s", "600",
            "--out", "crit",
        ],
    );
    assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stderr));
    let hold = dir.join("crit/T6.00");
    let scene_text = read(&hold.join("scene.toml"));
    assert!(!scene_text.contains("snapshot_every"), "{scene_text}");
    assert!(scene_text.contains("t_final = 1600.0"), "{scene_text}");
    assert!(hold.join("summary.json").is_file());
    assert!(dir.join("crit/critical.json").is_file());
}
