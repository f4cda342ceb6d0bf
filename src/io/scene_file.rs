//! The scene-file floor shared by every engine's scene parser: reading a scene file, TOML parsing into any schema
//! with one-line errors that name the file, line and field ([`parse_toml_as`]), the [`SceneError`] type, the
//! field checks of [`Validator`], and the physical constants and limits every engine's scene uses
//! (defined in `io::limits`, re-exported here).
//!
//! The limits are one rule per engine-neutral concept, so the three engines agree and every input is bounded,
//! finite and named: a positive size is at least [`MIN_MEANINGFUL`]; a time step or cadence at least
//! `t_end ×` [`MIN_STEP_FRACTION`]; counts stay below [`MAX_TIMESERIES_ROWS`], [`MAX_SNAPSHOTS`], [`MAX_BODIES`],
//! [`MAX_EVENTS_PER_STEP`] and [`MAX_THREADS`]; input files are read through [`BoundedReader`] ([`MAX_INPUT_BYTES`],
//! [`MAX_LINE_BYTES`]); fixed-length arrays are read by [`exact`]; and a scene whose estimated work exceeds
//! [`WORK_WARNING_STEPS`] is accepted with a warning.

use std::path::{Path, PathBuf};

pub use super::limits::{
    MAX_BODIES, MAX_EVENTS_PER_STEP, MAX_INPUT_BYTES, MAX_LINE_BYTES, MAX_SNAPSHOTS, MAX_THREADS, MAX_TIMESERIES_ROWS,
    MIN_MEANINGFUL, MIN_RTOL, MIN_STEP_FRACTION, SI_G, WORK_WARNING_STEPS,
};

/// Parses a thread count of the command line: a whole number in `1..=`[`MAX_THREADS`]. Zero is refused rather than
/// passed on: rayon reads a pool of 0 threads as "all cores", which is not what was written.
pub fn thread_count(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if (1..=MAX_THREADS).contains(&n) => Ok(n),
        _ => Err(format!(
            "must be a whole number of threads in 1..={MAX_THREADS}, got {s:?}"
        )),
    }
}

/// A bad scene. Display is always one line: `<file>: <field>: <what was expected>, got <value>`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// The scene file (or its bodies file) could not be read.
    #[error("{file}: cannot read: {reason}")]
    Read {
        /// The file as named by the user.
        file: String,
        /// The OS error.
        reason: String,
    },
    /// Malformed TOML, an unknown or missing key, or a value of the wrong type.
    #[error("{file}: {message}")]
    Syntax {
        /// The scene file.
        file: String,
        /// One-line description with the location.
        message: String,
    },
    /// A value out of its allowed range.
    #[error("{file}: {field}: {message}")]
    Invalid {
        /// The scene file.
        file: String,
        /// Dotted path of the field, e.g. `body[3].axes` or `integrator.rtol`.
        field: String,
        /// What was expected and what was given.
        message: String,
    },
    /// `model.calibrate` has no solution (the message starts with `model.calibrate:`).
    #[error("{file}: {message}")]
    Calibration {
        /// The scene file.
        file: String,
        /// Why (one line, starting with `model.calibrate:`).
        message: String,
    },
}

impl SceneError {
    /// The field the error is about, where there is one (e.g. `body[3].axes`).
    pub fn field(&self) -> Option<&str> {
        match self {
            SceneError::Invalid { field, .. } => Some(field),
            SceneError::Calibration { .. } => Some("model.calibrate"),
            _ => None,
        }
    }
}

pub(crate) fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Formats a number for a message: plainly in `[1e-4, 1e16)` (and 0), in scientific notation otherwise, so that
/// `1e308` is not printed as 309 digits.
pub fn fmt_num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e16).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Formats a list of numbers as `[1, 2, 3]` ([`fmt_num`] each).
pub(crate) fn fmt_list(v: &[f64]) -> String {
    let parts: Vec<String> = v.iter().map(|&x| fmt_num(x)).collect();
    format!("[{}]", parts.join(", "))
}

/// A scene value (an engine's scene-file struct) as the text of a scene file: each of `comments` on a `# ` line, then
/// the value in TOML, which parses back to the same value. Panics only for a value TOML cannot hold (an integer
/// above `i64::MAX`), which the scenes' checks refuse first.
pub fn scene_text<T: serde::Serialize>(comments: &[&str], scene: &T) -> String {
    let body = toml::to_string(scene).expect("a checked scene value is TOML");
    comments.iter().map(|c| format!("# {c}\n")).collect::<String>() + &body
}

