//! `rubblepile bench work-precision`: work–precision diagrams (final-state error and energy residual against
//! integration wall time) of Bulirsch–Stoer, Dop853, Dopri5 and Rk4 on the canonical problems of
//! [`rubblepile::impact::problems`], after Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.10.
//! The measurement itself is [`crate::bench::work_precision`]; this file holds the command line, the CSV
//! and the plot.

use std::io::Write;
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;

use super::BenchError as CliError;
use crate::bench::work_precision::{
    CSV_HEADER, DEFAULT_TOLERANCES, LONG_RUN_REPEATS, LONG_RUN_SECONDS, Sweep, SweepConfig, SweepRow, csv_line, sweep,
};
use rubblepile::impact::problems::{ProblemSetup, ReferenceKind, WorkPrecisionProblem};
use rubblepile::integrate::Method;
use rubblepile::named::Named;

/// `rubblepile bench work-precision`.
///
/// Writes into DIR:
/// * `work_precision_<problem>.csv` with the columns
///   `method,rtol,error,energy_error,wall_seconds,rhs_evaluations,steps,h,rejected_steps,timed_runs,wall_statistic,
///   cpu_seconds,error_over_tol`: one row per setting; `rtol` (= atol) is empty for rk4, whose fixed step is in `h`
///   (empty for the
///   adaptive methods); `error` is the final-state error, `energy_error` the largest energy residual,
///   `wall_seconds` the integration time (median of the timed runs, or minimum when `wall_statistic` = `min`),
///   `steps` the accepted steps of one run, `cpu_seconds` the same statistic of the thread's CPU time,
///   `error_over_tol` the error over `rtol` (tolerance proportionality);
/// * `work_precision_<problem>.svg`: log–log error and energy error against wall time, one line per method;
/// * `work_precision_<problem>.json`: the problem, the references and the settings.
#[derive(Debug, clap::Args)]
#[command(after_long_help = WP_AFTER_HELP)]
pub struct WorkPrecisionArgs {
    /// The problem: top (free asymmetric top, analytic reference), pair (two ellipsoids bouncing under gravity
    /// and contact, G = 1), pair-dissipative (the same with F0 = 0.1), n30 (the N30_T4 target hit by P1, SI),
    /// n200 (N200_T4 hit by P2 to 400 s), stiff-pair (two overlapping ellipsoids, F0 = 1e4, damping 1000× faster
    /// than the contact), pile (N30_T4 squeezed to 0.9, F0 = 1e-2 s m⁻²; both with --f0).
    #[arg(long, value_parser = crate::choice::choice::<WorkPrecisionProblem>())]
    pub problem: WorkPrecisionProblem,
    /// Output directory (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Overwrite the outputs of an earlier sweep of the same problem in DIR.
    #[arg(long)]
    pub force: bool,
    /// Timed runs per setting; the median is reported (runs longer than 2 s: at most 2 runs, minimum).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub repeats: u64,
    /// Tolerances rtol = atol of the adaptive methods, comma-separated (default 1e-4,1e-5,…,1e-12).
    #[arg(long, value_delimiter = ',', value_name = "TOL")]
    pub rtol: Option<Vec<f64>>,
    /// Methods, comma-separated, from bulirsch-stoer, dop853, dopri5, rk4, bulirsch-stoer-implicit (default the first
    /// four).
    #[arg(long, value_parser = crate::choice::choice::<Method>(), value_delimiter = ',', value_name = "METHOD")]
    pub methods: Option<Vec<Method>>,
    /// Fixed steps of rk4 (time unit of the problem), comma-separated (default: six per problem).
    #[arg(long, value_delimiter = ',', value_name = "H")]
    pub rk4_steps: Option<Vec<f64>>,
    /// A method's sweep stops after its first setting whose timed run exceeds this many seconds.
    #[arg(long = "max-run-s", default_value_t = 60.0, value_name = "SECONDS")]
    pub max_run_seconds: f64,
    /// rtol = atol of the reference runs (problems without an analytic reference).
    #[arg(long, default_value = "1e-13", value_name = "TOL")]
    pub reference_rtol: f64,
    /// F0 of the stiff problems (stiff-pair: G = 1 units, default 1e4; pile: s m⁻², default 1e-2); the outputs are
    /// then named `work_precision_<problem>_f0_<F0>.*`.
    #[arg(long, value_name = "F0")]
    pub f0: Option<f64>,
    /// Do not run anything: redraw the diagram (SVG and PNG) from the CSV an earlier sweep left in `--out`.
    #[arg(long)]
    pub replot: bool,
}

