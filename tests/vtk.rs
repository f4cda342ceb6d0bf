//! VTK output read back by an independent reader (the `vtkio` crate): the `.vtp` pieces' points, cells and arrays,
//! and the `.pvd` collection's times.

use std::path::Path;

use rubblepile::io::vtk::{Cells, DataArray, PolyData};
use vtkio::model::{Attribute, DataSet, IOBuffer, Piece, PolyDataPiece, VertexNumbers};

/// Reads the single PolyData piece of a `.vtp` file with vtkio.
pub fn read_piece(path: &Path) -> PolyDataPiece {
    let vtk = vtkio::Vtk::import(path).unwrap_or_else(|e| panic!("vtkio cannot read {}: {e:?}", path.display()));
    let DataSet::PolyData { mut pieces, .. } = vtk.data else {
        panic!("{} is not PolyData", path.display())
    };
    assert_eq!(pieces.len(), 1);
    match pieces.remove(0) {
        Piece::Inline(p) => *p,
        other => other.into_loaded_piece_data(Some(path)).unwrap(),
    }
}

/// The values of the named point (or cell) array as f64.
pub fn array(attrs: &[Attribute], name: &str) -> Vec<f64> {
    for a in attrs {
        if let Attribute::DataArray(d) = a
            && d.name == name
        {
            return d.data.clone().cast_into::<f64>().unwrap();
        }
    }
    panic!("no array {name:?}")
}

fn cells(v: &Option<VertexNumbers>) -> (Vec<u64>, Vec<u64>) {
    match v {
        Some(VertexNumbers::XML { connectivity, offsets }) => (connectivity.clone(), offsets.clone()),
        Some(other) => panic!("legacy cells {other:?}"),
        None => (vec![], vec![]),
    }
}

#[test]
fn a_polydata_piece_reads_back_bit_for_bit() {
    let dir = std::env::temp_dir().join(format!("rubblepile-vtk-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut lines = Cells::default();
    lines.push(&[0, 2]);
    lines.push(&[1, 2]);
    let pd = PolyData {
        points: vec![[1.0, 2.0, 3.0], [0.1, -0.2, 1e300], [f64::MIN_POSITIVE, 0.0, -7.5]],
        lines,
        point_data: vec![DataArray::scalars("radius", vec![0.5, 0.25, 1.0 / 3.0])],
        cell_data: vec![DataArray::scalars("normal_force", vec![10.0, 20.0])],
        ..Default::default()
    };
    let path = dir.join("p.vtp");
    pd.write(&path).unwrap();
    let piece = read_piece(&path);
    let IOBuffer::F64(points) = &piece.points else {
        panic!("points are not Float64")
    };
    assert_eq!(
        points,
        &vec![1.0, 2.0, 3.0, 0.1, -0.2, 1e300, f64::MIN_POSITIVE, 0.0, -7.5]
    );
    assert_eq!(cells(&piece.lines), (vec![0, 2, 1, 2], vec![2, 4]));
    assert_eq!(array(&piece.data.point, "radius"), vec![0.5, 0.25, 1.0 / 3.0]);
    assert_eq!(array(&piece.data.cell, "normal_force"), vec![10.0, 20.0]);
    std::fs::remove_dir_all(&dir).unwrap();
}

use rubblepile::driver::{RunOptions, run};
use rubblepile::ellipsoid::run::EllipsoidEngine;
use rubblepile::engine::Engine;
use rubblepile::granular::hard::run::HardEngine;
use rubblepile::granular::hard::scene::parse_hard_scene;
use rubblepile::granular::soft::run::SoftEngine;
use std::path::PathBuf;

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rubblepile-vtk-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn quiet() -> RunOptions {
    RunOptions {
        progress: false,
        checkpoint_every: None,
        ..RunOptions::default()
    }
}

/// `(timestep, part, file)` of every DataSet of a `.pvd`, read with quick-xml.
fn collection(path: &Path) -> Vec<(f64, usize, String)> {
    use quick_xml::events::Event;
    let text = std::fs::read_to_string(path).unwrap();
    let mut reader = quick_xml::Reader::from_str(&text);
    let mut out = Vec::new();
    loop {
        match reader.read_event().unwrap() {
            Event::Empty(e) if e.name().as_ref() == b"DataSet" => {
                let attr = |name: &[u8]| {
                    let a = e.try_get_attribute(name).unwrap().unwrap();
                    String::from_utf8(a.value.to_vec()).unwrap()
                };
                out.push((
                    attr(b"timestep").parse().unwrap(),
                    attr(b"part").parse().unwrap(),
                    attr(b"file"),
                ));
            }
            Event::Eof => break,
            _ => {}
        }
    }
    out
}

const TWO_ELLIPSOIDS: &str = r#"
[scene]
kind = "ellipsoids"
t_end = 2.0
[model]
kappa = 5.0
[physics]
gravity = {}
[integrator]
method = "bulirsch-stoer"
rtol = 1e-12
atol = 1e-12
[output]
times = [0.0, 0.7, 2.0]
every = 0.1
vtk = true
[[body]]
axes = [3.0, 2.0, 1.0]
mass = 1e9
position = [0.0, 0.0, 0.0]
velocity = [0.0, 0.0, 0.0]
quaternion = [0.1, -0.3, 0.5, 0.8062257748298549]
spin_body = [0.3, -0.2, 0.5]
[[body]]
axes = [1.5, 1.0, 0.25]
mass = 2e8
position = [20.0, 1.0, -2.0]
velocity = [0.0, 0.05, 0.0]
quaternion = [0.0, 0.0, 0.0, 1.0]
spin_body = [0.0, 0.7, 0.1]
"#;

/// Rotation body → world of a snapshot row's quaternion (vector part first): Roig03 Eq. 21's R(q) maps world to
/// body, so body → world is its transpose.
fn body_to_world(q: [f64; 4]) -> nalgebra::Matrix3<f64> {
    let uq = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[3], q[0], q[1], q[2]));
    // nalgebra's rotation matrix of q is R(q)ᵀ (Roig03 Eq. 21 is its transpose), i.e. body → world.
    uq.to_rotation_matrix().into_inner()
}

