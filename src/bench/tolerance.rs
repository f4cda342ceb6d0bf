//! `rubblepile bench tolerance`: tolerance proportionality of the adaptive integrators — does the final-state
//! error follow `rtol`? On the canonical problems (the free top with its analytic reference; the bouncing pair,
//! conservative and dissipative; the N30 impact; the N200 impact to 400 s; the Pythagorean three-body problem; the
//! outer Solar System; the stiff damped pair and the overdamped pile, F0 = 1e-2 s m⁻²), each
//! method runs once per `rtol = atol` from 1e-6 to 1e-12 and the error (as in `bench work-precision`, against a
//! reference by a different method at 1e-14; for the two stiff problems one reference for every method, tight
//! explicit Bulirsch–Stoer where it finishes, else tight implicit) is divided by `rtol`. A tolerance means what it says when
//! `error_over_tol` stays of order one, at most 100, and the error falls monotonically as `rtol` does.
//! Writes `tolerance.csv` and prints, per problem and method, the worst `error_over_tol` at `rtol ≥ 1e-11` and
//! whether the error is monotone.

use std::io::Write;
use std::path::PathBuf;

use super::BenchError;
use crate::bench::work_precision::{DEFAULT_REFERENCE_TOLERANCE, SweepConfig, sweep};
use rubblepile::impact::problems::{NBodyProblem, ProblemSetup, WorkPrecisionProblem};
use rubblepile::integrate::Method;

/// `rubblepile bench tolerance`.
#[derive(Debug, clap::Args)]
pub struct ToleranceArgs {
    /// Output directory (tolerance.csv).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Overwrite an earlier tolerance.csv in DIR.
    #[arg(long)]
    pub force: bool,
    /// Methods, comma-separated (default bulirsch-stoer,dop853; bulirsch-stoer-implicit for the stiff problems).
    #[arg(long, value_parser = crate::choice::choice::<Method>(), value_delimiter = ',', value_name = "METHOD")]
    pub methods: Option<Vec<Method>>,
    /// Problems, comma-separated, from top, pair, pair-dissipative, n30, n200, pythagorean, outer-solar, stiff-pair,
    /// pile (default all).
    #[arg(long, value_delimiter = ',', value_name = "PROBLEM")]
    pub problems: Option<Vec<String>>,
}

/// Tolerances of the suite: one per decade, 1e-6 … 1e-12.
pub const TOLERANCES: [f64; 7] = [1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12];

/// A problem of the suite: its name and how to build it.
pub type NamedProblem = (&'static str, fn() -> ProblemSetup);

/// Every problem of the suite by name.
pub fn problems() -> Vec<NamedProblem> {
    vec![
        ("top", || WorkPrecisionProblem::Top.setup()),
        ("pair", || WorkPrecisionProblem::Pair.setup()),
        ("pair-dissipative", || WorkPrecisionProblem::PairDissipative.setup()),
        ("n30", || WorkPrecisionProblem::N30.setup()),
        ("n200", || WorkPrecisionProblem::N200.setup()),
        ("pythagorean", || NBodyProblem::Pythagorean.setup()),
        ("outer-solar", || NBodyProblem::OuterSolar.setup()),
        ("stiff-pair", || WorkPrecisionProblem::StiffPair.setup()),
        ("pile", || WorkPrecisionProblem::Pile.setup()),
    ]
}

/// Runs `bench tolerance`.
pub fn tolerance(args: &ToleranceArgs) -> Result<(), BenchError> {
    let csv = args.out.join("tolerance.csv");
    if csv.exists() && !args.force {
        return Err(BenchError::usage(format!(
            "--out: {} already holds tolerance.csv; use --force to overwrite it",
            args.out.display()
        )));
    }
    let all = problems();
    let chosen: Vec<_> = match &args.problems {
        None => all,
        Some(names) => names
            .iter()
            .map(|n| {
                all.iter().find(|(k, _)| k == n).copied().ok_or_else(|| {
                    let known: Vec<&str> = all.iter().map(|(k, _)| *k).collect();
                    BenchError::usage(format!("--problems: unknown {n:?}; known: {}", known.join(", ")))
                })
            })
            .collect::<Result<_, _>>()?,
    };
    let methods = args
        .methods
        .clone()
        .unwrap_or(vec![Method::BulirschStoer, Method::Dop853]);
    if methods.contains(&Method::Rk4) {
        return Err(BenchError::usage("--methods: rk4 has no tolerance"));
    }
    std::fs::create_dir_all(&args.out).map_err(|e| BenchError::failed(format!("{}: {e}", args.out.display())))?;
    let mut lines = vec!["problem,method,rtol,error,error_over_tol,wall_seconds,steps,rejected_steps".to_string()];
    for (name, build) in chosen {
        let problem = build();
        let config = SweepConfig {
            methods: methods.clone(),
            tolerances: TOLERANCES.to_vec(),
            rk4_steps: Vec::new(),
            repeats: 1,
            max_run_seconds: 120.0,
            reference_tolerance: DEFAULT_REFERENCE_TOLERANCE,
        };
        let result = sweep(&problem, &config, &mut |_| {}).map_err(|e| BenchError::failed(format!("{name}: {e}")))?;
        for m in &methods {
            let rows: Vec<_> = result.rows.iter().filter(|r| r.setting.method == *m).collect();
            let mut worst: f64 = 0.0;
            let mut monotone = true;
            for (k, r) in rows.iter().enumerate() {
                let tol = r.setting.tolerance.unwrap_or(f64::NAN);
                let ratio = r.error / tol;
                if tol >= 1e-11 * (1.0 - 1e-9) {
                    worst = worst.max(ratio);
                }
                if k > 0 && r.error > rows[k - 1].error {
                    monotone = false;
                }
                lines.push(format!(
                    "{name},{m},{tol:e},{:e},{ratio:e},{:e},{},{}",
                    r.error, r.wall_seconds, r.steps, r.rejected_steps
                ));
            }
            let errors: Vec<String> = rows.iter().map(|r| format!("{:.1e}", r.error)).collect();
            println!(
                "{name:>16} {m:>14}: worst error/rtol {worst:>9.2e} (rtol >= 1e-11), {}; errors {}",
                if monotone { "monotone" } else { "NOT monotone" },
                errors.join(" ")
            );
        }
        for s in &result.skipped {
            println!("{name:>16}: skipped {s}");
        }
    }
    let mut f = std::fs::File::create(&csv).map_err(|e| BenchError::failed(format!("{}: {e}", csv.display())))?;
    f.write_all((lines.join("\n") + "\n").as_bytes())
        .map_err(|e| BenchError::failed(format!("{}: {e}", csv.display())))?;
    println!("wrote {}", csv.display());
    Ok(())
}