const WP_AFTER_HELP: &str = "\
Error measures (dimensionless):
  top:    |w(t_end) - w_exact(t_end)| / |w_exact(t_end)|, w = body-frame angular velocity, w_exact the
          torque-free solution (Jacobi elliptic functions).
  others: block norm of the final state against a reference: for each block kind (r, q, u = m v, p = M(q) q'),
          max over bodies of |y_b - y_ref,b| / max over bodies of |y_ref,b| (Euclidean norms), then the max over
          block kinds. The reference is a run of a different method at --reference-rtol: dop853 for
          bulirsch-stoer, bulirsch-stoer for dop853, dopri5 and rk4.
  energy_error: max over the problem's equally spaced checks of |H(t) - H(0) - 2 int F dt| / (K + |U_C| + |U_G|)(0).
Time: wall-clock time of the integration only (no set-up, diagnostics or I/O), median of --repeats runs (runs
  under 0.05 s: more runs, up to 25; runs over 2 s: at most 2 runs, minimum); cpu_seconds: the same for the
  thread's CPU time. Every run is on one thread.
CSV columns: method,rtol,error,energy_error,wall_seconds,rhs_evaluations,steps,h,rejected_steps,timed_runs,
  wall_statistic,cpu_seconds,error_over_tol (rtol empty for rk4, whose fixed step is h; h empty for the adaptive
  methods; error_over_tol = error / rtol).";

fn positive_list(flag: &str, values: &[f64]) -> Result<(), CliError> {
    if values.is_empty() {
        return Err(CliError::usage(format!("{flag}: give at least one value")));
    }
    for &v in values {
        if !(v.is_finite() && v > 0.0) {
            return Err(CliError::usage(format!(
                "{flag}: values must be > 0 and finite, got {v}"
            )));
        }
    }
    Ok(())
}

/// The output files of a sweep of `problem` in `dir`: CSV, SVG, JSON.
pub fn output_paths(dir: &Path, problem: &str) -> [PathBuf; 3] {
    let stem = format!("work_precision_{}", problem.replace('-', "_"));
    ["csv", "svg", "json"].map(|ext| dir.join(format!("{stem}.{ext}")))
}

/// Refuses (exit code 2) when one of `paths` exists and `force` is not set; creates `dir`.
pub fn prepare_outputs(dir: &Path, paths: &[PathBuf], force: bool) -> Result<(), CliError> {
    if !force && let Some(p) = paths.iter().find(|p| p.exists()) {
        return Err(CliError::usage(format!(
            "--out: {} already exists; use --force to overwrite it",
            p.display()
        )));
    }
    std::fs::create_dir_all(dir).map_err(|e| CliError::failed(format!("--out: {}: {e}", dir.display())))
}

/// Draws the work–precision diagram of `rows` into `svg` and the PNG beside it (same drawing, both backends).
fn draw_both(svg: &Path, title: &str, rows: &[SweepRow]) -> Result<PathBuf, CliError> {
    let png = svg.with_extension("png");
    {
        let root = SVGBackend::new(svg, (1200, 520)).into_drawing_area();
        draw_work_precision(&root, title, rows)
            .and_then(|()| root.present().map_err(|e| e.to_string()))
            .map_err(|e| CliError::failed(format!("{}: {e}", svg.display())))?;
    }
    {
        let root = BitMapBackend::new(&png, (1200, 520)).into_drawing_area();
        draw_work_precision(&root, title, rows)
            .and_then(|()| root.present().map_err(|e| e.to_string()))
            .map_err(|e| CliError::failed(format!("{}: {e}", png.display())))?;
    }
    Ok(png)
}

/// Reads the rows of a `work_precision_<problem>.csv` back (the columns [`write_csv`] writes).
pub fn read_csv(path: &Path) -> Result<Vec<SweepRow>, crate::bench::BenchError> {
    let err = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    // the first eight columns of those written (`method` to `h`)
    let mut header = CSV_HEADER.split(',');
    let names: [&str; 8] = std::array::from_fn(|_| header.next().unwrap_or_default());
    let (mut rdr, c) = rubblepile::io::table::open_columns(path, names).map_err(|e| err(&e))?;
    let mut rows = Vec::new();
    for (line, rec) in rdr.records().enumerate() {
        let rec = rec.map_err(|e| err(&e))?;
        let at = |k: usize| format!("row {}", line + 2) + &format!(", column {}", names[k]);
        let num =
            |k: usize| -> Result<f64, String> { rec[c[k]].parse::<f64>().map_err(|e| err(&format!("{}: {e}", at(k)))) };
        let opt = |k: usize| -> Result<Option<f64>, String> {
            if rec[c[k]].is_empty() {
                Ok(None)
            } else {
                num(k).map(Some)
            }
        };
        let method = <Method as rubblepile::named::Named>::from_name(&rec[c[0]])
            .ok_or_else(|| err(&format!("{}: no integrator is named {:?}", at(0), &rec[c[0]])))?;
        rows.push(SweepRow {
            setting: crate::bench::work_precision::Setting {
                method,
                tolerance: opt(1)?,
                step: opt(7)?,
            },
            error: num(2)?,
            energy_error: num(3)?,
            wall_seconds: num(4)?,
            rhs_evaluations: num(5)? as u64,
            steps: num(6)? as u64,
            rejected_steps: 0,
            timed_runs: 0,
            statistic: "median",
            cpu_seconds: f64::NAN,
        });
    }
    Ok(rows)
}

/// The problem of `args` (with `--f0` where given) and the name its outputs and title carry.
fn chosen_problem(args: &WorkPrecisionArgs) -> Result<(ProblemSetup, String), CliError> {
    match args.f0 {
        None => {
            let problem = args.problem.setup();
            let name = problem.name.to_string();
            Ok((problem, name))
        }
        Some(f0) => {
            if !args.problem.takes_f0() {
                return Err(CliError::usage(format!(
                    "--f0: only the stiff problems (stiff-pair, pile) take it, not {}",
                    args.problem.name()
                )));
            }
            if !(f0.is_finite() && f0 >= 0.0) {
                return Err(CliError::usage(format!("--f0: must be >= 0 and finite, got {f0}")));
            }
            let problem = args.problem.setup_with_f0(Some(f0));
            let name = format!("{}_f0_{f0:e}", problem.name);
            Ok((problem, name))
        }
    }
}

/// Runs `bench work-precision`.
pub fn work_precision(args: &WorkPrecisionArgs) -> Result<(), CliError> {
    if args.replot {
        let (_, name) = chosen_problem(args)?;
        let paths = output_paths(&args.out, &name);
        let [csv, svg, _] = &paths;
        let rows = read_csv(csv).map_err(CliError::usage)?;
        let png = draw_both(svg, &format!("work-precision: {name}"), &rows)?;
        println!(
            "  redrew {} and {} from {}",
            svg.display(),
            png.display(),
            csv.display()
        );
        return Ok(());
    }
    let tolerances = args.rtol.clone().unwrap_or_else(|| DEFAULT_TOLERANCES.to_vec());
    positive_list("--rtol", &tolerances)?;
    let methods = args
        .methods
        .clone()
        .unwrap_or_else(|| vec![Method::BulirschStoer, Method::Dop853, Method::Dopri5, Method::Rk4]);
    if methods.is_empty() {
        return Err(CliError::usage("--methods: give at least one method"));
    }
    if args.max_run_seconds.is_nan() || args.max_run_seconds <= 0.0 {
        return Err(CliError::usage(format!(
            "--max-run-s: must be > 0, got {}",
            args.max_run_seconds
        )));
    }
    if !(args.reference_rtol.is_finite() && args.reference_rtol > 0.0) {
        return Err(CliError::usage(format!(
            "--reference-rtol: must be > 0 and finite, got {}",
            args.reference_rtol
        )));
    }
    let (problem, name) = chosen_problem(args)?;
    let rk4_steps = if methods.contains(&Method::Rk4) {
        let steps = args.rk4_steps.clone().unwrap_or_else(|| problem.rk4_steps.clone());
        positive_list("--rk4-steps", &steps)?;
        steps
    } else {
        Vec::new()
    };
    let paths = output_paths(&args.out, &name);
    prepare_outputs(&args.out, &paths, args.force)?;
    let config = SweepConfig {
        methods: methods.clone(),
        tolerances,
        rk4_steps,
        repeats: args.repeats as usize,
        max_run_seconds: args.max_run_seconds,
        reference_tolerance: args.reference_rtol,
    };
    println!("bench work-precision: {}", problem.description);
    println!(
        "  {} state components, {} energy checks, {} timed runs per setting",
        problem.initial_state().len(),
        problem.energy_samples,
        config.repeats
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| CliError::failed(format!("cannot build a one-thread pool: {e}")))?;
    let result = pool
        .install(|| sweep(&problem, &config, &mut |line| println!("  {line}")))
        .map_err(|e| CliError::failed(format!("reference run failed: {e}")))?;
    if result.rows.is_empty() {
        return Err(CliError::failed("every setting failed; nothing to write"));
    }
    let [csv, svg, json] = &paths;
    write_csv(csv, &result.rows).map_err(|e| CliError::failed(format!("{}: {e}", csv.display())))?;
    let title = format!("work-precision: {name}");
    draw_both(svg, &title, &result.rows)?;
    let meta = metadata(&problem, &config, &result);
    std::fs::write(json, serde_json::to_string_pretty(&meta).unwrap_or_default() + "\n")
        .map_err(|e| CliError::failed(format!("{}: {e}", json.display())))?;
    println!("  wrote {}, {} and {}", csv.display(), svg.display(), json.display());
    Ok(())
}

fn write_csv(path: &Path, rows: &[SweepRow]) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(f, "{CSV_HEADER}")?;
    for row in rows {
        writeln!(f, "{}", csv_line(row))?;
    }
    f.flush()
}

