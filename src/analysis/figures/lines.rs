//! A plain x–y chart of several labelled curves and point sets (Richardson11 Figs. 7, 8 and 10: mean heights vs time,
//! KS curves, repose angle vs Froude number), drawn through [`super::style::write_figure`].

use plotters::coord::Shift;
use plotters::prelude::*;

use super::style::{
    Figure, PlotResult, SERIES_COLOURS, draw_err, draw_legend, figure_chart, finite_extent, label_style, padded,
    small_style,
};

/// How one series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mark {
    /// A solid line.
    Line,
    /// A dashed line (references, expectations).
    Dashed,
    /// Filled circles, with vertical error bars when the series has them.
    Points,
}

/// One curve or point set.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// `(x, y)` points.
    pub points: Vec<(f64, f64)>,
    /// Half-heights of error bars (same length as `points`, or empty).
    pub errors: Vec<f64>,
    /// Index into [`SERIES_COLOURS`] (taken modulo its length).
    pub colour: usize,
    /// How it is drawn.
    pub mark: Mark,
}

/// A linear x–y chart.
#[derive(Debug, Clone)]
pub struct LineChart {
    /// Title.
    pub title: String,
    /// x-axis label (with unit).
    pub x_label: String,
    /// y-axis label (with unit).
    pub y_label: String,
    /// The series, drawn in order.
    pub series: Vec<Series>,
    /// Logarithmic x axis (non-positive x are dropped).
    pub log_x: bool,
}

impl Figure for LineChart {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> PlotResult {
        let ok = |&(x, y): &(f64, f64)| x.is_finite() && y.is_finite() && (!self.log_x || x > 0.0);
        let xs = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().filter(|p| ok(p)).map(|p| p.0));
        let ys = self.series.iter().flat_map(|s| {
            s.points
                .iter()
                .enumerate()
                .filter(|(_, p)| ok(p))
                .flat_map(move |(k, p)| {
                    let e = s.errors.get(k).copied().unwrap_or(0.0);
                    [p.1 - e, p.1 + e]
                })
        });
        let (Some((x0, x1)), Some((y0, y1))) = (finite_extent(xs), finite_extent(ys)) else {
            return Err("nothing to plot".into());
        };
        let yr = padded(y0, y1, 0.06);
        let mut chart = figure_chart(root, &self.title, 70);
        if self.log_x {
            let (a, b) = (x0 / 1.5, x1 * 1.5);
            let mut c = chart
                .build_cartesian_2d((a..b).log_scale(), yr.0..yr.1)
                .map_err(draw_err)?;
            c.configure_mesh()
                .x_desc(&self.x_label)
                .y_desc(&self.y_label)
                .axis_desc_style(label_style())
                .label_style(small_style())
                .x_label_formatter(&super::style::log_tick)
                .draw()
                .map_err(draw_err)?;
            draw_series(&mut c, &self.series, &ok)?;
            draw_legend(&mut c, SeriesLabelPosition::UpperLeft)
        } else {
            let xr = padded(x0, x1, 0.02);
            let mut c = chart.build_cartesian_2d(xr.0..xr.1, yr.0..yr.1).map_err(draw_err)?;
            c.configure_mesh()
                .x_desc(&self.x_label)
                .y_desc(&self.y_label)
                .axis_desc_style(label_style())
                .label_style(small_style())
                .draw()
                .map_err(draw_err)?;
            draw_series(&mut c, &self.series, &ok)?;
            draw_legend(&mut c, SeriesLabelPosition::UpperRight)
        }
    }
}

/// Draws `series` on `chart` as their [`Mark`]s say, the points that pass `ok` only, each labelled for the legend.
pub(crate) fn draw_series<'a, DB: DrawingBackend + 'a, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    series: &[Series],
    ok: &dyn Fn(&(f64, f64)) -> bool,
) -> PlotResult
where
    CT: CoordTranslate<From = (f64, f64)>,
{
    for s in series {
        let colour = SERIES_COLOURS[s.colour % SERIES_COLOURS.len()];
        let pts: Vec<(f64, f64)> = s.points.iter().copied().filter(ok).collect();
        let anno = match s.mark {
            Mark::Line => chart
                .draw_series(LineSeries::new(pts, colour.stroke_width(2)))
                .map_err(draw_err)?,
            Mark::Dashed => chart
                .draw_series(DashedLineSeries::new(pts, 6, 4, colour.stroke_width(1)))
                .map_err(draw_err)?,
            Mark::Points => {
                let bars: Vec<_> = s
                    .points
                    .iter()
                    .zip(&s.errors)
                    .filter(|(p, e)| ok(p) && e.is_finite() && **e > 0.0)
                    .map(|(&(x, y), &e)| PathElement::new(vec![(x, y - e), (x, y + e)], colour.stroke_width(1)))
                    .collect();
                chart.draw_series(bars).map_err(draw_err)?;
                chart
                    .draw_series(pts.into_iter().map(|p| Circle::new(p, 4, colour.filled())))
                    .map_err(draw_err)?
            }
        };
        let style = colour.stroke_width(if s.mark == Mark::Dashed { 1 } else { 2 });
        anno.label(&s.label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::figures::style::write_figure;
    use crate::analysis::figures::testing::{assert_figure_files, temp_dir};

    #[test]
    fn lines_dashes_and_error_bars_write_both_files() {
        let dir = temp_dir("lines");
        let chart = LineChart {
            title: "test chart".into(),
            x_label: "x (s)".into(),
            y_label: "y (m)".into(),
            series: vec![
                Series {
                    label: "solid curve".into(),
                    points: (0..50)
                        .map(|k| (k as f64 * 0.1 + 0.1, (k as f64 * 0.1).sin()))
                        .collect(),
                    errors: Vec::new(),
                    colour: 0,
                    mark: Mark::Line,
                },
                Series {
                    label: "dashed reference".into(),
                    points: vec![(0.1, 0.5), (5.0, 0.5)],
                    errors: Vec::new(),
                    colour: 1,
                    mark: Mark::Dashed,
                },
                Series {
                    label: "points with bars".into(),
                    points: vec![(0.5, 0.2), (1.0, -0.3), (2.0, f64::NAN)],
                    errors: vec![0.1, 0.2, 0.1],
                    colour: 2,
                    mark: Mark::Points,
                },
            ],
            log_x: false,
        };
        write_figure(&dir, "lin", &chart).unwrap();
        assert_figure_files(
            &dir,
            "lin",
            &["test chart", "solid curve", "dashed reference", "points with bars"],
        );
        let log = LineChart { log_x: true, ..chart };
        write_figure(&dir, "log", &log).unwrap();
        assert_figure_files(&dir, "log", &["solid curve"]);
        let empty = LineChart {
            series: Vec::new(),
            ..log
        };
        assert!(write_figure(&dir, "empty", &empty).is_err());
    }
}
