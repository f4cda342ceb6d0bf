//! `rubblepile bench scaling`: strong scaling of every engine on one node, in one invocation: each case is timed at
//! 1, 2, 4, … threads (or a given list) in the same process, and reported with its speed-up `S(p) = T(1)/T(p)`, its
//! parallel efficiency `S(p)/p`, and the Karp–Flatt serial fraction `e(p) = (1/S − 1/p)/(1 − 1/p)` (Karp & Flatt
//! 1990: the serial fraction that Amdahl's law would need to explain the measured speed-up). Beside the inferred
//! fraction, the measured one: the share of the wall time spent in the serial phases of the engines' hot loops
//! ([`rubblepile::phase`]) and outside any timed phase (the integrator's and the driver's own work, which is serial).
//!
//! Cases (`--cases`, default all):
//! - `rhs-n200` / `rhs-n2000` / `rhs-n10000` / `rhs-n10000-tree`: one right-hand side of the relaxed piles
//!   `targets/N200_T4`, `N2000_T4` and `N10000_T4` (exact gravity; the octree with a step's frozen lists), contact
//!   and dissipation, the median of `--repeats` evaluations, on every thread of the pool (a run would use at most
//!   one per 25 bodies: `rhs-n200` shows why);
//! - `impact-n2000`: a window of the N2000 impact (P2, ζ = 45°, Dop853 at rtol 1e-8) from first contact, `--window-s`
//!   simulated seconds long;
//! - `impact-n200`: the N200 impact (P2, ζ = 45°, Bulirsch–Stoer at rtol 1e-6 of the run) to `--n200-t-end-s`;
//! - `ssdem-40k` / `ssdem-40k-tree10`: soft-sphere steps on the 40 000-sphere FCC ball ([`crate::bench::ssdem`]),
//!   contacts only and with the tree every 10 steps; `ssdem-2k`: the same on 2000 spheres (a small run);
//! - `campaign-n30`: a campaign of `--campaign-runs` N30 impacts run `p` at a time on one thread each;
//! - `hsdem-atmosphere`: the hard-sphere model atmosphere of Richardson11 §3.1, timed once settled (serial engine).
//!
//! Every case also records a fingerprint of what it computed (the RHS, the final snapshot, the final particles),
//! which must be the same at every thread count: the benchmark is also a determinism check, and says so when it
//! is not.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use super::BenchError;
use rubblepile::driver::RunOptions;
use rubblepile::ellipsoid::equations::{EllipsoidSystem, ModelConfig};
use rubblepile::ellipsoid::gravity_tree::{DEFAULT_THETA, GravityMethod};
use rubblepile::impact::campaign::{CampaignOptions, parse_campaign, run_campaign};
use rubblepile::impact::projectile::ProjectileSpec;
use rubblepile::impact::run::{ImpactConfig, read_target, run_impact};
use rubblepile::integrate::{Method, OdeSystem};
use rubblepile::phase::{self, Kind};

/// Every case, in the order they run.
pub const CASES: [&str; 11] = [
    "rhs-n200",
    "rhs-n2000",
    "rhs-n10000",
    "rhs-n10000-tree",
    "impact-n2000",
    "impact-n200",
    "ssdem-40k",
    "ssdem-40k-tree10",
    "ssdem-2k",
    "campaign-n30",
    "hsdem-atmosphere",
];

