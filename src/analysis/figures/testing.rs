//! Helpers for the figure tests (test builds only): temporary directories and checks of the written files (the
//! PNG size read from its IHDR chunk, per the PNG specification). In a file of their own so that the figure files'
//! tests use them without naming `figures/mod.rs`, which re-exports those files' writers.

use std::path::{Path, PathBuf};

use crate::analysis::figures::style::{FIGURE_SIZE, Figure, write_figure};

/// A fresh, empty temporary directory for one test.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rubblepile-figures-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Width and height from a PNG file's signature and IHDR chunk (the first chunk, by the PNG spec).
pub fn png_dimensions(bytes: &[u8]) -> Option<(u32, u32)> {
    const SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n'];
    if bytes.len() < 24 || bytes[..8] != SIGNATURE || &bytes[12..16] != b"IHDR" {
        return None;
    }
    let be = |k: usize| u32::from_be_bytes([bytes[k], bytes[k + 1], bytes[k + 2], bytes[k + 3]]);
    Some((be(16), be(20)))
}

/// Asserts that `dir/<stem>.svg` and `dir/<stem>.png` exist, the PNG has [`FIGURE_SIZE`] and more than one
/// colour's worth of data (text and lines drawn), and the SVG contains every one of `labels`; returns the
/// SVG text.
pub fn assert_figure_files(dir: &Path, stem: &str, labels: &[&str]) -> String {
    let png = std::fs::read(dir.join(format!("{stem}.png"))).unwrap_or_else(|e| panic!("{stem}.png: {e}"));
    assert_eq!(
        png_dimensions(&png),
        Some(FIGURE_SIZE),
        "{stem}.png: not a PNG of the figure size"
    );
    assert!(png.len() > 5_000, "{stem}.png: only {} bytes, nearly blank", png.len());
    let svg = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).unwrap_or_else(|e| panic!("{stem}.svg: {e}"));
    assert!(
        svg.starts_with("<svg") || svg.contains("<svg"),
        "{stem}.svg: not an SVG"
    );
    for label in labels {
        assert!(svg.contains(label), "{stem}.svg lacks {label:?}");
    }
    svg
}

/// Writes `figure` as `stem` into a fresh temporary directory, checks its files ([`assert_figure_files`] with
/// `labels`), removes the directory and returns the SVG text.
pub fn assert_writes(stem: &str, figure: &impl Figure, labels: &[&str]) -> String {
    let dir = temp_dir(stem);
    write_figure(&dir, stem, figure).unwrap();
    let svg = assert_figure_files(&dir, stem, labels);
    let _ = std::fs::remove_dir_all(&dir);
    svg
}

#[test]
fn png_dimensions_reads_ihdr_and_rejects_other_files() {
    let mut png = vec![0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n', 0, 0, 0, 13];
    png.extend_from_slice(b"IHDR");
    png.extend_from_slice(&800u32.to_be_bytes());
    png.extend_from_slice(&560u32.to_be_bytes());
    assert_eq!(png_dimensions(&png), Some((800, 560)));
    assert_eq!(png_dimensions(b"<svg></svg> and some more bytes here"), None);
}
