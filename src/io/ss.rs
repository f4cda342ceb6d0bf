//! pkdgrav's `.ss` particle files (its `ssio` library), so rubble piles move between pkdgrav and rubblepile.
//!
//! The format is XDR, i.e. big-endian: a 16-byte header — time (f64), number of particles `n_data` (i32), magic
//! number (i32; −1 marks the standard format, the only one read here; files of older pkdgrav versions, whose header
//! had a pad of 0 in its place, are that same standard format and are read too) — then `n_data` records of 96 bytes: mass,
//! radius, position (3), velocity (3), spin (3), all f64, then colour (i32) and original index (i32).
//!
//! pkdgrav works in units with G = 1: length 1 AU, mass 1 solar mass, time 1 yr/2π (so that the Earth's mean
//! motion is 1). Here they are fixed by two IAU constants and our G, so that G = 1 holds exactly in them:
//! [`AU_M`] = 1.495978707e11 m (IAU 2012 B2), [`GM_SUN`] = 1.32712440018e20 m³ s⁻² (IAU 2015 B3 nominal value),
//! mass unit `GM_SUN / G` with G = [`crate::io::scene_file::SI_G`] (1.9885e30 kg), time unit
//! `sqrt(AU³ / GM_SUN)` (5 022 642.9 s; 1 yr/2π to 2e-7). Everything is converted to SI when read and back when
//! written, so the rest of rubblepile only sees SI.

use std::path::Path;

use crate::io::scene_file::SI_G;
use crate::math::Vec3;

/// The astronomical unit (m), pkdgrav's length unit.
pub const AU_M: f64 = 1.495978707e11;
/// The Sun's gravitational parameter (m³ s⁻²), which fixes pkdgrav's mass and time units with G = 1.
pub const GM_SUN: f64 = 1.32712440018e20;
/// The standard format's magic number.
pub const MAGIC_STANDARD: i32 = -1;
/// The header's fourth word in files of older pkdgrav versions: an unused pad, written as 0, before the magic
/// number took its place; their records are the standard format's.
pub const MAGIC_OLD_PAD: i32 = 0;
/// Bytes of the header.
pub const HEADER_BYTES: usize = 16;
/// Bytes of one particle record.
pub const RECORD_BYTES: usize = 96;

/// pkdgrav's units in SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Units {
    /// Length unit (m).
    pub length: f64,
    /// Mass unit (kg).
    pub mass: f64,
    /// Time unit (s).
    pub time: f64,
}

impl Units {
    /// AU, solar mass (with G = [`SI_G`]) and yr/2π: G = 1 in them.
    pub fn pkdgrav() -> Units {
        Units {
            length: AU_M,
            mass: GM_SUN / SI_G,
            time: (AU_M * AU_M * AU_M / GM_SUN).sqrt(),
        }
    }

    /// The velocity unit (m/s).
    pub fn velocity(&self) -> f64 {
        self.length / self.time
    }
}

/// One particle of a `.ss` file, in SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SsParticle {
    /// Mass (kg).
    pub mass: f64,
    /// Radius (m).
    pub radius: f64,
    /// Position (m).
    pub position: Vec3,
    /// Velocity (m/s).
    pub velocity: Vec3,
    /// Spin (rad/s, world frame).
    pub spin: Vec3,
    /// pkdgrav's colour (kept through a round trip; 3 is green in its colour table).
    pub colour: i32,
    /// Original index.
    pub original_index: i32,
}

/// A whole `.ss` file, in SI.
#[derive(Debug, Clone, PartialEq)]
pub struct SsFile {
    /// Time (s).
    pub time: f64,
    /// The particles.
    pub particles: Vec<SsParticle>,
}

