//! pkdgrav `.ss` files: a file built here byte by byte from the format (not by our writer) is read correctly;
//! round trips of a rubble-pile target and of a soft-sphere aggregate are exact; bad files get one clear error;
//! scenes take `.ss` files as `bodies_file` and `particles_file`.

mod common;
use common::{rubblepile, temp_dir};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

// pkdgrav's units from the constants the format's documentation names: AU, the Sun's GM and G = 6.674e-11.
const AU: f64 = 1.495978707e11;
const GM: f64 = 1.32712440018e20;
const G: f64 = 6.674e-11;

fn time_unit() -> f64 {
    (AU * AU * AU / GM).sqrt()
}

/// The file of the format's description: big-endian header (time, n, magic −1) and 96-byte records.
fn hand_built(particles: &[[f64; 11]], time: f64, magic: i32) -> Vec<u8> {
    let mut b = Vec::new();
    b.extend_from_slice(&time.to_be_bytes());
    b.extend_from_slice(&(particles.len() as i32).to_be_bytes());
    b.extend_from_slice(&magic.to_be_bytes());
    for (k, p) in particles.iter().enumerate() {
        for x in p {
            b.extend_from_slice(&x.to_be_bytes());
        }
        b.extend_from_slice(&7i32.to_be_bytes()); // colour
        b.extend_from_slice(&(100 + k as i32).to_be_bytes()); // original index
    }
    b
}

