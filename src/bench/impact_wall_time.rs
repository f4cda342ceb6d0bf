//! `rubblepile bench impact`: the wall-clock time of whole impact runs (Roig03 §3), for the speed goal of the
//! N200_T4 + P2, ζ = 45°, 10 000 s run at the impact default rtol (1e-6 over the run), across dissipation coefficients and thread counts.
//!
//! Each configuration is a complete [`run_impact`] into a scratch directory under `--out` (removed afterwards
//! unless `--keep-runs`); the row reports its wall time beside its energy error, as every run does.

use std::io::Write;
use std::path::PathBuf;

use super::BenchError as CliError;
use crate::driver::RunOptions;
use crate::impact::projectile::ProjectileSpec;
use crate::impact::run::{ImpactConfig, run_impact};

/// `rubblepile bench impact`.
#[derive(Debug, clap::Args)]
pub struct ImpactBenchArgs {
    /// Target bodies file.
    #[arg(long, default_value = "targets/N200_T4.csv")]
    pub target: PathBuf,
    /// Projectile: P1, P2 or P3 (Roig03 Table 2).
    #[arg(long, default_value = "P2")]
    pub projectile: String,
    /// Impact angle ζ (degrees).
    #[arg(long, default_value_t = 45.0)]
    pub angle: f64,
    /// End time of each run (s).
    #[arg(long, default_value_t = 10_000.0)]
    pub t_end: f64,
    /// Bulirsch–Stoer tolerance (rtol = atol).
    #[arg(long, default_value_t = crate::impact::run::DEFAULT_RTOL)]
    pub rtol: f64,
    /// Dissipation coefficients F0 (s m⁻²), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1e-6")]
    pub f0: Vec<f64>,
    /// Thread counts, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1,2", value_parser = clap::value_parser!(u64).range(1..=4096))]
    pub threads: Vec<u64>,
    /// Repeats of each configuration (the median and the minimum are reported).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=100))]
    pub repeats: u64,
    /// Writes `bench_impact.csv`, `bench_impact.svg` and `bench_impact.png` here.
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite an earlier `bench_impact.csv`/`.svg` in OUT.
    #[arg(long)]
    pub force: bool,
    /// Keep the run directories (`OUT/runs/f0_<F0>_threads_<T>_<k>`).
    #[arg(long)]
    pub keep_runs: bool,
}

/// One configuration's result.
#[derive(Debug, Clone, PartialEq)]
pub struct ImpactTiming {
    /// F0 (s m⁻²).
    pub f0: f64,
    /// Threads.
    pub threads: usize,
    /// Median wall time over the repeats (s).
    pub median_s: f64,
    /// Minimum wall time (s).
    pub min_s: f64,
    /// Accepted steps (of the last repeat).
    pub steps: u64,
    /// RHS evaluations (of the last repeat).
    pub rhs_evaluations: u64,
    /// Relative energy error (of the last repeat).
    pub energy_error: f64,
}

