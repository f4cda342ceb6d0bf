//! Zhang17 Fig. 5-style time series of one spin-up run (from its `spinup.csv`): spin period with the path, axis
//! ratios b/a and c/a, interior packing fraction η_B, and the largest mobilized friction angle θ_max, stacked
//! against time.

use plotters::coord::Shift;
use plotters::prelude::*;

use rubblepile::analysis::figures::style::{
    Figure, PlotResult, SERIES_COLOURS, draw_err, draw_legend, finite_extent, label_style, padded, small_style,
    title_style,
};
use rubblepile::analysis::spinup_diagnostics::SpinupSample;

/// The four stacked panels of one run.
pub struct SpinupTimeSeries {
    /// Title (model and path).
    pub title: String,
    /// The run's samples.
    pub samples: Vec<SpinupSample>,
}

type Panel<'a> = (&'a str, Vec<(&'a str, fn(&SpinupSample) -> f64)>);

impl Figure for SpinupTimeSeries {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> PlotResult {
        if self.samples.len() < 2 {
            return Err("fewer than 2 samples".into());
        }
        let root = root.titled(&self.title, title_style()).map_err(draw_err)?;
        let panels: [Panel; 4] = [
            (
                "T (h)",
                vec![("spin period", |s| s.period_h), ("path", |s| s.path_period_h)],
            ),
            ("axis ratio", vec![("b/a", |s| s.b_over_a), ("c/a", |s| s.c_over_a)]),
            ("η_B", vec![("interior packing fraction", |s| s.packing_fraction)]),
            ("θ_max (°)", vec![("max friction angle", |s| s.theta_max_deg)]),
        ];
        let areas = root.split_evenly((4, 1));
        let t1 = self.samples.last().map(|s| s.t / 3600.0).unwrap_or(1.0);
        for (k, ((name, series), area)) in panels.iter().zip(areas.iter()).enumerate() {
            let values = series
                .iter()
                .flat_map(|(_, f)| self.samples.iter().map(f))
                .collect::<Vec<_>>();
            let Some((lo, hi)) = finite_extent(values) else {
                continue;
            };
            let (lo, hi) = padded(lo, hi, 0.08);
            let mut chart = ChartBuilder::on(area)
                .margin(4)
                .margin_right(20)
                .x_label_area_size(if k == 3 { 34 } else { 14 })
                .y_label_area_size(70)
                .build_cartesian_2d(0.0..t1, lo..hi)
                .map_err(draw_err)?;
            let mut mesh = chart.configure_mesh();
            mesh.y_desc(*name)
                .axis_desc_style(label_style())
                .label_style(small_style())
                .y_labels(4)
                .y_label_formatter(&|v| format!("{v:.4}"));
            if k == 3 {
                mesh.x_desc("time t (h)");
            } else {
                mesh.x_label_formatter(&|_| String::new());
            }
            mesh.draw().map_err(draw_err)?;
            for (j, (label, f)) in series.iter().enumerate() {
                let colour = SERIES_COLOURS[j % SERIES_COLOURS.len()];
                let pts: Vec<(f64, f64)> = self
                    .samples
                    .iter()
                    .map(|s| (s.t / 3600.0, f(s)))
                    .filter(|p| p.1.is_finite())
                    .collect();
                chart
                    .draw_series(LineSeries::new(pts, colour.stroke_width(2)))
                    .map_err(draw_err)?
                    .label(*label)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2)));
            }
            draw_legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        }
        Ok(())
    }
}
