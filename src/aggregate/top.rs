//! The axisymmetric Didymos-like top ([`Top`]): the shape our earlier Zhang17 runs were carved from, kept as
//! the named variant `--shape top`, and the unit figure that the `triaxial_top` module stretches to
//! Naidu et al. (2020)'s extents.

use crate::math::Vec3;

/// A Didymos-like top: an oblate spheroid with an equatorial ridge, symmetric about z.
///
/// Definition. In cylindrical coordinates `(s, z)` the inside is `|z| ≤ c_s` and `s ≤ S(z)` with
/// `S(z) = max(a_s √(1 − z²/c_s²), A (1 − |z|/h))`: the union of the spheroid (semi-axes `a_s, a_s, c_s`) and a
/// double cone (bicone) of equatorial radius `A = (1 + δ) a_s` and apex height `h`. The cone rises above the
/// spheroid only in a band about the equator, where it forms a sharp ridge of flank slope `atan(h/A)` to the
/// equatorial plane; above that band the body is the spheroid.
///
/// Chosen numbers ([`Top::didymos`]): overall polar-to-equatorial ratio `c_s / A = 0.84` (our reading of
/// the pre-DART radar model of the Didymos primary: c/a ≈ 0.83–0.85 with a ridge at the equator), ridge excess
/// `δ = 0.04` (the ridge stands 4 % beyond the spheroid's equator), `h = A/2` (flanks at 26.6°), and the whole
/// figure scaled so that its volume-equivalent diameter is exactly the one asked for (780 m for Didymos,
/// Zhang17 Table 1). The axes are those of the body: z is the spin (maximum-moment) axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Top {
    /// Equatorial radius of the spheroid `a_s` (m).
    pub spheroid_equatorial: f64,
    /// Polar semi-axis `c_s` (m), also the body's polar semi-axis.
    pub polar: f64,
    /// Equatorial radius of the ridge `A` (m), the body's equatorial semi-axis.
    pub ridge_radius: f64,
    /// Apex height of the bicone `h` (m).
    pub cone_height: f64,
}

impl Top {
    /// Overall polar/equatorial axis ratio of [`Top::didymos`].
    pub const C_OVER_A: f64 = 0.84;
    /// Ridge excess δ of [`Top::didymos`].
    pub const RIDGE_EXCESS: f64 = 0.04;
    /// Bicone apex height over the ridge radius, `h/A`, of [`Top::didymos`].
    pub const CONE_HEIGHT_OVER_A: f64 = 0.5;

    /// The Didymos-like top of volume-equivalent diameter `d_eq` (m).
    ///
    /// ```
    /// use rubblepile::aggregate::top::Top;
    /// let t = Top::didymos(780.0);
    /// let d = (6.0 * t.volume() / std::f64::consts::PI).cbrt();
    /// assert!((d - 780.0).abs() < 1e-9);
    /// assert!((t.polar / t.ridge_radius - 0.84).abs() < 1e-12);
    /// ```
    pub fn didymos(d_eq: f64) -> Self {
        let unit = Top::from_ridge_radius(1.0);
        let v_target = std::f64::consts::PI / 6.0 * d_eq.powi(3);
        Top::from_ridge_radius((v_target / unit.volume()).cbrt())
    }

    fn from_ridge_radius(a: f64) -> Self {
        Top {
            spheroid_equatorial: a / (1.0 + Top::RIDGE_EXCESS),
            polar: Top::C_OVER_A * a,
            ridge_radius: a,
            cone_height: Top::CONE_HEIGHT_OVER_A * a,
        }
    }

    fn spheroid_profile(&self, z: f64) -> f64 {
        self.spheroid_equatorial * (1.0 - (z / self.polar).powi(2)).max(0.0).sqrt()
    }

    fn cone_profile(&self, z: f64) -> f64 {
        (self.ridge_radius * (1.0 - z.abs() / self.cone_height)).max(0.0)
    }

    /// Height `z* > 0` where the cone's profile meets the spheroid's (bisection; the difference of a linear and
    /// a concave function is convex, positive at 0 and negative at the apex, so the root is unique).
    fn crossing(&self) -> f64 {
        let f = |z: f64| self.cone_profile(z) - self.spheroid_profile(z);
        let (mut lo, mut hi) = (0.0, self.cone_height.min(self.polar));
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if f(mid) > 0.0 { lo = mid } else { hi = mid }
        }
        0.5 * (lo + hi)
    }

    /// Radius of the body's cross-section at height `z` (m).
    pub fn profile(&self, z: f64) -> f64 {
        if z.abs() > self.polar {
            return 0.0;
        }
        self.spheroid_profile(z).max(self.cone_profile(z))
    }

    /// Exact volume (m³): `2π [∫₀^{z*} A²(1 − z/h)² dz + ∫_{z*}^{c} a_s²(1 − z²/c²) dz]`.
    pub fn volume(&self) -> f64 {
        let (a, c, big_a, h) = (
            self.spheroid_equatorial,
            self.polar,
            self.ridge_radius,
            self.cone_height,
        );
        let zs = self.crossing();
        let cone = big_a * big_a * h / 3.0 * (1.0 - (1.0 - zs / h).powi(3));
        let spheroid = a * a * ((c - zs) - (c.powi(3) - zs.powi(3)) / (3.0 * c * c));
        std::f64::consts::TAU * (cone + spheroid)
    }

    /// Whether `p` (m) is inside.
    pub fn contains(&self, p: &Vec3) -> bool {
        p.z.abs() <= self.polar && p.x.hypot(p.y) <= self.profile(p.z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::{generator, symmetric};

    /// Guards the top's exact volume against a Monte Carlo count of `contains` in its bounding box.
    #[test]
    fn top_volume_matches_monte_carlo() {
        let t = Top::didymos(780.0);
        let (a, c) = (t.ridge_radius, t.polar);
        let mut rng = generator(3);
        let n = 400_000;
        let inside = (0..n)
            .filter(|_| {
                t.contains(&Vec3::new(
                    symmetric(&mut rng, a),
                    symmetric(&mut rng, a),
                    symmetric(&mut rng, c),
                ))
            })
            .count();
        let estimate = inside as f64 / n as f64 * 8.0 * a * a * c;
        let sigma = (estimate * (8.0 * a * a * c - estimate) / n as f64).sqrt();
        assert!(
            (estimate - t.volume()).abs() < 4.0 * sigma,
            "{estimate:e} vs {:e}",
            t.volume()
        );
        // the ridge really is there: the equator reaches A, just above it the spheroid's radius is smaller
        assert!(t.profile(0.0) == a && t.profile(0.3 * c) < a);
    }
}
