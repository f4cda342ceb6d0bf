//! `rubblepile convert`: pkdgrav `.ss` files to and from rubblepile's CSV bodies and particles files.
//!
//! - `.ss` → CSV: spheres become bodies with A = B = C = radius, no rotation and their spin (an ellipsoid bodies
//!   file, usable as `bodies_file`), or, with `spheres`, a particles file for the soft- and hard-sphere engines
//!   (`t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz`). When the `.ss` file has a sidecar `<stem>.bodies.csv` written
//!   by the opposite conversion and its masses and positions agree, the sidecar's ellipsoids come back exactly.
//! - CSV → `.ss`: a particles file maps one to one; an ellipsoid bodies file (or snapshot) is written as spheres
//!   of the same volume, radius (ABC)^(1/3), with their world-frame spin — pkdgrav has no axes or attitudes — and
//!   the exact bodies go to the sidecar `<stem>.bodies.csv`.
//!
//! Units are converted at this edge ([`crate::io::ss::Units`]); pkdgrav colour 3 and the original index = the
//! body's index are written.

use std::path::{Path, PathBuf};

use crate::ellipsoid::body::Body;
use crate::ellipsoid::output::{read_bodies_csv, read_ss_bodies, ss_sidecar, write_snapshot};
use crate::ellipsoid::quaternion::rotation_matrix;
use crate::io::fmt_f64;
use crate::io::ss::{SsFile, SsParticle, is_ss};
use crate::math::{Vec3, Vec4};

/// pkdgrav colour written for every particle (green in its default colour table).
pub const SS_COLOUR: i32 = 3;

/// What [`convert`] did, one line for the user.
#[derive(Debug, Clone, PartialEq)]
pub struct Converted {
    /// Particles or bodies written.
    pub count: usize,
    /// What was lost or kept, one line.
    pub note: String,
}

/// Why a conversion failed (one line naming the file).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}: {reason}", .path.display())]
pub struct ConvertError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong.
    pub reason: String,
}

fn err(path: &Path, reason: impl std::fmt::Display) -> ConvertError {
    ConvertError {
        path: path.to_path_buf(),
        reason: reason.to_string(),
    }
}

fn write_particles(path: &Path, t: f64, ps: &[SsParticle]) -> std::io::Result<()> {
    use std::io::Write;
    let mut w = crate::io::safe_write::AtomicFile::create(path)?;
    writeln!(w, "t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz")?;
    for (id, p) in ps.iter().enumerate() {
        let v: Vec<String> = [p.mass, p.radius]
            .into_iter()
            .chain(p.position.iter().copied())
            .chain(p.velocity.iter().copied())
            .chain(p.spin.iter().copied())
            .map(fmt_f64)
            .collect();
        writeln!(w, "{},{id},{}", fmt_f64(t), v.join(","))?;
    }
    w.finish()
}

/// Converts `input` to `output`, by their extensions (`.ss` ↔ `.csv`); `spheres` picks the particles-file
/// columns for `.ss` → CSV. Refuses to overwrite `output` unless `force`.
pub fn convert(input: &Path, output: &Path, spheres: bool, force: bool) -> Result<Converted, ConvertError> {
    // The output's format is read from its name: a directory or a name without `.csv` or `.ss` is refused first.
    let by_slash = output
        .as_os_str()
        .to_string_lossy()
        .ends_with(['/', std::path::MAIN_SEPARATOR]);
    if output.is_dir() || by_slash {
        return Err(err(
            output,
            "--to: is a directory; give the output file's name, ending in .csv or .ss",
        ));
    }
    let ext_ok = output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv") || e.eq_ignore_ascii_case("ss"));
    if !ext_ok {
        return Err(err(
            output,
            "--to: the output's name must end in .csv or .ss (the format is read from it)",
        ));
    }
    if output.exists() && !force {
        return Err(err(output, "exists already (give --force to overwrite it)"));
    }
    let io = |e: std::io::Error| err(output, crate::io::safe_write::reason(&e));
    match (is_ss(input), is_ss(output)) {
        (true, false) if spheres => {
            let ss = SsFile::read(input).map_err(|e| err(input, e))?;
            let (t, ps) = (ss.time, ss.particles);
            write_particles(output, t, &ps).map_err(io)?;
            Ok(Converted {
                count: ps.len(),
                note: "spheres, one to one (particles-file columns)".into(),
            })
        }
        (true, false) => {
            let (t, records, exact) = read_ss_bodies(input).map_err(|e| err(input, e))?;
            // As read: a sidecar's quaternions are not renormalised, so a round trip is exact.
            let bodies: Vec<Body> = records.iter().map(|r| r.to_body_as_written()).collect();
            write_snapshot(output, t, &bodies).map_err(io)?;
            let note = if exact {
                format!(
                    "ellipsoids restored exactly from the sidecar {}",
                    ss_sidecar(input).display()
                )
            } else {
                "spheres as bodies with A = B = C = radius and no rotation".into()
            };
            Ok(Converted {
                count: bodies.len(),
                note,
            })
        }
        (false, true) => csv_to_ss(input, output),
        _ => Err(err(output, "convert between a .ss file and a .csv file (one of each)")),
    }
}

