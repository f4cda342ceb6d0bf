//! `checkpoint.json`: everything a run needs to continue exactly where it was (see
//! [`crate::run::resume_run`]).
//!
//! # Format
//!
//! One JSON object ([`Checkpoint`]), pretty-printed. Every `f64` that influences the continuation is
//! stored as its IEEE-754 bit pattern, 16 lower-case hex digits (`"3ff0000000000000"` = 1.0), so it
//! round-trips bit for bit whatever the JSON reader does with decimals, and non-finite values
//! (`smallest_step = ∞` before the first step) survive too. Counters are JSON integers (exact for
//! `u64` in `serde_json`). A few decimal copies (`t_seconds`, `wall_seconds_approx`) are only for
//! people reading the file and are ignored on resume.
//!
//! # Atomicity
//!
//! [`write_checkpoint`] writes `checkpoint.json.tmp`, fsyncs it, renames it over `checkpoint.json`
//! and fsyncs the directory: a reader sees either the previous checkpoint or the new one, never a
//! mix. [`read_checkpoint`] turns a missing, truncated or corrupt file into a one-line error.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::integrate::IntegratorState;
use crate::io::csv::TimeseriesWriter;

/// Name of the checkpoint file in a run directory.
pub const CHECKPOINT_FILE: &str = "checkpoint.json";
/// Name of the temporary file a checkpoint is written to before the rename.
pub const CHECKPOINT_TMP_FILE: &str = "checkpoint.json.tmp";
/// The `format` tag of a checkpoint file.
pub const CHECKPOINT_FORMAT: &str = "rubblepile-checkpoint";
/// The version of the checkpoint layout this build writes and reads.
pub const CHECKPOINT_VERSION: u32 = 1;

/// `f64` as its bit pattern in 16 hex digits, for `#[serde(with = "exact_f64")]`.
pub mod exact_f64 {
    use serde::{Deserialize, Deserializer, Serializer};

    /// The 16-hex-digit bit pattern of `x`.
    pub fn to_hex(x: f64) -> String {
        format!("{:016x}", x.to_bits())
    }

    /// Parses [`to_hex`]'s output (exactly 16 hex digits).
    pub fn from_hex(s: &str) -> Option<f64> {
        if s.len() != 16 || !s.bytes().all(|b| b.is_ascii_hexdigit()) {
            return None;
        }
        u64::from_str_radix(s, 16).ok().map(f64::from_bits)
    }

    pub(crate) fn parse<E: serde::de::Error>(s: &str) -> Result<f64, E> {
        from_hex(s).ok_or_else(|| E::custom(format!("expected an f64 as 16 hex digits of its bits, got {s:?}")))
    }

    /// Serializes `x` as [`to_hex`].
    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&to_hex(*x))
    }

    /// Deserializes [`to_hex`]'s output.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        let s = String::deserialize(d)?;
        parse::<D::Error>(&s)
    }
}

/// `Option<f64>` with [`exact_f64`] (`null` for `None`).
pub mod exact_f64_opt {
    use serde::{Deserialize, Deserializer, Serializer};

    /// Serializes `Some(x)` as [`super::exact_f64::to_hex`], `None` as `null`.
    pub fn serialize<S: Serializer>(x: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
        match x {
            Some(v) => s.serialize_some(&super::exact_f64::to_hex(*v)),
            None => s.serialize_none(),
        }
    }

    /// Deserializes what [`serialize`] writes.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        match Option::<String>::deserialize(d)? {
            Some(s) => super::exact_f64::parse::<D::Error>(&s).map(Some),
            None => Ok(None),
        }
    }
}

/// `Vec<f64>` with [`exact_f64`] (a JSON array of hex strings).
pub mod exact_f64_vec {
    use serde::{Deserialize, Deserializer, Serializer};

    /// Serializes each element as [`super::exact_f64::to_hex`].
    pub fn serialize<S: Serializer>(x: &[f64], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(x.iter().map(|&v| super::exact_f64::to_hex(v)))
    }

    /// Deserializes what [`serialize`] writes.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
        Vec::<String>::deserialize(d)?
            .iter()
            .map(|s| super::exact_f64::parse::<D::Error>(s))
            .collect()
    }
}

