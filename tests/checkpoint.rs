//! Checkpoints and resume: a run stopped right after a checkpoint and resumed ends bit for bit like
//! an uninterrupted one (snapshots, time series without `wall_seconds`, summary counters and
//! errors); checkpoints are written atomically; bad or missing checkpoints and completed runs give
//! one-line errors; integrator states restore exactly.

mod common;
use common::{rubblepile, snapshots, temp_dir};
use std::path::{Path, PathBuf};
use std::process::Output;

use rubblepile::integrate::bulirsch_stoer::BulirschStoer;
use rubblepile::integrate::ode_solvers_adapter::OdeSolversAdapter;
use rubblepile::integrate::problems::{Arenstorf, TestProblem};
use rubblepile::integrate::{Integrator, IntegratorState, Method, Tolerances, make_integrator};
use rubblepile::io::checkpoint::{CHECKPOINT_FILE, CHECKPOINT_TMP_FILE};

/// Four ellipsoids with gravity, contact and dissipation: bodies 0 and 2 collide from t ≈ 12 s (the
/// contact energy peaks near t = 21 s), the others drift past. `{METHOD}` and `{BODIES}` are filled in.
const SCENE: &str = r#"[scene]
kind = "ellipsoids"
t_end = 24.0
seed = 1
{BODIES_FILE}
[model]
kappa = 10.0

[physics]
gravity = {}
contact = {}
dissipation = { F0 = 0.01 }

[integrator]
method = "{METHOD}"
rtol = 1e-10
atol = 1e-10

[output]
times = [0.0, 8.0, 16.0, 24.0]
every = 1.0
track = [3, 1]
{BODIES}"#;

const BODY_TABLES: &str = r#"
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
velocity = [-0.15, 0.0, 0.0]
quaternion = [0.0, 0.0, 0.6, 0.8]
spin_body = [0.0, -0.03, 0.01]

[[body]]
axes = [1.5, 1.2, 1.0]
mass = 8000.0
position = [-1.0, 5.0, 0.5]
velocity = [0.02, -0.2, 0.0]
spin_body = [0.01, 0.0, -0.02]

[[body]]
axes = [1.2, 1.0, 0.8]
mass = 5000.0
position = [1.0, -5.0, -0.3]
velocity = [0.0, 0.15, 0.02]
"#;

/// The same bodies as [`BODY_TABLES`], as a bodies file.
const BODIES_CSV: &str = "mass,a,b,c,x,y,z,vx,vy,vz,qa,qb,qc,qd,wx,wy,wz
30000,3,2,1.5,0,0,0,0.05,0,0,0,0,0,1,0.01,0.02,0.05
12000,2,1.5,1,5.5,0.5,0,-0.15,0,0,0,0,0.6,0.8,0,-0.03,0.01
8000,1.5,1.2,1,-1,5,0.5,0.02,-0.2,0,0,0,0,1,0.01,0,-0.02
5000,1.2,1,0.8,1,-5,-0.3,0,0.15,0.02,0,0,0,1,0,0,0
";

fn scene(method: &str, bodies_file: bool) -> String {
    let s = SCENE.replace("{METHOD}", method);
    if bodies_file {
        s.replace("{BODIES_FILE}", "bodies_file = \"bodies.csv\"\n")
            .replace("{BODIES}", "")
    } else {
        s.replace("{BODIES_FILE}", "").replace("{BODIES}", BODY_TABLES)
    }
}

