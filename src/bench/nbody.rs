//! `rubblepile bench nbody`: timed point-mass runs of the ellipsoid model (tiny spheres, gravity only, G = 1)
//! with their final states, the rubblepile side of the comparison with REBOUND in `analysis/rebound_compare/`
//! (problems from [`rubblepile::impact::problems::NBodyProblem`]; Rein & Liu 2012, Rein & Spiegel 2015
//! for the REBOUND side).
//!
//! Besides the wall time of the integration (measured inside the binary, so process start-up and file I/O do
//! not count), every setting is run twice more for a profile: once with the right-hand side wrapped in a timer
//! (time spent inside the RHS), and once with the same integrator on [`PointMassGravity`], a bare N-body RHS,
//! which separates the integrator's own cost from the cost of the general ellipsoid RHS.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use super::BenchError as CliError;
use crate::bench::work_precision::{Setting, fmt_cpu, median, run_once, thread_cpu_seconds};
use crate::bench::work_precision_sweep::prepare_outputs;
use rubblepile::impact::problems::{NBodyProblem, PointMassGravity, ProblemSetup};
use rubblepile::integrate::{IntegrateError, Method, OdeSystem, Stats, Tolerances, make_integrator};

/// `rubblepile bench nbody`.
///
/// Writes into DIR:
/// * `nbody_<problem>.csv`: `method,rtol,wall_seconds,wall_min_seconds,rhs_evaluations,steps,rejected_steps,
///   timed_runs,energy_error,rhs_seconds,profiled_wall_seconds,bare_wall_seconds,bare_difference,cpu_seconds,
///   bare_cpu_seconds` — one row per method and tolerance (rtol = atol); `wall_seconds` is the median and
///   `wall_min_seconds` the minimum over the timed runs (integration only, one thread); `cpu_seconds` and
///   `bare_cpu_seconds` the medians of the thread's CPU time; `energy_error` = |H(t_end) − H(0)| / (K + |U_G|)(0); `rhs_seconds` is the
///   time inside the RHS during `profiled_wall_seconds` of a separate, instrumented run; `bare_wall_seconds` the
///   median wall time of the same integrator on a bare point-mass RHS, and `bare_difference` the block-norm
///   distance of its final state from the ellipsoid model's;
/// * `nbody_<problem>_states.csv`: `method,rtol,body,mass,x,y,z,vx,vy,vz`, the initial state (method `initial`,
///   empty rtol) and the final state of every setting, in shortest round-trip notation.
#[derive(Debug, clap::Args)]
pub struct NBodyArgs {
    /// The problem: pythagorean (masses 3, 4, 5 at rest, t = 0..10) or outer-solar (Sun + 4 giants, t = 0..1000).
    #[arg(long, value_parser = crate::choice::choice::<NBodyProblem>())]
    pub problem: NBodyProblem,
    /// Tolerances rtol = atol, comma-separated.
    #[arg(long, value_delimiter = ',', value_name = "TOL",
          default_values_t = [1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12])]
    pub rtol: Vec<f64>,
    /// Methods, comma-separated, from bulirsch-stoer, dop853, dopri5.
    #[arg(long, value_parser = crate::choice::choice::<Method>(), value_delimiter = ',', value_name = "METHOD",
          default_values_t = [Method::BulirschStoer])]
    pub methods: Vec<Method>,
    /// Timed runs per setting (median and minimum reported).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub repeats: u64,
    /// Output directory (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Overwrite the outputs of an earlier run of the same problem in DIR.
    #[arg(long)]
    pub force: bool,
}

/// An [`OdeSystem`] wrapper that adds up the time spent in the wrapped RHS (ns).
struct TimedSystem<'a> {
    inner: &'a dyn OdeSystem,
    nanos: AtomicU64,
}

impl OdeSystem for TimedSystem<'_> {
    fn dim(&self) -> usize {
        self.inner.dim()
    }
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        let start = Instant::now();
        self.inner.rhs(t, y, dydt);
        self.nanos
            .fetch_add(start.elapsed().as_nanos() as u64, Ordering::Relaxed);
    }
}

