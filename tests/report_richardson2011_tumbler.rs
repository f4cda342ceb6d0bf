//! What the paper-scale tumbler report (Richardson11 §3.2, Fig. 8) rests on: every committed Richardson11 scene
//! loading. The report and its measurements (the slope's fit error, synthetic run directories whose answers are
//! known) are tested beside them in `src/studies/richardson2011/`.

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
