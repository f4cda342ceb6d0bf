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

pub mod camera;
pub mod colour;
pub mod encode;
pub mod error;
pub mod frame;
pub mod image;
pub mod light;
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

pub use error::RenderError;