fn describe(out: &Output) -> String {
    format!(
        "exit {:?}\nstdout: {}\nstderr: {}",
        out.status.code(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

fn assert_ok(out: &Output, what: &str) {
    assert!(out.status.success(), "{what}: {}", describe(out));
}

/// Asserts exit `code` with a single `error: …` line on stderr containing `needle`, and no panic.
fn assert_one_line_error(out: &Output, code: i32, needle: &str, what: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{what}: {}", describe(out));
    assert!(!stderr.contains("panicked"), "{what}: {stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{what}: not one line: {stderr}");
    assert!(lines[0].starts_with("error: "), "{what}: {stderr}");
    assert!(lines[0].contains(needle), "{what}: expected {needle:?} in {stderr}");
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The time series without its last (wall_seconds) column.
fn timeseries_without_wall(dir: &Path) -> Vec<String> {
    read(&dir.join("timeseries.csv"))
        .lines()
        .map(|l| l.rsplit_once(',').unwrap().0.to_string())
        .collect()
}

/// summary.json without its wall_seconds.
fn summary_without_wall(dir: &Path) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_str(&read(&dir.join("summary.json"))).unwrap();
    let obj = v.as_object_mut().unwrap();
    assert!(obj.remove("wall_seconds").is_some());
    v
}

/// Asserts that `b` ended exactly like `a`.
fn assert_same_run(a: &Path, b: &Path, what: &str) {
    let (sa, sb) = (snapshots(a), snapshots(b));
    assert_eq!(sa.len(), 4, "{what}: snapshots of the uninterrupted run");
    assert_eq!(
        sa.iter().map(|s| &s.0).collect::<Vec<_>>(),
        sb.iter().map(|s| &s.0).collect::<Vec<_>>(),
        "{what}: snapshot names"
    );
    for ((name, x), (_, y)) in sa.iter().zip(&sb) {
        assert!(x == y, "{what}: snapshots/{name} differs");
    }
    assert_eq!(
        timeseries_without_wall(a),
        timeseries_without_wall(b),
        "{what}: timeseries.csv"
    );
    // tracks.csv: header + 2 tracked bodies × 25 samples, truncated and continued exactly on resume.
    let (ta, tb) = (read(&a.join("tracks.csv")), read(&b.join("tracks.csv")));
    assert_eq!(ta.lines().count(), 1 + 2 * 25, "{what}: tracks.csv rows");
    assert!(
        ta.lines().nth(1).unwrap().split(',').nth(1) == Some("3"),
        "{what}: first tracked id"
    );
    assert_eq!(ta, tb, "{what}: tracks.csv");
    let (ja, jb) = (summary_without_wall(a), summary_without_wall(b));
    for key in [
        "status",
        "steps_accepted",
        "steps_rejected",
        "rhs_evaluations",
        "smallest_step",
        "energy_error",
        "linear_momentum_error",
        "angular_momentum_error",
        "quaternion_norm_error",
        "samples",
    ] {
        assert_eq!(ja[key], jb[key], "{what}: summary.json {key}");
    }
    assert_eq!(ja, jb, "{what}: summary.json (wall_seconds aside)");
    assert!(
        !b.join(CHECKPOINT_TMP_FILE).exists(),
        "{what}: temporary checkpoint left behind"
    );
}

/// Contact energy over translational kinetic energy at time `t` in a run's time series.
fn contact_fraction(dir: &Path, t: f64) -> f64 {
    let text = read(&dir.join("timeseries.csv"));
    for line in text.lines().skip(1) {
        let f: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        if f[0] == t {
            return f[3] / f[1];
        }
    }
    panic!("no row at t = {t}");
}

/// Uninterrupted run into `a`; the same run into `b` stopped after checkpoint `stops[0]`, resumed
/// and stopped after `stops[1..]` more checkpoints, …, then resumed to the end (from `resume_cwd`).
fn kill_and_resume(method: &str, bodies_file: bool, stops: &[u64], resume_cwd: &Path) -> (PathBuf, PathBuf) {
    let dir = temp_dir(method);
    std::fs::write(dir.join("scene.toml"), scene(method, bodies_file)).unwrap();
    if bodies_file {
        std::fs::write(dir.join("bodies.csv"), BODIES_CSV).unwrap();
    }
    let (a, b) = (dir.join("a"), dir.join("b"));
    let (a_s, b_s) = (a.to_str().unwrap(), b.to_str().unwrap());
    assert_ok(
        &rubblepile(&dir, &["run", "scene.toml", "--out", a_s, "--no-progress"]),
        "uninterrupted run",
    );
    assert!(
        !a.join(CHECKPOINT_FILE).exists(),
        "a short run wrote a wall-clock checkpoint"
    );

    let stop = stops[0].to_string();
    let out = rubblepile(
        &dir,
        &[
            "run",
            "scene.toml",
            "--out",
            b_s,
            "--no-progress",
            "--checkpoint-every-sim-s",
            "0",
            "--stop-after-checkpoints",
            &stop,
        ],
    );
    assert_one_line_error(&out, 3, "stopped after checkpoint", "stopped run");
    assert!(b.join(CHECKPOINT_FILE).is_file());
    assert!(!b.join(CHECKPOINT_TMP_FILE).exists());
    assert!(!b.join("summary.json").exists());
    // One checkpoint per sample, the first at t = 0: the k-th is at t = k − 1.
    let t_stop = (stops[0] - 1) as f64;
    assert!(
        contact_fraction(&a, t_stop) > 1e-3,
        "the collision has not started before the checkpoint at t = {t_stop}"
    );
    // As if the process had died after writing more rows (the last one half written) and a
    // snapshot after the checkpoint.
    let extra: Vec<String> = read(&a.join("timeseries.csv"))
        .lines()
        .skip(stops[0] as usize + 1)
        .take(3)
        .map(String::from)
        .collect();
    let mut ts = std::fs::OpenOptions::new()
        .append(true)
        .open(b.join("timeseries.csv"))
        .unwrap();
    std::io::Write::write_all(
        &mut ts,
        format!("{}\n{}", extra[..2].join("\n"), &extra[2][..10]).as_bytes(),
    )
    .unwrap();
    drop(ts);
    std::fs::write(b.join("snapshots").join("3.csv"), "garbage").unwrap();
    std::fs::write(b.join(CHECKPOINT_TMP_FILE), "{ half a checkp").unwrap();

    for &more in &stops[1..] {
        let more = more.to_string();
        let out = rubblepile(
            resume_cwd,
            &[
                "resume",
                b_s,
                "--no-progress",
                "--checkpoint-every-sim-s",
                "0",
                "--stop-after-checkpoints",
                &more,
            ],
        );
        assert_one_line_error(&out, 3, "stopped after checkpoint", "stopped resume");
    }
    let out = rubblepile(resume_cwd, &["resume", b_s, "--no-progress"]);
    assert_ok(&out, "final resume");
    assert!(
        String::from_utf8_lossy(&out.stdout).starts_with("done: t = 24 s"),
        "{}",
        describe(&out)
    );
    (a, b)
}

#[test]
fn bulirsch_stoer_run_killed_and_resumed_twice_is_bit_identical() {
    let cwd = temp_dir("cwd");
    // Stopped at t = 14 s (collision under way), then at t = 19 s, then resumed to the end.
    let (a, b) = kill_and_resume("bulirsch-stoer", false, &[15, 5], &cwd);
    assert_same_run(&a, &b, "bulirsch-stoer");
}

#[test]
fn implicit_bulirsch_stoer_run_killed_and_resumed_is_bit_identical() {
    // The linearly implicit method restores its step, column count and compensation; its Jacobian is rebuilt from
    // the state at every step, so nothing else carries over.
    let cwd = temp_dir("cwd");
    let (a, b) = kill_and_resume("bulirsch-stoer-implicit", false, &[15, 5], &cwd);
    assert_same_run(&a, &b, "bulirsch-stoer-implicit");
}

#[test]
fn dop853_run_killed_and_resumed_is_bit_identical() {
    // Every `advance` of Dop853 evaluates the derivative at its start afresh, so restoring the proposed step and
    // the counters is exact. The scene reads its bodies from a relative bodies_file, and the resume runs from
    // another directory.
    let cwd = temp_dir("cwd");
    let (a, b) = kill_and_resume("dop853", true, &[17], &cwd);
    assert_same_run(&a, &b, "dop853");
}

#[test]
fn checkpoint_of_the_crates_dop853_is_refused_with_one_line() {
    // A checkpoint written when "dop853" ran the ode_solvers crate (the same checkpoint version: only a new
    // integrator state was added) holds an `ode-solvers` state; resuming it under our Dop853 would continue with
    // another method's step history, so it is refused, naming why.
    let dir = temp_dir("old-dop853");
    std::fs::write(dir.join("scene.toml"), scene("dop853", false)).unwrap();
    let out = rubblepile(
        &dir,
        &[
            "run",
            "scene.toml",
            "--out",
            "x",
            "--no-progress",
            "--checkpoint-every-sim-s",
            "5",
            "--stop-after-checkpoints",
            "2",
        ],
    );
    assert_one_line_error(&out, 3, "at t = 10 s", "stopped run");
    let path = dir.join("x").join(CHECKPOINT_FILE);
    let mut checkpoint: serde_json::Value = serde_json::from_str(&read(&path)).unwrap();
    let integrator = &mut checkpoint["engine"]["integrator"];
    assert_eq!(integrator["kind"], "dop853", "{integrator}");
    let dim = integrator["dim"].as_u64().unwrap() as usize;
    let old = OdeSolversAdapter::new(Method::Dop853, Tolerances::uniform(1e-10, 1e-10, dim), None).unwrap();
    *integrator = serde_json::to_value(old.save_state()).unwrap();
    assert_eq!(integrator["kind"], "ode-solvers");
    std::fs::write(&path, serde_json::to_string_pretty(&checkpoint).unwrap()).unwrap();
    // The manifest (issue 53) would name the edited checkpoint as damaged: a run of that time had none.
    std::fs::remove_file(dir.join("x").join("manifest.txt")).unwrap();
    let out = rubblepile(&dir, &["resume", "x", "--no-progress"]);
    assert_one_line_error(&out, 2, "`ode_solvers` crate's Dop853", "old Dop853 checkpoint");
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("re-run"),
        "{}",
        describe(&out)
    );
}

#[test]
fn completed_and_missing_and_corrupt_checkpoints_give_one_line_errors() {
    let dir = temp_dir("errors");
    std::fs::write(dir.join("scene.toml"), scene("bulirsch-stoer", false)).unwrap();

    // A completed run with checkpoints at every sample: no temporary file left, resume refused.
    let out = rubblepile(
        &dir,
        &[
            "run",
            "scene.toml",
            "--out",
            "done",
            "--no-progress",
            "--checkpoint-every-sim-s",
            "0",
        ],
    );
    assert_ok(&out, "run with checkpoints");
    assert!(dir.join("done").join(CHECKPOINT_FILE).is_file());
    assert!(!dir.join("done").join(CHECKPOINT_TMP_FILE).exists());
    let summary = read(&dir.join("done/summary.json"));
    let out = rubblepile(&dir, &["resume", "done"]);
    assert_one_line_error(&out, 2, "already completed", "resume of a completed run");
    assert_eq!(
        read(&dir.join("done/summary.json")),
        summary,
        "refused resume changed the summary"
    );

    // No checkpoint (a short run without checkpoints), or no directory at all.
    assert_ok(
        &rubblepile(&dir, &["run", "scene.toml", "--out", "plain", "--no-progress"]),
        "plain run",
    );
    std::fs::remove_file(dir.join("plain/summary.json")).unwrap();
    let out = rubblepile(&dir, &["resume", "plain"]);
    assert_one_line_error(&out, 2, "nothing to resume", "resume without checkpoint");
    let out = rubblepile(&dir, &["resume", "no-such-dir"]);
    assert_one_line_error(&out, 2, "nothing to resume", "resume of a missing directory");

    // A stopped run whose checkpoint is then truncated, or not even text.
    let out = rubblepile(
        &dir,
        &[
            "run",
            "scene.toml",
            "--out",
            "cut",
            "--no-progress",
            "--checkpoint-every-sim-s",
            "5",
            "--stop-after-checkpoints",
            "2",
        ],
    );
    assert_one_line_error(&out, 3, "at t = 10 s", "stopped run");
    let ckpt = dir.join("cut").join(CHECKPOINT_FILE);
    let good = std::fs::read(&ckpt).unwrap();
    std::fs::write(&ckpt, &good[..good.len() / 2]).unwrap();
    let out = rubblepile(&dir, &["resume", "cut"]);
    assert_one_line_error(&out, 2, "corrupt", "truncated checkpoint");
    std::fs::write(&ckpt, [0xff, 0xfe, 0x00, 0x7b]).unwrap();
    let out = rubblepile(&dir, &["resume", "cut"]);
    assert_one_line_error(&out, 2, "corrupt", "binary checkpoint");
    let text = String::from_utf8(good.clone()).unwrap();
    std::fs::write(&ckpt, text.replacen("\"t\": \"", "\"t\": \"x", 1)).unwrap();
    let out = rubblepile(&dir, &["resume", "cut"]);
    assert_one_line_error(&out, 2, "16 hex digits", "bad float in checkpoint");

    // An edited scene copy is refused; the intact checkpoint then resumes fine.
    std::fs::write(&ckpt, &good).unwrap();
    let scene_copy = dir.join("cut/scene.toml");
    let original = read(&scene_copy);
    std::fs::write(&scene_copy, original.replace("F0 = 0.01", "F0 = 0.02")).unwrap();
    let out = rubblepile(&dir, &["resume", "cut"]);
    assert_one_line_error(&out, 2, "changed since the checkpoint", "edited scene copy");
    std::fs::write(&scene_copy, original).unwrap();
    assert_ok(&rubblepile(&dir, &["resume", "cut", "--no-progress"]), "resume");
    let out = rubblepile(&dir, &["resume", "cut"]);
    assert_one_line_error(&out, 2, "already completed", "second resume");
}

#[test]
fn moved_bodies_file_is_detected_on_resume() {
    let dir = temp_dir("bodies");
    std::fs::write(dir.join("scene.toml"), scene("bulirsch-stoer", true)).unwrap();
    std::fs::write(dir.join("bodies.csv"), BODIES_CSV).unwrap();
    let out = rubblepile(
        &dir,
        &[
            "run",
            "scene.toml",
            "--out",
            "out",
            "--no-progress",
            "--checkpoint-every-sim-s",
            "0",
            "--stop-after-checkpoints",
            "3",
        ],
    );
    assert_one_line_error(&out, 3, "stopped", "stopped run");
    // A different bodies file under the same name: refused, not silently used.
    std::fs::write(dir.join("bodies.csv"), BODIES_CSV.replace("30000,", "30001,")).unwrap();
    let out = rubblepile(&dir, &["resume", "out"]);
    assert_one_line_error(&out, 2, "differ from those the run started with", "changed bodies file");
    // Gone: the scene error names the file.
    std::fs::remove_file(dir.join("bodies.csv")).unwrap();
    let out = rubblepile(&dir, &["resume", "out"]);
    assert_one_line_error(&out, 2, "bodies.csv", "missing bodies file");
}

#[test]
fn bad_checkpoint_flags_are_refused() {
    let dir = temp_dir("flags");
    std::fs::write(dir.join("scene.toml"), scene("bulirsch-stoer", false)).unwrap();
    for (flag, value) in [
        ("--checkpoint-every-s", "-1"),
        ("--checkpoint-every-sim-s", "nan"),
        ("--stop-after-checkpoints", "0"),
    ] {
        let out = rubblepile(&dir, &["run", "scene.toml", "--out", "x", flag, value]);
        assert_eq!(out.status.code(), Some(2), "{flag} {value}: {}", describe(&out));
        assert!(!dir.join("x").exists(), "{flag} {value}: output written");
    }
}

// ---------------------------------------------------------------------------------------------
// Integrator level

/// Advances through `outputs` from `(t, y)`.
fn advance_all(integ: &mut dyn Integrator, t: &mut f64, y: &mut [f64], outputs: &[f64]) {
    for &t_out in outputs {
        integ.advance(&Arenstorf, t, y, t_out).unwrap();
        assert_eq!(*t, t_out);
    }
}

/// Uninterrupted vs. saved after `first`, round-tripped through JSON, restored into a fresh
/// integrator from `make`, continued through `second`: identical state bits and statistics.
fn assert_restore_is_exact(mut make: impl FnMut() -> Box<dyn Integrator>, what: &str) {
    let p = Arenstorf;
    let t_end = p.t_end();
    let outputs: Vec<f64> = (1..=40).map(|i| t_end * i as f64 / 40.0).collect();
    let (first, second) = outputs.split_at(13);

    let mut whole = make();
    let (mut t, mut y) = (p.t0(), p.initial_state());
    advance_all(whole.as_mut(), &mut t, &mut y, &outputs);

    let mut part = make();
    let (mut t2, mut y2) = (p.t0(), p.initial_state());
    advance_all(part.as_mut(), &mut t2, &mut y2, first);
    let json = serde_json::to_string(&part.save_state()).unwrap();
    let state: IntegratorState = serde_json::from_str(&json).unwrap();
    assert_eq!(state, part.save_state(), "{what}: JSON round trip");
    drop(part);
    let mut resumed = make();
    resumed.restore_state(&state).unwrap();
    assert_eq!(resumed.save_state(), state, "{what}: restored state");
    advance_all(resumed.as_mut(), &mut t2, &mut y2, second);

    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&y2), bits(&y), "{what}: final state");
    assert_eq!(resumed.stats(), whole.stats(), "{what}: statistics");
    assert_eq!(
        resumed.save_state(),
        whole.save_state(),
        "{what}: final integrator state"
    );
    assert!(whole.stats().steps_rejected > 0, "{what}: no rejection exercised");
}

