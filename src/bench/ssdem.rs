//! `rubblepile bench ssdem`: particle-steps per second of the soft-sphere engine (Zhang17's SSDEM) on an FCC ball
//! of loaded contacts, per thread count, with or without self-gravity (`analysis/ssdem_perf/`).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use super::BenchError;
use rubblepile::granular::soft::contact::Material;
use rubblepile::granular::soft::forces::{Gravity, SoftSystem};
use rubblepile::granular::soft::packing::fcc_ball;
use rubblepile::granular::soft::run::checked_step;
use rubblepile::gravity::SelfGravity;
use rubblepile::io::scene_file::SI_G;
use rubblepile::math::Vec3;

/// `rubblepile bench ssdem`.
#[derive(Debug, clap::Args)]
pub struct BenchSsdemArgs {
    /// Particles (an FCC ball of spheres of radius 1 m, grain density 2000 kg/m³, 0.5 % overlaps so every
    /// contact is loaded, small random-free shear motion from a uniform spin of the ball).
    #[arg(long, default_value_t = 10000, value_parser = clap::value_parser!(u64).range(2..=10_000_000))]
    pub particles: u64,
    /// Gravity: `off` (contacts only), `tree` (θ = 0.5) or `direct`.
    #[arg(long, default_value = "off", value_parser = ["off", "tree", "direct"])]
    pub gravity: String,
    /// Self-gravity every K steps (r-RESPA; `[gravity] interval_steps` of a scene), K >= 1.
    #[arg(long, default_value_t = 1, value_name = "K", value_parser = clap::value_parser!(u64).range(1..=1_000_000))]
    pub gravity_interval: u64,
    /// Timed steps per thread count.
    #[arg(long, default_value_t = 50, value_parser = clap::value_parser!(u64).range(1..=1_000_000))]
    pub steps: u64,
    /// Thread counts to time (comma-separated).
    #[arg(long, default_value = "1,2", value_delimiter = ',', value_parser = rubblepile::io::scene_file::thread_count)]
    pub threads: Vec<usize>,
    /// Write `bench_ssdem.csv` and `bench_ssdem.svg` here.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Overwrite an earlier benchmark's files in DIR.
    #[arg(long)]
    pub force: bool,
    /// Also write the benchmark's starting particles (before the timed steps) to FILE in the snapshot columns
    /// `t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz`, e.g. to set up the same packing in another code
    /// (`analysis/ssdem_perf/`).
    #[arg(long, value_name = "FILE")]
    pub dump_particles: Option<PathBuf>,
    /// Also time every phase of the step ([`rubblepile::phase`]) and print, per thread count, each phase's share of
    /// the timed steps and the serial fraction (the phase timers cost two clock reads per phase and step).
    #[arg(long)]
    pub phases: bool,
}

/// The benchmark system: `n` spheres on an FCC ball compressed by 0.5 %, spinning slowly, self-gravity (if
/// any) every `gravity_interval` steps.
pub fn bench_system(n: usize, gravity: Option<SelfGravity>, gravity_interval: u64) -> SoftSystem {
    let mut particles = fcc_ball(n, 1.0, 2000.0, -0.005);
    for p in particles.iter_mut() {
        p.velocity = Vec3::new(0.0, 0.0, 1e-3).cross(&p.position);
    }
    // k_N so that a 1 % overlap holds ~ the benchmark's loads; dt = T_c/50.
    let k_n = 1e7;
    let mut sys = SoftSystem::new(
        particles,
        Vec::new(),
        Material::nominal(k_n),
        Gravity {
            uniform: Vec3::zeros(),
            self_gravity: gravity,
            g: SI_G,
        },
    );
    sys.gravity_interval = gravity_interval;
    sys.compute_forces(0.0, 0.0);
    sys
}

/// Particle-steps per second of `steps` leapfrog steps on `threads` threads (a pool of its own), as a run takes
/// its steps between output samples ([`checked_step`]: the state before each step kept for `last_good_state.csv`,
/// the new state checked, the dissipation summed at every step, the springs' stored energy not, as runs sum it
/// only at samples). One untimed step comes first; when phase timing is on ([`rubblepile::phase`]) its totals are reset
/// after it, so that they hold the timed steps only.
pub fn time_steps(sys: &SoftSystem, threads: usize, steps: u64) -> Result<f64, BenchError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| format!("cannot build a pool of {threads} threads: {e}"))?;
    let mut s = sys.clone();
    s.spring_energy_wanted = false;
    let dt = std::f64::consts::PI * (0.5 * s.particles[0].mass / s.material.k_n).sqrt() / 50.0;
    let mut before = Vec::new();
    let elapsed = pool.install(|| -> Result<f64, String> {
        checked_step(&mut s, &mut before, 0, dt, |_, _| ())?;
        if rubblepile::phase::enabled() {
            rubblepile::phase::reset();
        }
        let start = Instant::now();
        for k in 1..=steps {
            checked_step(&mut s, &mut before, k, dt, |_, _| ())?;
        }
        Ok(start.elapsed().as_secs_f64())
    });
    let elapsed = elapsed.map_err(|e| BenchError::failed(format!("the benchmark system broke: {e}")))?;
    Ok(s.particles.len() as f64 * steps as f64 / elapsed)
}

