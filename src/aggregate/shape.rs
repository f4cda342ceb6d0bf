//! Shapes that aggregates are carved from (Zhang17 §2.3.2 carves its packings with the Didymos primary's shape
//! model; a particle is kept when its centre is inside, so grains stick out of the surface by up to a radius, as
//! in the paper's Fig. 4).
//!
//! One enum, [`Shape`], with `contains(p)` and an exact volume: a sphere, a triaxial ellipsoid, the Didymos primary
//! with Naidu et al. (2020)'s extents ([`TriaxialTop`], the nominal shape of the Zhang17 scenes), the axisymmetric
//! Didymos-like "top" ([`Top`], the shape of our Zhang17 runs before Dec 2026), and any closed triangulated OBJ
//! model ([`crate::geometry::polyhedron::Polyhedron`]).

use std::path::Path;

use crate::aggregate::triaxial_top::TriaxialTop;
use crate::geometry::polyhedron::Polyhedron;
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
    /// use rubblepile::aggregate::shape::Top;
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

/// A shape to carve an aggregate from, centred on the origin (an OBJ keeps its own frame).
#[derive(Debug, Clone)]
pub enum Shape {
    /// A sphere of this radius (m).
    Sphere {
        /// Radius (m).
        radius: f64,
    },
    /// A triaxial ellipsoid with these semi-axes along x, y, z (m).
    Ellipsoid {
        /// Semi-axes (m).
        axes: [f64; 3],
    },
    /// The Didymos-like top ([`Top`]).
    Top(Top),
    /// A triaxial top with a given volume ([`TriaxialTop`]; Naidu et al. 2020's Didymos by default).
    TriaxialTop(TriaxialTop),
    /// A closed triangulated model, with the path it was read from.
    Polyhedron {
        /// The model (m).
        model: Box<Polyhedron>,
        /// Where it came from (for reports).
        source: String,
    },
}

/// Why a shape specification was refused.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("--shape: {0}")]
pub struct ShapeSpecError(pub String);

impl Shape {
    /// Parses `sphere:R`, `ellipsoid:A,B,C` (semi-axes), `top` or `top:D_EQ` (volume-equivalent diameter,
    /// default 780 m), `didymos` or `didymos:LX,LY,LZ,D_EQ` (a [`TriaxialTop`] of full extents LX, LY, LZ and
    /// volume-equivalent diameter D_EQ; default Naidu et al. 2020's 832, 838, 786 and 780 m), or `obj:PATH`
    /// (coordinates multiplied by `obj_scale`, e.g. 1000 for km); lengths in m.
    ///
    /// ```
    /// use rubblepile::aggregate::shape::Shape;
    /// assert!((Shape::parse("sphere:2", 1.0).unwrap().volume() - 32.0 / 3.0 * std::f64::consts::PI).abs() < 1e-12);
    /// assert!(Shape::parse("sphere:-2", 1.0).is_err());
    /// assert!(Shape::parse("cube:2", 1.0).is_err());
    /// ```
    pub fn parse(spec: &str, obj_scale: f64) -> Result<Shape, ShapeSpecError> {
        let (kind, arg) = spec.split_once(':').unwrap_or((spec, ""));
        let numbers = |n: usize, what: &str| -> Result<Vec<f64>, ShapeSpecError> {
            let v: Vec<f64> = arg
                .split(',')
                .map(|s| s.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| {
                    ShapeSpecError(format!(
                        "`{spec}`: expected {kind}:{what} with {n} positive number(s) in m"
                    ))
                })?;
            if v.len() != n || v.iter().any(|x| !(x.is_finite() && *x > 0.0)) {
                return Err(ShapeSpecError(format!(
                    "`{spec}`: expected {kind}:{what} with {n} positive number(s) in m"
                )));
            }
            Ok(v)
        };
        match kind {
            "sphere" => Ok(Shape::Sphere {
                radius: numbers(1, "RADIUS")?[0],
            }),
            "ellipsoid" => {
                let v = numbers(3, "A,B,C")?;
                Ok(Shape::Ellipsoid {
                    axes: [v[0], v[1], v[2]],
                })
            }
            "top" if arg.is_empty() => Ok(Shape::Top(Top::didymos(780.0))),
            "top" => Ok(Shape::Top(Top::didymos(numbers(1, "EQUIVALENT_DIAMETER")?[0]))),
            "didymos" if arg.is_empty() => Ok(Shape::TriaxialTop(TriaxialTop::didymos_naidu2020())),
            "didymos" => {
                let v = numbers(4, "LX,LY,LZ,EQUIVALENT_DIAMETER")?;
                TriaxialTop::new([v[0], v[1], v[2]], v[3])
                    .map(Shape::TriaxialTop)
                    .map_err(|e| ShapeSpecError(format!("`{spec}`: {e}")))
            }
            "obj" => {
                if arg.is_empty() {
                    return Err(ShapeSpecError(format!("`{spec}`: expected obj:PATH")));
                }
                if !(obj_scale.is_finite() && obj_scale > 0.0) {
                    return Err(ShapeSpecError(format!(
                        "--obj-scale must be a positive number, got {obj_scale}"
                    )));
                }
                let model =
                    Polyhedron::from_obj(Path::new(arg), obj_scale).map_err(|e| ShapeSpecError(e.to_string()))?;
                if model.triangles.len() < 4 || model.volume() <= 0.0 {
                    return Err(ShapeSpecError(format!(
                        "{arg}: not a closed outward-facing surface (volume {:e} m³, {} triangles)",
                        model.volume(),
                        model.triangles.len()
                    )));
                }
                Ok(Shape::Polyhedron {
                    model: Box::new(model),
                    source: arg.to_string(),
                })
            }
            _ => Err(ShapeSpecError(format!(
                "unknown shape `{spec}`; expected sphere:R, ellipsoid:A,B,C, top[:D_EQ], didymos[:LX,LY,LZ,D_EQ] or obj:PATH"
            ))),
        }
    }

