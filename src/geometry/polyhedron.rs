//! Closed triangulated shape models (OBJ) and point-in-polyhedron, for carving aggregates out of real asteroid
//! shapes (Zhang17 §2.3.2 builds its aggregates inside the Didymos radar model).
//!
//! [`Polyhedron::contains`] counts the crossings of a ray from the point along +z with the surface (parity:
//! odd = inside). The triangles are binned by their (x, y) bounding boxes on a uniform grid, so a query tests
//! only the triangles of its cell. A ray through an edge or a vertex is counted once through a half-open
//! barycentric rule (the crossing belongs to the triangle for which the point's barycentric coordinates are in
//! `[0, 1)`-style half-open ranges), which is exact for points in general position.
//! [`Polyhedron::contains_brute_force`] is the O(triangles) reference along another axis (+x), used in tests.

use std::path::Path;

use crate::math::Vec3;

/// A closed, consistently triangulated surface.
#[derive(Debug, Clone)]
pub struct Polyhedron {
    /// Vertices (the file's length unit, times the scale given to [`Polyhedron::from_obj`]).
    pub vertices: Vec<Vec3>,
    /// Triangles as vertex indices (0-based).
    pub triangles: Vec<[usize; 3]>,
    grid: XyGrid,
}

/// Triangles binned by the (x, y) bounding boxes.
#[derive(Debug, Clone)]
struct XyGrid {
    origin: [f64; 2],
    cell: [f64; 2],
    dims: [usize; 2],
    bins: Vec<Vec<u32>>,
}

/// Why a shape model could not be read. Messages are one line, naming the file and the line.
#[derive(Debug, thiserror::Error)]
pub enum ShapeError {
    /// The file could not be read.
    #[error("{path}: cannot read: {reason}")]
    Read {
        /// The file.
        path: String,
        /// The OS error.
        reason: String,
    },
    /// A malformed line.
    #[error("{path} line {line}: {message}")]
    Format {
        /// The file.
        path: String,
        /// 1-based line number.
        line: usize,
        /// What was expected.
        message: String,
    },
}

impl Polyhedron {
    /// Reads an OBJ file: `v x y z` and `f i j k` lines (1-based indices, `i/…` forms accepted, polygons
    /// fan-triangulated); other lines are ignored. Coordinates are multiplied by `scale` (e.g. 1000 for km → m).
    pub fn from_obj(path: &Path, scale: f64) -> Result<Self, ShapeError> {
        let text = std::fs::read_to_string(path).map_err(|e| ShapeError::Read {
            path: path.display().to_string(),
            reason: e.to_string(),
        })?;
        Self::parse_obj(&text, &path.display().to_string(), scale)
    }

    /// [`Polyhedron::from_obj`] on the text of a file named `name` in messages.
    pub fn parse_obj(text: &str, name: &str, scale: f64) -> Result<Self, ShapeError> {
        let bad = |line: usize, message: String| ShapeError::Format {
            path: name.to_string(),
            line,
            message,
        };
        let mut vertices = Vec::new();
        let mut faces: Vec<(usize, Vec<usize>)> = Vec::new();
        for (k, raw) in text.lines().enumerate() {
            let line = k + 1;
            let mut words = raw.split_whitespace();
            match words.next() {
                Some("v") => {
                    let xyz: Vec<f64> = words.take(3).filter_map(|w| w.parse().ok()).collect();
                    if xyz.len() != 3 || xyz.iter().any(|x| !x.is_finite()) {
                        return Err(bad(line, "expected `v x y z` with three finite numbers".into()));
                    }
                    vertices.push(Vec3::new(xyz[0], xyz[1], xyz[2]) * scale);
                }
                Some("f") => {
                    let idx: Result<Vec<usize>, _> = words
                        .map(|w| w.split('/').next().unwrap_or("").parse::<usize>())
                        .collect();
                    match idx {
                        Ok(v) if v.len() >= 3 && v.iter().all(|&i| i >= 1) => faces.push((line, v)),
                        _ => return Err(bad(line, "expected `f i j k` with 1-based vertex indices".into())),
                    }
                }
                _ => {}
            }
        }
        let mut triangles = Vec::new();
        for (line, f) in faces {
            if let Some(&i) = f.iter().find(|&&i| i > vertices.len()) {
                return Err(bad(
                    line,
                    format!("vertex {i} does not exist ({} vertices)", vertices.len()),
                ));
            }
            for k in 1..f.len() - 1 {
                triangles.push([f[0] - 1, f[k] - 1, f[k + 1] - 1]);
            }
        }
        if triangles.len() < 4 {
            return Err(bad(
                0,
                format!("need a closed surface, got {} triangles", triangles.len()),
            ));
        }
        Ok(Self::new(vertices, triangles))
    }