fn metadata(problem: &ProblemSetup, config: &SweepConfig, result: &Sweep) -> serde_json::Value {
    let reference = match (&problem.reference, &result.references) {
        (ReferenceKind::Analytic, _) => serde_json::json!({
            "kind": "analytic",
            "what": "torque-free body-frame angular velocity (Jacobi elliptic functions)",
        }),
        (_, Some(r)) => serde_json::json!({
            "kind": if problem.reference == ReferenceKind::Stiff { "stiff" } else { "numerical" },
            "rtol": r.tolerance,
            "runs": r.runs.iter().map(|run| serde_json::json!({
                "method": run.method.to_string(),
                "wall_seconds": run.wall_seconds,
            })).collect::<Vec<_>>(),
            "measured_against": if r.runs.len() == 1 {
                format!("every method against the {} run", r.runs[0].method)
            } else {
                "bulirsch-stoer against dop853, every other method against bulirsch-stoer".to_string()
            },
            "difference_between_references": r.difference,
            "explicit_reference_given_up": r.explicit_given_up,
        }),
        _ => serde_json::Value::Null,
    };
    serde_json::json!({
        "problem": problem.name,
        "description": problem.description,
        "t_end": problem.t_end,
        "state_components": problem.initial_state().len(),
        "energy_checks": problem.energy_samples,
        "error": if problem.reference == ReferenceKind::Analytic {
            "|w - w_exact| / |w_exact| of the body-frame spin at t_end"
        } else {
            "block norm: max over block kinds (r, q, u, p) of max_b |y_b - y_ref,b| / max_b |y_ref,b|"
        },
        "energy_error": "max over checks of |H(t) - H(0) - 2 int F dt| / E_scale(0)",
        "timing": format!(
            "integration wall time only, one thread; median of {} runs (more for runs under 0.05 s), or min of at \
             most {LONG_RUN_REPEATS} when a run takes more than {LONG_RUN_SECONDS} s",
            config.repeats
        ),
        "methods": config.methods.iter().map(|m| m.to_string()).collect::<Vec<_>>(),
        "tolerances": config.tolerances,
        "rk4_steps": config.rk4_steps,
        "reference": reference,
        "skipped": result.skipped,
    })
}

