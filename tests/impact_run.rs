//! Impact runs end to end, and the committed Roig03 targets against Table 1.

mod common;
use common::{rubblepile, temp_dir};
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn json(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
}

/// Speed of the last body (the projectile) in a snapshot.
fn last_body_speed(snapshot: &Path) -> f64 {
    let mut rdr = csv::Reader::from_path(snapshot).unwrap();
    let headers = rdr.headers().unwrap().clone();
    let col = |name: &str| headers.iter().position(|h| h == name).unwrap();
    let last = rdr.records().map(|r| r.unwrap()).last().unwrap();
    let v: Vec<f64> = ["vx", "vy", "vz"]
        .iter()
        .map(|c| last[col(c)].parse().unwrap())
        .collect();
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// N30 + P1 at ζ = 45° to t = 200 s (contact from ≈ 80–90 s): conservation within 1e-6 and the projectile
/// stopped by the pile.
#[test]
fn short_impact_conserves_and_decelerates_the_projectile() {
    let out = temp_dir("short");
    let target = root().join("targets/N30_T4.csv");
    let status = Command::new(env!("CARGO_BIN_EXE_rubblepile"))
        .args(["impact", "--target"])
        .arg(&target)
        .args([
            "--projectile",
            "P1",
            "--angle-deg",
            "45",
            "--t-end-s",
            "200",
            "--snapshots-s",
            "0,60,200",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
    let summary = json(&out.join("summary.json"));
    for key in ["energy_error", "linear_momentum_error", "angular_momentum_error"] {
        let e = summary[key].as_f64().unwrap();
        assert!(e <= 1e-6, "{key} = {e:e}");
    }
    let impact = json(&out.join("impact.json"));
    let q = impact["q_erg_per_g"].as_f64().unwrap();
    assert!((q / 0.44e9 - 1.0).abs() < 0.02, "Q = {q:e} erg/g");
    // relative to the target the projectile moves at 5 km/s before contact and is nearly stopped after
    let (before, after) = (
        last_body_speed(&out.join("snapshots/1.csv")),
        last_body_speed(&out.join("snapshots/2.csv")),
    );
    assert!(before > 4900.0, "pre-impact speed {before}");
    assert!(
        after < 0.1 * before,
        "projectile not decelerated: {before} -> {after} m/s"
    );
    // the run is an ordinary scene: scene.toml + initial_bodies.csv beside it
    assert!(out.join("initial_bodies.csv").is_file());
    assert!(
        std::fs::read_to_string(out.join("scene.toml"))
            .unwrap()
            .contains("bodies_file = \"initial_bodies.csv\"")
    );
    // tracks.csv follows the projectile (id 30) at every time-series row (every 10 s from 0 to 200 s, plus
    // the snapshot at 60 s which lies on that grid): its last row is the last snapshot's projectile row.
    let tracks = std::fs::read_to_string(out.join("tracks.csv")).unwrap();
    let rows: Vec<&str> = tracks.lines().skip(1).collect();
    assert_eq!(rows.len(), 21, "tracks.csv rows");
    assert!(rows.iter().all(|r| r.split(',').nth(1) == Some("30")), "tracked id");
    let last_snapshot = std::fs::read_to_string(out.join("snapshots/2.csv")).unwrap();
    assert_eq!(
        Some(*rows.last().unwrap()),
        last_snapshot.lines().last(),
        "tracks vs snapshot"
    );
    let _ = std::fs::remove_dir_all(&out);
}

/// `impact --method dop853`: the scene names the method, the run keeps the conservation of the Bulirsch–Stoer run
/// above (dissipation booked) and projects the attitudes by default; rk4 is refused naming the field.
#[test]
fn impact_with_dop853_writes_its_method_and_conserves() {
    let out = temp_dir("short-dop853");
    let target = root().join("targets/N30_T4.csv");
    let t = target.to_str().unwrap();
    let common = [
        "impact",
        "--target",
        t,
        "--projectile",
        "P1",
        "--t-end-s",
        "200",
        "--snapshots-s",
        "0,200",
    ];
    let dir = out.join("run");
    let run = rubblepile(&out, &[&common[..], &["--method", "dop853", "--out", "run"]].concat());
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(
        std::fs::read_to_string(dir.join("scene.toml"))
            .unwrap()
            .contains("method = \"dop853\"")
    );
    let summary = json(&dir.join("summary.json"));
    assert_eq!(summary["integrator"], "dop853");
    // Dop853 applies its tolerance per step, so its default is tighter than Bulirsch–Stoer's run tolerance.
    assert_eq!(summary["rtol"], 1e-8);
    assert_eq!(summary["project_attitudes"], true);
    for key in ["energy_error", "linear_momentum_error", "angular_momentum_error"] {
        let e = summary[key].as_f64().unwrap();
        assert!(e <= 1e-6, "{key} = {e:e}");
    }
    let bad = rubblepile(&out, &[&common[..], &["--method", "rk4", "--out", "bad"]].concat());
    assert_eq!(bad.status.code(), Some(2), "{}", String::from_utf8_lossy(&bad.stderr));
    let stderr = String::from_utf8_lossy(&bad.stderr);
    assert!(
        stderr.contains("method") && stderr.contains("rk4 has a fixed step"),
        "{stderr}"
    );
    assert!(!out.join("bad").exists(), "a refused run leaves no directory");
    let _ = std::fs::remove_dir_all(&out);
}

/// Roig03 Table 1 for the committed targets: total mass and effective radius within 1 % of the paper,
/// porosity 0.30–0.45, spin period within 10 % of 4 h / 12 h, rigid, and the CSV agrees with the JSON.
#[test]
fn committed_targets_reproduce_table1() {
    // (N, total mass kg, effective radius km) from Table 1
    let table = [(30, 10.03e18, 92.76), (100, 9.99e18, 92.64), (200, 10.05e18, 92.82)];
    let mut seen = 0;
    for (n, mass, r_eff) in table {
        for period in [4.0, 12.0] {
            let csv_path = root().join(format!("targets/N{n}_T{period}.csv"));
            let json_path = csv_path.with_extension("json");
            if !json_path.exists() {
                panic!(
                    "{} missing: build it with `rubblepile target build --fragments {n} --period-h {period} --seed 1 --out targets/N{n}_T{period}.csv`",
                    json_path.display()
                );
            }
            seen += 1;
            let r = json(&json_path);
            let get = |k: &str| r[k].as_f64().unwrap_or_else(|| panic!("{k} missing"));
            assert_eq!(r["fragments"].as_u64().unwrap() as usize, n);
            assert!(
                (get("total_mass_kg") / mass - 1.0).abs() <= 0.01,
                "N{n}: mass {}",
                get("total_mass_kg")
            );
            assert!(
                (get("effective_radius_m") / 1e3 / r_eff - 1.0).abs() <= 0.01,
                "N{n}: R_eff"
            );
            let porosity = get("porosity");
            assert!((0.30..=0.45).contains(&porosity), "N{n}_T{period}: porosity {porosity}");
            assert!(
                (get("spin_period_hours") / period - 1.0).abs() <= 0.10,
                "N{n}_T{period}: period"
            );
            assert!(get("non_rigid_fraction") < 1e-4);
            let mut rdr = csv::Reader::from_path(&csv_path).unwrap();
            let mass_col = rdr.headers().unwrap().iter().position(|h| h == "mass").unwrap();
            let (count, total) = rdr.records().fold((0, 0.0), |(c, m), rec| {
                (c + 1, m + rec.unwrap()[mass_col].parse::<f64>().unwrap())
            });
            assert_eq!(count, n);
            assert!((total / get("total_mass_kg") - 1.0).abs() < 1e-12);
        }
    }
    assert_eq!(seen, 6);
}

/// `target build` twice with the same seed writes identical bytes; a different seed does not.
#[test]
fn target_build_is_deterministic() {
    let dir = temp_dir("build");
    let command = |name: &str, seed: &str| {
        let mut args = vec![
            "target",
            "build",
            "--fragments",
            "6",
            "--r-largest-km",
            "3",
            "--r-smallest-km",
            "1.5",
        ];
        args.extend([
            "--total-mass-kg",
            "8.1e14",
            "--f0",
            "0.3",
            "--period-h",
            "8",
            "--seed",
            seed,
            "--out",
            name,
        ]);
        rubblepile(&dir, &args)
    };
    let build = |name: &str, seed: &str| {
        let o = command(name, seed);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let out = dir.join(name);
        (
            std::fs::read(&out).unwrap(),
            std::fs::read(out.with_extension("json")).unwrap(),
        )
    };
    let a = build("a.csv", "5");
    let b = build("b.csv", "5");
    assert_eq!(a, b, "same seed, different bytes");
    let c = build("c.csv", "6");
    assert_ne!(a.0, c.0, "the seed changes nothing");
    // refuses to overwrite without --force
    assert_eq!(command("a.csv", "5").status.code(), Some(2));
    let _ = std::fs::remove_dir_all(&dir);
}