/// Integrates `system` from `y0` at t = 0 to `t_end` in one `advance` call; returns the final state, the
/// statistics, the wall time and the thread's CPU time of the call (s).
fn integrate_timed(
    system: &dyn OdeSystem,
    y0: &[f64],
    t_end: f64,
    setting: &Setting,
) -> Result<(Vec<f64>, Stats, f64, f64), IntegrateError> {
    let tol = setting.tolerance.unwrap_or(1e-6);
    let mut integ = make_integrator(setting.method, Tolerances::scale_free(tol, tol, system), setting.step)?;
    integ.set_span(t_end);
    let (mut t, mut y) = (0.0, y0.to_vec());
    let cpu_start = thread_cpu_seconds();
    let start = Instant::now();
    integ.advance(system, &mut t, &mut y, t_end)?;
    let wall = start.elapsed().as_secs_f64();
    let cpu = match (cpu_start, thread_cpu_seconds()) {
        (Some(a), Some(b)) => b - a,
        _ => f64::NAN,
    };
    Ok((y, integ.stats(), wall, cpu))
}

/// One setting's measurements.
struct NBodyRow {
    setting: Setting,
    wall: f64,
    wall_min: f64,
    stats: Stats,
    timed_runs: usize,
    energy_error: f64,
    rhs_seconds: f64,
    profiled_wall: f64,
    bare_wall: f64,
    bare_difference: f64,
    cpu: f64,
    bare_cpu: f64,
    y: Vec<f64>,
}

fn measure_nbody(problem: &ProblemSetup, setting: &Setting, repeats: usize) -> Result<NBodyRow, IntegrateError> {
    let mut times = Vec::with_capacity(repeats);
    let mut cpu = Vec::with_capacity(repeats);
    let mut first = None;
    for _ in 0..repeats {
        let run = run_once(problem, setting)?;
        times.push(run.wall_seconds);
        cpu.push(run.cpu_seconds);
        first.get_or_insert(run);
    }
    let first = first.expect("repeats >= 1");
    let y0 = problem.initial_state();
    let timed = TimedSystem {
        inner: &problem.system,
        nanos: AtomicU64::new(0),
    };
    let (_, _, profiled_wall, _) = integrate_timed(&timed, &y0, problem.t_end, setting)?;
    let bare = PointMassGravity::new(1.0, &problem.bodies);
    let mut bare_times = Vec::with_capacity(repeats);
    let mut bare_cpu = Vec::with_capacity(repeats);
    let mut bare_y = Vec::new();
    for _ in 0..repeats {
        let (y, _, wall, c) = integrate_timed(&bare, &y0, problem.t_end, setting)?;
        bare_times.push(wall);
        bare_cpu.push(c);
        bare_y = y;
    }
    Ok(NBodyRow {
        setting: *setting,
        wall: median(&times),
        wall_min: times.iter().copied().fold(f64::INFINITY, f64::min),
        stats: first.stats,
        timed_runs: times.len(),
        energy_error: first.energy_error,
        rhs_seconds: timed.nanos.load(Ordering::Relaxed) as f64 * 1e-9,
        profiled_wall,
        bare_wall: median(&bare_times),
        bare_difference: problem.state_error(&bare_y, &first.y),
        cpu: median(&cpu),
        bare_cpu: median(&bare_cpu),
        y: first.y,
    })
}

/// The output files of `bench nbody` for `problem` in `dir`: timing CSV and states CSV.
pub fn output_paths(dir: &Path, problem: &str) -> [PathBuf; 2] {
    let stem = format!("nbody_{}", problem.replace('-', "_"));
    [dir.join(format!("{stem}.csv")), dir.join(format!("{stem}_states.csv"))]
}