/// Colour of a method's line.
fn method_colour(method: Method) -> RGBColor {
    match method {
        Method::BulirschStoer => RGBColor(0xd6, 0x27, 0x28),
        Method::Dop853 => RGBColor(0x1f, 0x77, 0xb4),
        Method::Dopri5 => RGBColor(0x2c, 0xa0, 0x2c),
        Method::Rk4 => RGBColor(0x94, 0x67, 0xbd),
        Method::BulirschStoerImplicit => RGBColor(0xff, 0x7f, 0x0e),
    }
}

/// Draws the work–precision diagram of `rows` onto `area` (any plotters backend: SVG now, a bitmap later):
/// two log–log panels, final-state error and energy error against wall time, one line per method (adaptive
/// methods in tolerance order, Rk4 in step order).
pub fn draw_work_precision<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    rows: &[SweepRow],
) -> Result<(), String> {
    // plotters measures (and in bitmaps draws) text with the font the figures embed: register it first
    rubblepile::analysis::figures::style::ensure_font()?;
    let e = |err: &dyn std::fmt::Display| err.to_string();
    area.fill(&WHITE).map_err(|x| e(&x))?;
    let area = area.titled(title, ("sans-serif", 20)).map_err(|x| e(&x))?;
    let (left, right) = area.split_horizontally(area.dim_in_pixel().0 / 2);
    let mut methods: Vec<Method> = Vec::new();
    for r in rows {
        if !methods.contains(&r.setting.method) {
            methods.push(r.setting.method);
        }
    }
    let floor = 1e-17;
    type Metric = fn(&SweepRow) -> f64;
    let panels: [(&DrawingArea<DB, Shift>, &str, Metric); 2] = [
        (&left, "final-state error", |r| r.error),
        (&right, "max energy residual", |r| r.energy_error),
    ];
    for (panel, label, value) in panels {
        let pts: Vec<(f64, f64)> = rows
            .iter()
            .map(|r| (r.wall_seconds, value(r)))
            .filter(|(t, v)| *t > 0.0 && v.is_finite())
            .collect();
        if pts.is_empty() {
            continue;
        }
        let (mut t0, mut t1, mut v0, mut v1) = (f64::INFINITY, 0.0_f64, f64::INFINITY, 0.0_f64);
        for &(t, v) in &pts {
            let v = v.max(floor);
            (t0, t1, v0, v1) = (t0.min(t), t1.max(t), v0.min(v), v1.max(v));
        }
        let mut chart = ChartBuilder::on(panel)
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(72)
            .build_cartesian_2d((t0 / 1.5..t1 * 1.5).log_scale(), (v0 / 3.0..v1 * 3.0).log_scale())
            .map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .x_desc("integration wall time (s)")
            .y_desc(label)
            .x_label_formatter(&|v| format!("{v:.0e}"))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(|x| e(&x))?;
        for &method in &methods {
            let colour = method_colour(method);
            let mut line: Vec<(f64, f64, f64)> = rows
                .iter()
                .filter(|r| r.setting.method == method && r.wall_seconds > 0.0 && value(r).is_finite())
                .map(|r| {
                    let key = r.setting.tolerance.or(r.setting.step).unwrap_or(0.0);
                    (key, r.wall_seconds, value(r).max(floor))
                })
                .collect();
            line.sort_by(|a, b| b.0.total_cmp(&a.0));
            let points: Vec<(f64, f64)> = line.iter().map(|&(_, t, v)| (t, v)).collect();
            chart
                .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
                .map_err(|x| e(&x))?
                .label(method.to_string())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
            chart
                .draw_series(points.into_iter().map(|p| Circle::new(p, 3, colour.filled())))
                .map_err(|x| e(&x))?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(|x| e(&x))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::work_precision::Setting;

    /// `--replot` reads back what a sweep wrote: each row's method, `rtol` (empty for Rk4), `h` (empty for the
    /// adaptive methods) and measured columns.
    #[test]
    fn read_csv_reads_back_what_write_csv_writes() {
        let row = |setting, error| SweepRow {
            setting,
            error,
            energy_error: 2e-9,
            wall_seconds: 0.5,
            rhs_evaluations: 1200,
            steps: 100,
            rejected_steps: 3,
            timed_runs: 5,
            statistic: "median",
            cpu_seconds: 0.25,
        };
        let rows = [
            row(Setting::adaptive(Method::BulirschStoer, 1e-4), 3e-5),
            row(Setting::rk4(0.2), 1e-3),
        ];
        let path = std::env::temp_dir().join(format!("rubblepile-unit-wp-csv-{}.csv", std::process::id()));
        write_csv(&path, &rows).unwrap();
        let back = read_csv(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(back.len(), rows.len());
        for (a, b) in back.iter().zip(&rows) {
            assert_eq!(a.setting, b.setting);
            assert_eq!(
                (a.error, a.energy_error, a.wall_seconds),
                (b.error, b.energy_error, b.wall_seconds)
            );
            assert_eq!((a.rhs_evaluations, a.steps), (b.rhs_evaluations, b.steps));
        }
        assert_eq!(back[0].setting.tolerance, Some(1e-4));
        assert_eq!(back[1].setting.step, Some(0.2));
    }
}
