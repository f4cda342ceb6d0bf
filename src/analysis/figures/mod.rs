//! Figures of the Roig03 §4 post-processing (Roig et al. 2003, Icarus 165, Figs. 2–9), each written as SVG
//! and PNG with titled, unit-labelled axes and a legend.
//!
//! * [`run_figures`]: one run — Fig. 2 `energy_partition`, Fig. 3 `velocity_field`, Fig. 4
//!   `ejection_vs_size`, Fig. 6 `spin_histogram`, Fig. 8 `spin_vs_size`, Fig. 9 `rotation_mode_vs_size`, and `sfd` (below).
//! * [`campaign_figures`]: a campaign — Fig. 5 `bound_fraction_vs_q`, Fig. 7 `spin_distributions`.
//! * [`sfd`]: the cumulative mass distribution of a snapshot's clumps (`sfd`).
//! * [`spinup_figures`]: Zhang17 Fig. 5-style time series of a spin-up run.
//! * [`stacked`]: panels of lines over one x axis (Zhang17 Fig. 22: the holds of a T_c,3 search).
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
pub mod stacked;
pub mod style;

pub use campaign_figures::{write_campaign_figures, write_spin_distributions};
pub use run_figures::write_run_figures;

/// Helpers for the figure tests: temporary directories and checks of the written files.
#[cfg(test)]
pub(crate) mod testing;