    /// Whether `p` (m) is inside.
    pub fn contains(&self, p: &Vec3) -> bool {
        match self {
            Shape::Sphere { radius } => p.norm_squared() <= radius * radius,
            Shape::Ellipsoid { axes } => (0..3).map(|k| (p[k] / axes[k]).powi(2)).sum::<f64>() <= 1.0,
            Shape::Top(t) => t.contains(p),
            Shape::TriaxialTop(t) => t.contains(p),
            Shape::Polyhedron { model, .. } => model.contains(p),
        }
    }

    /// Volume (m³).
    pub fn volume(&self) -> f64 {
        let ball = 4.0 / 3.0 * std::f64::consts::PI;
        match self {
            Shape::Sphere { radius } => ball * radius.powi(3),
            Shape::Ellipsoid { axes } => ball * axes[0] * axes[1] * axes[2],
            Shape::Top(t) => t.volume(),
            Shape::TriaxialTop(t) => t.volume(),
            Shape::Polyhedron { model, .. } => model.volume(),
        }
    }

    /// Radius (m) of a ball about the origin that contains the shape.
    pub fn bounding_radius(&self) -> f64 {
        match self {
            Shape::Sphere { radius } => *radius,
            Shape::Ellipsoid { axes } => axes.iter().cloned().fold(0.0, f64::max),
            Shape::Top(t) => t.ridge_radius.max(t.polar),
            Shape::TriaxialTop(t) => t.semi_extents.iter().cloned().fold(0.0, f64::max),
            Shape::Polyhedron { model, .. } => model.vertices.iter().map(|v| v.norm()).fold(0.0, f64::max),
        }
    }

    /// Volume-equivalent diameter (m).
    pub fn equivalent_diameter(&self) -> f64 {
        (6.0 * self.volume() / std::f64::consts::PI).cbrt()
    }

    /// A one-line description for reports.
    pub fn describe(&self) -> String {
        match self {
            Shape::Sphere { radius } => format!("sphere radius {radius} m"),
            Shape::Ellipsoid { axes } => format!("ellipsoid semi-axes {} {} {} m", axes[0], axes[1], axes[2]),
            Shape::Top(t) => format!(
                "top (oblate spheroid a_s {:.3} m, c {:.3} m, with an equatorial ridge A {:.3} m, cone apex h {:.3} m)",
                t.spheroid_equatorial, t.polar, t.ridge_radius, t.cone_height
            ),
            Shape::TriaxialTop(t) => format!(
                "triaxial top (extents {} × {} × {} m, ridge excess {:.4}, volume-equivalent diameter {:.3} m)",
                2.0 * t.semi_extents[0],
                2.0 * t.semi_extents[1],
                2.0 * t.semi_extents[2],
                t.ridge_excess(),
                t.equivalent_diameter()
            ),
            Shape::Polyhedron { model, source } => format!("obj {source} ({} triangles)", model.triangles.len()),
        }
    }

    /// Whether `p` lies at least `depth` (m) inside: `p` and the 14 points `p + depth u` (u along the 6 axis
    /// directions and the 8 cube diagonals) are all inside. Used to pick the interior particles of a packing.
    pub fn contains_with_margin(&self, p: &Vec3, depth: f64) -> bool {
        if !self.contains(p) {
            return false;
        }
        let d = depth / 3f64.sqrt();
        let mut probes = Vec::with_capacity(14);
        for k in 0..3 {
            for s in [-1.0, 1.0] {
                let mut u = Vec3::zeros();
                u[k] = s * depth;
                probes.push(u);
            }
        }
        for sx in [-d, d] {
            for sy in [-d, d] {
                for sz in [-d, d] {
                    probes.push(Vec3::new(sx, sy, sz));
                }
            }
        }
        probes.iter().all(|u| self.contains(&(p + u)))
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
