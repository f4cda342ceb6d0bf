//! Voronoi cells of a particle packing and the interior packing fraction η_B (Zhang17 §3, "packing efficiency" from
//! a Voronoi tessellation; the paper used Voro++). Our own construction: each cell starts as a cube around its
//! particle and is clipped by its neighbours' planes in order of distance, until the next neighbour lies beyond twice
//! the cell's farthest vertex. Cells are convex polyhedra kept as face polygons; volume = Σ area × plane distance / 3.
//!
//! [`radical_cells`] use the radical (power, Laguerre) planes, `(d² + r_i² − r_j²)/(2d)` from `i`, through the contact
//! circle, so every cell holds its whole sphere (Voro++'s radical option; plain bisectors hand part of the larger
//! sphere to the smaller one's cell, a large bias near a rough surface); equal radii give the same cells bit for bit.
//! A cell keeping a face of its starting cube is open (it measures the cube) and is excluded from
//! [`packing_fraction`], as are particles outside the caller's `interior` mask. Not a crate: Voro++ needs a C++ build,
//! and we need only cell volumes and a boundary flag (tested on lattices with exact answers).

use crate::geometry::neighbours::sphere_pairs;
use crate::math::Vec3;
use rayon::prelude::*;

/// One Voronoi cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VoronoiCell {
    /// Volume (m³).
    pub volume: f64,
    /// Whether a face of the starting cube survived: the cell is open to the outside of the packing.
    pub boundary: bool,
    /// Largest distance from the centre to a vertex of the cell (m).
    pub reach: f64,
}

impl VoronoiCell {
    /// Whether the cell reaches `radius` (m) from its centre (or the starting cube): open by a test that does
    /// not depend on how the packing is turned relative to the axis-aligned starting cube, for any `radius` up
    /// to the cube's half-side. [`VoronoiCell::boundary`] alone does: a surface cell closed by its neighbours'
    /// planes just inside a cube corner is open once the packing has turned so that a face lies there.
    pub fn reaches(&self, radius: f64) -> bool {
        self.boundary || self.reach >= radius
    }
}

/// A face: the plane `normal · x = offset` (outward normal) and its polygon.
#[derive(Debug, Clone)]
struct Face {
    normal: Vec3,
    offset: f64,
    polygon: Vec<Vec3>,
    from_box: bool,
}

/// Keeps the part of `cell` with `n · x ≤ d`, closing the cut with a new face.
fn clip(cell: &mut Vec<Face>, n: Vec3, d: f64, eps: f64) {
    let mut cap: Vec<Vec3> = Vec::new();
    let mut kept = Vec::with_capacity(cell.len() + 1);
    for face in cell.drain(..) {
        let m = face.polygon.len();
        let side: Vec<f64> = face.polygon.iter().map(|p| n.dot(p) - d).collect();
        if side.iter().all(|&s| s <= eps) {
            for (p, &s) in face.polygon.iter().zip(&side) {
                if s.abs() <= eps {
                    cap.push(*p);
                }
            }
            kept.push(face);
            continue;
        }
        let mut out = Vec::with_capacity(m + 1);
        for k in 0..m {
            let (a, b) = (face.polygon[k], face.polygon[(k + 1) % m]);
            let (sa, sb) = (side[k], side[(k + 1) % m]);
            if sa <= eps {
                out.push(a);
                if sa.abs() <= eps {
                    cap.push(a);
                }
            }
            if (sa < -eps && sb > eps) || (sa > eps && sb < -eps) {
                let x = a + (b - a) * (sa / (sa - sb));
                out.push(x);
                cap.push(x);
            }
        }
        if out.len() >= 3 {
            kept.push(Face { polygon: out, ..face });
        }
    }
    *cell = kept;
    if cap.len() >= 3 {
        // order the cap's points by angle about their centroid, in a basis of the cutting plane
        let c = cap.iter().fold(Vec3::zeros(), |s, p| s + p) / cap.len() as f64;
        let e1 = {
            let t = if n.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() };
            (t - n * n.dot(&t)).normalize()
        };
        let e2 = n.cross(&e1);
        cap.sort_by(|p, q| {
            let (dp, dq) = (p - c, q - c);
            dp.dot(&e2)
                .atan2(dp.dot(&e1))
                .total_cmp(&dq.dot(&e2).atan2(dq.dot(&e1)))
        });
        cap.dedup_by(|a, b| (*a - *b).norm() <= eps);
        if cap.len() >= 3 {
            cell.push(Face {
                normal: n,
                offset: d,
                polygon: cap,
                from_box: false,
            });
        }
    }
}

fn polygon_area(poly: &[Vec3]) -> f64 {
    let mut s = Vec3::zeros();
    for k in 1..poly.len().saturating_sub(1) {
        s += (poly[k] - poly[0]).cross(&(poly[k + 1] - poly[0]));
    }
    0.5 * s.norm()
}

fn cube_around(g: &Vec3, h: f64) -> Vec<Face> {
    let mut faces = Vec::with_capacity(6);
    for axis in 0..3 {
        for sign in [-1.0, 1.0] {
            let mut normal = Vec3::zeros();
            normal[axis] = sign;
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let corner = |a: f64, b: f64| {
                let mut p = *g;
                p[axis] += sign * h;
                p[u] += a * h;
                p[v] += b * h;
                p
            };
            faces.push(Face {
                normal,
                offset: normal.dot(g) + h,
                polygon: vec![
                    corner(-1.0, -1.0),
                    corner(1.0, -1.0),
                    corner(1.0, 1.0),
                    corner(-1.0, 1.0),
                ],
                from_box: true,
            });
        }
    }
    faces
}

