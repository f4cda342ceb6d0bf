//! `rubblepile bench render`: what looking at a run costs. Milliseconds per 800×800 frame ([`render_frame`]: ray
//! casting, colour bar, caption) for random clouds of N ellipsoids, on 1 and on all threads, side by side in one run;
//! and the VTK writer's throughput (MB/s of `.vtp` bytes produced) for the same snapshots, plus the size of a
//! 42 000-sphere snapshot (a pile of Zhang17's size, budgeted at 5 MB). Writes `bench_render.csv` and
//! `bench_render.svg`/`.png`.

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use super::BenchError;
use rubblepile::analysis::figures::lines::{LineChart, Mark, Series};
use rubblepile::driver::formats::vtk::pieces;
use rubblepile::ellipsoid::cloud::cloud_view;
use rubblepile::engine::SnapshotView;
use rubblepile::render::{Camera, ColourScale, FrameBody, Framing, Projection, View, render_frame};

/// `rubblepile bench render`.
#[derive(Debug, clap::Args)]
pub struct RenderBenchArgs {
    /// Numbers of ellipsoids (random cloud: equivalent radii 1–5 km on a jittered cubic lattice, random
    /// attitudes), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "30,200,2000")]
    pub bodies: Vec<usize>,
    /// Thread counts, comma-separated [default: 1 and all available].
    #[arg(long, value_delimiter = ',', value_parser = rubblepile::io::scene_file::thread_count)]
    pub threads: Option<Vec<usize>>,
    /// Frame size (pixels, square).
    #[arg(long, default_value_t = 800)]
    pub size: u32,
    /// Timed frames (and VTK writes) per case; medians are reported.
    #[arg(long, default_value_t = 7)]
    pub repeats: usize,
    /// Where bench_render.csv and the plot go.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Overwrite an earlier benchmark in DIR.
    #[arg(long)]
    pub force: bool,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    rubblepile::math::median(&v)
}

/// Median ms to draw one frame of `view` on `threads` threads (after one untimed frame).
pub fn time_frame(view: &SnapshotView, size: u32, threads: usize, repeats: usize) -> Result<f64, BenchError> {
    let bodies: Vec<FrameBody> = view
        .particles
        .iter()
        .map(|p| FrameBody {
            centre: p.position,
            rotation: p.rotation,
            axes: p.axes,
            value: p.velocity.norm(),
        })
        .collect();
    let camera = Camera::new(
        View::Iso,
        Projection::Orthographic,
        Framing::enclosing(bodies.iter()),
        size,
        size,
    );
    let scale = ColourScale::spanning("speed (m/s)", bodies.iter().map(|b| b.value));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| BenchError::failed(format!("cannot build a pool of {threads} threads: {e}")))?;
    pool.install(|| {
        let mut samples = Vec::new();
        for k in 0..=repeats {
            let t0 = Instant::now();
            render_frame(&bodies, &scale, &camera, "t = 0 s").map_err(BenchError::failed)?;
            if k > 0 {
                samples.push(t0.elapsed().as_secs_f64() * 1e3);
            }
        }
        Ok(median(samples))
    })
}

/// Bytes of the VTK pieces of `view` and the median MB/s of producing them.
pub fn time_vtk(view: &SnapshotView, repeats: usize) -> Result<(u64, f64), BenchError> {
    let mut bytes = 0;
    let mut samples = Vec::new();
    for _ in 0..repeats.max(1) {
        let t0 = Instant::now();
        bytes = 0;
        for (_, piece) in pieces(view) {
            bytes += piece.to_bytes().map_err(BenchError::failed)?.len() as u64;
        }
        samples.push(bytes as f64 / 1e6 / t0.elapsed().as_secs_f64());
    }
    Ok((bytes, median(samples)))
}

/// Runs `bench render`.
pub fn render(args: &RenderBenchArgs) -> Result<(), BenchError> {
    let csv = args.out.join("bench_render.csv");
    if csv.exists() && !args.force {
        return Err(BenchError::usage(format!(
            "--out: {} already holds a benchmark; use --force to overwrite it",
            args.out.display()
        )));
    }
    if args.bodies.contains(&0) || !(16..=8192).contains(&args.size) || args.repeats == 0 {
        return Err(BenchError::usage(
            "--bodies must be >= 1, --size 16 to 8192 pixels, --repeats >= 1",
        ));
    }
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    let threads = args
        .threads
        .clone()
        .unwrap_or(if all > 1 { vec![1, all] } else { vec![1] });
    if threads.contains(&0) {
        return Err(BenchError::usage("--threads: each count must be >= 1"));
    }
    std::fs::create_dir_all(&args.out).map_err(|e| BenchError::failed(format!("{}: {e}", args.out.display())))?;
    let mut rows = vec!["case,bodies,threads,size_px,median_ms_per_frame,vtk_bytes,vtk_mb_per_s".to_string()];
    let mut series: Vec<Series> = threads
        .iter()
        .enumerate()
        .map(|(i, t)| Series {
            label: format!("{t} thread{}", if *t == 1 { "" } else { "s" }),
            points: Vec::new(),
            errors: Vec::new(),
            colour: i,
            mark: Mark::Line,
        })
        .collect();
    for &n in &args.bodies {
        let view = cloud_view(n, false);
        let (bytes, mbs) = time_vtk(&view, args.repeats)?;
        let mut line = format!("bench render: {n} ellipsoids, {}x{} px:", args.size, args.size);
        let mut per_thread = Vec::new();
        for (i, &t) in threads.iter().enumerate() {
            let ms = time_frame(&view, args.size, t, args.repeats)?;
            line.push_str(&format!(
                " {ms:.1} ms/frame on {t} thread{};",
                if t == 1 { "" } else { "s" }
            ));
            rows.push(format!("ellipsoids,{n},{t},{},{ms:e},{bytes},{mbs:e}", args.size));
            series[i].points.push((n as f64, ms));
            per_thread.push(ms);
        }
        if per_thread.len() > 1 {
            line.push_str(&format!(
                " speed-up {:.2}x;",
                per_thread[0] / per_thread[per_thread.len() - 1]
            ));
        }
        println!("{line} VTK {:.2} MB at {mbs:.0} MB/s", bytes as f64 / 1e6);
    }
    // The size budget: a 42 000-sphere snapshot, a pile of Zhang17's size.
    let big = cloud_view(42_000, true);
    let (bytes, mbs) = time_vtk(&big, 3)?;
    rows.push(format!("spheres,42000,1,0,,{bytes},{mbs:e}"));
    println!(
        "bench render: a 42000-sphere snapshot is {:.2} MB of VTK, written at {mbs:.0} MB/s",
        bytes as f64 / 1e6
    );
    let mut f = std::fs::File::create(&csv).map_err(|e| BenchError::failed(format!("{}: {e}", csv.display())))?;
    f.write_all((rows.join("\n") + "\n").as_bytes())
        .map_err(|e| BenchError::failed(format!("{}: {e}", csv.display())))?;
    let chart = LineChart {
        title: format!("Ray-cast frames, {0}x{0} px", args.size),
        x_label: "bodies".into(),
        y_label: "median ms per frame".into(),
        series,
        log_x: true,
    };
    rubblepile::analysis::figures::style::write_figure(&args.out, "bench_render", &chart)
        .map_err(BenchError::failed)?;
    println!("  wrote {} and bench_render.svg/.png", csv.display());
    Ok(())
}
