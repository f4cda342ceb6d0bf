//! `rubblepile bench memory`: bytes per grain or body of the soft-sphere engine (an FCC ball of loaded contacts, as
//! `bench ssdem` builds it) and of the ellipsoid engine (a committed target under Bulirsch–Stoer), each case in a
//! child process of its own so that its peak resident set (`VmHWM` of `/proc/self/status`, Linux) is its own: the
//! peak less the process's resident set before the case was built, per body, beside the engine's own count of
//! what it holds between steps ([`rubblepile::granular::soft::forces::SoftSystem::heap_bytes`]; for ellipsoids the
//! state vector and the integrator are not itemised, only the peak).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use super::BenchError;
use rubblepile::granular::soft::run::checked_step;
use rubblepile::gravity::SelfGravity;
use rubblepile::integrate::{Method, Tolerances, make_integrator};

/// `rubblepile bench memory`.
#[derive(Debug, clap::Args)]
pub struct BenchMemoryArgs {
    /// Soft-sphere grain counts (comma-separated; each case an FCC ball of 1 m spheres, as `bench ssdem`).
    #[arg(long, default_value = "10000,100000,1000000", value_delimiter = ',', value_parser = clap::value_parser!(u64).range(2..=10_000_000))]
    pub particles: Vec<u64>,
    /// Self-gravity of the soft-sphere cases: `off` or `tree` (θ = 0.5; its octree is rebuilt at every evaluation).
    #[arg(long, default_value = "tree", value_parser = ["off", "tree"])]
    pub gravity: String,
    /// Ellipsoid targets (comma-separated bodies files with their `.json` beside them giving κ; `--targets` with
    /// no value for none).
    #[arg(long, default_value = "targets/N10000_T4.csv", value_delimiter = ',', num_args = 0..)]
    pub targets: Vec<PathBuf>,
    /// Leapfrog steps per soft-sphere case (an ellipsoid case advances 0.01 s under Bulirsch–Stoer).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub steps: u64,
    /// Write `bench_memory.csv` and `bench_memory.svg` here.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Overwrite an earlier benchmark's files in DIR.
    #[arg(long)]
    pub force: bool,
    /// Internal: run one case in this process (`soft:N` or `ellipsoids:FILE`) and print its line.
    #[arg(long, hide = true, value_name = "CASE")]
    pub child: Option<String>,
}

/// The columns of `bench_memory.csv`.
const CSV_COLUMNS: [&str; 10] = [
    "engine",
    "bodies",
    "baseline_rss_bytes",
    "peak_rss_bytes",
    "peak_bytes_per_body",
    "engine_bytes",
    "engine_bytes_per_body",
    "contacts",
    "steps",
    "step_seconds",
];

/// One case's figures.
#[derive(Debug, Clone, PartialEq)]
struct Case {
    engine: String,
    bodies: usize,
    /// Resident set before the case was built (bytes).
    baseline: u64,
    /// Peak resident set of the process (bytes).
    peak: u64,
    /// The engine's own count (bytes), when it keeps one.
    engine_bytes: Option<u64>,
    /// Pair contacts at the end (soft spheres).
    contacts: Option<usize>,
    /// Wall time of the steps (s).
    seconds: f64,
}

impl Case {
    fn per_body_peak(&self) -> f64 {
        self.peak.saturating_sub(self.baseline) as f64 / self.bodies as f64
    }

    fn per_body_engine(&self) -> Option<f64> {
        self.engine_bytes.map(|b| b as f64 / self.bodies as f64)
    }

    /// The line a child prints and its parent reads back (tab-separated: an engine's name has spaces).
    fn to_line(&self) -> String {
        let opt = |x: Option<u64>| x.map_or("-".to_string(), |x| x.to_string());
        format!(
            "MEMORY\t{}\t{}\t{}\t{}\t{}\t{}\t{}",
            self.engine,
            self.bodies,
            self.baseline,
            self.peak,
            opt(self.engine_bytes),
            opt(self.contacts.map(|c| c as u64)),
            self.seconds
        )
    }

