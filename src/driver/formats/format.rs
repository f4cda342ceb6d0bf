//! What a snapshot format is ([`SnapshotFormat`]: its name, how it writes a snapshot, which files it wrote) and the
//! listing of a format's files ([`files_with_extension`]). Below `formats/mod.rs`, which registers the formats and
//! re-exports these, so that each format's file implements the trait without naming the registry.

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
