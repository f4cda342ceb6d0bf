//! Aggregate builders for spin-up studies (Zhang17 §2.3.2, Table 2): the six rubble-pile models HCP, RCP, RCPC,
//! PP1, PP2 and PPC, carved from a shape, with masses set by a bulk density, written in the soft-sphere
//! particle-file format so spin-up scenes can load them.
//!
//! - [`shape`]: sphere, ellipsoid, Didymos-like top, [`triaxial_top`] (Naidu et al. 2020's Didymos), OBJ model
//!   (`contains`, volume);
//! - [`size_distribution`]: `dN/dr ∝ r⁻³` radii;
//! - [`hcp`]: lattice carving, turned as [`lattice_orientation`] says; [`random_packing`]: the collapse → shaking → settling recipe on the SSDEM engine;
//! - [`core`]: RCPC's HCP core and PPC's denser core; [`density`]: masses from a bulk density and its variants;
//! - [`report`]: the JSON report.
//!
//! Grain radii: `--radius-m` / `--radius-range-m` directly, or from a requested count `N` via the shape's volume and
//! an assumed packing fraction ([`expected_packing`]); the count actually carved is reported.

pub mod core;
pub mod density;
pub mod files;
pub mod hcp;
pub mod lattice_orientation;
pub mod random_packing;
pub mod report;
pub mod shape;
pub mod size_distribution;
pub mod top;
pub mod triaxial_top;

use crate::aggregate::lattice_orientation::LatticeOrientation;
use crate::aggregate::random_packing::{BuildProgress, Recipe, random_heap};
use crate::aggregate::report::{AggregateReport, measure};
use crate::aggregate::shape::Shape;
use crate::aggregate::size_distribution::PowerLawRadii;
use crate::granular::soft::particle::Particle;
use crate::math::Vec3;
use crate::random::generator;

/// The six models of Zhang17 Table 2.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Model {
    /// Hexagonal close packing of equal spheres.
    Hcp,
    /// Monodisperse random close packing.
    Rcp,
    /// RCP shell around an HCP core.
    Rcpc,
    /// Polydisperse, r⁻³ over 4–32 m at the paper's scale.
    Pp1,
    /// Polydisperse, r⁻³ over 4–16 m at the paper's scale.
    Pp2,
    /// PP1 with a core of 1.5× grain density.
    Ppc,
}

impl Model {
    /// Parses a model name (`hcp`, `rcp`, `rcpc`, `pp1`, `pp2`, `ppc`).
    pub fn parse(s: &str) -> Option<Model> {
        let all = [Model::Hcp, Model::Rcp, Model::Rcpc, Model::Pp1, Model::Pp2, Model::Ppc];
        all.into_iter().find(|m| m.name() == s)
    }

    /// The model's name.
    pub fn name(self) -> &'static str {
        match self {
            Model::Hcp => "hcp",
            Model::Rcp => "rcp",
            Model::Rcpc => "rcpc",
            Model::Pp1 => "pp1",
            Model::Pp2 => "pp2",
            Model::Ppc => "ppc",
        }
    }

    /// Zhang17 Table 2: particle count and radius range (m) of the paper's model in the 780 m Didymos shape.
    pub fn paper(self) -> (usize, f64, f64) {
        match self {
            Model::Hcp => (42062, 10.0, 10.0),
            Model::Rcp => (36523, 10.0, 10.0),
            Model::Rcpc => (37081, 10.0, 10.0),
            Model::Pp1 => (47761, 4.0, 32.0),
            Model::Pp2 => (95637, 4.0, 16.0),
            Model::Ppc => (47761, 4.0, 32.0),
        }
    }

    /// Whether the grains are polydisperse.
    pub fn polydisperse(self) -> bool {
        matches!(self, Model::Pp1 | Model::Pp2 | Model::Ppc)
    }
}