/// `rubblepile bench ssdem`.
pub fn bench(args: &BenchSsdemArgs) -> Result<(), BenchError> {
    let gravity = match args.gravity.as_str() {
        "tree" => Some(SelfGravity::Tree { theta: 0.5 }),
        "direct" => Some(SelfGravity::Direct),
        _ => None,
    };
    if let Some(dir) = &args.out {
        let csv = dir.join("bench_ssdem.csv");
        if csv.exists() && !args.force {
            return Err(BenchError::usage(format!(
                "{} exists; use --force to overwrite it",
                csv.display()
            )));
        }
        std::fs::create_dir_all(dir).map_err(|e| BenchError::failed(format!("{}: {e}", dir.display())))?;
    }
    let sys = bench_system(args.particles as usize, gravity, args.gravity_interval);
    if let Some(path) = &args.dump_particles {
        rubblepile::granular::soft::run::write_particles_csv(path, 0.0, &sys.particles)
            .map_err(|e| BenchError::failed(format!("--dump-particles {}: {e}", path.display())))?;
    }
    let mut rows = Vec::new();
    for &t in &args.threads {
        if t == 0 {
            return Err(BenchError::usage("--threads: each count must be >= 1, got 0"));
        }
        rubblepile::phase::enable(args.phases);
        let rate = time_steps(&sys, t, args.steps)?;
        rubblepile::phase::enable(false);
        println!(
            "N = {}, gravity {} (interval {}), {t} thread(s): {rate:.4e} particle-steps/s ({} contacts)",
            args.particles, args.gravity, args.gravity_interval, sys.stats.pair_contacts
        );
        if args.phases {
            let wall = sys.particles.len() as f64 * args.steps as f64 / rate;
            print!("{}", phase_table(wall, args.steps));
        }
        rows.push((t, rate));
    }
    if let Some(dir) = &args.out {
        let csv = dir.join("bench_ssdem.csv");
        let mut f = std::fs::File::create(&csv).map_err(|e| BenchError::failed(format!("{}: {e}", csv.display())))?;
        let mut text = String::from("particles,gravity,threads,steps,particle_steps_per_second,gravity_interval\n");
        for (t, r) in &rows {
            text += &format!(
                "{},{},{t},{},{r},{}\n",
                args.particles, args.gravity, args.steps, args.gravity_interval
            );
        }
        f.write_all(text.as_bytes())
            .map_err(|e| BenchError::failed(format!("{}: {e}", csv.display())))?;
        plot(&dir.join("bench_ssdem.svg"), &rows, &args.gravity, args.particles).map_err(BenchError::failed)?;
    }
    Ok(())
}

/// The phases of the soft-sphere step and of the tree (`soft.*`, `gravity.*`) timed since the last reset, as a
/// table: seconds, milliseconds per step and share of the timed wall time `wall` (s) of `steps` steps, then the
/// serial and parallel sums and the serial fraction `serial / (serial + parallel)`.
pub fn phase_table(wall: f64, steps: u64) -> String {
    let mut text = String::new();
    let (mut serial, mut parallel) = (0.0, 0.0);
    for prefix in ["soft.", "gravity."] {
        let (mine, s, p) = rubblepile::phase::split(prefix);
        serial += s;
        parallel += p;
        for t in mine.iter().filter(|t| t.calls > 0) {
            text += &format!(
                "  {:<26} {:<8} {:>9.4} s {:>9.4} ms/step {:>6.2} %  ({} calls)\n",
                t.name,
                t.kind.as_str(),
                t.seconds,
                1e3 * t.seconds / steps as f64,
                100.0 * t.seconds / wall,
                t.calls
            );
        }
    }
    text += &format!(
        "  timed {wall:.4} s; phases: serial {serial:.4} s, parallel {parallel:.4} s, unaccounted {:.4} s; \
         serial fraction {:.2} %\n",
        wall - serial - parallel,
        100.0 * serial / (serial + parallel).max(f64::MIN_POSITIVE)
    );
    text
}

fn plot(path: &Path, rows: &[(usize, f64)], gravity: &str, n: u64) -> Result<(), String> {
    use plotters::prelude::*;
    // plotters measures text with the embedded font (its ab_glyph feature): register it first
    rubblepile::analysis::figures::style::ensure_font()?;
    let root = SVGBackend::new(path, (640, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let max_t = rows.iter().map(|r| r.0).max().unwrap_or(1) as f64 + 0.5;
    let max_r = rows.iter().map(|r| r.1).fold(0.0, f64::max) * 1.2;
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("SSDEM N = {n}, gravity {gravity}"), ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(70)
        .build_cartesian_2d(0.5..max_t, 0.0..max_r.max(1.0))
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc("threads")
        .y_desc("particle-steps / s")
        .draw()
        .map_err(|e| e.to_string())?;
    chart
        .draw_series(LineSeries::new(rows.iter().map(|r| (r.0 as f64, r.1)), &BLUE))
        .map_err(|e| e.to_string())?;
    chart
        .draw_series(rows.iter().map(|r| Circle::new((r.0 as f64, r.1), 4, BLUE.filled())))
        .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())
}