#[test]
fn bulirsch_stoer_state_restores_exactly() {
    let tol = || Tolerances::uniform(1e-10, 1e-10, 4);
    assert_restore_is_exact(|| Box::new(BulirschStoer::new(tol(), None).unwrap()), "bulirsch-stoer");
    // Non-default settings travel with the state.
    assert_restore_is_exact(
        || {
            let mut bs = BulirschStoer::new(tol(), Some(1e-3)).unwrap();
            bs.set_max_columns(6).unwrap();
            bs.set_h_max(0.05);
            Box::new(bs)
        },
        "bulirsch-stoer, km 6, h_max",
    );
    let mut other = BulirschStoer::new(tol(), None).unwrap();
    let dop = OdeSolversAdapter::new(Method::Dop853, tol(), None).unwrap();
    assert!(other.restore_state(&dop.save_state()).is_err());
    let wrong_dim = BulirschStoer::new(Tolerances::uniform(1e-10, 1e-10, 3), None).unwrap();
    assert!(other.restore_state(&wrong_dim.save_state()).is_err());
}

#[test]
fn dop853_and_dopri5_states_restore_exactly() {
    // Dop853 is ours (`integrate::dop853`), Dopri5 the ode_solvers crate's.
    for method in [Method::Dop853, Method::Dopri5] {
        assert_restore_is_exact(
            || make_integrator(method, Tolerances::uniform(1e-9, 1e-9, 4), None).unwrap(),
            &method.to_string(),
        );
    }
    let tol = || Tolerances::uniform(1e-9, 1e-9, 4);
    let mut dopri = OdeSolversAdapter::new(Method::Dopri5, tol(), None).unwrap();
    let dop = OdeSolversAdapter::new(Method::Dop853, tol(), None).unwrap();
    assert!(
        dopri.restore_state(&dop.save_state()).is_err(),
        "another method's state"
    );
    let looser = OdeSolversAdapter::new(Method::Dopri5, Tolerances::uniform(1e-8, 1e-9, 4), None).unwrap();
    assert!(dopri.restore_state(&looser.save_state()).is_err(), "other tolerances");
}

