//! Progress on a non-terminal (issue 41): with stderr piped, as in a batch job, a run prints a plain progress line
//! (simulated time, per cent, ETA, the engine's error) every `--progress-every` seconds of wall clock, none with
//! the default 60 s in a run that takes less, and refuses a bad cadence by name.

mod common;

use common::{rubblepile, temp_dir};

const SCENE: &str = r#"[scene]
kind = "hard-spheres"
t_end = 2.0
[stepping]
dt = 0.01
[material]
eps_n = 0.5
eps_t = 1.0
[output]
snapshot_every = 0.5
every = 0.1
[[particle]]
mass = 1.0
radius = 0.1
position = [0.0, 0.0, 0.0]
velocity = [1.0, 0.0, 0.0]
[[particle]]
mass = 1.0
radius = 0.1
position = [1.0, 0.0, 0.0]
velocity = [-1.0, 0.0, 0.0]
"#;

fn progress_lines(stderr: &str) -> Vec<&str> {
    stderr.lines().filter(|l| l.starts_with("progress: ")).collect()
}

#[test]
fn a_piped_run_prints_progress_lines_at_the_wall_clock_cadence() {
    let dir = temp_dir("progress-lines");
    std::fs::write(dir.join("s.toml"), SCENE).unwrap();
    // A cadence below any step's wall time: a line at every sample (21 rows of the time series).
    let o = rubblepile(&dir, &["run", "s.toml", "--out", "fast", "--progress-every", "1e-9"]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    let lines = progress_lines(&stderr);
    assert!(lines.len() >= 21, "{stderr}");
    let last = lines.last().unwrap();
    assert!(last.starts_with("progress: t = 2 of 2 s (100.0 %), wall "), "{last}");
    assert!(last.contains(", ETA 0s, energy residual "), "{last}");
    for l in &lines {
        assert!(
            l.contains(" s (") && l.contains(" %), wall ") && l.contains(", ETA "),
            "{l}"
        );
    }
    // The snapshots follow `snapshot_every`: 0, 0.5, 1, 1.5, 2 s.
    for k in 0..5 {
        assert!(dir.join(format!("fast/snapshots/{k}.csv")).is_file(), "snapshot {k}");
    }
    assert!(!dir.join("fast/snapshots/5.csv").exists());

    // The default cadence (60 s) prints nothing in a run of milliseconds; neither does --no-progress.
    let o = rubblepile(&dir, &["run", "s.toml", "--out", "default"]);
    assert!(o.status.success());
    assert!(progress_lines(&String::from_utf8_lossy(&o.stderr)).is_empty());
    let o = rubblepile(
        &dir,
        &[
            "run",
            "s.toml",
            "--out",
            "quiet",
            "--no-progress",
            "--progress-every",
            "1e-9",
        ],
    );
    assert!(o.status.success());
    assert!(progress_lines(&String::from_utf8_lossy(&o.stderr)).is_empty());
}

#[test]
fn the_environment_sets_the_cadence_and_bad_values_are_refused() {
    let dir = temp_dir("progress-env");
    std::fs::write(dir.join("s.toml"), SCENE).unwrap();
    let bin = env!("CARGO_BIN_EXE_rubblepile");
    let run = |out: &str, env: &str| {
        std::process::Command::new(bin)
            .args(["run", "s.toml", "--out", out])
            .env("RUBBLEPILE_PROGRESS_EVERY", env)
            .current_dir(&dir)
            .output()
            .unwrap()
    };
    let o = run("env", "1e-9");
    assert!(o.status.success());
    assert!(progress_lines(&String::from_utf8_lossy(&o.stderr)).len() >= 21);
    let o = run("bad-env", "soon");
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("RUBBLEPILE_PROGRESS_EVERY"));
    let o = rubblepile(&dir, &["run", "s.toml", "--out", "bad-flag", "--progress-every=-1"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--progress-every"));
}
