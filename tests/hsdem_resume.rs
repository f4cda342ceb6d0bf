//! Hard-sphere runs checkpoint and resume bit for bit (`rubblepile run … --checkpoint-every-sim-s`, `rubblepile
//! resume`), here on a small tumbler (Richardson11 §3.2): a spinning drum lined with particles attached from t = 0
//! (`stuck_to` column of the particles file), free rough spheres, gravity, frictionless end planes.

mod common;

use common::{rubblepile, temp_dir};

const SCENE: &str = r#"
[scene]
kind = "hard-spheres"
t_end = 0.3
seed = 0
particles_file = "p.csv"

[stepping]
dt = 2e-4
collapse_speed = 4e-3

[gravity]
uniform = [0.0, 0.0, -9.81]

[material]
eps_n = 0.8
eps_t = 0.8

[output]
every = 0.02
times = [0.0, 0.1, 0.2, 0.3]

[[wall]]
kind = "cylinder"
axis = [0.0, 1.0, 0.0]
radius = 0.03
spin = 12.0

[[wall]]
kind = "plane"
point = [0.0, -0.0025, 0.0]
normal = [0.0, 1.0, 0.0]
eps_t = 1.0

[[wall]]
kind = "plane"
point = [0.0, 0.0025, 0.0]
normal = [0.0, -1.0, 0.0]
eps_t = 1.0
"#;

/// Lining of 2 × 40 particles touching the drum (attached to wall 0) and 60 free particles in the lower half.
fn particles_csv() -> String {
    let (r, rc) = (1.5e-3, 0.03);
    let mut s = String::from("t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz,stuck_to\n");
    let mut id = 0;
    for (k, y) in [-1.0e-3, 1.0e-3].into_iter().enumerate() {
        for j in 0..40 {
            let a = std::f64::consts::TAU * (j as f64 + 0.5 * k as f64) / 40.0;
            let (x, z) = ((rc - r) * a.sin(), -(rc - r) * a.cos());
            s += &format!("0,{id},3.5e-5,{r},{x},{y},{z},0,0,0,0,0,0,0\n");
            id += 1;
        }
    }
    for n in 0..60 {
        let (ix, iz) = ((n % 9) as f64 - 4.0, (n / 9) as f64);
        let (x, z) = (ix * 3.2e-3, -0.018 + iz * 3.2e-3);
        s += &format!("0,{id},3.5e-5,{r},{x},0,{z},0,0,0,0,0,0,-1\n");
        id += 1;
    }
    s
}

fn timeseries_without_clock(path: &std::path::Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let skip: Vec<usize> = ["events_per_second", "wall_seconds"]
        .iter()
        .map(|c| header.iter().position(|h| h == c).unwrap())
        .collect();
    text.lines()
        .map(|l| {
            l.split(',')
                .enumerate()
                .filter(|(k, _)| !skip.contains(k))
                .map(|(_, v)| v)
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect()
}

#[test]
fn interrupted_run_resumes_bit_for_bit() {
    let dir = temp_dir("hsdem-resume");
    std::fs::write(dir.join("s.toml"), SCENE).unwrap();
    std::fs::write(dir.join("p.csv"), particles_csv()).unwrap();
    let ck = [
        "--checkpoint-every-s",
        "0",
        "--checkpoint-every-sim-s",
        "0.05",
        "--no-progress",
    ];
    let out = rubblepile(&dir, &[&["run", "s.toml", "--out", "a"][..], &ck].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = rubblepile(
        &dir,
        &[
            &["run", "s.toml", "--out", "b", "--stop-after-checkpoints", "3"][..],
            &ck,
        ]
        .concat(),
    );
    assert_eq!(out.status.code(), Some(3), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(dir.join("b/checkpoint.json").is_file());
    assert!(!dir.join("b/snapshots/3.csv").exists(), "stopped before the end");
    let out = rubblepile(&dir, &["resume", "b", "--no-progress"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    for k in 0..4 {
        let a = std::fs::read(dir.join(format!("a/snapshots/{k}.csv"))).unwrap();
        let b = std::fs::read(dir.join(format!("b/snapshots/{k}.csv"))).unwrap();
        assert_eq!(a, b, "snapshot {k} differs");
    }
    assert_eq!(
        timeseries_without_clock(&dir.join("a/timeseries.csv")),
        timeseries_without_clock(&dir.join("b/timeseries.csv"))
    );
    let summary = |d: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.join(d).join("summary.json")).unwrap()).unwrap()
    };
    let (sa, sb) = (summary("a"), summary("b"));
    for key in [
        "status",
        "steps",
        "collisions",
        "events",
        "energy_error",
        "max_overlap",
        "stuck",
    ] {
        assert_eq!(sa[key], sb[key], "summary {key}");
    }
    assert_eq!(sa["stuck"], 80);
    assert!(sa["collisions"].as_u64().unwrap() > 100);
    // The lining turned with the drum (0.3 s × 12 rad/s) and stayed on it.
    let snap = std::fs::read_to_string(dir.join("a/snapshots/3.csv")).unwrap();
    let first = snap.lines().nth(1).unwrap();
    let v: Vec<f64> = first.split(',').map(|x| x.parse().unwrap()).collect();
    let (x, z) = (v[4], v[6]);
    assert!(
        ((x * x + z * z).sqrt() - 0.0285).abs() < 1e-12,
        "lining radius {}",
        (x * x + z * z).sqrt()
    );
    let angle = x.atan2(-z);
    // Right-handed turn about +y: the drum's bottom moves towards −x, so the angle atan2(x, −z) decreases.
    let expect = -12.0 * 0.3;
    let d = (angle - expect).rem_euclid(std::f64::consts::TAU);
    assert!(
        d.min(std::f64::consts::TAU - d) < 1e-9,
        "lining angle {angle}, expected {expect}"
    );
    // Nothing left to resume; a run directory without a checkpoint cannot be resumed.
    let out = rubblepile(&dir, &["resume", "b", "--no-progress"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("already completed"));
}
