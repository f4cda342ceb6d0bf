//! The second zonal harmonic (J2) of an oblate planet, the leading correction to its point-mass field (Murray &
//! Dermott 1999, *Solar System Dynamics*, §4.9; Kaula 1966). With `d` relative to the planet's centre, `r = |d|`,
//! `z = d·k̂` along the spin axis `k̂`, `R` the reference radius: `Φ_J2(d) = (G M J2 R² / 2) (3 z² − r²) / r⁵` (J/kg),
//! the part of `Φ = −(GM/r) [1 − J2 (R/r)² P₂(z/r)]` beyond the monopole, and
//! `g_J2 = −∇Φ_J2 = (G M J2 R² / 2) r⁻⁵ [(15 z²/r² − 3) d − 6 z k̂]` (m/s²). Earth: J2 = 1.0826e-3, R = 6378.137 km.
//!
//! ```
//! use rubblepile::gravity::zonal::J2Field;
//! use rubblepile::math::Vec3;
//! // Over the pole an oblate planet pulls less than a point mass: the J2 term points outward, 3 GM J2 R²/r⁴.
//! let field = J2Field::new(1.0, 1e-3, 1.0, Vec3::z());
//! let g = field.acceleration(&Vec3::new(0.0, 0.0, 2.0));
//! assert!((g.z - 3.0e-3 / 16.0).abs() < 1e-18 && g.x == 0.0);
//! ```

use crate::math::Vec3;

/// The J2 part of a planet's field.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct J2Field {
    /// `G M J2 R² / 2` (m⁵ s⁻²).
    pub strength: f64,
    /// The planet's spin axis `k̂` (unit vector, frame coordinates).
    pub pole: Vec3,
}

impl J2Field {
    /// The field of a planet with `gm` (m³ s⁻²), `j2` (dimensionless), reference radius `radius` (m) and spin
    /// axis `pole` (any non-zero vector; normalised here).
    pub fn new(gm: f64, j2: f64, radius: f64, pole: Vec3) -> Self {
        J2Field {
            strength: 0.5 * gm * j2 * radius * radius,
            pole: pole.normalize(),
        }
    }

    /// `Φ_J2` (J/kg) at `d` (m) from the planet's centre.
    pub fn potential(&self, d: &Vec3) -> f64 {
        let r2 = d.norm_squared();
        let z = d.dot(&self.pole);
        let r5 = r2 * r2 * r2.sqrt();
        self.strength * (3.0 * z * z - r2) / r5
    }

    /// `g_J2 = −∇Φ_J2` (m/s²) at `d` (m) from the planet's centre.
    pub fn acceleration(&self, d: &Vec3) -> Vec3 {
        let r2 = d.norm_squared();
        let z = d.dot(&self.pole);
        let r5 = r2 * r2 * r2.sqrt();
        let s = self.strength / r5;
        d * (s * (15.0 * z * z / r2 - 3.0)) - self.pole * (s * 6.0 * z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The acceleration is minus the gradient of the potential (central differences, relative 1e-8), at points
    /// all around a planet with a tilted pole.
    #[test]
    fn acceleration_is_minus_the_gradient_of_the_potential() {
        let field = J2Field::new(3.986e14, 1.0826e-3, 6.378e6, Vec3::new(0.3, -0.2, 1.0));
        for d in [
            Vec3::new(7e6, 0.0, 0.0),
            Vec3::new(-2e6, 9e6, 3e6),
            Vec3::new(1e6, -1e6, -3e7),
            Vec3::new(4e7, 2e7, -1e7),
        ] {
            let h = 1e-4 * d.norm();
            let fd = Vec3::from_fn(|k, _| {
                let mut e = Vec3::zeros();
                e[k] = h;
                -(field.potential(&(d + e)) - field.potential(&(d - e))) / (2.0 * h)
            });
            let g = field.acceleration(&d);
            assert!((g - fd).norm() < 1e-7 * g.norm(), "at {d:?}: {g:?} vs {fd:?}");
        }
    }

    /// On the equator the J2 term adds an inward pull of `(3/2) GM J2 R² / r⁴` (the textbook value).
    #[test]
    fn equatorial_pull_matches_the_textbook_value() {
        let (gm, j2, radius, r) = (3.986e14, 1.0826e-3, 6.378e6, 2e7);
        let field = J2Field::new(gm, j2, radius, Vec3::z());
        let g = field.acceleration(&Vec3::new(0.0, r, 0.0));
        let expected = -1.5 * gm * j2 * radius * radius / r.powi(4);
        assert!(
            (g.y - expected).abs() < 1e-14 * expected.abs() && g.x == 0.0 && g.z == 0.0,
            "{g:?}"
        );
    }
}