/// `rubblepile bench scaling`.
#[derive(Debug, clap::Args)]
pub struct ScalingArgs {
    /// Thread counts, comma-separated [default: 1, 2, 4, … up to all cores, and all cores].
    #[arg(long, value_delimiter = ',', value_parser = clap::value_parser!(u64).range(1..=4096))]
    pub threads: Vec<u64>,
    /// Cases to run, comma-separated [default: all]: rhs-n200, rhs-n2000, rhs-n10000, rhs-n10000-tree, impact-n2000,
    /// impact-n200, ssdem-40k, ssdem-40k-tree10, ssdem-2k, campaign-n30, hsdem-atmosphere.
    #[arg(long, value_delimiter = ',')]
    pub cases: Vec<String>,
    /// Timed right-hand sides per thread count of the rhs cases (the median is reported).
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub repeats: u64,
    /// Simulated seconds of the N2000 impact window, from first contact (s).
    #[arg(long = "window-s", default_value_t = 20.0)]
    pub window: f64,
    /// End time of the N200 impact (s).
    #[arg(long = "n200-t-end-s", default_value_t = 10_000.0)]
    pub n200_t_end: f64,
    /// Timed soft-sphere steps per thread count.
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u64).range(1..=1_000_000))]
    pub ssdem_steps: u64,
    /// Runs of the N30 campaign (P1/P2/P3 × angles × seeds, cut to this many).
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u64).range(1..=10_000))]
    pub campaign_runs: u64,
    /// End time of each campaign run (s).
    #[arg(long = "campaign-t-end-s", default_value_t = 2_000.0)]
    pub campaign_t_end: f64,
    /// Time from which the hard-sphere atmosphere is timed (system units; the gas has settled by t = 20).
    #[arg(long, default_value_t = 20.0)]
    pub hsdem_from: f64,
    /// Timed stretch of the hard-sphere atmosphere (system units; dt = 1e-3, about 2500 collisions per unit).
    #[arg(long, default_value_t = 5.0)]
    pub hsdem_window: f64,
    /// The repository's root, where `targets/` and `analysis/` are read [default: the working directory].
    #[arg(long, default_value = ".")]
    pub root: PathBuf,
    /// Write `scaling.csv`, `scaling_phases.csv`, `scaling.svg` and `scaling.png` here.
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite an earlier benchmark's files in OUT.
    #[arg(long)]
    pub force: bool,
}

/// One case timed at one thread count.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    /// The case.
    pub case: String,
    /// Threads of the pool.
    pub threads: usize,
    /// Wall time of the case's work (s; the median for the rhs cases).
    pub seconds: f64,
    /// What the work was, in `unit`s (RHS evaluations, steps, particle-steps, runs, collisions…).
    pub work: f64,
    /// The unit of `work`.
    pub unit: &'static str,
    /// Wall time in the serial phases plus outside any phase (s).
    pub serial_seconds: f64,
    /// Wall time in the parallel phases (s).
    pub parallel_seconds: f64,
    /// The phases' totals (all repeats of this thread count).
    pub phases: Vec<phase::Total>,
    /// Fingerprint of the result (the same at every thread count when the engine is deterministic).
    pub fingerprint: String,
}

/// Speed-up, efficiency and Karp–Flatt serial fraction of `t_p` against `t_1` on `p` threads (`e` is `None` at
/// `p = 1`, where it is undefined).
pub fn karp_flatt(t_1: f64, t_p: f64, p: usize) -> (f64, f64, Option<f64>) {
    let s = t_1 / t_p;
    let pf = p as f64;
    let e = (p > 1).then(|| (1.0 / s - 1.0 / pf) / (1.0 - 1.0 / pf));
    (s, s / pf, e)
}

/// The default thread counts: powers of two up to `cores`, and `cores`.
pub fn default_threads(cores: usize) -> Vec<usize> {
    let mut t = vec![1];
    while t.last().is_some_and(|&x| x * 2 <= cores) {
        t.push(t.last().unwrap() * 2);
    }
    if *t.last().unwrap() != cores {
        t.push(cores);
    }
    t
}

/// Runs `work` with phase timing on; returns its result and the totals of the phases it entered.
fn with_phases<R>(work: impl FnOnce() -> R) -> (R, Vec<phase::Total>) {
    phase::reset();
    phase::enable(true);
    let r = work();
    phase::enable(false);
    (r, phase::totals().into_iter().filter(|t| t.calls > 0).collect())
}

/// Runs `work` on a fresh pool of `threads` threads.
fn on_threads<R: Send>(threads: usize, work: impl FnOnce() -> R + Send) -> Result<R, BenchError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| BenchError::failed(format!("cannot build a pool of {threads} threads: {e}")))?;
    Ok(pool.install(work))
}

/// `phases` scaled by `factor` (to one evaluation, or to the timed part of a case).
fn scaled(phases: Vec<phase::Total>, factor: f64) -> Vec<phase::Total> {
    phases
        .into_iter()
        .map(|t| phase::Total {
            seconds: t.seconds * factor,
            ..t
        })
        .collect()
}

/// The serial and parallel seconds of `phases` over a case's wall time `seconds`: the serial phases plus whatever
/// no phase covers (the integrator, the driver: serial), and the parallel phases.
fn split(phases: &[phase::Total], seconds: f64) -> (f64, f64) {
    let serial: f64 = phases
        .iter()
        .filter(|t| t.kind == Kind::Serial)
        .map(|t| t.seconds)
        .sum();
    let parallel: f64 = phases
        .iter()
        .filter(|t| t.kind == Kind::Parallel)
        .map(|t| t.seconds)
        .sum();
    let outside = (seconds - serial - parallel).max(0.0);
    (serial + outside, parallel)
}

