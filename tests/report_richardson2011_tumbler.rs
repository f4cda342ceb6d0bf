//! What the paper-scale tumbler report (Richardson11 §3.2, Fig. 8) rests on: the slope's fit error against the
//! closed form of least squares, and every committed Richardson11 scene loading. The report itself, on synthetic run
//! directories whose answers are known (a bed tilted at a known angle, a run stopped before its end, the Froude
//! number taken with the lining's inner edge), is tested beside it in `src/studies/richardson2011/tumbler_paper.rs`.

use rubblepile::analysis::tumbler::repose_fit;

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