/// Packing fraction assumed when a grain size is derived from a requested count: π/(3√2) for HCP, 0.62 for the
/// monodisperse random models (near random close packing), 0.70 for the polydisperse ones.
pub fn expected_packing(model: Model) -> f64 {
    match model {
        Model::Hcp => hcp::HCP_PACKING,
        Model::Rcp | Model::Rcpc => 0.62,
        _ => 0.70,
    }
}

/// How the grain sizes are given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Grains {
    /// About this many particles in the shape.
    Count(usize),
    /// This radius (m), monodisperse models.
    Radius(f64),
    /// This radius range (m), polydisperse models.
    Range(f64, f64),
}

/// Everything a build needs.
#[derive(Debug, Clone)]
pub struct BuildSpec {
    /// The model.
    pub model: Model,
    /// The shape carved.
    pub shape: Shape,
    /// Grain sizes.
    pub grains: Grains,
    /// Bulk density (kg/m³): total mass / shape volume.
    pub bulk_density: f64,
    /// Seed.
    pub seed: u64,
    /// Core radius (m) for RCPC and PPC; default [`core::default_core_radius`].
    pub core_radius: Option<f64>,
    /// Random-packing recipe.
    pub recipe: Recipe,
    /// How the lattice of HCP (and of RCPC's core) is turned before carving; default: layers ⟂ the spin axis.
    pub orientation: LatticeOrientation,
}

/// Why a build was refused or failed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum AggregateError {
    /// Bad input, naming the field and what was expected.
    #[error("{field}: {message}")]
    Input {
        /// The field (CLI flag).
        field: String,
        /// What was expected.
        message: String,
    },
    /// The build itself failed.
    #[error("{0}")]
    Failed(String),
}

impl Recipe {
    /// The default recipe with a user's choices: `shake_periods` (≥ 0) and `gravity_interval` (self-gravity every K
    /// steps, 1 ≤ K ≤ a fifth of the steps per contact). Bad values are an input error naming the flag.
    pub fn with_overrides(shake_periods: Option<f64>, gravity_interval: Option<u64>) -> Result<Recipe, AggregateError> {
        let mut recipe = Recipe::default();
        if let Some(p) = shake_periods {
            if !(p.is_finite() && p >= 0.0) {
                return Err(input("--shake-periods", format!("a number of periods >= 0, got {p}")));
            }
            recipe.shake_periods = p;
        }
        if let Some(k) = gravity_interval {
            let most = (recipe.steps_per_contact / 5.0).floor() as u64;
            if !(1..=most).contains(&k) {
                return Err(input(
                    "--gravity-interval",
                    format!(
                        "steps between self-gravity evaluations, 1 to {most} (steps per contact {} / 5), got {k}",
                        recipe.steps_per_contact
                    ),
                ));
            }
            recipe.gravity_interval = k;
        }
        Ok(recipe)
    }
}

fn input(field: &str, message: impl Into<String>) -> AggregateError {
    AggregateError::Input {
        field: field.into(),
        message: message.into(),
    }
}

/// A built aggregate and its report.
#[derive(Debug, Clone)]
pub struct Aggregate {
    /// The grains, at rest, in the shape's frame.
    pub particles: Vec<Particle>,
    /// The report.
    pub report: AggregateReport,
}

/// The smallest count accepted.
pub const MIN_PARTICLES: usize = 20;