fn fingerprint_f64(values: &[f64]) -> String {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_bits().to_le_bytes()).collect();
    rubblepile::bits::fnv1a_hex(&bytes)
}

/// A relaxed pile with its κ (from `FILE.json`), under gravity by `method`, contact and dissipation.
pub(crate) fn pile_system(path: &Path, method: GravityMethod) -> Result<EllipsoidSystem, BenchError> {
    let bodies = read_target(path).map_err(|e| BenchError::usage(format!("{}: {e}", path.display())))?;
    let json = path.with_extension("json");
    let text = std::fs::read_to_string(&json).map_err(|e| BenchError::usage(format!("{}: {e}", json.display())))?;
    let report: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| BenchError::usage(format!("{}: {e}", json.display())))?;
    let kappa = report["kappa"]
        .as_f64()
        .filter(|k| k.is_finite() && *k > 1.5)
        .ok_or_else(|| BenchError::usage(format!("{}: expected a number kappa > 1.5", json.display())))?;
    Ok(EllipsoidSystem::new(
        &bodies,
        ModelConfig::gaussian_si(kappa),
        crate::bench::rhs::bench_physics(Some(method)),
    ))
}

/// The median wall time of `repeats` right-hand sides of `system` on `threads` threads (as [`crate::bench::rhs`]
/// times them, the pool's other workers kept polling), with a step's frozen tree lists when `step_lists`.
fn rhs_case(
    case: &str,
    system: &EllipsoidSystem,
    threads: usize,
    repeats: usize,
    step_lists: bool,
) -> Result<Measurement, BenchError> {
    let y = system.initial_state();
    // First the fingerprint's evaluation, which also builds what the evaluations keep (the candidate pairs), so
    // that the timed ones are those of a run between rebuilds.
    let dydt = on_threads(threads, || {
        let mut dydt = vec![0.0; system.dim()];
        if step_lists {
            system.begin_step(0.0, &y);
        }
        system.rhs(0.0, &y, &mut dydt);
        system.end_steps();
        dydt
    })?;
    let (timing, phases) = with_phases(|| crate::bench::rhs::time_rhs(system, threads, repeats, step_lists));
    let timing = timing?;
    let seconds = timing.median_us * 1e-6;
    // The phases cover the timed evaluations and the untimed warm-up one: per evaluation.
    let phases = scaled(phases, 1.0 / (repeats + 1) as f64);
    let (serial_seconds, parallel_seconds) = split(&phases, seconds);
    Ok(Measurement {
        case: case.into(),
        threads,
        seconds,
        work: 1.0,
        unit: "RHS",
        serial_seconds,
        parallel_seconds,
        phases,
        fingerprint: fingerprint_f64(&dydt),
    })
}

/// A whole impact run on `threads` threads into `dir` (removed afterwards).
fn impact_case(case: &str, cfg: &ImpactConfig, dir: &Path, threads: usize) -> Result<Measurement, BenchError> {
    let _ = std::fs::remove_dir_all(dir);
    let options = RunOptions {
        force: true,
        progress: false,
        checkpoint_every: None,
        ..RunOptions::default()
    };
    let (summary, phases) = with_phases(|| on_threads(threads, || run_impact(cfg, dir, &options)));
    let summary = summary?.map_err(|e| BenchError::failed(format!("{case}, {threads} threads: {e}")))?;
    // The run's own wall time (its sampling loop), as every run reports it: without reading the target and
    // setting the impact up.
    let seconds = summary.wall_seconds;
    let last = cfg.snapshots.len() - 1;
    let snapshot = std::fs::read(dir.join("snapshots").join(format!("{last}.csv")))
        .map_err(|e| BenchError::failed(format!("{case}: {}: {e}", dir.display())))?;
    let _ = std::fs::remove_dir_all(dir);
    let (serial_seconds, parallel_seconds) = split(&phases, seconds);
    Ok(Measurement {
        case: case.into(),
        threads,
        seconds,
        work: summary.rhs_evaluations as f64,
        unit: "RHS",
        serial_seconds,
        parallel_seconds,
        phases,
        fingerprint: rubblepile::bits::fnv1a_hex(&snapshot),
    })
}

