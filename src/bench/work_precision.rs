//! Work–precision measurements: run an integrator on a [`ProblemSetup`] at a tolerance (or fixed step),
//! time the integration, and measure the final-state error against a reference and the energy residual.
//!
//! The method follows Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.10 ("Numerical comparisons": error at
//! the end point against computing time, one curve per code, tolerances one per decade) and the
//! work–precision diagrams of DifferentialEquations.jl's SciMLBenchmarks.
//!
//! * **Time** is the wall-clock time of the [`rubblepile::integrate::Integrator::advance`] calls only: building the system, the
//!   initial state, the diagnostics at the energy checks and all I/O are outside the clock. Each setting is
//!   run `repeats` times and the **median** is reported; a setting whose first run takes less than
//!   [`SHORT_RUN_SECONDS`] is run more often (up to [`SHORT_RUN_MAX_REPEATS`] times, about
//!   [`SHORT_RUN_BUDGET_SECONDS`] in all) so that its median is not at the mercy of one scheduler hiccup, and
//!   a setting whose first run takes longer than [`LONG_RUN_SECONDS`] is run [`LONG_RUN_REPEATS`] times at
//!   most and the **minimum** is reported.
//! * **CPU time** of the calling thread over the same `advance` calls is recorded beside it (from Linux's
//!   `/proc/thread-self/schedstat`, NaN elsewhere): on a shared, loaded machine the wall time measures the
//!   scheduler's share as much as the code, the thread's CPU time much less so. The CLI runs every setting in
//!   a one-thread pool, so the RHS's rayon loops (used from 64 bodies / 256 pairs) stay on that thread.
//! * **Error** is [`ProblemSetup::spin_error`] for the top (analytic reference) and otherwise
//!   [`ProblemSetup::state_error`] (block norm) against a reference state at `t_end` computed by a
//!   *different* method at a tight tolerance: Dop853 for Bulirsch–Stoer, Bulirsch–Stoer for every other method.
//! * **Energy error** is the largest [`ProblemSetup::energy_residual`] over the problem's
//!   `energy_samples` equally spaced checks (the integrator lands on each).

use std::time::Instant;

use rubblepile::impact::problems::{ProblemSetup, ReferenceKind};
use rubblepile::integrate::{IntegrateError, Method, Stats, Tolerances, make_integrator};

/// Runs longer than this (s) are repeated at most [`LONG_RUN_REPEATS`] times and timed by their minimum.
pub const LONG_RUN_SECONDS: f64 = 2.0;
/// Repeats of a run longer than [`LONG_RUN_SECONDS`].
pub const LONG_RUN_REPEATS: usize = 2;
/// Runs shorter than this (s) are repeated more than asked, see [`SHORT_RUN_MAX_REPEATS`].
pub const SHORT_RUN_SECONDS: f64 = 0.05;
/// Most repeats of a short run.
pub const SHORT_RUN_MAX_REPEATS: usize = 25;
/// Total time (s) the repeats of a short run aim at.
pub const SHORT_RUN_BUDGET_SECONDS: f64 = 0.25;
/// Default tolerances of the sweep: `rtol = atol = 10⁻⁴ … 10⁻¹²`, one per decade.
pub const DEFAULT_TOLERANCES: [f64; 9] = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12];
/// Default tolerance of the reference runs.
pub const DEFAULT_REFERENCE_TOLERANCE: f64 = 1e-14;

/// What one run integrates with: a method and its tolerance (`rtol = atol`) or, for Rk4, its fixed step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setting {
    /// The method.
    pub method: Method,
    /// `rtol = atol` of the adaptive methods (`None` for Rk4).
    pub tolerance: Option<f64>,
    /// Rk4's fixed step (time unit of the problem; `None` for the adaptive methods).
    pub step: Option<f64>,
}

impl Setting {
    /// An adaptive method at `rtol = atol = tolerance`.
    pub fn adaptive(method: Method, tolerance: f64) -> Self {
        Setting {
            method,
            tolerance: Some(tolerance),
            step: None,
        }
    }

    /// Rk4 with the fixed step `step`.
    pub fn rk4(step: f64) -> Self {
        Setting {
            method: Method::Rk4,
            tolerance: None,
            step: Some(step),
        }
    }

