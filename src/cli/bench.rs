//! `rubblepile bench rhs`: the cost of one right-hand-side evaluation, serial and parallel.

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use crate::cli::CliError;
use crate::ellipsoid::body::InertiaModel;
use crate::ellipsoid::equations::{ContactTerm, DissipationTerm, EllipsoidSystem, GravityTerm, ModelConfig, Physics};
use crate::integrate::OdeSystem;
use crate::scene::cloud::{CloudParams, random_cloud};
use crate::scene::{DEFAULT_CONTACT_CUTOFF, SI_G};

/// `rubblepile bench rhs`.
#[derive(Debug, clap::Args)]
pub struct RhsArgs {
    /// Number of ellipsoids (density 3000 kg/m³, equivalent radii 1–5 km, on a jittered cubic
    /// lattice with spacing 1.9 × the mean radius, random attitudes, spins and velocities).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=1_000_000))]
    pub bodies: u64,
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
    /// Write `bench_rhs.csv` (bodies, threads, median_us, min_us, repeats) into this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
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
/// (after one untimed warm-up evaluation).
pub fn time_rhs(system: &EllipsoidSystem, threads: usize, repeats: usize) -> Result<RhsTiming, String> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| format!("cannot build a pool of {threads} threads: {e}"))?;
    let y = system.initial_state();
    let mut dydt = vec![0.0; system.dim()];
    let mut samples = pool.install(|| {
        system.rhs(0.0, &y, &mut dydt);
        (0..repeats)
            .map(|_| {
                let start = Instant::now();
                system.rhs(0.0, std::hint::black_box(&y), &mut dydt);
                std::hint::black_box(&dydt);
                start.elapsed().as_secs_f64() * 1e6
            })
            .collect::<Vec<f64>>()
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

/// The system benchmarked by `bench rhs`: gravity + contact + dissipation (F0 = 1 s/m²).
pub fn bench_system(n: usize, seed: u64, kappa: f64) -> EllipsoidSystem {
    let bodies = random_cloud(n, seed, &CloudParams::default());
    let model = ModelConfig {
        kappa,
        inertia: InertiaModel::Gaussian,
        contact_g: SI_G,
    };
    let physics = Physics {
        gravity: Some(GravityTerm { g: SI_G }),
        contact: Some(ContactTerm {
            cutoff: DEFAULT_CONTACT_CUTOFF,
        }),
        dissipation: Some(DissipationTerm { f0: 1.0 }),
    };
    EllipsoidSystem::new(&bodies, model, physics)
}

/// Runs `bench rhs`.
pub fn rhs(args: &RhsArgs) -> Result<(), CliError> {
    if !(args.kappa.is_finite() && args.kappa > 1.5) {
        return Err(CliError::usage(format!(
            "--kappa: must be > 1.5 and finite, got {}",
            args.kappa
        )));
    }
    let n = args.bodies as usize;
    let repeats = args.repeats as usize;
    let all = match args.threads {
        Some(k) => k as usize,
        None => std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
    };
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir).map_err(|e| CliError::failed(format!("{}: {e}", dir.display())))?;
    }
    let system = bench_system(n, args.seed, args.kappa);
    let mut counts = vec![1];
    if all > 1 {
        counts.push(all);
    }
    println!(
        "bench rhs: {n} bodies, {repeats} repeats, seed {}, kappa {}",
        args.seed, args.kappa
    );
    let mut results = Vec::new();
    for &threads in &counts {
        let r = time_rhs(&system, threads, repeats).map_err(CliError::failed)?;
        println!(
            "  {:>3} thread{}: median {:.1} us per RHS (min {:.1} us)",
            r.threads,
            if r.threads == 1 { " " } else { "s" },
            r.median_us,
            r.min_us
        );
        results.push(r);
    }
    if results.len() == 2 {
        println!(
            "  speed-up {:.2}x on {} threads (median 1 thread / median {} threads)",
            results[0].median_us / results[1].median_us,
            results[1].threads,
            results[1].threads
        );
    }
    if let Some(dir) = &args.out {
        let path = dir.join("bench_rhs.csv");
        let write = || -> std::io::Result<()> {
            let mut f = std::io::BufWriter::new(std::fs::File::create(&path)?);
            writeln!(f, "bodies,threads,median_us,min_us,repeats")?;
            for r in &results {
                writeln!(f, "{n},{},{:e},{:e},{repeats}", r.threads, r.median_us, r.min_us)?;
            }
            f.flush()
        };
        write().map_err(|e| CliError::failed(format!("{}: {e}", path.display())))?;
        println!("  wrote {}", path.display());
    }
    Ok(())
}