/// `[f64; N]` with [`exact_f64`] (a JSON array of exactly `N` hex strings).
pub mod exact_f64_array {
    use serde::de::Error as _;
    use serde::{Deserialize, Deserializer, Serializer};

    /// Serializes each element as [`super::exact_f64::to_hex`].
    pub fn serialize<S: Serializer, const N: usize>(x: &[f64; N], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(x.iter().map(|&v| super::exact_f64::to_hex(v)))
    }

    /// Deserializes what [`serialize`] writes.
    pub fn deserialize<'de, D: Deserializer<'de>, const N: usize>(d: D) -> Result<[f64; N], D::Error> {
        let v = Vec::<String>::deserialize(d)?;
        if v.len() != N {
            return Err(D::Error::custom(format!("expected {N} numbers, got {}", v.len())));
        }
        let mut out = [0.0; N];
        for (o, s) in out.iter_mut().zip(&v) {
            *o = super::exact_f64::parse::<D::Error>(s)?;
        }
        Ok(out)
    }
}

/// The complete state of a run at an output sample, as stored in `checkpoint.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Checkpoint {
    /// Always [`CHECKPOINT_FORMAT`].
    pub format: String,
    /// Layout version ([`CHECKPOINT_VERSION`]).
    pub version: u32,
    /// The crate version that wrote the file (informative).
    pub writer: String,
    /// Absolute directory of the original scene file, where a relative `scene.bodies_file` of the
    /// run's `scene.toml` copy is resolved on resume; `null` for the built-in default scene.
    pub scene_base_dir: Option<PathBuf>,
    /// FNV-1a 64 hash (hex) of the text of the run's `scene.toml`.
    pub scene_hash: String,
    /// FNV-1a 64 hash (hex) of the scene's initial bodies in snapshot format (lossless), so that a
    /// changed `bodies_file` is detected on resume.
    pub bodies_hash: String,
    /// Number of bodies.
    pub n_bodies: usize,
    /// Simulated time of the checkpoint (s): an output sample time.
    #[serde(with = "exact_f64")]
    pub t: f64,
    /// `t` in decimal, for people (ignored on resume).
    pub t_seconds: f64,
    /// The packed ODE state at `t` (length = the system's dimension).
    #[serde(with = "exact_f64_vec")]
    pub y: Vec<f64>,
    /// The integrator's internal state ([`crate::integrate::Integrator::save_state`]).
    pub integrator: IntegratorState,
    /// The run driver's state.
    pub driver: DriverState,
}

/// The run driver's part of a [`Checkpoint`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DriverState {
    /// Index (0-based) of the next output sample to produce (the samples before it are done).
    pub next_sample: u64,
    /// Data rows of `timeseries.csv` written so far (header not counted).
    pub timeseries_rows: u64,
    /// Length of `timeseries.csv` in bytes after those rows; resume truncates the file to it.
    pub timeseries_bytes: u64,
    /// Wall-clock seconds used by the run so far (all its processes together).
    #[serde(with = "exact_f64")]
    pub wall_seconds: f64,
    /// `wall_seconds` in decimal, for people (ignored on resume).
    pub wall_seconds_approx: f64,
    /// Checkpoints written by the run so far, this one included.
    pub checkpoints: u64,
    /// The conservation-error bookkeeping.
    pub errors: ErrorState,
}

/// The driver's conservation-error bookkeeping: reference values at t = 0 and running maxima.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ErrorState {
    /// Energy `H` at t = 0 (J).
    #[serde(with = "exact_f64")]
    pub h0: f64,
    /// Dissipated energy at t = 0 (J).
    #[serde(with = "exact_f64")]
    pub dissipated0: f64,
    /// Linear momentum at t = 0 (kg m/s).
    #[serde(with = "exact_f64_array")]
    pub p0: [f64; 3],
    /// Angular momentum at t = 0 (kg m²/s).
    #[serde(with = "exact_f64_array")]
    pub l0: [f64; 3],
    /// Energy, momentum and angular-momentum scales at t = 0.
    #[serde(with = "exact_f64_array")]
    pub scales0: [f64; 3],
    /// Largest finite values of those scales over the samples so far.
    #[serde(with = "exact_f64_array")]
    pub scales_max: [f64; 3],
    /// Largest absolute energy residual so far (J).
    #[serde(with = "exact_f64")]
    pub energy: f64,
    /// Largest `|P − P0|` so far.
    #[serde(with = "exact_f64")]
    pub momentum: f64,
    /// Largest `|L − L0|` so far.
    #[serde(with = "exact_f64")]
    pub angular: f64,
    /// Largest `||q| − 1|` so far.
    #[serde(with = "exact_f64")]
    pub quaternion: f64,
    /// Samples taken so far.
    pub samples: u64,
}

