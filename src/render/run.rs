//! A whole run in pictures (`rubblepile render RUN_DIR`): one PNG per snapshot in `RUN_DIR/frames/` (or `--out
//! DIR`) and an animated GIF of them, each frame with the simulated time, a colour bar, a scale bar and an axis
//! triad, the run's walls drawn translucent where they were at that time. The snapshots are read back through the
//! run's engine ([`crate::driver::export::visit_snapshots`]), so every engine's runs can be drawn.
//!
//! The camera follows the bodies ([`following_framings`]): each frame is centred on its snapshot's centre of mass
//! (the middle of the bodies when no masses are written), and its half-width is the largest [`reach_98`] of the
//! snapshots so far — it grows as a pile expands and never shrinks, so nothing that was in the picture is cropped
//! and the picture does not zoom in and out. `extent` fixes the half-width instead. Continuous colour scales span 0
//! to the 95th percentile of the value over all frames, so one fast body (a projectile at 5 km/s) does not wash
//! out the fragments' tens of m/s.

use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::time::Instant;

use super::{
    Camera, ColourScale, FrameBody, Framing, GifWriter, Projection, RenderError, View, render_frame_with_walls,
    wall_polygons, write_png,
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
    /// Half-width of the picture (m) about each snapshot's centre of mass; `None`: following the bodies
    /// ([`following_framings`]).
    pub extent: Option<f64>,
    /// Fixed centre of every frame (m); `None`: each snapshot's centre of mass. A drum or a box is framed whole
    /// about its axis this way, where its grains' centre of mass would cut it off.
    pub centre: Option<crate::math::Vec3>,
    /// File name of the animation in the frames directory.
    pub gif_name: String,
    /// Time each GIF frame is shown (1/100 s).
    pub gif_delay_centiseconds: u16,
    /// Directory of the frames and the animation; `None`: `RUN_DIR/frames`.
    pub out: Option<PathBuf>,
    /// Overwrite an earlier frames directory.
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
            centre: None,
            gif_name: "run.gif".into(),
            gif_delay_centiseconds: 10,
            out: None,
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
    /// The directory the frames were written to.
    pub frames_dir: PathBuf,
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

/// Share of the bodies [`reach_98`] holds.
pub const REACH_QUANTILE: f64 = 0.98;

/// The centre of mass of `particles` (the middle of their bounding box when they have no mass) and their robust
/// reach about it (m): the smallest radius that holds the whole of at least 98 % of the bodies (nearest-rank
/// percentile of each body's centre distance plus its largest semi-axis; up to 49 bodies that is all of them). One
/// fragment flying off does not widen the picture; a pile expanding does.
pub fn reach_98(particles: &[ParticleView]) -> (crate::math::Vec3, f64) {
    use crate::math::Vec3;
    if particles.is_empty() {
        return (Vec3::zeros(), 0.0);
    }
    let mass: f64 = particles.iter().map(|p| p.mass).sum();
    let centre = if mass > 0.0 && mass.is_finite() {
        particles.iter().map(|p| p.position * p.mass).sum::<Vec3>() / mass
    } else {
        let lo = particles
            .iter()
            .fold(Vec3::repeat(f64::INFINITY), |a, p| a.inf(&p.position));
        let hi = particles
            .iter()
            .fold(Vec3::repeat(f64::NEG_INFINITY), |a, p| a.sup(&p.position));
        0.5 * (lo + hi)
    };
    let mut reach: Vec<f64> = particles
        .iter()
        .map(|p| (p.position - centre).norm() + p.axes.max())
        .collect();
    reach.sort_by(f64::total_cmp);
    let rank = (REACH_QUANTILE * reach.len() as f64).ceil() as usize;
    (centre, reach[rank.clamp(1, reach.len()) - 1])
}

/// The framing of each frame from each snapshot's [`reach_98`] `(centre, reach)`: centred on the snapshot's centre,
/// with half-width `extent` when given, else the largest reach so far plus [`Framing::MARGIN`] (never shrinking;
/// 1 m while every reach is zero). Frame by frame: [`Follower`].
pub fn following_framings(reaches: &[(crate::math::Vec3, f64)], extent: Option<f64>) -> Vec<Framing> {
    let mut follower = Follower::default();
    reaches.iter().map(|r| follower.frame(*r, extent)).collect()
}

/// A [`reach_98`] `(centre, reach)` moved to a fixed `centre`: the reach grows by the distance moved, so the frame
/// still holds what it held.
fn about((com, reach): (crate::math::Vec3, f64), centre: Option<crate::math::Vec3>) -> (crate::math::Vec3, f64) {
    match centre {
        Some(c) => (c, reach + (com - c).norm()),
        None => (com, reach),
    }
}

/// The camera of [`following_framings`], one frame at a time (a run still being written may gain snapshots while
/// it is drawn).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Follower {
    /// The widest half-width so far (m; 0 before any).
    widest: f64,
}

