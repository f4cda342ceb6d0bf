//! What each wall primitive looks like: a surface mesh in the wall frame (z the wall axis, origin the reference
//! point), and in the world at a time, for visualisation files and pictures. Every vertex lies on the analytic
//! surface (`nearest` distance zero up to round-off); unbounded primitives (planes, infinite cylinders and lines)
//! are cut to a finite piece of half-size `extent` (m) around the reference point.

use super::{Shape, Wall};
use crate::geometry::mesh::SurfaceMesh;
use crate::math::Vec3;

/// Segments around a circle (a disk's rim, a cylinder, a ring): fine enough that a 1 m circle's chords stay within
/// 1.2 mm of it.
pub const CIRCLE_SEGMENTS: usize = 64;

fn circle(radius: f64, z: f64) -> impl Iterator<Item = Vec3> {
    (0..CIRCLE_SEGMENTS).map(move |k| {
        let phi = std::f64::consts::TAU * k as f64 / CIRCLE_SEGMENTS as f64;
        Vec3::new(radius * phi.cos(), radius * phi.sin(), z)
    })
}

impl Shape {
    /// The surface in the wall frame; `extent` (m, > 0) bounds the unbounded primitives.
    pub fn surface_local(&self, extent: f64) -> SurfaceMesh {
        let mut m = SurfaceMesh::default();
        let m_seg = CIRCLE_SEGMENTS;
        match *self {
            Shape::Plane => {
                for (x, y) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                    m.add_point(Vec3::new(x * extent, y * extent, 0.0));
                }
                m.polys.push(vec![0, 1, 2, 3]);
            }
            Shape::Disk { radius } => {
                let centre = m.add_point(Vec3::zeros());
                circle(radius, 0.0).for_each(|p| {
                    m.add_point(p);
                });
                for k in 0..m_seg {
                    m.polys.push(vec![centre, 1 + k, 1 + (k + 1) % m_seg]);
                }
            }
            Shape::Cylinder { radius, length } => {
                let half = length.map_or(extent, |l| l / 2.0);
                circle(radius, -half).chain(circle(radius, half)).for_each(|p| {
                    m.add_point(p);
                });
                for k in 0..m_seg {
                    let next = (k + 1) % m_seg;
                    m.polys.push(vec![k, next, m_seg + next, m_seg + k]);
                }
            }
            Shape::Ring { radius } => {
                circle(radius, 0.0).for_each(|p| {
                    m.add_point(p);
                });
                m.lines.push((0..m_seg).chain([0]).collect());
            }
            Shape::Point => {
                let p = m.add_point(Vec3::zeros());
                m.verts.push(p);
            }
            Shape::Line { length } => {
                let half = length.map_or(extent, |l| l / 2.0);
                m.add_point(Vec3::new(0.0, 0.0, -half));
                m.add_point(Vec3::new(0.0, 0.0, half));
                m.lines.push(vec![0, 1]);
            }
        }
        m
    }
}

impl Wall {
    /// The surface in the world at time `t` (s): where the wall's prescribed motion has carried it.
    pub fn surface_at(&self, t: f64, extent: f64) -> SurfaceMesh {
        let origin = self.origin_at(t);
        self.shape
            .surface_local(extent)
            .map_points(|p| origin + self.to_world(p))
    }
}

/// Latitude bands of a spherical container's mesh.
pub const SPHERE_BANDS: usize = 32;

impl super::soft::Wall {
    /// The soft-sphere wall's surface at time `t` (s), where its oscillation has carried it: a plane as a square
    /// patch of half-size `extent` (m) about its point, a spherical container as a latitude–longitude mesh whose
    /// vertices lie on the sphere, a cylinder as the hard-sphere primitive's mesh (an infinite one cut to `extent`).
    pub fn surface_at(&self, t: f64, extent: f64) -> SurfaceMesh {
        let offset = |o: &Option<super::motion::Oscillation>| o.as_ref().map_or(Vec3::zeros(), |o| o.displacement(t));
        match self {
            super::soft::Wall::Plane(p) => {
                Wall::new(Shape::Plane, p.point + offset(&p.oscillation), p.normal).surface_at(0.0, extent)
            }
            super::soft::Wall::Cylinder(c) => Wall::new(
                Shape::Cylinder {
                    radius: c.radius,
                    length: c.length,
                },
                c.centre + offset(&c.oscillation),
                c.axis,
            )
            .surface_at(0.0, extent),
            super::soft::Wall::Sphere(s) => {
                let centre = s.centre + offset(&s.oscillation);
                let mut m = SurfaceMesh::default();
                let north = m.add_point(centre + Vec3::z() * s.radius);
                for j in 1..SPHERE_BANDS {
                    let theta = std::f64::consts::PI * j as f64 / SPHERE_BANDS as f64;
                    circle(s.radius * theta.sin(), s.radius * theta.cos()).for_each(|p| {
                        m.add_point(centre + p);
                    });
                }
                let south = m.add_point(centre - Vec3::z() * s.radius);
                let n = CIRCLE_SEGMENTS;
                let ring = |j: usize, k: usize| 1 + (j - 1) * n + k % n;
                for k in 0..n {
                    m.polys.push(vec![north, ring(1, k), ring(1, k + 1)]);
                    for j in 1..SPHERE_BANDS - 1 {
                        m.polys
                            .push(vec![ring(j, k), ring(j + 1, k), ring(j + 1, k + 1), ring(j, k + 1)]);
                    }
                    m.polys
                        .push(vec![ring(SPHERE_BANDS - 1, k), south, ring(SPHERE_BANDS - 1, k + 1)]);
                }
                m
            }
        }
    }
}