/// A scene file as every engine's loader needs it: its name for messages (the path as given), its text, and the
/// directory relative paths in it are resolved against (`.` for a bare file name).
pub struct SceneText {
    /// The path as given.
    pub name: String,
    /// The file's contents.
    pub text: String,
    /// The file's directory.
    pub base_dir: PathBuf,
}

/// Refuses particles whose kinetic energy, momentum or angular momentum is not finite at t = 0 (finite inputs can
/// overflow: a speed of 1e300 m/s gives an infinite energy), naming the particle and the field.
pub(crate) fn check_finite_motion(
    particles: impl Iterator<Item = (f64, f64, crate::math::Vec3, crate::math::Vec3, crate::math::Vec3)>,
) -> Result<(), (String, String)> {
    for (k, (mass, radius, x, v, w)) in particles.enumerate() {
        if !(0.5 * mass * v.norm_squared()).is_finite() || !(mass * x.norm() * v.norm()).is_finite() {
            return Err((
                format!("particle[{k}].velocity"),
                format!(
                    "gives a non-finite kinetic energy or momentum at t = 0 (mass {mass:e} kg, |v| = {:e} m/s)",
                    v.norm()
                ),
            ));
        }
        if !(0.2 * mass * radius * radius * w.norm_squared()).is_finite() {
            return Err((
                format!("particle[{k}].spin"),
                "gives a non-finite rotational energy at t = 0".to_string(),
            ));
        }
    }
    Ok(())
}

/// A reader that refuses input larger than [`MAX_INPUT_BYTES`] or with a line longer than [`MAX_LINE_BYTES`], with
/// an [`std::io::ErrorKind::InvalidData`] error of one line (without the file name, which every caller adds).
pub struct BoundedReader<R> {
    inner: R,
    /// Bytes read so far.
    total: u64,
    /// Bytes of the current line so far.
    line: usize,
    /// 1-based number of the current line.
    line_no: u64,
}

impl<R: std::io::Read> BoundedReader<R> {
    /// Wraps `inner`.
    pub fn new(inner: R) -> Self {
        BoundedReader {
            inner,
            total: 0,
            line: 0,
            line_no: 1,
        }
    }
}

/// An [`std::io::ErrorKind::InvalidData`] error with this one-line message.
fn invalid_data(message: String) -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::InvalidData, message)
}

impl<R: std::io::Read> std::io::Read for BoundedReader<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.total += n as u64;
        if self.total > MAX_INPUT_BYTES {
            return Err(invalid_data(format!(
                "larger than {} bytes (MAX_INPUT_BYTES, the largest input file read)",
                MAX_INPUT_BYTES
            )));
        }
        let chunk = &buf[..n];
        match chunk.iter().rposition(|&b| b == b'\n') {
            Some(last) => {
                // The longest line ending in this chunk, and the line still open at its end.
                let mut start = 0;
                for (k, &b) in chunk.iter().enumerate() {
                    if b == b'\n' {
                        let len = if start == 0 { self.line + k } else { k - start };
                        if len > MAX_LINE_BYTES {
                            return Err(self.long_line());
                        }
                        self.line_no += 1;
                        start = k + 1;
                    }
                }
                self.line = n - last - 1;
            }
            None => self.line += n,
        }
        if self.line > MAX_LINE_BYTES {
            return Err(self.long_line());
        }
        Ok(n)
    }
}

impl<R> BoundedReader<R> {
    fn long_line(&self) -> std::io::Error {
        invalid_data(format!(
            "line {} is longer than {} bytes (MAX_LINE_BYTES): not a text file",
            self.line_no, MAX_LINE_BYTES
        ))
    }
}

/// Opens `path` for reading through a [`BoundedReader`]; a regular file larger than [`MAX_INPUT_BYTES`] is refused
/// before reading anything.
pub fn open_bounded(path: &Path) -> std::io::Result<BoundedReader<std::io::BufReader<std::fs::File>>> {
    let file = std::fs::File::open(path)?;
    let meta = file.metadata()?;
    if meta.is_dir() {
        return Err(std::io::Error::new(std::io::ErrorKind::IsADirectory, "is a directory"));
    }
    if meta.is_file() && meta.len() > MAX_INPUT_BYTES {
        return Err(invalid_data(format!(
            "{} bytes, larger than {} (MAX_INPUT_BYTES, the largest input file read)",
            meta.len(),
            MAX_INPUT_BYTES
        )));
    }
    Ok(BoundedReader::new(std::io::BufReader::new(file)))
}

