//! `rubblepile export FORMAT RUN_DIR` (visualisation files of a finished run), `rubblepile render RUN_DIR`
//! (PNG frames and an animated GIF) and `rubblepile convert FILE --to FILE` (pkdgrav `.ss` files).

use crate::cli::common::CliError;
use crate::cli::render_args::RenderArgs;
use rubblepile::analysis::run_analysis::FragmentFields;
use rubblepile::driver::export::{ExportError, export};
use rubblepile::driver::formats::Formats;
use rubblepile::render::run::{RenderReport, RenderRunError, RenderRunOptions, render_run};
use std::path::PathBuf;

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

/// `rubblepile convert`.
#[derive(Debug, clap::Args)]
pub struct ConvertArgs {
    /// Input: a pkdgrav `.ss` file, or a bodies/particles/snapshot CSV.
    pub input: PathBuf,
    /// Output: a `.csv` (from `.ss`) or a `.ss` file (from CSV).
    #[arg(long, value_name = "FILE")]
    pub to: PathBuf,
    /// `.ss` → CSV: write the sphere engines' particles columns (t,id,mass,radius,…) instead of a bodies file.
    #[arg(long)]
    pub spheres: bool,
    /// Overwrite the output.
    #[arg(long)]
    pub force: bool,
}

/// Runs `export`.
pub fn export_cmd(args: &ExportArgs) -> Result<(), CliError> {
    let formats = Formats::parse(std::slice::from_ref(&args.format))
        .map_err(|e| CliError::usage(e.to_string().replacen("--format", "FORMAT", 1)))?;
    let fields = FragmentFields::read(&args.dir).map_err(CliError::usage)?;
    let extra = |view: &rubblepile::engine::SnapshotView| {
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
                .join(rubblepile::driver::formats::vtk::COLLECTION_FILE)
                .display()
        );
    }
    Ok(())
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
    let r = render_dir(&args.dir, &args.options().map_err(CliError::usage)?)?;
    println!(
        "rendered {} frames into {} in {:.1} s (median {:.0} ms per frame drawn); animation: {}",
        r.frames,
        r.frames_dir.display(),
        r.seconds,
        r.median_frame_ms,
        r.gif.display()
    );
    Ok(())
}

/// Runs `convert`.
pub fn convert_cmd(args: &ConvertArgs) -> Result<(), CliError> {
    let c = rubblepile::driver::convert::convert(&args.input, &args.to, args.spheres, args.force)
        .map_err(CliError::usage)?;
    println!("wrote {} ({} bodies): {}", args.to.display(), c.count, c.note);
    Ok(())
}
