//! Octree self-gravity against direct summation on 10 000 particles (uniform ball, clumpy distribution, many
//! small isolated clusters whose leaves are used whole): RMS relative force error ≤ 1e-3 at θ = 0.5, falling
//! with θ (the interior field of a uniform ball is checked in the octree's unit tests).

use rubblepile::gravity::direct;
use rubblepile::gravity::octree::Octree;
use rubblepile::math::Vec3;
use rubblepile::random::{generator, point_in_ball, uniform};

fn rms_error(x: &[Vec3], m: &[f64], theta: f64, exact: &[Vec3]) -> f64 {
    let (tree, _) = Octree::build(x, m).accelerations(theta, 1.0);
    let sum: f64 = tree
        .iter()
        .zip(exact)
        .map(|(a, e)| ((a - e).norm() / e.norm()).powi(2))
        .sum();
    (sum / x.len() as f64).sqrt()
}

fn check(name: &str, x: &[Vec3]) {
    let m = vec![1.0; x.len()];
    let (exact, _) = direct(x, &m, 1.0);
    let errors: Vec<f64> = [0.3, 0.5, 0.7].iter().map(|&t| rms_error(x, &m, t, &exact)).collect();
    println!(
        "{name}: RMS relative force error at theta 0.3/0.5/0.7 = {:.2e} / {:.2e} / {:.2e}",
        errors[0], errors[1], errors[2]
    );
    assert!(errors[1] <= 1e-3, "{name}: {:e} at theta = 0.5", errors[1]);
    assert!(
        errors[0] < errors[1] && errors[1] < errors[2],
        "{name}: error does not fall with theta: {errors:?}"
    );
}

#[test]
fn tree_matches_direct_on_a_uniform_ball() {
    let mut rng = generator(7);
    let x: Vec<Vec3> = (0..10_000).map(|_| point_in_ball(&mut rng, 100.0)).collect();
    check("uniform ball", &x);
}

#[test]
fn tree_matches_direct_on_a_clumpy_distribution() {
    let mut rng = generator(8);
    let centres: Vec<(Vec3, f64)> = (0..20)
        .map(|_| (point_in_ball(&mut rng, 100.0), 2.0 + 15.0 * uniform(&mut rng)))
        .collect();
    let x: Vec<Vec3> = (0..10_000)
        .map(|k| {
            let (c, s) = centres[k % centres.len()];
            c + point_in_ball(&mut rng, s)
        })
        .collect();
    check("clumpy", &x);
}

#[test]
fn far_leaves_of_small_clusters_match_direct() {
    // 2 000 clusters (radius 2) in a ball of radius 100, each of `FAR_LEAF_MIN + 1` particles: an
    // isolated cluster is one leaf, used by its multipole beyond the opening distance.
    let size = rubblepile::gravity::octree::FAR_LEAF_MIN + 1;
    let mut rng = generator(9);
    let mut x = Vec::new();
    for _ in 0..2000 {
        let c = point_in_ball(&mut rng, 100.0);
        for _ in 0..size {
            x.push(c + point_in_ball(&mut rng, 2.0));
        }
    }
    check("small clusters", &x);
}

#[test]
fn far_leaves_of_a_lattice_ball_match_direct() {
    // The FCC ball of the benchmarks and spin-up scenes: its small leaves hold a few lattice sites at their
    // cube's corners, the worst case for a leaf's quadrupole.
    let x: Vec<Vec3> = rubblepile::granular::soft::packing::fcc_ball(2000, 10.0, 2000.0, 0.0)
        .iter()
        .map(|p| p.position)
        .collect();
    check("FCC ball", &x);
}
