//! The one place where an engine is chosen: from one read of a scene's `scene.kind` (or of a run directory's
//! `scene.toml` copy). `run`, `resume` and `check` of the command line go through here.

use crate::named::Named;
use std::path::Path;

use super::runner::{RunError, RunOptions};
pub use super::scene_kind::SceneKind;
use crate::ellipsoid::run::EllipsoidEngine;
use crate::engine::RunReport;
use crate::granular::hard::run::HardEngine;
use crate::granular::soft::run::SoftEngine;
use crate::io::messages::{Channel, emit};

/// The text of `rubblepile check --explain [KIND]`: the field reference of one kind's scene file, or of all three
/// (`None`), one after the other.
pub fn explain(kind: Option<SceneKind>) -> String {
    let kinds: Vec<SceneKind> = kind.map_or(SceneKind::ALL.to_vec(), |k| vec![k]);
    kinds
        .iter()
        .map(|k| crate::io::scene_fields::explain_text(k.reference()))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Any engine's summary as the command line reports it: its one line and its warnings.
#[derive(Debug, Clone, serde::Serialize)]
pub struct AnyReport {
    /// [`RunReport::one_line`] of the engine's summary.
    pub line: String,
    /// [`RunReport::warnings`] of the engine's summary.
    pub warnings: Vec<String>,
}

impl AnyReport {
    fn of<S: RunReport>(s: &S) -> Self {
        AnyReport {
            line: s.one_line(),
            warnings: s.warnings(),
        }
    }
}

type AnyResult = Result<AnyReport, RunError<AnyReport>>;

fn erase<S: RunReport>(r: Result<S, RunError<S>>) -> AnyResult {
    r.map(|s| AnyReport::of(&s))
        .map_err(|e| e.map_summary(|s| AnyReport::of(&s)))
}

/// Loads the scene at `path` (the built-in default scene when `None`) and runs it into `out` with the engine its
/// `scene.kind` names. Scene errors come back as [`RunError::Setup`] (one line naming the field). Scene warnings are
/// printed to stderr as `warning: …` before the run starts. The built-in scene's run also gets its
/// `impact.json` (the impact setup [`crate::ellipsoid::scene::DEFAULT_IMPACT_JSON`]), as `rubblepile impact` writes.
pub fn run_file(path: Option<&Path>, out: &Path, options: &RunOptions) -> AnyResult {
    let kind = path.map_or(SceneKind::Ellipsoids, SceneKind::of_file);
    match kind {
        SceneKind::Ellipsoids => {
            let engine = match path {
                Some(p) => EllipsoidEngine::load(p),
                None => EllipsoidEngine::default_scene(),
            }
            .map_err(|e| RunError::Setup(e.to_string()))?;
            // The built-in scene's impact.json is written after the run: the directory stays locked until then.
            let _lock = path
                .is_none()
                .then(|| super::runner::lock_output_dir(out, options.force))
                .transpose()?;
            for w in engine.scene_warnings() {
                emit(Channel::Warning, &format!("warning: {w}"));
            }
            let result = erase(super::runner::run(engine, out, options));
            if path.is_none() && result.is_ok() {
                // The built-in scene is an impact: its setup lets `rubblepile analyze` read the run.
                let json = out.join("impact.json");
                crate::io::safe_write::write_atomic(&json, crate::ellipsoid::scene::DEFAULT_IMPACT_JSON)
                    .and_then(|()| crate::io::manifest::add_files(out, &["impact.json"]))
                    .map_err(|source| RunError::Io { path: json, source })?;
            }
            result
        }
        SceneKind::SoftSpheres => {
            let engine = SoftEngine::load(path.expect("a soft-sphere scene comes from a file"))
                .map_err(|e| RunError::Setup(e.to_string()))?;
            for w in engine.scene_warnings() {
                emit(Channel::Warning, &format!("warning: {w}"));
            }
            erase(super::runner::run(engine, out, options))
        }
        SceneKind::HardSpheres => {
            let engine = HardEngine::load(path.expect("a hard-sphere scene comes from a file"))
                .map_err(|e| RunError::Setup(e.to_string()))?;
            for w in engine.scene_warnings() {
                emit(Channel::Warning, &format!("warning: {w}"));
            }
            erase(super::runner::run(engine, out, options))
        }
    }
}

/// Continues the run in `dir` from its checkpoint with the engine its `scene.toml` names ([`super::runner::resume`]).
pub fn resume_dir(dir: &Path, options: &RunOptions) -> AnyResult {
    match SceneKind::of_run_dir(dir) {
        SceneKind::Ellipsoids => erase(super::runner::resume::<EllipsoidEngine>(dir, options)),
        SceneKind::SoftSpheres => erase(super::runner::resume::<SoftEngine>(dir, options)),
        SceneKind::HardSpheres => erase(super::runner::resume::<HardEngine>(dir, options)),
    }
}

/// Validates the scene at `path` (the default scene when `None`) and describes what it resolves to: `(warnings,
/// lines)` for the terminal. Errors are one line naming the field.
pub fn check_file(path: Option<&Path>) -> Result<(Vec<String>, Vec<String>), crate::engine::EngineError> {
    match path.map_or(SceneKind::Ellipsoids, SceneKind::of_file) {
        SceneKind::Ellipsoids => match path {
            Some(p) => EllipsoidEngine::load(p),
            None => EllipsoidEngine::default_scene(),
        }
        .map(|e| (e.scene_warnings().to_vec(), e.describe())),
        SceneKind::SoftSpheres => SoftEngine::load(path.expect("a soft-sphere scene comes from a file"))
            .map(|e| (e.scene_warnings().to_vec(), e.describe())),
        SceneKind::HardSpheres => HardEngine::load(path.expect("a hard-sphere scene comes from a file"))
            .map(|e| (e.scene_warnings().to_vec(), e.describe())),
    }
}

/// [`RunReport`] of any engine, for code that runs whichever engine a scene names.
impl RunReport for AnyReport {
    fn one_line(&self) -> String {
        self.line.clone()
    }
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }
}
