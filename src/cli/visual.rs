//! `rubblepile export FORMAT RUN_DIR` (visualisation files of a finished run) and `rubblepile render RUN_DIR`
//! (PNG frames and an animated GIF).

use std::path::PathBuf;

use crate::analysis::run_analysis::FragmentFields;
use crate::cli::CliError;
use crate::driver::export::{ExportError, export};
use crate::driver::formats::Formats;
use crate::render::run::{ColourBy, RenderReport, RenderRunError, RenderRunOptions, render_run};
use crate::render::{Projection, View};

/// `rubblepile export`.
#[derive(Debug, clap::Args)]
pub struct ExportArgs {
    /// Format: `vtk` (ParaView: DIR/vtk/*.vtp and DIR/vtk/run.pvd) or `xyz` (DIR/snapshots/<k>.xyz).
    pub format: String,
    /// The run directory (any engine).
    pub dir: PathBuf,
    /// Overwrite files an earlier export (or the run itself) wrote in this format.
    #[arg(long)]
    pub force: bool,
}

/// Runs `export`.
pub fn export_cmd(args: &ExportArgs) -> Result<(), CliError> {
    let formats = Formats::parse(std::slice::from_ref(&args.format))
        .map_err(|e| CliError::usage(e.to_string().replacen("--format", "FORMAT", 1)))?;
    let fields = FragmentFields::read(&args.dir).map_err(CliError::usage)?;
    let extra = |view: &crate::engine::SnapshotView| {
        Ok(fields
            .as_ref()
            .map(|f| f.columns(view.particles.iter().map(|p| p.id)))
            .unwrap_or_default())
    };
    let report = export(&args.dir, formats, args.force, &extra).map_err(|e| match e {
        ExportError::Io { .. } => CliError::failed(e),
        _ => CliError::usage(e),
    })?;
    println!(
        "exported {} snapshots as {} in {:.2} s ({:.1} MB, {:.0} MB/s){}",
        report.snapshots,
        args.format,
        report.seconds,
        report.bytes as f64 / 1e6,
        report.bytes as f64 / 1e6 / report.seconds.max(1e-9),
        if fields.is_some() {
            "; with the analysis' bound and ejection_speed per body"
        } else {
            ""
        }
    );
    if args.format == "vtk" {
        println!(
            "open {} in ParaView",
            args.dir
                .join("vtk")
                .join(crate::driver::formats::vtk::COLLECTION_FILE)
                .display()
        );
    }
    Ok(())
}

/// `rubblepile render`.
#[derive(Debug, clap::Args)]
pub struct RenderArgs {
    /// The run directory (any engine).
    pub dir: PathBuf,
    /// Direction of view: x, y, z (looking down each axis) or iso.
    #[arg(long, default_value = "iso")]
    pub view: String,
    /// Colour of the bodies: speed (m/s), bound (after `rubblepile analyze`), spin (rev/day) or id.
    #[arg(long, default_value = "speed")]
    pub color: String,
    /// Frame size in pixels, WIDTHxHEIGHT.
    #[arg(long, default_value = "800x800")]
    pub size: String,
    /// Perspective camera with this field of view (degrees) instead of the orthographic one.
    #[arg(long, value_name = "DEGREES")]
    pub perspective: Option<f64>,
    /// Half-width of the picture (m) about the first snapshot's centre [default: the first snapshot's bodies].
    #[arg(long, value_name = "METRES")]
    pub extent: Option<f64>,
    /// File name of the animation in DIR/frames.
    #[arg(long, default_value = "run.gif")]
    pub gif: String,
    /// Overwrite an earlier DIR/frames.
    #[arg(long)]
    pub force: bool,
}

impl RenderArgs {
    /// The options these arguments ask for (errors name the flag).
    pub fn options(&self) -> Result<RenderRunOptions, CliError> {
        let view: View = self.view.parse().map_err(CliError::usage)?;
        let colour: ColourBy = self.color.parse().map_err(CliError::usage)?;
        let bad_size = || CliError::usage(format!("--size: expected WIDTHxHEIGHT in pixels, got {:?}", self.size));
        let (w, h) = self.size.split_once('x').ok_or_else(bad_size)?;
        let (width, height) = (w.parse().map_err(|_| bad_size())?, h.parse().map_err(|_| bad_size())?);
        let projection = match self.perspective {
            None => Projection::Orthographic,
            Some(f) if f.is_finite() && f > 1.0 && f < 170.0 => Projection::Perspective { fov_deg: f },
            Some(f) => {
                return Err(CliError::usage(format!(
                    "--perspective: expected 1 to 170 degrees, got {f}"
                )));
            }
        };
        if self.gif.contains(['/', '\\']) || !self.gif.ends_with(".gif") {
            return Err(CliError::usage(format!(
                "--gif: expected a file name ending in .gif, got {:?}",
                self.gif
            )));
        }
        Ok(RenderRunOptions {
            view,
            projection,
            width,
            height,
            colour,
            extent: self.extent,
            gif_name: self.gif.clone(),
            force: self.force,
            ..RenderRunOptions::default()
        })
    }
}

/// Renders the run in `dir` with `opts`; errors mapped to exit codes (bad input 2, failures 1).
pub fn render_dir(dir: &std::path::Path, opts: &RenderRunOptions) -> Result<RenderReport, CliError> {
    render_run(dir, opts).map_err(|e| match e {
        RenderRunError::Render(_) => CliError::failed(e),
        _ => CliError::usage(e),
    })
}

/// Runs `render`.
pub fn render_cmd(args: &RenderArgs) -> Result<(), CliError> {
    let r = render_dir(&args.dir, &args.options()?)?;
    println!(
        "rendered {} frames into {} in {:.1} s (median {:.0} ms per frame drawn); animation: {}",
        r.frames,
        args.dir.join("frames").display(),
        r.seconds,
        r.median_frame_ms,
        r.gif.display()
    );
    Ok(())
}
