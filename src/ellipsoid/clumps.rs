//! Clumps: connected sets of touching bodies, the contact graph behind every clump of the crate (`analysis::clumps`,
//! which refines them by boundness; `analysis::composition`; fragments shed during the target build,
//! `impact::target`). Two bodies are linked when their ellipsoids, each enlarged about its centre, overlap
//! ([`are_apart`]); clumps are the connected components (friends of friends, union–find). [`Linking`]:
//!
//! - [`Linking::SurfaceGap`]`(f)`, after pkdgrav's companion finder: linked when the surface gap is at most
//!   `ℓ = f · min(cᵢ, cⱼ)` (`c` the smallest semi-axis). Each body is scaled by `1 + ℓ/(2c)`; since the support
//!   function obeys `h(u) + s c ≤ (1 + s) h(u) ≤ h(u) + s a`, every gap ≤ ℓ is linked and none above
//!   `ℓ (aᵢ/cᵢ + aⱼ/cⱼ)/2`: exact for spheres.
//! - [`Linking::ScaledAxes`]`(m)`: every semi-axis times `1 + m` (target build, composition).
//!
//! Resting bodies sit in shallow overlap under the contact barrier (Roig03 Eqs. 12–13) and are linked by either rule.

use crate::ellipsoid::body::Body;
use crate::ellipsoid::quaternion::rotation_matrix;
use crate::geometry::ellipsoid_overlap::are_apart;
use crate::geometry::neighbours::sphere_pairs;
use crate::math::Mat3;

/// The default linking length of [`Linking::SurfaceGap`]: 0.1 of the smaller body's smallest semi-axis.
pub const DEFAULT_GAP_FRACTION: f64 = 0.1;

/// Which bodies are linked (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Linking {
    /// Surface gap at most this fraction (dimensionless, ≥ 0) of the smaller smallest semi-axis of the pair.
    SurfaceGap(f64),
    /// Semi-axes times `1 +` this margin (dimensionless, ≥ 0).
    ScaledAxes(f64),
}

impl Linking {
    /// The scale factor of body `b` in a pair whose other body's smallest semi-axis is `c_other` (m).
    fn scale(self, b: &Body, c_other: f64) -> f64 {
        match self {
            Linking::SurfaceGap(f) => 1.0 + f * b.shape.axes.z.min(c_other) / (2.0 * b.shape.axes.z),
            Linking::ScaledAxes(m) => 1.0 + m,
        }
    }

    /// The largest scale factor body `b` can get in any pair.
    fn max_scale(self) -> f64 {
        match self {
            Linking::SurfaceGap(f) => 1.0 + 0.5 * f,
            Linking::ScaledAxes(m) => 1.0 + m,
        }
    }
}

/// World-frame shape matrix `Rᵀ diag(a², b², c²) R` with every semi-axis times `scale`.
pub(crate) fn shape_matrix(b: &Body, scale: f64) -> Mat3 {
    let r = rotation_matrix(&b.quaternion);
    let axes = b.shape.axes * scale;
    r.transpose() * Mat3::from_diagonal(&axes.component_mul(&axes)) * r
}

