//! The paper-scale tumbler report (Richardson11 §3.2, Fig. 8; `src/studies/richardson2011/tumbler_paper.rs`)
//! on synthetic run directories whose answers are known: a packed bed whose surface is tilted at a known angle, a
//! run stopped before its end (no `summary.json`, read from its time series), the slope's fit error against the
//! closed form of least squares, and the Froude number taken with the lining's inner edge.

mod common;
use common::temp_dir;
use rubblepile::analysis::tumbler::{analyse_tumbler_run, repose_fit};
use rubblepile::studies::richardson2011::tumbler_paper::{
    TumblerPaperArgs, lining_froude, tumbler_paper_markdown, write_tumbler_paper_report,
};
use std::fmt::Write as _;

/// The paper's scale: particle radius 0.53 mm, wall at 31.06 mm, so the lining's inner edge is at 30 mm.
const R_PART: f64 = 0.53e-3;
const R_WALL: f64 = 0.03106;
const OMEGA: f64 = 4.0;

#[test]
fn the_fit_error_of_an_angle_is_the_slope_standard_error_carried_through_atan() {
    // (0, 0), (1, 1), (2, 0): slope 0, residuals −1/3, 2/3, −1/3, s² = rss / (N − 2) = 2/3, Sxx = 2, so
    // σ_slope = √(1/3) and, at slope 0, σ_θ = σ_slope rad.
    let (a, e) = repose_fit(&[(0.0, 0.0), (1.0, 1.0), (2.0, 0.0)], -1.0, 3.0).unwrap();
    assert!(a.abs() < 1e-12, "angle {a}");
    assert!((e - (1.0f64 / 3.0).sqrt().to_degrees()).abs() < 1e-9, "error {e}");
    // The same residuals about the line z = −x: 45°, and σ_θ = σ_slope / (1 + 1).
    let (a, e) = repose_fit(&[(0.0, 0.0), (1.0, 0.0), (2.0, -2.0)], -1.0, 3.0).unwrap();
    assert!((a - 45.0).abs() < 1e-9, "angle {a}");
    assert!((e - (1.0f64 / 3.0).sqrt().to_degrees() / 2.0).abs() < 1e-9, "error {e}");
    // Points on an exact line have no fit error; fewer than three points give no fit.
    let (a, e) = repose_fit(&[(-3.0, 3.0), (-2.0, 2.0), (-1.0, 1.0)], -4.0, 0.0).unwrap();
    assert!((a - 45.0).abs() < 1e-9 && e.abs() < 1e-9, "{a} {e}");
    assert!(repose_fit(&[(0.0, 0.0), (1.0, 1.0)], -1.0, 3.0).is_none());
}

/// A hexagonally packed bed of free particles (spacing 2r) inside the lining, below the line z = −tan(θ) x.
fn tilted_bed(theta_deg: f64) -> Vec<(f64, f64)> {
    let inner = R_WALL - 3.0 * R_PART;
    let slope = -theta_deg.to_radians().tan();
    let mut c = Vec::new();
    for i in -40..=40 {
        for k in -40..=40 {
            let x = 2.0 * R_PART * i as f64 + if k % 2 == 0 { 0.0 } else { R_PART };
            let z = 2.0 * R_PART * k as f64 * 0.866;
            if x.hypot(z) < inner && z < slope * x {
                c.push((x, z));
            }
        }
    }
    c
}

fn write_run(dir: &std::path::Path, theta_deg: f64) {
    write_run_at(dir, theta_deg, OMEGA);
}

