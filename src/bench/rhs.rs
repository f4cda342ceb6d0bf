//! `rubblepile bench rhs`: the cost of one right-hand-side evaluation, serial and parallel, with gravity among
//! centres (Roig03 Eq. 6) summed exactly, by the octree ([`rubblepile::ellipsoid::gravity_tree`]) or left out (the
//! pair work alone), with the pair counts ([`rubblepile::ellipsoid::equations::PairCensus`]) that set the pair work.

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use super::BenchError as CliError;
use rubblepile::driver::warm_pool::with_warm_workers;
use rubblepile::ellipsoid::cloud::{CloudParams, random_cloud};
use rubblepile::ellipsoid::equations::{
    ContactTerm, DissipationTerm, EllipsoidSystem, GravityTerm, ModelConfig, PairCensus, Physics,
};
use rubblepile::ellipsoid::gravity_tree::{GravityMethod, MAX_THETA};
use rubblepile::ellipsoid::scene::DEFAULT_CONTACT_CUTOFF;
use rubblepile::integrate::OdeSystem;
use rubblepile::io::scene_file::SI_G;

/// `rubblepile bench rhs`.
#[derive(Debug, clap::Args)]
pub struct RhsArgs {
    /// Number of ellipsoids (density 3000 kg/m³, equivalent radii 1–5 km, on a jittered cubic
    /// lattice with spacing 1.9 × the mean radius, random attitudes, spins and velocities).
    /// Several sizes may be given, comma-separated (`--bodies 30,200,2000`), to see how the cost scales.
    #[arg(long, value_delimiter = ',', value_parser = clap::value_parser!(u64).range(1..=1_000_000))]
    pub bodies: Vec<u64>,
    /// Relaxed piles to time instead of (or beside) the lattices: target files written by `target build`
    /// (`FILE.csv`, comma-separated), each at the κ of its `FILE.json`, with the same physics as the lattices.
    #[arg(long, value_delimiter = ',', value_name = "FILE.csv")]
    pub targets: Vec<PathBuf>,
    /// Timed evaluations per thread count (the median and minimum are reported).
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u64).range(1..=1_000_000))]
    pub repeats: u64,
    /// Seed of the random cloud.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// κ of the model (dimensionless, > 1.5).
    #[arg(long, default_value_t = 10.0)]
    pub kappa: f64,
    /// Threads of the parallel run (default: all available).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=4096))]
    pub threads: Option<u64>,
    /// Gravity methods to time, comma-separated: `auto` (exact below 5000 bodies, tree from there on),
    /// `direct` (exact pair sum), `tree` (octree at θ = `--theta`, walked afresh at every evaluation, as the
    /// `ode_solvers` methods, Dopri5 and Rk4, use it), `tree-step` (the same octree with its interaction lists fixed
    /// at the timed state, as every evaluation of a Bulirsch–Stoer or Dop853 step sums them; the lists are found
    /// once per step, untimed),
    /// `none` (no gravity: contact and dissipation only, so that the pair work is timed alone).
    #[arg(long, value_delimiter = ',', default_value = "auto", value_parser = ["auto", "direct", "tree", "tree-step", "none"])]
    pub gravity: Vec<String>,
    /// Opening angle θ of the tree (dimensionless, in (0, 1]).
    #[arg(long, default_value_t = rubblepile::ellipsoid::gravity_tree::DEFAULT_THETA)]
    pub theta: f64,
    /// Write `bench_rhs.csv` (bodies, threads, median_us, min_us, repeats, gravity, packing: `lattice` or the
    /// target file's stem, and the pair counts of the timed state: candidate_pairs, interacting_pairs,
    /// touching_pairs) and the plot `bench_rhs.svg` + `bench_rhs.png` (median µs per RHS against N, one line per
    /// thread count and gravity method, lattices and relaxed piles apart) into this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Overwrite `bench_rhs.csv`/`bench_rhs.svg` of an earlier benchmark in DIR.
    #[arg(long)]
    pub force: bool,
}

/// Timing of one thread count.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RhsTiming {
    /// Threads used.
    pub threads: usize,
    /// Median over repeats (µs).
    pub median_us: f64,
    /// Minimum over repeats (µs).
    pub min_us: f64,
}

