//! A whole run in pictures (`rubblepile render RUN_DIR`): one PNG per snapshot in `RUN_DIR/frames/` and an
//! animated GIF of them, each frame with the simulated time and a colour bar. The snapshots are read back through
//! the run's engine ([`crate::driver::export::visit_snapshots`]), so every engine's runs can be drawn.
//!
//! The camera does not move between frames: it frames the first snapshot (for an impact: the target and the
//! incoming projectile), or a sphere of `extent` metres about the first snapshot's centre of mass when given (for
//! an impact: the target, wherever the projectile starts). Continuous
//! colour scales span 0 to the 95th percentile of the value over all frames, so one fast body (a projectile at
//! 5 km/s) does not wash out the fragments' tens of m/s.

use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::time::Instant;

use super::{
    Camera, ColourScale, FrameBody, Framing, GifOptions, GifWriter, Projection, RenderError, View, render_frame,
    write_png,
};
use crate::analysis::run_analysis::FragmentFields;
use crate::driver::export::{ExportError, visit_snapshots};
use crate::engine::{ParticleView, SnapshotView};
use crate::io::run_lock::DirLock;

/// The scalar that colours the bodies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColourBy {
    /// Speed |v| (m/s).
    Speed,
    /// Bound (1) or escaping (0), from `rubblepile analyze` (`analysis/fragments.csv`).
    Bound,
    /// Spin rate |ω| in revolutions per day.
    Spin,
    /// Body index.
    Id,
}

impl FromStr for ColourBy {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "speed" => Ok(ColourBy::Speed),
            "bound" => Ok(ColourBy::Bound),
            "spin" => Ok(ColourBy::Spin),
            "id" => Ok(ColourBy::Id),
            _ => Err(format!("--color: expected speed, bound, spin or id, got {s:?}")),
        }
    }
}

/// How a run is rendered.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderRunOptions {
    /// Direction of view.
    pub view: View,
    /// Orthographic or perspective.
    pub projection: Projection,
    /// Frame width (pixels).
    pub width: u32,
    /// Frame height (pixels).
    pub height: u32,
    /// What colours the bodies.
    pub colour: ColourBy,
    /// Half-width of the picture (m) about the first snapshot's centre of mass; `None`: framed on the whole first
    /// snapshot.
    pub extent: Option<f64>,
    /// File name of the animation in `frames/`.
    pub gif_name: String,
    /// Time each GIF frame is shown (1/100 s).
    pub gif_delay_centiseconds: u16,
    /// Overwrite an earlier `frames/`.
    pub force: bool,
}

impl Default for RenderRunOptions {
    /// Iso view, orthographic, 800×800, coloured by speed, `run.gif` at 10 frames per second.
    fn default() -> Self {
        RenderRunOptions {
            view: View::Iso,
            projection: Projection::Orthographic,
            width: 800,
            height: 800,
            colour: ColourBy::Speed,
            extent: None,
            gif_name: "run.gif".into(),
            gif_delay_centiseconds: 10,
            force: false,
        }
    }
}

/// Why a run could not be rendered.
#[derive(Debug, thiserror::Error)]
pub enum RenderRunError {
    /// The run's snapshots could not be read, or the output exists.
    #[error(transparent)]
    Run(#[from] ExportError),
    /// A frame could not be drawn or written.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// A bad option (one line naming it).
    #[error("{0}")]
    Option(String),
}

/// What [`render_run`] made.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderReport {
    /// Frames drawn.
    pub frames: usize,
    /// Median wall time of drawing one frame (ray casting, colour bar and text; not the file encoding), ms.
    pub median_frame_ms: f64,
    /// Wall time of the whole rendering, files included (s).
    pub seconds: f64,
    /// The animation.
    pub gif: PathBuf,
}

fn frame_bodies(view: &SnapshotView, values: &[f64]) -> Vec<FrameBody> {
    view.particles
        .iter()
        .zip(values)
        .map(|(p, &value)| FrameBody {
            centre: p.position,
            rotation: p.rotation,
            axes: p.axes,
            value,
        })
        .collect()
}

fn values(view: &SnapshotView, colour: ColourBy, fields: Option<&FragmentFields>) -> Vec<f64> {
    let per = |f: fn(&ParticleView) -> f64| view.particles.iter().map(f).collect();
    match colour {
        ColourBy::Speed => per(|p| p.velocity.norm()),
        ColourBy::Spin => per(|p| p.spin_world.norm() * 86_400.0 / std::f64::consts::TAU),
        ColourBy::Id => per(|p| p.id as f64),
        ColourBy::Bound => fields
            .map(|f| f.columns(view.particles.iter().map(|p| p.id)).remove(0).1)
            .unwrap_or_default(),
    }
}

