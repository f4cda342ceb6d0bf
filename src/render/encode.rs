//! Writing frames: one PNG file per frame ([`write_png`]) and an animated, endlessly looping GIF of a run
//! ([`GifWriter`]).
//!
//! GIF frames are quantised to 256 colours each with the `gif` crate's NeuQuant at speed [`GIF_SPEED`].

use std::path::{Path, PathBuf};

use crate::io::safe_write::AtomicFile;

use super::error::RenderError;
use super::image::RgbImage;

fn io_error(path: &Path, source: std::io::Error) -> RenderError {
    RenderError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Writes `image` as an 8-bit RGB PNG at `path`.
pub fn write_png(path: &Path, image: &RgbImage) -> Result<(), RenderError> {
    let mut file = AtomicFile::create(path).map_err(|e| io_error(path, e))?;
    let mut encoder = png::Encoder::new(&mut file, image.width, image.height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().map_err(|e| png_error(path, e))?;
    writer.write_image_data(&image.pixels).map_err(|e| png_error(path, e))?;
    writer.finish().map_err(|e| png_error(path, e))?;
    file.finish().map_err(|e| io_error(path, e))
}

/// The PNG encoder reports I/O failures inside its own error type; they are file errors for the caller.
fn png_error(path: &Path, e: png::EncodingError) -> RenderError {
    match e {
        png::EncodingError::IoError(source) => io_error(path, source),
        other => RenderError::Encode(other.to_string()),
    }
}

/// NeuQuant speed of the GIF frames, from 1 (best colours, slowest) to 30 (fastest): an 800×800 frame encodes in
/// well under a second.
pub const GIF_SPEED: i32 = 10;

/// An animated GIF being written, one frame at a time; loops forever.
pub struct GifWriter {
    encoder: gif::Encoder<AtomicFile>,
    path: PathBuf,
    width: u32,
    height: u32,
    delay: u16,
}

impl GifWriter {
    /// Starts a GIF at `path` for frames of `width × height` pixels, each shown `frame_delay_centiseconds`
    /// (1/100 s).
    pub fn create(
        path: &Path,
        width: u32,
        height: u32,
        frame_delay_centiseconds: u16,
    ) -> Result<GifWriter, RenderError> {
        // GIF stores sizes in 16 bits.
        let too_big = || RenderError::Size {
            expected_width: u32::from(u16::MAX),
            expected_height: u32::from(u16::MAX),
            got_width: width,
            got_height: height,
        };
        let w16 = u16::try_from(width).map_err(|_| too_big())?;
        let h16 = u16::try_from(height).map_err(|_| too_big())?;
        let file = AtomicFile::create(path).map_err(|e| io_error(path, e))?;
        let mut encoder = gif::Encoder::new(file, w16, h16, &[]).map_err(|e| gif_error(path, e))?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .map_err(|e| gif_error(path, e))?;
        Ok(GifWriter {
            encoder,
            path: path.to_path_buf(),
            width,
            height,
            delay: frame_delay_centiseconds,
        })
    }

    /// Appends one frame; it must have the size given at creation.
    pub fn add(&mut self, image: &RgbImage) -> Result<(), RenderError> {
        if image.width != self.width || image.height != self.height {
            return Err(RenderError::Size {
                expected_width: self.width,
                expected_height: self.height,
                got_width: image.width,
                got_height: image.height,
            });
        }
        // Sizes were checked to fit u16 at creation.
        let mut frame = gif::Frame::from_rgb_speed(image.width as u16, image.height as u16, &image.pixels, GIF_SPEED);
        frame.delay = self.delay;
        self.encoder.write_frame(&frame).map_err(|e| gif_error(&self.path, e))
    }

    /// Writes the GIF trailer and flushes the file.
    pub fn finish(self) -> Result<(), RenderError> {
        let path = self.path;
        let writer = self.encoder.into_inner().map_err(|e| io_error(&path, e))?;
        writer.finish().map_err(|e| io_error(&path, e))
    }
}

fn gif_error(path: &Path, e: gif::EncodingError) -> RenderError {
    match e {
        gif::EncodingError::Io(source) => io_error(path, source),
        other => RenderError::Encode(other.to_string()),
    }
}
