//! Pictures of runs: bodies drawn as shaded ellipsoids and spheres by exact ray casting, walls as translucent
//! surfaces, written as PNG frames and an animated GIF.
//!
//! The pipeline, one file per step:
//!
//! - [`camera`]: where the picture is taken from ([`View`], [`Projection`]), what it shows ([`Framing`]) and the
//!   primary ray of every pixel ([`Camera`]);
//! - [`raycast`]: exact ray–ellipsoid intersection and the depth-buffered, row-parallel renderer
//!   ([`render_bodies`]);
//! - [`colour`]: the perceptual colour map ([`ColourMap`]) and the mapping of one scalar per body to a colour
//!   ([`ColourScale`], continuous or categorical);
//! - [`walls`]: the run's walls as translucent polygons ([`WallPolygon`]) blended over the bodies;
//! - [`overlay`]: the scale bar ([`ScaleBar`]) and the axis triad ([`Triad`]) on every frame;
//! - [`frame`]: one finished frame ([`render_frame`], [`render_frame_with_walls`]): bodies coloured by a scale, walls,
//!   a colour bar, a caption, a scale bar and an axis triad, as an [`RgbImage`];
//! - [`encode`]: PNG files ([`write_png`]) and animated GIFs ([`GifWriter`]).
//!
//! Units: positions and semi-axes in metres, rotations body → world, image sizes in pixels.
//!
//! All parallel work goes through rayon's global API, so a caller can bound the threads by running inside
//! `rayon::ThreadPoolBuilder::new().num_threads(n).build()?.install(|| …)`.

use std::path::PathBuf;

pub mod args;
pub mod camera;
pub mod colour;
pub mod encode;
pub mod frame;
pub mod image;
pub mod overlay;
pub mod raycast;
pub mod run;
pub mod walls;

pub use camera::{BoundingSphere, Camera, Framing, Projection, Ray, View};
pub use colour::{Category, ColourMap, ColourScale, ScaleKind};
pub use encode::{GifOptions, GifWriter, write_png};
pub use frame::{BACKGROUND, FrameBody, render_frame, render_frame_with_walls};
pub use image::RgbImage;
pub use overlay::{ScaleBar, Triad};
pub use raycast::{Hit, RenderBody, intersect_ellipsoid, render_bodies, render_scene};
pub use walls::{WALL_ALPHA, WALL_COLOUR, WallPolygon, wall_polygons};

/// Why a picture could not be made or written.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A file could not be created or written.
    #[error("cannot write {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// The PNG or GIF encoder failed.
    #[error("image encoding failed: {0}")]
    Encode(String),
    /// Text (caption, colour-bar labels) could not be drawn, or the font could not be registered.
    #[error("cannot draw text on the frame: {0}")]
    Text(String),
    /// An image does not have the size its destination expects (a GIF's frames all share one size), or a size is
    /// beyond what the format can store.
    #[error("image size {got_width}×{got_height} px does not fit: expected {expected_width}×{expected_height} px")]
    Size {
        /// Width expected (pixels).
        expected_width: u32,
        /// Height expected (pixels).
        expected_height: u32,
        /// Width given (pixels).
        got_width: u32,
        /// Height given (pixels).
        got_height: u32,
    },
    /// A `--view` value that is not one of the accepted names.
    #[error("unknown --view `{0}`: expected one of x, y, z, iso")]
    UnknownView(String),
}