    /// E.g. `bulirsch-stoer rtol 1e-8` or `rk4 h 0.01`.
    pub fn label(&self) -> String {
        match (self.tolerance, self.step) {
            (Some(t), _) => format!("{} rtol {t:e}", self.method),
            (None, Some(h)) => format!("{} h {h:e}", self.method),
            _ => self.method.to_string(),
        }
    }
}

/// The outcome of one run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutcome {
    /// The state at `t_end`.
    pub y: Vec<f64>,
    /// Largest energy residual over the checks.
    pub energy_error: f64,
    /// The integrator's statistics.
    pub stats: Stats,
    /// Wall-clock time of the `advance` calls (s).
    pub wall_seconds: f64,
    /// CPU time of the calling thread over the `advance` calls (s; NaN where not measurable).
    pub cpu_seconds: f64,
}

/// CPU time the calling thread has run so far (s), from `/proc/thread-self/schedstat` (Linux, ns resolution);
/// `None` where that file is not available or accounts no CPU time (reads 0).
pub fn thread_cpu_seconds() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: u64 = text.split_whitespace().next()?.parse().ok()?;
    // The calling thread is running: a kernel that accounts its CPU time says more than 0. Some (containers,
    // kernels without schedstats) always say 0: then the CPU time is unknown, not zero (issue 57).
    (ns > 0).then_some(ns as f64 * 1e-9)
}

/// A CPU time for a printed line: `1.2345e-2 s`, or `n/a` when it could not be measured (NaN,
/// [`thread_cpu_seconds`]).
pub fn fmt_cpu(seconds: f64) -> String {
    if seconds.is_finite() {
        format!("{seconds:.4e} s")
    } else {
        "n/a".to_string()
    }
}

/// How a row's time was taken, for a printed line: `median of 5`, and why the number of timed runs differs from
/// `--repeats` when it does (a short run is repeated more, a long one at most [`LONG_RUN_REPEATS`] times).
pub fn timed_runs_note(statistic: &str, timed_runs: usize, repeats: usize) -> String {
    let mut note = format!("{statistic} of {timed_runs}");
    if timed_runs > repeats {
        note += &format!("; --repeats {repeats} raised for a run under {SHORT_RUN_SECONDS} s");
    } else if timed_runs < repeats {
        note += &format!("; --repeats {repeats} capped for a run over {LONG_RUN_SECONDS} s");
    }
    note
}

/// Integrates `problem` from 0 to `t_end` with `setting`, landing on the energy checks; only the
/// `advance` calls are timed.
pub fn run_once(problem: &ProblemSetup, setting: &Setting) -> Result<RunOutcome, IntegrateError> {
    let system = &problem.system;
    let mut y = problem.initial_state();
    let tol = setting.tolerance.unwrap_or(1e-6);
    let mut integ = make_integrator(setting.method, Tolerances::scale_free(tol, tol, system), setting.step)?;
    integ.set_span(problem.t_end);
    let d0 = system.diagnostics(&y);
    let mut t = 0.0;
    let mut wall = 0.0;
    let mut cpu = 0.0;
    let mut energy: f64 = 0.0;
    let samples = problem.energy_samples.max(1);
    for k in 1..=samples {
        let target = if k == samples {
            problem.t_end
        } else {
            problem.t_end * k as f64 / samples as f64
        };
        let cpu_start = thread_cpu_seconds();
        let start = Instant::now();
        let r = integ.advance(system, &mut t, &mut y, target);
        wall += start.elapsed().as_secs_f64();
        cpu += match (cpu_start, thread_cpu_seconds()) {
            (Some(a), Some(b)) => b - a,
            _ => f64::NAN,
        };
        r?;
        energy = energy.max(problem.energy_residual(&d0, &y));
    }
    Ok(RunOutcome {
        y,
        energy_error: energy,
        stats: integ.stats(),
        wall_seconds: wall,
        cpu_seconds: cpu,
    })
}