/// Reads the text file at `path` through [`open_bounded`] (errors without the file name: the caller names it).
pub fn read_text_bounded(path: &Path) -> std::io::Result<String> {
    let mut text = String::new();
    std::io::Read::read_to_string(&mut open_bounded(path)?, &mut text)?;
    Ok(text)
}

/// Which factor of a product that overflows is to blame: the one of largest magnitude (its field is named). Used where
/// a derived quantity (e.g. the potential energy `m |g| |x|`) is a product of fields.
pub(crate) fn largest_factor<'a>(factors: &[(&'a str, f64)]) -> &'a str {
    factors
        .iter()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .map_or("", |f| f.0)
}

/// Reads a scene file (a one-line [`SceneError::Read`] naming it if that fails).
pub fn read_scene_text(path: &Path) -> Result<SceneText, SceneError> {
    let name = path.display().to_string();
    let text = read_text_bounded(path).map_err(|e| SceneError::Read {
        file: name.clone(),
        reason: one_line(&e.to_string()),
    })?;
    let base_dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    Ok(SceneText { name, text, base_dir })
}

/// The scene kinds `rubblepile run` knows.
pub const SCENE_KINDS: [&str; 3] = ["ellipsoids", "soft-spheres", "hard-spheres"];

/// The `scene.kind` string of a scene text, if it is TOML with one (used to pick the engine before the
/// kind-specific parse).
pub fn peek_kind(text: &str) -> Option<String> {
    let table: toml::Table = text.parse().ok()?;
    table.get("scene")?.get("kind")?.as_str().map(str::to_string)
}

/// Parses TOML into any scene-file model `T` (each engine has its own) with the same one-line messages as
/// `ellipsoid::scene::parse_toml`.
pub fn parse_toml_as<T: serde::de::DeserializeOwned>(text: &str, name: &str) -> Result<T, SceneError> {
    let de = toml::Deserializer::parse(text).map_err(|e| SceneError::Syntax {
        file: name.to_string(),
        message: format!("{}: {}", location(text, e.span()), one_line(e.message())),
    })?;
    serde_path_to_error::deserialize::<_, T>(de).map_err(|e| {
        let segments: Vec<serde_path_to_error::Segment> = e.path().iter().cloned().collect();
        let inner = e.into_inner();
        SceneError::Syntax {
            file: name.to_string(),
            message: describe_toml_error(text, &segments, &inner),
        }
    })
}

/// `line L, column C` of a byte span in `text`.
fn location(text: &str, span: Option<std::ops::Range<usize>>) -> String {
    match span {
        Some(span) => {
            let (line, col) = line_col(text, span.start);
            format!("line {line}, column {col}")
        }
        None => "unknown location".to_string(),
    }
}

fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text.as_bytes()[..offset];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let line_start = before.iter().rposition(|&b| b == b'\n').map(|p| p + 1).unwrap_or(0);
    let col = String::from_utf8_lossy(&before[line_start..]).chars().count() + 1;
    (line, col)
}

fn fmt_path(segments: &[serde_path_to_error::Segment]) -> String {
    use serde_path_to_error::Segment;
    let mut s = String::new();
    for seg in segments {
        let key = match seg {
            Segment::Seq { index } => {
                s.push_str(&format!("[{index}]"));
                continue;
            }
            Segment::Map { key } | Segment::Enum { variant: key } => key.as_str(),
            Segment::Unknown => "?",
        };
        if !s.is_empty() {
            s.push('.');
        }
        s.push_str(key);
    }
    s
}

/// Where a table lives, for "unknown field `x` in …": `[physics]`, `[physics.gravity]`, `body[2]`,
/// `the top level`.
fn fmt_table(segments: &[serde_path_to_error::Segment]) -> String {
    if segments.is_empty() {
        return "the top level".to_string();
    }
    let p = fmt_path(segments);
    if p.contains('[') { p } else { format!("[{p}]") }
}