/// Soft-sphere steps of `sys` on `threads` threads.
fn ssdem_case(
    case: &str,
    sys: &rubblepile::granular::soft::forces::SoftSystem,
    threads: usize,
    steps: u64,
) -> Result<Measurement, BenchError> {
    let (rate, phases) = with_phases(|| crate::bench::ssdem::time_steps(sys, threads, steps));
    // Three steps again, for the fingerprint of the particles they leave.
    let after = on_threads(threads, || {
        let mut s = sys.clone();
        let dt = std::f64::consts::PI * (0.5 * s.particles[0].mass / s.material.k_n).sqrt() / 50.0;
        for k in 0..3 {
            rubblepile::granular::soft::leapfrog::step(&mut s, k as f64 * dt, dt);
        }
        s.particles
            .iter()
            .flat_map(|p| {
                p.position
                    .iter()
                    .chain(p.velocity.iter())
                    .copied()
                    .collect::<Vec<f64>>()
            })
            .collect::<Vec<f64>>()
    })?;
    let rate = rate?;
    let particles = sys.particles.len() as f64;
    let seconds = particles * steps as f64 / rate;
    // `time_steps` resets the phase totals after its untimed first step, so they cover the timed steps only.
    let (serial_seconds, parallel_seconds) = split(&phases, seconds);
    Ok(Measurement {
        case: case.into(),
        threads,
        seconds,
        work: particles * steps as f64,
        unit: "particle-steps",
        serial_seconds,
        parallel_seconds,
        phases,
        fingerprint: fingerprint_f64(&after),
    })
}

/// The N30 campaign of `runs` impacts run `threads` at a time, one thread each, into `dir` (removed afterwards).
fn campaign_case(root: &Path, dir: &Path, runs: usize, t_end: f64, threads: usize) -> Result<Measurement, BenchError> {
    let _ = std::fs::remove_dir_all(dir);
    // The campaign resolves relative paths against `root`: give it absolute ones.
    let dir = &std::path::absolute(dir).map_err(|e| BenchError::failed(format!("{}: {e}", dir.display())))?;
    let target = std::path::absolute(root.join("targets/N30_T4.csv"))
        .map_err(|e| BenchError::failed(format!("targets/N30_T4.csv: {e}")))?;
    // 3 projectiles × 11 angles × 2 seeds = 66 points, cut to `runs`.
    let text = format!(
        "[campaign]\nout = {:?}\ntargets = [{:?}]\nprojectiles = [\"P1\", \"P2\", \"P3\"]\n\
         angles = [0.0, 18.0, 36.0, 54.0, 72.0, 90.0, 108.0, 126.0, 144.0, 162.0, 180.0]\nseeds = [1, 2]\n\
         [impact]\nt_end = {t_end:?}\nsnapshots = [0.0, {t_end:?}]\nevery = {:?}\n",
        dir.display().to_string(),
        target.display().to_string(),
        t_end / 10.0
    );
    let mut campaign = parse_campaign(&text, "bench scaling campaign", root)
        .map_err(|e| BenchError::failed(format!("campaign-n30: {e}")))?;
    campaign.points.truncate(runs);
    let options = CampaignOptions {
        run: RunOptions {
            progress: false,
            checkpoint_every: None,
            ..RunOptions::default()
        },
        parallel: Some(threads),
        threads_per_run: Some(1),
        verbose: false,
        shard: None,
    };
    let started = Instant::now();
    let (report, phases) = with_phases(|| on_threads(threads, || run_campaign(&campaign, &options)));
    let report = report?;
    let seconds = started.elapsed().as_secs_f64();
    let report = report.map_err(|e| BenchError::failed(format!("campaign-n30: {e}")))?;
    if report.completed() != campaign.points.len() {
        return Err(BenchError::failed(format!(
            "campaign-n30: {} of {} runs completed on {threads} threads",
            report.completed(),
            campaign.points.len()
        )));
    }
    let mut finals = Vec::new();
    for p in &campaign.points {
        let f = dir.join(&p.name).join("snapshots/1.csv");
        finals.extend(std::fs::read(&f).map_err(|e| BenchError::failed(format!("{}: {e}", f.display())))?);
    }
    let _ = std::fs::remove_dir_all(dir);
    // Many runs at once: the phases of different runs overlap in time, so only the runs' count is meaningful.
    Ok(Measurement {
        case: "campaign-n30".into(),
        threads,
        seconds,
        work: campaign.points.len() as f64,
        unit: "runs",
        serial_seconds: f64::NAN,
        parallel_seconds: f64::NAN,
        phases,
        fingerprint: rubblepile::bits::fnv1a_hex(&finals),
    })
}

