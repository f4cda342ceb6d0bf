//! The interior packing fraction from Voronoi cells (Zhang17 η_B): an HCP packing gives π/(3√2) = 0.7405 and a
//! simple cubic one π/6 within ±0.002, boundary cells are excluded, and the closed cells tile the interior; for
//! unequal spheres the radical cells give each sphere type its exact share (a CsCl crystal).

use rubblepile::geometry::lattice::hcp_centres;
use rubblepile::geometry::voronoi::{packing_fraction, radical_cells, voronoi_cells};
use rubblepile::math::Vec3;

/// Centres of equal spheres of radius `r` (m) on a simple cubic lattice of spacing 2r within `extent` (m) of the
/// origin.
fn simple_cubic_centres(r: f64, extent: f64) -> Vec<Vec3> {
    let d = 2.0 * r;
    let n = (extent / d).ceil() as i64;
    let mut out = Vec::new();
    for i in -n..=n {
        for j in -n..=n {
            for k in -n..=n {
                let p = Vec3::new(i as f64, j as f64, k as f64) * d;
                if p.norm() <= extent {
                    out.push(p);
                }
            }
        }
    }
    out
}

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

/// CsCl crystal of unequal spheres: big spheres (R = 1) on a simple cubic lattice of side a = 2 (touching along
/// the edges) and a small sphere (r = √3 − 1) at each cube centre, touching its 8 big neighbours. The radical plane
/// of a small–big pair is their tangent plane, at r along the body diagonal, so the small sphere's cell is the
/// octahedron |x| + |y| + |z| ≤ s (s = r√3 = 3 − √3) cut by the cube |x|, |y|, |z| ≤ 1 (the small–small planes):
/// V_small = (4/3) s³ − 4 (s − 1)³, V_big = a³ − V_small. Each type's packing fraction comes out exact with radical
/// cells; bisector cells hand part of the big spheres to the small ones' cells (the bias that made a polydisperse
/// pile's η_B 0.47 instead of ≈ 0.73).
#[test]
fn cscl_radical_cells_give_each_sphere_type_its_share() {
    let (a, big, small) = (2.0, 1.0, 3f64.sqrt() - 1.0);
    let mut centres = Vec::new();
    let mut radii = Vec::new();
    for i in -4i32..=4 {
        for j in -4i32..=4 {
            for k in -4i32..=4 {
                centres.push(Vec3::new(i as f64, j as f64, k as f64) * a);
                radii.push(big);
                if i < 4 && j < 4 && k < 4 {
                    centres.push((Vec3::new(i as f64, j as f64, k as f64) + Vec3::repeat(0.5)) * a);
                    radii.push(small);
                }
            }
        }
    }
    let s = 3.0 - 3f64.sqrt();
    let v_small = 4.0 / 3.0 * s.powi(3) - 4.0 * (s - 1.0).powi(3);
    let v_big = a * a * a - v_small;
    let ball = |r: f64| 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
    let deep = |p: &Vec3| p.amax() < 2.5 * a;
    let cells = radical_cells(&centres, &radii, 3.0 * a);
    for ((c, p), &r) in cells.iter().zip(&centres).zip(&radii) {
        if deep(p) {
            let exact = if r == big { v_big } else { v_small };
            assert!(
                !c.boundary && (c.volume - exact).abs() < 1e-9,
                "cell at {p:?}: {c:?} vs {exact}"
            );
        }
    }
    let only = |want: f64| -> Vec<bool> { centres.iter().zip(&radii).map(|(p, &r)| deep(p) && r == want).collect() };
    let eta_big = packing_fraction(&cells, &radii, &only(big)).unwrap();
    let eta_small = packing_fraction(&cells, &radii, &only(small)).unwrap();
    assert!((eta_big - ball(big) / v_big).abs() < 1e-12, "big: {eta_big}");
    assert!((eta_small - ball(small) / v_small).abs() < 1e-12, "small: {eta_small}");
    // bisector cells: the small spheres' cells take part of the big spheres (their η drops well below the exact one)
    let bisector = voronoi_cells(&centres, 3.0 * a);
    let eta_small_bisector = packing_fraction(&bisector, &radii, &only(small)).unwrap();
    assert!(
        eta_small_bisector < ball(small) / v_small - 0.1,
        "bisector: {eta_small_bisector}"
    );
    // equal radii: radical cells are the bisector cells, bit for bit
    let hcp = hcp_centres(1.0, 5.0);
    assert_eq!(
        radical_cells(&hcp, &vec![1.0; hcp.len()], 4.0),
        voronoi_cells(&hcp, 4.0)
    );
}
