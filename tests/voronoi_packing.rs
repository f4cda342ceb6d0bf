//! The interior packing fraction from Voronoi cells (Zhang17 η_B): an HCP packing gives π/(3√2) = 0.7405 and a
//! simple cubic one π/6 within ±0.002, boundary cells are excluded, and the closed cells tile the interior.

use rubblepile::geometry::lattice::{hcp_centres, simple_cubic_centres};
use rubblepile::geometry::voronoi::{packing_fraction, voronoi_cells};
use rubblepile::math::Vec3;

fn interior_fraction(centres: &[Vec3], r: f64, depth: f64, extent: f64) -> (f64, usize, usize) {
    let cells = voronoi_cells(centres, 4.0 * r);
    let interior: Vec<bool> = centres.iter().map(|p| p.norm() < extent - depth).collect();
    let open = cells.iter().filter(|c| c.boundary).count();
    // every open cell is a surface particle
    for (c, p) in cells.iter().zip(centres) {
        if c.boundary {
            assert!(p.norm() > extent - 4.0 * r, "open cell deep inside at {p:?}");
        }
    }
    let radii = vec![r; centres.len()];
    let eta = packing_fraction(&cells, &radii, &interior).expect("interior cells");
    (eta, interior.iter().filter(|&&k| k).count(), open)
}

#[test]
fn hcp_interior_packing_fraction() {
    let (r, extent) = (1.0, 9.0);
    let centres = hcp_centres(r, extent);
    let (eta, n_interior, open) = interior_fraction(&centres, r, 3.0 * r, extent);
    let exact = std::f64::consts::PI / (3.0 * 2f64.sqrt());
    assert!(
        (eta - exact).abs() <= 0.002,
        "η = {eta} vs {exact} ({n_interior} interior, {open} open cells)"
    );
    assert!(open > 0 && n_interior > 50);
    // each interior cell is the trapezo-rhombic dodecahedron of volume 4√2 r³
    let cells = voronoi_cells(&centres, 4.0 * r);
    let centre = centres.iter().position(|p| p.norm() < 1e-9).unwrap();
    assert!(
        (cells[centre].volume - 4.0 * 2f64.sqrt()).abs() < 1e-9,
        "{:?}",
        cells[centre]
    );
}

#[test]
fn simple_cubic_interior_packing_fraction() {
    let (r, extent) = (1.0, 9.0);
    let centres = simple_cubic_centres(r, extent);
    let (eta, _, _) = interior_fraction(&centres, r, 3.0 * r, extent);
    let exact = std::f64::consts::PI / 6.0;
    assert!((eta - exact).abs() <= 0.002, "η = {eta} vs {exact}");
}

/// Random points: the closed cells' volumes add up to the volume they tile (checked on a cube of jittered points,
/// whose interior cells must fill the inner region without gaps: Σ V ≈ count × mean spacing³).
#[test]
fn jittered_lattice_cells_conserve_volume() {
    let mut state = 99u64;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let n = 12;
    let mut pts = Vec::new();
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                pts.push(Vec3::new(
                    i as f64 + 0.3 * next(),
                    j as f64 + 0.3 * next(),
                    k as f64 + 0.3 * next(),
                ));
            }
        }
    }
    let cells = voronoi_cells(&pts, 3.0);
    // cells of the unperturbed inner block [3, 8]^3 do not see the surface; their jitter averages out
    let inner: Vec<f64> = pts
        .iter()
        .zip(&cells)
        .filter(|(p, _)| p.iter().all(|&x| (3.5..=7.5).contains(&x)))
        .map(|(_, c)| {
            assert!(!c.boundary);
            c.volume
        })
        .collect();
    let mean = inner.iter().sum::<f64>() / inner.len() as f64;
    assert!(
        (mean - 1.0).abs() < 0.02,
        "mean cell volume {mean} over {} cells",
        inner.len()
    );
    assert!(inner.iter().all(|&v| v > 0.3 && v < 2.0));
}
