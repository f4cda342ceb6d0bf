//! A campaign's outcomes against one field (`analysis/campaign_by_<FIELD>.svg` and `.png`, from
//! [`crate::analysis::campaign_by::ByTable`]): the largest remnant and bound fractions of every run (small marks:
//! the seeds' scatter) and per row their mean with a standard-error bar.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::style::{
    Figure, PlotResult, SERIES_COLOURS, draw_err, draw_legend, figure_chart, finite_extent, label_style, padded,
    small_style,
};
use crate::analysis::campaign_by::ByTable;

/// The figure of a table whose field is numeric.
#[derive(Debug, Clone)]
pub struct OutcomesByField<'a> {
    /// The table.
    pub table: &'a ByTable,
    /// Time of the analysed snapshots (s).
    pub t_at: f64,
}

/// The outcomes drawn: their index in [`crate::analysis::campaign_by::BY_METRICS`] and label.
const DRAWN: [(usize, &str); 2] = [(0, "largest remnant / total mass"), (1, "bound fraction of the target")];

impl Figure for OutcomesByField<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> PlotResult {
        let rows = &self.table.rows;
        if rows.iter().any(|r| r.x.is_none()) {
            return Err(format!("{} is not numeric: see the table", self.table.field).into());
        }
        let Some((x0, x1)) = finite_extent(rows.iter().filter_map(|r| r.x)) else {
            return Err("no run to plot".into());
        };
        let xr = padded(x0, x1, 0.08);
        let mut chart = figure_chart(
            root,
            &format!("Outcomes vs {} at t = {} s", self.table.field, self.t_at),
            64,
        )
        .build_cartesian_2d(xr.0..xr.1, 0.0..1.1)
        .map_err(draw_err)?;
        chart
            .configure_mesh()
            .x_desc(self.table.field.as_str())
            .y_desc("mass fraction (dimensionless)")
            .axis_desc_style(label_style())
            .label_style(small_style())
            .draw()
            .map_err(draw_err)?;
        let cap = 0.01 * (xr.1 - xr.0);
        for (k, (m, label)) in DRAWN.iter().enumerate() {
            let colour = SERIES_COLOURS[k];
            // a small offset keeps the two outcomes' bars apart
            let dx = (k as f64 - 0.5) * cap;
            let points: Vec<(f64, f64)> = rows
                .iter()
                .flat_map(|r| r.stats[*m].values.iter().map(move |&v| (r.x.unwrap_or(0.0) + dx, v)))
                .collect();
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.mix(0.4).filled())))
                .map_err(draw_err)?;
            let means: Vec<(f64, f64, f64)> = rows
                .iter()
                .filter_map(|r| {
                    let s = &r.stats[*m];
                    s.mean
                        .is_finite()
                        .then(|| (r.x.unwrap_or(0.0) + dx, s.mean, s.standard_error))
                })
                .collect();
            chart
                .draw_series(means.iter().filter(|p| p.2.is_finite()).map(|&(x, y, se)| {
                    PathElement::new(
                        vec![
                            (x - cap, y - se),
                            (x + cap, y - se),
                            (x, y - se),
                            (x, y + se),
                            (x - cap, y + se),
                            (x + cap, y + se),
                        ],
                        colour.stroke_width(2),
                    )
                }))
                .map_err(draw_err)?;
            chart
                .draw_series(means.iter().map(|&(x, y, _)| Circle::new((x, y), 5, colour.filled())))
                .map_err(draw_err)?
                .label(format!("{label}: runs, mean ± standard error"))
                .legend(move |(x, y)| Circle::new((x + 10, y), 5, colour.filled()));
        }
        draw_legend(&mut chart, SeriesLabelPosition::LowerLeft)
    }
}

/// Writes `table` as `campaign_dir/analysis/<stem>.csv` ([`ByTable::write_csv`]) and its figure (`t_at`: the
/// snapshots' time, s): the CSV's path, and why the figure was not drawn, if it was not.
pub fn write_by_field(
    campaign_dir: &std::path::Path,
    table: &ByTable,
    t_at: f64,
) -> Result<(std::path::PathBuf, Option<String>), crate::analysis::run_analysis::AnalysisError> {
    let csv = table.write_csv(campaign_dir)?;
    let figure = OutcomesByField { table, t_at };
    let drawn = super::style::write_figure(&campaign_dir.join("analysis"), &table.stem(), &figure);
    Ok((csv, drawn.err().map(String::from)))
}
