//! Incomplete run directories: `resume` refuses, with one line naming what is missing and before it changes
//! anything, a run whose snapshots written before its checkpoint are gone or whose time series is shorter than its
//! checkpoint says; `rubblepile check DIR` says whether a run directory is whole, for every engine, completed, in
//! progress or damaged (exit code 0 when whole, 2 when not).

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

/// Asserts exit code 2 and one `error: …` line on stderr containing every one of `needles`.
fn assert_error(o: &Output, needles: &[&str], what: &str) {
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{what}: {}", describe(o));
    assert!(!stderr.contains("panicked"), "{what}: {stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{what}: not one line: {stderr}");
    assert!(lines[0].starts_with("error: "), "{what}: {stderr}");
    for n in needles {
        assert!(lines[0].contains(n), "{what}: expected {n:?} in {stderr}");
    }
}

/// Every file of `dir` (lock files aside) with its bytes.
fn files(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let e = e.unwrap();
            let p = e.path();
            if rubblepile::io::run_lock::is_lock_file(&e.file_name()) {
                continue;
            }
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push((p.clone(), std::fs::read(&p).unwrap()));
            }
        }
    }
    out.sort();
    out
}

/// The bad-input corpus' base scene of an engine (`ellipsoids`, `soft`, `hard`), copied into `dir` as `scene.toml`.
fn scene(dir: &Path, engine: &str) {
    std::fs::copy(
        root().join("tests/bad_input").join(format!("{engine}.toml")),
        dir.join("scene.toml"),
    )
    .unwrap();
}

/// Runs `scene.toml` of `dir` into `dir/<name>` with `extra` arguments; returns the output directory and the output.
fn run(dir: &Path, name: &str, extra: &[&str]) -> (PathBuf, Output) {
    let out = dir.join(name);
    let o = rubblepile(
        dir,
        &[&["run", "scene.toml", "--out", s(&out), "--no-progress"], extra].concat(),
    );
    (out, o)
}

/// The ellipsoid scene (snapshots at 0, 20, 40, 60 s) stopped at its first checkpoint at or after t = 25 s: two
/// snapshots written before it.
fn stopped_after_two_snapshots(dir: &Path, name: &str) -> PathBuf {
    let (out, o) = run(
        dir,
        name,
        &["--checkpoint-every-sim-s", "25", "--stop-after-checkpoints", "1"],
    );
    assert_eq!(o.status.code(), Some(3), "{}", describe(&o));
    assert!(out.join("snapshots/1.csv").is_file() && !out.join("snapshots/2.csv").exists());
    out
}

