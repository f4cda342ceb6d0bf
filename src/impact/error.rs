//! Why an impact could not be set up or run ([`ImpactError`], with its exit code), and the reader of an impact's
//! target bodies file ([`read_target`]), whose refusals are the first of those errors. Below both the single
//! impact (`run.rs`) and the rubble-pile projectile (`pile.rs`), which both use them, so that neither imports the
//! other's file for them (Roig03 §3 set-up; the bodies file is `rubblepile target build`'s).

use std::path::{Path, PathBuf};

use crate::driver::{RunError, RunSummary};
use crate::ellipsoid::body::Body;
use crate::ellipsoid::output::read_bodies_csv;
use crate::io::scene_file::SceneError;

/// Why an impact could not be set up or run. Messages are one line.
#[derive(Debug, thiserror::Error)]
pub enum ImpactError {
    /// A configuration value out of range; `field` as in `ImpactConfig` (`run.rs`).
    #[error("{field}: {message}")]
    Invalid {
        /// The field, e.g. `angle_deg`.
        field: String,
        /// What was expected and what was given.
        message: String,
    },
    /// The target bodies file cannot be read or holds bad bodies.
    #[error("{}: {message}", .path.display())]
    Target {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// The generated scene was refused (e.g. too many time-series rows).
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// Writing a file of the run directory failed (or a symbolic link stands where it writes).
    #[error("{}", crate::io::safe_write::describe(.path, .source))]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The run itself (or the preparation of its directory) failed.
    #[error(transparent)]
    Run(#[from] RunError<RunSummary>),
}

impl ImpactError {
    /// An [`ImpactError::Invalid`] naming `field`.
    pub fn invalid(field: &str, message: String) -> Self {
        ImpactError::Invalid {
            field: field.to_string(),
            message,
        }
    }

    /// The command line's exit code: 2 for bad input, 1 for a failed run, 3 for a run stopped on request.
    pub fn exit_code(&self) -> u8 {
        match self {
            ImpactError::Invalid { .. } | ImpactError::Target { .. } | ImpactError::Scene(_) => 2,
            ImpactError::Io { .. } => 1,
            ImpactError::Run(e) => e.exit_code(),
        }
    }
}

/// Reads a target bodies file into bodies (quaternions normalised): at least one body, finite values,
/// mass > 0 and `A >= B >= C > 0`.
pub fn read_target(path: &Path) -> Result<Vec<Body>, ImpactError> {
    let target_error = |message: String| ImpactError::Target {
        path: path.to_path_buf(),
        message,
    };
    let records = read_bodies_csv(path).map_err(|e| target_error(e.to_string()))?;
    if records.is_empty() {
        return Err(target_error("no bodies".into()));
    }
    records
        .iter()
        .map(|r| {
            let ok = r.mass > 0.0 && r.axes[2] > 0.0 && r.axes[0] >= r.axes[1] && r.axes[1] >= r.axes[2];
            let finite = [r.mass]
                .iter()
                .chain(&r.axes)
                .chain(&r.position)
                .chain(&r.velocity)
                .chain(&r.spin_body)
                .chain(&r.quaternion)
                .all(|v| v.is_finite());
            if !(ok && finite) {
                return Err(target_error(format!(
                    "line {}: need finite values, mass > 0 and A >= B >= C > 0",
                    r.line
                )));
            }
            Ok(r.to_body())
        })
        .collect()
}
