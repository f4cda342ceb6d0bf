//! The one place where an engine is chosen: from one read of a scene's `scene.kind` (or of a run directory's
//! `scene.toml` copy). `run`, `resume` and `check` of the command line go through here.

use std::path::Path;

use super::{RunError, RunOptions};
use crate::ellipsoid::run::EllipsoidEngine;
use crate::engine::{Engine, RunReport};
use crate::granular::hard::run::HardEngine;
use crate::granular::soft::run::SoftEngine;

/// The engines a scene file can name in `scene.kind` (on the command line by the same names).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SceneKind {
    /// `kind = "ellipsoids"` (also a scene without `kind`): interacting ellipsoids (Roig03).
    Ellipsoids,
    /// `kind = "soft-spheres"`: soft-sphere DEM (Zhang17).
    SoftSpheres,
    /// `kind = "hard-spheres"`: hard spheres with predicted collisions (Richardson11).
    HardSpheres,
}

impl SceneKind {
    /// The kind a scene text names. A text that is not TOML, has no `scene.kind` or names an unknown kind is taken
    /// as an ellipsoid scene, whose parser then reports exactly what is wrong with it.
    pub fn of_text(text: &str) -> SceneKind {
        let kind = text
            .parse::<toml::Table>()
            .ok()
            .and_then(|t| t.get("scene")?.get("kind")?.as_str().map(str::to_string));
        match kind.as_deref() {
            Some(SoftEngine::KIND) => SceneKind::SoftSpheres,
            Some(HardEngine::KIND) => SceneKind::HardSpheres,
            _ => SceneKind::Ellipsoids,
        }
    }

    /// The kind of the scene file at `path` (an unreadable file counts as an ellipsoid scene, whose loader reports
    /// the read error).
    pub fn of_file(path: &Path) -> SceneKind {
        crate::io::scene_file::read_text_bounded(path).map_or(SceneKind::Ellipsoids, |t| SceneKind::of_text(&t))
    }

    /// The kind of the run in `dir` (from its `scene.toml` copy).
    pub fn of_run_dir(dir: &Path) -> SceneKind {
        SceneKind::of_file(&dir.join("scene.toml"))
    }
}

impl SceneKind {
    /// Every kind, in the order `rubblepile check --explain` prints them.
    pub const ALL: [SceneKind; 3] = [SceneKind::Ellipsoids, SceneKind::SoftSpheres, SceneKind::HardSpheres];

    /// The field reference of this kind's scene file (every key, its unit, default, range and meaning).
    pub fn reference(self) -> &'static crate::io::scene_fields::SceneReference {
        match self {
            SceneKind::Ellipsoids => &crate::ellipsoid::scene_fields::REFERENCE,
            SceneKind::SoftSpheres => &crate::granular::soft::scene_fields::REFERENCE,
            SceneKind::HardSpheres => &crate::granular::hard::scene_fields::REFERENCE,
        }
    }
}

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
                .then(|| super::lock_output_dir(out, options.force))
                .transpose()?;
            for w in engine.scene_warnings() {
                eprintln!("warning: {w}");
            }
            let result = erase(super::run(engine, out, options));
            if path.is_none() && result.is_ok() {
                // The built-in scene is an impact: its setup lets `rubblepile analyze` read the run.
                let json = out.join("impact.json");
                std::fs::write(&json, crate::ellipsoid::scene::DEFAULT_IMPACT_JSON)
                    .map_err(|source| RunError::Io { path: json, source })?;
            }
            result
        }
        SceneKind::SoftSpheres => {
            let engine = SoftEngine::load(path.expect("a soft-sphere scene comes from a file"))
                .map_err(|e| RunError::Setup(e.to_string()))?;
            for w in engine.scene_warnings() {
                eprintln!("warning: {w}");
            }
            erase(super::run(engine, out, options))
        }
        SceneKind::HardSpheres => {
            let engine = HardEngine::load(path.expect("a hard-sphere scene comes from a file"))
                .map_err(|e| RunError::Setup(e.to_string()))?;
            for w in engine.scene_warnings() {
                eprintln!("warning: {w}");
            }
            erase(super::run(engine, out, options))
        }
    }
}

/// Continues the run in `dir` from its checkpoint with the engine its `scene.toml` names ([`super::resume`]).
pub fn resume_dir(dir: &Path, options: &RunOptions) -> AnyResult {
    match SceneKind::of_run_dir(dir) {
        SceneKind::Ellipsoids => erase(super::resume::<EllipsoidEngine>(dir, options)),
        SceneKind::SoftSpheres => erase(super::resume::<SoftEngine>(dir, options)),
        SceneKind::HardSpheres => erase(super::resume::<HardEngine>(dir, options)),
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