/// One row of a work–precision table (one setting).
#[derive(Debug, Clone, PartialEq)]
pub struct SweepRow {
    /// The setting.
    pub setting: Setting,
    /// Final-state error (see the module docs).
    pub error: f64,
    /// Largest energy residual.
    pub energy_error: f64,
    /// Median (or, for long runs, minimum) wall time of the integration (s).
    pub wall_seconds: f64,
    /// RHS evaluations of one run.
    pub rhs_evaluations: u64,
    /// Accepted steps of one run.
    pub steps: u64,
    /// Rejected steps of one run.
    pub rejected_steps: u64,
    /// How many runs were timed.
    pub timed_runs: usize,
    /// `"median"` or `"min"`: which statistic `wall_seconds` (and `cpu_seconds`) is.
    pub statistic: &'static str,
    /// The same statistic of the thread's CPU time over the integration (s; NaN where not measurable).
    pub cpu_seconds: f64,
}

pub use rubblepile::math::median;

/// Runs `setting` `repeats` times (more for short runs, fewer for long ones, see the module docs); the error is computed with
/// `error_of(final state)`.
pub fn measure(
    problem: &ProblemSetup,
    setting: &Setting,
    repeats: usize,
    error_of: &dyn Fn(&[f64]) -> f64,
) -> Result<SweepRow, IntegrateError> {
    let first = run_once(problem, setting)?;
    let mut times = vec![first.wall_seconds];
    let mut cpu = vec![first.cpu_seconds];
    let long = first.wall_seconds > LONG_RUN_SECONDS;
    let runs = if long {
        repeats.clamp(1, LONG_RUN_REPEATS)
    } else if first.wall_seconds < SHORT_RUN_SECONDS {
        let fill = (SHORT_RUN_BUDGET_SECONDS / first.wall_seconds.max(1e-9)).ceil() as usize;
        repeats.max(fill.min(SHORT_RUN_MAX_REPEATS))
    } else {
        repeats.max(1)
    };
    for _ in 1..runs {
        let run = run_once(problem, setting)?;
        times.push(run.wall_seconds);
        cpu.push(run.cpu_seconds);
    }
    let min = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
    let (wall, cpu_seconds, statistic) = if long {
        (min(&times), min(&cpu), "min")
    } else {
        (median(&times), median(&cpu), "median")
    };
    Ok(SweepRow {
        setting: *setting,
        error: error_of(&first.y),
        energy_error: first.energy_error,
        wall_seconds: wall,
        rhs_evaluations: first.stats.rhs_evaluations,
        steps: first.stats.steps_accepted,
        rejected_steps: first.stats.steps_rejected,
        timed_runs: times.len(),
        statistic,
        cpu_seconds,
    })
}

/// The reference states of a problem with a numerical reference.
#[derive(Debug, Clone, PartialEq)]
pub struct References {
    /// Tolerance of the reference runs.
    pub tolerance: f64,
    /// The reference runs: Dop853 and Bulirsch–Stoer ([`ReferenceKind::Numerical`]: each method is measured
    /// against the other method's run), or the one run every method is measured against ([`ReferenceKind::Stiff`]).
    pub runs: Vec<ReferenceRun>,
    /// Block-norm distance between the two runs of a [`ReferenceKind::Numerical`] problem (a floor under the
    /// measurable error); `None` with one run.
    pub difference: Option<f64>,
    /// Why the explicit reference of a stiff problem was given up (its time limit), when it was.
    pub explicit_given_up: Option<String>,
}

/// One reference run.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceRun {
    /// The method.
    pub method: Method,
    /// Its state at `t_end`.
    pub state: Vec<f64>,
    /// Wall time of the run (s).
    pub wall_seconds: f64,
}

/// Wall-clock limit (s) of a stiff problem's explicit reference run: past it the tight implicit run is the reference.
pub const STIFF_REFERENCE_EXPLICIT_SECONDS: f64 = 60.0;