/// A state that fails a check of `restore_state` leaves the integrator as it was (every check comes before any
/// field is set): for each method, a state saved earlier in the run with one field spoiled (a non-finite
/// compensation, a bad span, a column count out of range, a negative step) is refused, and the integrator keeps
/// its later state.
#[test]
fn refused_states_leave_the_integrator_as_it_was() {
    let tol = || Tolerances::uniform(1e-10, 1e-10, 4);
    let methods = [Method::BulirschStoer, Method::BulirschStoerImplicit, Method::Dop853];
    for method in methods {
        let mut integ = make_integrator(method, tol(), None).unwrap();
        integ.set_span(Arenstorf.t_end());
        let (mut t, mut y) = (Arenstorf.t0(), Arenstorf.initial_state());
        advance_all(integ.as_mut(), &mut t, &mut y, &[0.5]);
        let earlier = integ.save_state();
        advance_all(integ.as_mut(), &mut t, &mut y, &[1.0]);
        let before = integ.save_state();
        assert_ne!(earlier, before, "{method}");
        let mut spoiled: Vec<IntegratorState> = Vec::new();
        match &earlier {
            IntegratorState::BulirschStoer(s) => {
                let mut bad = s.clone();
                bad.compensation = vec![f64::NAN; 4];
                spoiled.push(IntegratorState::BulirschStoer(bad));
                let mut bad = s.clone();
                bad.columns.span = Some(-1.0);
                spoiled.push(IntegratorState::BulirschStoer(bad));
            }
            IntegratorState::LinearlyImplicit(s) => {
                let mut bad = s.clone();
                bad.compensation = vec![1.0; 3];
                spoiled.push(IntegratorState::LinearlyImplicit(bad));
                let mut bad = s.clone();
                bad.columns.k = bad.km;
                spoiled.push(IntegratorState::LinearlyImplicit(bad));
            }
            IntegratorState::Dop853(s) => {
                let mut bad = s.clone();
                bad.h = -1.0;
                spoiled.push(IntegratorState::Dop853(bad));
            }
            other => panic!("{method}: unexpected state {other:?}"),
        }
        for bad in &spoiled {
            assert!(integ.restore_state(bad).is_err(), "{method}: {bad:?} accepted");
            assert_eq!(integ.save_state(), before, "{method}: changed by a refused state");
        }
    }
}
