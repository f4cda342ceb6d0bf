//! Point-in-polyhedron on a real shape model (Itokawa, 12 192 triangles): the grid-accelerated +z ray parity
//! agrees with the brute-force +x ray parity on 10⁵ random points, and the inside fraction of the bounding box
//! reproduces the enclosed volume (a Monte Carlo oracle).

use rayon::prelude::*;
use rubblepile::geometry::polyhedron::Polyhedron;
use rubblepile::math::Vec3;
use rubblepile::random::{generator, uniform};

#[test]
fn itokawa_containment_agrees_with_brute_force_and_volume() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("targets/shapes/itokawa_radar_25143.obj");
    let shape = Polyhedron::from_obj(&path, 1000.0).expect("the committed Itokawa model reads");
    assert_eq!((shape.vertices.len(), shape.triangles.len()), (6098, 12192));
    let volume = shape.volume();
    // a radar model of Itokawa: about 0.55 × 0.31 × 0.28 km, a few 1e7 m³
    assert!(volume > 1e7 && volume < 3e7, "volume {volume:e} m³");
    let (lo, hi) = shape.bounds();
    let mut rng = generator(2017);
    let n = 100_000;
    let points: Vec<Vec3> = (0..n)
        .map(|_| {
            let u = Vec3::new(uniform(&mut rng), uniform(&mut rng), uniform(&mut rng));
            lo + (hi - lo).component_mul(&u)
        })
        .collect();
    let disagreements: Vec<usize> = (0..n)
        .into_par_iter()
        .filter(|&k| shape.contains(&points[k]) != shape.contains_brute_force(&points[k]))
        .collect();
    assert!(
        disagreements.is_empty(),
        "{} disagreements, e.g. {:?}",
        disagreements.len(),
        points[disagreements[0]]
    );
    let inside = points.iter().filter(|p| shape.contains(p)).count() as f64;
    let box_volume = (hi - lo).iter().product::<f64>();
    let f = inside / n as f64;
    let estimate = f * box_volume;
    let sigma = box_volume * (f * (1.0 - f) / n as f64).sqrt();
    assert!(
        (estimate - volume).abs() < 4.0 * sigma,
        "MC volume {estimate:e} ± {sigma:e} vs {volume:e}"
    );
}
