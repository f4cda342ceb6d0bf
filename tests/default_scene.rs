//! The built-in default scene (`targets/default.toml`, what `rubblepile run` runs without a scene file) is the
//! impact its header says it is: P2 on the committed N30 target at ζ = 45°, set up by `rubblepile impact`.

use std::path::PathBuf;

use rubblepile::ellipsoid::scene::default_scene;
use rubblepile::impact::projectile::ProjectileSpec;
use rubblepile::impact::run::{ImpactConfig, read_target};

#[test]
fn the_default_scene_is_the_n30_p2_impact_of_its_header() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let target = read_target(&root.join("targets/N30_T4.csv")).unwrap();
    let mut cfg = ImpactConfig::new(root.join("targets/N30_T4.csv"), ProjectileSpec::preset("P2").unwrap());
    cfg.angle_deg = 45.0;
    cfg.contact_time = 30.0;
    cfg.t_end = 600.0;
    cfg.snapshots = (0..=60).map(|k| 10.0 * k as f64).collect();
    cfg.every = 10.0;
    let plan = cfg.plan(&target).unwrap();
    let scene = default_scene().unwrap();
    assert_eq!(scene.bodies.len(), 31);
    assert_eq!(scene.bodies.len(), plan.bodies.len());
    for (i, (a, b)) in scene.bodies.iter().zip(&plan.bodies).enumerate() {
        assert_eq!(a.shape, b.shape, "body {i}: axes and mass");
        assert_eq!(a.position, b.position, "body {i}: position");
        assert_eq!(a.velocity, b.velocity, "body {i}: velocity");
        assert_eq!(a.spin_body, b.spin_body, "body {i}: spin");
        // The scene normalises [[body]] quaternions (a bodies file keeps them as written): equal to round-off.
        assert!((a.quaternion - b.quaternion).norm() < 1e-15, "body {i}: attitude");
    }
    assert_eq!(scene.t_end, cfg.t_end);
    assert_eq!(scene.output.times, cfg.snapshots);
    assert!(scene.file.output.vtk, "the default run writes VTK");
    assert_eq!(scene.output.track, vec![30], "the projectile is tracked");
    // The impact.json its runs get is this plan's setup.
    let mut setup = serde_json::to_value(&plan.setup).unwrap();
    setup["target"] = "targets/N30_T4.csv".into();
    let committed: serde_json::Value = serde_json::from_str(rubblepile::ellipsoid::scene::DEFAULT_IMPACT_JSON).unwrap();
    assert_eq!(committed, setup);
}