/// Why a `.ss` file cannot be read (one line, without the file name, which the caller adds).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SsError {
    /// Read or write failure.
    #[error("{0}")]
    Io(String),
    /// The file is shorter than its header.
    #[error("{0} bytes: shorter than the 16-byte header of a pkdgrav .ss file")]
    Short(usize),
    /// Not the standard format.
    #[error(
        "magic number {0}: expected -1 (pkdgrav's standard .ss format) or 0 (the pad of older pkdgrav versions); reduced formats are not read"
    )]
    Magic(i32),
    /// The length does not match `n_data`.
    #[error("header says {n} particles ({expected} bytes), the file has {actual} bytes")]
    Length {
        /// `n_data`.
        n: i64,
        /// Bytes `n` particles take.
        expected: usize,
        /// Bytes in the file.
        actual: usize,
    },
    /// A value is not finite, or a mass or radius is not positive.
    #[error("particle {index}: {field} is {value} (expected a finite{positive} number)")]
    Value {
        /// 0-based particle.
        index: usize,
        /// The field.
        field: &'static str,
        /// The value in the file.
        value: f64,
        /// `" positive"` where that is required.
        positive: &'static str,
    },
}

/// The values of particle `index`'s record in file order (mass, radius, position, velocity, spin): all finite,
/// mass and radius positive; the error names the particle and the field.
fn check_record(index: usize, values: [f64; 11]) -> Result<(), SsError> {
    const NAMES: [&str; 11] = ["mass", "radius", "x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz"];
    for (k, (value, field)) in values.into_iter().zip(NAMES).enumerate() {
        let positive = k < 2;
        if !value.is_finite() || (positive && value <= 0.0) {
            return Err(SsError::Value {
                index,
                field,
                value,
                positive: if positive { " positive" } else { "" },
            });
        }
    }
    Ok(())
}

fn f64_at(b: &[u8], at: usize) -> f64 {
    f64::from_be_bytes(b[at..at + 8].try_into().expect("8 bytes"))
}

fn i32_at(b: &[u8], at: usize) -> i32 {
    i32::from_be_bytes(b[at..at + 4].try_into().expect("4 bytes"))
}

/// Accepts the header's fourth word of a standard-format file: [`MAGIC_STANDARD`] or an older pkdgrav's pad
/// ([`MAGIC_OLD_PAD`]).
fn standard_format(magic: i32) -> Result<(), SsError> {
    if magic == MAGIC_STANDARD || magic == MAGIC_OLD_PAD {
        Ok(())
    } else {
        Err(SsError::Magic(magic))
    }
}

impl SsFile {
    /// Parses the bytes of a `.ss` file.
    pub fn from_bytes(b: &[u8], units: &Units) -> Result<SsFile, SsError> {
        if b.len() < HEADER_BYTES {
            return Err(SsError::Short(b.len()));
        }
        let time = f64_at(b, 0);
        let n = i32_at(b, 8);
        standard_format(i32_at(b, 12))?;
        let expected = HEADER_BYTES + RECORD_BYTES * n.max(0) as usize;
        if n < 0 || b.len() != expected {
            return Err(SsError::Length {
                n: i64::from(n),
                expected,
                actual: b.len(),
            });
        }
        if !time.is_finite() {
            return Err(SsError::Value {
                index: 0,
                field: "the header's time",
                value: time,
                positive: "",
            });
        }
        let v = units.velocity();
        let spin_unit = 1.0 / units.time;
        let mut particles = Vec::with_capacity(n as usize);
        for index in 0..n as usize {
            let r = &b[HEADER_BYTES + RECORD_BYTES * index..HEADER_BYTES + RECORD_BYTES * (index + 1)];
            let x: [f64; 11] = std::array::from_fn(|k| f64_at(r, 8 * k));
            check_record(index, x)?;
            particles.push(SsParticle {
                mass: x[0] * units.mass,
                radius: x[1] * units.length,
                position: Vec3::new(x[2], x[3], x[4]) * units.length,
                velocity: Vec3::new(x[5], x[6], x[7]) * v,
                spin: Vec3::new(x[8], x[9], x[10]) * spin_unit,
                colour: i32_at(r, 88),
                original_index: i32_at(r, 92),
            });
        }
        Ok(SsFile {
            time: time * units.time,
            particles,
        })
    }

    /// Checks what [`SsFile::from_bytes`] requires of a file, before one is written: a finite time, and for every
    /// particle finite values with a positive mass and radius. The error names the particle and the field.
    pub fn check(&self) -> Result<(), SsError> {
        if !self.time.is_finite() {
            return Err(SsError::Value {
                index: 0,
                field: "the header's time",
                value: self.time,
                positive: "",
            });
        }
        for (index, p) in self.particles.iter().enumerate() {
            let (r, v, w) = (p.position, p.velocity, p.spin);
            check_record(index, [p.mass, p.radius, r.x, r.y, r.z, v.x, v.y, v.z, w.x, w.y, w.z])?;
        }
        Ok(())
    }

