//! Soft-sphere runs through the command line: outputs, determinism (same bits on 1 and 2 threads), resume
//! after a checkpoint bit-identical to an uninterrupted run, `ssdem advise`, and bad input.

mod common;
use common::{rubblepile, temp_dir};
use std::path::Path;

/// Twelve spheres dropped into a spherical bowl under 1 g onto a floor, with friction and rolling resistance.
fn scene(extra_particle: &str, dt: &str) -> String {
    let mut s = format!(
        r#"[scene]
kind = "soft-spheres"
t_end = 0.5
seed = 3

[stepping]
dt = {dt}

[material]
k_n = 2e5

[gravity]
uniform = [0.0, 0.0, -9.81]
self = "direct"
G = 1e-3

[output]
every = 0.05
times = [0.0, 0.25, 0.5]

[[wall]]
kind = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
oscillation = {{ amplitude = 0.002, angular_frequency = 62.83185307179586 }}

[[wall]]
kind = "sphere"
centre = [0.0, 0.0, 0.5]
radius = 0.9
"#
    );
    for k in 0..12 {
        let (x, y, z) = (
            -0.25 + 0.17 * (k % 4) as f64,
            -0.1 + 0.2 * ((k / 4) % 2) as f64,
            0.12 + 0.22 * (k / 8) as f64 + 0.01 * k as f64,
        );
        s += &format!(
            "\n[[particle]]\nradius = 0.08\ndensity = 2500.0\nposition = [{x}, {y}, {z}]\nvelocity = [{}, 0.0, 0.0]\nspin = [0.0, 0.0, {}]\n",
            0.1 * (k % 3) as f64,
            k as f64
        );
    }
    s + extra_particle
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The time series without its last column (wall seconds).
fn series(dir: &Path) -> String {
    read(&dir.join("timeseries.csv"))
        .lines()
        .map(|l| l.rsplit_once(',').unwrap().0.to_string())
        .collect::<Vec<_>>()
        .join("\n")
}

fn run(dir: &Path, scene_file: &str, out: &str, extra: &[&str], threads: &str) -> std::process::Output {
    let mut args = vec!["run", scene_file, "--out", out, "--no-progress"];
    args.extend_from_slice(extra);
    std::process::Command::new(env!("CARGO_BIN_EXE_rubblepile"))
        .args(&args)
        .current_dir(dir)
        .env("RAYON_NUM_THREADS", threads)
        .output()
        .unwrap()
}

#[test]
fn run_outputs_determinism_and_bit_identical_resume() {
    let dir = temp_dir("ssdem-run");
    std::fs::write(dir.join("s.toml"), scene("", "2e-4")).unwrap();
    let a = run(&dir, "s.toml", "a", &[], "1");
    assert!(a.status.success(), "{}", String::from_utf8_lossy(&a.stderr));
    let b = run(&dir, "s.toml", "b", &[], "2");
    assert!(b.status.success());
    for f in ["snapshots/0.csv", "snapshots/1.csv", "snapshots/2.csv"] {
        assert_eq!(
            read(&dir.join("a").join(f)),
            read(&dir.join("b").join(f)),
            "{f} differs between 1 and 2 threads"
        );
    }
    assert_eq!(series(&dir.join("a")), series(&dir.join("b")));
    let summary: serde_json::Value = serde_json::from_str(&read(&dir.join("a/summary.json"))).unwrap();
    assert_eq!(summary["status"], "completed");
    assert_eq!(summary["steps"], 2500);
    let overlap = summary["max_overlap_fraction"].as_f64().unwrap();
    assert!(overlap > 0.0 && overlap < 0.2, "max overlap {overlap}");
    let header = read(&dir.join("a/timeseries.csv")).lines().next().unwrap().to_string();
    for col in [
        "max_overlap_fraction",
        "contacts",
        "coordination_number",
        "energy_residual",
    ] {
        assert!(header.contains(col), "timeseries lacks {col}");
    }
    assert!(read(&dir.join("a/snapshots/2.csv")).starts_with("t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz\n"));

    // Refuses to overwrite without --force; --force works.
    let again = run(&dir, "s.toml", "a", &[], "2");
    assert_eq!(again.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&again.stderr).contains("--force"));

    // Interrupted after the second checkpoint, resumed: bit-identical.
    let c = run(
        &dir,
        "s.toml",
        "c",
        &["--checkpoint-every-sim-s", "0.1", "--stop-after-checkpoints", "2"],
        "2",
    );
    assert_eq!(c.status.code(), Some(3), "{}", String::from_utf8_lossy(&c.stderr));
    assert!(!dir.join("c/summary.json").exists());
    let r = rubblepile(&dir, &["resume", "c", "--no-progress"]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    for f in ["snapshots/0.csv", "snapshots/1.csv", "snapshots/2.csv"] {
        assert_eq!(
            read(&dir.join("a").join(f)),
            read(&dir.join("c").join(f)),
            "{f} differs after resume"
        );
    }
    assert_eq!(
        series(&dir.join("a")),
        series(&dir.join("c")),
        "time series differs after resume"
    );
    let sc: serde_json::Value = serde_json::from_str(&read(&dir.join("c/summary.json"))).unwrap();
    for key in [
        "energy_error",
        "max_overlap_fraction",
        "angular_momentum_error",
        "steps",
        "contacts",
    ] {
        assert_eq!(summary[key], sc[key], "summary {key} differs after resume");
    }
    // A completed run cannot be resumed.
    let done = rubblepile(&dir, &["resume", "c"]);
    assert_eq!(done.status.code(), Some(2));

    // A snapshot works as a particles_file.
    let text = scene("", "2e-4");
    let head: String = text.split("\n[[particle]]").next().unwrap().to_string();
    let from_file = head.replace("seed = 3", "seed = 3\nparticles_file = \"a/snapshots/2.csv\"");
    std::fs::write(dir.join("f.toml"), from_file).unwrap();
    let f = rubblepile(&dir, &["check", "f.toml"]);
    assert!(f.status.success(), "{}", String::from_utf8_lossy(&f.stderr));
    assert!(String::from_utf8_lossy(&f.stdout).contains("12 particles"));
}

fn bad(extra: &str, dt: &str, expect: &str) {
    let dir = temp_dir("ssdem-bad");
    std::fs::write(dir.join("s.toml"), scene(extra, dt)).unwrap();
    let out = rubblepile(&dir, &["run", "s.toml", "--out", "o"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "not one line: {err}");
    assert!(err.contains(expect), "expected {expect:?} in {err}");
}

#[test]
fn bad_input_gives_one_line_errors_naming_the_field() {
    bad(
        "\n[[particle]]\nradius = -0.1\nmass = 1.0\nposition = [0.0, 0.3, 0.3]\n",
        "2e-4",
        "particle[12].radius: must be > 0 and finite, got -0.1",
    );
    bad(
        "\n[[particle]]\nradius = 0.08\nmass = 1.0\nposition = [-0.25, -0.1, 0.13]\n",
        "2e-4",
        "particle[0].position: overlaps particle[12]",
    );
    bad("", "0.05", "stepping.dt: must be <= the leapfrog stability limit");
    let dir = temp_dir("ssdem-bad");
    let s = scene("", "2e-4").replace("self = \"direct\"", "self = \"fast\"");
    std::fs::write(dir.join("s.toml"), s).unwrap();
    let out = rubblepile(&dir, &["check", "s.toml"]);
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("gravity.self: must be \"tree\" or \"direct\", got \"fast\"")
    );
    // A step above 10 × the advised one (but stable) runs with a warning.
    let s = scene("", "2e-4")
        .replace("t_end = 0.5", "t_end = 0.01")
        .replace("times = [0.0, 0.25, 0.5]", "times = [0.0]");
    let dt_warn = "4e-3";
    std::fs::write(dir.join("w.toml"), s.replace("dt = 2e-4", &format!("dt = {dt_warn}"))).unwrap();
    let out = rubblepile(&dir, &["check", "w.toml"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("warning:")
            && String::from_utf8_lossy(&out.stderr).contains("stepping.dt")
    );
}

#[test]
fn advise_suggests_k_n_and_dt() {
    let dir = temp_dir("ssdem-advise");
    let out = rubblepile(
        &dir,
        &[
            "ssdem",
            "advise",
            "--radius-m",
            "10",
            "--density-kg-m3",
            "2000",
            "--body-radius-m",
            "390",
            "--spin-period-h",
            "2.26",
        ],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("k_n = ") && text.contains("dt = "), "{text}");
    let out = rubblepile(
        &dir,
        &[
            "ssdem",
            "advise",
            "--radius-m=-1",
            "--density-kg-m3",
            "2000",
            "--speed-m-s",
            "1",
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--radius-m must be > 0"));
}