/// The hard-sphere model atmosphere of Richardson11 §3.1 (`analysis/richardson2011/atmosphere.toml`, 991 spheres),
/// stepped as a run steps it ([`crate::bench::hsdem::time_scene`]) from t = 0 and timed from `from` (the gas settled)
/// to `to`, on `threads` threads. The engine takes one event at a time, so it is serial: its row shows that more
/// threads neither help nor hurt.
fn hsdem_case(root: &Path, from: f64, to: f64, threads: usize) -> Result<Measurement, BenchError> {
    let scene = root.join("analysis/richardson2011/atmosphere.toml");
    let t = crate::bench::hsdem::time_scene(&scene, from, Some(to), threads, true)?;
    let phases: Vec<phase::Total> = t
        .phases
        .iter()
        .map(|&(name, seconds)| phase::Total {
            name,
            kind: Kind::Serial,
            seconds,
            calls: 0,
        })
        .collect();
    let seconds = t.wall_seconds;
    let (serial_seconds, parallel_seconds) = split(&phases, seconds);
    Ok(Measurement {
        case: "hsdem-atmosphere".into(),
        threads,
        seconds,
        work: t.collisions as f64,
        unit: "collisions",
        serial_seconds,
        parallel_seconds,
        phases,
        // The event sequence's counts: the same on every thread count when the engine is deterministic.
        fingerprint: format!("{}-{}-{}-{}", t.steps, t.collisions, t.pair_collisions, t.relists),
    })
}

/// The pieces of the N2000 and N200 impacts of the benchmark.
fn impact_config(root: &Path, target: &str, method: Method, rtol: f64, contact: f64, t_end: f64) -> ImpactConfig {
    let projectile = ProjectileSpec::preset("P2").expect("P2 is a preset");
    let mut cfg = ImpactConfig::new(root.join(target), projectile);
    cfg.method = method;
    cfg.rtol = rtol;
    cfg.contact_time = contact;
    cfg.t_end = t_end;
    cfg.snapshots = vec![0.0, t_end];
    cfg.every = t_end / 10.0;
    cfg
}

/// Times `case` at `threads` threads.
fn measure(args: &ScalingArgs, case: &str, threads: usize, cache: &mut Systems) -> Result<Measurement, BenchError> {
    let root = &args.root;
    let scratch = args.out.join("scratch");
    let repeats = args.repeats as usize;
    match case {
        "rhs-n200" => rhs_case(
            case,
            cache.pile(root, "targets/N200_T4.csv", false)?,
            threads,
            repeats,
            false,
        ),
        "rhs-n2000" => rhs_case(
            case,
            cache.pile(root, "targets/N2000_T4.csv", false)?,
            threads,
            repeats,
            false,
        ),
        "rhs-n10000" => rhs_case(
            case,
            cache.pile(root, "targets/N10000_T4.csv", false)?,
            threads,
            repeats,
            false,
        ),
        "rhs-n10000-tree" => rhs_case(
            case,
            cache.pile(root, "targets/N10000_T4.csv", true)?,
            threads,
            repeats,
            true,
        ),
        "impact-n2000" => {
            // Contact 2 s in, so that the window is nearly all contact.
            let cfg = impact_config(
                root,
                "targets/N2000_T4.csv",
                Method::Dop853,
                1e-8,
                2.0,
                2.0 + args.window,
            );
            impact_case(case, &cfg, &scratch.join(case), threads)
        }
        "impact-n200" => {
            let cfg = impact_config(
                root,
                "targets/N200_T4.csv",
                Method::BulirschStoer,
                1e-6,
                90.0,
                args.n200_t_end,
            );
            impact_case(case, &cfg, &scratch.join(case), threads)
        }
        "ssdem-40k" | "ssdem-40k-tree10" | "ssdem-2k" => {
            let sys = cache.ssdem(case);
            ssdem_case(case, sys, threads, args.ssdem_steps)
        }
        "campaign-n30" => campaign_case(
            root,
            &scratch.join(case),
            args.campaign_runs as usize,
            args.campaign_t_end,
            threads,
        ),
        "hsdem-atmosphere" => hsdem_case(root, args.hsdem_from, args.hsdem_from + args.hsdem_window, threads),
        other => Err(BenchError::usage(format!(
            "--cases: unknown case {other:?}; expected some of {}",
            CASES.join(", ")
        ))),
    }
}

