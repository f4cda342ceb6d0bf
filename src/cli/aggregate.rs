//! `rubblepile aggregate build|density`: rubble-pile aggregates for spin-up studies (Zhang17 §2.3.2, Table 2;
//! see [`rubblepile::aggregate`]) written as a particle file (`t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz`, the
//! soft-sphere scene's `particles_file`) with a JSON report beside it (`NAME.json`).

use std::path::PathBuf;

use crate::cli::common::CliError;
use rubblepile::aggregate::files::{check_outputs, density_variant, write_aggregate};
use rubblepile::aggregate::random_packing::{BuildProgress, Recipe};
use rubblepile::aggregate::shape::Shape;
use rubblepile::aggregate::{BuildSpec, Grains, Model, build_with_progress};

/// `rubblepile aggregate …`.
#[derive(Debug, clap::Subcommand)]
pub enum AggregateCommand {
    /// Build an aggregate (HCP lattice or the random-packing recipe), carve it, set masses, write CSV + JSON.
    Build(BuildArgs),
    /// Bulk-density variant of an aggregate: same positions and radii, masses scaled (ρ_B = 2100 · M_a/M_P).
    Density(DensityArgs),
}

/// `rubblepile aggregate build`.
#[derive(Debug, clap::Args)]
pub struct BuildArgs {
    /// Model: hcp, rcp, rcpc, pp1, pp2 or ppc (Zhang17 Table 2).
    #[arg(long)]
    pub model: String,
    /// Shape: sphere:R, ellipsoid:A,B,C (semi-axes), top[:D_EQ] (axisymmetric Didymos-like top, default 780 m),
    /// didymos[:LX,LY,LZ,D_EQ] (Naidu et al. 2020: extents 832 × 838 × 786 m, D_eq 780 m, with an equatorial
    /// bulge), obj:PATH (m).
    #[arg(long)]
    pub shape: String,
    /// Multiply OBJ coordinates by this (1000 for a model in km).
    #[arg(long, default_value_t = 1.0)]
    pub obj_scale: f64,
    /// About this many particles (grain size from the shape's volume and an assumed packing fraction).
    #[arg(long, conflicts_with_all = ["radius", "radius_range"])]
    pub particles: Option<usize>,
    /// Grain radius (m), monodisperse models.
    #[arg(long = "radius-m", conflicts_with = "radius_range", allow_negative_numbers = true)]
    pub radius: Option<f64>,
    /// Radius range RMIN,RMAX (m), polydisperse models (dN/dr ∝ r⁻³).
    #[arg(long = "radius-range-m", value_name = "RMIN,RMAX")]
    pub radius_range: Option<String>,
    /// Bulk density (kg/m³): total mass / shape volume.
    #[arg(long = "bulk-density-kg-m3", default_value_t = 2100.0, allow_negative_numbers = true)]
    pub bulk_density: f64,
    /// Core radius (m) for rcpc and ppc (default: Zhang17's 200 m scaled to the shape, 200/390 of its
    /// volume-equivalent radius).
    #[arg(long = "core-radius-m")]
    pub core_radius: Option<f64>,
    /// Seed of every random choice.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// How the lattice of hcp (and of rcpc's core) is turned before carving: perpendicular (close-packed layers ⟂
    /// the spin axis z), parallel (layers containing it), tilt:DEG (stacking axis DEG degrees from z) or
    /// random[:SEED] (uniform over rotations; default SEED: --seed). Recorded in NAME.json.
    #[arg(long, value_name = "ORIENTATION", default_value = "perpendicular")]
    pub lattice_orientation: String,
    /// Shaking periods of the random-packing recipe (default 10).
    #[arg(long)]
    pub shake_periods: Option<f64>,
    /// Self-gravity every K steps in the recipe's collapse and settle stages (r-RESPA; 1 ≤ K ≤ 4, the recipe's
    /// 20 steps per contact over 5). Default 1.
    #[arg(long, value_name = "K")]
    pub gravity_interval: Option<u64>,
    /// The particle file to write; NAME.json goes beside it.
    #[arg(long, value_name = "FILE.csv")]
    pub out: PathBuf,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
}

/// `rubblepile aggregate density`.
#[derive(Debug, clap::Args)]
pub struct DensityArgs {
    /// An aggregate written by `aggregate build` (its NAME.json must be beside it), or a snapshot of one (with
    /// `--report`).
    #[arg(long, value_name = "FILE.csv")]
    pub input: PathBuf,
    /// The aggregate's report (`NAME.json` of `aggregate build`) when it is not beside `--input`, e.g. for a
    /// settled snapshot: its shape volume sets the bulk density.
    #[arg(long, value_name = "FILE.json")]
    pub report: Option<PathBuf>,
    /// New bulk density (kg/m³).
    #[arg(long = "bulk-density-kg-m3")]
    pub bulk_density: f64,
    /// The particle file to write; NAME.json goes beside it.
    #[arg(long, value_name = "FILE.csv")]
    pub out: PathBuf,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
}