fn csv_to_ss(input: &Path, output: &Path) -> Result<Converted, ConvertError> {
    let header = csv::Reader::from_path(input)
        .and_then(|mut r| r.headers().cloned())
        .map_err(|e| err(input, e))?;
    let has = |c: &str| header.iter().any(|h| h.trim() == c);
    let time_of = || -> Result<f64, ConvertError> {
        let rows = crate::io::particles::read_particles(input, &[], &["t"]).map_err(|e| err(input, e))?;
        Ok(rows
            .first()
            .and_then(|r| r.optional[0].as_deref()?.parse().ok())
            .unwrap_or(0.0))
    };
    let t = if has("t") { time_of()? } else { 0.0 };
    let (particles, note) = if has("a") {
        let records = read_bodies_csv(input).map_err(|e| err(input, e))?;
        let ellipsoids = records.iter().any(|r| r.axes[0] != r.axes[1] || r.axes[1] != r.axes[2]);
        let ps: Vec<SsParticle> = records
            .iter()
            .enumerate()
            .map(|(id, r)| {
                let q = Vec4::from(r.quaternion);
                let to_world = rotation_matrix(&q.normalize()).transpose();
                SsParticle {
                    mass: r.mass,
                    radius: (r.axes[0] * r.axes[1] * r.axes[2]).cbrt(),
                    position: Vec3::from(r.position),
                    velocity: Vec3::from(r.velocity),
                    spin: to_world * Vec3::from(r.spin_body),
                    colour: SS_COLOUR,
                    original_index: id as i32,
                }
            })
            .collect();
        // Nothing is written (sidecar included) for a file that would hold a non-finite value.
        SsFile {
            time: t,
            particles: ps.clone(),
        }
        .check()
        .map_err(|e| err(input, format!("{e}; nothing written")))?;
        let side = ss_sidecar(output);
        crate::io::safe_write::copy_atomic(input, &side).map_err(|e| err(&side, crate::io::safe_write::reason(&e)))?;
        let note = if ellipsoids {
            format!(
                "ellipsoids written as volume-equivalent spheres with their spin (pkdgrav has no axes or attitudes); \
                 the exact bodies are kept in {}",
                side.display()
            )
        } else {
            format!("spheres, one to one (bodies kept in {})", side.display())
        };
        (ps, note)
    } else {
        const COLS: [&str; 11] = ["mass", "radius", "x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz"];
        let rows = crate::io::particles::read_particles(input, &COLS, &[]).map_err(|e| err(input, e))?;
        let ps = rows
            .iter()
            .enumerate()
            .map(|(id, r)| {
                let v = &r.values;
                SsParticle {
                    mass: v[0],
                    radius: v[1],
                    position: Vec3::new(v[2], v[3], v[4]),
                    velocity: Vec3::new(v[5], v[6], v[7]),
                    spin: Vec3::new(v[8], v[9], v[10]),
                    colour: SS_COLOUR,
                    original_index: id as i32,
                }
            })
            .collect();
        (ps, "spheres, one to one".to_string())
    };
    let count = particles.len();
    let ss = SsFile { time: t, particles };
    ss.check().map_err(|e| err(input, format!("{e}; nothing written")))?;
    ss.write(output).map_err(|e| err(output, e))?;
    Ok(Converted { count, note })
}
