//! The image type every step of a frame passes along: an 8-bit RGB pixel buffer, written by the ray caster
//! (`raycast.rs`), the overlays and the frame, and encoded as PNG or GIF (`encode.rs`). On its own so
//! that the ray caster and the frame, which both draw into it, need not import each other.

/// An RGB image, 8 bits per channel.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RgbImage {
    /// Width (pixels).
    pub width: u32,
    /// Height (pixels).
    pub height: u32,
    /// RGB triplets, row-major, top row first (`3·width·height` bytes).
    pub pixels: Vec<u8>,
}

impl RgbImage {
    /// A `width × height` image filled with `fill`.
    pub fn new(width: u32, height: u32, fill: [u8; 3]) -> RgbImage {
        let pixels = fill.repeat(width as usize * height as usize);
        RgbImage { width, height, pixels }
    }

    /// Colour of pixel `(x, y)` (`(0, 0)` = top left). Panics outside the image.
    pub fn get(&self, x: u32, y: u32) -> [u8; 3] {
        let i = self.index(x, y);
        [self.pixels[i], self.pixels[i + 1], self.pixels[i + 2]]
    }

    /// Sets pixel `(x, y)`. Panics outside the image.
    pub fn set(&mut self, x: u32, y: u32, colour: [u8; 3]) {
        let i = self.index(x, y);
        self.pixels[i..i + 3].copy_from_slice(&colour);
    }

    fn index(&self, x: u32, y: u32) -> usize {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside {}×{}",
            self.width,
            self.height
        );
        3 * (y as usize * self.width as usize + x as usize)
    }
}