/// The radius (m, monodisperse) or radius law (polydisperse) the spec asks for, and a note on the scaling.
fn grain_sizes(spec: &BuildSpec) -> Result<(Option<f64>, Option<PowerLawRadii>, String), AggregateError> {
    let volume = spec.shape.volume();
    let phi = expected_packing(spec.model);
    let (paper_n, paper_lo, paper_hi) = spec.model.paper();
    let ball = 4.0 / 3.0 * std::f64::consts::PI;
    match (spec.grains, spec.model.polydisperse()) {
        (Grains::Count(n), _) if n < MIN_PARTICLES => Err(input(
            "--particles",
            format!("at least {MIN_PARTICLES} particles, got {n}"),
        )),
        (Grains::Count(n), false) => {
            let r = (phi * volume / (n as f64 * ball)).cbrt();
            let note = format!(
                "radius from N = {n} at packing {phi:.4}: r = {r:.4} m = paper's {paper_lo} m × {:.4} (paper N = {paper_n}; (paper N / N)^(1/3) = {:.4})",
                r / paper_lo,
                (paper_n as f64 / n as f64).cbrt()
            );
            Ok((Some(r), None, note))
        }
        (Grains::Count(n), true) => {
            let law = PowerLawRadii::inverse_cube(paper_lo, paper_hi).expect("paper range is valid");
            let s = (phi * volume / (n as f64 * ball * law.moment(3.0))).cbrt();
            let note = format!(
                "radius range from N = {n} at packing {phi:.2}: paper's {paper_lo}–{paper_hi} m × {s:.4} (paper N = {paper_n}; (paper N / N)^(1/3) = {:.4})",
                (paper_n as f64 / n as f64).cbrt()
            );
            Ok((None, Some(law.scaled(s)), note))
        }
        (Grains::Radius(r), false) => {
            if !(r.is_finite() && r > 0.0) {
                return Err(input("--radius-m", format!("a positive radius in m, got {r}")));
            }
            Ok((Some(r), None, format!("radius given: {r} m")))
        }
        (Grains::Radius(_), true) => Err(input(
            "--radius-m",
            "polydisperse models take --radius-range-m RMIN,RMAX (m)",
        )),
        (Grains::Range(lo, hi), true) => match PowerLawRadii::inverse_cube(lo, hi) {
            Some(law) => Ok((None, Some(law), format!("radius range given: {lo}–{hi} m"))),
            None => Err(input(
                "--radius-range-m",
                format!("0 < RMIN < RMAX in m, got {lo},{hi}"),
            )),
        },
        (Grains::Range(..), false) => Err(input("--radius-range-m", "monodisperse models take --radius-m R (m)")),
    }
}

/// Builds an aggregate. Deterministic: the same spec gives the same particles bit for bit.
pub fn build(spec: &BuildSpec) -> Result<Aggregate, AggregateError> {
    build_with_progress(spec, &mut |_| {})
}

