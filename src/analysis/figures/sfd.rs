//! The cumulative size–frequency distribution of a snapshot's clumps (`analysis/sfd.svg` and `.png`): `N(>m)`,
//! the number of clumps of mass ≥ `m`, against `m`, log–log, for every clump and for the clumps that escape the
//! largest remnant ([`crate::analysis::clumps`]), as impact studies plot their remnants (e.g. Michel et al.
//! 2001, Science 294, Fig. 2; there against diameter).

use plotters::coord::Shift;
use plotters::prelude::*;

use super::style::{Figure, PlotResult, SERIES_COLOURS, draw_err, draw_legend, log_log_chart, padded_log};
use crate::analysis::clumps::{ClumpReport, Fate};

/// `(m, N(≥ m))` for the masses `masses` (kg): one point per mass, heaviest first (N = 1, 2, …).
pub fn cumulative_counts(masses: &[f64]) -> Vec<(f64, f64)> {
    let mut m: Vec<f64> = masses.iter().copied().filter(|m| m.is_finite() && *m > 0.0).collect();
    m.sort_by(|a, b| b.total_cmp(a));
    m.into_iter().enumerate().map(|(k, m)| (m, (k + 1) as f64)).collect()
}

/// The figure: the cumulative counts of all clumps and of the escaping ones at time `t` (s).
#[derive(Debug, Clone)]
pub struct SizeFrequency {
    /// Time of the snapshot (s).
    pub t: f64,
    /// `(label, points)` of each series.
    pub series: Vec<(String, Vec<(f64, f64)>)>,
}

impl SizeFrequency {
    /// The two series of `report` at time `t` (s): every clump, and those escaping the largest remnant.
    pub fn of(report: &ClumpReport, t: f64) -> SizeFrequency {
        let all: Vec<f64> = report.clumps.iter().map(|c| c.mass_kg).collect();
        let escaping: Vec<f64> = report
            .clumps
            .iter()
            .filter(|c| c.fate == Fate::Escaping)
            .map(|c| c.mass_kg)
            .collect();
        SizeFrequency {
            t,
            series: vec![
                (format!("all clumps ({})", all.len()), cumulative_counts(&all)),
                (
                    format!("escaping clumps ({})", escaping.len()),
                    cumulative_counts(&escaping),
                ),
            ],
        }
    }
}

impl Figure for SizeFrequency {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> PlotResult {
        let points = || self.series.iter().flat_map(|s| s.1.iter());
        let (Some(m0), Some(m1)) = (
            points().map(|p| p.0).min_by(f64::total_cmp),
            points().map(|p| p.0).max_by(f64::total_cmp),
        ) else {
            return Err("no clumps to plot".into());
        };
        let n1 = points().map(|p| p.1).fold(1.0, f64::max);
        let (xr, yr) = (padded_log(m0, m1, 1.5), padded_log(0.8, n1, 1.3));
        let title = format!("Cumulative mass distribution of clumps at t = {} s", self.t);
        let mut chart = log_log_chart(
            root,
            &title,
            70,
            (xr, yr),
            "clump mass m (kg)",
            "N(≥ m), number of clumps",
        )?;
        for (k, (label, pts)) in self.series.iter().enumerate() {
            let colour = SERIES_COLOURS[k % SERIES_COLOURS.len()];
            // a cumulative count is a staircase: N steps up by one at each mass, going down in mass
            let mut steps = Vec::with_capacity(2 * pts.len());
            for (j, &(m, n)) in pts.iter().enumerate() {
                steps.push((m, if j == 0 { n } else { pts[j - 1].1 }));
                steps.push((m, n));
            }
            chart
                .draw_series(LineSeries::new(steps, colour.stroke_width(2)))
                .map_err(draw_err)?;
            chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 3, colour.filled())))
                .map_err(draw_err)?
                .label(label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
        }
        draw_legend(&mut chart, SeriesLabelPosition::UpperRight)
    }
}

impl crate::analysis::run_analysis::ClumpRunAnalysis {
    /// Draws the size–frequency figure into `dir/analysis` (`sfd.svg`, `sfd.png`) and returns the line `analyze`
    /// prints; a figure that cannot be drawn is a warning on stderr, not an error (the tables are written).
    pub fn write_figure_and_describe(&self, analysis_dir: &std::path::Path) -> String {
        let figure = SizeFrequency::of(&self.clump_report, self.t_at);
        let drawn = crate::analysis::figures::style::write_figure(analysis_dir, "sfd", &figure);
        if let Err(why) = &drawn {
            crate::io::messages::emit(
                crate::io::messages::Channel::Warning,
                &format!("warning: figure not drawn: sfd: {why}"),
            );
        }
        format!(
            "clumps at t = {} s: {}; wrote {} (clumps.csv, analysis.json{})",
            self.t_at,
            self.clump_report.summary_line(),
            analysis_dir.display(),
            if drawn.is_ok() { ", sfd.svg, sfd.png" } else { "" }
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::figures::style::write_figure;
    use crate::analysis::figures::testing::{assert_figure_files, temp_dir};

    #[test]
    fn cumulative_counts_count_down_the_masses() {
        assert_eq!(
            cumulative_counts(&[1.0, 5.0, 0.0, 3.0]),
            vec![(5.0, 1.0), (3.0, 2.0), (1.0, 3.0)]
        );
    }

    #[test]
    fn size_frequency_writes_both_files() {
        let dir = temp_dir("sfd");
        let figure = SizeFrequency {
            t: 400.0,
            series: vec![
                ("all clumps (3)".into(), cumulative_counts(&[1e12, 3e10, 2e10])),
                ("escaping clumps (1)".into(), cumulative_counts(&[2e10])),
            ],
        };
        write_figure(&dir, "sfd", &figure).unwrap();
        assert_figure_files(
            &dir,
            "sfd",
            &["all clumps (3)", "escaping clumps (1)", "clump mass m (kg)"],
        );
        let empty = SizeFrequency {
            t: 0.0,
            series: vec![("all clumps (0)".into(), Vec::new())],
        };
        assert!(write_figure(&dir, "empty", &empty).is_err());
    }
}