    /// The bytes of this file in `units`.
    pub fn to_bytes(&self, units: &Units) -> Vec<u8> {
        let mut out = Vec::with_capacity(HEADER_BYTES + RECORD_BYTES * self.particles.len());
        out.extend_from_slice(&(self.time / units.time).to_be_bytes());
        out.extend_from_slice(&(self.particles.len() as i32).to_be_bytes());
        out.extend_from_slice(&MAGIC_STANDARD.to_be_bytes());
        let v = units.velocity();
        for p in &self.particles {
            let values = [p.mass / units.mass, p.radius / units.length]
                .into_iter()
                .chain(p.position.iter().map(|x| x / units.length))
                .chain(p.velocity.iter().map(|x| x / v))
                .chain(p.spin.iter().map(|x| x * units.time));
            for x in values {
                out.extend_from_slice(&x.to_be_bytes());
            }
            out.extend_from_slice(&p.colour.to_be_bytes());
            out.extend_from_slice(&p.original_index.to_be_bytes());
        }
        out
    }

    /// Reads `path` (pkdgrav units) into SI. The header is read first and only the bytes its particle count
    /// promises (at most [`crate::io::scene_file::MAX_INPUT_BYTES`]) after it, so a device or a runaway file is
    /// refused at once rather than read into memory.
    pub fn read(path: &Path) -> Result<SsFile, SsError> {
        use std::io::Read;
        let io = |e: std::io::Error| SsError::Io(e.to_string());
        let mut file = std::fs::File::open(path).map_err(io)?;
        let meta = file.metadata().map_err(io)?;
        let mut b = Vec::with_capacity(HEADER_BYTES);
        (&mut file).take(HEADER_BYTES as u64).read_to_end(&mut b).map_err(io)?;
        if b.len() < HEADER_BYTES {
            return Err(SsError::Short(b.len()));
        }
        let n = i32_at(&b, 8);
        standard_format(i32_at(&b, 12))?;
        let expected = HEADER_BYTES as u64 + RECORD_BYTES as u64 * u64::from(n.max(0).unsigned_abs());
        let actual = |read: usize| if meta.is_file() { meta.len() as usize } else { read };
        if n < 0 || expected > crate::io::scene_file::MAX_INPUT_BYTES {
            return Err(SsError::Length {
                n: i64::from(n),
                expected: expected as usize,
                actual: actual(b.len()),
            });
        }
        // One byte more than promised tells a longer file from an exact one.
        (&mut file)
            .take(expected - HEADER_BYTES as u64 + 1)
            .read_to_end(&mut b)
            .map_err(io)?;
        if b.len() as u64 != expected {
            return Err(SsError::Length {
                n: i64::from(n),
                expected: expected as usize,
                actual: actual(b.len()),
            });
        }
        SsFile::from_bytes(&b, &Units::pkdgrav())
    }

    /// Writes to `path` in pkdgrav units; refuses (writing nothing) what [`SsFile::check`] refuses, so no file that
    /// pkdgrav or [`SsFile::read`] would choke on is written.
    pub fn write(&self, path: &Path) -> Result<(), SsError> {
        self.check()?;
        crate::io::safe_write::write_atomic(path, self.to_bytes(&Units::pkdgrav()))
            .map_err(|e| SsError::Io(crate::io::safe_write::describe(path, &e)))
    }
}

/// Whether `path` names a `.ss` file (by its extension).
pub fn is_ss(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("ss"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn g_is_one_in_pkdgrav_units() {
        let u = Units::pkdgrav();
        let g = SI_G * u.mass * u.time * u.time / (u.length * u.length * u.length);
        assert!((g - 1.0).abs() < 1e-15, "{g}");
        // yr/2π with the Julian year, to the accuracy of Kepler's third law with the Sun's GM alone.
        assert!((u.time / (365.25 * 86400.0 / std::f64::consts::TAU) - 1.0).abs() < 1e-4);
    }
}
