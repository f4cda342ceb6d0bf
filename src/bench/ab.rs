//! `rubblepile bench ab`: two builds of rubblepile timed on the same command, alternately, in one invocation — the
//! before/after measurement of a change. Runs alternate (baseline, candidate, baseline, …) so that a drift of the
//! machine's load falls on both sides alike, and the 1-minute load average is recorded before and after every run:
//! a figure taken beside other jobs is not a result.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use super::BenchError;
use super::critical::load_average;

/// `rubblepile bench ab`.
#[derive(Debug, clap::Args)]
pub struct BenchAbArgs {
    /// The build before the change (a rubblepile executable).
    #[arg(long, value_name = "PATH")]
    pub baseline: PathBuf,
    /// The build after the change [default: this executable].
    #[arg(long, value_name = "PATH")]
    pub candidate: Option<PathBuf>,
    /// Runs of each build (at least 1).
    #[arg(long, default_value_t = 5)]
    pub repeat: usize,
    /// Write `ab.csv` and `ab.svg` here; each run's output goes to a fresh `DIR/scratch/<side>_<k>/`, put in place of
    /// `{out}` in the command.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Overwrite an earlier benchmark in DIR.
    #[arg(long)]
    pub force: bool,
    /// The rubblepile command both builds run, after `--`, e.g. `-- run targets/x.toml --out {out}`.
    #[arg(last = true, required = true, value_name = "ARGS")]
    pub command: Vec<String>,
}

/// One timed run.
#[derive(Debug, Clone, PartialEq)]
pub struct AbRun {
    /// `baseline` or `candidate`.
    pub side: &'static str,
    /// Its index among the runs of its side (from 0).
    pub k: usize,
    /// Wall time of the process (s).
    pub seconds: f64,
    /// The 1-minute load average before and after it.
    pub load: (f64, f64),
}

/// The median of `x` (NaN for none).
fn median(mut x: Vec<f64>) -> f64 {
    if x.is_empty() {
        return f64::NAN;
    }
    x.sort_by(f64::total_cmp);
    let n = x.len();
    if n % 2 == 1 {
        x[n / 2]
    } else {
        0.5 * (x[n / 2 - 1] + x[n / 2])
    }
}

/// The seconds of every run of `side`.
fn seconds_of(runs: &[AbRun], side: &str) -> Vec<f64> {
    runs.iter().filter(|r| r.side == side).map(|r| r.seconds).collect()
}

/// `ab.csv`: one row per run, in the order they ran.
pub fn ab_csv(runs: &[AbRun]) -> String {
    let mut text = String::from("run,side,k,seconds,load_before,load_after\n");
    for (i, r) in runs.iter().enumerate() {
        text += &format!(
            "{i},{},{},{:.4},{:.2},{:.2}\n",
            r.side, r.k, r.seconds, r.load.0, r.load.1
        );
    }
    text
}

/// The summary line: each side's median and fastest run, and candidate over baseline.
pub fn summary(runs: &[AbRun]) -> String {
    let (a, b) = (seconds_of(runs, "baseline"), seconds_of(runs, "candidate"));
    let min = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
    let (ma, mb) = (median(a.clone()), median(b.clone()));
    let loads: Vec<f64> = runs.iter().flat_map(|r| [r.load.0, r.load.1]).collect();
    format!(
        "baseline median {ma:.3} s (fastest {:.3} s), candidate median {mb:.3} s (fastest {:.3} s): candidate / \
         baseline = {:.3} by the medians, {:.3} by the fastest runs; load average {:.2} to {:.2}",
        min(&a),
        min(&b),
        mb / ma,
        min(&b) / min(&a),
        min(&loads),
        loads.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    )
}

/// Runs `bin` with `command` (`{out}` replaced by `scratch`) and returns its wall time; a failed run is an error
/// naming the build and its exit status.
fn time_one(bin: &Path, command: &[String], scratch: &Path) -> Result<f64, BenchError> {
    let args: Vec<String> = command
        .iter()
        .map(|a| a.replace("{out}", &scratch.display().to_string()))
        .collect();
    let started = Instant::now();
    let out = Command::new(bin)
        .args(&args)
        .output()
        .map_err(|e| BenchError::usage(format!("{}: cannot run it: {e}", bin.display())))?;
    let seconds = started.elapsed().as_secs_f64();
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        return Err(BenchError::failed(format!(
            "{} {} failed ({}): {}",
            bin.display(),
            args.join(" "),
            out.status,
            stderr.lines().last().unwrap_or("")
        )));
    }
    Ok(seconds)
}