    /// A polyhedron from vertices and triangles (indices must be in range).
    pub fn new(vertices: Vec<Vec3>, triangles: Vec<[usize; 3]>) -> Self {
        let grid = XyGrid::build(&vertices, &triangles);
        Polyhedron {
            vertices,
            triangles,
            grid,
        }
    }

    /// Axis-aligned bounding box `(min, max)`.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::from_element(f64::INFINITY);
        let mut hi = Vec3::from_element(f64::NEG_INFINITY);
        for v in &self.vertices {
            lo = lo.inf(v);
            hi = hi.sup(v);
        }
        (lo, hi)
    }

    /// Enclosed volume (divergence theorem over the triangles; positive for outward-facing triangles).
    pub fn volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.vertices[i]);
                a.dot(&b.cross(&c)) / 6.0
            })
            .sum()
    }

    /// Whether `p` is inside (ray parity along +z, grid-accelerated).
    pub fn contains(&self, p: &Vec3) -> bool {
        let Some(bin) = self.grid.bin_of(p.x, p.y) else {
            return false;
        };
        let mut crossings = 0usize;
        for &t in &self.grid.bins[bin] {
            let [a, b, c] = self.triangles[t as usize].map(|i| self.vertices[i]);
            if ray_crosses(p, [a, b, c], 2) {
                crossings += 1;
            }
        }
        crossings % 2 == 1
    }

    /// Whether `p` is inside, by ray parity along +x over every triangle (the O(triangles) reference).
    pub fn contains_brute_force(&self, p: &Vec3) -> bool {
        let crossings = self
            .triangles
            .iter()
            .filter(|t| ray_crosses(p, t.map(|i| self.vertices[i]), 0))
            .count();
        crossings % 2 == 1
    }
}

/// Whether the ray from `p` along +axis (0 = x, 2 = z) crosses triangle `tri`. The triangle is projected on the
/// plane orthogonal to the axis; the crossing point must lie strictly ahead of `p`. Edges and vertices belong to
/// one side by the top-left style rule on the projected edge functions, so a ray through a shared edge counts once.
fn ray_crosses(p: &Vec3, tri: [Vec3; 3], axis: usize) -> bool {
    let (u, v) = match axis {
        0 => (1, 2),
        1 => (2, 0),
        _ => (0, 1),
    };
    let q = [p[u], p[v]];
    let pts = tri.map(|t| [t[u] - q[0], t[v] - q[1]]);
    // Edge functions: the signed double areas of (origin, edge). The origin is inside the projected triangle when
    // all three have the same sign; zeros are broken by a fixed rule on the edge direction so that two triangles
    // sharing an edge never both claim a point on it.
    let edge = |a: [f64; 2], b: [f64; 2]| {
        let w = a[0] * b[1] - a[1] * b[0];
        if w != 0.0 {
            w > 0.0
        } else {
            // tie: the edge (a → b) owns the point when it points "up" (or right if horizontal)
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            dy > 0.0 || (dy == 0.0 && dx < 0.0)
        }
    };
    let s0 = edge(pts[0], pts[1]);
    let s1 = edge(pts[1], pts[2]);
    let s2 = edge(pts[2], pts[0]);
    if !(s0 == s1 && s1 == s2) {
        return false;
    }
    // the crossing point's coordinate along the axis, by barycentric interpolation
    let w0 = pts[1][0] * pts[2][1] - pts[1][1] * pts[2][0];
    let w1 = pts[2][0] * pts[0][1] - pts[2][1] * pts[0][0];
    let w2 = pts[0][0] * pts[1][1] - pts[0][1] * pts[1][0];
    let total = w0 + w1 + w2;
    if total == 0.0 {
        return false; // triangle seen edge-on: the ray grazes it
    }
    let along = (w0 * tri[0][axis] + w1 * tri[1][axis] + w2 * tri[2][axis]) / total;
    along > p[axis]
}