/// `resume` of a run whose `snapshots/` was deleted (it used to carry on and lose snapshot 0 for good), whose one
/// snapshot was deleted, or whose time series was cut: refused with one line naming what is missing, and the
/// directory left exactly as it was; `check DIR` names the same.
#[test]
fn resume_refuses_a_run_with_missing_snapshots_or_a_short_time_series() {
    let dir = temp_dir("incomplete-resume");
    scene(&dir, "ellipsoids");

    let out = stopped_after_two_snapshots(&dir, "no-snapshots");
    std::fs::remove_dir_all(out.join("snapshots")).unwrap();
    let before = files(&out);
    let o = rubblepile(&dir, &["resume", s(&out), "--no-progress"]);
    let missing = format!(
        "{}/ is missing (2 snapshots written by the checkpoint at t = 25 s)",
        out.join("snapshots").display()
    );
    assert_error(
        &o,
        &["cannot resume: ", &missing, "re-run the scene from the start"],
        "snapshots/ deleted",
    );
    assert_eq!(files(&out), before, "a refused resume changed the directory");
    assert!(!out.join("snapshots").exists(), "a refused resume recreated snapshots/");
    let o = rubblepile(&dir, &["check", s(&out)]);
    assert_error(&o, &["is not whole", &missing], "check, snapshots/ deleted");

    let out = stopped_after_two_snapshots(&dir, "one-snapshot");
    std::fs::remove_file(out.join("snapshots/1.csv")).unwrap();
    let before = files(&out);
    let o = rubblepile(&dir, &["resume", s(&out), "--no-progress"]);
    let missing = format!(
        "{} is missing (snapshot 1 at t = 20 s, written by the checkpoint at t = 25 s)",
        out.join("snapshots/1.csv").display()
    );
    assert_error(&o, &[&missing], "snapshot 1 deleted");
    assert_eq!(files(&out), before, "a refused resume changed the directory");

    let out = stopped_after_two_snapshots(&dir, "short-timeseries");
    let ts = out.join("timeseries.csv");
    let text = std::fs::read_to_string(&ts).unwrap();
    std::fs::write(&ts, &text[..text.len() / 2]).unwrap();
    let before = files(&out);
    let o = rubblepile(&dir, &["resume", s(&out), "--no-progress"]);
    assert_error(
        &o,
        &[&format!(
            "{}: holds {} bytes, fewer than the {} written before the checkpoint",
            ts.display(),
            text.len() / 2,
            text.len()
        )],
        "time series cut",
    );
    assert_eq!(files(&out), before, "a refused resume changed the directory");
    let o = rubblepile(&dir, &["check", s(&out)]);
    assert_error(
        &o,
        &["is not whole", "written before the checkpoint"],
        "check, time series cut",
    );

    // Undamaged, the same stop resumes and completes.
    let out = stopped_after_two_snapshots(&dir, "whole");
    let o = rubblepile(&dir, &["resume", s(&out), "--no-progress"]);
    assert!(o.status.success(), "{}", describe(&o));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `check DIR` on every engine's runs: completed and in progress (stopped after a checkpoint) are whole (exit 0,
/// one line per finding); a deleted, garbled or mistimed snapshot, a deleted scene copy, a time series shorter than
/// the summary says, and a directory with neither summary nor checkpoint are not (exit 2, naming the problem).
#[test]
fn check_says_whether_a_run_directory_is_whole() {
    let dir = temp_dir("check-dir");
    for engine in ["ellipsoids", "soft", "hard"] {
        let edir = dir.join(engine);
        std::fs::create_dir_all(&edir).unwrap();
        scene(&edir, engine);
        let check = |out: &Path| rubblepile(&edir, &["check", s(out)]);

        let (done, o) = run(&edir, "done", &[]);
        assert!(o.status.success(), "{engine}: {}", describe(&o));
        let o = check(&done);
        let stdout = String::from_utf8_lossy(&o.stdout);
        assert!(o.status.success(), "{engine}, completed: {}", describe(&o));
        assert!(stdout.contains("status: completed"), "{engine}: {stdout}");
        assert!(stdout.contains("present and readable"), "{engine}: {stdout}");
        assert!(
            stdout.trim_end().ends_with(&format!("{} is whole", done.display())),
            "{engine}: {stdout}"
        );
        assert!(!stdout.contains("problem: "), "{engine}: {stdout}");

        let (going, o) = run(
            &edir,
            "going",
            &["--checkpoint-every-sim-s", "0", "--stop-after-checkpoints", "1"],
        );
        assert_eq!(o.status.code(), Some(3), "{engine}: {}", describe(&o));
        let o = check(&going);
        let stdout = String::from_utf8_lossy(&o.stdout);
        assert!(o.status.success(), "{engine}, in progress: {}", describe(&o));
        assert!(
            stdout.contains("status: in progress (or interrupted), checkpoint at t = "),
            "{engine}: {stdout}"
        );

        // Damage, one copy of the completed run each.
        let damaged = |name: &str, damage: &dyn Fn(&Path), needles: &[&str]| {
            let d = edir.join(name);
            std::fs::create_dir_all(d.join("snapshots")).unwrap();
            for (p, bytes) in files(&done) {
                let to = d.join(p.strip_prefix(&done).unwrap());
                std::fs::create_dir_all(to.parent().unwrap()).unwrap();
                std::fs::write(to, bytes).unwrap();
            }
            damage(&d);
            let o = check(&d);
            assert_error(
                &o,
                &[&format!("{} is not whole: ", d.display())],
                &format!("{engine}, {name}"),
            );
            let stdout = String::from_utf8_lossy(&o.stdout);
            for n in needles {
                assert!(stdout.contains(n), "{engine}, {name}: expected {n:?} in {stdout}");
            }
        };
        damaged(
            "deleted",
            &|d| std::fs::remove_file(d.join("snapshots/0.csv")).unwrap(),
            &["snapshots/0.csv is missing"],
        );
        damaged(
            "garbled",
            &|d| std::fs::write(d.join("snapshots/1.csv"), "not,a\nsnapshot").unwrap(),
            &["problem: ", "snapshots/1.csv is unreadable"],
        );
        damaged(
            "mistimed",
            &|d| {
                std::fs::copy(d.join("snapshots/0.csv"), d.join("snapshots/1.csv"))
                    .map(|_| ())
                    .unwrap()
            },
            &["snapshots/1.csv holds t = 0 s; the schedule puts snapshot 1 at t = "],
        );
        damaged(
            "no-scene",
            &|d| std::fs::remove_file(d.join("scene.toml")).unwrap(),
            &["scene.toml is missing"],
        );
        damaged(
            "short",
            &|d| {
                let ts = d.join("timeseries.csv");
                let text = std::fs::read_to_string(&ts).unwrap();
                let keep: Vec<&str> = text.lines().take(3).collect();
                std::fs::write(&ts, keep.join("\n") + "\n").unwrap();
            },
            &["timeseries.csv: 2 rows, but"],
        );
        damaged(
            "no-record",
            &|d| std::fs::remove_file(d.join("summary.json")).unwrap(),
            &["no summary.json and no checkpoint.json"],
        );
    }
    // Not a run directory at all.
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let o = rubblepile(&dir, &["check", s(&empty)]);
    assert_error(&o, &["scene.toml is missing"], "an empty directory");
    assert_eq!(
        std::fs::read_dir(&empty).unwrap().count(),
        0,
        "check wrote into the directory"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