/// [`write_run`] with the drum's spin `omega` (rad/s).
fn write_run_at(dir: &std::path::Path, theta_deg: f64, omega: f64) {
    std::fs::write(
        dir.join("scene.toml"),
        format!(
            "[stepping]\ndt = 5e-4\n[gravity]\ng = [0.0, 0.0, -9.81]\n[material]\neps_n = 0.5\neps_t = 0.3\n[[wall]]\ntype = \"cylinder\"\n\
             radius = {R_WALL:?}\nspin = {omega:?}\n"
        ),
    )
    .unwrap();
    // Stopped at t = 0.4 s: no summary.json; the time series holds per-row collision counts and the wall clock.
    std::fs::write(
        dir.join("timeseries.csv"),
        "t,kinetic,energy_residual,collisions,wall_seconds\n0e0,0,0,0,0.5\n2e-1,1,-3e-3,100,5\n4e-1,1,2e-3,300,12\n",
    )
    .unwrap();
    std::fs::create_dir_all(dir.join("snapshots")).unwrap();
    // Flat at first, tilted in the second half of the run (t ≥ 0.2 s), which is all the angle is taken over.
    for (k, t) in [0.0, 0.1, 0.2, 0.3, 0.4].into_iter().enumerate() {
        let bed = tilted_bed(if t < 0.2 { 0.0 } else { theta_deg });
        let mut s = String::from("t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz,stuck_to\n");
        let _ = writeln!(s, "{t},0,1e-6,{R_PART},0,0,{},0,0,0,0,0,0,0", -(R_WALL - R_PART));
        for (n, (x, z)) in bed.iter().enumerate() {
            let _ = writeln!(s, "{t},{},1e-6,{R_PART},{x},0,{z},0,0,0,0,0,0,-1", n + 1);
        }
        std::fs::write(dir.join(format!("snapshots/{k}.csv")), s).unwrap();
    }
}

#[test]
fn a_stopped_run_of_a_bed_tilted_at_35_degrees_reports_35_degrees_and_its_time_series_totals() {
    let root = temp_dir("tumbler_paper");
    let run_dir = root.join("run");
    std::fs::create_dir_all(&run_dir).unwrap();
    write_run(&run_dir, 35.0);
    let run = analyse_tumbler_run(&run_dir).unwrap();
    assert_eq!(run.status, "interrupted");
    assert_eq!(run.t_reached, 0.4);
    assert_eq!(run.collisions, 400);
    assert!((run.wall_seconds - 12.0).abs() < 1e-12 && (run.events_per_second - 400.0 / 12.0).abs() < 1e-9);
    assert_eq!(run.restitution, (0.5, 0.3));
    // Three snapshots in the second half, each at 35° to within the column discretisation, with a fit error well
    // under a degree (the packed surface is a staircase about the line).
    assert_eq!(run.angles.len(), 3);
    assert!((run.angle.0 - 35.0).abs() < 2.0, "angle {:?}", run.angle);
    assert_eq!(run.angle_fit_errors.len(), 3);
    // The history holds every snapshot: flat (0°, an exact line, no fit error) before the tilt.
    assert_eq!(run.angle_history.len(), 5);
    assert!(
        run.angle_history[..2]
            .iter()
            .all(|h| h.1.abs() < 1e-9 && h.2.abs() < 1e-9),
        "{:?}",
        run.angle_history
    );
    assert_eq!(
        &run.angle_history[2..].iter().map(|h| (h.0, h.1)).collect::<Vec<_>>(),
        &run.angles
    );
    assert!(
        run.angle_fit_errors.iter().all(|e| *e > 0.0 && *e < 1.0),
        "{:?}",
        run.angle_fit_errors
    );
    // Fr with R = 31.06 − 2 × 0.53 = 30 mm, and R/r = 30 / 0.53.
    assert!((lining_froude(&run) - OMEGA * OMEGA * 0.030 / 9.81).abs() < 1e-12);
    // The step from the scene and, for a stopped run, the largest |energy_residual| of the time series.
    assert_eq!(run.dt, 5e-4);
    assert_eq!(run.energy_error, 3e-3);
    assert!((run.radius_ratio() - 0.030 / R_PART).abs() < 1e-9);
    // The report: one table row with the interrupted status and the angle, and both figures.
    let out = root.join("out");
    let compact = root.join("compact");
    let path = write_tumbler_paper_report(&TumblerPaperArgs {
        runs: vec![run_dir.clone()],
        out: out.clone(),
        compact: Some(compact.clone()),
    })
    .unwrap();
    // The compact copy analyses to the same run (its directory aside), so the report regenerates from it.
    let mut again = analyse_tumbler_run(&compact.join("run")).unwrap();
    assert_eq!(again.dir, compact.join("run"));
    again.dir = run.dir.clone();
    assert_eq!(format!("{again:?}"), format!("{run:?}"));
    assert!(
        std::fs::read_dir(compact.join("run")).unwrap().count() == 2,
        "two CSV files, no snapshots"
    );
    let md = std::fs::read_to_string(&path).unwrap();
    assert_eq!(
        md,
        tumbler_paper_markdown(std::slice::from_ref(&run), &md_command(&run_dir, &out))
    );
    let row = md.lines().find(|l| l.contains("| interrupted |")).expect("table row");
    assert!(
        row.contains(&format!("{:.1} ± {:.1}", run.angle.0, run.angle.1)),
        "{row}"
    );
    assert!(
        row.starts_with(&format!("| {:.3} | 0.5 | 0.3 |", lining_froude(&run))),
        "{row}"
    );
    for f in ["tumbler_paper_angle_vs_froude.png", "tumbler_paper_angle_vs_time.png"] {
        assert!(out.join("figures").join(f).is_file(), "{f}");
    }
    std::fs::remove_dir_all(&root).unwrap();
}