/// Bad input to the aggregate layer is a usage error; a failed build is a failure.
fn cli_error(e: rubblepile::aggregate::AggregateError) -> CliError {
    match e {
        rubblepile::aggregate::AggregateError::Input { .. } => CliError::usage(e),
        rubblepile::aggregate::AggregateError::Failed(_) => CliError::failed(e),
    }
}

fn grains(args: &BuildArgs) -> Result<Grains, CliError> {
    match (args.particles, args.radius, &args.radius_range) {
        (Some(n), None, None) => Ok(Grains::Count(n)),
        (None, Some(r), None) => Ok(Grains::Radius(r)),
        (None, None, Some(s)) => {
            let v: Vec<f64> = s
                .split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| CliError::usage(format!("--radius-range-m: expected RMIN,RMAX in m, got `{s}`")))?;
            match v[..] {
                [lo, hi] => Ok(Grains::Range(lo, hi)),
                _ => Err(CliError::usage(format!(
                    "--radius-range-m: expected RMIN,RMAX in m, got `{s}`"
                ))),
            }
        }
        _ => Err(CliError::usage(
            "give one of --particles N, --radius-m R (m) or --radius-range-m RMIN,RMAX (m)",
        )),
    }
}

/// Runs `aggregate build`.
pub fn build_cmd(args: &BuildArgs) -> Result<(), CliError> {
    let model = Model::parse(&args.model).ok_or_else(|| {
        CliError::usage(format!(
            "--model: unknown model `{}`; expected hcp, rcp, rcpc, pp1, pp2 or ppc",
            args.model
        ))
    })?;
    check_outputs(&args.out, args.force).map_err(cli_error)?;
    let shape = Shape::parse(&args.shape, args.obj_scale).map_err(CliError::usage)?;
    let recipe = Recipe::with_overrides(args.shake_periods, args.gravity_interval).map_err(cli_error)?;
    let spec = BuildSpec {
        model,
        shape,
        grains: grains(args)?,
        bulk_density: args.bulk_density,
        seed: args.seed,
        core_radius: args.core_radius,
        recipe,
        orientation: args.lattice_orientation.parse().map_err(CliError::usage)?,
    };
    let agg = build_with_progress(&spec, &mut build_progress()).map_err(cli_error)?;
    write_aggregate(&args.out, &agg.particles, &agg.report).map_err(cli_error)?;
    let r = &agg.report;
    println!(
        "{}: {} N = {}, r {:.4}–{:.4} m, grain density {:.1} kg/m³, bulk {:.1} kg/m³, interior packing {}, b/a {:.4}, c/a {:.4}, {:.1} s",
        args.out.display(),
        r.model,
        r.n,
        r.r_min_m,
        r.r_max_m,
        r.grain_density_kg_m3,
        r.bulk_density_kg_m3,
        r.interior_packing_fraction.map_or("n/a".into(), |x| format!("{x:.4}")),
        r.b_over_a,
        r.c_over_a,
        r.build_seconds
    );
    Ok(())
}

/// Wall time between two progress lines when stderr is not a terminal (s).
const PROGRESS_LINE_EVERY_S: f64 = 300.0;

/// The build's progress display: a spinner on a terminal; otherwise (a log file) a line on stderr at the start
/// of every stage and every few minutes within one, so that a background build shows where it stands.
fn build_progress() -> impl FnMut(BuildProgress<'_>) {
    use std::io::IsTerminal;
    let started = std::time::Instant::now();
    let bar = std::io::stderr().is_terminal().then(|| {
        let b = indicatif::ProgressBar::new_spinner();
        b.enable_steady_tick(std::time::Duration::from_millis(200));
        b
    });
    let mut last_line = f64::NEG_INFINITY;
    move |p: BuildProgress<'_>| {
        let wall = started.elapsed().as_secs_f64();
        let percent = 100.0 * p.step as f64 / p.steps.max(1) as f64;
        let text = format!(
            "aggregate build: {} step {}/{} ({percent:.0} %), {wall:.0} s",
            p.stage, p.step, p.steps
        );
        match &bar {
            Some(b) => b.set_message(text),
            None if p.step == 0 || wall - last_line >= PROGRESS_LINE_EVERY_S => {
                eprintln!("{text}");
                last_line = wall;
            }
            None => {}
        }
    }
}

/// Runs `aggregate density`.
pub fn density_cmd(args: &DensityArgs) -> Result<(), CliError> {
    let (particles, report, factor) =
        density_variant(&args.input, args.report.as_deref(), args.bulk_density).map_err(cli_error)?;
    check_outputs(&args.out, args.force).map_err(cli_error)?;
    write_aggregate(&args.out, &particles, &report).map_err(cli_error)?;
    println!(
        "{}: bulk density {:.1} kg/m³, grain density {:.1} kg/m³ (masses × {factor:.6})",
        args.out.display(),
        report.bulk_density_kg_m3,
        report.grain_density_kg_m3
    );
    Ok(())
}
