//! `rubblepile bench impact`: whole impact runs timed per F0 and thread count; the same run on 1 and 2 threads
//! gives the same numbers (only the wall time differs); bad flags give one-line errors.

mod common;
use common::{rubblepile, temp_dir};

#[test]
fn bench_impact_rows_are_thread_independent_and_flags_checked() {
    let dir = temp_dir("bench-impact");
    let target = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("targets/N30_T4.csv");
    let target = target.to_str().unwrap();
    let args = [
        "bench",
        "impact",
        "--target",
        target,
        "--projectile",
        "P1",
        "--t-end-s",
        "100",
        "--f0",
        "1e-6,1e-4",
        "--threads",
        "1,2",
        "--out",
        "b",
    ];
    let out = rubblepile(&dir, &args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let csv = std::fs::read_to_string(dir.join("b/bench_impact.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().map(|l| l.split(',').collect()).collect();
    assert_eq!(
        rows[0].join(","),
        "target,projectile,angle_deg,t_end,rtol,f0,threads,median_s,min_s,repeats,steps,rhs_evaluations,energy_error,method"
    );
    assert_eq!(rows.len(), 5, "{csv}");
    // steps, RHS evaluations and energy error do not depend on the thread count; F0 changes them
    for pair in [(1, 2), (3, 4)] {
        assert_eq!(rows[pair.0][10..], rows[pair.1][10..], "{csv}");
    }
    assert_ne!(rows[1][12], rows[3][12], "F0 must matter: {csv}");
    assert!(rows[1][12].parse::<f64>().unwrap() < 1e-8, "energy error: {csv}");
    assert!(dir.join("b/bench_impact.svg").is_file() && dir.join("b/bench_impact.png").is_file());
    assert!(!dir.join("b/runs").exists(), "scratch runs removed");
    // no overwrite without --force; bad F0 names the flag
    let again = rubblepile(&dir, &args);
    assert_eq!(again.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&again.stderr).contains("use --force"));
    let bad = rubblepile(&dir, &["bench", "impact", "--f0=-1", "--out", "c"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--f0: each must be >= 0"));
    let bad = rubblepile(&dir, &["bench", "impact", "--rtol", "1e-6,2", "--out", "c"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--rtol: each must be in (0, 1), got 2"));
    let bad = rubblepile(&dir, &["bench", "impact", "--goal-s", "0", "--out", "c"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--goal-s: must be > 0 s"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bench_impact_times_each_tolerance_and_draws_the_goal_it_is_given() {
    let dir = temp_dir("bench-impact-rtol");
    let target = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("targets/N30_T4.csv");
    let args = [
        "bench",
        "impact",
        "--target",
        target.to_str().unwrap(),
        "--projectile",
        "P1",
        "--t-end-s",
        "100",
        "--rtol",
        "1e-6,1e-4",
        "--threads",
        "1",
        "--goal-s",
        "600",
        "--out",
        "b",
    ];
    let out = rubblepile(&dir, &args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let csv = std::fs::read_to_string(dir.join("b/bench_impact.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 2, "{csv}");
    assert_eq!((rows[0][4], rows[1][4]), ("1e-6", "1e-4"), "{csv}");
    // the looser tolerance takes fewer RHS evaluations and makes a larger energy error
    let (rhs, err) = (
        |r: &Vec<&str>| r[11].parse::<u64>().unwrap(),
        |r: &Vec<&str>| r[12].parse::<f64>().unwrap(),
    );
    assert!(rhs(&rows[1]) < rhs(&rows[0]), "{csv}");
    assert!(err(&rows[1]) > err(&rows[0]), "{csv}");
    let svg = std::fs::read_to_string(dir.join("b/bench_impact.svg")).unwrap();
    assert!(
        svg.contains("goal: 600 s on 2 cores"),
        "the goal line is not labelled with --goal-s"
    );
    assert!(
        svg.contains("rtol 1e-4") && svg.contains("rtol 1e-6") && svg.matches("F0 1e-6, 1 thr").count() == 2,
        "bars not labelled by their configuration"
    );
    assert_eq!(svg.matches("dE/E ").count(), 2, "each bar carries its energy error");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bench_impact_times_each_method_and_names_it_in_the_csv_and_on_the_bars() {
    let dir = temp_dir("bench-impact-method");
    let target = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("targets/N30_T4.csv");
    let target = target.to_str().unwrap();
    let common = [
        "bench",
        "impact",
        "--target",
        target,
        "--projectile",
        "P1",
        "--t-end-s",
        "100",
    ];
    let args = [
        &common[..],
        &["--method", "bulirsch-stoer:1e-6,dop853", "--threads", "1", "--out", "b"],
    ]
    .concat();
    let out = rubblepile(&dir, &args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let csv = std::fs::read_to_string(dir.join("b/bench_impact.csv")).unwrap();
    assert!(csv.lines().next().unwrap().ends_with(",energy_error,method"), "{csv}");
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 2, "{csv}");
    assert_eq!((rows[0][13], rows[1][13]), ("bulirsch-stoer", "dop853"), "{csv}");
    // `METHOD:RTOL` runs at its own tolerance; a bare method without --rtol at the impact's default for it.
    assert_eq!((rows[0][4], rows[1][4]), ("1e-6", "1e-8"), "{csv}");
    // Two different integrators: different step counts, both conserving energy (dissipation booked) to 1e-6.
    assert_ne!(rows[0][10], rows[1][10], "{csv}");
    for r in &rows {
        assert!(r[12].parse::<f64>().unwrap() < 1e-6, "energy error: {csv}");
    }
    let svg = std::fs::read_to_string(dir.join("b/bench_impact.svg")).unwrap();
    assert!(
        svg.contains("BS rtol 1e-6") && svg.contains("dop853 rtol 1e-8"),
        "bars not labelled by their method"
    );
    // --replot draws the same bars again from the CSV, with the goal it is given, and runs nothing.
    let before = std::fs::metadata(dir.join("b/bench_impact.csv"))
        .unwrap()
        .modified()
        .unwrap();
    let replot = rubblepile(&dir, &["bench", "impact", "--replot", "--goal-s", "250", "--out", "b"]);
    assert!(replot.status.success(), "{}", String::from_utf8_lossy(&replot.stderr));
    let again = std::fs::read_to_string(dir.join("b/bench_impact.svg")).unwrap();
    assert!(
        again.contains("goal: 250 s on 2 cores") && again.contains("N30_T4 + P1"),
        "replot title or goal"
    );
    assert!(
        again.contains("BS rtol 1e-6") && again.contains("dop853 rtol 1e-8"),
        "replot labels"
    );
    assert_eq!(
        std::fs::metadata(dir.join("b/bench_impact.csv"))
            .unwrap()
            .modified()
            .unwrap(),
        before
    );
    let missing = rubblepile(&dir, &["bench", "impact", "--replot", "--out", "nothing_here"]);
    assert_eq!(
        missing.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&missing.stderr)
    );
    assert!(String::from_utf8_lossy(&missing.stderr).contains("bench_impact.csv"));
    for (bad_arg, needle) in [
        ("rk4", "each must be bulirsch-stoer, dop853 or dopri5"),
        ("dop853:2", "tolerance after ':' must be in (0, 1), got 2"),
        ("dop853:x", "tolerance after ':' must be a number"),
    ] {
        let bad = rubblepile(&dir, &[&common[..], &["--method", bad_arg, "--out", "c"]].concat());
        assert_eq!(bad.status.code(), Some(2), "--method {bad_arg}");
        let stderr = String::from_utf8_lossy(&bad.stderr);
        assert!(
            stderr.contains("--method") && stderr.contains(needle),
            "--method {bad_arg}: {stderr}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
