//! A finished (or stopped) run's snapshots, read back through its engine: the views that `rubblepile export` writes
//! in other formats and `rubblepile render` draws. The engine is rebuilt from the run's `scene.toml` copy, so walls
//! and contact networks are recomputed for each snapshot's state and time exactly as during the run.

use std::path::{Path, PathBuf};
use std::time::Instant;

use super::formats::Formats;
use super::scene_kind::SceneKind;
use crate::ellipsoid::run::EllipsoidEngine;
use crate::engine::{Engine, EngineError, SnapshotView};
use crate::granular::hard::run::HardEngine;
use crate::granular::soft::run::SoftEngine;
use crate::io::checkpoint::CHECKPOINT_FILE;

/// Why a run's snapshots could not be read or exported. One line each, naming the file.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The directory holds no run (no `scene.toml`).
    #[error("{}: not a run directory (no scene.toml)", .0.display())]
    NotARun(PathBuf),
    /// The run has no snapshots.
    #[error("{}: no snapshots (snapshots/<k>.csv)", .0.display())]
    NoSnapshots(PathBuf),
    /// The run's scene or a snapshot cannot be read.
    #[error("{}: {source}", .dir.display())]
    Engine {
        /// The run directory.
        dir: PathBuf,
        /// What is wrong.
        source: EngineError,
    },
    /// The output exists already (and `--force` was not given).
    #[error("{}: exists already (give --force to overwrite it)", .0.display())]
    Exists(PathBuf),
    /// A file could not be read or written (or a symbolic link stands where one is written).
    #[error("{}", crate::io::safe_write::describe(.path, .source))]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// Another rubblepile process writes the directory ([`crate::io::run_lock`]).
    #[error(transparent)]
    Locked(#[from] crate::io::run_lock::LockError),
    /// A caller's step failed (e.g. an analysis file could not be read).
    #[error("{0}")]
    Other(String),
}

/// The snapshot files of the run in `dir`, `(k, path)` sorted by `k`.
pub fn snapshot_files(dir: &Path) -> Result<Vec<(usize, PathBuf)>, ExportError> {
    let snap_dir = dir.join("snapshots");
    let entries = std::fs::read_dir(&snap_dir).map_err(|_| ExportError::NoSnapshots(dir.to_path_buf()))?;
    let mut out: Vec<(usize, PathBuf)> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "csv"))
        .filter_map(|p| Some((p.file_stem()?.to_str()?.parse().ok()?, p)))
        .collect();
    out.sort();
    if out.is_empty() {
        return Err(ExportError::NoSnapshots(dir.to_path_buf()));
    }
    Ok(out)
}

/// Calls `visit(k, view)` for every snapshot of the run in `dir`, in order of `k`.
pub fn visit_snapshots(
    dir: &Path,
    visit: &mut dyn FnMut(usize, SnapshotView) -> Result<(), ExportError>,
) -> Result<(), ExportError> {
    let scene_path = dir.join("scene.toml");
    let text =
        crate::io::scene_file::read_text_bounded(&scene_path).map_err(|_| ExportError::NotARun(dir.to_path_buf()))?;
    let files = snapshot_files(dir)?;
    let base = scene_base_dir(dir);
    let name = scene_path.display().to_string();
    let engine_err = |source| ExportError::Engine {
        dir: dir.to_path_buf(),
        source,
    };
    fn each<E: Engine>(
        (text, name, base): (&str, &str, &Path),
        files: &[(usize, PathBuf)],
        visit: &mut dyn FnMut(usize, SnapshotView) -> Result<(), ExportError>,
        engine_err: &dyn Fn(EngineError) -> ExportError,
    ) -> Result<(), ExportError> {
        let engine = E::from_scene_text(text, name, Some(base)).map_err(engine_err)?;
        // A long run's snapshots take a while to read and draw: a bar on a terminal, nothing otherwise.
        let pb = std::io::IsTerminal::is_terminal(&std::io::stderr()).then(|| {
            let pb = indicatif::ProgressBar::with_draw_target(
                Some(files.len() as u64),
                indicatif::ProgressDrawTarget::stderr(),
            );
            if let Ok(style) =
                indicatif::ProgressStyle::with_template("[{elapsed_precise}] {wide_bar} {pos}/{len} snapshots")
            {
                pb.set_style(style);
            }
            pb
        });
        for (k, path) in files {
            // A damaged file (its manifest's checksum, a row cut short, a non-finite number) is refused by name,
            // never drawn or converted.
            let dir = path.parent().and_then(Path::parent).unwrap_or(Path::new("."));
            crate::io::manifest::verify_file(dir, path, true).map_err(ExportError::Other)?;
            visit(*k, engine.view_of_snapshot(path).map_err(engine_err)?)?;
            if let Some(pb) = &pb {
                pb.inc(1);
            }
        }
        if let Some(pb) = pb {
            pb.finish_and_clear();
        }
        Ok(())
    }
    let scene = (text.as_str(), name.as_str(), base.as_path());
    match SceneKind::of_text(&text) {
        SceneKind::Ellipsoids => each::<EllipsoidEngine>(scene, &files, visit, &engine_err),
        SceneKind::SoftSpheres => each::<SoftEngine>(scene, &files, visit, &engine_err),
        SceneKind::HardSpheres => each::<HardEngine>(scene, &files, visit, &engine_err),
    }
}

