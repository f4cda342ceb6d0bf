//! Budgets, not crawls (issue 53): a scene whose own work estimate exceeds its step budget is refused unless the
//! budget is raised (`[run] max_steps`, `--max-steps`); a run that reaches its step or wall-clock budget stops at an
//! output sample with a checkpoint and the reason named (exit code 3), and `resume` with a larger budget ends it
//! exactly as an uninterrupted run; the wall-clock budget holds inside a long sample interval too (an implicit
//! integrator crawling through a fast spin). Each run is written below the test's temporary directory.

mod common;
use common::{describe, rubblepile, temp_dir};
use std::path::{Path, PathBuf};
use std::process::Output;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The bad-input corpus' base scene of `engine` with `replace` applied, as `dir/<name>.toml`.
fn scene(dir: &Path, engine: &str, name: &str, replace: &[(&str, &str)]) -> PathBuf {
    let mut text = std::fs::read_to_string(root().join("tests/bad_input").join(format!("{engine}.toml"))).unwrap();
    for (old, new) in replace {
        assert!(text.contains(old), "{old:?}");
        text = text.replacen(old, new, 1);
    }
    let p = dir.join(format!("{name}.toml"));
    std::fs::write(&p, text).unwrap();
    p
}

/// The one `error: …` line of `o`, after asserting the exit code.
fn error_line(o: &Output, code: i32) -> String {
    assert_eq!(o.status.code(), Some(code), "{}", describe(o));
    let stderr = String::from_utf8_lossy(&o.stderr);
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error: ")).collect();
    assert_eq!(errors.len(), 1, "{stderr}");
    errors[0].to_string()
}

