//! CSV files of the ellipsoid engine: snapshots (and `last_good_state.csv`), tracks, and bodies files.

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use crate::ellipsoid::body::Body;
use crate::engine::{MOMENTUM_COLUMNS, column_names};
use crate::io::fmt_f64;
use crate::io::scene_file::one_line;

/// Columns of a snapshot (and of a bodies file): time (s), body index, mass (kg), semi-axes A, B, C
/// (m), position (m), velocity (m/s), quaternion `(α, β, γ, δ)` (scalar last), body-frame spin (rad/s).
pub const SNAPSHOT_COLUMNS: [&str; 19] = [
    "t", "id", "mass", "a", "b", "c", "x", "y", "z", "vx", "vy", "vz", "qa", "qb", "qc", "qd", "wx", "wy", "wz",
];

/// Columns of `timeseries.csv`: time (s); energies (J): translational and rotational kinetic, contact and
/// gravitational potential, dissipated `2∫F dt` (≤ 0); the relative energy residual
/// `(H − H0 − dissipated)/energy_scale(0)`; total linear momentum (kg m/s); total angular momentum about the origin
/// (kg m²/s); wall-clock seconds since the run started.
pub const TIMESERIES_COLUMNS: [&str; 14] = column_names(&[
    &[
        "t",
        "kinetic_translational",
        "kinetic_rotational",
        "potential_contact",
        "potential_gravity",
        "dissipated",
        "energy_residual",
    ],
    &MOMENTUM_COLUMNS,
    &["wall_seconds"],
]);

fn csv_to_io(e: ::csv::Error) -> std::io::Error {
    match e.into_kind() {
        ::csv::ErrorKind::Io(e) => e,
        other => std::io::Error::other(format!("{other:?}")),
    }
}

/// The snapshot rows of `bodies` at time `t` (ids are the indices), without the header.
pub fn snapshot_records(t: f64, bodies: &[Body]) -> Vec<Vec<String>> {
    bodies
        .iter()
        .enumerate()
        .map(|(id, b)| {
            let mut row = Vec::with_capacity(SNAPSHOT_COLUMNS.len());
            row.push(fmt_f64(t));
            row.push(id.to_string());
            row.push(fmt_f64(b.shape.mass));
            row.extend(b.shape.axes.iter().map(|&x| fmt_f64(x)));
            row.extend(b.position.iter().map(|&x| fmt_f64(x)));
            row.extend(b.velocity.iter().map(|&x| fmt_f64(x)));
            row.extend(b.quaternion.iter().map(|&x| fmt_f64(x)));
            row.extend(b.spin_body.iter().map(|&x| fmt_f64(x)));
            row
        })
        .collect()
}

/// Writes `tracks.csv` (the snapshot columns, one row per tracked body per time-series sample), flushing after
/// each sample so a crash loses nothing written.
pub struct TracksWriter {
    w: ::csv::Writer<BufWriter<File>>,
}

impl TracksWriter {
    /// Creates the file and writes the header.
    pub fn create(path: &Path) -> std::io::Result<Self> {
        let file = crate::io::safe_write::create_fresh(path)?;
        let mut w = ::csv::Writer::from_writer(BufWriter::new(file));
        w.write_record(SNAPSHOT_COLUMNS).map_err(csv_to_io)?;
        w.flush()?;
        Ok(TracksWriter { w })
    }

    /// Reopens `path` after a checkpoint: keeps the header and the first `rows` complete rows, drops the
    /// rest (rows written after the checkpoint, or a half-written line) and positions for appending.
    /// Errors are one line, naming the file.
    pub fn open_truncated(path: &Path, rows: u64) -> std::io::Result<Self> {
        let data = std::fs::read(path)?;
        let mut newlines = data.iter().enumerate().filter(|&(_, &b)| b == b'\n').map(|(i, _)| i);
        let keep = match newlines.nth(rows as usize) {
            Some(i) => i as u64 + 1,
            None => {
                return Err(std::io::Error::other(format!(
                    "holds fewer than the header and the {rows} rows written before the checkpoint"
                )));
            }
        };
        let mut file = crate::io::safe_write::open_nofollow(path, false)?;
        file.set_len(keep)?;
        std::io::Seek::seek(&mut file, std::io::SeekFrom::End(0))?;
        Ok(TracksWriter {
            w: ::csv::Writer::from_writer(BufWriter::new(file)),
        })
    }