/// Why a checkpoint could not be read. Messages are one line.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    /// There is no checkpoint file.
    #[error("{} does not exist", .0.display())]
    Missing(PathBuf),
    /// The file could not be read.
    #[error("{}: {source}", .path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The file is truncated, corrupt or of another format/version.
    #[error("{}: corrupt or incompatible checkpoint: {reason}", .path.display())]
    Corrupt {
        /// The file.
        path: PathBuf,
        /// What is wrong (one line).
        reason: String,
    },
}

/// FNV-1a 64 of `bytes`, as 16 hex digits (a cheap fingerprint, not a cryptographic hash).
pub fn fnv1a_hex(bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("{h:016x}")
}

/// Writes `checkpoint` into `dir/checkpoint.json` atomically (temporary file, fsync, rename,
/// directory fsync). Returns the path written.
pub fn write_checkpoint(dir: &Path, checkpoint: &Checkpoint) -> std::io::Result<PathBuf> {
    let tmp = dir.join(CHECKPOINT_TMP_FILE);
    let dst = dir.join(CHECKPOINT_FILE);
    {
        let mut w = BufWriter::new(File::create(&tmp)?);
        serde_json::to_writer_pretty(&mut w, checkpoint).map_err(std::io::Error::other)?;
        w.write_all(b"\n")?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
    }
    std::fs::rename(&tmp, &dst)?;
    // Make the rename durable; not every platform can open a directory, so failures are ignored.
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(dst)
}

/// Reads and checks `dir/checkpoint.json` (format tag and version).
pub fn read_checkpoint(dir: &Path) -> Result<Checkpoint, CheckpointError> {
    let path = dir.join(CHECKPOINT_FILE);
    let text = match std::fs::read_to_string(&path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Err(CheckpointError::Missing(path)),
        Err(e) if e.kind() == std::io::ErrorKind::InvalidData => {
            return Err(CheckpointError::Corrupt {
                path,
                reason: "not UTF-8 text".into(),
            });
        }
        Err(source) => return Err(CheckpointError::Read { path, source }),
    };
    let corrupt = |reason: String| CheckpointError::Corrupt {
        path: path.clone(),
        reason: reason.split_whitespace().collect::<Vec<_>>().join(" "),
    };
    let de = &mut serde_json::Deserializer::from_str(&text);
    let c: Checkpoint = serde_path_to_error::deserialize(de).map_err(|e| {
        let at = e.path().to_string();
        let inner = e.into_inner();
        if at.is_empty() || at == "." {
            corrupt(inner.to_string())
        } else {
            corrupt(format!("{at}: {inner}"))
        }
    })?;
    if c.format != CHECKPOINT_FORMAT {
        return Err(corrupt(format!(
            "format is {:?}, expected {CHECKPOINT_FORMAT:?}",
            c.format
        )));
    }
    if c.version != CHECKPOINT_VERSION {
        return Err(corrupt(format!(
            "version {} (this build reads version {CHECKPOINT_VERSION})",
            c.version
        )));
    }
    if !c.t.is_finite() || !c.y.iter().all(|v| v.is_finite()) {
        return Err(corrupt("non-finite time or state".into()));
    }
    Ok(c)
}

/// Reopens `timeseries.csv` when a run resumes (rows are then written by
/// [`crate::io::csv::TimeseriesWriter`], so the format cannot drift).
pub struct TimeseriesAppender;