/// Times `repeats` RHS evaluations of `system` at its initial state on a pool of `threads` threads
/// (after one untimed warm-up evaluation). With `step_lists`, the evaluations are those of one Bulirsch–Stoer
/// step: [`OdeSystem::begin_step`] is called first (untimed), so tree gravity sums the step's frozen lists.
pub fn time_rhs(
    system: &EllipsoidSystem,
    threads: usize,
    repeats: usize,
    step_lists: bool,
) -> Result<RhsTiming, crate::bench::BenchError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| format!("cannot build a pool of {threads} threads: {e}"))?;
    let y = system.initial_state();
    let mut dydt = vec![0.0; system.dim()];
    // Timed as a run evaluates it: on a pool whose other workers are kept polling (`with_warm_workers`).
    let mut samples = pool.install(|| {
        with_warm_workers(|| {
            if step_lists {
                system.begin_step(0.0, &y);
            }
            system.rhs(0.0, &y, &mut dydt);
            let samples = (0..repeats)
                .map(|_| {
                    let start = Instant::now();
                    system.rhs(0.0, std::hint::black_box(&y), &mut dydt);
                    std::hint::black_box(&dydt);
                    start.elapsed().as_secs_f64() * 1e6
                })
                .collect::<Vec<f64>>();
            system.end_steps();
            samples
        })
    });
    samples.sort_by(f64::total_cmp);
    let n = samples.len();
    let median = if n % 2 == 1 {
        samples[n / 2]
    } else {
        0.5 * (samples[n / 2 - 1] + samples[n / 2])
    };
    Ok(RhsTiming {
        threads,
        median_us: median,
        min_us: samples[0],
    })
}

fn lattice_system(n: usize, seed: u64, kappa: f64, method: Option<GravityMethod>) -> EllipsoidSystem {
    let bodies = random_cloud(n, seed, &CloudParams::default());
    EllipsoidSystem::new(&bodies, ModelConfig::gaussian_si(kappa), bench_physics(method))
}

/// The physics of every `bench rhs` system: gravity by `method` (`None`: no gravity), contact, dissipation
/// (F0 = 1 s/m²).
pub fn bench_physics(method: Option<GravityMethod>) -> Physics {
    Physics {
        gravity: method.map(|method| GravityTerm { g: SI_G, method }),
        contact: Some(ContactTerm {
            cutoff: DEFAULT_CONTACT_CUTOFF,
        }),
        dissipation: Some(DissipationTerm { f0: 1.0 }),
    }
}

/// What one benchmark row times: a lattice of N bodies, or a relaxed pile read from a target file.
enum Packing {
    /// [`lattice_system`]'s jittered lattice.
    Lattice(usize),
    /// A target's bodies at its κ, labelled by the file's stem.
    Pile(String, Vec<rubblepile::ellipsoid::body::Body>, f64),
}

/// Reads a target file and the κ of its `FILE.json` report.
fn read_pile(path: &std::path::Path) -> Result<Packing, CliError> {
    let bodies = rubblepile::impact::run::read_target(path).map_err(|e| CliError::usage(format!("--targets: {e}")))?;
    let json = path.with_extension("json");
    let text = std::fs::read_to_string(&json)
        .map_err(|e| CliError::usage(format!("--targets: {} ({e}); κ is read from it", json.display())))?;
    let report: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| CliError::usage(format!("--targets: {}: {e}", json.display())))?;
    let kappa = report["kappa"]
        .as_f64()
        .filter(|k| k.is_finite() && *k > 1.5)
        .ok_or_else(|| CliError::usage(format!("--targets: {}: expected a number kappa > 1.5", json.display())))?;
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(Packing::Pile(stem, bodies, kappa))
}