/// Systems built once per invocation and timed at every thread count.
#[derive(Default)]
struct Systems {
    piles: Vec<(String, bool, EllipsoidSystem)>,
    soft: Vec<(String, rubblepile::granular::soft::forces::SoftSystem)>,
}

impl Systems {
    fn pile(&mut self, root: &Path, target: &str, tree: bool) -> Result<&EllipsoidSystem, BenchError> {
        if let Some(k) = self.piles.iter().position(|(t, tr, _)| t == target && *tr == tree) {
            return Ok(&self.piles[k].2);
        }
        let method = if tree {
            GravityMethod::Tree { theta: DEFAULT_THETA }
        } else {
            GravityMethod::Direct
        };
        let system = pile_system(&root.join(target), method)?;
        self.piles.push((target.to_string(), tree, system));
        Ok(&self.piles.last().expect("just pushed").2)
    }

    fn ssdem(&mut self, case: &str) -> &rubblepile::granular::soft::forces::SoftSystem {
        if let Some(k) = self.soft.iter().position(|(c, _)| c == case) {
            return &self.soft[k].1;
        }
        let (n, gravity, interval) = match case {
            "ssdem-40k-tree10" => (40_000, Some(rubblepile::gravity::SelfGravity::Tree { theta: 0.5 }), 10),
            "ssdem-2k" => (2_000, None, 1),
            _ => (40_000, None, 1),
        };
        let sys = crate::bench::ssdem::bench_system(n, gravity, interval);
        self.soft.push((case.to_string(), sys));
        &self.soft.last().expect("just pushed").1
    }
}

/// A case's rows with their speed-up, efficiency and Karp–Flatt fraction against its own 1-thread row (or its
/// fewest threads).
pub fn derived(rows: &[Measurement]) -> Vec<(f64, f64, Option<f64>)> {
    rows.iter()
        .map(|r| {
            let base = rows
                .iter()
                .filter(|b| b.case == r.case)
                .min_by_key(|b| b.threads)
                .expect("the row itself");
            // Against the fewest threads timed, scaled as if it were one thread's time × its threads, per unit of
            // work (runs that did no work, e.g. no collision yet, compare their times).
            let per_work = if base.work > 0.0 && r.work > 0.0 {
                r.work / base.work
            } else {
                1.0
            };
            let t_1 = base.seconds * base.threads as f64 * per_work;
            karp_flatt(t_1, r.seconds, r.threads)
        })
        .collect()
}

/// `scaling.csv`'s header.
pub const CSV_HEADER: &str = "case,threads,seconds,work,unit,rate_per_s,speedup,efficiency,karp_flatt,\
serial_seconds,parallel_seconds,measured_serial_fraction,fingerprint";

fn write_csv(path: &Path, rows: &[Measurement]) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(f, "{CSV_HEADER}")?;
    for (r, (s, e, kf)) in rows.iter().zip(derived(rows)) {
        let fraction = r.serial_seconds / r.seconds;
        writeln!(
            f,
            "{},{},{:e},{:e},{},{:e},{:.4},{:.4},{},{:e},{:e},{},{}",
            r.case,
            r.threads,
            r.seconds,
            r.work,
            r.unit,
            r.work / r.seconds,
            s,
            e,
            kf.map_or(String::new(), |x| format!("{x:.4}")),
            r.serial_seconds,
            r.parallel_seconds,
            if fraction.is_finite() {
                format!("{fraction:.4}")
            } else {
                String::new()
            },
            r.fingerprint
        )?;
    }
    f.flush()
}

fn write_phases_csv(path: &Path, rows: &[Measurement]) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(f, "case,threads,phase,kind,seconds,calls")?;
    for r in rows {
        for t in &r.phases {
            writeln!(
                f,
                "{},{},{},{},{:e},{}",
                r.case,
                r.threads,
                t.name,
                t.kind.as_str(),
                t.seconds,
                t.calls
            )?;
        }
    }
    f.flush()
}

