//! `rubblepile bench hsdem`: the speed of the hard-sphere engine (Richardson11 §2.1: kick–drift–kick steps with
//! predicted collisions) on a scene, in collisions and steps per second of one core, with the split of the time over
//! the stepper's phases ([`rubblepile::phase`], `hard.*`).
//!
//! The canonical case is Richardson11 §3.1's model atmosphere (`analysis/richardson2011/atmosphere.toml`: 991
//! elastic spheres in a cylinder on a plane under uniform gravity). Its first seconds (a blob falling and
//! splashing) are not what a long run spends its time on, so the timing can start after a warm-up (`--from-s`, e.g.
//! t = 50, when the atmosphere has equilibrated); the warm-up is stepped exactly as the timed part and not timed.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use super::BenchError;
use rubblepile::granular::hard::scene::load_hard_scene;
use rubblepile::granular::hard::stepper::System;
use rubblepile::phase;

/// `rubblepile bench hsdem`.
#[derive(Debug, clap::Args)]
pub struct BenchHsdemArgs {
    /// Hard-sphere scene file (e.g. analysis/richardson2011/atmosphere.toml).
    #[arg(long, value_name = "FILE")]
    pub scene: PathBuf,
    /// Time the steps from this simulated time on (s); the steps before it are taken untimed (warm-up).
    #[arg(long = "from-s", default_value_t = 0.0, value_name = "T")]
    pub from: f64,
    /// Simulated end time (s); default the scene's `t_end`.
    #[arg(long = "t-end-s", value_name = "T")]
    pub t_end: Option<f64>,
    /// Threads of the pool the engine runs in (the stepper is serial; only full neighbour-list builds fork).
    #[arg(long, default_value_t = 1)]
    pub threads: usize,
    /// Write this CSV (one row: the counts, times and rates, then one column of seconds per phase).
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Time without the phase probes (they read the clock twice per event: about 10 % of a collision-dominated run
    /// such as a dense drum, under 2 % of the model atmosphere).
    #[arg(long)]
    pub no_phases: bool,
}

/// What one timed stretch of a hard-sphere run did and cost.
#[derive(Debug, Clone, PartialEq)]
pub struct HsdemTiming {
    /// Start of the timed stretch (s of simulated time).
    pub t_from: f64,
    /// End of the timed stretch (s).
    pub t_to: f64,
    /// Steps timed.
    pub steps: u64,
    /// Collisions (pair + wall) in the timed stretch.
    pub collisions: u64,
    /// Particle–particle collisions in the timed stretch.
    pub pair_collisions: u64,
    /// Single particles re-listed in the neighbour list in the timed stretch.
    pub relists: u64,
    /// Full neighbour-list builds in the timed stretch.
    pub rebuilds: u64,
    /// Wall-clock seconds of the timed stretch.
    pub wall_seconds: f64,
    /// CPU seconds of the stepping thread (Linux `/proc/thread-self/schedstat`; `None` where unreadable): on a
    /// loaded machine this, not the wall time, measures the engine.
    pub cpu_seconds: Option<f64>,
    /// Seconds per stepper phase (`hard.*`), in the order the phases first ran.
    pub phases: Vec<(&'static str, f64)>,
}

impl HsdemTiming {
    /// Collisions per CPU second (per wall second where the CPU time is unknown).
    pub fn collisions_per_second(&self) -> f64 {
        self.collisions as f64 / self.cpu_seconds.unwrap_or(self.wall_seconds)
    }
    /// Steps per CPU second (per wall second where the CPU time is unknown).
    pub fn steps_per_second(&self) -> f64 {
        self.steps as f64 / self.cpu_seconds.unwrap_or(self.wall_seconds)
    }
}

/// CPU time (s) of the calling thread, where the kernel reports it (not where it reads 0: issue 57).
fn thread_cpu_seconds() -> Option<f64> {
    crate::bench::work_precision::thread_cpu_seconds()
}

/// Steps `system` to `t` with steps of `dt`, the last one shortened to land on `t` (as the run driver lands on an
/// output time).
fn step_to(system: &mut System, dt: f64, t: f64) -> Result<u64, BenchError> {
    let mut steps = 0;
    while system.t < t {
        let left = t - system.t;
        let h = if left < 1.000001 * dt { left } else { dt };
        system
            .step(h)
            .map_err(|e| BenchError::failed(format!("step at t = {}: {e}", system.t)))?;
        steps += 1;
        if left == h {
            system.t = t;
        }
    }
    Ok(steps)
}

/// Runs the hard-sphere scene at `scene` on a pool of `threads` threads from t = 0 to `t_end` (default the scene's),
/// timing the steps from `t_from` on, with the stepper's phase timers on if `phases` (then
/// [`HsdemTiming::phases`] is filled; the probes cost a little, see [`BenchHsdemArgs::no_phases`]).
pub fn time_scene(
    scene: &Path,
    t_from: f64,
    t_end: Option<f64>,
    threads: usize,
    phases: bool,
) -> Result<HsdemTiming, BenchError> {
    let sc = load_hard_scene(scene).map_err(|e| BenchError::usage(e.to_string()))?;
    let t_end = t_end.unwrap_or(sc.t_end);
    if !(t_from.is_finite() && t_from >= 0.0 && t_end.is_finite() && t_end > t_from) {
        return Err(BenchError::usage(format!(
            "need 0 <= --from-s < --t-end-s, got {t_from} and {t_end}"
        )));
    }
    if threads == 0 {
        return Err(BenchError::usage("--threads must be >= 1, got 0"));
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| BenchError::failed(format!("cannot build a pool of {threads} threads: {e}")))?;
    pool.install(|| {
        let mut system = System::new(sc.particles.clone(), sc.walls.clone(), sc.settings);
        step_to(&mut system, sc.dt, t_from)?;
        let before = system.counters;
        let was_on = phase::enabled();
        phase::enable(phases);
        let hard_before: Vec<(&'static str, f64)> = phase::split("hard.")
            .0
            .into_iter()
            .map(|t| (t.name, t.seconds))
            .collect();
        let cpu0 = thread_cpu_seconds();
        let clock = Instant::now();
        let steps = step_to(&mut system, sc.dt, t_end)?;
        let wall_seconds = clock.elapsed().as_secs_f64();
        let cpu_seconds = thread_cpu_seconds().zip(cpu0).map(|(b, a)| b - a);
        phase::enable(was_on);
        let phases = phase::split("hard.")
            .0
            .into_iter()
            .map(|t| {
                let earlier = hard_before.iter().find(|(n, _)| *n == t.name).map_or(0.0, |x| x.1);
                (t.name, t.seconds - earlier)
            })
            .filter(|(_, s)| phases && *s > 0.0)
            .collect();
        let c = system.counters;
        let collisions = |c: &rubblepile::granular::hard::stepper::Counters| c.pair_collisions + c.wall_collisions;
        Ok(HsdemTiming {
            t_from,
            t_to: t_end,
            steps,
            collisions: collisions(&c) - collisions(&before),
            pair_collisions: c.pair_collisions - before.pair_collisions,
            relists: c.reanchors - before.reanchors,
            rebuilds: c.rebuilds - before.rebuilds,
            wall_seconds,
            cpu_seconds,
            phases,
        })
    })
}

/// `rubblepile bench hsdem`: times the scene, prints the rates and the phase split, writes the CSV.
pub fn bench(args: &BenchHsdemArgs) -> Result<(), BenchError> {
    let t = time_scene(&args.scene, args.from, args.t_end, args.threads, !args.no_phases)?;
    let cpu = t.cpu_seconds.map_or("unknown".to_string(), |c| format!("{c:.3} s"));
    println!(
        "{}: t = {} .. {} s, {} steps, {} collisions ({} pair), {} re-listings, {} list builds",
        args.scene.display(),
        t.t_from,
        t.t_to,
        t.steps,
        t.collisions,
        t.pair_collisions,
        t.relists,
        t.rebuilds
    );
    println!(
        "wall {:.3} s, CPU {cpu}: {:.4e} collisions/s, {:.4e} steps/s (per CPU second where known)",
        t.wall_seconds,
        t.collisions_per_second(),
        t.steps_per_second()
    );
    let timed: f64 = t.phases.iter().map(|p| p.1).sum();
    for (name, s) in &t.phases {
        println!(
            "  {name:<20} {s:9.4} s  {:5.1} %",
            100.0 * s / timed.max(f64::MIN_POSITIVE)
        );
    }
    if let Some(path) = &args.out {
        let mut head = String::from(
            "scene,t_from,t_to,threads,steps,collisions,pair_collisions,relists,rebuilds,wall_seconds,cpu_seconds,\
             collisions_per_second,steps_per_second",
        );
        let mut row = format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{}",
            args.scene.display(),
            t.t_from,
            t.t_to,
            args.threads,
            t.steps,
            t.collisions,
            t.pair_collisions,
            t.relists,
            t.rebuilds,
            t.wall_seconds,
            t.cpu_seconds.map_or(String::new(), |c| c.to_string()),
            t.collisions_per_second(),
            t.steps_per_second()
        );
        for (name, s) in &t.phases {
            head += &format!(",{name}");
            row += &format!(",{s}");
        }
        let mut f = std::fs::File::create(path).map_err(|e| BenchError::failed(format!("{}: {e}", path.display())))?;
        writeln!(f, "{head}\n{row}").map_err(|e| BenchError::failed(format!("{}: {e}", path.display())))?;
    }
    Ok(())
}
