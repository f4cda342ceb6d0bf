//! A cylinder wall for soft spheres (a drum): the surface at radius `R` about an axis through `centre`, infinite or
//! of length `L` centred on `centre`, open-ended. As for the hard-sphere cylinder (Richardson11 §2.2) both faces are
//! walls: a sphere whose centre is inside touches the inner face, one outside the outer face, and near the rims of
//! a finite cylinder the nearest point is on the rim circle. The contact is Zhang17's wall contact (§2.1), the same
//! spring–dashpot–slider law as the plane's; the cylinder may oscillate and spin about its axis, its surface then
//! moving with `Ω â × ρ` and its spin entering the twisting and rolling laws as the partner's.
//!
//! The nearest surface point is the hard-sphere primitive's (`walls::cylinder::nearest`) taken in the plane through
//! the axis and the sphere's centre, where the surface is axisymmetric.

use super::super::motion::Oscillation;
use super::touch::{WallTouch, motion};
use crate::math::Vec3;

/// A cylinder wall (sizes in m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cylinder {
    /// Centre of the axis segment at rest (m).
    pub centre: Vec3,
    /// Unit axis.
    pub axis: Vec3,
    /// Radius `R` (m, > 0).
    pub radius: f64,
    /// Length `L` (m, > 0) along the axis, centred on `centre`; `None` = infinite.
    pub length: Option<f64>,
    /// Optional oscillation of the whole cylinder.
    pub oscillation: Option<Oscillation>,
    /// Spin `Ω` about the axis (rad/s, right-handed).
    pub spin: f64,
}

impl Cylinder {
    /// Contact of a sphere (`centre`, `radius`) with the cylinder's surface at time `t` (s), if they overlap.
    ///
    /// ```
    /// use rubblepile::geometry::walls::soft::Cylinder;
    /// use rubblepile::math::Vec3;
    /// let drum = Cylinder { centre: Vec3::zeros(), axis: Vec3::y(), radius: 1.0, length: None, oscillation: None, spin: 0.0 };
    /// let touch = drum.touch(&Vec3::new(0.0, 0.0, -0.91), 0.1, 0.0).unwrap();
    /// assert!((touch.overlap - 0.01).abs() < 1e-12 && (touch.normal + Vec3::z()).norm() < 1e-12);
    /// ```
    pub fn touch(&self, centre: &Vec3, radius: f64, t: f64) -> Option<WallTouch> {
        let (offset, velocity) = motion(&self.oscillation, t);
        let origin = self.centre + offset;
        let d = centre - origin;
        let z = d.dot(&self.axis);
        let radial = d - self.axis * z;
        let rho = radial.norm();
        let e_rho = if rho > 0.0 {
            radial / rho
        } else {
            any_normal(&self.axis)
        };
        // In the half-plane (ê_ρ, â) through the sphere's centre the surface is the primitive's at azimuth 0.
        let (distance, n) =
            crate::geometry::walls::cylinder::nearest(&Vec3::new(rho, 0.0, z), self.radius, self.length);
        let overlap = radius - distance;
        if overlap <= 0.0 {
            return None;
        }
        // From the nearest surface point towards the sphere's centre.
        let outward = e_rho * n.x + self.axis * n.z;
        let contact = centre - outward * distance;
        let wall_spin = self.axis * self.spin;
        Some(WallTouch {
            normal: -outward,
            overlap,
            wall_velocity: velocity + wall_spin.cross(&(contact - origin)),
            wall_spin,
        })
    }
}

/// A unit vector normal to the unit vector `a`.
fn any_normal(a: &Vec3) -> Vec3 {
    let helper = if a.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() };
    (helper - a * a.dot(&helper)).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drum(length: Option<f64>) -> Cylinder {
        Cylinder {
            centre: Vec3::new(0.5, -1.0, 2.0),
            axis: Vec3::new(1.0, 2.0, 2.0) / 3.0,
            radius: 1.5,
            length,
            oscillation: None,
            spin: 0.0,
        }
    }

    /// A point at radial distance `rho` and axial position `z` in the drum's frame, at azimuth `phi`.
    fn at(c: &Cylinder, rho: f64, z: f64, phi: f64) -> Vec3 {
        let e1 = any_normal(&c.axis);
        let e2 = c.axis.cross(&e1);
        c.centre + (e1 * phi.cos() + e2 * phi.sin()) * rho + c.axis * z
    }

    /// Inside, the overlap is `ρ + r − R` and the normal points radially out (towards the wall); outside, `R + r − ρ`
    /// and radially in; beyond the end of a finite cylinder, the rim is touched like a ring.
    #[test]
    fn overlap_and_normal_are_the_distance_to_the_surface() {
        let c = drum(None);
        for phi in [0.0, 1.0, 2.5, -2.0] {
            let inside = at(&c, 1.45, 3.0, phi);
            let t = c.touch(&inside, 0.1, 0.0).unwrap();
            assert!((t.overlap - 0.05).abs() < 1e-12, "{t:?}");
            let radial = (at(&c, 1.0, 3.0, phi) - at(&c, 0.0, 3.0, phi)).normalize();
            assert!((t.normal - radial).norm() < 1e-12, "{t:?}");
            let outside = at(&c, 1.56, -7.0, phi);
            let t = c.touch(&outside, 0.1, 0.0).unwrap();
            assert!(
                (t.overlap - 0.04).abs() < 1e-12 && (t.normal + radial).norm() < 1e-12,
                "{t:?}"
            );
            assert!(c.touch(&at(&c, 1.3, 0.0, phi), 0.1, 0.0).is_none());
        }
        let finite = drum(Some(2.0));
        assert!(finite.touch(&at(&finite, 1.45, 1.5, 0.3), 0.1, 0.0).is_none());
        // Beyond the rim at z = 1, 0.06 above it and 0.08 outside: distance 0.1 from the rim circle.
        let t = finite.touch(&at(&finite, 1.58, 1.06, 0.3), 0.11, 0.0).unwrap();
        assert!((t.overlap - 0.01).abs() < 1e-12, "{t:?}");
    }

    /// A spinning drum's surface moves with `Ω â × ρ` at the contact point (speed `Ω R`) and its spin is `Ω â`.
    #[test]
    fn spinning_drum_moves_its_surface_tangentially() {
        let mut c = drum(None);
        c.spin = 2.0;
        let p = at(&c, 1.45, 0.7, 0.4);
        let t = c.touch(&p, 0.1, 0.0).unwrap();
        assert!((t.wall_velocity.norm() - 2.0 * 1.5).abs() < 1e-12);
        assert!(t.wall_velocity.dot(&t.normal).abs() < 1e-12 && t.wall_velocity.dot(&c.axis).abs() < 1e-12);
        assert_eq!(t.wall_spin, c.axis * 2.0);
    }
}
