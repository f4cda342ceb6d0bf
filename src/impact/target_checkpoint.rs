//! Checkpoints of a target build (Roig03 §3's relaxation of `target.rs`): where a build stands
//! between two rigidity checks, so that a relaxation of hours (N = 2000 fragments) survives a stopped process.
//!
//! The sizes, the placement and κ are redone on resume (they are seeded and take seconds); the checkpoint holds
//! what they cannot give: the round, the bodies the round started from, the state vector, the integrator's
//! step-size and order control, and the running totals. Every float is stored as its bit pattern
//! ([`crate::bits`]), so a resumed build ends with the same bits as one that was never stopped.

use std::path::{Path, PathBuf};

use crate::bits::{exact_f64, exact_f64_vec};
use crate::ellipsoid::body::Body;
use crate::impact::target_spec::{TargetError, TargetSpec};
use crate::integrate::IntegratorState;
use crate::math::{Vec3, Vec4};

/// Path of the checkpoint of an interrupted build beside a target CSV (`NAME.checkpoint.json`).
pub fn checkpoint_path(csv: &Path) -> PathBuf {
    csv.with_extension("checkpoint.json")
}

/// Reads the checkpoint a resumed build continues from; the error is one line naming the file.
pub fn read_checkpoint(path: &Path) -> Result<BuildCheckpoint, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("--resume: cannot read {} ({e}); nothing to resume", path.display()))?;
    serde_json::from_str(&text).map_err(|e| format!("--resume: {} is not a target checkpoint: {e}", path.display()))
}

/// Writes a checkpoint atomically, never through a link ([`crate::io::safe_write`]).
pub fn write_checkpoint(path: &Path, checkpoint: &BuildCheckpoint) -> std::io::Result<()> {
    crate::io::safe_write::write_atomic(path, serde_json::to_string(checkpoint)?)
}

/// The `format` tag of a target-build checkpoint.
pub const TARGET_CHECKPOINT_FORMAT: &str = "rubblepile-target-checkpoint";
/// The layout this build writes and reads.
pub const TARGET_CHECKPOINT_VERSION: u32 = 1;
/// Floats per body in [`BuildCheckpoint::round_start`]: position (3), velocity (3), quaternion (4), body spin (3).
const PER_BODY: usize = 13;

/// Where a relaxation round stands after a rigidity check.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RoundState {
    /// Simulated time since the round began (s).
    #[serde(with = "exact_f64")]
    pub t: f64,
    /// The system's state vector at `t`.
    #[serde(with = "exact_f64_vec")]
    pub y: Vec<f64>,
    /// The integrator's control state at `t`.
    pub integrator: IntegratorState,
    /// Successive rigid checks so far (two end the round).
    pub rigid_checks: usize,
    /// Largest relative energy residual of the round so far.
    #[serde(with = "exact_f64")]
    pub energy_error: f64,
}

/// A target build stopped between two rigidity checks (written as `NAME.checkpoint.json` by the CLI).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BuildCheckpoint {
    /// [`TARGET_CHECKPOINT_FORMAT`].
    pub format: String,
    /// [`TARGET_CHECKPOINT_VERSION`].
    pub version: u32,
    /// The build's inputs; a resume with other inputs is refused.
    pub spec: TargetSpec,
    /// The relaxation round in progress (from 1).
    pub round: usize,
    /// The bodies' kinematics when the round began, [`PER_BODY`] floats each (shapes come from the placement).
    #[serde(with = "exact_f64_vec")]
    pub round_start: Vec<f64>,
    /// Simulated relaxation time of the finished rounds (s).
    #[serde(with = "exact_f64")]
    pub time_before: f64,
    /// Largest energy residual of the finished rounds.
    #[serde(with = "exact_f64")]
    pub energy_error_before: f64,
    /// The round in progress.
    pub state: RoundState,
    /// Each round-start body's index in the placement, when detached fragments were dropped
    /// ([`TargetSpec::drop_detached`]); absent while all N remain.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kept: Option<Vec<usize>>,
}

impl BuildCheckpoint {
    /// A checkpoint of round `round`, which began from `round_start`, the placement's bodies `kept`.
    pub fn new(
        spec: &TargetSpec,
        round: usize,
        round_start: &[Body],
        kept: &[usize],
        time_before: f64,
        energy_error_before: f64,
        state: RoundState,
    ) -> Self {
        let round_start = round_start
            .iter()
            .flat_map(|b| {
                [
                    b.position.as_slice(),
                    b.velocity.as_slice(),
                    b.quaternion.as_slice(),
                    b.spin_body.as_slice(),
                ]
                .concat()
            })
            .collect();
        BuildCheckpoint {
            format: TARGET_CHECKPOINT_FORMAT.into(),
            version: TARGET_CHECKPOINT_VERSION,
            spec: spec.clone(),
            round,
            round_start,
            time_before,
            energy_error_before,
            state,
            kept: (kept.len() < spec.fragments).then(|| kept.to_vec()),
        }
    }

    /// Checks that this checkpoint continues a build of `spec` with `fragments` bodies, naming what differs.
    pub fn check(&self, spec: &TargetSpec) -> Result<(), TargetError> {
        let refuse = |why: String| Err(TargetError::Invalid(format!("checkpoint: {why}")));
        if self.format != TARGET_CHECKPOINT_FORMAT {
            return refuse(format!(
                "format is {:?}, expected {TARGET_CHECKPOINT_FORMAT:?}",
                self.format
            ));
        }
        if self.version != TARGET_CHECKPOINT_VERSION {
            return refuse(format!(
                "layout version {} is not this build's {TARGET_CHECKPOINT_VERSION}; build the target again",
                self.version
            ));
        }
        if self.spec != *spec {
            return refuse(
                "it was written by a build with other inputs (fragments, period, seed, radii, mass or f0); \
                 give the same options or build afresh with --force"
                    .into(),
            );
        }
        let bodies = self.kept.as_ref().map_or(spec.fragments, Vec::len);
        if self.round == 0 || self.round_start.len() != PER_BODY * bodies {
            return refuse(format!(
                "round {} with {} kinematic values; expected a round >= 1 and {} values",
                self.round,
                self.round_start.len(),
                PER_BODY * bodies
            ));
        }
        if let Some(kept) = &self.kept
            && (kept.iter().any(|&i| i >= spec.fragments) || kept.windows(2).any(|w| w[0] >= w[1]))
        {
            return refuse(format!(
                "kept: expected ascending body indices below {}",
                spec.fragments
            ));
        }
        Ok(())
    }

    /// The bodies the round began from: the shapes of `placed`, the kinematics of the checkpoint.
    pub fn round_start_bodies(&self, placed: &[Body]) -> Vec<Body> {
        let all: Vec<usize> = (0..placed.len()).collect();
        self.kept
            .as_ref()
            .unwrap_or(&all)
            .iter()
            .map(|&i| &placed[i])
            .zip(self.round_start.chunks_exact(PER_BODY))
            .map(|(b, k)| Body {
                shape: b.shape,
                position: Vec3::new(k[0], k[1], k[2]),
                velocity: Vec3::new(k[3], k[4], k[5]),
                quaternion: Vec4::new(k[6], k[7], k[8], k[9]),
                spin_body: Vec3::new(k[10], k[11], k[12]),
            })
            .collect()
    }
}