/// The camera's framing from the first snapshot: all its bodies, or a sphere of `extent` (m) about its centre of
/// mass. The centre of mass, not the middle of the bodies' box: an impact's projectile starts hundreds of km out,
/// which would put the target in a corner of a tight frame.
fn first_framing(view: &SnapshotView, values: &[f64], extent: Option<f64>) -> Framing {
    let all = Framing::enclosing(frame_bodies(view, values).iter());
    let Some(half_extent) = extent else {
        return all;
    };
    let mass: f64 = view.particles.iter().map(|p| p.mass).sum();
    let centre = if mass > 0.0 {
        view.particles
            .iter()
            .map(|p| p.position * p.mass)
            .sum::<crate::math::Vec3>()
            / mass
    } else {
        all.centre
    };
    Framing { centre, half_extent }
}

/// Renders every snapshot of the run in `dir` into `dir/frames/<k>.png` and `dir/frames/<gif_name>`, holding the lock
/// of `dir/frames/` ([`crate::io::run_lock`]): a second render of the run is refused at once
/// ([`ExportError::Locked`]); the run itself may still be going.
pub fn render_run(dir: &Path, opts: &RenderRunOptions) -> Result<RenderReport, RenderRunError> {
    if opts.width < 16 || opts.height < 16 || opts.width > 8192 || opts.height > 8192 {
        return Err(RenderRunError::Option(format!(
            "--size: width and height must be 16 to 8192 pixels, got {}x{}",
            opts.width, opts.height
        )));
    }
    if let Some(e) = opts.extent
        && !(e.is_finite() && e > 0.0)
    {
        return Err(RenderRunError::Option(format!("--extent: must be > 0 m, got {e}")));
    }
    let fields = match opts.colour {
        ColourBy::Bound => Some(
            FragmentFields::read(dir)
                .map_err(|e| RenderRunError::Option(e.to_string()))?
                .ok_or_else(|| {
                    RenderRunError::Option(format!(
                        "--color bound: {} has not been analysed; run `rubblepile analyze {}` first",
                        dir.display(),
                        dir.display()
                    ))
                })?,
        ),
        _ => None,
    };
    let frames_dir = dir.join("frames");
    // `frames/` is locked, not the run: a run still going can be drawn as far as it got. A directory without
    // snapshots is refused below without a lock file left in it.
    let _lock = dir
        .join("snapshots")
        .is_dir()
        .then(|| DirLock::acquire_part(dir, "frames"))
        .transpose()
        .map_err(ExportError::Locked)?;
    if !opts.force && frames_dir.read_dir().is_ok_and(|mut d| d.next().is_some()) {
        return Err(ExportError::Exists(frames_dir).into());
    }
    let start = Instant::now();

    // Pass 1: the framing (first snapshot) and the colour range (all snapshots).
    let mut framing: Option<Framing> = None;
    let mut all_values: Vec<f64> = Vec::new();
    visit_snapshots(dir, &mut |_, view| {
        let vals = values(&view, opts.colour, fields.as_ref());
        if framing.is_none() {
            framing = Some(first_framing(&view, &vals, opts.extent));
        }
        all_values.extend(vals.into_iter().filter(|v| v.is_finite()));
        Ok(())
    })?;
    let framing = framing.unwrap_or(Framing {
        centre: crate::math::Vec3::zeros(),
        half_extent: 1.0,
    });
    let scale = colour_scale(opts.colour, &mut all_values);

    // Pass 2: draw and write.
    std::fs::create_dir_all(&frames_dir).map_err(|source| RenderError::Io {
        path: frames_dir.clone(),
        source,
    })?;
    let camera = Camera::new(opts.view, opts.projection, framing, opts.width, opts.height);
    let gif_path = frames_dir.join(&opts.gif_name);
    let options = GifOptions {
        speed: 10,
        halve: false,
    };
    let mut gif = GifWriter::create_with(&gif_path, opts.width, opts.height, opts.gif_delay_centiseconds, options)?;
    let mut frame_ms = Vec::new();
    let mut fail: Option<RenderError> = None;
    visit_snapshots(dir, &mut |k, view| {
        let vals = values(&view, opts.colour, fields.as_ref());
        let t0 = Instant::now();
        let drawn = render_frame(&frame_bodies(&view, &vals), &scale, &camera, &caption(view.t));
        frame_ms.push(t0.elapsed().as_secs_f64() * 1e3);
        let written = drawn.and_then(|image| {
            write_png(&frames_dir.join(format!("{k:04}.png")), &image)?;
            gif.add(&image)
        });
        if let Err(e) = written {
            fail = Some(e);
            return Err(ExportError::Other("rendering stopped".into()));
        }
        Ok(())
    })
    .map_err(|e| fail.take().map_or(RenderRunError::Run(e), RenderRunError::Render))?;
    gif.finish()?;
    Ok(RenderReport {
        frames: frame_ms.len(),
        median_frame_ms: crate::math::median(&frame_ms),
        seconds: start.elapsed().as_secs_f64(),
        gif: gif_path,
    })
}