/// Integrates `problem` to `t_end` with `method` at `rtol = atol = tolerance` in 100 pieces, giving up (`Ok(None)`)
/// once the wall time passes `limit_seconds`.
fn run_limited(
    problem: &ProblemSetup,
    method: Method,
    tolerance: f64,
    limit_seconds: f64,
) -> Result<Option<ReferenceRun>, IntegrateError> {
    let system = &problem.system;
    let mut y = problem.initial_state();
    let mut integ = make_integrator(method, Tolerances::scale_free(tolerance, tolerance, system), None)?;
    integ.set_span(problem.t_end);
    let start = Instant::now();
    let mut t = 0.0;
    let pieces = 100;
    for k in 1..=pieces {
        let target = if k == pieces {
            problem.t_end
        } else {
            problem.t_end * k as f64 / pieces as f64
        };
        integ.advance(system, &mut t, &mut y, target)?;
        if k < pieces && start.elapsed().as_secs_f64() > limit_seconds {
            return Ok(None);
        }
    }
    Ok(Some(ReferenceRun {
        method,
        state: y,
        wall_seconds: start.elapsed().as_secs_f64(),
    }))
}

impl References {
    /// Computes the reference runs at `tolerance`: for a [`ReferenceKind::Numerical`] problem Dop853 and
    /// Bulirsch–Stoer; for a [`ReferenceKind::Stiff`] one explicit Bulirsch–Stoer, or where that takes more than
    /// [`STIFF_REFERENCE_EXPLICIT_SECONDS`], the linearly implicit method.
    pub fn compute(problem: &ProblemSetup, tolerance: f64) -> Result<Self, IntegrateError> {
        if problem.reference == ReferenceKind::Stiff {
            let limit = STIFF_REFERENCE_EXPLICIT_SECONDS;
            if let Some(run) = run_limited(problem, Method::BulirschStoer, tolerance, limit)? {
                return Ok(References {
                    tolerance,
                    runs: vec![run],
                    difference: None,
                    explicit_given_up: None,
                });
            }
            let run =
                run_limited(problem, Method::BulirschStoerImplicit, tolerance, f64::INFINITY)?.expect("no time limit");
            return Ok(References {
                tolerance,
                runs: vec![run],
                difference: None,
                explicit_given_up: Some(format!(
                    "bulirsch-stoer at rtol {tolerance:e} did not finish within {limit} s"
                )),
            });
        }
        let d = run_once(problem, &Setting::adaptive(Method::Dop853, tolerance))?;
        let b = run_once(problem, &Setting::adaptive(Method::BulirschStoer, tolerance))?;
        Ok(References {
            tolerance,
            difference: Some(problem.state_error(&b.y, &d.y)),
            runs: vec![
                ReferenceRun {
                    method: Method::Dop853,
                    state: d.y,
                    wall_seconds: d.wall_seconds,
                },
                ReferenceRun {
                    method: Method::BulirschStoer,
                    state: b.y,
                    wall_seconds: b.wall_seconds,
                },
            ],
            explicit_given_up: None,
        })
    }

    /// The reference run for runs of `method`: the only one, or the other method's (Dop853 for Bulirsch–Stoer,
    /// Bulirsch–Stoer for every other method).
    pub fn run_for(&self, method: Method) -> &ReferenceRun {
        if self.runs.len() == 1 {
            return &self.runs[0];
        }
        let wanted = if method == Method::BulirschStoer {
            Method::Dop853
        } else {
            Method::BulirschStoer
        };
        self.runs.iter().find(|r| r.method == wanted).unwrap_or(&self.runs[0])
    }

    /// The reference state for runs of `method` ([`Self::run_for`]).
    pub fn for_method(&self, method: Method) -> &[f64] {
        &self.run_for(method).state
    }

    /// One line saying what the references are, how long they took and, for two, how far they differ.
    pub fn describe(&self) -> String {
        let runs: Vec<String> = self
            .runs
            .iter()
            .map(|r| format!("{} at rtol {:e} ({:.2} s)", r.method, self.tolerance, r.wall_seconds))
            .collect();
        let mut line = format!("reference: {}", runs.join(" and "));
        if let Some(d) = self.difference {
            line += &format!("; the two differ by {d:.2e} (block norm)");
        }
        if let Some(why) = &self.explicit_given_up {
            line += &format!("; the implicit run, because {why}");
        }
        line
    }
}

/// What a sweep runs.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepConfig {
    /// Adaptive methods swept over `tolerances` (in this order).
    pub methods: Vec<Method>,
    /// `rtol = atol` values, loosest first.
    pub tolerances: Vec<f64>,
    /// Rk4 steps, largest first (empty = no Rk4).
    pub rk4_steps: Vec<f64>,
    /// Timed repeats per setting.
    pub repeats: usize,
    /// A method's sweep stops after its first run longer than this (s): tighter settings would take longer.
    pub max_run_seconds: f64,
    /// Tolerance of the reference runs (problems with a numerical reference).
    pub reference_tolerance: f64,
}

