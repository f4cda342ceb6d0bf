//! Extra snapshot formats beside each engine's own CSV snapshots, written at every snapshot time of any engine.
//!
//! A format is one file implementing [`SnapshotFormat`] plus one line in [`registered`]; the command line
//! offers it as `--format NAME` (and a scene may ask for it, e.g. `[output] vtk = true`); the driver calls it for
//! every snapshot with the engine's [`SnapshotView`], so the formats know no engine. `rubblepile export` calls the
//! same code on a finished run's snapshots (`driver::export`).

pub mod format;
pub mod vtk;
pub mod xyz;

pub use format::{SnapshotFormat, files_with_extension};

/// Every format, in the order of [`Formats`]' bits. Adding a format: one new file and one line here.
pub fn registered() -> Vec<Box<dyn SnapshotFormat>> {
    vec![Box::new(xyz::ExtendedXyz), Box::new(vtk::Vtk)]
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
/// the driver's `RunOptions`.
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