/// The scale of `colour` over `values` (all frames' values; reordered).
fn colour_scale(colour: ColourBy, values: &mut [f64]) -> ColourScale {
    values.sort_by(f64::total_cmp);
    let p95 = if values.is_empty() {
        1.0
    } else {
        values[((values.len() - 1) as f64 * 0.95).round() as usize]
    };
    let top = |v: f64| if v > 0.0 { v } else { 1.0 };
    match colour {
        ColourBy::Speed => ColourScale::new("speed (m/s)", 0.0, top(p95)),
        ColourBy::Spin => ColourScale::new("spin (rev/day)", 0.0, top(p95)),
        ColourBy::Id => ColourScale::new("body", 0.0, top(values.last().copied().unwrap_or(1.0))),
        ColourBy::Bound => ColourScale::categorical("fate", vec![(1.0, "bound".into()), (0.0, "escaping".into())]),
    }
}

/// `t = 123.4 s`, with hours beside it for long runs.
fn caption(t: f64) -> String {
    if t >= 7200.0 {
        format!("t = {t:.0} s ({:.2} h)", t / 3600.0)
    } else {
        format!("t = {t:.1} s")
    }
}

/// Renders a run just finished by `rubblepile run` (`--render`, or always for the built-in default scene, whose
/// animation is `impact.gif`): the line to print before the run's summary, and those after it (what to open).
pub fn after_run(out: &Path, default_scene: bool, force: bool) -> Result<(String, Vec<String>), RenderRunError> {
    let opts = RenderRunOptions {
        gif_name: if default_scene { "impact.gif" } else { "run.gif" }.into(),
        force,
        ..Default::default()
    };
    let r = render_run(out, &opts)?;
    let before = format!(
        "rendered {} frames in {:.1} s (median {:.0} ms per frame)",
        r.frames, r.seconds, r.median_frame_ms
    );
    let mut after = vec![format!("look at it: {}", r.gif.display())];
    let pvd = out.join("vtk").join(crate::driver::formats::vtk::COLLECTION_FILE);
    if pvd.exists() {
        after.push(format!(
            "in ParaView: open {} (see README, \"Looking at a run\")",
            pvd.display()
        ));
    }
    Ok((before, after))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

    fn view(particles: Vec<ParticleView>) -> SnapshotView {
        SnapshotView {
            spheres: true,
            particles,
            ..SnapshotView::default()
        }
    }

    /// An impact's first snapshot: a heavy target at the origin and a light projectile 450 km out. Without an
    /// extent the frame holds both; with one it is centred on the centre of mass (here 4.5 km from the target),
    /// not halfway to the projectile.
    #[test]
    fn extent_frames_the_centre_of_mass_not_the_middle_of_the_bodies() {
        let zero = Vec3::zeros();
        let snapshot = view(vec![
            ParticleView::sphere(0, 99.0, 90e3, zero, zero, zero),
            ParticleView::sphere(1, 1.0, 20e3, Vec3::new(450e3, 0.0, 0.0), zero, zero),
        ]);
        let values = [0.0, 0.0];
        let all = first_framing(&snapshot, &values, None);
        assert!((all.centre.x - 0.5 * (-90e3 + 470e3)).abs() < 1e-6, "{:?}", all.centre);
        let tight = first_framing(&snapshot, &values, Some(150e3));
        assert!(
            (tight.centre - Vec3::new(4.5e3, 0.0, 0.0)).norm() < 1e-6,
            "{:?}",
            tight.centre
        );
        assert_eq!(tight.half_extent, 150e3);
        // Massless bodies (no masses written): the middle of the bodies, as without an extent.
        let massless = view(
            snapshot
                .particles
                .iter()
                .map(|p| ParticleView { mass: 0.0, ..*p })
                .collect(),
        );
        assert_eq!(first_framing(&massless, &values, Some(1.0)).centre, all.centre);
    }
}