/// A finished sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct Sweep {
    /// One row per completed setting.
    pub rows: Vec<SweepRow>,
    /// The numerical references (`None` for the analytic top).
    pub references: Option<References>,
    /// Settings left out, with why (a failed run, or the time limit).
    pub skipped: Vec<String>,
}

/// Runs the sweep; `progress` is called with every finished row and every skip note.
pub fn sweep(
    problem: &ProblemSetup,
    config: &SweepConfig,
    progress: &mut dyn FnMut(&str),
) -> Result<Sweep, IntegrateError> {
    let references = match problem.reference {
        ReferenceKind::Analytic => None,
        ReferenceKind::Numerical | ReferenceKind::Stiff => {
            progress(&format!(
                "reference runs at rtol = atol = {:e} ...",
                config.reference_tolerance
            ));
            let r = References::compute(problem, config.reference_tolerance)?;
            progress(&format!("  {}", r.describe()));
            Some(r)
        }
    };
    let t_end = problem.t_end;
    let mut rows = Vec::new();
    let mut skipped = Vec::new();
    let mut plan: Vec<Vec<Setting>> = config
        .methods
        .iter()
        .filter(|&&m| m != Method::Rk4)
        .map(|&m| config.tolerances.iter().map(|&t| Setting::adaptive(m, t)).collect())
        .collect();
    if !config.rk4_steps.is_empty() {
        plan.push(config.rk4_steps.iter().map(|&h| Setting::rk4(h)).collect());
    }
    for settings in plan {
        for (k, setting) in settings.iter().enumerate() {
            let error_of = |y: &[f64]| match &references {
                None => problem.spin_error(t_end, y).unwrap_or(f64::NAN),
                Some(r) => problem.state_error(y, r.for_method(setting.method)),
            };
            match measure(problem, setting, config.repeats, &error_of) {
                Ok(row) => {
                    progress(&format!(
                        "{:<28} error {:.3e}  energy {:.3e}  wall {:.4e} s, cpu {} ({})  {} RHS, {} steps",
                        setting.label(),
                        row.error,
                        row.energy_error,
                        row.wall_seconds,
                        fmt_cpu(row.cpu_seconds),
                        timed_runs_note(row.statistic, row.timed_runs, config.repeats),
                        row.rhs_evaluations,
                        row.steps
                    ));
                    let slow = row.wall_seconds > config.max_run_seconds;
                    rows.push(row);
                    if slow && k + 1 < settings.len() {
                        let note = format!(
                            "{}: settings tighter than {} left out (a run took more than {} s)",
                            setting.method,
                            setting.label(),
                            config.max_run_seconds
                        );
                        progress(&note);
                        skipped.push(note);
                        break;
                    }
                }
                Err(e) => {
                    let note = format!("{}: failed: {e}", setting.label());
                    progress(&note);
                    skipped.push(note);
                }
            }
        }
    }
    Ok(Sweep {
        rows,
        references,
        skipped,
    })
}

/// The CSV header of a work–precision table: the required columns
/// `method,rtol,error,energy_error,wall_seconds,rhs_evaluations,steps`, then `h,rejected_steps,timed_runs,
/// wall_statistic,cpu_seconds`.
pub const CSV_HEADER: &str = "method,rtol,error,energy_error,wall_seconds,rhs_evaluations,steps,h,rejected_steps,\
                              timed_runs,wall_statistic,cpu_seconds,error_over_tol";

