//! Why a picture could not be made or written: the one error of the render pipeline, in a file of its own so that
//! each step (camera, encoder, frame) returns it without naming `render/mod.rs`, which re-exports those steps.

use std::path::PathBuf;

/// Why a picture could not be made or written.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A file could not be created or written.
    #[error("{}", if crate::io::safe_write::is_symlink_refusal(.source) {
        .source.to_string()
    } else {
        format!("cannot write {}: {}", .path.display(), .source)
    })]
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