/// Runs `bench rhs`.
pub fn rhs(args: &RhsArgs) -> Result<(), CliError> {
    if args.bodies.is_empty() && args.targets.is_empty() {
        return Err(CliError::usage(
            "--bodies or --targets: give at least one lattice size or one target file".to_string(),
        ));
    }
    if !(args.kappa.is_finite() && args.kappa > 1.5) {
        return Err(CliError::usage(format!(
            "--kappa: must be > 1.5 and finite, got {}",
            args.kappa
        )));
    }
    if !(args.theta > 0.0 && args.theta <= MAX_THETA) {
        return Err(CliError::usage(format!(
            "--theta: must be in (0, 1], got {}",
            args.theta
        )));
    }
    let repeats = args.repeats as usize;
    let all = match args.threads {
        Some(k) => k as usize,
        None => std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
    };
    let paths = args.out.as_ref().map(|dir| {
        (
            dir.join("bench_rhs.csv"),
            dir.join("bench_rhs.svg"),
            dir.join("bench_rhs.png"),
        )
    });
    if let (Some(dir), Some((csv, svg, png))) = (&args.out, &paths) {
        if !args.force && (csv.exists() || svg.exists() || png.exists()) {
            return Err(CliError::usage(format!(
                "--out: {} already holds a benchmark; use --force to overwrite it",
                dir.display()
            )));
        }
        std::fs::create_dir_all(dir).map_err(|e| CliError::failed(format!("{}: {e}", dir.display())))?;
    }
    let mut counts = vec![1];
    if all > 1 {
        counts.push(all);
    }
    let mut packings: Vec<Packing> = args.bodies.iter().map(|&n| Packing::Lattice(n as usize)).collect();
    for path in &args.targets {
        packings.push(read_pile(path)?);
    }
    // (bodies, timing, gravity method, packing: "lattice" or the target's stem, pair counts)
    let mut results: Vec<(usize, RhsTiming, String, String, PairCensus)> = Vec::new();
    for (packing, gravity) in packings.iter().flat_map(|p| args.gravity.iter().map(move |g| (p, g))) {
        let theta = args.theta;
        let method = match gravity.as_str() {
            "direct" => Some(GravityMethod::Direct),
            "tree" | "tree-step" => Some(GravityMethod::Tree { theta }),
            "none" => None,
            _ => Some(GravityMethod::Auto { theta }),
        };
        let (system, name, kappa) = match packing {
            Packing::Lattice(n) => (lattice_system(*n, args.seed, args.kappa, method), "lattice", args.kappa),
            Packing::Pile(stem, bodies, kappa) => (
                EllipsoidSystem::new(bodies, ModelConfig::gaussian_si(*kappa), bench_physics(method)),
                stem.as_str(),
                *kappa,
            ),
        };
        let n = system.n_bodies();
        let census = system.pair_census(&system.initial_state());
        println!(
            "bench rhs: {n} bodies ({name}), gravity {gravity} ({}), {repeats} repeats, seed {}, kappa {kappa}",
            match method {
                None => "none",
                Some(m) if m.tree_theta(n).is_some() => "tree",
                Some(_) => "exact",
            },
            args.seed,
        );
        println!(
            "  pairs: {} candidates, {} interacting ({:.1} per body), {} touching",
            census.candidates,
            census.interacting,
            2.0 * census.interacting as f64 / n.max(1) as f64,
            census.touching
        );
        let mut row = Vec::new();
        for &threads in &counts {
            let r = time_rhs(&system, threads, repeats, gravity == "tree-step").map_err(CliError::failed)?;
            println!(
                "  {:>3} thread{}: median {:.1} us per RHS (min {:.1} us)",
                r.threads,
                if r.threads == 1 { " " } else { "s" },
                r.median_us,
                r.min_us
            );
            row.push(r);
        }
        if row.len() == 2 {
            println!(
                "  speed-up {:.2}x on {} threads (median 1 thread / median {} threads)",
                row[0].median_us / row[1].median_us,
                row[1].threads,
                row[1].threads
            );
        }
        results.extend(
            row.into_iter()
                .map(|r| (n, r, gravity.clone(), name.to_string(), census)),
        );
    }
    if let Some((csv, svg, png)) = &paths {
        let write = || -> std::io::Result<()> {
            let mut f = std::io::BufWriter::new(std::fs::File::create(csv)?);
            writeln!(
                f,
                "bodies,threads,median_us,min_us,repeats,gravity,packing,candidate_pairs,interacting_pairs,touching_pairs"
            )?;
            for (n, r, g, p, c) in &results {
                writeln!(
                    f,
                    "{n},{},{:e},{:e},{repeats},{g},{p},{},{},{}",
                    r.threads, r.median_us, r.min_us, c.candidates, c.interacting, c.touching
                )?;
            }
            f.flush()
        };
        write().map_err(|e| CliError::failed(format!("{}: {e}", csv.display())))?;
        // one line per (threads, gravity) over the lattices, and one over the relaxed piles
        let labelled: Vec<(usize, RhsTiming, String)> = results
            .iter()
            .map(|(n, r, g, p, _)| {
                (
                    *n,
                    *r,
                    if p == "lattice" {
                        g.clone()
                    } else {
                        format!("{g}, relaxed piles")
                    },
                )
            })
            .collect();
        let mut lines: Vec<(usize, String)> = Vec::new();
        for (_, r, label) in &labelled {
            if !lines.contains(&(r.threads, label.clone())) {
                lines.push((r.threads, label.clone()));
            }
        }
        let results = labelled;
        {
            use plotters::prelude::*;
            let svg_root = SVGBackend::new(svg, (720, 480)).into_drawing_area();
            plot_rhs(&svg_root, &results, &lines).map_err(|e| CliError::failed(format!("{}: {e}", svg.display())))?;
            let png_root = BitMapBackend::new(png, (720, 480)).into_drawing_area();
            plot_rhs(&png_root, &results, &lines).map_err(|e| CliError::failed(format!("{}: {e}", png.display())))?;
        }
        println!("  wrote {}, {} and {}", csv.display(), svg.display(), png.display());
    }
    Ok(())
}