/// Root of `i` in a union–find forest, halving the path on the way.
fn root(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// The clumps of `bodies` (connected components of the linking graph), as lists of body indices, each list
/// ascending, the lists ordered by their first index.
///
/// ```
/// use rubblepile::ellipsoid::body::{Body, Ellipsoid};
/// use rubblepile::ellipsoid::clumps::{Linking, find_clumps};
/// use rubblepile::math::{Vec3, Vec4};
/// let sphere = |x: f64| Body {
///     shape: Ellipsoid { axes: Vec3::new(1.0, 1.0, 1.0), mass: 1.0 },
///     position: Vec3::new(x, 0.0, 0.0),
///     velocity: Vec3::zeros(),
///     quaternion: Vec4::new(0.0, 0.0, 0.0, 1.0),
///     spin_body: Vec3::zeros(),
/// };
/// // unit spheres 2.05 apart (gap 0.05) are linked by a gap of 0.1 radii; the third, 10 radii away, is alone
/// let bodies = [sphere(0.0), sphere(2.05), sphere(12.0)];
/// assert_eq!(find_clumps(&bodies, Linking::SurfaceGap(0.1)), vec![vec![0, 1], vec![2]]);
/// ```
pub fn find_clumps(bodies: &[Body], linking: Linking) -> Vec<Vec<usize>> {
    let all: Vec<usize> = (0..bodies.len()).collect();
    find_clumps_among(bodies, &all, linking)
}

/// The clumps of the bodies `ids` (indices into `bodies`) alone, as [`find_clumps`] gives them for all bodies:
/// lists of indices into `bodies`, each ascending, ordered by their first index.
pub fn find_clumps_among(bodies: &[Body], ids: &[usize], linking: Linking) -> Vec<Vec<usize>> {
    let mut ids = ids.to_vec();
    ids.sort_unstable();
    // Candidates: bodies whose bounding spheres at their largest scale overlap, found on a grid.
    let centres: Vec<_> = ids.iter().map(|&i| bodies[i].position).collect();
    let reach: Vec<f64> = ids
        .iter()
        .map(|&i| linking.max_scale() * bodies[i].shape.axes.x)
        .collect();
    let mut parent: Vec<usize> = (0..ids.len()).collect();
    for (p, q) in sphere_pairs(&centres, &reach) {
        let (bi, bj) = (&bodies[ids[p]], &bodies[ids[q]]);
        let si = shape_matrix(bi, linking.scale(bi, bj.shape.axes.z));
        let sj = shape_matrix(bj, linking.scale(bj, bi.shape.axes.z));
        if !are_apart(&(bj.position - bi.position), &si, &sj) {
            let (a, b) = (root(&mut parent, p), root(&mut parent, q));
            parent[a.max(b)] = a.min(b);
        }
    }
    let mut clumps: Vec<Vec<usize>> = Vec::new();
    let mut slot = vec![usize::MAX; ids.len()];
    for (p, &id) in ids.iter().enumerate() {
        let r = root(&mut parent, p);
        if slot[r] == usize::MAX {
            slot[r] = clumps.len();
            clumps.push(Vec::new());
        }
        clumps[slot[r]].push(id);
    }
    clumps
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ellipsoid::body::Ellipsoid;
    use crate::math::{Vec3, Vec4};

    fn body(axes: [f64; 3], x: f64, q: Vec4) -> Body {
        Body {
            shape: Ellipsoid {
                axes: Vec3::from(axes),
                mass: 1.0,
            },
            position: Vec3::new(x, 0.0, 0.0),
            velocity: Vec3::zeros(),
            quaternion: q,
            spin_body: Vec3::zeros(),
        }
    }

    /// Spheres: the gap rule is exact, with the linking length of the *smaller* sphere.
    #[test]
    fn sphere_gap_rule_uses_the_smaller_radius() {
        let id = Vec4::new(0.0, 0.0, 0.0, 1.0);
        // radii 1 and 10, ℓ = 0.1 × 1: gap 0.09 linked, gap 0.11 not (with 10 % of the larger radius it would be)
        for (gap, linked) in [(0.09, true), (0.11, false)] {
            let b = [body([1.0; 3], 0.0, id), body([10.0; 3], 11.0 + gap, id)];
            let n = find_clumps(&b, Linking::SurfaceGap(0.1)).len();
            assert_eq!(n, if linked { 1 } else { 2 }, "gap {gap}");
        }
    }

    /// Ellipsoids: a gap ≤ ℓ is always linked (here the long axes point at each other, the worst case of the
    /// bound), and a gap beyond the documented bound `ℓ (a/c + a/c)/2` never is.
    #[test]
    fn ellipsoid_gap_rule_keeps_its_bounds() {
        let id = Vec4::new(0.0, 0.0, 0.0, 1.0);
        let axes = [3.0, 2.0, 1.0];
        let ell = 0.1; // f = 0.1, c = 1
        // long axes along x, facing each other: surface gap = d − 6
        let linked = [body(axes, 0.0, id), body(axes, 6.0 + 0.99 * ell, id)];
        assert_eq!(find_clumps(&linked, Linking::SurfaceGap(0.1)).len(), 1);
        let apart = [body(axes, 0.0, id), body(axes, 6.0 + 1.01 * ell * 3.0, id)];
        assert_eq!(find_clumps(&apart, Linking::SurfaceGap(0.1)).len(), 2);
        // short axes facing (rotated by 90° about y: body z along world x): gap = d − 2, linked at the bound ℓ
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let turned = Vec4::new(0.0, s, 0.0, s);
        let short = [body(axes, 0.0, turned), body(axes, 2.0 + 0.99 * ell, turned)];
        assert_eq!(find_clumps(&short, Linking::SurfaceGap(0.1)).len(), 1);
        let short_apart = [body(axes, 0.0, turned), body(axes, 2.0 + 1.01 * ell, turned)];
        assert_eq!(find_clumps(&short_apart, Linking::SurfaceGap(0.1)).len(), 2);
    }

    /// A subset is linked on its own: the middle of a chain removed leaves two clumps.
    #[test]
    fn clumps_among_a_subset_ignore_the_others() {
        let id = Vec4::new(0.0, 0.0, 0.0, 1.0);
        let chain: Vec<Body> = (0..3).map(|k| body([1.0; 3], 2.0 * k as f64, id)).collect();
        assert_eq!(find_clumps(&chain, Linking::SurfaceGap(0.1)), vec![vec![0, 1, 2]]);
        assert_eq!(
            find_clumps_among(&chain, &[2, 0], Linking::SurfaceGap(0.1)),
            vec![vec![0], vec![2]]
        );
    }
}
