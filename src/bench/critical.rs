//! `rubblepile bench critical`: the wall time of a T_c,3 search's holds (Zhang17 §3.3.3) run one after another
//! (`spinup critical --parallel 1`, every thread on each hold) and several at once (`--parallel P`, the threads
//! shared), both in one invocation on one prepared base run, with the check that their `critical.csv` are the same.
//!
//! The base run and the branches are made once (`--prepare-only`) and copied for every setting, so the timings are
//! of the holds alone: the part `--parallel` can speed up. The load average before and after is printed and written
//! beside the times; a figure taken beside other jobs is not a result.

use std::path::{Path, PathBuf};
use std::time::Instant;

use super::BenchError;
use rubblepile::experiment::critical_search::{CriticalOptions, critical};

/// `rubblepile bench critical`.
#[derive(Debug, clap::Args)]
pub struct BenchCriticalArgs {
    /// Soft-sphere spin-up scene (a path without rests), e.g. the 3k HCP of `analysis/zhang2017/decide/`.
    #[arg(long, value_name = "SCENE.toml")]
    pub scene: PathBuf,
    /// First T_final (hours).
    #[arg(long = "from-h")]
    pub from: f64,
    /// Last T_final (hours).
    #[arg(long = "to-h")]
    pub to: f64,
    /// Step of T_final (hours).
    #[arg(long = "step-h", default_value_t = 0.05)]
    pub step: f64,
    /// Length of each hold (simulated seconds).
    #[arg(long = "hold-s", default_value_t = 4000.0)]
    pub hold: f64,
    /// Holds at once to compare with one at a time (comma-separated; 1 is always timed first).
    #[arg(long, default_value = "2", value_delimiter = ',')]
    pub parallel: Vec<usize>,
    /// Write `bench_critical.csv` and `bench_critical.svg` here, and the searches under `DIR/searches/`.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Overwrite an earlier benchmark in DIR.
    #[arg(long)]
    pub force: bool,
    /// Reuse the base run and branches an earlier benchmark of the same scene and grid left in
    /// `DIR/searches/prepared` (so that the timed part alone needs the quiet machine).
    #[arg(long)]
    pub reuse_prepared: bool,
    /// Also time the holds one at a time on a single thread each (`--parallel 1 --threads-per-hold 1`): the
    /// baseline that shows how much of `--parallel`'s gain the threads of one hold already take.
    #[arg(long)]
    pub single_thread: bool,
}

/// The 1-minute load average, from `/proc/loadavg` (NaN where there is none).
pub fn load_average() -> f64 {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().and_then(|x| x.parse().ok()))
        .unwrap_or(f64::NAN)
}

fn copy_dir(from: &Path, to: &Path) -> Result<(), String> {
    std::fs::create_dir_all(to).map_err(|e| format!("{}: {e}", to.display()))?;
    for entry in std::fs::read_dir(from).map_err(|e| format!("{}: {e}", from.display()))? {
        let entry = entry.map_err(|e| e.to_string())?;
        let (src, dst) = (entry.path(), to.join(entry.file_name()));
        if src.is_dir() {
            copy_dir(&src, &dst)?;
        } else {
            std::fs::copy(&src, &dst).map_err(|e| format!("{}: {e}", src.display()))?;
        }
    }
    Ok(())
}

/// One timed setting: holds at once, threads per hold, wall seconds, load before and after.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timing {
    /// Holds at once.
    pub parallel: usize,
    /// Threads of each hold.
    pub threads_per_hold: usize,
    /// Wall time of the holds (s).
    pub wall_s: f64,
    /// 1-minute load average before.
    pub load_before: f64,
    /// After.
    pub load_after: f64,
}

