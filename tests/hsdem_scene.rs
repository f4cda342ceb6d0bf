//! The `kind = "hard-spheres"` scene through `rubblepile run`: outputs, `--force`, determinism, one-line errors.

mod common;

use common::{rubblepile, temp_dir};

const SCENE: &str = r#"
[scene]
kind = "hard-spheres"
t_end = 0.5
seed = 4

[stepping]
dt = 1e-3
collapse_speed = 1e-4

[gravity]
uniform = [0.0, 0.0, -9.81]

[material]
eps_n = 0.9
eps_t = 0.5

[output]
times = [0.0, 0.25, 0.5]
every = 0.05

[[particle]]
mass = 1.0
radius = 0.05
position = [0.0, 0.0, 0.3]
velocity = [0.2, 0.0, 0.0]

[[particle]]
mass = 2.0
radius = 0.05
position = [0.01, 0.0, 0.5]
spin = [0.0, 3.0, 0.0]
eps_n = 1.0

[[wall]]
kind = "cylinder"
radius = 0.3
length = 2.0

[[wall]]
kind = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
oscillation = { amplitude = 0.001, angular_frequency = 30.0 }
"#;

#[test]
fn runs_writes_outputs_and_is_deterministic() {
    let dir = temp_dir("hsdem-scene");
    std::fs::write(dir.join("s.toml"), SCENE).unwrap();
    let out = rubblepile(&dir, &["run", "s.toml", "--out", "a", "--no-progress"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("a/summary.json")).unwrap()).unwrap();
    assert_eq!(summary["status"], "completed");
    assert!(summary["collisions"].as_u64().unwrap() > 0);
    for key in [
        "wall_seconds",
        "energy_error",
        "events_per_second",
        "max_overlap",
        "absorbed",
    ] {
        assert!(summary.get(key).is_some(), "summary lacks {key}");
    }
    assert!(summary["max_overlap"].as_f64().unwrap() < 1e-9);
    let snap = std::fs::read_to_string(dir.join("a/snapshots/2.csv")).unwrap();
    assert!(snap.starts_with("t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz,stuck_to\n"));
    let ts = std::fs::read_to_string(dir.join("a/timeseries.csv")).unwrap();
    assert_eq!(ts.lines().count(), 1 + 11);
    // Same scene, same bits.
    let out = rubblepile(&dir, &["run", "s.toml", "--out", "b", "--no-progress"]);
    assert!(out.status.success());
    for k in 0..3 {
        let a = std::fs::read(dir.join(format!("a/snapshots/{k}.csv"))).unwrap();
        let b = std::fs::read(dir.join(format!("b/snapshots/{k}.csv"))).unwrap();
        assert_eq!(a, b, "snapshot {k} differs");
    }
    // A snapshot restarts a run as a particles file.
    let restart = SCENE
        .split("[[particle]]")
        .next()
        .unwrap()
        .replace("seed = 4", "seed = 4\nparticles_file = \"a/snapshots/2.csv\"")
        + SCENE
            .split("[[wall]]")
            .skip(1)
            .map(|w| format!("[[wall]]{w}"))
            .collect::<String>()
            .as_str();
    std::fs::write(dir.join("r.toml"), restart).unwrap();
    let out = rubblepile(&dir, &["run", "r.toml", "--out", "r", "--no-progress"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // No overwrite without --force.
    let out = rubblepile(&dir, &["run", "s.toml", "--out", "a", "--no-progress"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--force"));
    let out = rubblepile(&dir, &["run", "s.toml", "--out", "a", "--force", "--no-progress"]);
    assert!(out.status.success());
}

#[test]
fn bad_input_is_one_line_naming_the_field() {
    let dir = temp_dir("hsdem-bad");
    let cases = [
        (
            "eps_n = 0.9",
            "eps_n = 1.5",
            "material.eps_n: must be in [0, 1], got 1.5",
        ),
        ("dt = 1e-3", "dt = -1.0", "stepping.dt: must be > 0 and finite, got -1"),
        ("kind = \"cylinder\"", "kind = \"cone\"", "wall[0].kind: must be one of"),
        ("radius = 0.3", "", "wall[0].radius: required for a cylinder"),
        ("mass = 2.0", "mass = 0.0", "particle[1].mass: must be > 0"),
        (
            "eps_t = 0.5",
            "eps_t = 0.5\nfoo = 1",
            "unknown field `foo` in [material]",
        ),
        (
            "position = [0.01, 0.0, 0.5]",
            "position = [0.01, 0.0, 0.35]",
            "particle[0].position: overlaps particle[1]",
        ),
        (
            "angular_frequency = 30.0 }",
            "angular_frequency = 30.0, direction = [0.0, 0.0, 0.0] }",
            "wall[1].oscillation.direction",
        ),
    ];
    for (k, (from, to, expect)) in cases.iter().enumerate() {
        let text = SCENE.replacen(from, to, 1);
        let name = format!("bad{k}.toml");
        std::fs::write(dir.join(&name), text).unwrap();
        let out = rubblepile(&dir, &["run", &name, "--out", &format!("o{k}"), "--no-progress"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(expect), "case {k}: {err}");
    }
}
