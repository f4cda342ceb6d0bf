//! `rubblepile bench scaling`: every case at every thread count in one invocation, with the columns the report reads
//! (speed-up, efficiency, Karp–Flatt serial fraction, measured serial share), the same result fingerprint on every
//! thread count, the phase split of the engines' hot loops, the plot; bad options refused in one line.

mod common;
use common::{rubblepile, temp_dir};

/// `scaling.csv`'s header, as `rubblepile bench scaling` writes it.
const CSV_HEADER: &str = "case,threads,seconds,work,unit,rate_per_s,speedup,efficiency,karp_flatt,\
serial_seconds,parallel_seconds,measured_serial_fraction,fingerprint";

#[test]
fn bench_scaling_writes_every_case_at_every_thread_count() {
    let dir = temp_dir("bench-scaling");
    let root = env!("CARGO_MANIFEST_DIR");
    let args = [
        "bench",
        "scaling",
        "--cases",
        "rhs-n2000,impact-n200,ssdem-2k,campaign-n30",
        "--threads",
        "1,2",
        "--repeats",
        "2",
        "--n200-t-end-s",
        "150",
        "--ssdem-steps",
        "2",
        "--campaign-runs",
        "3",
        "--campaign-t-end-s",
        "200",
        "--root",
        root,
        "--out",
        "s",
    ];
    let out = rubblepile(&dir, &args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        !String::from_utf8_lossy(&out.stderr).contains("differ between thread counts"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.join("s/scaling.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header.join(","), CSV_HEADER);
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 8, "4 cases × 2 thread counts:\n{csv}");
    for pair in rows.chunks(2) {
        let (one, two) = (&pair[0], &pair[1]);
        assert_eq!(one[col("case")], two[col("case")]);
        assert_eq!((one[col("threads")], two[col("threads")]), ("1", "2"));
        assert_eq!(one[col("speedup")], "1.0000", "{csv}");
        assert_eq!(one[col("karp_flatt")], "", "undefined on one thread");
        assert!(!one[col("fingerprint")].is_empty());
        assert_eq!(
            one[col("fingerprint")],
            two[col("fingerprint")],
            "same result on 1 and 2 threads: {csv}"
        );
        // the Karp–Flatt column is the formula of the speed-up column
        let s: f64 = two[col("speedup")].parse().unwrap();
        let e: f64 = two[col("karp_flatt")].parse().unwrap();
        // (S is printed to 4 decimals: its rounding moves 1/S by up to 0.5e-4/S², which a loaded machine's small S
        // makes larger than the formula's own rounding)
        let tolerance = 2e-3 + 2.0 * 0.5e-4 / (s * s);
        assert!((e - (1.0 / s - 0.5) / 0.5).abs() < tolerance, "{e} against S = {s}");
        let seconds: f64 = two[col("seconds")].parse().unwrap();
        let rate: f64 = two[col("rate_per_s")].parse().unwrap();
        let work: f64 = two[col("work")].parse().unwrap();
        assert!(seconds > 0.0 && (rate * seconds / work - 1.0).abs() < 1e-9, "{csv}");
    }
    // The measured split covers the case's time: serial phases + time outside any phase + parallel phases.
    for r in rows.iter().filter(|r| r[col("case")] != "campaign-n30") {
        let seconds: f64 = r[col("seconds")].parse().unwrap();
        let serial: f64 = r[col("serial_seconds")].parse().unwrap();
        let parallel: f64 = r[col("parallel_seconds")].parse().unwrap();
        let fraction: f64 = r[col("measured_serial_fraction")].parse().unwrap();
        assert!(serial >= 0.0 && parallel >= 0.0, "{csv}");
        assert!(serial + parallel >= seconds * (1.0 - 1e-9), "{csv}");
        assert!((fraction - serial / seconds).abs() < 1e-3 && fraction <= 1.0, "{csv}");
    }
    assert_eq!(
        rows.iter().find(|r| r[col("case")] == "campaign-n30").unwrap()[col("work")],
        "3e0"
    );
    let phases = std::fs::read_to_string(dir.join("s/scaling_phases.csv")).unwrap();
    assert!(phases.starts_with("case,threads,phase,kind,seconds,calls\n"));
    for phase in [
        "rhs-n2000,1,ellipsoid.pair_forces,parallel,",
        "rhs-n2000,1,ellipsoid.gravity,parallel,",
        "rhs-n2000,1,ellipsoid.pair_sum,serial,",
        "rhs-n2000,2,ellipsoid.pair_sum_per_body,parallel,",
    ] {
        assert!(phases.contains(phase), "{phase} missing:\n{phases}");
    }
    for f in ["scaling.svg", "scaling.png"] {
        assert!(std::fs::metadata(dir.join("s").join(f)).unwrap().len() > 1000, "{f}");
    }
    // a second invocation into the same directory is refused without --force
    let again = rubblepile(&dir, &args);
    assert_eq!(again.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&again.stderr).contains("use --force"));
}

#[test]
fn bench_scaling_refuses_unknown_cases_and_bad_times() {
    let dir = temp_dir("bench-scaling-bad");
    for (args, expect) in [
        (vec!["--cases", "rhs-n2"], "--cases: unknown case \"rhs-n2\""),
        (vec!["--window-s", "0"], "--window-s: must be a time > 0 s"),
        (vec!["--threads", "0"], "--threads"),
    ] {
        let mut all = vec!["bench", "scaling", "--out", "s"];
        all.extend(args);
        let out = rubblepile(&dir, &all);
        assert_eq!(out.status.code(), Some(2), "{all:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(expect), "{all:?}: {err}");
        assert_eq!(err.lines().count(), 1, "one line: {err}");
    }
}
