//! `rubblepile bench impact`: the wall-clock time of whole impact runs (Roig03 §3), for the speed goals of the
//! N200_T4 + P2, ζ = 45°, 10 000 s run at the impact default rtol (1e-6 over the run; goal 60 s) and of the same
//! impact on `targets/N2000_T4.csv` (goal 10 min), across integrators, tolerances, dissipation coefficients and thread counts.
//!
//! Each configuration is a complete [`run_impact`] into a scratch directory under `--out` (removed afterwards
//! unless `--keep-runs`); the row reports its wall time beside its energy error, as every run does.

use std::io::Write;
use std::path::PathBuf;

use super::BenchError as CliError;
use rubblepile::driver::RunOptions;
use rubblepile::impact::projectile::ProjectileSpec;
use rubblepile::impact::run::{ImpactConfig, run_impact};
use rubblepile::integrate::Method;

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
    #[arg(long = "angle-deg", default_value_t = 45.0)]
    pub angle: f64,
    /// End time of each run (s).
    #[arg(long = "t-end-s", default_value_t = 10_000.0)]
    pub t_end: f64,
    /// Integrators, comma-separated: bulirsch-stoer (the impact default), dop853, dopri5, bulirsch-stoer-implicit. `METHOD:RTOL` runs that
    /// method at that tolerance only (e.g. `bulirsch-stoer:1e-4,dop853:1e-8`); a bare METHOD runs every --rtol.
    #[arg(long, value_delimiter = ',', default_value = "bulirsch-stoer", value_parser = parse_method_spec)]
    pub method: Vec<MethodSpec>,
    /// Tolerances (rtol = atol, dimensionless, in (0, 1)), comma-separated; each is run with each bare method.
    /// Default: the impact's default of each method (1e-6 of the run for Bulirsch–Stoer, 1e-8 per step otherwise).
    #[arg(long, value_delimiter = ',')]
    pub rtol: Vec<f64>,
    /// Dissipation coefficients F0 (s m⁻²), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1e-6")]
    pub f0: Vec<f64>,
    /// Thread counts, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1,2", value_parser = clap::value_parser!(u64).range(1..=4096))]
    pub threads: Vec<u64>,
    /// The wall-time goal drawn as a line on the plot (s): 60 for the N200 impact, 600 for the N2000 one.
    #[arg(long = "goal-s", default_value_t = 60.0)]
    pub goal: f64,
    /// Repeats of each configuration (the median and the minimum are reported).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=100))]
    pub repeats: u64,
    /// Writes `bench_impact.csv`, `bench_impact.svg` and `bench_impact.png` here.
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite an earlier `bench_impact.csv`/`.svg` in OUT.
    #[arg(long)]
    pub force: bool,
    /// Run nothing: redraw `bench_impact.svg` and `.png` from OUT/bench_impact.csv (its target, projectile, angle
    /// and end time; `--goal-s` as given), overwriting the plot only.
    #[arg(long)]
    pub replot: bool,
    /// Keep the run directories (`OUT/runs/<METHOD>_rtol_<RTOL>_f0_<F0>_threads_<T>_<k>`).
    #[arg(long)]
    pub keep_runs: bool,
}

/// A `--method` entry: an integrator, and the tolerance it runs at when it names one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MethodSpec {
    /// The integrator.
    pub method: Method,
    /// Its own tolerance (`METHOD:RTOL`); `None`: every `--rtol`.
    pub rtol: Option<f64>,
}

/// Parses `METHOD` or `METHOD:RTOL` (bulirsch-stoer, dop853, dopri5 or bulirsch-stoer-implicit; RTOL in (0, 1)).
fn parse_method_spec(text: &str) -> Result<MethodSpec, String> {
    let (name, rtol) = match text.split_once(':') {
        Some((name, rtol)) => {
            let r: f64 = rtol
                .parse()
                .map_err(|_| format!("tolerance after ':' must be a number, got {rtol:?}"))?;
            if !(r > 0.0 && r < 1.0) {
                return Err(format!("tolerance after ':' must be in (0, 1), got {rtol}"));
            }
            (name, Some(r))
        }
        None => (text, None),
    };
    let method = <Method as rubblepile::named::Named>::from_name(name)
        .filter(|m| *m != Method::Rk4)
        .ok_or_else(|| {
            format!(
                "each must be bulirsch-stoer, dop853 or dopri5, or bulirsch-stoer-implicit (rk4 needs a fixed step), \
                 got {name:?}"
            )
        })?;
    Ok(MethodSpec { method, rtol })
}