fn md_command(run: &std::path::Path, out: &std::path::Path) -> String {
    format!(
        "rubblepile report richardson2011-tumbler {} --out {}",
        run.display(),
        out.display()
    )
}

#[test]
fn a_run_without_summary_or_time_series_is_an_input_error_naming_the_file() {
    let root = temp_dir("tumbler_paper_bad");
    let run_dir = root.join("run");
    std::fs::create_dir_all(&run_dir).unwrap();
    write_run(&run_dir, 30.0);
    std::fs::remove_file(run_dir.join("timeseries.csv")).unwrap();
    let e = analyse_tumbler_run(&run_dir).unwrap_err().to_string();
    assert!(e.contains("summary.json"), "{e}");
    std::fs::remove_dir_all(&root).unwrap();
}

/// Every committed Richardson11 scene loads, and the smooth drum of NOTES row 20 is the R/r = 28 drum at
/// Fr ≈ 0.05 with the lining removed: the same free spheres, none stuck to the wall, the same spin.
#[test]
fn every_richardson2011_scene_loads_and_the_smooth_drum_lacks_only_the_lining() {
    use rubblepile::granular::hard::scene::load_hard_scene;
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("analysis/richardson2011");
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    names.sort();
    assert!(names.len() >= 20, "{names:?}");
    for p in &names {
        load_hard_scene(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    }
    let lined = load_hard_scene(&dir.join("tumbler_fr0.05.toml")).unwrap();
    let smooth = load_hard_scene(&dir.join("tumbler_fr0.05_smooth.toml")).unwrap();
    let stuck =
        |s: &rubblepile::granular::hard::scene::HardScene| s.particles.iter().filter(|p| p.stuck.is_some()).count();
    assert!(
        stuck(&lined) > 100,
        "the lined drum has {} stuck spheres",
        stuck(&lined)
    );
    assert_eq!(stuck(&smooth), 0);
    assert_eq!(smooth.particles.len(), lined.particles.len() - stuck(&lined));
    assert_eq!(smooth.walls.len(), lined.walls.len());
}

/// Guards the Fig. 8 comparison against centrifuging runs: at Fr ≥ 1 the paper estimates no slope, so the table
/// prints none (a line through a bed spread round the lining is not a dynamic angle of repose) while a subcritical
/// run keeps its angle.
#[test]
fn a_centrifuging_run_gets_no_slope_in_the_table() {
    let root = temp_dir("tumbler_paper_centrifuging");
    let (slow, fast) = (root.join("slow"), root.join("fast"));
    for d in [&slow, &fast] {
        std::fs::create_dir_all(d).unwrap();
    }
    write_run(&slow, 30.0);
    // Fr = ω² R / g = 1.2 with R = 30 mm.
    write_run_at(&fast, 30.0, (1.2f64 * 9.81 / 0.030).sqrt());
    let out = root.join("out");
    let path = write_tumbler_paper_report(&TumblerPaperArgs {
        runs: vec![slow, fast],
        out,
        compact: None,
    })
    .unwrap();
    let md = std::fs::read_to_string(&path).unwrap();
    let row = |fr: &str| {
        md.lines()
            .find(|l| l.starts_with(&format!("| {fr} |")))
            .unwrap()
            .to_string()
    };
    assert!(row("1.200").contains("— (Fr ≥ 1: no slope)"), "{}", row("1.200"));
    assert!(
        !row("1.200").contains(" / "),
        "no halves of a slope either: {}",
        row("1.200")
    );
    assert!(!row("0.049").contains("no slope"), "{}", row("0.049"));
    std::fs::remove_dir_all(&root).unwrap();
}