impl XyGrid {
    fn build(vertices: &[Vec3], triangles: &[[usize; 3]]) -> Self {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for v in vertices {
            for k in 0..2 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
        // about 2 triangles per cell on average over the projected area
        let n = (triangles.len() as f64 / 2.0).sqrt().ceil().max(1.0) as usize;
        let dims = [n, n];
        let cell = [0, 1].map(|k| ((hi[k] - lo[k]) / n as f64).max(f64::MIN_POSITIVE));
        let mut bins = vec![Vec::new(); n * n];
        for (t, tri) in triangles.iter().enumerate() {
            let (mut a, mut b) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for &i in tri {
                for k in 0..2 {
                    a[k] = a[k].min(vertices[i][k]);
                    b[k] = b[k].max(vertices[i][k]);
                }
            }
            let index = |x: f64, k: usize| (((x - lo[k]) / cell[k]).floor().max(0.0) as usize).min(dims[k] - 1);
            for i in index(a[0], 0)..=index(b[0], 0) {
                for j in index(a[1], 1)..=index(b[1], 1) {
                    bins[i * n + j].push(t as u32);
                }
            }
        }
        XyGrid {
            origin: lo,
            cell,
            dims,
            bins,
        }
    }

    fn bin_of(&self, x: f64, y: f64) -> Option<usize> {
        let index = |v: f64, k: usize| {
            let i = (v - self.origin[k]) / self.cell[k];
            // the upper boundary belongs to the last cell
            let top = i.floor() as usize == self.dims[k] && v == self.origin[k] + self.cell[k] * self.dims[k] as f64;
            (i >= 0.0).then(|| i.floor() as usize - usize::from(top))
        };
        let (i, j) = (index(x, 0)?, index(y, 1)?);
        (i < self.dims[0] && j < self.dims[1]).then_some(i * self.dims[1] + j)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube as 12 outward-facing triangles.
    fn cube() -> Polyhedron {
        let v: Vec<Vec3> = (0..8)
            .map(|k| Vec3::new((k & 1) as f64, ((k >> 1) & 1) as f64, ((k >> 2) & 1) as f64))
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let mut t = Vec::new();
        for q in quads {
            t.push([q[0], q[1], q[2]]);
            t.push([q[0], q[2], q[3]]);
        }
        Polyhedron::new(v, t)
    }

    #[test]
    fn cube_volume_and_containment() {
        let c = cube();
        assert!((c.volume() - 1.0).abs() < 1e-14, "{}", c.volume());
        // points on the grid lines of the triangulation (rays through shared edges and vertices) count once
        for (p, inside) in [
            (Vec3::new(0.5, 0.5, 0.5), true),
            (Vec3::new(0.25, 0.25, 0.1), true),
            (Vec3::new(0.5, 0.5, -0.5), false),
            (Vec3::new(1.5, 0.5, 0.5), false),
            (Vec3::new(0.3, 0.3, 0.3), true), // on the diagonal edge of the top and bottom quads
            (Vec3::new(0.3, 0.3, 1.3), false),
        ] {
            assert_eq!(c.contains(&p), inside, "{p:?}");
            assert_eq!(c.contains_brute_force(&p), inside, "{p:?} (brute force)");
        }
    }

    #[test]
    fn bad_obj_lines_are_named() {
        let e = Polyhedron::parse_obj("v 0 0 0\nv 1 0\n", "x.obj", 1.0).unwrap_err();
        assert_eq!(
            e.to_string(),
            "x.obj line 2: expected `v x y z` with three finite numbers"
        );
        let e = Polyhedron::parse_obj("v 0 0 0\nf 1 2 3\n", "x.obj", 1.0).unwrap_err();
        assert!(
            e.to_string().starts_with("x.obj line 2: vertex 2 does not exist"),
            "{e}"
        );
    }
}
