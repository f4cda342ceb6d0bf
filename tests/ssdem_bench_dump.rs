//! `rubblepile bench ssdem --dump-particles`: the benchmark's starting packing in the snapshot columns
//! (used by `analysis/ssdem_perf/` to set up the same packing in LAMMPS).

mod common;
use common::{rubblepile, temp_dir};

#[test]
fn dump_particles_writes_one_row_per_particle() {
    let dir = temp_dir("ssdem-bench-dump");
    let out = rubblepile(
        &dir,
        &[
            "bench",
            "ssdem",
            "--particles",
            "500",
            "--steps",
            "1",
            "--threads",
            "1",
            "--dump-particles",
            "p.csv",
        ],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(dir.join("p.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next().unwrap(), "t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz");
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse::<f64>().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 500);
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r.len(), 13);
        assert_eq!(r[1], k as f64);
        assert_eq!(r[3], 1.0, "radius");
        let mass = 4.0 / 3.0 * std::f64::consts::PI * 2000.0;
        assert!((r[2] - mass).abs() < 1e-9 * mass, "mass {}", r[2]);
    }

    // An unwritable path: one-line error naming the flag.
    let bad = rubblepile(
        &dir,
        &[
            "bench",
            "ssdem",
            "--particles",
            "20",
            "--steps",
            "1",
            "--threads",
            "1",
            "--dump-particles",
            "no/such/dir/p.csv",
        ],
    );
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(err.contains("--dump-particles"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
}
