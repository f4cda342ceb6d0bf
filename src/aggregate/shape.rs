//! Shapes that aggregates are carved from (Zhang17 §2.3.2 carves its packings with the Didymos primary's shape
//! model; a particle is kept when its centre is inside, so grains stick out of the surface by up to a radius, as
//! in the paper's Fig. 4).
//!
//! One enum, [`Shape`], with `contains(p)` and an exact volume: a sphere, a triaxial ellipsoid, the Didymos primary
//! with Naidu et al. (2020)'s extents ([`TriaxialTop`], the nominal shape of the Zhang17 scenes), the axisymmetric
//! Didymos-like "top" ([`Top`], the shape of our earlier Zhang17 runs), and any closed triangulated OBJ
//! model ([`crate::geometry::polyhedron::Polyhedron`]).

use std::path::Path;

pub use crate::aggregate::top::Top;
use crate::aggregate::triaxial_top::TriaxialTop;
use crate::geometry::polyhedron::Polyhedron;
use crate::math::Vec3;

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
            let bad = || {
                ShapeSpecError(format!(
                    "`{spec}`: expected {kind}:{what} with {n} positive number(s) in m"
                ))
            };
            let v: Vec<f64> = arg
                .split(',')
                .map(|s| s.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| bad())?;
            if v.len() != n || v.iter().any(|x| !(x.is_finite() && *x > 0.0)) {
                return Err(bad());
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