/// The Voronoi cells of `centres`, each started as a cube of half-side `half_size` (m) around its centre (choose
/// it larger than any interior cell: a few mean spacings). Cells are independent, so they are built in parallel;
/// the result does not depend on the number of threads.
pub fn voronoi_cells(centres: &[Vec3], half_size: f64) -> Vec<VoronoiCell> {
    tessellate(centres, None, half_size)
}

/// The radical (power) cells of spheres with these `centres` and `radii` (m), each started as a cube of
/// half-side `half_size` (m; a few largest diameters); with equal radii, exactly [`voronoi_cells`].
///
/// ```
/// use rubblepile::geometry::voronoi::radical_cells;
/// use rubblepile::math::Vec3;
/// // two touching spheres of radii 1 and 3: the radical plane is their tangent plane, 1 m from the first
/// // centre, so the first cell is the cube of side 4 cut at x = 1: 4 × 4 × 3
/// let cells = radical_cells(&[Vec3::zeros(), Vec3::new(4.0, 0.0, 0.0)], &[1.0, 3.0], 2.0);
/// assert!((cells[0].volume - 48.0).abs() < 1e-9);
/// ```
pub fn radical_cells(centres: &[Vec3], radii: &[f64], half_size: f64) -> Vec<VoronoiCell> {
    let equal = radii.iter().all(|&r| r == radii[0]);
    tessellate(centres, (!equal).then_some(radii), half_size)
}

/// Bisector cells (`radii` = `None`) or radical cells.
fn tessellate(centres: &[Vec3], radii: Option<&[f64]>, half_size: f64) -> Vec<VoronoiCell> {
    let n = centres.len();
    let largest = radii.map_or(0.0, |r| r.iter().cloned().fold(0.0, f64::max));
    // candidates: every pair within the security radius of the starting cube, 2 √3 h
    let reach = vec![half_size * 3f64.sqrt(); n];
    let mut neighbours: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (i, j) in sphere_pairs(centres, &reach) {
        neighbours[i].push(j);
        neighbours[j].push(i);
    }
    let eps = 1e-12 * half_size;
    (0..n)
        .into_par_iter()
        .map(|i| {
            let g = centres[i];
            let mut order: Vec<(f64, usize)> = neighbours[i].iter().map(|&j| ((centres[j] - g).norm(), j)).collect();
            order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            let reach = |cell: &[Face]| {
                cell.iter()
                    .flat_map(|f| &f.polygon)
                    .map(|p| (p - g).norm())
                    .fold(0.0, f64::max)
            };
            let mut cell = cube_around(&g, half_size);
            for (dist, j) in order {
                let r_max = reach(&cell);
                if dist == 0.0 {
                    continue; // a duplicate point has no bisector
                }
                let normal = (centres[j] - g) / dist;
                match radii {
                    None => {
                        if dist > 2.0 * r_max {
                            break; // no farther neighbour can reach the cell
                        }
                        clip(&mut cell, normal, normal.dot(&(0.5 * (g + centres[j]))), eps);
                    }
                    Some(r) => {
                        // the plane of a neighbour at `dist` lies at least (dist² − r_largest²)/(2 dist) away,
                        // which grows with dist: once beyond the cell, no farther neighbour can cut it
                        if (dist * dist - largest * largest) / (2.0 * dist) > r_max {
                            break;
                        }
                        let t = (dist * dist + r[i] * r[i] - r[j] * r[j]) / (2.0 * dist);
                        clip(&mut cell, normal, normal.dot(&g) + t, eps);
                    }
                }
            }
            let volume = cell
                .iter()
                .map(|f| polygon_area(&f.polygon) * (f.offset - f.normal.dot(&g)) / 3.0)
                .sum();
            VoronoiCell {
                volume,
                boundary: cell.iter().any(|f| f.from_box),
                reach: reach(&cell),
            }
        })
        .collect()
}

/// Packing fraction Σ (4/3)π r³ / Σ V_cell over the particles with `interior[i]` whose cells are closed
/// (not [`VoronoiCell::boundary`]); `None` when no particle qualifies.
pub fn packing_fraction(cells: &[VoronoiCell], radii: &[f64], interior: &[bool]) -> Option<f64> {
    let weights: Vec<f64> = interior.iter().map(|&keep| if keep { 1.0 } else { 0.0 }).collect();
    weighted_packing_fraction(cells, radii, &weights)
}

/// Weighted packing fraction Σ wᵢ (4/3)π rᵢ³ / Σ wᵢ Vᵢ over the particles with closed cells (weights ≥ 0);
/// `None` when no closed cell has a positive weight. With 0/1 weights it is [`packing_fraction`].
pub fn weighted_packing_fraction(cells: &[VoronoiCell], radii: &[f64], weights: &[f64]) -> Option<f64> {
    let (mut solid, mut total) = (0.0, 0.0);
    for ((c, &r), &w) in cells.iter().zip(radii).zip(weights) {
        if w > 0.0 && !c.boundary {
            solid += w * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
            total += w * c.volume;
        }
    }
    (total > 0.0).then(|| solid / total)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_points_split_the_cube_in_half_and_both_are_open() {
        let cells = voronoi_cells(&[Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0)], 2.0);
        // each cell: the cube of side 4 around its point, cut at x = 0.5: 4 × 4 × 2.5
        for c in &cells {
            assert!((c.volume - 40.0).abs() < 1e-9, "{c:?}");
            assert!(c.boundary);
        }
    }
}