/// [`build`], telling `progress` where the random-packing recipe stands (HCP lattices are built at once).
pub fn build_with_progress(
    spec: &BuildSpec,
    progress: &mut dyn FnMut(BuildProgress<'_>),
) -> Result<Aggregate, AggregateError> {
    let started = std::time::Instant::now();
    if !(spec.bulk_density.is_finite() && spec.bulk_density > 0.0) {
        return Err(input(
            "--bulk-density-kg-m3",
            format!("a positive density in kg/m³, got {}", spec.bulk_density),
        ));
    }
    let (radius, law, mut notes) = grain_sizes(spec)?;
    let r_max = radius.or(law.map(|l| l.r_max)).unwrap_or(0.0);
    let bounding = spec.shape.bounding_radius();
    if r_max > 0.25 * bounding {
        return Err(input(
            "--particles/--radius-m",
            format!(
                "grains of radius {r_max:.4e} m are too large for a shape of bounding radius {bounding:.4e} m (at most a quarter)"
            ),
        ));
    }
    let core_radius = match spec.model {
        Model::Rcpc | Model::Ppc => {
            let c = spec
                .core_radius
                .unwrap_or_else(|| core::default_core_radius(spec.shape.equivalent_diameter()));
            if !(c.is_finite() && c > 0.0 && c < bounding) {
                return Err(input(
                    "--core-radius-m",
                    format!("a radius in m between 0 and {bounding:.4e}, got {c}"),
                ));
            }
            Some(c)
        }
        _ => None,
    };
    let has_lattice = matches!(spec.model, Model::Hcp | Model::Rcpc);
    if !has_lattice && spec.orientation != LatticeOrientation::default() {
        return Err(input(
            "--lattice-orientation",
            format!("only hcp and rcpc have a lattice to turn, not {}", spec.model.name()),
        ));
    }
    let rotation = spec.orientation.rotation(spec.seed);
    let mut rng = generator(spec.seed);
    // Grains before carving: centres about the shape's origin, radii, density weights.
    let mut heap_n = None;
    let mut stages = Vec::new();
    let (centres, radii): (Vec<Vec3>, Vec<f64>) = if spec.model == Model::Hcp {
        let r = radius.expect("monodisperse");
        let c = hcp::hcp_carve_oriented(&spec.shape, r, &rotation);
        let n = c.len();
        (c, vec![r; n])
    } else {
        // The heap must cover the shape's bounding ball plus two grains of loose surface layer.
        let heap_radius = bounding + 2.0 * r_max;
        let phi_heap = 0.6;
        let heap_radii: Vec<f64> = match (radius, law) {
            (Some(r), _) => vec![r; (phi_heap * (heap_radius / r).powi(3)).ceil() as usize],
            (None, Some(l)) => {
                let n = (phi_heap * heap_radius.powi(3) / l.moment(3.0)).ceil() as usize;
                (0..n).map(|_| l.sample(&mut rng)).collect()
            }
            _ => unreachable!("grain_sizes gives a radius or a law"),
        };
        let insert = match (spec.model, core_radius) {
            (Model::Rcpc, Some(c)) => Some(core::hcp_core(radius.expect("monodisperse"), c, &rotation)),
            _ => None,
        };
        let rho_build = spec.bulk_density / expected_packing(spec.model);
        let heap = random_heap(
            &heap_radii,
            rho_build,
            &spec.recipe,
            &mut rng,
            insert.as_ref(),
            progress,
        )
        .ok_or_else(|| AggregateError::Failed("the random cloud could not be placed".into()))?;
        heap_n = Some(heap.centres.len());
        stages = heap.stages;
        heap.centres
            .into_iter()
            .zip(heap.radii)
            .filter(|(c, _)| spec.shape.contains(c))
            .unzip()
    };
    if centres.len() < MIN_PARTICLES {
        return Err(input(
            "--particles/--radius-m",
            format!(
                "only {} grains fit in the shape; at least {MIN_PARTICLES} are needed (smaller grains)",
                centres.len()
            ),
        ));
    }
    let weights = match (spec.model, core_radius) {
        (Model::Ppc, Some(c)) => core::core_weights(&centres, c, core::PPC_CORE_DENSITY_RATIO),
        _ => vec![1.0; centres.len()],
    };
    // Massless until the bulk density sets the masses.
    let mut particles = random_packing::particles(&centres, &radii, 0.0);
    let rho_g = density::assign_masses(&mut particles, &weights, spec.shape.volume(), spec.bulk_density);
    let mut report = measure(&particles, &spec.shape);
    report.model = spec.model.name().into();
    report.seed = spec.seed;
    report.grain_density_kg_m3 = rho_g;
    if let Some(c) = core_radius {
        report.core_radius_m = Some(c);
        report.n_core = Some(centres.iter().filter(|p| p.norm() <= c).count());
        if spec.model == Model::Ppc {
            report.core_grain_density_kg_m3 = Some(rho_g * core::PPC_CORE_DENSITY_RATIO);
        }
    }
    if spec.model != Model::Hcp {
        report.recipe = Some(spec.recipe);
        report.heap_n = heap_n;
        notes.push_str("; carved from the settled heap, centred on its centre of mass");
    }
    if has_lattice {
        report.lattice_orientation = Some(spec.orientation.name(spec.seed));
        report.lattice_tilt_deg = Some(spec.orientation.stacking_axis_tilt_deg(spec.seed));
    }
    report.stages = stages;
    report.notes = notes;
    report.build_seconds = started.elapsed().as_secs_f64();
    Ok(Aggregate { particles, report })
}