    /// Appends the rows of the tracked bodies `ids` (indices into `bodies`, in that order; scene validation keeps
    /// them in range) at time `t` and flushes them to the OS.
    pub fn write_sample(&mut self, t: f64, bodies: &[Body], ids: &[usize]) -> std::io::Result<()> {
        let rows = snapshot_records(t, bodies);
        for &id in ids {
            self.w.write_record(&rows[id]).map_err(csv_to_io)?;
        }
        self.w.flush()
    }
}

/// Writes a snapshot of `bodies` at time `t` to `path` (header + one row per body), lossless. Not made durable
/// here: the run driver syncs the snapshots a checkpoint counts before writing it, as for the sphere engines.
pub fn write_snapshot(path: &Path, t: f64, bodies: &[Body]) -> std::io::Result<()> {
    let file = crate::io::safe_write::AtomicFile::create(path)?;
    let mut w = ::csv::Writer::from_writer(file);
    w.write_record(SNAPSHOT_COLUMNS).map_err(csv_to_io)?;
    for row in snapshot_records(t, bodies) {
        w.write_record(&row).map_err(csv_to_io)?;
    }
    w.into_inner().map_err(|e| e.into_error())?.finish()
}

/// One body read from a bodies file (values unchecked; the scene validates them).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyRecord {
    /// Line of the file the body came from (1-based; line 1 is the header).
    pub line: u64,
    /// Mass (kg).
    pub mass: f64,
    /// Semi-axes `[A, B, C]` (m).
    pub axes: [f64; 3],
    /// Position (m).
    pub position: [f64; 3],
    /// Velocity (m/s).
    pub velocity: [f64; 3],
    /// Quaternion `[α, β, γ, δ]`.
    pub quaternion: [f64; 4],
    /// Body-frame spin (rad/s).
    pub spin_body: [f64; 3],
}

impl BodyRecord {
    /// The body of this record exactly as written: its quaternion not renormalised (what the run's state held, so
    /// that views and conversions of a snapshot repeat the run's own numbers).
    pub fn to_body_as_written(&self) -> Body {
        Body {
            quaternion: crate::math::Vec4::from(self.quaternion),
            ..self.to_body()
        }
    }

    /// The body of this record, its quaternion normalised (no other check: validate the values first).
    pub fn to_body(&self) -> Body {
        Body {
            shape: crate::ellipsoid::body::Ellipsoid {
                axes: crate::math::Vec3::from(self.axes),
                mass: self.mass,
            },
            position: crate::math::Vec3::from(self.position),
            velocity: crate::math::Vec3::from(self.velocity),
            quaternion: crate::math::Vec4::from(self.quaternion).normalize(),
            spin_body: crate::math::Vec3::from(self.spin_body),
        }
    }
}

/// Why a bodies file could not be read. Messages are one line.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BodiesFileError {
    /// The file could not be opened or read.
    #[error("{0}")]
    Read(String),
    /// A bad header or value.
    #[error("line {line}: {message}")]
    Format {
        /// 1-based line.
        line: u64,
        /// What is wrong.
        message: String,
    },
}

