//! Shape of a sphere aggregate: centre of mass, inertia tensor, principal axes, and the semi-axis lengths
//! a ≥ b ≥ c measured as the maximum extents along the principal axes of inertia (Zhang17 §3.1: the
//! axis ratios b/a and c/a whose change defines the first critical spin limit T_c,1).
//!
//! The extents include the sphere radii, so a single sphere has a = b = c = its radius.

use crate::math::{Mat3, Vec3};

/// Semi-axis lengths of an aggregate and the directions they were measured along.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisLengths {
    /// Longest semi-extent (m).
    pub a: f64,
    /// Intermediate semi-extent (m).
    pub b: f64,
    /// Shortest semi-extent (m).
    pub c: f64,
    /// Unit principal axes of inertia along which `a`, `b`, `c` were measured, in that order.
    pub axes: [Vec3; 3],
    /// Centre of mass (m).
    pub centre: Vec3,
}

impl AxisLengths {
    /// b/a (dimensionless).
    pub fn b_over_a(&self) -> f64 {
        self.b / self.a
    }

    /// c/a (dimensionless).
    pub fn c_over_a(&self) -> f64 {
        self.c / self.a
    }
}

/// Centre of mass (m) of point masses `masses` (kg) at `positions` (m); the origin for an empty or massless set.
pub fn centre_of_mass(positions: &[Vec3], masses: &[f64]) -> Vec3 {
    let m: f64 = masses.iter().sum();
    if m <= 0.0 {
        return Vec3::zeros();
    }
    positions.iter().zip(masses).map(|(p, mi)| p * *mi).sum::<Vec3>() / m
}

/// Inertia tensor (kg m²) about `centre` of uniform spheres (mass kg, radius m): the point-mass part plus each
/// sphere's own (2/5) m r².
pub fn inertia_tensor(positions: &[Vec3], masses: &[f64], radii: &[f64], centre: &Vec3) -> Mat3 {
    let mut inertia = Mat3::zeros();
    for ((p, m), r) in positions.iter().zip(masses).zip(radii) {
        let d = p - centre;
        inertia += (Mat3::identity() * (d.norm_squared() + 0.4 * r * r) - d * d.transpose()) * *m;
    }
    inertia
}

/// Semi-axis lengths of spheres (positions m, masses kg, radii m) along the principal axes of inertia.
///
/// Along each principal axis `e` the semi-extent is half of `max(x·e + r) − min(x·e − r)`; the three are sorted
/// so that a ≥ b ≥ c.
///
/// ```
/// use rubblepile::analysis::shape_metrics::axis_lengths;
/// use rubblepile::math::Vec3;
/// // Three spheres of radius 1 m in a row along y: a = 5 m, b = c = 1 m.
/// let x = [Vec3::new(0.0, -4.0, 0.0), Vec3::zeros(), Vec3::new(0.0, 4.0, 0.0)];
/// let ax = axis_lengths(&x, &[1.0; 3], &[1.0; 3]);
/// assert!((ax.a - 5.0).abs() < 1e-12 && (ax.b - 1.0).abs() < 1e-12 && (ax.c - 1.0).abs() < 1e-12);
/// assert!(ax.axes[0].y.abs() > 0.999);
/// ```
pub fn axis_lengths(positions: &[Vec3], masses: &[f64], radii: &[f64]) -> AxisLengths {
    let centre = centre_of_mass(positions, masses);
    let eigen = inertia_tensor(positions, masses, radii, &centre).symmetric_eigen();
    let mut measured: Vec<(f64, Vec3)> = (0..3)
        .map(|k| {
            let e: Vec3 = eigen.eigenvectors.column(k).into_owned().normalize();
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for (p, r) in positions.iter().zip(radii) {
                let s = (p - centre).dot(&e);
                lo = lo.min(s - r);
                hi = hi.max(s + r);
            }
            (0.5 * (hi - lo), e)
        })
        .collect();
    measured.sort_by(|x, y| y.0.total_cmp(&x.0));
    AxisLengths {
        a: measured[0].0,
        b: measured[1].0,
        c: measured[2].0,
        axes: [measured[0].1, measured[1].1, measured[2].1],
        centre,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::lattice::hcp_centres;
    use nalgebra::Rotation3;

    /// Guards the extents against the principal-axis rotation: a lattice-carved ellipsoid, rotated arbitrarily,
    /// gives its semi-axes back to within one lattice spacing, and the axes come back rotated.
    #[test]
    fn rotated_ellipsoid_aggregate_gives_its_semi_axes() {
        let (a, b, c, r) = (10.0, 7.0, 5.0, 0.25);
        let inside: Vec<Vec3> = hcp_centres(r, a)
            .into_iter()
            .filter(|p| (p.x / (a - r)).powi(2) + (p.y / (b - r)).powi(2) + (p.z / (c - r)).powi(2) <= 1.0)
            .collect();
        let rot = Rotation3::from_euler_angles(0.3, -0.7, 1.1);
        let x: Vec<Vec3> = inside.iter().map(|p| rot * p + Vec3::new(3.0, -2.0, 1.0)).collect();
        let n = x.len();
        let ax = axis_lengths(&x, &vec![1.0; n], &vec![r; n]);
        for (got, want) in [(ax.a, a), (ax.b, b), (ax.c, c)] {
            assert!((got - want).abs() < 2.0 * r, "{got} vs {want}");
        }
        assert!((ax.axes[0].dot(&(rot * Vec3::x()))).abs() > 0.999);
        assert!((ax.axes[2].dot(&(rot * Vec3::z()))).abs() > 0.999);
    }
}