/// Runs `bench nbody`.
pub fn nbody(args: &NBodyArgs) -> Result<(), CliError> {
    if args.rtol.is_empty() {
        return Err(CliError::usage("--rtol: give at least one tolerance"));
    }
    if let Some(&bad) = args.rtol.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
        return Err(CliError::usage(format!(
            "--rtol: values must be > 0 and finite, got {bad}"
        )));
    }
    if args.methods.contains(&Method::Rk4) {
        return Err(CliError::usage(
            "--methods: rk4 has no tolerance; choose from bulirsch-stoer, dop853, dopri5",
        ));
    }
    let problem = args.problem.setup();
    let paths = output_paths(&args.out, problem.name);
    prepare_outputs(&args.out, &paths, args.force)?;
    println!("bench nbody: {}", problem.description);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| CliError::failed(format!("cannot build a one-thread pool: {e}")))?;
    let mut rows = Vec::new();
    for &method in &args.methods {
        for &tol in &args.rtol {
            let setting = Setting::adaptive(method, tol);
            let row = pool
                .install(|| measure_nbody(&problem, &setting, args.repeats as usize))
                .map_err(|e| CliError::failed(format!("{}: {e}", setting.label())))?;
            println!(
                "  {:<28} {:.4e} s (median of {}; min {:.4e} s; cpu {})  {} RHS, {} steps  energy {:.2e}  \
                 RHS share {:.0}%  bare RHS {:.4e} s",
                setting.label(),
                row.wall,
                row.timed_runs,
                row.wall_min,
                fmt_cpu(row.cpu),
                row.stats.rhs_evaluations,
                row.stats.steps_accepted,
                row.energy_error,
                100.0 * row.rhs_seconds / row.profiled_wall,
                row.bare_wall
            );
            rows.push(row);
        }
    }
    let [timing, states] = &paths;
    write_timing(timing, &rows).map_err(|e| CliError::failed(format!("{}: {e}", timing.display())))?;
    write_states(states, &problem, &rows).map_err(|e| CliError::failed(format!("{}: {e}", states.display())))?;
    println!("  wrote {} and {}", timing.display(), states.display());
    Ok(())
}

fn write_timing(path: &Path, rows: &[NBodyRow]) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(
        f,
        "method,rtol,wall_seconds,wall_min_seconds,rhs_evaluations,steps,rejected_steps,timed_runs,energy_error,\
         rhs_seconds,profiled_wall_seconds,bare_wall_seconds,bare_difference,cpu_seconds,bare_cpu_seconds"
    )?;
    for r in rows {
        writeln!(
            f,
            "{},{:e},{:e},{:e},{},{},{},{},{:e},{:e},{:e},{:e},{:e},{:e},{:e}",
            r.setting.method,
            r.setting.tolerance.unwrap_or(f64::NAN),
            r.wall,
            r.wall_min,
            r.stats.rhs_evaluations,
            r.stats.steps_accepted,
            r.stats.steps_rejected,
            r.timed_runs,
            r.energy_error,
            r.rhs_seconds,
            r.profiled_wall,
            r.bare_wall,
            r.bare_difference,
            r.cpu,
            r.bare_cpu
        )?;
    }
    f.flush()
}

fn write_states(path: &Path, problem: &ProblemSetup, rows: &[NBodyRow]) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(f, "method,rtol,body,mass,x,y,z,vx,vy,vz")?;
    let mut write = |label: &str, rtol: String, y: &[f64]| -> std::io::Result<()> {
        for (b, body) in problem.bodies.iter().enumerate() {
            let m = body.shape.mass;
            let s = &y[6 * b..6 * b + 6];
            writeln!(
                f,
                "{label},{rtol},{b},{m:e},{:e},{:e},{:e},{:e},{:e},{:e}",
                s[0],
                s[1],
                s[2],
                s[3] / m,
                s[4] / m,
                s[5] / m
            )?;
        }
        Ok(())
    };
    write("initial", String::new(), &problem.initial_state())?;
    for r in rows {
        write(
            &r.setting.method.to_string(),
            format!("{:e}", r.setting.tolerance.unwrap_or(f64::NAN)),
            &r.y,
        )?;
    }
    f.flush()
}