    fn from_line(line: &str) -> Option<Case> {
        let w: Vec<&str> = line.strip_prefix("MEMORY\t")?.split('\t').collect();
        let opt = |s: &str| if s == "-" { Some(None) } else { s.parse().ok().map(Some) };
        (w.len() == 7).then_some(())?;
        Some(Case {
            engine: w[0].to_string(),
            bodies: w[1].parse().ok()?,
            baseline: w[2].parse().ok()?,
            peak: w[3].parse().ok()?,
            engine_bytes: opt(w[4])?,
            contacts: opt(w[5])?.map(|c: u64| c as usize),
            seconds: w[6].parse().ok()?,
        })
    }
}

/// A field of `/proc/self/status` in bytes (`VmRSS`, `VmHWM`; the file gives kB).
fn status_bytes(field: &str) -> Result<u64, BenchError> {
    let text = std::fs::read_to_string("/proc/self/status")
        .map_err(|e| BenchError::failed(format!("/proc/self/status (bench memory needs Linux): {e}")))?;
    text.lines()
        .find_map(|l| l.strip_prefix(field)?.strip_prefix(':'))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .map(|kb| kb * 1024)
        .ok_or_else(|| BenchError::failed(format!("/proc/self/status has no {field}")))
}

/// Runs one case in this process.
fn run_case(case: &str, gravity: &str, steps: u64) -> Result<Case, BenchError> {
    let baseline = status_bytes("VmRSS")?;
    if let Some(n) = case.strip_prefix("soft:") {
        let n: usize = n
            .parse()
            .map_err(|_| BenchError::usage(format!("--child: bad count in {case:?}")))?;
        let g = (gravity == "tree").then_some(SelfGravity::Tree { theta: 0.5 });
        let mut sys = super::ssdem::bench_system(n, g, 1);
        let dt = std::f64::consts::PI * (0.5 * sys.particles[0].mass / sys.material.k_n).sqrt() / 50.0;
        // A run keeps the state before each step (for `last_good_state.csv`): so does the case.
        let mut before = Vec::new();
        let start = Instant::now();
        for k in 0..steps {
            checked_step(&mut sys, &mut before, k, dt, |_, _| ()).map_err(BenchError::failed)?;
        }
        let seconds = start.elapsed().as_secs_f64();
        let engine = sys.heap_bytes() + rubblepile::math::vec_bytes(&before);
        return Ok(Case {
            engine: format!("soft-spheres (gravity {gravity})"),
            bodies: n,
            baseline,
            peak: status_bytes("VmHWM")?,
            engine_bytes: Some(engine as u64),
            contacts: Some(sys.stats.pair_contacts),
            seconds,
        });
    }
    let path = case
        .strip_prefix("ellipsoids:")
        .ok_or_else(|| BenchError::usage(format!("--child: expected soft:N or ellipsoids:FILE, got {case:?}")))?;
    let system = super::scaling::pile_system(
        Path::new(path),
        rubblepile::ellipsoid::gravity_tree::GravityMethod::Tree { theta: 0.5 },
    )?;
    let mut y = system.initial_state();
    let tolerances = Tolerances::scale_free(1e-6, 1e-6, &system);
    let mut bs =
        make_integrator(Method::BulirschStoer, tolerances, None).map_err(|e| BenchError::failed(e.to_string()))?;
    let mut t = 0.0;
    let start = Instant::now();
    // One advance over a short span: the system, its candidate pairs and the extrapolation tableau are all built,
    // which is what a run holds; how many steps that takes does not change it.
    bs.advance(&system, &mut t, &mut y, 1e-2)
        .map_err(|e| BenchError::failed(format!("{path}: {e}")))?;
    Ok(Case {
        engine: "ellipsoids (tree)".into(),
        bodies: system.n_bodies(),
        baseline,
        peak: status_bytes("VmHWM")?,
        engine_bytes: None,
        contacts: None,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// `rubblepile bench memory`: each case in a child process, then the table (and the CSV and SVG in `--out`).
pub fn bench(args: &BenchMemoryArgs) -> Result<(), BenchError> {
    if let Some(case) = &args.child {
        println!("{}", run_case(case, &args.gravity, args.steps)?.to_line());
        return Ok(());
    }
    if let Some(dir) = &args.out {
        let csv = dir.join("bench_memory.csv");
        if csv.exists() && !args.force {
            return Err(BenchError::usage(format!(
                "{} exists; use --force to overwrite it",
                csv.display()
            )));
        }
    }
    let exe = std::env::current_exe().map_err(|e| BenchError::failed(format!("cannot find this program: {e}")))?;
    let cases = args
        .particles
        .iter()
        .map(|n| format!("soft:{n}"))
        .chain(args.targets.iter().map(|p| format!("ellipsoids:{}", p.display())));
    println!(
        "engine | bodies | peak RSS less baseline per body (B) | engine's own count per body (B) | contacts | steps (s)"
    );
    let mut rows = Vec::new();
    for case in cases {
        let out = Command::new(&exe)
            .args(["bench", "memory", "--child", &case, "--gravity", &args.gravity])
            .args(["--steps", &args.steps.to_string()])
            .output()
            .map_err(|e| BenchError::failed(format!("{case}: cannot start {}: {e}", exe.display())))?;
        let stdout = String::from_utf8_lossy(&out.stdout);
        let row = stdout.lines().find_map(Case::from_line).ok_or_else(|| {
            let err = String::from_utf8_lossy(&out.stderr);
            BenchError::failed(format!("{case}: the child printed no result ({})", err.trim()))
        })?;
        println!(
            "{} | {} | {:.0} | {} | {} | {:.2}",
            row.engine,
            row.bodies,
            row.per_body_peak(),
            row.per_body_engine().map_or("-".into(), |b| format!("{b:.0}")),
            row.contacts.map_or("-".into(), |c| c.to_string()),
            row.seconds
        );
        rows.push(row);
    }
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir).map_err(|e| BenchError::failed(format!("{}: {e}", dir.display())))?;
        let csv = dir.join("bench_memory.csv");
        let fail = |e: &dyn std::fmt::Display| BenchError::failed(format!("{}: {e}", csv.display()));
        let mut w = csv::Writer::from_path(&csv).map_err(|e| fail(&e))?;
        w.write_record(CSV_COLUMNS).map_err(|e| fail(&e))?;
        for r in &rows {
            let blank = |x: Option<String>| x.unwrap_or_default();
            w.write_record([
                r.engine.clone(),
                r.bodies.to_string(),
                r.baseline.to_string(),
                r.peak.to_string(),
                format!("{:.1}", r.per_body_peak()),
                blank(r.engine_bytes.map(|b| b.to_string())),
                blank(r.per_body_engine().map(|b| format!("{b:.1}"))),
                blank(r.contacts.map(|c| c.to_string())),
                args.steps.to_string(),
                format!("{:.3}", r.seconds),
            ])
            .map_err(|e| fail(&e))?;
        }
        w.flush().map_err(|e| fail(&e))?;
        plot(&dir.join("bench_memory.svg"), &rows).map_err(BenchError::failed)?;
        println!("wrote {} and bench_memory.svg", csv.display());
    }
    Ok(())
}

/// Bytes per body against bodies (log–log): peak RSS and the engine's count per engine, and the 1 kB line.
fn plot(path: &Path, rows: &[Case]) -> Result<(), String> {
    use plotters::prelude::*;
    let err = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    // plotters measures text with the embedded font (its ab_glyph feature): register it first
    rubblepile::analysis::figures::style::ensure_font()?;
    let root = SVGBackend::new(path, (800, 500)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let n_max = rows.iter().map(|r| r.bodies).max().unwrap_or(10) as f64 * 2.0;
    let b_max = rows.iter().map(Case::per_body_peak).fold(2048.0, f64::max) * 2.0;
    let mut chart = ChartBuilder::on(&root)
        .caption("bytes per body (rubblepile bench memory)", ("sans-serif", 20))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((1e3..n_max).log_scale(), (10.0..b_max).log_scale())
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc("bodies")
        .y_desc("bytes per body")
        .draw()
        .map_err(|e| err(&e))?;
    chart
        .draw_series(LineSeries::new([(1e3, 1024.0), (n_max, 1024.0)], BLACK.mix(0.4)))
        .map_err(|e| err(&e))?
        .label("1 kB");
    let engines: Vec<String> = rows.iter().fold(Vec::new(), |mut v, r| {
        if !v.contains(&r.engine) {
            v.push(r.engine.clone());
        }
        v
    });
    for (k, e) in engines.iter().enumerate() {
        let colour = Palette99::pick(k).to_rgba();
        let mine: Vec<&Case> = rows.iter().filter(|r| &r.engine == e).collect();
        let peak: Vec<(f64, f64)> = mine.iter().map(|r| (r.bodies as f64, r.per_body_peak())).collect();
        chart
            .draw_series(LineSeries::new(peak.clone(), colour.stroke_width(2)))
            .map_err(|e| err(&e))?
            .label(format!("{e}: peak RSS"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
        chart
            .draw_series(peak.iter().map(|&p| Circle::new(p, 4, colour.filled())))
            .map_err(|e| err(&e))?;
        let own: Vec<(f64, f64)> = mine
            .iter()
            .filter_map(|r| Some((r.bodies as f64, r.per_body_engine()?)))
            .collect();
        if !own.is_empty() {
            chart
                .draw_series(own.iter().map(|&p| TriangleMarker::new(p, 6, colour.filled())))
                .map_err(|e| err(&e))?
                .label(format!("{e}: engine's count"))
                .legend(move |(x, y)| TriangleMarker::new((x + 10, y), 6, colour.filled()));
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Guards the line a child prints and its parent reads: every field survives, `-` for a count not kept.
    #[test]
    fn a_case_line_reads_back_as_written() {
        let c = Case {
            engine: "soft-spheres (gravity tree)".into(),
            bodies: 1000,
            baseline: 10 << 20,
            peak: 12 << 20,
            engine_bytes: None,
            contacts: Some(5800),
            seconds: 0.25,
        };
        assert_eq!(Case::from_line(&c.to_line()), Some(c.clone()));
        assert_eq!(c.per_body_peak(), (2 << 20) as f64 / 1000.0);
    }

    /// Guards the engine's own count: it holds at least the spheres, their forces and torques and one list entry
    /// (a `u32` partner) per touching pair, and stays within 4 kB per sphere on a 20 000-sphere ball.
    #[test]
    fn the_soft_engine_count_holds_the_spheres_and_their_pairs() {
        let mut sys = super::super::ssdem::bench_system(20_000, None, 1);
        let dt = std::f64::consts::PI * (0.5 * sys.particles[0].mass / sys.material.k_n).sqrt() / 50.0;
        let mut keep = Vec::new();
        checked_step(&mut sys, &mut keep, 0, dt, |_, _| ()).unwrap();
        let n = sys.particles.len();
        let floor = n * (std::mem::size_of_val(&sys.particles[0]) + 2 * std::mem::size_of::<rubblepile::math::Vec3>())
            + sys.stats.pair_contacts * std::mem::size_of::<u32>();
        let count = sys.heap_bytes();
        assert!(sys.stats.pair_contacts > 5 * n, "{} contacts", sys.stats.pair_contacts);
        assert!(count >= floor, "{count} < {floor}");
        assert!(count <= 4096 * n, "{count} > 4 kB per sphere");
    }
}
