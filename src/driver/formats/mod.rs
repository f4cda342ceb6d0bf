//! Extra snapshot formats beside each engine's own CSV snapshots, written at every snapshot time of any engine.
//!
//! A format is one file implementing [`SnapshotFormat`] plus one line in [`registered`]; the command line
//! offers it as `--format NAME` (and a scene may ask for it, e.g. `[output] vtk = true`); the driver calls it for
//! every snapshot with the engine's [`SnapshotView`], so the formats know no engine. `rubblepile export` calls the
//! same code on a finished run's snapshots ([`crate::driver::export`]).

pub mod vtk;
pub mod xyz;

use std::path::Path;

use crate::engine::SnapshotView;

/// An output format for snapshots.
pub trait SnapshotFormat: Send + Sync {
    /// The name users select it by (`--format NAME`).
    fn name(&self) -> &'static str;
    /// Writes the k-th snapshot into the run directory `dir`. `written` lists every snapshot of the run so far as
    /// `(k, t)` (this one last), for formats that keep an index of the whole run.
    fn write(&self, dir: &Path, k: usize, view: &SnapshotView, written: &[(usize, f64)]) -> std::io::Result<()>;
    /// The files this format has written into the run directory `dir` (none: the format was not written there).
    fn files(&self, dir: &Path) -> Vec<std::path::PathBuf>;
}

/// Every format, in the order of [`Formats`]' bits. Adding a format: one new file and one line here.
pub fn registered() -> Vec<Box<dyn SnapshotFormat>> {
    vec![Box::new(xyz::ExtendedXyz), Box::new(vtk::Vtk)]
}

/// The files in `dir` whose names end in `.ext` (none if `dir` cannot be read).
pub fn files_with_extension(dir: &Path, ext: &str) -> Vec<std::path::PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut out: Vec<_> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    out.sort();
    out
}

/// A format name that is not [`registered`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("--format: unknown format {name:?}; known: {}", .known.join(", "))]
pub struct UnknownFormat {
    /// The name given.
    pub name: String,
    /// The registered names.
    pub known: Vec<&'static str>,
}

/// A set of [`registered`] formats (bit `i` = the i-th format), small and `Copy` so that it rides in
/// [`super::RunOptions`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Formats(u32);

impl Formats {
    /// No extra format.
    pub const NONE: Formats = Formats(0);

    /// The formats named in `names`; an unknown name is an error listing the known ones.
    pub fn parse(names: &[String]) -> Result<Formats, UnknownFormat> {
        let all = registered();
        let mut bits = 0u32;
        for name in names {
            let Some(i) = all.iter().position(|f| f.name() == name) else {
                return Err(UnknownFormat {
                    name: name.clone(),
                    known: all.iter().map(|f| f.name()).collect(),
                });
            };
            bits |= 1 << i;
        }
        Ok(Formats(bits))
    }

    /// These formats and those named in `names` (names known to be registered, e.g. from
    /// [`crate::engine::Engine::scene_vtk`]).
    pub fn with(self, names: &[&str]) -> Formats {
        let all = registered();
        let bits = names
            .iter()
            .filter_map(|n| all.iter().position(|f| f.name() == *n))
            .fold(self.0, |b, i| b | (1 << i));
        Formats(bits)
    }

    /// The selected formats.
    pub fn selected(self) -> Vec<Box<dyn SnapshotFormat>> {
        registered()
            .into_iter()
            .enumerate()
            .filter(|(i, _)| self.0 & (1 << i) != 0)
            .map(|(_, f)| f)
            .collect()
    }
}
