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
        "--bulk-density",
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
    bad(&["--model", "fcc", "--shape", "sphere:100", "--radius", "5"], "--model");
    bad(&["--model", "hcp", "--shape", "cube:100", "--radius", "5"], "--shape");
    bad(
        &["--model", "hcp", "--shape", "sphere:100", "--radius", "-5"],
        "--radius",
    );
    bad(
        &["--model", "hcp", "--shape", "obj:/nonexistent.obj", "--radius", "5"],
        "/nonexistent.obj",
    );
    bad(
        &["--model", "rcp", "--shape", "sphere:100", "--particles", "3"],
        "--particles",
    );
    bad(
        &["--model", "pp1", "--shape", "sphere:100", "--radius-range", "8,4"],
        "--radius-range",
    );
    bad(
        &[
            "--model",
            "hcp",
            "--shape",
            "sphere:100",
            "--radius",
            "5",
            "--bulk-density",
            "0",
        ],
        "--bulk-density",
    );
    std::fs::remove_dir_all(&dir).ok();
}