fn describe_toml_error(text: &str, segments: &[serde_path_to_error::Segment], e: &toml::de::Error) -> String {
    let msg = one_line(e.message());
    let line = match e.span() {
        Some(span) => format!(" (line {})", line_col(text, span.start).0),
        None => String::new(),
    };
    if let Some(rest) = msg.strip_prefix("unknown field `") {
        // The path ends with the unknown key itself; name the table that holds it.
        if let Some(end) = rest.find('`') {
            let key = &rest[..end];
            let expected = rest[end + 1..].trim_start_matches(',').trim();
            let parent = match segments.last() {
                Some(serde_path_to_error::Segment::Map { key: k }) if k == key => &segments[..segments.len() - 1],
                _ => segments,
            };
            let expected = if expected.is_empty() {
                String::new()
            } else {
                format!("; {expected}")
            };
            return format!("unknown field `{key}` in {}{expected}{line}", fmt_table(parent));
        }
    }
    if let Some(rest) = msg.strip_prefix("missing field `")
        && let Some(end) = rest.find('`')
    {
        let key = &rest[..end];
        let full = if segments.is_empty() {
            key.to_string()
        } else {
            format!("{}.{key}", fmt_path(segments))
        };
        return format!("{full}: missing (required in {}){line}", fmt_table(segments));
    }
    if segments.is_empty() {
        format!("{msg}{line}")
    } else {
        format!("{}: {msg}{line}", fmt_path(segments))
    }
}

/// Field checks shared by the scene parsers of every engine: each error names the file, the dotted field and the
/// expected value on one line.
pub(crate) struct Validator<'a> {
    /// How the file is named in messages.
    pub(crate) file: &'a str,
}