fn ulps(a: f64, b: f64) -> u64 {
    (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs()
}

fn csv_rows(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut r = csv::Reader::from_path(path).unwrap();
    let h: Vec<String> = r.headers().unwrap().iter().map(str::to_string).collect();
    let rows = r
        .records()
        .map(|rec| rec.unwrap().iter().map(|c| c.parse().unwrap()).collect())
        .collect();
    (h, rows)
}

#[test]
fn a_hand_built_two_particle_file_is_read_in_si() {
    let dir = temp_dir("ss-hand");
    let p = [
        [1e-12, 1e-9, 1.0, -2.0, 0.5, 0.01, 0.0, -0.02, 3.0, 0.0, -1.0],
        [2e-13, 5e-10, 1.0 + 1e-8, -2.0, 0.5, 0.01, 1e-3, -0.02, 0.0, 0.5, 0.0],
    ];
    std::fs::write(dir.join("two.ss"), hand_built(&p, 0.25, -1)).unwrap();
    let o = rubblepile(&dir, &["convert", "two.ss", "--to", "two.csv", "--spheres"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (h, rows) = csv_rows(&dir.join("two.csv"));
    assert_eq!(
        h,
        [
            "t", "id", "mass", "radius", "x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz"
        ]
    );
    let (m, t) = (GM / G, time_unit());
    let v = AU / t;
    for (row, q) in rows.iter().zip(&p) {
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-14 * b.abs();
        assert!(close(row[0], 0.25 * t));
        assert!(close(row[2], q[0] * m), "mass {} vs {}", row[2], q[0] * m);
        assert!(close(row[3], q[1] * AU));
        for k in 0..3 {
            assert!(close(row[4 + k], q[2 + k] * AU));
            assert!(close(row[7 + k], q[5 + k] * v));
            assert!(close(row[10 + k], q[8 + k] / t));
        }
    }
    // One solar mass at 1 AU moves at 2π AU per year in these units: v = 1 is 29.78 km/s.
    assert!((v - 29_784.69).abs() < 0.1, "{v}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Older pkdgrav wrote a header pad of 0 where the magic number −1 now stands; the records are the same standard
/// format, so a hand-written pad-0 file converts to the very bytes of its magic −1 twin.
#[test]
fn a_file_whose_header_pad_is_zero_is_read_as_the_standard_format() {
    let dir = temp_dir("ss-pad0");
    let p = [
        [1e-12, 1e-9, 1.0, -2.0, 0.5, 0.01, 0.0, -0.02, 3.0, 0.0, -1.0],
        [2e-13, 5e-10, 1.0 + 1e-8, -2.0, 0.5, 0.01, 1e-3, -0.02, 0.0, 0.5, 0.0],
    ];
    let old = hand_built(&p, 0.25, 0);
    assert_eq!(&old[12..16], &[0, 0, 0, 0], "the pad word");
    std::fs::write(dir.join("old.ss"), old).unwrap();
    std::fs::write(dir.join("new.ss"), hand_built(&p, 0.25, -1)).unwrap();
    for stem in ["old", "new"] {
        let o = rubblepile(
            &dir,
            &[
                "convert",
                &format!("{stem}.ss"),
                "--to",
                &format!("{stem}.csv"),
                "--spheres",
            ],
        );
        assert!(o.status.success(), "{stem}: {}", String::from_utf8_lossy(&o.stderr));
    }
    let old_csv = std::fs::read(dir.join("old.csv")).unwrap();
    assert_eq!(old_csv, std::fs::read(dir.join("new.csv")).unwrap());
    let (_, rows) = csv_rows(&dir.join("old.csv"));
    assert_eq!(rows.len(), 2);
    assert!((rows[1][2] - 2e-13 * GM / G).abs() <= 1e-14 * rows[1][2]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_files_get_one_clear_error() {
    let dir = temp_dir("ss-bad");
    let good = hand_built(&[[1e-12, 1e-9, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]], 0.0, -1);
    let mut nan = good.clone();
    nan[16 + 8 * 3..16 + 8 * 4].copy_from_slice(&f64::NAN.to_be_bytes());
    let cases: [(&str, Vec<u8>, &str); 4] = [
        ("short", good[..10].to_vec(), "shorter than the 16-byte header"),
        ("magic", hand_built(&[[1.0; 11]], 0.0, -2), "magic number -2"),
        ("length", good[..good.len() - 8].to_vec(), "header says 1 particles"),
        ("nan", nan, "particle 0: y is NaN"),
    ];
    for (name, bytes, expected) in cases {
        let f = format!("{name}.ss");
        std::fs::write(dir.join(&f), bytes).unwrap();
        let o = rubblepile(&dir, &["convert", &f, "--to", "out.csv"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains(expected) && err.contains(&f), "{name}: {err}");
        assert_eq!(err.lines().count(), 1, "{name}: {err}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_soft_sphere_aggregate_round_trips_within_one_ulp() {
    let dir = temp_dir("ss-spheres");
    let src = root().join("targets/zhang2017/hcp.csv");
    let run = |a: &[&str]| {
        let o = rubblepile(&dir, a);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    run(&["convert", src.to_str().unwrap(), "--to", "agg.ss"]);
    run(&["convert", "agg.ss", "--to", "back.csv", "--spheres"]);
    let (h0, a) = csv_rows(&src);
    let (h1, b) = csv_rows(&dir.join("back.csv"));
    assert_eq!(h0, h1);
    assert_eq!(a.len(), b.len());
    let mut worst = 0;
    for (ra, rb) in a.iter().zip(&b) {
        for (x, y) in ra.iter().zip(rb) {
            worst = worst.max(ulps(*x, *y));
        }
    }
    assert!(worst <= 1, "worst difference {worst} ulp");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_ellipsoid_target_round_trips_exactly_through_its_sidecar_and_as_equal_volume_spheres_without_it() {
    let dir = temp_dir("ss-target");
    let src = root().join("targets/N30_T4.csv");
    let run = |a: &[&str]| {
        let o = rubblepile(&dir, a);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let said = run(&["convert", src.to_str().unwrap(), "--to", "t.ss"]);
    assert!(
        said.contains("volume-equivalent spheres") && said.contains("t.bodies.csv"),
        "{said}"
    );
    run(&["convert", "t.ss", "--to", "back.csv"]);
    // With the sidecar: the same rows, bit for bit (the time column aside: both 0).
    let (h0, a) = csv_rows(&src);
    let (h1, b) = csv_rows(&dir.join("back.csv"));
    assert_eq!((h0, a.len()), (h1, b.len()));
    for (ra, rb) in a.iter().zip(&b) {
        for (x, y) in ra.iter().zip(rb) {
            assert_eq!(x.to_bits(), y.to_bits());
        }
    }
    // Without it: spheres of the same volume and mass, spin rotated to the world frame (|ω| kept).
    std::fs::remove_file(dir.join("t.bodies.csv")).unwrap();
    run(&["convert", "t.ss", "--to", "spheres.csv", "--force"]);
    let (h, s) = csv_rows(&dir.join("spheres.csv"));
    let col = |n: &str| h.iter().position(|x| x == n).unwrap();
    for (ra, rs) in a.iter().zip(&s) {
        let vol = ra[col("a")] * ra[col("b")] * ra[col("c")];
        assert!((rs[col("a")].powi(3) / vol - 1.0).abs() < 1e-14);
        assert_eq!(rs[col("a")], rs[col("c")]);
        assert!(ulps(rs[col("mass")], ra[col("mass")]) <= 1);
        let w = |r: &Vec<f64>| (r[col("wx")].powi(2) + r[col("wy")].powi(2) + r[col("wz")].powi(2)).sqrt();
        assert!((w(rs) - w(ra)).abs() <= 1e-12 * w(ra));
    }
    // A scene takes the .ss file as its bodies_file.
    let scene = r#"
[scene]
kind = "ellipsoids"
t_end = 10.0
seed = 1
bodies_file = "t.ss"
[model]
kappa = 10.0
[physics]
gravity = {}
[integrator]
method = "bulirsch-stoer"
rtol = 1e-9
atol = 1e-9
[output]
every = 5.0
"#;
    std::fs::write(dir.join("scene.toml"), scene).unwrap();
    let out = run(&["run", "scene.toml", "--out", "r", "--no-progress"]);
    assert!(out.contains("done: t = 10 s"), "{out}");
    std::fs::remove_dir_all(&dir).unwrap();
}
