//! The JSON report written beside every aggregate (`NAME.json`): counts, radii, grain and bulk density, the
//! interior packing fraction (Zhang17 Eqs. 13–14: Voronoi cells, interior particles only), the semi-axes
//! a ≥ b ≥ c and axis ratios (Zhang17 §3.1), and how the aggregate was built.

use crate::aggregate::random_packing::{Recipe, StageLog};
use crate::aggregate::shape::Shape;
use crate::geometry::shape_metrics::axis_lengths;
use crate::geometry::voronoi::{packing_fraction, radical_cells};
use crate::granular::soft::particle::Particle;
use serde::{Deserialize, Serialize};

/// Interior particles lie at least this many largest radii inside the shape (see
/// [`Shape::contains_with_margin`]); the Voronoi cells start as cubes of half-side `VORONOI_HALF_SIZE` r_max.
pub const INTERIOR_DEPTH: f64 = 2.0;
/// Half-side of the Voronoi starting cube, in largest radii.
pub const VORONOI_HALF_SIZE: f64 = 3.0;

/// The report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AggregateReport {
    /// Model name (hcp, rcp, rcpc, pp1, pp2, ppc).
    pub model: String,
    /// The shape, in words.
    pub shape: String,
    /// Shape volume (m³).
    pub shape_volume_m3: f64,
    /// Shape's volume-equivalent diameter (m).
    pub shape_equivalent_diameter_m: f64,
    /// Seed of the random choices.
    pub seed: u64,
    /// Number of particles.
    pub n: usize,
    /// Smallest radius (m).
    pub r_min_m: f64,
    /// Largest radius (m).
    pub r_max_m: f64,
    /// Mean radius (m).
    pub r_mean_m: f64,
    /// Grain density (kg/m³), of the shell where there is a denser core.
    pub grain_density_kg_m3: f64,
    /// Grain density of the core (kg/m³), PPC only.
    pub core_grain_density_kg_m3: Option<f64>,
    /// Core radius (m), RCPC and PPC.
    pub core_radius_m: Option<f64>,
    /// Particles in the core.
    pub n_core: Option<usize>,
    /// Total mass (kg).
    pub total_mass_kg: f64,
    /// Total mass / shape volume (kg/m³).
    pub bulk_density_kg_m3: f64,
    /// Interior packing fraction (Voronoi, boundary cells and particles within the interior depth excluded).
    pub interior_packing_fraction: Option<f64>,
    /// Particles counted in it.
    pub n_interior: usize,
    /// Grains' volume / shape volume.
    pub filling_fraction: f64,
    /// Semi-axes along the principal axes of inertia (m), extents including radii.
    pub a_m: f64,
    /// Intermediate semi-axis (m).
    pub b_m: f64,
    /// Shortest semi-axis (m).
    pub c_m: f64,
    /// b/a.
    pub b_over_a: f64,
    /// c/a.
    pub c_over_a: f64,
    /// Centre of mass (m) in the shape's frame.
    pub centre_of_mass_m: [f64; 3],
    /// Largest overlap between two grains / smaller radius.
    pub max_overlap_fraction: f64,
    /// Wall-clock build time (s).
    pub build_seconds: f64,
    /// The random-packing recipe (random models).
    pub recipe: Option<Recipe>,
    /// What each stage of the recipe did.
    pub stages: Vec<StageLog>,
    /// Grains in the settled heap before carving (random models).
    pub heap_n: Option<usize>,
    /// Free text: how the radii were chosen (scaling relative to the paper).
    pub notes: String,
    /// How the lattice (HCP, RCPC's core) was turned before carving: `perpendicular`, `parallel`, `tilt:DEG` or
    /// `random:SEED` ([`crate::aggregate::lattice_orientation`]); absent for models without a lattice and in
    /// reports written before it was recorded (those lattices are `perpendicular`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lattice_orientation: Option<String>,
    /// Angle (degrees, 0–90) between the lattice's stacking axis and the spin axis z.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lattice_tilt_deg: Option<f64>,
}

/// Largest pairwise overlap over the smaller radius (0 if none).
pub fn max_overlap_fraction(particles: &[Particle]) -> f64 {
    let centres: Vec<_> = particles.iter().map(|p| p.position).collect();
    let radii: Vec<f64> = particles.iter().map(|p| p.radius).collect();
    crate::geometry::neighbours::sphere_pairs(&centres, &radii)
        .into_iter()
        .map(|(i, j)| {
            let d = (centres[i] - centres[j]).norm();
            ((radii[i] + radii[j] - d) / radii[i].min(radii[j])).max(0.0)
        })
        .fold(0.0, f64::max)
}

/// Interior packing fraction and the number of interior particles counted.
pub fn interior_packing(particles: &[Particle], shape: &Shape) -> (Option<f64>, usize) {
    let centres: Vec<_> = particles.iter().map(|p| p.position).collect();
    let radii: Vec<f64> = particles.iter().map(|p| p.radius).collect();
    let r_max = radii.iter().cloned().fold(0.0, f64::max);
    let cells = radical_cells(&centres, &radii, VORONOI_HALF_SIZE * r_max);
    let interior: Vec<bool> = centres
        .iter()
        .map(|c| shape.contains_with_margin(c, INTERIOR_DEPTH * r_max))
        .collect();
    let counted = cells.iter().zip(&interior).filter(|(c, k)| **k && !c.boundary).count();
    (packing_fraction(&cells, &radii, &interior), counted)
}

/// The geometric part of the report (everything but model, seed, recipe, timings and notes, which the caller fills).
pub fn measure(particles: &[Particle], shape: &Shape) -> AggregateReport {
    let n = particles.len();
    let centres: Vec<_> = particles.iter().map(|p| p.position).collect();
    let masses: Vec<f64> = particles.iter().map(|p| p.mass).collect();
    let radii: Vec<f64> = particles.iter().map(|p| p.radius).collect();
    let ax = axis_lengths(&centres, &masses, &radii);
    let total_mass: f64 = masses.iter().sum();
    let grains: f64 = radii.iter().map(|r| 4.0 / 3.0 * std::f64::consts::PI * r.powi(3)).sum();
    let (eta, n_interior) = interior_packing(particles, shape);
    let volume = shape.volume();
    AggregateReport {
        model: String::new(),
        shape: shape.describe(),
        shape_volume_m3: volume,
        shape_equivalent_diameter_m: shape.equivalent_diameter(),
        seed: 0,
        n,
        r_min_m: radii.iter().cloned().fold(f64::INFINITY, f64::min),
        r_max_m: radii.iter().cloned().fold(0.0, f64::max),
        r_mean_m: radii.iter().sum::<f64>() / n as f64,
        grain_density_kg_m3: total_mass / grains,
        core_grain_density_kg_m3: None,
        core_radius_m: None,
        n_core: None,
        total_mass_kg: total_mass,
        bulk_density_kg_m3: total_mass / volume,
        interior_packing_fraction: eta,
        n_interior,
        filling_fraction: grains / volume,
        a_m: ax.a,
        b_m: ax.b,
        c_m: ax.c,
        b_over_a: ax.b_over_a(),
        c_over_a: ax.c_over_a(),
        centre_of_mass_m: [ax.centre.x, ax.centre.y, ax.centre.z],
        max_overlap_fraction: max_overlap_fraction(particles),
        build_seconds: 0.0,
        recipe: None,
        stages: Vec::new(),
        heap_n: None,
        notes: String::new(),
        lattice_orientation: None,
        lattice_tilt_deg: None,
    }
}
