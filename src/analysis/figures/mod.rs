//! Figures of the Roig03 §4 post-processing (Roig et al. 2003, Icarus 165, Figs. 2–9), each written as SVG
//! and PNG with titled, unit-labelled axes and a legend.
//!
//! * [`run_figures`]: one run — Fig. 2 `energy_partition`, Fig. 3 `velocity_field`, Fig. 4
//!   `ejection_vs_size`, Fig. 6 `spin_histogram`, Fig. 8 `spin_vs_size`, Fig. 9 `rotation_mode_vs_size`, and `sfd` (below).
//! * [`campaign_figures`]: a campaign — Fig. 5 `bound_fraction_vs_q`, Fig. 7 `spin_distributions`.
//! * [`sfd`]: the cumulative mass distribution of a snapshot's clumps (`sfd`).
//! * [`spinup_figures`]: Zhang17 Fig. 5-style time series of a spin-up run.
//! * [`energy`]: the data of Fig. 2 (energies and momentum drift over time from `timeseries.csv` and
//!   `tracks.csv`).
//! * [`style`]: the embedded font, the common look, and [`style::write_figure`], which renders each figure
//!   once per backend so the SVG and PNG files cannot diverge.
//!
//! A figure that cannot be drawn (missing input, nothing to plot) is reported as a one-line warning and the
//! others are still written; nothing here panics on bad data.

pub mod campaign_figures;
pub mod energy;
pub mod lines;
pub mod run_figures;
pub mod sfd;
pub mod spinup_figures;
pub mod style;

pub use campaign_figures::{write_campaign_figures, write_spin_distributions};
pub use run_figures::write_run_figures;

/// Helpers for the figure tests: temporary directories and checks of the written files.
#[cfg(test)]
pub(crate) mod testing {
    use std::path::{Path, PathBuf};

    use super::style::FIGURE_SIZE;

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
        let svg =
            std::fs::read_to_string(dir.join(format!("{stem}.svg"))).unwrap_or_else(|e| panic!("{stem}.svg: {e}"));
        assert!(
            svg.starts_with("<svg") || svg.contains("<svg"),
            "{stem}.svg: not an SVG"
        );
        for label in labels {
            assert!(svg.contains(label), "{stem}.svg lacks {label:?}");
        }
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
}