/// Log–log plot of the median µs per RHS against the number of bodies, one line per (thread count, gravity
/// method) in `lines`.
fn plot_rhs<DB: plotters::prelude::DrawingBackend>(
    root: &plotters::prelude::DrawingArea<DB, plotters::coord::Shift>,
    results: &[(usize, RhsTiming, String)],
    lines: &[(usize, String)],
) -> Result<(), String> {
    use plotters::prelude::*;
    use rubblepile::analysis::figures::style;
    let err = |e: &dyn std::fmt::Display| e.to_string();
    // plotters measures (and, in PNGs, draws) text with the font the figures embed; it must be registered first
    style::ensure_font()?;
    let (mut n_lo, mut n_hi) = (f64::INFINITY, 0.0_f64);
    let (mut t_lo, mut t_hi) = (f64::INFINITY, 0.0_f64);
    for (n, r, _) in results {
        n_lo = n_lo.min(*n as f64);
        n_hi = n_hi.max(*n as f64);
        t_lo = t_lo.min(r.median_us);
        t_hi = t_hi.max(r.median_us);
    }
    let mut sizes: Vec<f64> = results.iter().map(|(n, _, _)| *n as f64).collect();
    sizes.sort_by(f64::total_cmp);
    let sizes = style::spread_on_log_axis(&sizes, 1.15);
    let (y_lo, y_hi) = (t_lo * 0.5, t_hi * 2.0);
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut chart = ChartBuilder::on(root)
        .caption("rubblepile bench rhs: cost of one right-hand side", ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(
            // The x ticks are the benchmarked N: plotters' own log ticks overlap from 1000 to 10 000 and vanish
            // over less than a decade.
            // N that differ by less than 15 % (a lattice of 2000 and a pile of 2001) share one tick.
            (n_lo * 0.8..n_hi * 1.25).log_scale().with_key_points(sizes),
            (y_lo..y_hi)
                .log_scale()
                .with_key_points(style::log_key_points(y_lo, y_hi)),
        )
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_label_formatter(&|n| format!("{n:.0}"))
        .y_label_formatter(&|t| {
            if *t >= 1.0 {
                format!("{t:.0}")
            } else {
                style::log_tick(t)
            }
        })
        .x_desc("number of bodies N")
        .y_desc("median time per RHS (µs)")
        .draw()
        .map_err(|e| err(&e))?;
    for (k, (threads, gravity)) in lines.iter().enumerate() {
        let (threads, color) = (*threads, Palette99::pick(k).to_rgba());
        let points: Vec<(f64, f64)> = results
            .iter()
            .filter(|(_, r, g)| r.threads == threads && g == gravity)
            .map(|(n, r, _)| (*n as f64, r.median_us))
            .collect();
        chart
            .draw_series(LineSeries::new(points.clone(), color.stroke_width(2)))
            .map_err(|e| err(&e))?
            .label(format!(
                "{threads} thread{}, gravity {gravity}",
                if threads == 1 { "" } else { "s" }
            ))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
        chart
            .draw_series(points.into_iter().map(|p| Circle::new(p, 3, color.filled())))
            .map_err(|e| err(&e))?;
    }
    // Upper left: the costs grow with N, so that corner is free of data.
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))
}