/// One configuration's result.
#[derive(Debug, Clone, PartialEq)]
pub struct ImpactTiming {
    /// Integrator.
    pub method: Method,
    /// rtol (= atol).
    pub rtol: f64,
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
    if let Some(bad) = args.rtol.iter().find(|r| !(**r > 0.0 && **r < 1.0)) {
        return Err(CliError::usage(format!("--rtol: each must be in (0, 1), got {bad}")));
    }
    if !(args.goal.is_finite() && args.goal > 0.0) {
        return Err(CliError::usage(format!("--goal-s: must be > 0 s, got {}", args.goal)));
    }
    if args.replot {
        return replot(args);
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
    let pairs: Vec<(Method, f64)> = args
        .method
        .iter()
        .flat_map(|m| match m.rtol {
            Some(r) => vec![(m.method, r)],
            None if args.rtol.is_empty() => vec![(m.method, rubblepile::impact::run::default_rtol(m.method))],
            None => args.rtol.iter().map(|r| (m.method, *r)).collect(),
        })
        .collect();
    let configurations = pairs.iter().flat_map(|&(m, r)| {
        args.f0
            .iter()
            .flat_map(move |f| args.threads.iter().map(move |t| (m, r, *f, *t)))
    });
    for (method, rtol, f0, threads) in configurations {
        let mut cfg = ImpactConfig::new(args.target.clone(), projectile.clone());
        cfg.angle_deg = args.angle;
        cfg.t_end = args.t_end;
        cfg.method = method;
        cfg.rtol = rtol;
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
            let dir = args
                .out
                .join("runs")
                .join(format!("{method}_rtol_{rtol:e}_f0_{f0:e}_threads_{threads}_{k}"));
            let options = RunOptions {
                force: true,
                progress: false,
                ..RunOptions::default()
            };
            let summary = pool.install(|| run_impact(&cfg, &dir, &options)).map_err(|e| {
                CliError::failed(format!(
                    "{method}, rtol = {rtol:e}, F0 = {f0:e}, {threads} threads: {e}"
                ))
            })?;
            walls.push(summary.wall_seconds);
            println!(
                "  {method}, rtol {rtol:e}, F0 {f0:e} s m^-2, {threads} thread{}: wall {:.1} s, {} steps, {} RHS, energy error {:.1e}",
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
            method,
            rtol,
            f0,
            threads: threads as usize,
            median_s: rubblepile::math::median(&walls),
            min_s: min,
            steps: s.steps_accepted,
            rhs_evaluations: s.rhs_evaluations,
            energy_error: s.energy_error,
        });
    }
    if !args.keep_runs {
        let _ = std::fs::remove_dir(args.out.join("runs"));
    }
    let write = || -> std::io::Result<()> {
        let mut f = std::io::BufWriter::new(std::fs::File::create(&csv)?);
        writeln!(
            f,
            "target,projectile,angle_deg,t_end,rtol,f0,threads,median_s,min_s,repeats,steps,rhs_evaluations,energy_error,method"
        )?;
        for r in &results {
            writeln!(
                f,
                "{},{},{},{},{:e},{:e},{},{:.3},{:.3},{},{},{},{:e},{}",
                args.target.display(),
                args.projectile,
                args.angle,
                args.t_end,
                r.rtol,
                r.f0,
                r.threads,
                r.median_s,
                r.min_s,
                args.repeats,
                r.steps,
                r.rhs_evaluations,
                r.energy_error,
                r.method
            )?;
        }
        f.flush()
    };
    write().map_err(|e| CliError::failed(format!("{}: {e}", csv.display())))?;
    let title = format!(
        "{} + {}, zeta = {} deg, {} s",
        args.target.file_stem().and_then(|s| s.to_str()).unwrap_or("target"),
        args.projectile,
        args.angle,
        args.t_end,
    );
    plot(&results, title, args).map_err(|e| CliError::failed(format!("{}: {e}", svg.display())))?;
    println!("  wrote {}, {} and bench_impact.png", csv.display(), svg.display());
    Ok(())
}

/// Bars of the median wall time per (rtol, F0, threads), each with its energy error above it, and the goal as a
/// line.
struct WallTimeBars<'a> {
    results: &'a [ImpactTiming],
    title: String,
    /// The goal (s).
    goal: f64,
}