/// `rubblepile bench critical`.
pub fn bench(args: &BenchCriticalArgs) -> Result<(), BenchError> {
    if args.parallel.contains(&0) {
        return Err(BenchError::usage("--parallel: each count must be >= 1, got 0"));
    }
    let csv_path = args.out.join("bench_critical.csv");
    if csv_path.exists() && !args.force {
        return Err(BenchError::usage(format!(
            "{} exists; use --force to overwrite it",
            csv_path.display()
        )));
    }
    let searches = args.out.join("searches");
    let prepared = searches.join("prepared");
    let reuse = args.reuse_prepared && prepared.join("base").is_dir();
    if searches.exists() {
        for entry in std::fs::read_dir(&searches).map_err(|e| BenchError::failed(e.to_string()))? {
            let path = entry.map_err(|e| BenchError::failed(e.to_string()))?.path();
            if !(reuse && path == prepared) {
                std::fs::remove_dir_all(&path).map_err(|e| BenchError::failed(format!("{}: {e}", path.display())))?;
            }
        }
    }
    let options = |out: PathBuf| CriticalOptions {
        branch: true,
        hold: Some(args.hold),
        all_holds: true,
        force: true,
        ..CriticalOptions::new(args.scene.clone(), args.from, args.to, args.step, out)
    };
    let started = Instant::now();
    critical(&CriticalOptions {
        prepare_only: true,
        ..options(prepared.clone())
    })
    .map_err(|e| BenchError::usage(e.to_string()))?;
    println!(
        "base run and branches{}: {:.1} s",
        if reuse { " (reused)" } else { "" },
        started.elapsed().as_secs_f64()
    );
    let threads = rayon::current_num_threads();
    // (holds at once, threads per hold): one at a time on every thread first (the speed-up's reference)
    let mut settings = vec![(1, threads)];
    if args.single_thread && threads > 1 {
        settings.push((1, 1));
    }
    settings.extend(
        args.parallel
            .iter()
            .filter(|&&p| p != 1)
            .map(|&p| (p, (threads / p).max(1))),
    );
    let mut rows = Vec::new();
    let mut reference: Option<String> = None;
    for (p, threads_per_hold) in settings {
        let dir = if p == 1 && threads_per_hold != threads {
            searches.join(format!("parallel1_threads{threads_per_hold}"))
        } else {
            searches.join(format!("parallel{p}"))
        };
        copy_dir(&prepared, &dir)?;
        let load_before = load_average();
        let t0 = Instant::now();
        critical(&CriticalOptions {
            parallel: p,
            threads_per_hold: Some(threads_per_hold),
            ..options(dir.clone())
        })
        .map_err(|e| BenchError::failed(e.to_string()))?;
        let wall_s = t0.elapsed().as_secs_f64();
        let load_after = load_average();
        let csv = std::fs::read_to_string(dir.join("critical.csv")).map_err(|e| BenchError::failed(e.to_string()))?;
        match &reference {
            None => reference = Some(csv),
            Some(r) if *r != csv => {
                return Err(BenchError::failed(format!(
                    "--parallel {p} with {threads_per_hold} thread(s) per hold judged the holds differently from \
                     --parallel 1 ({})",
                    dir.display()
                )));
            }
            _ => {}
        }
        println!(
            "parallel {p} x {threads_per_hold} thread(s): holds {wall_s:.1} s (load {load_before:.2} before, \
             {load_after:.2} after)"
        );
        rows.push(Timing {
            parallel: p,
            threads_per_hold,
            wall_s,
            load_before,
            load_after,
        });
    }
    let base = rows[0].wall_s;
    let mut text = String::from("parallel,threads_per_hold,holds_wall_s,speedup,load_before,load_after\n");
    for r in &rows {
        text += &format!(
            "{},{},{:.3},{:.4},{:.2},{:.2}\n",
            r.parallel,
            r.threads_per_hold,
            r.wall_s,
            base / r.wall_s,
            r.load_before,
            r.load_after
        );
        if r.parallel != 1 || r.threads_per_hold != threads {
            println!(
                "speed-up of --parallel {} x {} thread(s): {:.3}x",
                r.parallel,
                r.threads_per_hold,
                base / r.wall_s
            );
        }
    }
    rubblepile::io::safe_write::write_atomic(&csv_path, text)
        .map_err(|e| BenchError::failed(format!("{}: {e}", csv_path.display())))?;
    plot(&args.out.join("bench_critical.svg"), &rows).map_err(BenchError::failed)?;
    println!("wrote {}", csv_path.display());
    Ok(())
}

fn plot(path: &Path, rows: &[Timing]) -> Result<(), String> {
    use plotters::prelude::*;
    rubblepile::analysis::figures::style::ensure_font()?;
    let root = SVGBackend::new(path, (640, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let max_x = rows.len() as f64 + 0.5;
    let max_w = rows.iter().map(|r| r.wall_s).fold(0.0, f64::max) * 1.2;
    let mut chart = ChartBuilder::on(&root)
        .caption("T_c3 search: wall time of the holds", ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(70)
        .build_cartesian_2d(0.5..max_x, 0.0..max_w.max(1.0))
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc("holds at once x threads per hold")
        .x_labels(rows.len() + 1)
        .x_label_formatter(&|x| {
            let i = x.round() as usize;
            match rows.get(i.wrapping_sub(1)) {
                Some(r) if (x - i as f64).abs() < 1e-9 => format!("{} x {}", r.parallel, r.threads_per_hold),
                _ => String::new(),
            }
        })
        .y_desc("wall time of the holds (s)")
        .draw()
        .map_err(|e| e.to_string())?;
    chart
        .draw_series(rows.iter().enumerate().map(|(i, r)| {
            let x = (i + 1) as f64;
            Rectangle::new([(x - 0.3, 0.0), (x + 0.3, r.wall_s)], BLUE.filled())
        }))
        .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())
}
