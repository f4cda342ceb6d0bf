//! Clumps: connected sets of ellipsoids in contact. Used by the impact analysis (which bodies stick together, the
//! `analysis::composition` module) and by the target build (fragments that left the pile during its collapse,
//! `impact::target`).
//!
//! Two bodies are in contact when their ellipsoids, each semi-axis enlarged by a relative `margin`, overlap (the
//! overlap test of the contact model, [`are_apart`]). Resting bodies sit in shallow overlap under the contact
//! barrier (Roig03 Eqs. 12–13); the margin also joins those a hair apart.

use crate::ellipsoid::body::Body;
use crate::ellipsoid::quaternion::rotation_matrix;
use crate::geometry::ellipsoid_overlap::are_apart;
use crate::geometry::neighbours::sphere_pairs;
use crate::math::Mat3;

/// World-frame shape matrix `Rᵀ diag(a², b², c²) R` with every semi-axis times `scale`.
fn shape_matrix(b: &Body, scale: f64) -> Mat3 {
    let r = rotation_matrix(&b.quaternion);
    let axes = b.shape.axes * scale;
    r.transpose() * Mat3::from_diagonal(&axes.component_mul(&axes)) * r
}

/// The clumps of `bodies` (connected components of the contact graph with semi-axes enlarged by `margin`,
/// dimensionless), as lists of body indices, each list ascending, the lists ordered by their first index.
///
/// ```
/// use rubblepile::ellipsoid::body::{Body, Ellipsoid};
/// use rubblepile::ellipsoid::clumps::find_clumps;
/// use rubblepile::math::{Vec3, Vec4};
/// let sphere = |x: f64| Body {
///     shape: Ellipsoid { axes: Vec3::new(1.0, 1.0, 1.0), mass: 1.0 },
///     position: Vec3::new(x, 0.0, 0.0),
///     velocity: Vec3::zeros(),
///     quaternion: Vec4::new(0.0, 0.0, 0.0, 1.0),
///     spin_body: Vec3::zeros(),
/// };
/// // two spheres 1.9 radii apart touch; the third, 10 radii away, is alone
/// let clumps = find_clumps(&[sphere(0.0), sphere(1.9), sphere(12.0)], 0.1);
/// assert_eq!(clumps, vec![vec![0, 1], vec![2]]);
/// ```
pub fn find_clumps(bodies: &[Body], margin: f64) -> Vec<Vec<usize>> {
    let scale = 1.0 + margin;
    let sigmas: Vec<Mat3> = bodies.iter().map(|b| shape_matrix(b, scale)).collect();
    // Union–find with path halving.
    let mut parent: Vec<usize> = (0..bodies.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    // Candidates: bodies whose enlarged bounding spheres (the major semi-axis) overlap, found on a grid.
    let centres: Vec<_> = bodies.iter().map(|b| b.position).collect();
    let reach: Vec<f64> = bodies.iter().map(|b| scale * b.shape.axes.x).collect();
    for (i, j) in sphere_pairs(&centres, &reach) {
        let d = bodies[j].position - bodies[i].position;
        if !are_apart(&d, &sigmas[i], &sigmas[j]) {
            let (a, b) = (root(&mut parent, i), root(&mut parent, j));
            parent[a.max(b)] = a.min(b);
        }
    }
    let mut clumps: Vec<Vec<usize>> = Vec::new();
    let mut slot = vec![usize::MAX; bodies.len()];
    for i in 0..bodies.len() {
        let r = root(&mut parent, i);
        if slot[r] == usize::MAX {
            slot[r] = clumps.len();
            clumps.push(Vec::new());
        }
        clumps[slot[r]].push(i);
    }
    clumps
}