/// Runs the benchmark: both builds `repeat` times, alternately, then writes `ab.csv` and `ab.svg`.
pub fn bench(args: &BenchAbArgs) -> Result<(), BenchError> {
    if args.repeat == 0 {
        return Err(BenchError::usage("--repeat: expected at least 1, got 0"));
    }
    let candidate = match &args.candidate {
        Some(c) => c.clone(),
        None => std::env::current_exe().map_err(|e| BenchError::failed(format!("this executable: {e}")))?,
    };
    for (flag, bin) in [("--baseline", &args.baseline), ("--candidate", &candidate)] {
        if !bin.is_file() {
            return Err(BenchError::usage(format!(
                "{flag}: expected an executable file, got {}",
                bin.display()
            )));
        }
    }
    let csv_path = args.out.join("ab.csv");
    if csv_path.exists() && !args.force {
        return Err(BenchError::usage(format!(
            "{} exists; use --force to overwrite it",
            csv_path.display()
        )));
    }
    let scratch = args.out.join("scratch");
    if scratch.exists() {
        std::fs::remove_dir_all(&scratch).map_err(|e| BenchError::failed(format!("{}: {e}", scratch.display())))?;
    }
    std::fs::create_dir_all(&scratch).map_err(|e| BenchError::failed(format!("{}: {e}", scratch.display())))?;
    let mut runs = Vec::new();
    for k in 0..args.repeat {
        for (side, bin) in [("baseline", &args.baseline), ("candidate", &candidate)] {
            let dir = scratch.join(format!("{side}_{k}"));
            let before = load_average();
            let seconds = time_one(bin, &args.command, &dir)?;
            runs.push(AbRun {
                side,
                k,
                seconds,
                load: (before, load_average()),
            });
            println!("{side} {k}: {seconds:.3} s");
        }
    }
    rubblepile::io::safe_write::write_atomic(&csv_path, ab_csv(&runs))
        .map_err(|e| BenchError::failed(format!("{}: {e}", csv_path.display())))?;
    plot(&args.out.join("ab.svg"), &runs).map_err(BenchError::failed)?;
    println!("{}", summary(&runs));
    println!("wrote {}", csv_path.display());
    Ok(())
}

/// Every run's wall time by its order, baseline and candidate in two colours.
fn plot(path: &Path, runs: &[AbRun]) -> Result<(), String> {
    use plotters::prelude::*;
    rubblepile::analysis::figures::style::ensure_font()?;
    let root = SVGBackend::new(path, (640, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let max_s = runs.iter().map(|r| r.seconds).fold(0.0, f64::max) * 1.2;
    let mut chart = ChartBuilder::on(&root)
        .caption("baseline and candidate, alternately", ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(70)
        .build_cartesian_2d(-0.5..runs.len() as f64 - 0.5, 0.0..max_s.max(1e-3))
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc("run, in the order they ran")
        .y_desc("wall time (s)")
        .draw()
        .map_err(|e| e.to_string())?;
    for (side, colour) in [("baseline", BLUE), ("candidate", RED)] {
        chart
            .draw_series(
                runs.iter()
                    .enumerate()
                    .filter(|(_, r)| r.side == side)
                    .map(|(i, r)| Circle::new((i as f64, r.seconds), 4, colour.filled())),
            )
            .map_err(|e| e.to_string())?
            .label(side)
            .legend(move |(x, y)| Circle::new((x, y), 4, colour.filled()));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE)
        .border_style(BLACK)
        .draw()
        .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(side: &'static str, k: usize, seconds: f64) -> AbRun {
        AbRun {
            side,
            k,
            seconds,
            load: (0.5, 0.6),
        }
    }

    /// The summary's ratio is candidate over baseline by the medians and by the fastest runs.
    #[test]
    fn summary_gives_candidate_over_baseline_by_medians_and_fastest_runs() {
        let runs = [
            run("baseline", 0, 2.0),
            run("candidate", 0, 1.0),
            run("baseline", 1, 4.0),
            run("candidate", 1, 3.0),
            run("baseline", 2, 3.0),
            run("candidate", 2, 1.5),
        ];
        let s = summary(&runs);
        assert!(s.contains("baseline median 3.000 s (fastest 2.000 s)"), "{s}");
        assert!(s.contains("candidate median 1.500 s (fastest 1.000 s)"), "{s}");
        assert!(s.contains("= 0.500 by the medians, 0.500 by the fastest runs"), "{s}");
        let csv = ab_csv(&runs);
        assert_eq!(csv.lines().count(), 7);
        assert_eq!(csv.lines().nth(2).unwrap(), "1,candidate,0,1.0000,0.50,0.60");
    }

    /// Both builds run the command with `{out}` replaced, alternately; a missing build is refused by its flag.
    #[test]
    fn both_builds_run_alternately_and_a_missing_build_is_refused_by_its_flag() {
        let dir = std::env::temp_dir().join(format!("rubblepile-bench-ab-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let sh = PathBuf::from("/bin/sh");
        let args = BenchAbArgs {
            baseline: sh.clone(),
            candidate: Some(sh),
            repeat: 2,
            out: dir.clone(),
            force: false,
            command: vec!["-c".into(), "mkdir -p {out} && touch {out}/done".into()],
        };
        bench(&args).unwrap();
        let csv = std::fs::read_to_string(dir.join("ab.csv")).unwrap();
        let sides: Vec<&str> = csv.lines().skip(1).map(|l| l.split(',').nth(1).unwrap()).collect();
        assert_eq!(sides, ["baseline", "candidate", "baseline", "candidate"]);
        assert!(dir.join("scratch/candidate_1/done").exists());
        assert!(dir.join("ab.svg").exists());
        // an earlier benchmark is kept unless --force
        let again = bench(&args).unwrap_err().to_string();
        assert!(again.contains("use --force"), "{again}");
        let missing = BenchAbArgs {
            baseline: dir.join("no-such-build"),
            force: true,
            ..args
        };
        let e = bench(&missing).unwrap_err().to_string();
        assert!(e.starts_with("--baseline: expected an executable file"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