impl rubblepile::analysis::figures::style::Figure for WallTimeBars<'_> {
    fn draw<DB: plotters::prelude::DrawingBackend>(
        &self,
        root: &plotters::prelude::DrawingArea<DB, plotters::coord::Shift>,
    ) -> rubblepile::analysis::figures::style::PlotResult {
        use plotters::prelude::*;
        let err = |e: &dyn std::fmt::Display| e.to_string();
        let results = self.results;
        let goal = self.goal;
        // Room above the tallest bar for its three lines of text (to 0.76 of the height), and above those for
        // the legend in the upper right corner.
        let top = results.iter().map(|r| r.median_s).fold(goal, f64::max) * 1.6;
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(50)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..results.len() as f64, 0.0..top)
            .map_err(|e| err(&e))?;
        // Each bar is labelled above itself (plotters' ticks on a 0..n axis need not fall under every bar).
        chart
            .configure_mesh()
            .x_labels(0)
            .y_label_formatter(&|t| {
                if top >= 20.0 {
                    format!("{t:.0}")
                } else {
                    format!("{t:.1}")
                }
            })
            .x_desc("configuration: method, rtol, F0 (s m^-2), threads; relative energy error above each bar")
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
                vec![(0.0, goal), (results.len() as f64, goal)],
                RED.stroke_width(2),
            ))
            .map_err(|e| err(&e))?
            .label(format!("goal: {goal} s on 2 cores"))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
        // Above each bar, its configuration and (every run's error beside its time) its relative energy error.
        let lines = |r: &ImpactTiming| {
            [
                format!("{} rtol {:e}", short_name(r.method), r.rtol),
                format!("F0 {:e}, {} thr", r.f0, r.threads),
                format!("dE/E {:.1e}", r.energy_error),
            ]
        };
        let line_height = 0.045 * top;
        chart
            .draw_series(results.iter().enumerate().flat_map(|(k, r)| {
                lines(r).into_iter().enumerate().map(move |(i, text)| {
                    Text::new(
                        text,
                        (k as f64 + 0.15, r.median_s + (3 - i) as f64 * line_height),
                        ("sans-serif", 12),
                    )
                })
            }))
            .map_err(|e| err(&e))?;
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| err(&e))?;
        Ok(())
    }
}

/// The method as a bar label: "BS" for Bulirsch–Stoer, the method's name otherwise.
fn short_name(method: Method) -> String {
    match method {
        Method::BulirschStoer => "BS".to_string(),
        Method::BulirschStoerImplicit => "BS-implicit".to_string(),
        other => other.to_string(),
    }
}

/// `--replot`: the rows of OUT/bench_impact.csv drawn again (a CSV written before the `method` column reads as
/// Bulirsch–Stoer throughout).
fn replot(args: &ImpactBenchArgs) -> Result<(), CliError> {
    let path = args.out.join("bench_impact.csv");
    let fail = |e: String| CliError::failed(format!("{}: {e}", path.display()));
    let mut reader = csv::Reader::from_path(&path).map_err(|e| fail(e.to_string()))?;
    let headers = reader.headers().map_err(|e| fail(e.to_string()))?.clone();
    let (mut results, mut title) = (Vec::new(), None);
    for (k, record) in reader.records().enumerate() {
        let record = record.map_err(|e| fail(e.to_string()))?;
        let field = |name: &str| {
            headers
                .iter()
                .position(|h| h == name)
                .and_then(|i| record.get(i))
                .ok_or_else(|| fail(format!("row {}: no column `{name}`", k + 1)))
        };
        let number = |name: &str| {
            let text = field(name)?;
            text.parse::<f64>()
                .map_err(|_| fail(format!("row {}: `{name}` must be a number, got {text:?}", k + 1)))
        };
        let method = match headers.iter().any(|h| h == "method") {
            false => Method::BulirschStoer,
            true => {
                parse_method_spec(field("method")?)
                    .map_err(|e| fail(format!("row {}: `method`: {e}", k + 1)))?
                    .method
            }
        };
        title.get_or_insert(format!(
            "{} + {}, zeta = {} deg, {} s",
            std::path::Path::new(field("target")?)
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("target"),
            field("projectile")?,
            field("angle_deg")?,
            field("t_end")?,
        ));
        results.push(ImpactTiming {
            method,
            rtol: number("rtol")?,
            f0: number("f0")?,
            threads: number("threads")? as usize,
            median_s: number("median_s")?,
            min_s: number("min_s")?,
            steps: number("steps")? as u64,
            rhs_evaluations: number("rhs_evaluations")? as u64,
            energy_error: number("energy_error")?,
        });
    }
    let title = title.ok_or_else(|| fail("no rows to plot".to_string()))?;
    plot(&results, title, args).map_err(fail)?;
    println!(
        "  redrew bench_impact.svg and bench_impact.png in {}",
        args.out.display()
    );
    Ok(())
}

fn plot(results: &[ImpactTiming], title: String, args: &ImpactBenchArgs) -> Result<(), String> {
    let figure = WallTimeBars {
        results,
        title,
        goal: args.goal,
    };
    rubblepile::analysis::figures::style::write_figure(&args.out, "bench_impact", &figure)
        .map(|_| ())
        .map_err(String::from)
}