/// Runs `bench impact`.
pub fn impact(args: &ImpactBenchArgs) -> Result<(), CliError> {
    let mut projectile = ProjectileSpec::preset(&args.projectile)
        .ok_or_else(|| CliError::usage(format!("--projectile: expected P1, P2 or P3, got {}", args.projectile)))?;
    projectile.speed = 5e3;
    if let Some(bad) = args.f0.iter().find(|f| !(f.is_finite() && **f >= 0.0)) {
        return Err(CliError::usage(format!("--f0: each must be >= 0 s m^-2, got {bad}")));
    }
    let (csv, svg) = (args.out.join("bench_impact.csv"), args.out.join("bench_impact.svg"));
    for p in [&csv, &svg] {
        if p.exists() && !args.force {
            return Err(CliError::usage(format!(
                "{}: exists; use --force to overwrite it",
                p.display()
            )));
        }
    }
    std::fs::create_dir_all(&args.out).map_err(|e| CliError::failed(format!("{}: {e}", args.out.display())))?;
    let mut results = Vec::new();
    for &f0 in &args.f0 {
        for &threads in &args.threads {
            let mut cfg = ImpactConfig::new(args.target.clone(), projectile.clone());
            cfg.angle_deg = args.angle;
            cfg.t_end = args.t_end;
            cfg.rtol = args.rtol;
            cfg.f0 = f0;
            cfg.snapshots = vec![0.0, args.t_end];
            cfg.validate()
                .map_err(|e| CliError::usage(format!("bench impact: {e}")))?;
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads as usize)
                .build()
                .map_err(|e| CliError::failed(format!("cannot build a pool of {threads} threads: {e}")))?;
            let mut walls = Vec::new();
            let mut last = None;
            for k in 0..args.repeats {
                let dir = args.out.join("runs").join(format!("f0_{f0:e}_threads_{threads}_{k}"));
                let options = RunOptions {
                    force: true,
                    progress: false,
                    ..RunOptions::default()
                };
                let summary = pool
                    .install(|| run_impact(&cfg, &dir, &options))
                    .map_err(|e| CliError::failed(format!("F0 = {f0:e}, {threads} threads: {e}")))?;
                walls.push(summary.wall_seconds);
                println!(
                    "  F0 {f0:e} s m^-2, {threads} thread{}: wall {:.1} s, {} steps, {} RHS, energy error {:.1e}",
                    if threads == 1 { "" } else { "s" },
                    summary.wall_seconds,
                    summary.steps_accepted,
                    summary.rhs_evaluations,
                    summary.energy_error
                );
                last = Some(summary);
                if !args.keep_runs {
                    let _ = std::fs::remove_dir_all(&dir);
                }
            }
            let s = last.expect("repeats >= 1");
            let min = walls.iter().copied().fold(f64::INFINITY, f64::min);
            results.push(ImpactTiming {
                f0,
                threads: threads as usize,
                median_s: crate::math::median(&walls),
                min_s: min,
                steps: s.steps_accepted,
                rhs_evaluations: s.rhs_evaluations,
                energy_error: s.energy_error,
            });
        }
    }
    if !args.keep_runs {
        let _ = std::fs::remove_dir(args.out.join("runs"));
    }
    let write = || -> std::io::Result<()> {
        let mut f = std::io::BufWriter::new(std::fs::File::create(&csv)?);
        writeln!(
            f,
            "target,projectile,angle_deg,t_end,rtol,f0,threads,median_s,min_s,repeats,steps,rhs_evaluations,energy_error"
        )?;
        for r in &results {
            writeln!(
                f,
                "{},{},{},{},{:e},{:e},{},{:.3},{:.3},{},{},{},{:e}",
                args.target.display(),
                args.projectile,
                args.angle,
                args.t_end,
                args.rtol,
                r.f0,
                r.threads,
                r.median_s,
                r.min_s,
                args.repeats,
                r.steps,
                r.rhs_evaluations,
                r.energy_error
            )?;
        }
        f.flush()
    };
    write().map_err(|e| CliError::failed(format!("{}: {e}", csv.display())))?;
    plot(&results, args).map_err(|e| CliError::failed(format!("{}: {e}", svg.display())))?;
    println!("  wrote {}, {} and bench_impact.png", csv.display(), svg.display());
    Ok(())
}

/// Bars of the median wall time per (F0, threads), with the 60 s goal as a line.
struct WallTimeBars<'a> {
    results: &'a [ImpactTiming],
    title: String,
}

impl crate::analysis::figures::style::Figure for WallTimeBars<'_> {
    fn draw<DB: plotters::prelude::DrawingBackend>(
        &self,
        root: &plotters::prelude::DrawingArea<DB, plotters::coord::Shift>,
    ) -> crate::analysis::figures::style::PlotResult {
        use plotters::prelude::*;
        let err = |e: &dyn std::fmt::Display| e.to_string();
        let results = self.results;
        let top = results.iter().map(|r| r.median_s).fold(60.0, f64::max) * 1.2;
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(50)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..results.len() as f64, 0.0..top)
            .map_err(|e| err(&e))?;
        let labels: Vec<String> = results
            .iter()
            .map(|r| format!("F0 {:e}, {} thr", r.f0, r.threads))
            .collect();
        chart
            .configure_mesh()
            .x_labels(results.len())
            .x_label_formatter(&|x| labels.get(x.floor() as usize).cloned().unwrap_or_default())
            .x_desc("configuration (F0 in s m^-2, threads)")
            .y_desc("wall-clock time (s)")
            .disable_x_mesh()
            .draw()
            .map_err(|e| err(&e))?;
        chart
            .draw_series(results.iter().enumerate().map(|(k, r)| {
                Rectangle::new(
                    [(k as f64 + 0.15, 0.0), (k as f64 + 0.85, r.median_s)],
                    BLUE.mix(0.5).filled(),
                )
            }))
            .map_err(|e| err(&e))?;
        chart
            .draw_series(LineSeries::new(
                vec![(0.0, 60.0), (results.len() as f64, 60.0)],
                RED.stroke_width(2),
            ))
            .map_err(|e| err(&e))?
            .label("goal: 60 s on 2 cores")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| err(&e))?;
        Ok(())
    }
}

fn plot(results: &[ImpactTiming], args: &ImpactBenchArgs) -> Result<(), String> {
    let figure = WallTimeBars {
        results,
        title: format!(
            "{} + {}, zeta = {} deg, {} s at rtol {:e}",
            args.target.file_stem().and_then(|s| s.to_str()).unwrap_or("target"),
            args.projectile,
            args.angle,
            args.t_end,
            args.rtol
        ),
    };
    crate::analysis::figures::style::write_figure(&args.out, "bench_impact", &figure)
        .map(|_| ())
        .map_err(String::from)
}