/// The files of a finished run that must match an uninterrupted one: the snapshots and the time series without
/// its columns that measure the machine (wall-clock seconds, events per second).
fn physics(dir: &Path) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let ts = std::fs::read_to_string(dir.join("timeseries.csv")).unwrap();
    let cols: Vec<&str> = ts.lines().next().unwrap().split(',').collect();
    let keep = |l: &str| -> String {
        l.split(',')
            .zip(&cols)
            .filter(|(_, c)| **c != "wall_seconds" && **c != "events_per_second")
            .map(|(v, _)| v)
            .collect::<Vec<_>>()
            .join(",")
    };
    out.push((
        "timeseries.csv".into(),
        ts.lines().map(keep).collect::<Vec<_>>().join("\n"),
    ));
    let mut snaps: Vec<_> = std::fs::read_dir(dir.join("snapshots"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    snaps.sort();
    for p in snaps {
        out.push((
            p.file_name().unwrap().to_string_lossy().into(),
            std::fs::read_to_string(&p).unwrap(),
        ));
    }
    out
}

/// Asserts the runs in `a` and `b` hold the same physics ([`physics`]), naming the first line that differs.
fn same_physics(a: &Path, b: &Path) {
    let (pa, pb) = (physics(a), physics(b));
    assert_eq!(
        pa.len(),
        pb.len(),
        "{} and {} hold other files",
        a.display(),
        b.display()
    );
    for ((name, x), (_, y)) in pa.iter().zip(&pb) {
        if let Some((i, (l, r))) = x.lines().zip(y.lines()).enumerate().find(|(_, (l, r))| l != r) {
            panic!("{name} line {}: {l}\n  vs {r}", i + 1);
        }
        assert_eq!(x.lines().count(), y.lines().count(), "{name}");
    }
}

#[test]
fn a_scene_estimated_over_its_budget_is_refused_until_the_budget_is_raised() {
    let dir = temp_dir("budget-estimate");
    // 2000 fixed steps (t_end / dt).
    let hard = scene(&dir, "hard", "hard", &[]);
    let capped = scene(
        &dir,
        "hard",
        "capped",
        &[("[stepping]", "[run]\nmax_steps = 1000\n\n[stepping]")],
    );
    let e = error_line(
        &rubblepile(&dir, &["run", s(&capped), "--out", "a", "--no-progress"]),
        2,
    );
    assert!(
        e.contains("the scene needs about 2.0e3 steps to t_end = 2 s, more than max_steps = 1000 ([run] max_steps)"),
        "{e}"
    );
    assert!(!dir.join("a").exists(), "refused before the output directory is made");
    let e = error_line(
        &rubblepile(
            &dir,
            &["run", s(&hard), "--out", "a", "--no-progress", "--max-steps", "1999"],
        ),
        2,
    );
    assert!(e.contains("more than max_steps = 1999 (--max-steps)"), "{e}");
    // The command line raises the scene's budget.
    let o = rubblepile(
        &dir,
        &["run", s(&capped), "--out", "b", "--no-progress", "--max-steps", "2000"],
    );
    assert!(o.status.success(), "{}", describe(&o));
    // `check` of the scene says what `run` will do: a warning over the default ceiling, for the needle.
    let needle = scene(
        &dir,
        "ellipsoids",
        "needle",
        &[("axes = [3.0, 2.0, 1.5]", "axes = [3e-9, 2e-9, 1.5e-9]")],
    );
    let o = rubblepile(&dir, &["run", s(&needle), "--out", "c", "--no-progress"]);
    let e = error_line(&o, 2);
    assert!(e.contains("more than max_steps = 1e9 (the default ceiling)"), "{e}");
}

#[test]
fn a_run_that_reaches_its_step_budget_stops_with_a_checkpoint_and_resumes_exactly() {
    let dir = temp_dir("budget-steps");
    let sc = scene(&dir, "ellipsoids", "e", &[]);
    let o = rubblepile(&dir, &["run", s(&sc), "--out", "whole", "--no-progress"]);
    assert!(o.status.success(), "{}", describe(&o));
    let o = rubblepile(
        &dir,
        &["run", s(&sc), "--out", "cut", "--no-progress", "--max-steps", "60"],
    );
    let e = error_line(&o, 3);
    assert!(
        e.contains("stopped at t = ")
            && e.contains(": the step budget: 60 steps taken")
            && e.contains("max_steps = 60 (--max-steps); a checkpoint was written: continue with `rubblepile resume"),
        "{e}"
    );
    assert!(dir.join("cut/checkpoint.json").is_file());
    assert!(!dir.join("cut/summary.json").exists());
    let o = rubblepile(&dir, &["check", "cut"]);
    assert!(o.status.success(), "{}", describe(&o));
    // The same budget again: stopped where it is, nothing written.
    let before = std::fs::read(dir.join("cut/checkpoint.json")).unwrap();
    let e = error_line(
        &rubblepile(&dir, &["resume", "cut", "--no-progress", "--max-steps", "60"]),
        3,
    );
    assert!(
        e.contains("max_steps = 60 (--max-steps) reached: 60 steps taken"),
        "{e}"
    );
    assert_eq!(std::fs::read(dir.join("cut/checkpoint.json")).unwrap(), before);
    // A larger budget (here the default): the run ends as the uninterrupted one.
    let o = rubblepile(&dir, &["resume", "cut", "--no-progress"]);
    assert!(o.status.success(), "{}", describe(&o));
    same_physics(&dir.join("cut"), &dir.join("whole"));
}

#[test]
fn the_wall_clock_budget_stops_between_samples_and_inside_a_long_interval() {
    let dir = temp_dir("budget-wall");
    // 2e7 hard-sphere steps in 200 sample intervals: a second or two, stopped by a budget of one second.
    let hard = scene(&dir, "hard", "slow", &[("dt = 1e-3 ", "dt = 1e-7 ")]);
    let clock = std::time::Instant::now();
    let whole = rubblepile(
        &dir,
        &["run", s(&hard), "--out", "whole", "--no-progress", "--max-steps", "3e7"],
    );
    let whole_seconds = clock.elapsed().as_secs_f64();
    assert!(whole.status.success(), "{}", describe(&whole));
    let args = |verb: &str, target: &str| -> Vec<String> {
        let mut a: Vec<String> = match verb {
            "run" => vec!["run".into(), s(&hard).into(), "--out".into(), target.into()],
            _ => vec!["resume".into(), target.into()],
        };
        a.extend(["--no-progress", "--max-steps", "3e7", "--max-wall-s", "1"].map(String::from));
        a
    };
    let run = |a: Vec<String>| {
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        rubblepile(&dir, &a)
    };
    let mut o = run(args("run", "cut"));
    let mut stops = 0;
    while o.status.code() == Some(3) {
        let e = error_line(&o, 3);
        assert!(e.contains(": the wall-clock budget: "), "{e}");
        stops += 1;
        assert!(stops < 30, "no progress: {e}");
        o = run(args("resume", "cut"));
    }
    assert!(o.status.success(), "{}", describe(&o));
    // A run that takes well over the budget must have been stopped (a fast machine may not need to).
    assert!(stops >= 1 || whole_seconds < 2.0, "{whole_seconds} s and never stopped");
    same_physics(&dir.join("cut"), &dir.join("whole"));

    // An implicit integrator crawling through a 1e6 rad/s spin never reaches its first sample (1 s): the budget
    // stops it inside the interval, with a checkpoint at the sample before (t = 0).
    let implicit = scene(
        &dir,
        "ellipsoids",
        "implicit",
        &[
            ("method = \"bulirsch-stoer\"", "method = \"bulirsch-stoer-implicit\""),
            ("spin_body = [0.01, 0.02, 0.05]", "spin_body = [1e6, 0.0, 0.0]"),
        ],
    );
    let started = std::time::Instant::now();
    let o = rubblepile(
        &dir,
        &[
            "run",
            s(&implicit),
            "--out",
            "spin",
            "--no-progress",
            "--max-steps",
            "1e8",
            "--max-wall-s",
            "1",
        ],
    );
    let e = error_line(&o, 3);
    assert!(
        e.contains(
            "stopped at t = 0 s: the wall-clock budget: max_wall_seconds = 1 s ran out within the sample \
                    interval to t = 1 s"
        ),
        "{e}"
    );
    assert!(started.elapsed().as_secs_f64() < 30.0, "the budget did not hold");
    let o = rubblepile(&dir, &["check", "spin"]);
    assert!(o.status.success(), "{}", describe(&o));
}
