//! The scene-file floor shared by every engine's scene parser: reading a scene file, TOML parsing into any schema
//! with one-line errors that name the file, line and field ([`parse_toml_as`]), the [`SceneError`] type, the
//! field checks of [`Validator`], and the physical constants and limits every engine's scene uses.

use std::path::{Path, PathBuf};

/// The SI gravitational constant used when a scene gives none (m³ kg⁻¹ s⁻²).
pub const SI_G: f64 = 6.674e-11;

/// Smallest relative tolerance accepted: below it the integrators' error estimates are dominated by round-off
/// (f64 epsilon is 2.2e-16, and a Bulirsch–Stoer estimate sums many such terms).
pub const MIN_RTOL: f64 = 1e-15;

/// Most time-series rows a scene may ask for (`t_end / every`).
pub const MAX_TIMESERIES_ROWS: f64 = 1e8;

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

/// Formats a list of numbers as `[1, 2, 3]`.
pub(crate) fn fmt_list(v: &[f64]) -> String {
    let parts: Vec<String> = v.iter().map(|x| format!("{x}")).collect();
    format!("[{}]", parts.join(", "))
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

/// Reads a scene file (a one-line [`SceneError::Read`] naming it if that fails).
pub fn read_scene_text(path: &Path) -> Result<SceneText, SceneError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| SceneError::Read {
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
        match seg {
            Segment::Seq { index } => s.push_str(&format!("[{index}]")),
            Segment::Map { key } | Segment::Enum { variant: key } => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(key);
            }
            Segment::Unknown => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push('?');
            }
        }
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

    pub(crate) fn positive(&self, field: &str, x: f64) -> Result<f64, SceneError> {
        if x.is_finite() && x > 0.0 {
            Ok(x)
        } else {
            Err(self.invalid(field, format!("must be > 0 and finite, got {x}")))
        }
    }

    pub(crate) fn non_negative(&self, field: &str, x: f64) -> Result<f64, SceneError> {
        if x.is_finite() && x >= 0.0 {
            Ok(x)
        } else {
            Err(self.invalid(field, format!("must be >= 0 and finite, got {x}")))
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