#[test]
fn the_shape_tensor_gives_each_ellipsoids_axes_and_attitude_and_the_collection_its_times() {
    let dir = scratch("ellipsoids");
    let engine = EllipsoidEngine::from_scene_text(TWO_ELLIPSOIDS, "two.toml", None).unwrap();
    run(engine, &dir, &quiet()).unwrap();
    let entries = collection(&dir.join("vtk/run.pvd"));
    let times: Vec<f64> = entries.iter().map(|e| e.0).collect();
    assert_eq!(times, vec![0.0, 0.7, 2.0], "the .pvd lists the snapshot times exactly");
    assert!(entries.iter().all(|e| e.1 == 0));
    for (k, (_, _, file)) in entries.iter().enumerate() {
        assert_eq!(file, &format!("particles_{k}.vtp"));
        let piece = read_piece(&dir.join("vtk").join(file));
        let shape = array(&piece.data.point, "shape");
        let axes = array(&piece.data.point, "axes");
        // The snapshot CSV is the reference: its quaternions and positions at the same time.
        let rows = rubblepile::ellipsoid::output::read_bodies_csv(&dir.join(format!("snapshots/{k}.csv"))).unwrap();
        let IOBuffer::F64(points) = &piece.points else { panic!() };
        for (i, r) in rows.iter().enumerate() {
            assert_eq!(&points[3 * i..3 * i + 3], &r.position[..], "centre of body {i}");
            let q = nalgebra::Vector4::from(r.quaternion).normalize();
            let rot = body_to_world([q[0], q[1], q[2], q[3]]);
            let m = &shape[9 * i..9 * i + 9];
            for j in 0..3 {
                // VTK tensors are stored column by column: column j is the j-th body axis scaled by its semi-axis.
                let col = nalgebra::Vector3::new(m[3 * j], m[3 * j + 1], m[3 * j + 2]);
                assert!(
                    ((col.norm() - r.axes[j]) / r.axes[j]).abs() < 1e-12,
                    "body {i} axis {j}: |col| {}",
                    col.norm()
                );
                let dir_err = (col / r.axes[j] - rot.column(j)).norm();
                assert!(dir_err < 1e-12, "body {i} axis {j}: direction off by {dir_err:e}");
                assert_eq!(axes[3 * i + j], r.axes[j]);
            }
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

const SOFT_PACKING: &str = r#"
[scene]
kind = "soft-spheres"
t_end = 1e-4
[stepping]
dt = 1e-5
[material]
k_n = 1e5
max_start_overlap = 0.05
[output]
every = 1e-4
times = [0.0]
vtk = true
"#;

#[test]
fn force_chain_cells_connect_exactly_the_touching_pairs() {
    // A 4 x 4 x 2 simple-cubic packing of unit-radius spheres with spacings 1.99 (touching, overlap 0.01) or 2.01
    // (a 0.01 gap) chosen pseudo-randomly per gap, so about half the neighbours touch.
    let mut text = SOFT_PACKING.to_string();
    let mut xs = [0.0f64; 4];
    let mut ys = [0.0f64; 4];
    let mut zs = [0.0f64; 2];
    let mut seed = 12345u64;
    let mut gap = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        if (seed >> 33).is_multiple_of(2) { 1.99 } else { 2.01 }
    };
    for k in 1..4 {
        xs[k] = xs[k - 1] + gap();
        ys[k] = ys[k - 1] + gap();
    }
    zs[1] = 1.99;
    let mut centres = Vec::new();
    for x in xs {
        for y in ys {
            for z in zs {
                centres.push(nalgebra::Vector3::new(x, y, z));
                text.push_str(&format!(
                    "[[particle]]\nradius = 1.0\nmass = 1.0\nposition = [{x:?}, {y:?}, {z:?}]\n"
                ));
            }
        }
    }
    let mut touching = std::collections::BTreeSet::new();
    for i in 0..centres.len() {
        for j in i + 1..centres.len() {
            if (centres[i] - centres[j]).norm() < 2.0 {
                touching.insert((i, j));
            }
        }
    }
    assert!(touching.len() > 10, "{} touching pairs", touching.len());

    let dir = scratch("soft");
    let engine = SoftEngine::from_scene_text(&text, "packing.toml", None).unwrap();
    run(engine, &dir, &quiet()).unwrap();
    let piece = read_piece(&dir.join("vtk/contacts_0.vtp"));
    let (conn, offsets) = cells(&piece.lines);
    assert_eq!(offsets.len(), touching.len());
    let mut cells_found = std::collections::BTreeSet::new();
    for pair in conn.chunks(2) {
        let (a, b) = (pair[0] as usize, pair[1] as usize);
        cells_found.insert((a.min(b), a.max(b)));
    }
    assert_eq!(cells_found, touching, "contact cells = touching pairs");
    // At rest, the normal force of a linear spring is k_n times the overlap (Zhang17 Eq. 1): 1e5 N/m x 0.01 m.
    let forces = array(&piece.data.cell, "normal_force");
    for f in &forces {
        assert!((f - 1e3).abs() < 1e-6 * 1e3, "normal force {f} N");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

const HARD_WALLS: &str = r#"
[scene]
kind = "hard-spheres"
t_end = 0.3
[stepping]
dt = 1e-3
[output]
times = [0.0, 0.13, 0.3]
every = 0.01
vtk = true
[[particle]]
mass = 1.0
radius = 0.05
position = [0.3, 0.2, 0.5]
velocity = [0.1, 0.0, 0.0]
[[wall]]
kind = "plane"
point = [0.0, 0.0, -1.0]
normal = [0.1, 0.2, 1.0]
oscillation = { amplitude = 0.01, angular_frequency = 60.0, phase = 0.3, direction = [0.0, 0.0, 1.0] }
[[wall]]
kind = "disk"
centre = [0.0, 0.0, 2.0]
axis = [1.0, 1.0, 0.0]
radius = 0.7
velocity = [0.0, 0.5, 0.0]
[[wall]]
kind = "cylinder"
centre = [0.0, 0.0, 0.0]
axis = [0.0, 0.3, 1.0]
radius = 3.0
length = 4.0
spin = 2.0
[[wall]]
kind = "cylinder"
centre = [5.0, 0.0, 0.0]
radius = 0.5
[[wall]]
kind = "ring"
centre = [0.0, -2.0, 0.0]
axis = [0.0, 1.0, 0.0]
radius = 1.25
[[wall]]
kind = "line"
centre = [-4.0, 0.0, 0.0]
axis = [1.0, 0.0, 0.0]
length = 1.0
[[wall]]
kind = "point"
centre = [-6.0, 1.0, 1.0]
"#;

#[test]
fn hard_sphere_wall_surfaces_lie_on_the_analytic_walls_where_their_motion_took_them() {
    let dir = scratch("hard");
    let engine = HardEngine::from_scene_text(HARD_WALLS, "walls.toml", None).unwrap();
    run(engine, &dir, &quiet()).unwrap();
    let scene = parse_hard_scene(HARD_WALLS, "walls.toml", Path::new(".")).unwrap();
    let entries = collection(&dir.join("vtk/run.pvd"));
    // particles + 7 walls at each of the 3 snapshot times
    assert_eq!(entries.len(), 3 * 8);
    let mut checked = 0;
    for (t, part, file) in entries.iter().filter(|e| e.1 >= 1) {
        let wall = &scene.walls[part - 1];
        assert!(file.starts_with(&format!("wall{}_", part - 1)), "{file}");
        let piece = read_piece(&dir.join("vtk").join(file));
        let IOBuffer::F64(points) = &piece.points else { panic!() };
        assert!(!points.is_empty());
        let origin = wall.origin_at(*t);
        for p in points.chunks(3) {
            let p = rubblepile::math::Vec3::new(p[0], p[1], p[2]);
            let (dist, _) = wall.nearest(&origin, &p);
            assert!(
                dist.abs() < 1e-9,
                "{file} at t = {t}: vertex {p:?} is {dist:e} m off the {}",
                wall.shape.name()
            );
            checked += 1;
        }
        // A translating or oscillating wall's surface is not where it started (a spinning one is: it is
        // axisymmetric).
        if *t > 0.0 && wall.motion.displacement(*t).norm() > 1e-3 {
            let (d0, _) = wall.nearest(
                &wall.origin_at(0.0),
                &rubblepile::math::Vec3::new(points[0], points[1], points[2]),
            );
            assert!(d0.abs() > 1e-4, "{file}: the surface did not move ({d0:e})");
        }
    }
    assert!(checked > 500, "{checked} vertices checked");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn export_of_a_finished_run_writes_the_files_the_run_wrote() {
    for (name, scene) in [("walls", HARD_WALLS), ("ellipsoids", TWO_ELLIPSOIDS)] {
        let dir = scratch(&format!("export-{name}"));
        if name == "walls" {
            run(
                HardEngine::from_scene_text(scene, "s.toml", None).unwrap(),
                &dir,
                &quiet(),
            )
            .unwrap();
        } else {
            run(
                EllipsoidEngine::from_scene_text(scene, "s.toml", None).unwrap(),
                &dir,
                &quiet(),
            )
            .unwrap();
        }
        std::fs::rename(dir.join("vtk"), dir.join("vtk_during_run")).unwrap();
        let formats = rubblepile::driver::formats::Formats::parse(&["vtk".to_string()]).unwrap();
        let report = rubblepile::driver::export::export(&dir, formats, false, &|_| Ok(Vec::new())).unwrap();
        assert_eq!(report.snapshots, 3);
        let mut files: Vec<_> = std::fs::read_dir(dir.join("vtk_during_run"))
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        files.sort();
        assert!(files.len() >= 4);
        for f in &files {
            let a = std::fs::read(dir.join("vtk_during_run").join(f)).unwrap();
            let b = std::fs::read(dir.join("vtk").join(f)).unwrap();
            assert!(a == b, "{name}: {f:?} differs between the run and the export");
        }
        // A second export refuses to overwrite the first.
        let again = rubblepile::driver::export::export(&dir, formats, false, &|_| Ok(Vec::new()));
        assert!(again.unwrap_err().to_string().contains("--force"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn a_42000_sphere_snapshot_stays_under_5_mb() {
    let view = rubblepile::ellipsoid::cloud::cloud_view(42_000, true);
    let bytes: usize = rubblepile::driver::formats::vtk::pieces(&view)
        .iter()
        .map(|(_, p)| p.to_bytes().unwrap().len())
        .sum();
    assert!(bytes < 5_000_000, "{bytes} bytes");
}

#[test]
fn soft_sphere_walls_lie_on_their_plane_and_sphere_where_they_oscillated_to() {
    let scene = r#"
[scene]
kind = "soft-spheres"
t_end = 0.02
[stepping]
dt = 1e-3
[material]
k_n = 1e5
[output]
every = 0.01
times = [0.0, 0.013]
vtk = true
[[wall]]
kind = "plane"
point = [0.0, 0.0, -0.5]
normal = [0.0, 0.6, 0.8]
oscillation = { amplitude = 0.05, direction = [0.0, 0.0, 1.0], angular_frequency = 31.41592653589793 }
[[wall]]
kind = "sphere"
centre = [0.1, 0.0, 0.2]
radius = 4.0
oscillation = { amplitude = 0.02, direction = [1.0, 0.0, 0.0], angular_frequency = 18.84955592153876 }
[[particle]]
radius = 0.5
mass = 1.0
position = [0.0, 0.0, 1.0]
"#;
    let dir = scratch("soft-walls");
    run(
        SoftEngine::from_scene_text(scene, "w.toml", None).unwrap(),
        &dir,
        &quiet(),
    )
    .unwrap();
    let entries = collection(&dir.join("vtk/run.pvd"));
    // particles, contacts, two walls at each of the two snapshot times (the second lands on step 13)
    assert_eq!(entries.len(), 2 * 4);
    for (t, part, file) in entries.iter().filter(|e| e.1 >= 2) {
        let piece = read_piece(&dir.join("vtk").join(file));
        let IOBuffer::F64(points) = &piece.points else { panic!() };
        let tau = std::f64::consts::TAU;
        for p in points.chunks(3) {
            let p = nalgebra::Vector3::new(p[0], p[1], p[2]);
            let off = if *part == 2 {
                nalgebra::Vector3::new(0.0, 0.0, 0.05 * (tau * 5.0 * t).sin())
            } else {
                nalgebra::Vector3::new(0.02 * (tau * 3.0 * t).sin(), 0.0, 0.0)
            };
            let miss = if *part == 2 {
                (p - (nalgebra::Vector3::new(0.0, 0.0, -0.5) + off)).dot(&nalgebra::Vector3::new(0.0, 0.6, 0.8))
            } else {
                (p - (nalgebra::Vector3::new(0.1, 0.0, 0.2) + off)).norm() - 4.0
            };
            assert!(miss.abs() < 1e-9, "{file} at t = {t}: {miss:e} m off");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