impl TimeseriesAppender {
    /// Opens `path`, checks that it holds at least `bytes` bytes whose first `rows + 1` lines are the
    /// header and `rows` complete rows, truncates it to `bytes` (dropping rows written after the
    /// checkpoint) and positions for appending. Errors are one line.
    pub fn open_truncated(path: &Path, rows: u64, bytes: u64) -> Result<TimeseriesWriter, String> {
        let io = |e: std::io::Error| format!("{}: {e}", path.display());
        let data = std::fs::read(path).map_err(io)?;
        if (data.len() as u64) < bytes {
            return Err(format!(
                "{} holds {} bytes, fewer than the {bytes} written before the checkpoint",
                path.display(),
                data.len()
            ));
        }
        let kept = &data[..bytes as usize];
        let lines = kept.iter().filter(|&&b| b == b'\n').count() as u64;
        if lines != rows + 1 || kept.last().is_some_and(|&b| b != b'\n') {
            return Err(format!(
                "{}: its first {bytes} bytes are not the header and the {rows} rows written before the checkpoint",
                path.display()
            ));
        }
        let mut file = std::fs::OpenOptions::new().write(true).open(path).map_err(io)?;
        file.set_len(bytes).map_err(io)?;
        std::io::Seek::seek(&mut file, std::io::SeekFrom::End(0)).map_err(io)?;
        Ok(TimeseriesWriter::continue_file(file))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ellipsoid::equations::Diagnostics;
    use crate::io::csv::TimeseriesRow;
    use crate::math::Vec3;

    #[test]
    fn hex_round_trips_every_kind_of_f64() {
        for x in [
            0.0,
            -0.0,
            1.0,
            0.1,
            1.0 / 3.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MIN_POSITIVE,
            5e-324,
            f64::MAX,
        ] {
            let s = exact_f64::to_hex(x);
            assert_eq!(exact_f64::from_hex(&s).unwrap().to_bits(), x.to_bits());
        }
        assert!(exact_f64::from_hex(&exact_f64::to_hex(f64::NAN)).unwrap().is_nan());
        assert!(exact_f64::from_hex("3ff").is_none());
        assert!(exact_f64::from_hex("+ff0000000000000").is_none());
    }

    fn row(i: usize) -> TimeseriesRow {
        let x = i as f64;
        TimeseriesRow {
            t: x * 0.1,
            diagnostics: Diagnostics {
                kinetic_translational: 1.0 / (x + 3.0),
                kinetic_rotational: 2e-17 * x,
                potential_contact: -0.0,
                potential_gravity: -1e300 / (x + 1.0),
                dissipated: -x.sqrt(),
                momentum: Vec3::new(x, -x, 1e-300),
                angular_momentum: Vec3::new(0.1 * x, 7.0, f64::MIN_POSITIVE),
                momentum_scale: 1.0,
                angular_momentum_scale: 1.0,
                energy_scale: 1.0,
                quaternion_norm_error: 0.0,
            },
            energy_residual: 1e-12 * x,
            wall_seconds: 0.5 * x,
        }
    }

    #[test]
    fn appender_writes_what_the_timeseries_writer_writes() {
        let dir = std::env::temp_dir().join(format!("rubblepile-ckpt-unit-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let a = dir.join("a.csv");
        let mut w = TimeseriesWriter::create(&a).unwrap();
        for i in 0..6 {
            w.write_row(&row(i)).unwrap();
        }
        w.finish().unwrap();
        let full = std::fs::read(&a).unwrap();

        // Header + 3 rows, plus half a row of garbage that the appender must drop.
        let b = dir.join("b.csv");
        let mut w = TimeseriesWriter::create(&b).unwrap();
        for i in 0..3 {
            w.write_row(&row(i)).unwrap();
        }
        w.finish().unwrap();
        let bytes = std::fs::metadata(&b).unwrap().len();
        let mut f = std::fs::OpenOptions::new().append(true).open(&b).unwrap();
        f.write_all(b"9e0,1e0,2").unwrap();
        drop(f);
        assert!(TimeseriesAppender::open_truncated(&b, 4, bytes).is_err());
        assert!(TimeseriesAppender::open_truncated(&b, 3, bytes + 1000).is_err());
        let mut ap = TimeseriesAppender::open_truncated(&b, 3, bytes).unwrap();
        for i in 3..6 {
            ap.write_row(&row(i)).unwrap();
        }
        ap.finish().unwrap();
        assert_eq!(std::fs::read(&b).unwrap(), full);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