/// Runs `bench scaling`.
pub fn scaling(args: &ScalingArgs) -> Result<(), BenchError> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let threads: Vec<usize> = if args.threads.is_empty() {
        default_threads(cores)
    } else {
        args.threads.iter().map(|&t| t as usize).collect()
    };
    let cases: Vec<String> = if args.cases.is_empty() {
        CASES.iter().map(|c| c.to_string()).collect()
    } else {
        args.cases.clone()
    };
    if let Some(bad) = cases.iter().find(|c| !CASES.contains(&c.as_str())) {
        return Err(BenchError::usage(format!(
            "--cases: unknown case {bad:?}; expected some of {}",
            CASES.join(", ")
        )));
    }
    for (name, v) in [
        ("--window-s", args.window),
        ("--n200-t-end-s", args.n200_t_end),
        ("--campaign-t-end-s", args.campaign_t_end),
        ("--hsdem-window", args.hsdem_window),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(BenchError::usage(format!("{name}: must be a time > 0 s, got {v}")));
        }
    }
    let files = ["scaling.csv", "scaling_phases.csv", "scaling.svg", "scaling.png"].map(|f| args.out.join(f));
    if !args.force
        && let Some(f) = files.iter().find(|f| f.exists())
    {
        return Err(BenchError::usage(format!(
            "{} exists; use --force to overwrite it",
            f.display()
        )));
    }
    std::fs::create_dir_all(&args.out).map_err(|e| BenchError::failed(format!("{}: {e}", args.out.display())))?;
    if let Some(&most) = threads.iter().max()
        && most > cores
    {
        eprintln!("warning: timing {most} threads on {cores} cores: those rows measure oversubscription");
    }
    println!(
        "bench scaling: {} cases at threads {threads:?} ({cores} cores)",
        cases.len()
    );
    let mut rows: Vec<Measurement> = Vec::new();
    let mut cache = Systems::default();
    for case in &cases {
        let mut mine: Vec<Measurement> = Vec::new();
        for &t in &threads {
            let m = measure(args, case, t, &mut cache)?;
            mine.push(m);
            let d = derived(&mine);
            let (r, (s, e, kf)) = (mine.last().expect("just pushed"), d.last().expect("one per row"));
            println!(
                "  {case:<17} {t:>3} thread{} {:>10.4} s  {:>10.3e} {}/s  speed-up {s:>5.2}  efficiency {:>4.0} %{}{}",
                if t == 1 { " " } else { "s" },
                r.seconds,
                r.work / r.seconds,
                r.unit,
                100.0 * e,
                kf.map_or(String::new(), |x| format!("  Karp-Flatt {x:.3}")),
                {
                    let f = r.serial_seconds / r.seconds;
                    if f.is_finite() {
                        format!("  serial (measured) {:.1} %", 100.0 * f)
                    } else {
                        String::new()
                    }
                }
            );
        }
        if mine.iter().any(|m| m.fingerprint != mine[0].fingerprint) {
            eprintln!(
                "warning: {case}: the results differ between thread counts (fingerprints {:?})",
                {
                    mine.iter()
                        .map(|m| (m.threads, m.fingerprint.clone()))
                        .collect::<Vec<_>>()
                }
            );
        }
        print_phases(&mine);
        rows.extend(mine);
        // Rewritten after every case, so a run cut short (a time limit, a lent machine taken back) keeps the
        // cases it finished.
        write_csv(&files[0], &rows).map_err(|e| BenchError::failed(format!("{}: {e}", files[0].display())))?;
        write_phases_csv(&files[1], &rows).map_err(|e| BenchError::failed(format!("{}: {e}", files[1].display())))?;
    }
    let _ = std::fs::remove_dir_all(args.out.join("scratch"));
    rubblepile::analysis::figures::style::write_figure(&args.out, "scaling", &SpeedupPlot { rows: &rows })
        .map_err(|e| BenchError::failed(format!("{}: {e}", files[2].display())))?;
    println!(
        "  wrote {}, {}, {} and {}",
        files[0].display(),
        files[1].display(),
        files[2].display(),
        files[3].display()
    );
    Ok(())
}

