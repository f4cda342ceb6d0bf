//! Figures of the Roig03 §4 post-processing (Figs. 2–9) and of Zhang17 runs, each as SVG and PNG with titled,
//! unit-labelled axes: [`run_figures`] (one run: Figs. 2, 3, 4, 6, 8, 9 and `sfd`), [`campaign_figures`] (Fig. 5
//! `bound_fraction_vs_q`, Fig. 7 `spin_distributions`), [`sfd`] (clump mass distribution), [`stacked`] (Zhang17 Fig. 22 panels), [`energy`] (Fig. 2's data), [`style`]
//! (font, look, [`style::write_figure`] renders each figure once per backend so SVG and PNG agree). A figure that
//! cannot be drawn is a one-line warning, the others are still written; nothing panics on bad data.

pub mod by_field;
pub mod campaign_figures;
pub mod energy;
pub mod lines;
pub mod run_figures;
pub mod sfd;
pub mod stacked;
pub mod style;

pub use campaign_figures::{write_campaign_figures, write_spin_distributions};
pub use run_figures::write_run_figures;

/// Helpers for the figure tests: temporary directories and checks of the written files.
#[cfg(test)]
pub(crate) mod testing;
