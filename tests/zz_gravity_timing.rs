use rubblepile::ellipsoid::gravity::{add_gravity_forces, gravity_forces};
use rubblepile::math::Vec3;
#[test]
fn timing() {
    let n = 201;
    let pos: Vec<Vec3> = (0..n)
        .map(|i| Vec3::new((i as f64).sin() * 1e4, (i as f64 * 1.3).cos() * 1e4, i as f64 * 10.0))
        .collect();
    let m: Vec<f64> = (0..n).map(|i| 1e15 + i as f64).collect();
    let mut f = vec![Vec3::zeros(); n];
    let reps = 3000;
    let mut best_a = f64::MAX;
    let mut best_b = f64::MAX;
    for _ in 0..5 {
        let t = std::time::Instant::now();
        for _ in 0..reps {
            gravity_forces(6.674e-11, &pos, &m, &mut f);
        }
        best_a = best_a.min(t.elapsed().as_secs_f64() / reps as f64);
        let t = std::time::Instant::now();
        for _ in 0..reps {
            add_gravity_forces(6.674e-11, &pos, &m, &mut f);
        }
        best_b = best_b.min(t.elapsed().as_secs_f64() / reps as f64);
    }
    eprintln!(
        "half loop with potential {:.1} us, rows force-only {:.1} us",
        best_a * 1e6,
        best_b * 1e6
    );
}
