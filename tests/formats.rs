//! Extra snapshot formats (`--format NAME`, `rubblepile::driver::formats`): the extended XYZ snapshots of an
//! ellipsoid run and of a hard-sphere run hold exactly the positions, velocities and masses of the CSV snapshots, a
//! world-frame spin equal to the body-frame spin rotated by the body's attitude, and the time of the snapshot.

mod common;
use common::{rubblepile, temp_dir};
use rubblepile::ellipsoid::quaternion::rotation_matrix;
use rubblepile::math::{Vec3, Vec4};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn csv_rows(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(str::to_string).collect();
    let rows = lines
        .map(|l| l.split(',').map(|x| x.parse::<f64>().unwrap()).collect())
        .collect();
    (header, rows)
}

/// `(species, numbers)` per particle line and the `Time=` of an XYZ file.
fn xyz(path: &Path) -> (f64, Vec<(String, Vec<f64>)>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let n: usize = lines.next().unwrap().trim().parse().unwrap();
    let comment = lines.next().unwrap();
    assert!(comment.starts_with("Properties=species:S:1:pos:R:3:velo:R:3:spin:R:3:mass:R:1:axes:R:3"));
    let t: f64 = comment.split("Time=").nth(1).unwrap().trim().parse().unwrap();
    let rows: Vec<(String, Vec<f64>)> = lines
        .map(|l| {
            let mut w = l.split_whitespace();
            let s = w.next().unwrap().to_string();
            (s, w.map(|x| x.parse().unwrap()).collect())
        })
        .collect();
    assert_eq!(rows.len(), n);
    (t, rows)
}

#[test]
fn xyz_snapshots_match_the_csv_snapshots_of_an_ellipsoid_run() {
    let dir = temp_dir("format-xyz");
    let o = rubblepile(
        &root(),
        &[
            "run",
            "--out",
            dir.join("r").to_str().unwrap(),
            "--no-progress",
            "--format",
            "xyz",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for k in 0..5 {
        let (header, rows) = csv_rows(&dir.join(format!("r/snapshots/{k}.csv")));
        let col = |name: &str| header.iter().position(|h| h == name).unwrap();
        let (t, parts) = xyz(&dir.join(format!("r/snapshots/{k}.xyz")));
        assert_eq!(parts.len(), rows.len());
        assert_eq!(t.to_bits(), rows[0][col("t")].to_bits());
        for (row, (species, x)) in rows.iter().zip(&parts) {
            assert_eq!(species, "E");
            for (j, name) in ["x", "y", "z", "vx", "vy", "vz"].iter().enumerate() {
                assert_eq!(x[j].to_bits(), row[col(name)].to_bits(), "{name}");
            }
            assert_eq!(x[9].to_bits(), row[col("mass")].to_bits());
            for (j, name) in ["a", "b", "c"].iter().enumerate() {
                assert_eq!(x[10 + j].to_bits(), row[col(name)].to_bits(), "{name}");
            }
            let q = Vec4::new(row[col("qa")], row[col("qb")], row[col("qc")], row[col("qd")]);
            let w_body = Vec3::new(row[col("wx")], row[col("wy")], row[col("wz")]);
            // The snapshot's quaternion is unit to the integrator's constraint error: the world spin uses its rotation.
            let w_world = rotation_matrix(&q.normalize()).transpose() * w_body;
            let got = Vec3::new(x[6], x[7], x[8]);
            assert!(
                (got - w_world).norm() <= 1e-15 * w_world.norm().max(1e-300),
                "{got} vs {w_world}"
            );
        }
    }
}

#[test]
fn xyz_snapshots_of_spheres_and_unknown_formats() {
    let dir = temp_dir("format-xyz-hard");
    let scene = root().join("targets/examples/hard_spheres.toml");
    let out = dir.join("h");
    let o = rubblepile(
        &dir,
        &[
            "run",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--format",
            "xyz",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (header, rows) = csv_rows(&out.join("snapshots/2.csv"));
    let (_, parts) = xyz(&out.join("snapshots/2.xyz"));
    let r = header.iter().position(|h| h == "radius").unwrap();
    assert_eq!(parts[0].0, "S");
    assert_eq!(parts[0].1[10], rows[0][r]);
    assert_eq!(parts[0].1[12], rows[0][r]);
    let o = rubblepile(
        &dir,
        &["run", scene.to_str().unwrap(), "--out", "x", "--format", "vtkz"],
    );
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--format") && err.contains("xyz"), "{err}");
    assert!(!dir.join("x").exists(), "nothing written for a bad option");
}
