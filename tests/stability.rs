//! The stability suite from the command line: `rubblepile run` prints the contact-barrier overrun of the 3× head-on
//! case (Roig03 Eq. 14) as one warning on stderr, and `rubblepile bench stability` writes its tables and refuses to
//! overwrite them. The suite's cases themselves are tested beside them (`src/bench/stability/suite_tests.rs`).

mod common;

use std::path::Path;

use common::{rubblepile, temp_dir};

/// The scene of quick case `a2` (the 3× head-on impact), as `bench stability` writes it next to its run.
fn a2_scene(dir: &Path) -> String {
    let out = rubblepile(
        dir,
        &["bench", "stability", "--quick", "--only", "a2", "--out", "suite"],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    std::fs::read_to_string(dir.join("suite/runs/a2-headon-3x/scene.toml")).unwrap()
}

#[test]
fn command_line_prints_the_overrun_warning_on_stderr() {
    let dir = temp_dir("stability-cli");
    std::fs::write(dir.join("a2.toml"), a2_scene(&dir)).unwrap();
    let out = rubblepile(&dir, &["run", "a2.toml", "--out", "run", "--no-progress"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    assert!(
        lines[0].starts_with("warning: bodies 1 and 2 overran the contact barrier at t = "),
        "{stderr}"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("run/summary.json")).unwrap()).unwrap();
    assert_eq!(summary["barrier"]["overrun_pairs"], 1);
    assert_eq!(summary["barrier"]["pairs"][0]["i"], 1);
    assert_eq!(summary["barrier"]["pairs"][0]["j"], 2);
    assert_eq!(summary["barrier"]["beta_source"], "model.calibrate");
}

#[test]
fn bench_stability_writes_tables_and_refuses_to_overwrite() {
    let dir = temp_dir("stability-bench");
    let args = ["bench", "stability", "--quick", "--only", "d1", "--out", "res"];
    let out = rubblepile(&dir, &args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let csv = std::fs::read_to_string(dir.join("res/stability.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some(
            "case,description,steps,rejections,rhs_evaluations,wall_seconds,energy_error,max_quat_norm_error,min_step,verdict,note"
        )
    );
    let row = lines.next().unwrap();
    assert!(row.starts_with("d1-theta0-exact,"), "{row}");
    assert!(row.contains(",pass,"), "{row}");
    let md = std::fs::read_to_string(dir.join("res/stability.md")).unwrap();
    assert!(md.contains("| d1-theta0-exact |"), "{md}");
    assert!(dir.join("res/runs/d1-theta0-exact/summary.json").exists());
    // again without --force: refused, nothing touched
    let again = rubblepile(&dir, &args);
    assert_eq!(again.status.code(), Some(2));
    let err = String::from_utf8_lossy(&again.stderr);
    assert!(
        err.starts_with("error: --out: res already holds stability results; use --force"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(dir.join("res/stability.csv")).unwrap(), csv);
    // with --force: rewritten
    let mut forced = args.to_vec();
    forced.push("--force");
    assert!(rubblepile(&dir, &forced).status.success());
    // an unknown case is a usage error
    let none = rubblepile(&dir, &["bench", "stability", "--only", "zz", "--out", "other"]);
    assert_eq!(none.status.code(), Some(2));
}
