//! Panels of line series stacked over one shared x axis (Zhang17 Fig. 22: θ_max, η_B and the coordination number
//! of several holds against time), drawn through [`super::style::write_figure`].

use plotters::coord::Shift;
use plotters::prelude::*;

use super::lines::{Series, draw_series};
use super::style::{
    Figure, PlotResult, draw_err, draw_legend, finite_extent, label_style, padded, small_style, title_style,
};

/// One panel: its y label (with unit) and its series.
#[derive(Debug, Clone)]
pub struct Panel {
    /// y-axis label.
    pub y_label: String,
    /// The series, drawn in order; the first panel's labels make the legend.
    pub series: Vec<Series>,
}

/// Panels stacked top to bottom over one x range; the x label under the last.
#[derive(Debug, Clone)]
pub struct StackedLines {
    /// Title.
    pub title: String,
    /// x-axis label (with unit).
    pub x_label: String,
    /// The panels, top first.
    pub panels: Vec<Panel>,
}

impl Figure for StackedLines {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> PlotResult {
        let ok = |&(x, y): &(f64, f64)| x.is_finite() && y.is_finite();
        let xs = self.panels.iter().flat_map(|p| {
            p.series
                .iter()
                .flat_map(|s| s.points.iter().filter(|q| ok(q)).map(|q| q.0))
        });
        let Some((x0, x1)) = finite_extent(xs) else {
            return Err("nothing to plot".into());
        };
        let xr = padded(x0, x1, 0.02);
        let root = root.titled(&self.title, title_style()).map_err(draw_err)?;
        let areas = root.split_evenly((self.panels.len().max(1), 1));
        let last = self.panels.len().saturating_sub(1);
        for (k, (panel, area)) in self.panels.iter().zip(areas.iter()).enumerate() {
            let ys = panel
                .series
                .iter()
                .flat_map(|s| s.points.iter().filter(|q| ok(q)).map(|q| q.1));
            let Some((y0, y1)) = finite_extent(ys) else {
                continue;
            };
            let yr = padded(y0, y1, 0.08);
            let mut chart = ChartBuilder::on(area)
                .margin(4)
                .margin_right(20)
                .x_label_area_size(if k == last { 34 } else { 14 })
                .y_label_area_size(70)
                .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
                .map_err(draw_err)?;
            let mut mesh = chart.configure_mesh();
            mesh.y_desc(&panel.y_label)
                .axis_desc_style(label_style())
                .label_style(small_style())
                .y_labels(4);
            if k == last {
                mesh.x_desc(&self.x_label);
            } else {
                mesh.x_label_formatter(&|_| String::new());
            }
            mesh.draw().map_err(draw_err)?;
            draw_series(&mut chart, &panel.series, &ok)?;
            if k == 0 {
                draw_legend(&mut chart, SeriesLabelPosition::UpperRight)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::figures::lines::Mark;
    use crate::analysis::figures::style::write_figure;
    use crate::analysis::figures::testing::{assert_figure_files, temp_dir};

    #[test]
    fn stacked_panels_write_both_files_and_refuse_an_empty_figure() {
        let dir = temp_dir("stacked");
        let line = |label: &str, colour, slope: f64| Series {
            label: label.into(),
            points: (0..20).map(|i| (i as f64, 1.0 + slope * i as f64)).collect(),
            errors: vec![],
            colour,
            mark: Mark::Line,
        };
        let fig = StackedLines {
            title: "two panels".into(),
            x_label: "t (h)".into(),
            panels: vec![
                Panel {
                    y_label: "a".into(),
                    series: vec![line("rising", 0, 0.1), line("flat", 1, 0.0)],
                },
                Panel {
                    y_label: "b".into(),
                    series: vec![line("falling", 0, -0.1)],
                },
            ],
        };
        write_figure(&dir, "stacked", &fig).unwrap();
        assert_figure_files(&dir, "stacked", &["rising", "flat"]);
        let empty = StackedLines { panels: vec![], ..fig };
        assert!(write_figure(&dir, "empty", &empty).is_err());
    }
}