impl Follower {
    /// The framing of the next frame, whose snapshot has `reach` = `(centre, reach)` ([`reach_98`]).
    pub fn frame(&mut self, (centre, reach): (crate::math::Vec3, f64), extent: Option<f64>) -> Framing {
        if reach.is_finite() {
            self.widest = self.widest.max(reach * (1.0 + Framing::MARGIN));
        }
        let half_extent = extent.unwrap_or(if self.widest > 0.0 { self.widest } else { 1.0 });
        Framing { centre, half_extent }
    }
}

/// Renders every snapshot of the run in `dir` into `<frames>/<k>.png` and `<frames>/<gif_name>`, `<frames>` being
/// `opts.out` or `dir/frames`. Holds the lock of the frames directory ([`crate::io::run_lock`], a lock file beside
/// it): a second render into it is refused at once ([`ExportError::Locked`]); the run itself may still be going. A
/// frames directory that exists and is not empty is refused ([`ExportError::Exists`]) unless `opts.force`.
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
        return Err(RenderRunError::Option(format!("--extent-m: must be > 0 m, got {e}")));
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
    // The frames directory is locked through a file beside it (in its parent), not the run: a run still going can
    // be drawn as far as it got. A directory without snapshots is refused below without a lock file left anywhere.
    let (frames_dir, parent, part) = match &opts.out {
        None => (dir.join("frames"), dir.to_path_buf(), "frames".to_string()),
        Some(out) => {
            let name = out.file_name().and_then(|n| n.to_str()).filter(|n| *n != "..");
            let Some(name) = name else {
                return Err(RenderRunError::Option(format!(
                    "--out: expected a directory path ending in a name, got {:?}",
                    out.display().to_string()
                )));
            };
            let parent = out
                .parent()
                .filter(|p| !p.as_os_str().is_empty())
                .unwrap_or(Path::new("."));
            (out.clone(), parent.to_path_buf(), name.to_string())
        }
    };
    let has_snapshots = dir.join("snapshots").is_dir();
    if has_snapshots && !parent.is_dir() {
        crate::io::safe_write::ensure_dir(&parent).map_err(|source| RenderError::Io {
            path: parent.clone(),
            source,
        })?;
    }
    let _lock = has_snapshots
        .then(|| DirLock::acquire_part(&parent, &part))
        .transpose()
        .map_err(ExportError::Locked)?;
    if !opts.force && frames_dir.read_dir().is_ok_and(|mut d| d.next().is_some()) {
        return Err(ExportError::Exists(frames_dir).into());
    }
    let start = Instant::now();

    // Pass 1: the colour range (all snapshots).
    let mut all_values: Vec<f64> = Vec::new();
    visit_snapshots(dir, &mut |_, view| {
        let vals = values(&view, opts.colour, fields.as_ref());
        all_values.extend(vals.into_iter().filter(|v| v.is_finite()));
        Ok(())
    })?;
    let scale = colour_scale(opts.colour, &mut all_values);

    // Pass 2: draw and write.
    crate::io::safe_write::ensure_dir(&frames_dir).map_err(|source| RenderError::Io {
        path: frames_dir.clone(),
        source,
    })?;
    let gif_path = frames_dir.join(&opts.gif_name);
    let mut gif = GifWriter::create(&gif_path, opts.width, opts.height, opts.gif_delay_centiseconds)?;
    let mut frame_ms = Vec::new();
    let mut follower = Follower::default();
    let mut fail: Option<RenderError> = None;
    visit_snapshots(dir, &mut |k, view| {
        let vals = values(&view, opts.colour, fields.as_ref());
        let framing = follower.frame(about(reach_98(&view.particles), opts.centre), opts.extent);
        let camera = Camera::new(opts.view, opts.projection, framing, opts.width, opts.height);
        let t0 = Instant::now();
        let drawn = render_frame_with_walls(
            &frame_bodies(&view, &vals),
            &wall_polygons(view.surfaces.iter().map(|s| &s.mesh)),
            &scale,
            &camera,
            &caption(view.t),
        );
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
        frames_dir,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

    /// Guards `--centre-m` (a drum framed about its axis): every frame is centred there, and its half-width grows by
    /// the distance from the bodies' centre so that it still holds them.
    #[test]
    fn a_fixed_centre_frames_the_bodies_about_it() {
        let mut follower = Follower::default();
        let f = follower.frame(about((Vec3::new(3.0, 0.0, 4.0), 1.0), Some(Vec3::zeros())), None);
        assert_eq!(f.centre, Vec3::zeros());
        assert!((f.half_extent - 6.0 * (1.0 + Framing::MARGIN)).abs() < 1e-12, "{f:?}");
        let g = Follower::default().frame(about((Vec3::new(3.0, 0.0, 4.0), 1.0), None), None);
        assert_eq!(g.centre, Vec3::new(3.0, 0.0, 4.0));
    }
}
