//! The command-line arguments of `rubblepile render` and the options they ask for (errors name the flag).

use std::path::PathBuf;

use rubblepile::render::run::{ColourBy, RenderRunOptions};
use rubblepile::render::{Projection, RenderError, View};

/// Largest `--extent-m` accepted (m): 1e300, beyond it the camera's scale underflows.
pub const MAX_EXTENT_M: f64 = 1e300;

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
    #[arg(long = "perspective-deg", value_name = "DEGREES")]
    pub perspective: Option<f64>,
    /// Fixed half-width of the picture (m) about each snapshot's centre of mass [default: follows the bodies,
    /// growing to hold 98 % of them and never shrinking].
    #[arg(long = "extent-m", value_name = "METRES")]
    pub extent: Option<f64>,
    /// Fixed centre X,Y,Z of every frame (m), e.g. a drum's axis [default: each snapshot's centre of mass].
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true, value_name = "X,Y,Z")]
    pub centre_m: Option<Vec<f64>>,
    /// File name of the animation in the frames directory.
    #[arg(long, default_value = "run.gif")]
    pub gif: String,
    /// Directory of the frames and the animation, so a second view need not overwrite the first [default: DIR/frames].
    #[arg(long, value_name = "FRAMES_DIR")]
    pub out: Option<PathBuf>,
    /// Overwrite an earlier frames directory.
    #[arg(long)]
    pub force: bool,
}

impl RenderArgs {
    /// The options these arguments ask for (errors name the flag).
    pub fn options(&self) -> Result<RenderRunOptions, String> {
        // Said exactly: `"iso "` is a typo the reader should see, not a view taken on trust.
        if self.view.trim() != self.view || self.view.is_empty() {
            return Err(format!(
                "--view: expected x, y, z or iso (without spaces), got {:?}",
                self.view
            ));
        }
        let view: View = self.view.parse().map_err(|e: RenderError| e.to_string())?;
        if let Some(e) = self.extent
            && !(rubblepile::io::limits::MIN_MEANINGFUL..=MAX_EXTENT_M).contains(&e)
        {
            return Err(format!(
                "--extent-m: expected a half-width in metres from {:e} to {MAX_EXTENT_M:e}, got {}",
                rubblepile::io::limits::MIN_MEANINGFUL,
                rubblepile::io::scene_file::fmt_num(e)
            ));
        }
        let centre = match self.centre_m.as_deref() {
            None => None,
            Some([x, y, z]) if [x, y, z].iter().all(|v| v.is_finite()) => Some(rubblepile::math::Vec3::new(*x, *y, *z)),
            Some(v) => {
                return Err(format!(
                    "--centre-m: expected three finite coordinates X,Y,Z in metres, got {v:?}"
                ));
            }
        };
        let colour: ColourBy = self.color.parse()?;
        let bad_size = || format!("--size: expected WIDTHxHEIGHT in pixels, got {:?}", self.size);
        let (w, h) = self.size.split_once('x').ok_or_else(bad_size)?;
        let (width, height) = (w.parse().map_err(|_| bad_size())?, h.parse().map_err(|_| bad_size())?);
        let projection = match self.perspective {
            None => Projection::Orthographic,
            Some(f) if f.is_finite() && f > 1.0 && f < 170.0 => Projection::Perspective { fov_deg: f },
            Some(f) => {
                return Err(format!("--perspective-deg: expected 1 to 170 degrees, got {f}"));
            }
        };
        if self.gif.contains(['/', '\\']) || !self.gif.ends_with(".gif") {
            return Err(format!(
                "--gif: expected a file name ending in .gif, got {:?}",
                self.gif
            ));
        }
        Ok(RenderRunOptions {
            view,
            projection,
            width,
            height,
            colour,
            extent: self.extent,
            centre,
            gif_name: self.gif.clone(),
            out: self.out.clone(),
            force: self.force,
            ..RenderRunOptions::default()
        })
    }
}
