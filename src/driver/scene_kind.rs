//! Which engine a scene is for ([`SceneKind`]), from one read of its `scene.kind`, and the field reference of each
//! kind. Below the choice of engine (`driver::kind`), the run-directory check (`driver::inspect`) and the export,
//! which all read it.

use std::path::Path;

use crate::engine::Engine;
use crate::granular::hard::run::HardEngine;
use crate::granular::soft::run::SoftEngine;

/// The engines a scene file can name in `scene.kind` (on the command line by the same names).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SceneKind {
    /// `kind = "ellipsoids"` (also a scene without `kind`): interacting ellipsoids (Roig03).
    Ellipsoids,
    /// `kind = "soft-spheres"`: soft-sphere DEM (Zhang17).
    SoftSpheres,
    /// `kind = "hard-spheres"`: hard spheres with predicted collisions (Richardson11).
    HardSpheres,
}

impl crate::named::Named for SceneKind {
    /// Every kind, in the order `rubblepile check --explain` prints them.
    const ALL: &'static [SceneKind] = &[SceneKind::Ellipsoids, SceneKind::SoftSpheres, SceneKind::HardSpheres];

    fn name(self) -> &'static str {
        match self {
            SceneKind::Ellipsoids => "ellipsoids",
            SceneKind::SoftSpheres => SoftEngine::KIND,
            SceneKind::HardSpheres => HardEngine::KIND,
        }
    }

    fn help(self) -> &'static str {
        match self {
            SceneKind::Ellipsoids => "interacting ellipsoids (Roig03)",
            SceneKind::SoftSpheres => "soft-sphere DEM (Zhang17)",
            SceneKind::HardSpheres => "hard spheres with predicted collisions (Richardson11)",
        }
    }
}

impl std::fmt::Display for SceneKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(crate::named::Named::name(*self))
    }
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
    /// The field reference of this kind's scene file (every key, its unit, default, range and meaning), collected
    /// once from the rows on its scene structs.
    pub fn reference(self) -> &'static crate::io::scene_fields::SceneReference {
        use crate::io::scene_fields::SceneReference;
        use std::sync::OnceLock;
        static REFERENCES: [OnceLock<SceneReference>; 3] = [OnceLock::new(), OnceLock::new(), OnceLock::new()];
        let kind = crate::named::Named::name(self);
        match self {
            SceneKind::Ellipsoids => {
                REFERENCES[0].get_or_init(|| SceneReference::of::<crate::ellipsoid::scene::SceneFile>(kind))
            }
            SceneKind::SoftSpheres => {
                REFERENCES[1].get_or_init(|| SceneReference::of::<crate::granular::soft::scene::SoftSceneFile>(kind))
            }
            SceneKind::HardSpheres => {
                REFERENCES[2].get_or_init(|| SceneReference::of::<crate::granular::hard::scene::HardSceneFile>(kind))
            }
        }
    }
}
