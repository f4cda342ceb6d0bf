//! HCP aggregates (Zhang17 §2.3.2, model "HCP": "the HCP structure can be directly constructed"): the
//! hexagonal close-packed lattice of [`crate::geometry::lattice::hcp_centres`] (packing fraction π/(3√2) ≈ 0.7405),
//! carved by the shape (a sphere is kept when its centre is inside).

use crate::aggregate::shape::Shape;
use crate::geometry::lattice::hcp_centres;
use crate::math::{Mat3, Vec3};

/// Packing fraction of hexagonal close packing, π/(3√2).
pub const HCP_PACKING: f64 = std::f64::consts::PI / (3.0 * std::f64::consts::SQRT_2);

/// Centres (m) of the HCP lattice of spheres of radius `r` (m), with a site at the origin, inside `shape`.
///
/// ```
/// use rubblepile::aggregate::{hcp::hcp_carve, shape::Shape};
/// // a ball of radius 2 r holds the origin and its 12 touching neighbours (centres at distance 2 r)
/// assert_eq!(hcp_carve(&Shape::Sphere { radius: 2.0 + 1e-9 }, 1.0).len(), 13);
/// ```
pub fn hcp_carve(shape: &Shape, r: f64) -> Vec<Vec3> {
    hcp_carve_oriented(shape, r, &Mat3::identity())
}

/// [`hcp_carve`] with the lattice turned by `rotation` (lattice → body coordinates) before carving; see
/// [`crate::aggregate::lattice_orientation`]. The identity leaves the centres bit for bit as [`hcp_carve`]'s.
pub fn hcp_carve_oriented(shape: &Shape, r: f64, rotation: &Mat3) -> Vec<Vec3> {
    hcp_centres(r, shape.bounding_radius())
        .into_iter()
        .map(|p| rotate(rotation, p))
        .filter(|p| shape.contains(p))
        .collect()
}

/// `rotation · p`, exactly `p` for the identity (no −0 or rounding from the zero entries).
pub fn rotate(rotation: &Mat3, p: Vec3) -> Vec3 {
    if *rotation == Mat3::identity() { p } else { rotation * p }
}
