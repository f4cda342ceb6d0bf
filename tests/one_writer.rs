//! One writer per directory (`src/io/run_lock.rs`): two `resume`s of one run directory at once (one is refused, the
//! other ends bit for bit like an uninterrupted run), every writing command refused at once while another process
//! writes its directory (one line naming the directory and the holder's pid, exit code 2, nothing deleted), a killed
//! holder's lock released by the OS, and readers never blocked.

mod common;
use common::{describe, rubblepile, snapshots, temp_dir};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use rubblepile::io::run_lock::{DirLock, LOCK_FILE};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Held by every test of this file for its whole run: a lock file's descriptor that this process holds is
/// inherited by any child another thread is forking at that moment (until the child's `exec` closes it), so
/// the OS lock can outlive the guard by a moment. With one test at a time, no other thread forks while a test
/// drops a lock and then starts a process that takes it.
static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn one_at_a_time() -> std::sync::MutexGuard<'static, ()> {
    SERIAL.lock().unwrap_or_else(|e| e.into_inner())
}

/// `take()` retried for up to 2 s while the lock is held: right after this test drops a lock, a child process that
/// another test of this binary is just spawning may still share the lock file's descriptor (inherited at `fork`,
/// closed at `exec`), so the OS lock can outlive the guard by a moment. The retry guards against that race of the
/// test harness, not against a real second writer (those are refused and asserted above and below).
fn acquire_soon(take: impl Fn() -> Result<DirLock, rubblepile::io::run_lock::LockError>) -> DirLock {
    let start = Instant::now();
    loop {
        match take() {
            Ok(lock) => return lock,
            Err(e) if start.elapsed() > Duration::from_secs(2) => panic!("lock still held after 2 s: {e}"),
            Err(_) => std::thread::sleep(Duration::from_millis(10)),
        }
    }
}

/// The 30-fragment pile at rest for `t_end` seconds: ~1.5 s of wall time at 6000 s on two cores, long enough for a
/// second process to start while the first one holds the lock.
fn pile_scene(t_end: f64) -> String {
    format!(
        r#"[scene]
kind = "ellipsoids"
t_end = {t_end:?}
seed = 1
bodies_file = "{bodies}"

[model]
kappa = 10.0

[physics]
gravity = {{}}
contact = {{}}
dissipation = {{ F0 = 1e-6 }}

[integrator]
method = "bulirsch-stoer"
rtol = 1e-12
atol = 1e-12

[output]
times = [0.0, 2000.0, 4000.0, 6000.0]
every = 5.0
"#,
        bodies = root().join("targets/N30_T4.csv").display()
    )
}

