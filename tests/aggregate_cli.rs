//! `rubblepile aggregate build|density` on the command line: a build writes the particle file and its report,
//! refuses to overwrite without --force, and bad input is a one-line error naming the field (exit code 2).

use std::process::Command;

fn run(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_rubblepile"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn aggregate_cli_builds_refuses_overwrite_and_names_bad_fields() {
    let dir = std::env::temp_dir().join(format!("rubblepile-aggregate-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("hcp.csv");
    let o = out.to_str().unwrap();
    let base = [
        "aggregate",
        "build",
        "--model",
        "hcp",
        "--shape",
        "top:300",
        "--particles",
        "500",
        "--out",
        o,
    ];
    assert_eq!(run(&base).0, 0);
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz\n"));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("hcp.json")).unwrap()).unwrap();
    assert_eq!(report["n"].as_u64().unwrap() as usize, text.lines().count() - 1);
    let (code, err) = run(&base);
    assert_eq!(code, 2);
    assert!(err.contains("--force"), "{err}");
    // the density variant
    let dense = dir.join("dense.csv");
    let (code, err) = run(&[
        "aggregate",
        "density",
        "--input",
        o,
        "--bulk-density-kg-m3",
        "2500",
        "--out",
        dense.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let r2: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("dense.json")).unwrap()).unwrap();
    assert!((r2["bulk_density_kg_m3"].as_f64().unwrap() / 2500.0 - 1.0).abs() < 1e-12);

    let bad = |extra: &[&str], field: &str| {
        let mut args = vec!["aggregate", "build", "--out"];
        let path = dir.join("bad.csv");
        args.push(path.to_str().unwrap());
        let owned: Vec<String> = extra.iter().map(|s| s.to_string()).collect();
        let mut all: Vec<&str> = args.clone();
        all.extend(owned.iter().map(|s| s.as_str()));
        let (code, err) = run(&all);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(err.starts_with("error: ") && err.contains(field), "{extra:?}: {err}");
        assert!(!path.exists());
    };
    bad(
        &["--model", "fcc", "--shape", "sphere:100", "--radius-m", "5"],
        "--model",
    );
    bad(&["--model", "hcp", "--shape", "cube:100", "--radius-m", "5"], "--shape");
    bad(
        &["--model", "hcp", "--shape", "sphere:100", "--radius-m", "-5"],
        "--radius-m",
    );
    bad(
        &["--model", "hcp", "--shape", "obj:/nonexistent.obj", "--radius-m", "5"],
        "/nonexistent.obj",
    );
    bad(
        &["--model", "rcp", "--shape", "sphere:100", "--particles", "3"],
        "--particles",
    );
    bad(
        &["--model", "pp1", "--shape", "sphere:100", "--radius-range-m", "8,4"],
        "--radius-range-m",
    );
    bad(
        &[
            "--model",
            "hcp",
            "--shape",
            "sphere:100",
            "--radius-m",
            "5",
            "--bulk-density-kg-m3",
            "0",
        ],
        "--bulk-density-kg-m3",
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A settled snapshot has no `NAME.json` beside it: `--report` names the report of the aggregate it was settled
/// from, whose shape volume sets the bulk density; without it, or with a missing report, the error names the field.
#[test]
fn density_variant_of_a_snapshot_takes_the_report_named_by_report() {
    let dir = std::env::temp_dir().join(format!("rubblepile-aggregate-report-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let built = dir.join("hcp.csv");
    let args = [
        "aggregate",
        "build",
        "--model",
        "hcp",
        "--shape",
        "top:300",
        "--particles",
        "300",
    ];
    let (code, err) = run(&[&args[..], &["--out", built.to_str().unwrap()]].concat());
    assert_eq!(code, 0, "{err}");
    // a "settled" snapshot: the same particles under another name, with velocities
    let text = std::fs::read_to_string(&built).unwrap();
    let mut settled = String::new();
    for (k, line) in text.lines().enumerate() {
        if k == 0 {
            settled += line;
        } else {
            let mut cells: Vec<&str> = line.split(',').collect();
            cells[7] = "0.01"; // vx (m/s)
            settled += &cells.join(",");
        }
        settled += "\n";
    }
    let snap = dir.join("settled.csv");
    std::fs::write(&snap, settled).unwrap();
    let out = dir.join("dense.csv");
    let density = |report: Option<&str>| {
        let mut a = vec!["aggregate", "density", "--input", snap.to_str().unwrap()];
        if let Some(r) = report {
            a.extend(["--report", r]);
        }
        a.extend([
            "--bulk-density-kg-m3",
            "2500",
            "--out",
            out.to_str().unwrap(),
            "--force",
        ]);
        run(&a)
    };
    let (code, err) = density(None);
    assert_eq!(code, 2);
    assert!(err.contains("--input") && err.contains("settled.json"), "{err}");
    let (code, err) = density(Some("/nonexistent/hcp.json"));
    assert_eq!(code, 2);
    assert!(
        err.contains("--report") && err.contains("/nonexistent/hcp.json"),
        "{err}"
    );
    let (code, err) = density(Some(dir.join("hcp.json").to_str().unwrap()));
    assert_eq!(code, 0, "{err}");
    let old: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("hcp.json")).unwrap()).unwrap();
    let new: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("dense.json")).unwrap()).unwrap();
    assert!((new["bulk_density_kg_m3"].as_f64().unwrap() / 2500.0 - 1.0).abs() < 1e-12);
    let factor = 2500.0 / old["bulk_density_kg_m3"].as_f64().unwrap();
    let mass = |m: &serde_json::Value| m["total_mass_kg"].as_f64().unwrap();
    assert!((mass(&new) / (factor * mass(&old)) - 1.0).abs() < 1e-12);
    // the velocities of the snapshot are kept
    let dense = std::fs::read_to_string(&out).unwrap();
    let row: Vec<f64> = dense
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|c| c.parse().unwrap())
        .collect();
    assert_eq!(row[7], 0.01);
    std::fs::remove_dir_all(&dir).ok();
}
