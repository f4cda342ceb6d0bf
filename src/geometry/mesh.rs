//! Surface meshes for pictures and visualisation files: points with polygon, polyline and vertex cells (what a
//! wall looks like in ParaView; never used by the physics).

use crate::math::Vec3;

/// Points (m) and the cells through them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SurfaceMesh {
    /// Vertex positions (m).
    pub points: Vec<Vec3>,
    /// Polygons (triangles and quads), each a list of indices into `points`, counter-clockwise seen from the
    /// side the surface normal points to.
    pub polys: Vec<Vec<usize>>,
    /// Polylines (a ring, a line segment).
    pub lines: Vec<Vec<usize>>,
    /// Lone vertices (a point wall).
    pub verts: Vec<usize>,
}

impl SurfaceMesh {
    /// Appends a point and returns its index.
    pub fn add_point(&mut self, p: Vec3) -> usize {
        self.points.push(p);
        self.points.len() - 1
    }

    /// The mesh with every point mapped by `f` (cells unchanged).
    pub fn map_points(mut self, f: impl Fn(&Vec3) -> Vec3) -> Self {
        for p in &mut self.points {
            *p = f(p);
        }
        self
    }
}
