//! `rubblepile run` without a scene (the README's first command), `rubblepile render` and `rubblepile export` as a
//! user calls them: what they leave on disk and how they refuse bad input.

mod common;
use common::{rubblepile, temp_dir};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn gif_frames(path: &Path) -> (usize, u16, u16) {
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::Indexed);
    let mut decoder = options.read_info(std::fs::File::open(path).unwrap()).unwrap();
    let (w, h) = (decoder.width(), decoder.height());
    let mut n = 0;
    while decoder.read_next_frame().unwrap().is_some() {
        n += 1;
    }
    (n, w, h)
}

fn stdout(o: &std::process::Output) -> String {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn the_first_readme_command_runs_the_impact_and_leaves_an_animation_and_a_paraview_file() {
    let dir = temp_dir("demo");
    let out = dir.join("demo");
    let text = stdout(&rubblepile(
        &root(),
        &["run", "--out", out.to_str().unwrap(), "--no-progress"],
    ));
    let lines: Vec<&str> = text.lines().collect();
    let n = lines.len();
    assert!(n >= 3, "{text}");
    assert!(lines[n - 3].starts_with("done: t = 600 s, wall "), "{text}");
    assert!(
        lines[n - 3].contains("energy error"),
        "the error beside the run time: {text}"
    );
    assert!(lines[n - 2].ends_with("frames/run.gif"), "{text}");
    assert!(lines[n - 1].contains("vtk/run.pvd"), "{text}");
    // 61 snapshots (every 10 s to 600 s): 61 PNG frames, a 61-frame GIF, 61 times in the collection.
    assert_eq!(gif_frames(&out.join("frames/run.gif")), (61, 800, 800));
    assert!(out.join("frames/0060.png").exists());
    let pvd = std::fs::read_to_string(out.join("vtk/run.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 61);
    assert!(pvd.contains("timestep=\"6e2\""), "{pvd}");
    // It is an impact run like any other: `analyze` reads it, and `render --color bound` then colours by fate.
    let a = stdout(&rubblepile(
        &root(),
        &["analyze", out.to_str().unwrap(), "--at-s", "400"],
    ));
    assert!(a.contains("of the target mass bound"), "{a}");
    let r = stdout(&rubblepile(
        &root(),
        &["render", out.to_str().unwrap(), "--color", "bound", "--force"],
    ));
    assert!(r.contains("rendered 61 frames"), "{r}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn render_draws_every_snapshot_and_refuses_bad_options_by_name() {
    let dir = temp_dir("render");
    let run = dir.join("two");
    let scene = root().join("targets/examples/two_ellipsoids.toml");
    stdout(&rubblepile(
        &dir,
        &["run", scene.to_str().unwrap(), "--out", "two", "--no-progress"],
    ));
    let snapshots = std::fs::read_dir(run.join("snapshots")).unwrap().count();
    let text = stdout(&rubblepile(
        &dir,
        &[
            "render", "two", "--view", "z", "--color", "id", "--size", "200x120", "--gif", "a.gif",
        ],
    ));
    assert!(text.contains(&format!("rendered {snapshots} frames")), "{text}");
    assert_eq!(gif_frames(&run.join("frames/a.gif")), (snapshots, 200, 120));
    let err = |args: &[&str]| {
        let o = rubblepile(&dir, args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    assert!(
        err(&["render", "two"]).contains("--force"),
        "frames exist: refused without --force"
    );
    assert!(err(&["render", "two", "--force", "--view", "q"]).contains("--view"));
    assert!(err(&["render", "two", "--force", "--color", "mass"]).contains("--color"));
    assert!(err(&["render", "two", "--force", "--size", "8x8"]).contains("--size"));
    assert!(err(&["render", "two", "--force", "--size", "big"]).contains("--size"));
    assert!(err(&["render", "two", "--force", "--centre-m", "0,0"]).contains("--centre-m"));
    assert!(err(&["render", "two", "--force", "--color", "bound"]).contains("rubblepile analyze"));
    assert!(err(&["render", "nowhere"]).contains("scene.toml"));
    assert!(err(&["export", "vtu", "two"]).contains("vtk"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn export_after_analyze_adds_each_bodys_fate_and_ejection_speed() {
    let dir = temp_dir("export-analyzed");
    let t = root().join("targets/N30_T4.csv");
    stdout(&rubblepile(
        &dir,
        &[
            "impact",
            "--target",
            t.to_str().unwrap(),
            "--t-end-s",
            "400",
            "--out",
            "imp",
            "--no-progress",
        ],
    ));
    stdout(&rubblepile(&dir, &["analyze", "imp", "--at-s", "400"]));
    let text = stdout(&rubblepile(&dir, &["export", "vtk", "imp"]));
    assert!(text.contains("bound and ejection_speed"), "{text}");
    let piece = std::fs::read_to_string(dir.join("imp/vtk/particles_0.vtp")).unwrap();
    assert!(piece.contains("Name=\"bound\"") && piece.contains("Name=\"ejection_speed\""));
    // The values are the analysis' own (fragments.csv), read back with an independent VTK reader.
    let vtk = vtkio::Vtk::import(dir.join("imp/vtk/particles_0.vtp")).unwrap();
    let vtkio::model::DataSet::PolyData { pieces, .. } = vtk.data else {
        panic!()
    };
    let vtkio::model::Piece::Inline(p) = &pieces[0] else {
        panic!()
    };
    let get = |name: &str| {
        p.data
            .point
            .iter()
            .find_map(|a| match a {
                vtkio::model::Attribute::DataArray(d) if d.name == name => d.data.clone().cast_into::<f64>(),
                _ => None,
            })
            .unwrap()
    };
    let (bound, speed) = (get("bound"), get("ejection_speed"));
    let mut rdr = csv::Reader::from_path(dir.join("imp/analysis/fragments.csv")).unwrap();
    let h = rdr.headers().unwrap().clone();
    let col = |n: &str| h.iter().position(|x| x == n).unwrap();
    let mut rows = 0;
    for rec in rdr.records() {
        let rec = rec.unwrap();
        let i: usize = rec[col("index")].parse().unwrap();
        let escaping: bool = rec[col("escaping")].parse().unwrap();
        assert_eq!(bound[i], if escaping { 0.0 } else { 1.0 }, "body {i}");
        assert_eq!(speed[i], rec[col("ejection_speed")].parse::<f64>().unwrap(), "body {i}");
        rows += 1;
    }
    assert_eq!(rows, bound.len());
    std::fs::remove_dir_all(&dir).unwrap();
}