/// Reads a bodies file: a CSV with a header naming the columns `mass,a,b,c,x,y,z,vx,vy,vz,qa,qb,qc,qd,wx,wy,wz`
/// in any order (plus optional `t` and `id`, ignored); any other column is an error.
///
/// A pkdgrav `.ss` file (by its extension) is read too ([`read_ss_bodies`]).
pub fn read_bodies_csv(path: &Path) -> Result<Vec<BodyRecord>, BodiesFileError> {
    if crate::io::ss::is_ss(path) {
        return read_ss_bodies(path).map(|(_, records, _)| records);
    }
    let file = crate::io::scene_file::open_bounded(path).map_err(|e| BodiesFileError::Read(e.to_string()))?;
    read_bodies(file)
}

/// [`read_bodies_csv`] from any reader.
pub fn read_bodies<R: std::io::Read>(reader: R) -> Result<Vec<BodyRecord>, BodiesFileError> {
    let mut r = ::csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(::csv::Trim::All)
        .from_reader(reader);
    let bad_header = |message: String| BodiesFileError::Format { line: 1, message };
    let headers = r
        .headers()
        .map_err(|e| bad_header(format!("bad header: {}", one_line(&e.to_string()))))?
        .clone();
    let required = &SNAPSHOT_COLUMNS[2..];
    let expected = SNAPSHOT_COLUMNS.join(",");
    let mut index = [usize::MAX; 17];
    for (pos, name) in headers.iter().enumerate() {
        if name == "t" || name == "id" {
            continue;
        }
        match required.iter().position(|&c| c == name) {
            Some(k) if index[k] == usize::MAX => index[k] = pos,
            Some(_) => return Err(bad_header(format!("column `{name}` appears twice"))),
            None => return Err(bad_header(format!("unknown column `{name}`; expected {expected}"))),
        }
    }
    if let Some(k) = index.iter().position(|&i| i == usize::MAX) {
        return Err(bad_header(format!(
            "missing column `{}`; expected {expected}",
            required[k]
        )));
    }
    let mut out = Vec::new();
    for rec in r.records() {
        let rec = rec.map_err(|e| BodiesFileError::Format {
            line: e.position().map(|p| p.line()).unwrap_or(0),
            message: one_line(&e.to_string()),
        })?;
        let line = rec.position().map(|p| p.line()).unwrap_or(0);
        if out.len() >= crate::io::scene_file::MAX_BODIES {
            return Err(BodiesFileError::Format {
                line,
                message: format!(
                    "more than {} bodies (MAX_BODIES, the most a scene may hold)",
                    crate::io::scene_file::MAX_BODIES
                ),
            });
        }
        let mut v = [0.0; 17];
        for (k, &pos) in index.iter().enumerate() {
            let s = rec.get(pos).unwrap_or("");
            v[k] = s.parse::<f64>().map_err(|_| BodiesFileError::Format {
                line,
                message: format!("column `{}`: not a number: {s:?}", required[k]),
            })?;
        }
        out.push(BodyRecord {
            line,
            mass: v[0],
            axes: [v[1], v[2], v[3]],
            position: [v[4], v[5], v[6]],
            velocity: [v[7], v[8], v[9]],
            quaternion: [v[10], v[11], v[12], v[13]],
            spin_body: [v[14], v[15], v[16]],
        });
    }
    Ok(out)
}

/// The sidecar of a `.ss` file: `<stem>.bodies.csv` beside it, where `rubblepile convert` keeps the exact
/// ellipsoids it wrote to pkdgrav as spheres.
pub fn ss_sidecar(ss: &Path) -> std::path::PathBuf {
    ss.with_extension("bodies.csv")
}

