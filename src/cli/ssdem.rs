//! Soft-sphere (SSDEM, Zhang17) commands: `rubblepile ssdem advise` (the benchmark is
//! [`crate::bench::ssdem`]).

use std::path::PathBuf;

use crate::cli::common::CliError;
use rubblepile::granular::soft::advise::{Advice, DEFAULT_MAX_OVERLAP, advise_for_grains};
use rubblepile::granular::soft::scene::load_soft_scene;

/// `rubblepile ssdem …`.
#[derive(Debug, clap::Subcommand)]
pub enum SsdemCommand {
    /// Suggest k_N (N/m) and the step dt (s) for a requested largest overlap.
    Advise(AdviseArgs),
}

/// `rubblepile ssdem advise`.
#[derive(Debug, clap::Args)]
pub struct AdviseArgs {
    /// A soft-sphere scene: advice from its particles and gravity (the other options are then not used).
    #[arg(long, value_name = "SCENE.toml", conflicts_with_all = ["radius", "density", "body_radius", "spin_period_h", "speed"])]
    pub scene: Option<PathBuf>,
    /// Smallest particle radius (m).
    #[arg(long = "radius-m", required_unless_present = "scene")]
    pub radius: Option<f64>,
    /// Grain density (kg/m³).
    #[arg(long = "density-kg-m3", required_unless_present = "scene")]
    pub density: Option<f64>,
    /// Radius of the self-gravitating body (m): adds its escape speed and central pressure.
    #[arg(long = "body-radius-m")]
    pub body_radius: Option<f64>,
    /// Bulk density of the body (kg/m³); default 0.64 × the grain density (random close packing).
    #[arg(long = "bulk-density-kg-m3")]
    pub bulk_density: Option<f64>,
    /// Spin period of the body (hours): adds its equatorial speed.
    #[arg(long)]
    pub spin_period_h: Option<f64>,
    /// Largest expected impact speed (m/s).
    #[arg(long = "speed-m-s")]
    pub speed: Option<f64>,
    /// Largest overlap as a fraction of the smallest radius.
    #[arg(long, default_value_t = DEFAULT_MAX_OVERLAP)]
    pub max_overlap: f64,
}

fn positive(name: &str, x: Option<f64>) -> Result<Option<f64>, CliError> {
    match x {
        Some(v) if !(v.is_finite() && v > 0.0) => {
            Err(CliError::usage(format!("--{name} must be > 0 and finite, got {v}")))
        }
        other => Ok(other),
    }
}

/// `rubblepile ssdem advise`.
pub fn advise(args: &AdviseArgs) -> Result<(), CliError> {
    positive("max-overlap", Some(args.max_overlap))?;
    let advice: Advice = if let Some(path) = &args.scene {
        let scene = load_soft_scene(path).map_err(CliError::usage)?;
        let mut a = scene.advice;
        if args.max_overlap != DEFAULT_MAX_OVERLAP {
            // k_N ∝ 1/x² for the dynamic term; recompute through the generic recipe.
            let f = DEFAULT_MAX_OVERLAP / args.max_overlap;
            a.k_n *= f * f;
            a.contact_time /= f;
            a.dt /= f;
            a.stability_limit /= f;
            a.gravity_interval = a.dynamical_time.map_or(1, |t| {
                rubblepile::granular::soft::advise::gravity_interval(t, a.dt, a.contact_time)
            });
        }
        a
    } else {
        let r = positive("radius-m", args.radius)?.unwrap_or(1.0);
        let rho = positive("density-kg-m3", args.density)?.unwrap_or(1.0);
        let body = positive("body-radius-m", args.body_radius)?;
        let bulk = positive("bulk-density-kg-m3", args.bulk_density)?.unwrap_or(0.64 * rho);
        let period = positive("spin-period-h", args.spin_period_h)?.map(|h| h * 3600.0);
        let speed = positive("speed-m-s", args.speed)?.unwrap_or(0.0);
        if body.is_none() && speed == 0.0 {
            return Err(CliError::usage(
                "give --speed-m-s or --body-radius-m (and optionally --spin-period-h)",
            ));
        }
        advise_for_grains(r, rho, body.map(|b| (b, bulk)), period, speed, args.max_overlap)
    };
    println!("k_n = {:e} N/m", advice.k_n);
    println!("dt = {:e} s", advice.dt);
    println!(
        "(speed {:e} m/s, static force {:e} N, contact time {:e} s, leapfrog stability limit {:e} s)",
        advice.speed, advice.static_force, advice.contact_time, advice.stability_limit
    );
    if let Some(t_dyn) = advice.dynamical_time {
        println!(
            "gravity interval_steps = {} (self-gravity every k steps: k dt <= 1/sqrt(G rho)/100 = {:e} s and \
             k dt <= contact time/5; dynamical time 1/sqrt(G rho) = {t_dyn:e} s)",
            advice.gravity_interval,
            t_dyn / 100.0
        );
    }
    Ok(())
}