fn bin(cwd: &Path, args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_rubblepile"));
    c.args(args)
        .current_dir(cwd)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    c
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Asserts that `o` is the refusal of a second writer of `dir`: exit code 2 and one line `error: <dir> is being
/// written by another rubblepile process (pid <pid>); …`; returns the pid named.
fn assert_refused(o: &Output, dir: &Path, what: &str) -> u32 {
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{what}: {}", describe(o));
    assert!(!stderr.contains("panicked"), "{what}: {stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{what}: not one line: {stderr}");
    let prefix = format!(
        "error: {} is being written by another rubblepile process (pid ",
        dir.display()
    );
    let rest = lines[0]
        .strip_prefix(&prefix)
        .unwrap_or_else(|| panic!("{what}: expected {prefix:?}…, got {stderr}"));
    let (pid, tail) = rest.split_once(')').unwrap_or_else(|| panic!("{what}: {stderr}"));
    assert!(tail.starts_with("; wait for it to end"), "{what}: {stderr}");
    pid.parse().unwrap_or_else(|_| panic!("{what}: no pid in {stderr}"))
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Asserts that the run in `b` ended exactly like the uninterrupted run in `a`: snapshots, time series without its
/// wall_seconds column, summary without its wall_seconds.
fn assert_same_run(a: &Path, b: &Path, what: &str) {
    let (sa, sb) = (snapshots(a), snapshots(b));
    assert_eq!(sa.len(), 4, "{what}: snapshots of the uninterrupted run");
    assert!(sa == sb, "{what}: the snapshots differ");
    let no_wall = |d: &Path| -> Vec<String> {
        read(&d.join("timeseries.csv"))
            .lines()
            .map(|l| l.rsplit_once(',').unwrap().0.to_string())
            .collect()
    };
    assert_eq!(no_wall(a), no_wall(b), "{what}: timeseries.csv");
    let summary = |d: &Path| {
        let mut v: serde_json::Value = serde_json::from_str(&read(&d.join("summary.json"))).unwrap();
        assert!(v.as_object_mut().unwrap().remove("wall_seconds").is_some());
        v
    };
    assert_eq!(summary(a), summary(b), "{what}: summary.json (wall_seconds aside)");
}

/// A run of `scene.toml` in `cwd` stopped right after its first checkpoint (exit code 3), in `cwd/<name>`.
fn stopped_run(cwd: &Path, name: &str) -> PathBuf {
    let out = cwd.join(name);
    let o = bin(
        cwd,
        &[
            "run",
            "scene.toml",
            "--out",
            s(&out),
            "--no-progress",
            "--checkpoint-every-sim-s",
            "0",
            "--stop-after-checkpoints",
            "1",
        ],
    )
    .output()
    .unwrap();
    assert_eq!(o.status.code(), Some(3), "stopping {name}: {}", describe(&o));
    out
}

/// The pid in `dir`'s lock file, once it names `pid` (the holder has locked the directory); panics after 60 s.
fn wait_for_holder(dir: &Path, pid: u32) {
    let t0 = Instant::now();
    while std::fs::read_to_string(dir.join(LOCK_FILE))
        .ok()
        .as_deref()
        .map(str::trim)
        != Some(&pid.to_string())
    {
        assert!(
            t0.elapsed() < Duration::from_secs(60),
            "{} never locked {}",
            pid,
            dir.display()
        );
        std::thread::sleep(Duration::from_millis(1));
    }
}

/// The fault of issue 38: two `resume`s of one run directory at once. Exactly one is refused (one line naming the
/// directory and a pid, exit code 2) and the other one's outputs are those of an uninterrupted run, bit for bit.
/// Each round has a true race (both started together) and a race made certain (the second started once the first
/// holds the lock); last, the test itself holds the lock as a first writer would.
#[test]
fn two_concurrent_resumes_one_refused_the_other_matches_an_uninterrupted_run() {
    let _serial = one_at_a_time();
    let dir = temp_dir("two-resumes");
    std::fs::write(dir.join("scene.toml"), pile_scene(6000.0)).unwrap();
    let whole = dir.join("whole");
    let o = bin(&dir, &["run", "scene.toml", "--out", s(&whole), "--no-progress"])
        .output()
        .unwrap();
    assert!(o.status.success(), "uninterrupted run: {}", describe(&o));
    let resume = |d: &Path| bin(&dir, &["resume", s(d), "--no-progress"]);

    for round in 0..2 {
        // Both at once: whichever locks first runs; the other is refused at once.
        let d = stopped_run(&dir, &format!("race{round}"));
        let (a, b) = (resume(&d).spawn().unwrap(), resume(&d).spawn().unwrap());
        let (oa, ob) = (a.wait_with_output().unwrap(), b.wait_with_output().unwrap());
        let (winner, loser) = match (oa.status.success(), ob.status.success()) {
            (true, false) => (oa, ob),
            (false, true) => (ob, oa),
            _ => panic!(
                "round {round}: expected one resume to run and one to be refused:\nfirst: {}\nsecond: {}",
                describe(&oa),
                describe(&ob)
            ),
        };
        assert!(
            String::from_utf8_lossy(&winner.stdout).starts_with("done: t = 6000 s"),
            "{}",
            describe(&winner)
        );
        assert_refused(&loser, &d, &format!("round {round}, race"));
        assert_same_run(&whole, &d, &format!("round {round}, race"));

        // The second started once the first holds the lock: refused naming the first's pid.
        let d = stopped_run(&dir, &format!("second{round}"));
        let first = resume(&d).spawn().unwrap();
        wait_for_holder(&d, first.id());
        let second = resume(&d).output().unwrap();
        let first_pid = first.id();
        let first = first.wait_with_output().unwrap();
        assert!(
            first.status.success(),
            "round {round}: first resume: {}",
            describe(&first)
        );
        assert_eq!(assert_refused(&second, &d, "second resume"), first_pid);
        assert_same_run(&whole, &d, &format!("round {round}, second started late"));
    }

    // The test holds the lock as a first writer would (through the library): the binary is refused naming this
    // process; once the lock is dropped, the resume runs and ends like the uninterrupted run.
    let d = stopped_run(&dir, "held");
    let lock = DirLock::acquire(&d).unwrap();
    let refused = resume(&d).output().unwrap();
    assert_eq!(assert_refused(&refused, &d, "held by the test"), std::process::id());
    drop(lock);
    let o = resume(&d).output().unwrap();
    assert!(o.status.success(), "after the lock was dropped: {}", describe(&o));
    assert_same_run(&whole, &d, "after the test's lock");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `run --force` into a directory another process writes is refused before anything in it is removed.
#[test]
fn run_force_into_a_directory_being_written_is_refused_and_removes_nothing() {
    let _serial = one_at_a_time();
    let dir = temp_dir("force-locked");
    std::fs::copy(root().join("tests/bad_input/ellipsoids.toml"), dir.join("scene.toml")).unwrap();
    let out = dir.join("out");
    let o = rubblepile(&dir, &["run", "scene.toml", "--out", "out", "--no-progress"]);
    assert!(o.status.success(), "{}", describe(&o));
    let before = snapshots(&out);
    let summary = read(&out.join("summary.json"));
    let lock = DirLock::acquire(&out).unwrap();
    for args in [&["--force"][..], &[]] {
        let o = rubblepile(
            &dir,
            &[&["run", "scene.toml", "--out", s(&out), "--no-progress"], args].concat(),
        );
        assert_eq!(assert_refused(&o, &out, "run --force"), std::process::id());
        assert!(String::from_utf8_lossy(&o.stderr).contains("or use another --out"));
    }
    assert_eq!(snapshots(&out), before, "nothing removed");
    assert_eq!(read(&out.join("summary.json")), summary);
    drop(lock);
    let o = rubblepile(
        &dir,
        &["run", "scene.toml", "--out", s(&out), "--force", "--no-progress"],
    );
    assert!(o.status.success(), "once free: {}", describe(&o));
    assert!(out.join(LOCK_FILE).is_file(), "--force keeps the lock file");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `impact` and `flyby` into a directory another process writes: refused, the directory left as it was.
#[test]
fn impact_and_flyby_into_a_directory_being_written_are_refused() {
    let _serial = one_at_a_time();
    let dir = temp_dir("impact-locked");
    let target = root().join("targets/N30_T4.csv");
    for (name, args) in [
        (
            "impact",
            vec![
                "impact",
                "--target",
                s(&target),
                "--t-end-s",
                "10",
                "--force",
                "--no-progress",
            ],
        ),
        (
            "flyby",
            vec!["flyby", "--target", s(&target), "--q-m", "2e7", "--no-run", "--force"],
        ),
    ] {
        let out = dir.join(name);
        std::fs::create_dir_all(&out).unwrap();
        std::fs::write(out.join("keep.txt"), "precious").unwrap();
        let lock = DirLock::acquire(&out).unwrap();
        let o = rubblepile(&dir, &[&args[..], &["--out", s(&out)][..]].concat());
        assert_eq!(assert_refused(&o, &out, name), std::process::id());
        let left: Vec<String> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n != LOCK_FILE)
            .collect();
        assert_eq!(left, ["keep.txt"], "{name}: the directory was written");
        drop(lock);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A campaign whose directory another process writes is refused at once, and so are `campaign merge` and a second
/// process running the same shard; shards share the directory with each other but not with an unsharded campaign;
/// a run directory another process writes is a failed run of the campaign, not a broken campaign.
#[test]
fn campaign_directory_being_written_is_refused() {
    let _serial = one_at_a_time();
    let dir = temp_dir("campaign-locked");
    let text = read(&root().join("tests/bad_input/campaign.toml")).replace("ROOT", s(&root()));
    let file = dir.join("campaign.toml");
    std::fs::write(&file, text).unwrap();
    let camp = dir.join("camp");
    std::fs::create_dir_all(&camp).unwrap();
    let campaign = |extra: &[&str]| rubblepile(&dir, &[&["campaign", s(&file), "--no-progress"], extra].concat());

    let lock = DirLock::acquire(&camp).unwrap();
    assert_eq!(assert_refused(&campaign(&[]), &camp, "campaign"), std::process::id());
    assert_eq!(
        assert_refused(&campaign(&["--shard", "0/2"]), &camp, "shard"),
        std::process::id()
    );
    std::fs::write(camp.join("campaign.source"), format!("{}\n", file.display())).unwrap();
    let merge = rubblepile(&dir, &["campaign", "merge", s(&camp)]);
    assert_eq!(assert_refused(&merge, &camp, "merge"), std::process::id());
    assert!(!camp.join("campaign.csv").exists(), "nothing written");
    drop(lock);

    // Shards share the directory (each holds it shared, and its own index alone).
    let shard0 = acquire_soon(|| DirLock::acquire_part(&camp, "campaign.shard-0-of-2.csv"));
    let shared = acquire_soon(|| DirLock::acquire_shared(&camp));
    let o = campaign(&["--shard", "0/2"]);
    assert_refused(&o, &camp.join("campaign.shard-0-of-2.csv"), "the same shard twice");
    let o = campaign(&["--shard", "1/2"]); // an empty shard of the one-run grid: runs nothing
    assert!(o.status.success(), "another shard: {}", describe(&o));
    let o = campaign(&[]);
    assert_eq!(o.status.code(), Some(2), "{}", describe(&o));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("is being written by another rubblepile process (pid unknown)"),
        "an unsharded campaign beside shards: {}",
        describe(&o)
    );
    drop((shard0, shared));

    // One run directory held by another process: that run fails, the campaign goes on and says so.
    let run = camp.join("N30_T4_P1_z45_s1");
    std::fs::create_dir_all(&run).unwrap();
    let lock = DirLock::acquire(&run).unwrap();
    let o = campaign(&[]);
    assert_eq!(o.status.code(), Some(1), "{}", describe(&o));
    let index = read(&camp.join("campaign.csv"));
    assert!(
        index.contains("is being written by another rubblepile process"),
        "{index}"
    );
    assert!(!run.join("summary.json").exists());
    drop(lock);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A copy of the committed 200-s impact run (N30_T4 + P1, ζ = 45°; scene, impact.json, snapshots at 0 and 200 s; no
/// time series).
fn impact_run(tag: &str) -> PathBuf {
    let run = temp_dir(tag).join("run");
    let from = root().join("tests/data/n30_p1_z45");
    std::fs::create_dir_all(run.join("snapshots")).unwrap();
    for f in [
        "scene.toml",
        "impact.json",
        "summary.json",
        "snapshots/0.csv",
        "snapshots/1.csv",
    ] {
        std::fs::copy(from.join(f), run.join(f)).unwrap();
    }
    // The scene's bodies file is the state at t = 0, which snapshot 0 holds in the same columns.
    std::fs::copy(from.join("snapshots/0.csv"), run.join("initial_bodies.csv")).unwrap();
    run
}

/// `render`, `export` and `analyze` refused at once while another process writes what they would write: the run's
/// `frames/`, the run directory itself (a run writes the same VTK and XYZ files), the run's `analysis/`.
#[test]
fn render_export_and_analyze_are_refused_while_their_output_is_written() {
    let _serial = one_at_a_time();
    let run = impact_run("visual-locked");
    let cwd = run.parent().unwrap();

    let frames = DirLock::acquire_part(&run, "frames").unwrap();
    let o = rubblepile(cwd, &["render", s(&run), "--size", "64x64"]);
    assert_eq!(assert_refused(&o, &run.join("frames"), "render"), std::process::id());
    assert!(!run.join("frames").exists(), "render wrote nothing");
    drop(frames);

    let whole = acquire_soon(|| DirLock::acquire(&run));
    let o = rubblepile(cwd, &["export", "vtk", s(&run)]);
    assert_eq!(assert_refused(&o, &run, "export"), std::process::id());
    assert!(!run.join("vtk").exists(), "export wrote nothing");
    drop(whole);

    let analysis = acquire_soon(|| DirLock::acquire_part(&run, "analysis"));
    let o = rubblepile(cwd, &["analyze", s(&run), "--at-s", "200"]);
    assert_eq!(assert_refused(&o, &run.join("analysis"), "analyze"), std::process::id());
    assert!(!run.join("analysis").exists(), "analyze wrote nothing");
    drop(analysis);
    let _ = std::fs::remove_dir_all(cwd);
}

/// Readers are not blocked: while another process writes the run directory, `check DIR` reads it, `analyze` writes
/// its `analysis/` and `render` its `frames/` (README: "`analyze` also works on a run that is still going").
#[test]
fn readers_and_part_writers_work_on_a_run_being_written() {
    let _serial = one_at_a_time();
    let run = impact_run("readers");
    let cwd = run.parent().unwrap();
    let _lock = DirLock::acquire(&run).unwrap();
    let o = rubblepile(cwd, &["check", s(&run)]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("status: completed"), "check: {}", describe(&o));
    let o = rubblepile(cwd, &["analyze", s(&run), "--at-s", "200"]);
    assert!(o.status.success(), "analyze: {}", describe(&o));
    assert!(run.join("analysis/analysis.json").is_file());
    let o = rubblepile(cwd, &["render", s(&run), "--size", "64x64", "--color", "bound"]);
    assert!(o.status.success(), "render: {}", describe(&o));
    assert!(run.join("frames/run.gif").is_file());
    let _ = std::fs::remove_dir_all(cwd);
}

/// A holder killed with SIGKILL leaves its lock file behind but not its lock: the OS released it with the process,
/// so the next writer goes ahead at once.
#[test]
fn a_killed_holder_releases_the_lock() {
    let _serial = one_at_a_time();
    let dir = temp_dir("killed-holder");
    std::fs::write(
        dir.join("scene.toml"),
        pile_scene(600_000.0).replace("every = 5.0", "every = 100.0"),
    )
    .unwrap();
    let out = dir.join("out");
    let mut child = bin(&dir, &["run", "scene.toml", "--out", s(&out), "--no-progress"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    wait_for_holder(&out, child.id());
    let refused = bin(&dir, &["resume", s(&out)]).output().unwrap();
    assert_eq!(assert_refused(&refused, &out, "while alive"), child.id());
    child.kill().unwrap();
    let status = child.wait().unwrap();
    assert!(!status.success(), "the holder was killed");
    assert!(out.join(LOCK_FILE).is_file(), "the lock file stays");
    let lock = DirLock::acquire(&out).expect("the dead holder's lock is free");
    drop(lock);
    std::fs::write(
        dir.join("short.toml"),
        read(&root().join("tests/bad_input/ellipsoids.toml")),
    )
    .unwrap();
    let o = rubblepile(
        &dir,
        &["run", "short.toml", "--out", s(&out), "--force", "--no-progress"],
    );
    assert!(o.status.success(), "a new run after the killed one: {}", describe(&o));
    let _ = std::fs::remove_dir_all(&dir);
}