/// The bodies of a pkdgrav `.ss` file (SI, see [`crate::io::ss`]) and its time (s): spheres as bodies with
/// A = B = C = radius, no rotation and their spin — or, when its sidecar ([`ss_sidecar`]) lists the same masses and
/// positions (to the units conversion's round-off), the sidecar's exact ellipsoids (`true`).
pub fn read_ss_bodies(path: &Path) -> Result<(f64, Vec<BodyRecord>, bool), BodiesFileError> {
    let ss = crate::io::ss::SsFile::read(path).map_err(|e| BodiesFileError::Read(e.to_string()))?;
    if let Ok(side) = read_bodies_csv(&ss_sidecar(path)) {
        let close = |a: f64, b: f64| (a - b).abs() <= 4.0 * f64::EPSILON * a.abs().max(b.abs());
        let same = side.len() == ss.particles.len()
            && side.iter().zip(&ss.particles).all(|(r, p)| {
                close(r.mass, p.mass) && r.position.iter().zip(p.position.iter()).all(|(a, b)| close(*a, *b))
            });
        if same {
            return Ok((ss.time, side, true));
        }
    }
    let records = ss
        .particles
        .iter()
        .enumerate()
        .map(|(k, p)| BodyRecord {
            line: k as u64 + 1,
            mass: p.mass,
            axes: [p.radius; 3],
            position: p.position.into(),
            velocity: p.velocity.into(),
            quaternion: [0.0, 0.0, 0.0, 1.0],
            spin_body: p.spin.into(),
        })
        .collect();
    Ok((ss.time, records, false))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ellipsoid::body::Ellipsoid;
    use crate::math::{Vec3, Vec4};

    #[test]
    fn snapshot_round_trip_is_lossless() {
        let b = Body {
            shape: Ellipsoid {
                axes: Vec3::new(3.1, 2.0 / 3.0, 0.1),
                mass: 1.0 / 7.0,
            },
            position: Vec3::new(-1e-300, 1.0 / 3.0, 12345.678901234567),
            velocity: Vec3::new(-0.0, 2.0f64.sqrt(), 1e10),
            quaternion: Vec4::new(0.1, 0.2, 0.3, 0.9).normalize(),
            spin_body: Vec3::new(1e-5, -3.3, std::f64::consts::PI),
        };
        let mut bytes = Vec::new();
        {
            let mut w = ::csv::Writer::from_writer(&mut bytes);
            w.write_record(SNAPSHOT_COLUMNS).unwrap();
            for row in snapshot_records(1.5, std::slice::from_ref(&b)) {
                w.write_record(&row).unwrap();
            }
        }
        let recs = read_bodies(bytes.as_slice()).unwrap();
        assert_eq!(recs.len(), 1);
        let r = recs[0];
        assert_eq!(r.line, 2);
        assert_eq!(r.mass.to_bits(), b.shape.mass.to_bits());
        for k in 0..3 {
            assert_eq!(r.axes[k].to_bits(), b.shape.axes[k].to_bits());
            assert_eq!(r.position[k].to_bits(), b.position[k].to_bits());
            assert_eq!(r.velocity[k].to_bits(), b.velocity[k].to_bits());
            assert_eq!(r.spin_body[k].to_bits(), b.spin_body[k].to_bits());
        }
        for k in 0..4 {
            assert_eq!(r.quaternion[k].to_bits(), b.quaternion[k].to_bits());
        }
    }

    #[test]
    fn bad_bodies_files() {
        let e = read_bodies("mass,a\n1,2\n".as_bytes()).unwrap_err().to_string();
        assert!(e.contains("missing column `b`"), "{e}");
        let e = read_bodies("mass,a,b,c,x,y,z,vx,vy,vz,qa,qb,qc,qd,wx,wy,wz,zz\n".as_bytes())
            .unwrap_err()
            .to_string();
        assert!(e.contains("unknown column `zz`"), "{e}");
        let e = read_bodies(
            "mass,a,b,c,x,y,z,vx,vy,vz,qa,qb,qc,qd,wx,wy,wz\n1,1,1,1,0,0,0,0,0,0,0,0,0,1,0,0,x\n".as_bytes(),
        )
        .unwrap_err()
        .to_string();
        assert_eq!(e, "line 2: column `wz`: not a number: \"x\"");
        let e = read_bodies("mass,a,b,c,x,y,z,vx,vy,vz,qa,qb,qc,qd,wx,wy,wz\n1,1,1\n".as_bytes())
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("line 2:"), "{e}");
    }
}
