//! Progress on a non-terminal (issue 41): with stderr piped, as in a batch job, a run prints a plain progress line
//! (simulated time, per cent, ETA, the engine's error) every `--progress-every-s` seconds of wall clock, none with
//! the default 60 s in a run that takes less, and refuses a bad cadence by name: below the floor of 0.1 s (a
//! cadence of 1e-320 once printed 125 801 lines) or above the ceiling of 1e7 s (1e308 once panicked) (issue 53).

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

/// [`SCENE`] with steps a hundred thousand times shorter: 1e7 steps, a second or so of wall clock, long enough for
/// a few lines at the floor of 0.1 s.
fn slow_scene() -> String {
    SCENE.replace("dt = 0.01", "dt = 2e-7")
}

fn progress_lines(stderr: &str) -> Vec<&str> {
    stderr.lines().filter(|l| l.starts_with("progress: ")).collect()
}

#[test]
fn a_piped_run_prints_progress_lines_at_the_wall_clock_cadence() {
    let dir = temp_dir("progress-lines");
    std::fs::write(dir.join("s.toml"), SCENE).unwrap();
    std::fs::write(dir.join("slow.toml"), slow_scene()).unwrap();
    // The floor's cadence over a run of a second or so: several lines, in order of simulated time.
    let o = rubblepile(
        &dir,
        &["run", "slow.toml", "--out", "fast", "--progress-every-s", "0.1"],
    );
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    let lines = progress_lines(&stderr);
    assert!(lines.len() >= 2, "{stderr}");
    let mut last_t = -1.0;
    for l in &lines {
        assert!(
            l.contains(" s (") && l.contains(" %), wall ") && l.contains(", ETA ") && l.contains("energy residual "),
            "{l}"
        );
        let t: f64 = l["progress: t = ".len()..].split(' ').next().unwrap().parse().unwrap();
        assert!(t >= last_t, "{stderr}");
        last_t = t;
    }
    let o = rubblepile(&dir, &["run", "s.toml", "--out", "fast-snapshots"]);
    assert!(o.status.success());
    let fast = dir.join("fast-snapshots");
    for k in 0..5 {
        assert!(fast.join(format!("snapshots/{k}.csv")).is_file(), "snapshot {k}");
    }
    assert!(!fast.join("snapshots/5.csv").exists());
    // The snapshots follow `snapshot_every`: 0, 0.5, 1, 1.5, 2 s (checked above on `fast-snapshots`).

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
            "--progress-every-s",
            "0.1",
        ],
    );
    assert!(o.status.success());
    assert!(progress_lines(&String::from_utf8_lossy(&o.stderr)).is_empty());
}

#[test]
fn the_environment_sets_the_cadence_and_bad_values_are_refused() {
    let dir = temp_dir("progress-env");
    std::fs::write(dir.join("s.toml"), slow_scene()).unwrap();
    let bin = env!("CARGO_BIN_EXE_rubblepile");
    let run = |out: &str, env: &str| {
        std::process::Command::new(bin)
            .args(["run", "s.toml", "--out", out])
            .env("RUBBLEPILE_PROGRESS_EVERY", env)
            .current_dir(&dir)
            .output()
            .unwrap()
    };
    let o = run("env", "0.1");
    assert!(o.status.success());
    assert!(!progress_lines(&String::from_utf8_lossy(&o.stderr)).is_empty());
    for bad in ["soon", "1e308", "1e-320", "inf"] {
        let o = run("bad-env", bad);
        assert_eq!(o.status.code(), Some(2), "{bad}");
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(
            stderr.contains("RUBBLEPILE_PROGRESS_EVERY must be 0 (no lines) or a number of seconds from 0.1 to 1e7"),
            "{bad}: {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
    assert!(
        !dir.join("bad-env").exists(),
        "refused before the output directory is made"
    );
    for bad in ["-1", "1e308", "1e-320", "1e-9", "NaN"] {
        let o = rubblepile(
            &dir,
            &[
                "run",
                "s.toml",
                "--out",
                "bad-flag",
                &format!("--progress-every-s={bad}"),
            ],
        );
        assert_eq!(o.status.code(), Some(2), "{bad}");
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(
            stderr.contains("--progress-every-s must be 0 (no lines) or a number of seconds from 0.1 to 1e7"),
            "{stderr}"
        );
    }
}
