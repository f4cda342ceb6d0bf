//! Lattice-built aggregates (Zhang17 §2.3.2, Table 2): HCP packing fraction, requested bulk density, axis ratios
//! of a carved ellipsoid, carving by an OBJ model, the density variant and PPC's denser core.

use rubblepile::aggregate::core::{core_weights, hcp_core};
use rubblepile::aggregate::density::{assign_masses, rescale_bulk_density};
use rubblepile::aggregate::hcp::{HCP_PACKING, hcp_carve};
use rubblepile::aggregate::random_packing::Recipe;
use rubblepile::aggregate::shape::Shape;
use rubblepile::aggregate::{BuildSpec, Grains, Model, build};
use rubblepile::analysis::shape_metrics::axis_lengths;
use rubblepile::granular::soft::particle::Particle;
use rubblepile::math::Vec3;

fn spec(model: Model, shape: Shape, grains: Grains, bulk_density: f64) -> BuildSpec {
    BuildSpec {
        model,
        shape,
        grains,
        bulk_density,
        seed: 7,
        core_radius: None,
        recipe: Recipe::default(),
        orientation: Default::default(),
    }
}

/// The Voronoi interior packing of an HCP aggregate is π/(3√2) = 0.7405 (boundary cells excluded), and the
/// requested bulk density is met to rounding.
#[test]
fn hcp_aggregate_interior_packing_is_0_7405_and_bulk_density_is_met() {
    let agg = build(&spec(
        Model::Hcp,
        Shape::Sphere { radius: 100.0 },
        Grains::Radius(5.0),
        2100.0,
    ))
    .unwrap();
    let eta = agg.report.interior_packing_fraction.unwrap();
    assert!((eta - 0.7405).abs() < 0.002, "η = {eta}");
    assert!((HCP_PACKING - 0.74048).abs() < 1e-5);
    assert!(agg.report.n_interior > 1000, "{}", agg.report.n_interior);
    let mass: f64 = agg.particles.iter().map(|p| p.mass).sum();
    let rho = mass / Shape::Sphere { radius: 100.0 }.volume();
    assert!((rho / 2100.0 - 1.0).abs() < 1e-12, "{rho}");
    // grain density × grain volume = mass: the report's grain density is the particles'
    let grains: f64 = agg
        .particles
        .iter()
        .map(|p| 4.0 / 3.0 * std::f64::consts::PI * p.radius.powi(3))
        .sum();
    assert!((agg.report.grain_density_kg_m3 * grains / mass - 1.0).abs() < 1e-12);
}

/// Acceptance (issue 7): an ellipsoid-shape aggregate has the shape's axis ratios within 1 %.
#[test]
fn carved_ellipsoid_keeps_axis_ratios_within_one_percent() {
    let shape = Shape::Ellipsoid {
        axes: [1000.0, 800.0, 600.0],
    };
    // the ratios are off by up to about (layer spacing + r)/c: r = c/120 keeps that under 1 %
    let r = 5.0;
    let centres = hcp_carve(&shape, r);
    let n = centres.len();
    let ax = axis_lengths(&centres, &vec![1.0; n], &vec![r; n]);
    let (ba, ca) = (ax.b_over_a(), ax.c_over_a());
    assert!((ba / 0.8 - 1.0).abs() < 0.01, "b/a {ba} (N = {n})");
    assert!((ca / 0.6 - 1.0).abs() < 0.01, "c/a {ca} (N = {n})");
}

/// Every particle of an aggregate carved from the Itokawa radar model is inside it (brute-force ray parity
/// along another axis as the oracle), and the shape is filled (filling fraction near HCP's).
#[test]
fn obj_carved_aggregate_lies_inside_the_polyhedron() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/targets/shapes/itokawa_radar_25143.obj");
    let shape = Shape::parse(&format!("obj:{path}"), 1000.0).unwrap();
    let agg = build(&spec(Model::Hcp, shape.clone(), Grains::Radius(8.0), 1900.0)).unwrap();
    let Shape::Polyhedron { model, .. } = &shape else {
        unreachable!()
    };
    assert!(agg.particles.len() > 3000, "{}", agg.particles.len());
    assert!(agg.particles.iter().all(|p| model.contains_brute_force(&p.position)));
    // centres inside the surface: the grains fill a little less than the lattice would
    assert!(
        agg.report.filling_fraction > 0.6 && agg.report.filling_fraction < 0.8,
        "{}",
        agg.report.filling_fraction
    );
}

/// The bulk-density variant (ρ_B = 2100 · M_a/M_P, Zhang17 §4.2) keeps positions and radii and scales every
/// mass by the same factor, so the new bulk density is met.
#[test]
fn density_variant_keeps_positions_and_scales_masses() {
    let shape = Shape::parse("top:300", 1.0).unwrap();
    let agg = build(&spec(Model::Hcp, shape.clone(), Grains::Count(800), 2100.0)).unwrap();
    let mut variant = agg.particles.clone();
    let factor = rescale_bulk_density(&mut variant, shape.volume(), 1600.0);
    assert!((factor - 1600.0 / 2100.0).abs() < 1e-12);
    for (a, b) in agg.particles.iter().zip(&variant) {
        assert_eq!((a.position, a.radius), (b.position, b.radius));
        assert!((b.mass / a.mass - factor).abs() < 1e-14);
    }
    let rho: f64 = variant.iter().map(|p| p.mass).sum::<f64>() / shape.volume();
    assert!((rho / 1600.0 - 1.0).abs() < 1e-12);
}

/// PPC: grains within the core radius have exactly 1.5 times the shell's grain density and the bulk density is
/// still the requested one; RCPC's core is an HCP lattice (12 touching neighbours inside, no overlaps).
#[test]
fn core_variants_have_the_requested_density_ratio_and_structure() {
    let r = 5.0;
    let centres = hcp_carve(&Shape::Sphere { radius: 100.0 }, r);
    let weights = core_weights(&centres, 50.0, 1.5);
    let mut ps: Vec<Particle> = centres
        .iter()
        .map(|&position| Particle {
            mass: 0.0,
            radius: r,
            position,
            velocity: Vec3::zeros(),
            spin: Vec3::zeros(),
        })
        .collect();
    let volume = Shape::Sphere { radius: 100.0 }.volume();
    let rho_g = assign_masses(&mut ps, &weights, volume, 2100.0);
    let grain = |p: &Particle| p.mass / (4.0 / 3.0 * std::f64::consts::PI * p.radius.powi(3));
    for p in &ps {
        let want = if p.position.norm() <= 50.0 { 1.5 * rho_g } else { rho_g };
        assert!((grain(p) / want - 1.0).abs() < 1e-12);
    }
    assert!(ps.iter().any(|p| p.position.norm() <= 50.0) && ps.iter().any(|p| p.position.norm() > 50.0));
    let total: f64 = ps.iter().map(|p| p.mass).sum();
    assert!((total / volume / 2100.0 - 1.0).abs() < 1e-12);

    let core = hcp_core(r, 40.0, &rubblepile::math::Mat3::identity());
    assert!(core.centres.iter().all(|c| c.norm() <= 40.0));
    for c in core.centres.iter().filter(|c| c.norm() < 40.0 - 2.5 * r) {
        let touching = core
            .centres
            .iter()
            .filter(|d| ((*d - c).norm() - 2.0 * r).abs() < 1e-9)
            .count();
        assert_eq!(touching, 12);
        assert!(core.centres.iter().all(|d| d == c || (d - c).norm() > 2.0 * r - 1e-9));
    }
}