/// Where the time goes at the fewest and the most threads: the phases, largest first, serial ones marked.
fn print_phases(rows: &[Measurement]) {
    let (Some(lo), Some(hi)) = (
        rows.iter().min_by_key(|r| r.threads),
        rows.iter().max_by_key(|r| r.threads),
    ) else {
        return;
    };
    let both = [lo, hi];
    for r in &both[..if lo.threads == hi.threads { 1 } else { 2 }] {
        if r.phases.is_empty() || !r.serial_seconds.is_finite() {
            continue;
        }
        let mut phases = r.phases.clone();
        phases.sort_by(|a, b| b.seconds.total_cmp(&a.seconds));
        let inside: f64 = phases.iter().map(|t| t.seconds).sum();
        let parts: Vec<String> = phases
            .iter()
            .take(6)
            .map(|t| {
                format!(
                    "{} {:.1} %{}",
                    t.name.split_once('.').map_or(t.name, |(_, n)| n),
                    100.0 * t.seconds / r.seconds,
                    if t.kind == Kind::Serial { " (serial)" } else { "" }
                )
            })
            .collect();
        println!(
            "      {} thread{}: {}; outside the phases {:.1} % (serial)",
            r.threads,
            if r.threads == 1 { "" } else { "s" },
            parts.join(", "),
            100.0 * (r.seconds - inside).max(0.0) / r.seconds
        );
    }
}

/// Speed-up against threads, one line per case, and the ideal `S = p`.
struct SpeedupPlot<'a> {
    rows: &'a [Measurement],
}

impl rubblepile::analysis::figures::style::Figure for SpeedupPlot<'_> {
    fn draw<DB: plotters::prelude::DrawingBackend>(
        &self,
        root: &plotters::prelude::DrawingArea<DB, plotters::coord::Shift>,
    ) -> rubblepile::analysis::figures::style::PlotResult {
        use plotters::prelude::*;
        use rubblepile::analysis::figures::style;
        let err = |e: &dyn std::fmt::Display| rubblepile::analysis::AnalysisError::Output(e.to_string());
        let speedups = derived(self.rows);
        let p_max = self.rows.iter().map(|r| r.threads).max().unwrap_or(1) as f64;
        let s_max = speedups.iter().map(|d| d.0).fold(p_max, f64::max);
        let mut chart = ChartBuilder::on(root)
            .caption(
                "rubblepile bench scaling: speed-up against threads",
                style::title_style(),
            )
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(56)
            .build_cartesian_2d((0.8..p_max * 1.25).log_scale(), (0.5..s_max * 1.4).log_scale())
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc("threads p")
            .y_desc("speed-up T(1) / T(p)")
            .label_style(style::small_style())
            .axis_desc_style(style::label_style())
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| format!("{y:.1}"))
            .draw()
            .map_err(|e| err(&e))?;
        chart
            .draw_series(LineSeries::new(
                vec![(1.0, 1.0), (p_max, p_max)],
                BLACK.mix(0.5).stroke_width(1),
            ))
            .map_err(|e| err(&e))?
            .label("ideal S = p")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.5)));
        let mut cases: Vec<&str> = Vec::new();
        for r in self.rows {
            if !cases.contains(&r.case.as_str()) {
                cases.push(&r.case);
            }
        }
        for (k, case) in cases.iter().enumerate() {
            let color = Palette99::pick(k).to_rgba();
            let points: Vec<(f64, f64)> = self
                .rows
                .iter()
                .zip(&speedups)
                .filter(|(r, _)| r.case == *case)
                .map(|(r, d)| (r.threads as f64, d.0))
                .collect();
            chart
                .draw_series(LineSeries::new(points.clone(), color.stroke_width(2)))
                .map_err(|e| err(&e))?
                .label(case.to_string())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
            chart
                .draw_series(points.into_iter().map(|p| Circle::new(p, 3, color.filled())))
                .map_err(|e| err(&e))?;
        }
        style::draw_legend(&mut chart, SeriesLabelPosition::UpperLeft)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn karp_flatt_inverts_amdahls_law() {
        // Amdahl with serial fraction f on p threads: S = 1 / (f + (1 − f)/p); Karp–Flatt gives f back.
        for (f, p) in [(0.1, 2), (0.02, 16), (0.5, 4)] {
            let s = 1.0 / (f + (1.0 - f) / p as f64);
            let (speedup, efficiency, e) = karp_flatt(1.0, 1.0 / s, p);
            assert!((speedup - s).abs() < 1e-12);
            assert!((efficiency - s / p as f64).abs() < 1e-12);
            assert!((e.unwrap() - f).abs() < 1e-12, "{e:?} against {f}");
        }
        assert_eq!(karp_flatt(2.0, 2.0, 1).2, None, "undefined on one thread");
        assert_eq!(default_threads(16), vec![1, 2, 4, 8, 16]);
        assert_eq!(default_threads(12), vec![1, 2, 4, 8, 12]);
        assert_eq!(default_threads(1), vec![1]);
    }
}