impl Validator<'_> {
    pub(crate) fn invalid(&self, field: impl Into<String>, message: impl Into<String>) -> SceneError {
        SceneError::Invalid {
            file: self.file.to_string(),
            field: field.into(),
            message: one_line(&message.into()),
        }
    }

    /// A positive physical size: finite, > 0 and at least [`MIN_MEANINGFUL`].
    pub(crate) fn positive(&self, field: &str, x: f64) -> Result<f64, SceneError> {
        if x.is_finite() && x >= MIN_MEANINGFUL {
            Ok(x)
        } else if x > 0.0 && x < MIN_MEANINGFUL {
            Err(self.invalid(
                field,
                format!("is below the smallest meaningful value ({MIN_MEANINGFUL:e}), got {x:e}"),
            ))
        } else {
            Err(self.invalid(field, format!("must be > 0 and finite, got {}", fmt_num(x))))
        }
    }

    /// A time step or output cadence (s) of a run of length `t_end`: positive ([`Validator::positive`]) and at least
    /// `t_end ×` [`MIN_STEP_FRACTION`] (at most 1e12 steps or samples).
    pub(crate) fn step(&self, field: &str, x: f64, t_end: f64) -> Result<f64, SceneError> {
        let x = self.positive(field, x)?;
        let least = t_end * MIN_STEP_FRACTION;
        if x < least {
            return Err(self.invalid(
                field,
                format!(
                    "must be at least t_end x {MIN_STEP_FRACTION:e} = {least:e} s (at most 1e12 steps for t_end = {t_end} s), got {x:e}"
                ),
            ));
        }
        Ok(x)
    }

    /// The time-series cadence `every` (s) of a run of length `t_end`: positive and giving at most
    /// [`MAX_TIMESERIES_ROWS`] rows (so at least `t_end / 1e8`, stricter than a [`Validator::step`]'s `t_end × 1e-12`).
    pub(crate) fn cadence(&self, field: &str, every: f64, t_end: f64) -> Result<f64, SceneError> {
        let every = self.positive(field, every)?;
        if t_end / every > MAX_TIMESERIES_ROWS {
            return Err(self.invalid(
                field,
                format!(
                    "too small for t_end = {t_end}: would write {:e} rows (at most {MAX_TIMESERIES_ROWS:e}), got {every}",
                    t_end / every
                ),
            ));
        }
        Ok(every)
    }

    /// A count (snapshots, bodies, …) of at most `max`: `what` names what is counted.
    pub(crate) fn count(&self, field: &str, n: usize, max: usize, what: &str) -> Result<usize, SceneError> {
        if n > max {
            return Err(self.invalid(field, format!("at most {max} {what}, got {n}")));
        }
        Ok(n)
    }

    /// The snapshot times `times` (s): at most [`MAX_SNAPSHOTS`], each finite in `[0, t_end]`, strictly increasing.
    pub(crate) fn snapshot_times(&self, times: &[f64], t_end: f64) -> Result<(), SceneError> {
        self.count(
            "output.times",
            times.len(),
            MAX_SNAPSHOTS,
            "snapshot times (MAX_SNAPSHOTS)",
        )?;
        for (k, &t) in times.iter().enumerate() {
            if !(t.is_finite() && (0.0..=t_end).contains(&t)) {
                return Err(self.invalid(
                    format!("output.times[{k}]"),
                    format!("must be in [0, t_end = {t_end}], got {t}"),
                ));
            }
            if k > 0 && t <= times[k - 1] {
                return Err(self.invalid(
                    "output.times",
                    format!("must be strictly increasing, got {} then {t}", times[k - 1]),
                ));
            }
        }
        Ok(())
    }

    /// The snapshot times of an `[output]` table: the list `times` (checked by [`Validator::snapshot_times`]) or the
    /// cadence `snapshot_every` (s, positive, giving at most [`MAX_SNAPSHOTS`] times: `0, every, 2·every, …` and
    /// `t_end`, by [`crate::io::output_times::cadence_times`]); at most one of the two. Neither: `[0, t_end]`.
    pub(crate) fn output_times(
        &self,
        times: Option<&[f64]>,
        snapshot_every: Option<f64>,
        t_end: f64,
    ) -> Result<Vec<f64>, SceneError> {
        use crate::io::output_times::{cadence_count, cadence_times};
        match (times, snapshot_every) {
            (Some(_), Some(every)) => Err(self.invalid(
                "output.snapshot_every",
                format!(
                    "give either `times` (the list of snapshot times) or `snapshot_every` (their cadence), not both; \
                     got snapshot_every = {} beside times",
                    fmt_num(every)
                ),
            )),
            (Some(times), None) => {
                self.snapshot_times(times, t_end)?;
                Ok(times.to_vec())
            }
            (None, Some(every)) => {
                let every = self.positive("output.snapshot_every", every)?;
                let n = cadence_count(t_end, every);
                if n > MAX_SNAPSHOTS as f64 {
                    return Err(self.invalid(
                        "output.snapshot_every",
                        format!(
                            "too small for t_end = {t_end}: would write {n:e} snapshots (at most {MAX_SNAPSHOTS}, \
                             MAX_SNAPSHOTS), got {every:e}"
                        ),
                    ));
                }
                Ok(cadence_times(t_end, every))
            }
            (None, None) => Ok(vec![0.0, t_end]),
        }
    }

    /// A size that may be zero (a ring's radius, an amplitude): 0, or a [`Validator::positive`] size.
    pub(crate) fn size_or_zero(&self, field: &str, x: f64) -> Result<f64, SceneError> {
        if x == 0.0 {
            Ok(0.0)
        } else if x.is_finite() && x > 0.0 {
            self.positive(field, x)
        } else {
            Err(self.invalid(field, format!("must be >= 0 and finite, got {x}")))
        }
    }

    pub(crate) fn non_negative(&self, field: &str, x: f64) -> Result<f64, SceneError> {
        if x.is_finite() && x >= 0.0 {
            Ok(x)
        } else {
            Err(self.invalid(field, format!("must be >= 0 and finite, got {}", fmt_num(x))))
        }
    }

    pub(crate) fn finite_vec(&self, field: &str, v: &[f64]) -> Result<(), SceneError> {
        if v.iter().all(|x| x.is_finite()) {
            Ok(())
        } else {
            Err(self.invalid(field, format!("non-finite value, got {}", fmt_list(v))))
        }
    }
}

/// Fixed-length number arrays of the scene files, read strictly: `#[serde(deserialize_with = "exact::array")]` on a
/// `[f64; N]` field (`exact::option` on an `Option<[f64; N]>`) refuses an array of another length naming the
/// field and the length expected. (TOML's reader fills a `[f64; 3]` from the first three numbers of a longer array
/// and drops the rest, so four semi-axes would be read as three.)
pub mod exact {
    use serde::de::{Deserialize, Deserializer, Error};

    /// A `[f64; N]` from an array of exactly `N` numbers.
    pub fn array<'de, D: Deserializer<'de>, const N: usize>(d: D) -> Result<[f64; N], D::Error> {
        let v = Vec::<f64>::deserialize(d)?;
        let len = v.len();
        v.try_into()
            .map_err(|_| D::Error::invalid_length(len, &format!("an array of {N} numbers").as_str()))
    }

    /// An `Option<[f64; N]>` from an array of exactly `N` numbers (absent: `None`, with `#[serde(default)]`).
    pub fn option<'de, D: Deserializer<'de>, const N: usize>(d: D) -> Result<Option<[f64; N]>, D::Error> {
        array(d).map(Some)
    }
}
