//! `rubblepile bench stability`: runs the stability suite of [`crate::bench::stability`] (Roig03 model in its
//! regimes of trouble) and writes `stability.csv`, `stability.md` ([`crate::bench::stability`]) and a run per case.

use std::path::PathBuf;

use crate::bench::stability::cases::all_cases;
use crate::bench::stability::suite::{StabilityRow, Verdict, run_case};
use crate::bench::stability::{prepare_out, result_paths, write_csv, write_markdown};
use crate::cli::common::CliError;

/// `rubblepile bench stability`.
#[derive(Debug, clap::Args)]
pub struct StabilityArgs {
    /// Directory for `stability.csv`, `stability.md` and `runs/<case>/` (each case's ordinary run
    /// directory: scene.toml, summary.json, timeseries.csv, snapshots/).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Overwrite the results of an earlier suite in DIR.
    #[arg(long)]
    pub force: bool,
    /// The quick set that `tests/stability.rs` runs: a 64-body cloud instead of 2000, κ ∈ {1.6, 5, 50}.
    #[arg(long)]
    pub quick: bool,
    /// Run only the cases whose id contains one of these strings (comma-separated), e.g. `--only a2,f-kappa`.
    #[arg(long, value_delimiter = ',')]
    pub only: Vec<String>,
    /// The integrator every case runs with (its tolerances unchanged), e.g. `bulirsch-stoer-implicit` to compare
    /// the stiff rows.
    #[arg(long, value_parser = crate::choice::choice::<rubblepile::integrate::Method>(), default_value_t = rubblepile::integrate::Method::BulirschStoer)]
    pub method: rubblepile::integrate::Method,
}

/// Runs `bench stability`; exits with code 1 when a case fails.
pub fn stability(args: &StabilityArgs) -> Result<(), CliError> {
    let cases: Vec<_> = all_cases(args.quick)
        .into_iter()
        .filter(|c| args.only.is_empty() || args.only.iter().any(|s| c.id.contains(s.as_str())))
        .map(|c| c.with_method(args.method))
        .collect();
    if cases.is_empty() {
        return Err(CliError::usage(format!(
            "--only: no case id contains any of {:?}",
            args.only
        )));
    }
    prepare_out(&args.out, args.force).map_err(CliError::usage)?;
    let runs = args.out.join("runs");
    println!(
        "bench stability: {} cases{} into {}",
        cases.len(),
        if args.quick { " (quick set)" } else { "" },
        args.out.display()
    );
    let mut rows: Vec<StabilityRow> = Vec::new();
    for case in &cases {
        let result = run_case(case, &runs, args.force).map_err(CliError::failed)?;
        let r = &result.row;
        println!(
            "  {:<24} {:<4}  steps {:>7}  wall {:>7.2} s  energy {:.1e}  {}",
            r.case,
            r.verdict.as_str(),
            r.steps,
            r.wall_seconds,
            r.energy_error,
            r.note
        );
        rows.push(result.row);
    }
    let [csv, md] = result_paths(&args.out);
    write_csv(&csv, &rows).map_err(|e| CliError::failed(format!("{}: {e}", csv.display())))?;
    let title = if args.quick {
        "rubblepile bench stability --quick"
    } else {
        "rubblepile bench stability"
    };
    write_markdown(&md, &rows, title).map_err(|e| CliError::failed(format!("{}: {e}", md.display())))?;
    println!("  wrote {} and {}", csv.display(), md.display());
    let failed: Vec<&str> = rows
        .iter()
        .filter(|r| r.verdict == Verdict::Fail)
        .map(|r| r.case.as_str())
        .collect();
    if failed.is_empty() {
        Ok(())
    } else {
        Err(CliError::failed(format!(
            "{} of {} stability cases failed: {}",
            failed.len(),
            rows.len(),
            failed.join(", ")
        )))
    }
}