/// Where the run's scene resolves its relative files: the directory recorded in its checkpoint, if any, else the
/// run directory (where `rubblepile impact` puts the bodies file).
fn scene_base_dir(dir: &Path) -> PathBuf {
    crate::io::scene_file::read_text_bounded(&dir.join(CHECKPOINT_FILE))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .and_then(|v| v.get("scene_base_dir")?.as_str().map(PathBuf::from))
        .filter(|p| p.is_dir())
        .unwrap_or_else(|| dir.to_path_buf())
}

/// Per-body scalars added to a snapshot's view (name, one value per particle), or why they could not be had.
pub type ExtraFields<'a> = dyn Fn(&SnapshotView) -> Result<Vec<(String, Vec<f64>)>, String> + 'a;

/// Refuses a snapshot with a non-finite value (a damaged or hand-edited file), naming the snapshot, the body and the
/// field, before anything of it is written: the formats would carry the NaN on to ParaView or OVITO.
fn finite_view(dir: &Path, k: usize, view: &SnapshotView) -> Result<(), ExportError> {
    for p in &view.particles {
        let fields = [
            ("mass", p.mass),
            ("x", p.position.x),
            ("y", p.position.y),
            ("z", p.position.z),
            ("vx", p.velocity.x),
            ("vy", p.velocity.y),
            ("vz", p.velocity.z),
            ("wx", p.spin_world.x),
            ("wy", p.spin_world.y),
            ("wz", p.spin_world.z),
            ("a", p.axes.x),
            ("b", p.axes.y),
            ("c", p.axes.z),
        ];
        if let Some((field, value)) = fields.iter().find(|(_, v)| !v.is_finite()) {
            return Err(ExportError::Other(format!(
                "{}: body {}: {field} is {value}, expected a finite number; not exported",
                dir.join("snapshots").join(format!("{k}.csv")).display(),
                p.id
            )));
        }
    }
    Ok(())
}

/// What [`export`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportReport {
    /// Snapshots converted.
    pub snapshots: usize,
    /// Bytes written.
    pub bytes: u64,
    /// Wall-clock time (s).
    pub seconds: f64,
}

/// Writes every snapshot of the run in `dir` in `formats`, with the per-body scalars `extra` gives for each view
/// (e.g. an analysis' `bound`). Refuses to overwrite an existing `dir/<format>` output unless `force`.
///
/// Holds the run directory's lock while it writes ([`crate::io::run_lock`]): a run writes the same VTK and XYZ
/// files, so a run still going is refused at once ([`ExportError::Locked`]), as is a second export.
pub fn export(dir: &Path, formats: Formats, force: bool, extra: &ExtraFields<'_>) -> Result<ExportReport, ExportError> {
    // A directory without a scene copy is no run: refused below without a lock file left in it.
    let _lock = dir
        .join("scene.toml")
        .is_file()
        .then(|| crate::io::run_lock::DirLock::acquire(dir))
        .transpose()?;
    let selected = formats.selected();
    for f in &selected {
        if let Some(first) = f.files(dir).into_iter().next().filter(|_| !force) {
            return Err(ExportError::Exists(first));
        }
    }
    let start = Instant::now();
    let mut written: Vec<(usize, f64)> = Vec::new();
    let mut count = 0;
    visit_snapshots(dir, &mut |k, mut view| {
        finite_view(dir, k, &view)?;
        view.extra = extra(&view).map_err(ExportError::Other)?;
        written.push((k, view.t));
        for f in &selected {
            f.write(dir, k, &view, &written).map_err(|source| ExportError::Io {
                path: dir.join(f.name()),
                source,
            })?;
        }
        count += 1;
        Ok(())
    })?;
    let bytes = selected
        .iter()
        .flat_map(|f| f.files(dir))
        .filter_map(|p| p.metadata().ok())
        .map(|m| m.len())
        .sum();
    Ok(ExportReport {
        snapshots: count,
        bytes,
        seconds: start.elapsed().as_secs_f64(),
    })
}
