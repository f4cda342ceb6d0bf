//! Pictures of runs: ellipsoids and spheres shaded by exact ray casting, walls as translucent surfaces, as PNG frames
//! and an animated GIF. One file per step: [`camera`] ([`View`], [`Projection`], [`Framing`], the primary rays of
//! [`Camera`]); [`raycast`] (exact ray–ellipsoid intersection, depth-buffered row-parallel [`render_bodies`]);
//! [`colour`] ([`ColourMap`], [`ColourScale`]); [`walls`] ([`WallPolygon`]); [`overlay`] ([`ScaleBar`], [`Triad`]);
//! [`frame`] ([`render_frame`], [`render_frame_with_walls`], an [`RgbImage`]); [`encode`] ([`write_png`],
//! [`GifWriter`]).
//!
//! Units: positions and semi-axes in metres, rotations body → world, image sizes in pixels. Parallel work uses
//! rayon's global API, so a caller bounds the threads with `ThreadPoolBuilder::new().num_threads(n).build()?.install`.

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
pub use encode::{GifWriter, write_png};
pub use frame::{BACKGROUND, FrameBody, render_frame, render_frame_with_walls};
pub use image::RgbImage;
pub use overlay::{ScaleBar, Triad};
pub use raycast::{RenderBody, render_bodies, render_scene};
pub use walls::{WALL_ALPHA, WALL_COLOUR, WallPolygon, wall_polygons};

pub use error::RenderError;
