//! Walls in pictures: the surfaces a run's snapshot records for its walls (planes, disks, cylinders, spherical
//! containers — [`crate::engine::NamedSurface`], placed where the walls' prescribed motion had carried them at the
//! snapshot's time) prepared for exact ray casting as flat convex polygons, and the translucent look they are drawn
//! with ([`WALL_COLOUR`], [`WALL_ALPHA`]).
//!
//! A wall's mesh is the one the run's engine writes to its VTK files (`wall0`, `wall1`, …;
//! [`crate::geometry::walls::surface`]): planes and disks exactly, cylinders and spheres as facets whose chords stay
//! within 0.12 % of the radius (sub-pixel at 800 px). Unbounded walls come cut to a piece reaching past every body.
//! Walls without area (rings, lines, points) have no polygons and are not drawn.
//!
//! Compositing ("over", front to back, Porter & Duff 1984): along each pixel's ray the nearest body is opaque and
//! ends the ray; every wall polygon the ray crosses before it tints what lies behind by
//! `c ← α·w + (1 − α)·c`, with `w` the wall's shaded colour ([`wall_shade`]) and `α` = [`WALL_ALPHA`].

use crate::geometry::mesh::SurfaceMesh;
use crate::math::Vec3;

use super::camera::{BoundingSphere, Camera, Ray};
use super::light::{AMBIENT, DIFFUSE, light_direction};

/// Colour of walls before shading: a pale blue-grey, apart from viridis and the category colours.
pub const WALL_COLOUR: [u8; 3] = [190, 205, 225];
/// Opacity of one wall layer: a pixel behind one layer keeps 70 % of its own colour, so bodies behind a container's
/// two layers (front and back) still read.
pub const WALL_ALPHA: f64 = 0.3;

/// One flat convex polygon of a wall, ready for rays.
#[derive(Clone, Debug, PartialEq)]
pub struct WallPolygon {
    /// Vertices (m), in the mesh's order.
    points: Vec<Vec3>,
    /// Unit normal (Newell's method: robust for a quad whose corners are not exactly coplanar).
    normal: Vec3,
    /// Bounding sphere: centre (m) and radius (m).
    centre: Vec3,
    radius: f64,
}

impl BoundingSphere for WallPolygon {
    fn bounding_sphere(&self) -> (Vec3, f64) {
        (self.centre, self.radius)
    }
}

impl WallPolygon {
    /// The polygon through `points` (m; at least three, convex, planar); `None` for a degenerate one (no area or
    /// non-finite points).
    pub fn new(points: Vec<Vec3>) -> Option<WallPolygon> {
        if points.len() < 3 || points.iter().any(|p| !p.iter().all(|c| c.is_finite())) {
            return None;
        }
        let mut newell = Vec3::zeros();
        for (k, a) in points.iter().enumerate() {
            newell += a.cross(&points[(k + 1) % points.len()]);
        }
        let area2 = newell.norm();
        if area2.is_nan() || area2 <= 0.0 {
            return None;
        }
        let centre = points.iter().sum::<Vec3>() / points.len() as f64;
        let radius = points.iter().map(|p| (p - centre).norm()).fold(0.0, f64::max);
        Some(WallPolygon {
            normal: newell / area2,
            points,
            centre,
            radius,
        })
    }

    /// The vertices (m).
    pub fn points(&self) -> &[Vec3] {
        &self.points
    }

    /// The unit normal (the side the vertices turn counter-clockwise about).
    pub fn normal(&self) -> Vec3 {
        self.normal
    }

    /// The ray parameter `t > t_min` at which `ray` crosses the polygon (its edges included), if it does; a ray in
    /// the polygon's plane does not cross it.
    pub fn hit(&self, ray: &Ray, t_min: f64) -> Option<f64> {
        let along = self.normal.dot(&ray.direction);
        if along == 0.0 {
            return None;
        }
        let t = self.normal.dot(&(self.points[0] - ray.origin)) / along;
        if t.is_nan() || t <= t_min {
            return None;
        }
        let p = ray.origin + t * ray.direction;
        // Inside a convex polygon: on the inner side of every edge (counter-clockwise about the normal). The
        // tolerance, relative to the polygon's size, keeps the pixels along a shared edge from falling between
        // two facets; a hit counted on both is merged by the caller.
        let tol = -1e-12 * self.radius * self.radius;
        let n = self.points.len();
        (0..n)
            .all(|k| {
                let (a, b) = (&self.points[k], &self.points[(k + 1) % n]);
                (b - a).cross(&(p - a)).dot(&self.normal) >= tol
            })
            .then_some(t)
    }
}

/// The polygons of `meshes` (each polygon of each mesh; polylines and lone vertices have no area and give none).
pub fn wall_polygons<'a>(meshes: impl IntoIterator<Item = &'a SurfaceMesh>) -> Vec<WallPolygon> {
    meshes
        .into_iter()
        .flat_map(|m| {
            m.polys
                .iter()
                .filter_map(|poly| WallPolygon::new(poly.iter().filter_map(|&i| m.points.get(i).copied()).collect()))
        })
        .collect()
}

/// The shading factor of a wall whose surface has the unit `normal`, seen by `camera`: `AMBIENT + DIFFUSE·|n·l|`
/// with the bodies' light `l` ([`light_direction`]). Walls are thin, so both faces are lit alike.
pub fn wall_shade(camera: &Camera, normal: &Vec3) -> f64 {
    AMBIENT + DIFFUSE * normal.dot(&light_direction(camera)).abs()
}

/// `colour` seen through the wall layers at ray parameters `hits` (each with its shading factor), all nearer than
/// what `colour` shows: composited from the farthest layer to the nearest, which is the same as front-to-back "over"
/// for layers of one opacity. Layers closer together than `merge` (m) are one layer (a ray through the shared edge of
/// two facets). `hits` is reordered.
pub fn composite(colour: [f64; 3], hits: &mut [(f64, f64)], merge: f64) -> [f64; 3] {
    hits.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut c = colour;
    let mut last = f64::INFINITY;
    for &(t, shade) in hits.iter() {
        if (last - t).abs() <= merge {
            continue;
        }
        last = t;
        for k in 0..3 {
            c[k] = WALL_ALPHA * f64::from(WALL_COLOUR[k]) * shade + (1.0 - WALL_ALPHA) * c[k];
        }
    }
    c
}
