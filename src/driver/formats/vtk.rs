//! VTK snapshots for ParaView (`vtk/`): per snapshot `k` one PolyData file per part, and the collection
//! `vtk/run.pvd` listing every part of every snapshot with its simulated time, so that ParaView opens the run as one
//! time series (File → Open `run.pvd`). The files are written by [`crate::io::vtk`] (inline binary, `Float64`
//! values bit for bit).
//!
//! Parts:
//! - `particles_<k>.vtp` (part 0): one point per body at its centre (all in one poly-vertex cell) with point data
//!   `id` and `velocity` (m/s), then
//!   - ellipsoids: `mass` (kg), `speed` (m/s), `axes` (A, B, C, m), `spin_world` (rad/s, world frame) and `shape`,
//!     the 3×3 tensor R·diag(A, B, C)
//!     whose columns are the body's principal axes scaled by its semi-axes (R rotates body to world): ParaView's
//!     Tensor Glyph filter with a sphere glyph, *Extract eigenvalues* off and scale factor 1 draws each body as its
//!     true ellipsoid in its true attitude;
//!   - spheres: `radius` (m) and `spin` (rad/s, world frame) — no more, so that a 42 000-sphere snapshot stays
//!     under 5 MB (mass is in the CSV snapshot; ParaView colours by the velocity's magnitude directly);
//!   - any per-body scalars an analysis adds (e.g. `bound`, `ejection_speed` after `rubblepile analyze`).
//! - `contacts_<k>.vtp` (part 1; soft spheres): the contact network, one line cell between the centres of each
//!   touching pair, with cell data `normal_force` (N): ParaView's Tube filter coloured by it shows the force chains.
//! - `wall<i>_<k>.vtp` (the next parts; soft and hard spheres): each wall's surface where its motion has carried it
//!   (planes as finite patches reaching past every particle, disks, cylinders, rings, lines, points, spherical
//!   containers).

use std::path::Path;

use super::format::{SnapshotFormat, files_with_extension};
use crate::engine::SnapshotView;
use crate::io::vtk::{Cells, CollectionEntry, DataArray, PolyData, write_collection};

/// The VTK format.
pub struct Vtk;

/// The collection file in `vtk/`.
pub const COLLECTION_FILE: &str = "run.pvd";

impl SnapshotFormat for Vtk {
    fn name(&self) -> &'static str {
        "vtk"
    }

    fn write(&self, dir: &Path, k: usize, view: &SnapshotView, written: &[(usize, f64)]) -> std::io::Result<()> {
        let vtk_dir = dir.join("vtk");
        crate::io::safe_write::ensure_dir(&vtk_dir)?;
        let parts = pieces(view);
        for (name, piece) in &parts {
            piece.write(&vtk_dir.join(format!("{name}_{k}.vtp")))?;
        }
        let mut entries = Vec::new();
        for &(kk, t) in written {
            for (part, (name, _)) in parts.iter().enumerate() {
                entries.push(CollectionEntry {
                    time: t,
                    part,
                    name: name.clone(),
                    file: format!("{name}_{kk}.vtp"),
                });
            }
        }
        write_collection(&vtk_dir.join(COLLECTION_FILE), &entries)
    }

    fn files(&self, dir: &Path) -> Vec<std::path::PathBuf> {
        let vtk_dir = dir.join("vtk");
        let mut out = files_with_extension(&vtk_dir, "vtp");
        out.extend(files_with_extension(&vtk_dir, "pvd"));
        out
    }
}

/// The parts of one snapshot, named, in part order.
pub fn pieces(view: &SnapshotView) -> Vec<(String, PolyData)> {
    let mut out = vec![("particles".to_string(), particles(view))];
    if let Some(contacts) = &view.contacts {
        let mut lines = Cells::default();
        for c in contacts {
            lines.push(&[c.i, c.j]);
        }
        out.push((
            "contacts".into(),
            PolyData {
                points: view.particles.iter().map(|p| p.position.into()).collect(),
                lines,
                cell_data: vec![DataArray::scalars(
                    "normal_force",
                    contacts.iter().map(|c| c.normal_force).collect(),
                )],
                ..Default::default()
            },
        ));
    }
    for s in &view.surfaces {
        let cells = |list: &[Vec<usize>]| {
            let mut c = Cells::default();
            list.iter().for_each(|cell| c.push(cell));
            c
        };
        let mut verts = Cells::default();
        s.mesh.verts.iter().for_each(|&v| verts.push(&[v]));
        out.push((
            s.name.clone(),
            PolyData {
                points: s.mesh.points.iter().map(|p| (*p).into()).collect(),
                verts,
                lines: cells(&s.mesh.lines),
                polys: cells(&s.mesh.polys),
                ..Default::default()
            },
        ));
    }
    out
}

fn particles(view: &SnapshotView) -> PolyData {
    let ps = &view.particles;
    let vec3 = |f: fn(&crate::engine::ParticleView) -> crate::math::Vec3| ps.iter().map(move |p| f(p).into());
    let mut data = vec![
        DataArray::ids("id", ps.iter().map(|p| p.id as i64).collect()),
        DataArray::vectors("velocity", vec3(|p| p.velocity)),
    ];
    if view.spheres {
        data.push(DataArray::scalars("radius", ps.iter().map(|p| p.axes.x).collect()));
        data.push(DataArray::vectors("spin", vec3(|p| p.spin_world)));
    } else {
        data.push(DataArray::scalars("mass", ps.iter().map(|p| p.mass).collect()));
        data.push(DataArray::scalars(
            "speed",
            ps.iter().map(|p| p.velocity.norm()).collect(),
        ));
        data.push(DataArray::vectors("axes", vec3(|p| p.axes)));
        data.push(DataArray::vectors("spin_world", vec3(|p| p.spin_world)));
        data.push(DataArray::tensors(
            "shape",
            ps.iter().map(|p| {
                let m = p.rotation * crate::math::Mat3::from_diagonal(&p.axes);
                [0, 1, 2].map(|i| [m[(i, 0)], m[(i, 1)], m[(i, 2)]])
            }),
        ));
    }
    for (name, values) in &view.extra {
        data.push(DataArray::scalars(name, values.clone()));
    }
    PolyData {
        points: ps.iter().map(|p| p.position.into()).collect(),
        verts: Cells::poly_vertex(ps.len()),
        point_data: data,
        ..Default::default()
    }
}
