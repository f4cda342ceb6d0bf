//! Regular sphere packing: hexagonal close packing (HCP, packing fraction π/(3√2) ≈ 0.7405, Zhang17's HCP
//! aggregates), as a point set filling a sphere.

use crate::math::Vec3;

/// Centres of equal spheres of radius `r` (m) in hexagonal close packing (ABAB… stacking along z), touching
/// their 12 neighbours, that lie within `extent` (m) of the origin. The origin is a lattice site.
pub fn hcp_centres(r: f64, extent: f64) -> Vec<Vec3> {
    let d = 2.0 * r;
    let layer = d * (2.0f64 / 3.0).sqrt(); // spacing of the close-packed layers
    let row = d * 3f64.sqrt() / 2.0;
    let n = (extent / layer).ceil() as i64 + 1;
    let mut out = Vec::new();
    for k in -n..=n {
        // B layers are shifted to the centres of half the triangles of the A layers
        let (sx, sy) = if k.rem_euclid(2) == 1 {
            (0.5 * d, row / 3.0)
        } else {
            (0.0, 0.0)
        };
        let z = k as f64 * layer;
        for j in -n - 1..=n + 1 {
            for i in -n - 1..=n + 1 {
                let x = i as f64 * d + 0.5 * d * j.rem_euclid(2) as f64 + sx;
                let y = j as f64 * row + sy;
                let p = Vec3::new(x, y, z);
                if p.norm() <= extent {
                    out.push(p);
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every HCP sphere away from the surface touches exactly 12 others, and none overlap.
    #[test]
    fn hcp_has_twelve_touching_neighbours() {
        let r = 0.5;
        let pts = hcp_centres(r, 4.0);
        for p in pts.iter().filter(|p| p.norm() < 2.0) {
            let mut touching = 0;
            for q in &pts {
                let d = (p - q).norm();
                if d > 0.0 {
                    assert!(d > 2.0 * r - 1e-12, "overlap {d}");
                    if d < 2.0 * r + 1e-9 {
                        touching += 1;
                    }
                }
            }
            assert_eq!(touching, 12, "{p:?}");
        }
    }
}