/// One CSV line (no newline) for `row`: `rtol` is empty for Rk4 and `h` empty for the adaptive methods;
/// `error_over_tol` is the final-state error over `rtol` (tolerance proportionality; empty for Rk4).
pub fn csv_line(row: &SweepRow) -> String {
    let opt = |v: Option<f64>| v.map(|x| format!("{x:e}")).unwrap_or_default();
    format!(
        "{},{},{:e},{:e},{:e},{},{},{},{},{},{},{:e},{}",
        row.setting.method,
        opt(row.setting.tolerance),
        row.error,
        row.energy_error,
        row.wall_seconds,
        row.rhs_evaluations,
        row.steps,
        opt(row.setting.step),
        row.rejected_steps,
        row.timed_runs,
        row.statistic,
        row.cpu_seconds,
        opt(row.setting.tolerance.map(|t| row.error / t))
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 57: a CPU time that could not be measured prints as `n/a`, not `0.0000e0 s`, and a row timed more
    /// (or fewer) times than `--repeats` says why.
    #[test]
    fn printed_timing_says_what_was_measured() {
        assert_eq!(fmt_cpu(0.0123), "1.2300e-2 s");
        assert_eq!(fmt_cpu(f64::NAN), "n/a");
        assert_eq!(timed_runs_note("median", 5, 5), "median of 5");
        assert_eq!(
            timed_runs_note("median", 25, 1),
            "median of 25; --repeats 1 raised for a run under 0.05 s"
        );
        assert_eq!(
            timed_runs_note("min", 2, 5),
            "min of 2; --repeats 5 capped for a run over 2 s"
        );
        if let Some(t) = thread_cpu_seconds() {
            assert!(t > 0.0, "{t}");
        }
    }

    use rubblepile::impact::problems::WorkPrecisionProblem;

    #[test]
    fn top_analytic_reference_agrees_with_tight_bulirsch_stoer() {
        let top = WorkPrecisionProblem::Top.setup();
        let run = run_once(&top, &Setting::adaptive(Method::BulirschStoer, 1e-12)).unwrap();
        let err = top.spin_error(top.t_end, &run.y).unwrap();
        eprintln!(
            "top: BS 1e-12 spin error {err:.3e}, energy {:.3e}, {:?}",
            run.energy_error, run.stats
        );
        assert!(err <= 1e-9, "spin error {err:e}");
        assert!(run.energy_error <= 1e-10, "energy {:e}", run.energy_error);
        // |L| is conserved by the analytic solution and by the run.
        let moments = top.system.principal_moments()[0];
        let w_exact = top.exact_spin(top.t_end).unwrap();
        let w0 = top.bodies[0].spin_body;
        let l = |w: &rubblepile::math::Vec3| moments.component_mul(w).norm();
        assert!((l(&w_exact) / l(&w0) - 1.0).abs() < 1e-13);
        // And a loose run is visibly worse: the error measures something.
        let loose = run_once(&top, &Setting::adaptive(Method::BulirschStoer, 1e-5)).unwrap();
        assert!(top.spin_error(top.t_end, &loose.y).unwrap() > 1e3 * err);
    }

    /// The stiff damped pair of the benchmarks (`bench work-precision --problem stiff-pair`, damping ~1000× faster than
    /// the contact): the implicit method's final-state error against the tight explicit reference (which finishes
    /// here, so the reference is explicit) stays within 10 × rtol and falls with rtol, in a few hundred steps where
    /// the explicit method needs about 11 000.
    #[test]
    fn stiff_pair_error_follows_the_tolerance_against_the_explicit_reference() {
        let problem = WorkPrecisionProblem::StiffPair.setup();
        let reference = References::compute(&problem, 1e-11).unwrap();
        assert_eq!(reference.runs.len(), 1);
        assert_eq!(
            reference.runs[0].method,
            Method::BulirschStoer,
            "the explicit reference finishes"
        );
        assert!(reference.explicit_given_up.is_none());
        let mut previous = f64::INFINITY;
        for tol in [1e-4, 1e-6] {
            let run = run_once(&problem, &Setting::adaptive(Method::BulirschStoerImplicit, tol)).unwrap();
            let err = problem.state_error(&run.y, &reference.runs[0].state);
            eprintln!(
                "rtol {tol:e}: error {err:e} ({:.2} x rtol), {} steps",
                err / tol,
                run.stats.steps_accepted
            );
            assert!(err <= 10.0 * tol, "error {err:e} at rtol {tol:e}");
            assert!(err < previous, "error {err:e} not below {previous:e}");
            assert!(run.stats.steps_accepted < 2000, "{} steps", run.stats.steps_accepted);
            previous = err;
        }
    }
}
