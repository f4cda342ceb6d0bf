//! The one reader of particle CSV files (a header of column names, then one particle a row) over the `csv` crate,
//! shared by the sphere engines' `particles_file` and the analyses of their snapshots: the caller names the columns
//! it needs (in the order it wants the numbers) and those it may use; other columns are ignored. Errors name the
//! line and the column.

use std::path::Path;

use crate::math::Vec3;

/// A sphere's state in the particles-file column order `mass,radius,x,y,z,vx,vy,vz,wx,wy,wz` (kg, m, m/s, rad/s).
pub fn sphere_state(mass: f64, radius: f64, position: &Vec3, velocity: &Vec3, spin: &Vec3) -> [f64; 11] {
    [
        mass, radius, position.x, position.y, position.z, velocity.x, velocity.y, velocity.z, spin.x, spin.y, spin.z,
    ]
}

/// Why a particles file could not be read (one line, without the file name, which the caller adds).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParticlesFileError {
    /// The file cannot be opened, or its header or a row is not CSV.
    #[error("{0}")]
    Read(String),
    /// A required column is missing.
    #[error("missing column `{column}` (need {})", .required.join(","))]
    MissingColumn {
        /// The column.
        column: &'static str,
        /// Every required column.
        required: Vec<&'static str>,
    },
    /// A cell is not what its column holds.
    #[error("line {line}: column `{column}`: expected {expected}, got {value:?}")]
    Cell {
        /// 1-based line.
        line: usize,
        /// The column.
        column: &'static str,
        /// What the column holds.
        expected: &'static str,
        /// The cell.
        value: String,
    },
}

/// One row: the required columns' numbers in the order asked for, and the optional columns' cells (trimmed; `None`
/// where the file has no such column).
#[derive(Debug, Clone, PartialEq)]
pub struct ParticleRecord {
    /// 1-based line in the file.
    pub line: usize,
    /// The required columns, in the order asked for.
    pub values: Vec<f64>,
    /// The optional columns, in the order asked for.
    pub optional: Vec<Option<String>>,
}

/// Reads the particles file at `path`: every `required` column must be present and hold numbers; `optional` columns
/// are returned as text for the caller to interpret.
pub fn read_particles(
    path: &Path,
    required: &[&'static str],
    optional: &[&'static str],
) -> Result<Vec<ParticleRecord>, ParticlesFileError> {
    use ParticlesFileError as E;
    if crate::io::ss::is_ss(path) {
        return read_ss_particles(path, required, optional);
    }
    let file = crate::io::scene_file::open_bounded(path).map_err(|e| E::Read(format!("cannot read: {e}")))?;
    let mut reader = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(file);
    let headers = reader
        .headers()
        .map_err(|e| E::Read(format!("bad header: {e}")))?
        .clone();
    let mut idx = Vec::with_capacity(required.len());
    for &column in required {
        idx.push(
            headers
                .iter()
                .position(|h| h == column)
                .ok_or_else(|| E::MissingColumn {
                    column,
                    required: required.to_vec(),
                })?,
        );
    }
    let opt_idx: Vec<Option<usize>> = optional.iter().map(|c| headers.iter().position(|h| h == *c)).collect();
    let mut rows = Vec::new();
    for (k, record) in reader.records().enumerate() {
        let line = k + 2;
        let record = record.map_err(|e| E::Read(format!("line {line}: {e}")))?;
        if rows.len() >= crate::io::scene_file::MAX_BODIES {
            return Err(E::Read(format!(
                "line {line}: more than {} particles (MAX_BODIES, the most a scene may hold)",
                crate::io::scene_file::MAX_BODIES
            )));
        }
        let mut values = Vec::with_capacity(required.len());
        for (&i, &column) in idx.iter().zip(required) {
            let cell = record.get(i).unwrap_or("");
            values.push(cell.parse().map_err(|_| E::Cell {
                line,
                column,
                expected: "a number",
                value: cell.to_string(),
            })?);
        }
        let optional = opt_idx
            .iter()
            .map(|i| i.and_then(|i| record.get(i)).map(str::to_string))
            .collect();
        rows.push(ParticleRecord { line, values, optional });
    }
    Ok(rows)
}

/// A pkdgrav `.ss` file read as a particles file with the columns `t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz` (SI;
/// see [`crate::io::ss`]); `line` is the 1-based particle number.
fn read_ss_particles(
    path: &Path,
    required: &[&'static str],
    optional: &[&'static str],
) -> Result<Vec<ParticleRecord>, ParticlesFileError> {
    const COLUMNS: [&str; 13] = [
        "t", "id", "mass", "radius", "x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz",
    ];
    let ss = crate::io::ss::SsFile::read(path).map_err(|e| ParticlesFileError::Read(e.to_string()))?;
    let find = |c: &str| COLUMNS.iter().position(|k| *k == c);
    let idx: Vec<usize> = required
        .iter()
        .map(|&column| {
            find(column).ok_or_else(|| ParticlesFileError::MissingColumn {
                column,
                required: required.to_vec(),
            })
        })
        .collect::<Result<_, _>>()?;
    Ok(ss
        .particles
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let mut row = vec![ss.time, k as f64];
            row.extend(sphere_state(p.mass, p.radius, &p.position, &p.velocity, &p.spin));
            ParticleRecord {
                line: k + 1,
                values: idx.iter().map(|&i| row[i]).collect(),
                optional: optional
                    .iter()
                    .map(|c| find(c).map(|i| crate::io::fmt_f64(row[i])))
                    .collect(),
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_are_found_by_name_and_errors_name_line_and_column() {
        let dir = std::env::temp_dir().join(format!("rubblepile-particles-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("p.csv");
        std::fs::write(&p, "radius,extra,mass,tag\n0.5,x,2.0,7\n 1e-1 ,y,3,\n").unwrap();
        let rows = read_particles(&p, &["mass", "radius"], &["tag", "none"]).unwrap();
        assert_eq!(rows[0].values, vec![2.0, 0.5]);
        assert_eq!(rows[1].values, vec![3.0, 0.1]);
        assert_eq!(rows[0].optional, vec![Some("7".to_string()), None]);
        assert_eq!(rows[1].optional, vec![Some(String::new()), None]);
        assert_eq!(rows[1].line, 3);
        let e = read_particles(&p, &["mass", "spin"], &[]).unwrap_err().to_string();
        assert_eq!(e, "missing column `spin` (need mass,spin)");
        std::fs::write(&p, "mass\n1\nheavy\n").unwrap();
        let e = read_particles(&p, &["mass"], &[]).unwrap_err().to_string();
        assert_eq!(e, "line 3: column `mass`: expected a number, got \"heavy\"");
    }
}
