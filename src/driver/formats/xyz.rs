//! Extended XYZ snapshots (`snapshots/<k>.xyz`), the plain-text particle format OVITO, VMD and ASE read: a line with
//! the particle count, a comment line declaring the columns (`Properties=…`) and the simulated time, then one line per
//! particle: species (`E` ellipsoid, `S` sphere), position (m), velocity (m/s), world-frame spin (rad/s), mass (kg)
//! and the three semi-axes (m; a sphere repeats its radius). Floats are written losslessly ([`crate::io::fmt_f64`]).

use std::io::Write;
use std::path::Path;

use super::format::{SnapshotFormat, files_with_extension};
use crate::engine::SnapshotView;
use crate::io::fmt_f64;

/// The extended XYZ format.
pub struct ExtendedXyz;

impl SnapshotFormat for ExtendedXyz {
    fn name(&self) -> &'static str {
        "xyz"
    }

    fn write(&self, dir: &Path, k: usize, view: &SnapshotView, _written: &[(usize, f64)]) -> std::io::Result<()> {
        let (t, particles) = (view.t, &view.particles);
        let path = dir.join("snapshots").join(format!("{k}.xyz"));
        let mut w = crate::io::safe_write::AtomicFile::create(&path)?;
        writeln!(w, "{}", particles.len())?;
        writeln!(
            w,
            "Properties=species:S:1:pos:R:3:velo:R:3:spin:R:3:mass:R:1:axes:R:3 Time={}",
            fmt_f64(t)
        )?;
        for p in particles.iter() {
            let species = if p.axes.x == p.axes.y && p.axes.y == p.axes.z {
                "S"
            } else {
                "E"
            };
            let numbers: Vec<String> = [p.position, p.velocity, p.spin_world]
                .iter()
                .flat_map(|v| v.iter().copied())
                .chain([p.mass])
                .chain(p.axes.iter().copied())
                .map(fmt_f64)
                .collect();
            writeln!(w, "{species} {}", numbers.join(" "))?;
        }
        w.finish()
    }

    fn files(&self, dir: &Path) -> Vec<std::path::PathBuf> {
        files_with_extension(&dir.join("snapshots"), "xyz")
    }
}
