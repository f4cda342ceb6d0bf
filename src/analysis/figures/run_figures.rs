//! Figures of one impact run (Roig03 Figs. 2, 3, 4, 6, 8, 9), written by `rubblepile analyze RUN_DIR` into
//! `RUN_DIR/analysis/` as SVG and PNG: `energy_partition` (Fig. 2), `velocity_field` (Fig. 3, with the escape
//! circle), `ejection_vs_size` (Fig. 4, power-law fit, −3/2 reference), `spin_histogram` (Fig. 6, histogram and
//! empirical CDF with the least-squares and likelihood fits of Eq. 44), `spin_vs_size` (Fig. 8, −5/2 reference), `rotation_mode_vs_size` (Fig. 9, SAM/LAM) and
//! `sfd` (clump mass distribution, [`super::sfd`]).
//!
//! Only target fragments are plotted ([`crate::analysis::fragments`]); sizes over the parent's effective radius,
//! spins §4.3-corrected. The paper gives the equipartition references of Figs. 4 and 8 no normalisation (they
//! bound the data from above); here they pass through the fit at the largest plotted fragment (through its value
//! without a fit).

use std::path::Path;

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use crate::analysis::figures::energy::{EnergyInputs, EnergySeries, momentum_scales, read_energy_series};
use crate::analysis::figures::style::{
    DATA_COLOUR, FIT_COLOUR, Figure, FigureLog, GUIDE_COLOUR, HIGHLIGHT_COLOUR, PlotResult, REFERENCE_COLOUR,
    SERIES_COLOURS, draw_dashed, draw_err, draw_legend, figure_chart, finite_extent, inside_runs, label_style,
    linear_samples, log_log_chart, log_samples, log_tick, padded, padded_log, small_style, square_margins, title_style,
    write_figure,
};
use crate::analysis::fits::{PowerLawFit, SpinFit};
use crate::analysis::fragments::FragmentReport;
use crate::analysis::run_analysis::{Fit, RunAnalysis};
use crate::analysis::spin_likelihood::{LikelihoodFit, SpinLikelihood, format_p};

/// X-axis label of the size plots (Figs. 4, 8, 9).
pub const SIZE_LABEL: &str = "fragment size / parent-body effective radius (dimensionless)";

/// Roig03 Fig. 4 / Fig. 8: a log–log scatter against normalised size, with the power-law fit, an
/// equipartition reference power law and an optional horizontal line (the escape speed).
#[derive(Debug, Clone)]
pub struct SizeScatter {
    /// Figure title.
    pub title: String,
    /// Y-axis label, with its unit.
    pub y_label: String,
    /// `(size, value)` per fragment; non-positive values are left out (log axes).
    pub points: Vec<(f64, f64)>,
    /// The fitted `value = c size^α`, if the fit could be made.
    pub fit: Option<PowerLawFit>,
    /// Exponent of the dashed reference power law and its legend text (module docs for its anchor).
    pub reference: Option<(f64, String)>,
    /// A dotted horizontal line and its legend text.
    pub horizontal: Option<(f64, String)>,
}

impl SizeScatter {
    /// `c` of the reference `y = c x^e`: through the fit (or the data) at the largest size.
    fn reference_coefficient(&self, exponent: f64, pts: &[(f64, f64)]) -> Option<f64> {
        let (_, x_max) = finite_extent(pts.iter().map(|p| p.0))?;
        let y = match &self.fit {
            Some(f) => f.c * x_max.powf(f.alpha),
            None => pts.iter().filter(|p| p.0 == x_max).map(|p| p.1).fold(0.0, f64::max),
        };
        (y > 0.0 && y.is_finite()).then(|| y / x_max.powf(exponent))
    }
}

impl Figure for SizeScatter {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> PlotResult {
        let pts: Vec<(f64, f64)> = self
            .points
            .iter()
            .copied()
            .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
            .collect();
        let (Some((x0, x1)), Some((mut y0, mut y1))) = (
            finite_extent(pts.iter().map(|p| p.0)),
            finite_extent(pts.iter().map(|p| p.1)),
        ) else {
            return Err("nothing positive to plot".into());
        };
        if let Some((h, _)) = &self.horizontal
            && *h > 0.0
        {
            (y0, y1) = (y0.min(*h), y1.max(*h));
        }
        let (xr, yr) = (padded_log(x0, x1, 1.25), padded_log(y0, y1, 2.0));
        let mut chart = log_log_chart(root, &self.title, 78, (xr, yr), SIZE_LABEL, &self.y_label)?;
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 3, DATA_COLOUR.mix(0.65).filled())))
            .map_err(draw_err)?
            .label("target fragments")
            .legend(|(x, y)| Circle::new((x + 10, y), 3, DATA_COLOUR.filled()));
        let xs = log_samples(xr.0, xr.1, 80);
        if let Some(f) = &self.fit {
            let line: Vec<(f64, f64)> = xs.iter().map(|&x| (x, f.c * x.powf(f.alpha))).collect();
            for (k, run) in inside_runs(&line, xr, yr).into_iter().enumerate() {
                let s = chart
                    .draw_series(LineSeries::new(run, FIT_COLOUR.stroke_width(2)))
                    .map_err(draw_err)?;
                if k == 0 {
                    s.label(format!("power-law fit: exponent {:.2} ± {:.2}", f.alpha, f.sigma_alpha))
                        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], FIT_COLOUR.stroke_width(2)));
                }
            }
        }
        if let Some((e, name)) = &self.reference
            && let Some(c) = self.reference_coefficient(*e, &pts)
        {
            let line: Vec<(f64, f64)> = xs.iter().map(|&x| (x, c * x.powf(*e))).collect();
            let style = (REFERENCE_COLOUR.stroke_width(2), 8, 5);
            draw_dashed(&mut chart, &line, (xr, yr), style, name, (20, 6, 3))?;
        }
        if let Some((h, name)) = &self.horizontal
            && *h > 0.0
        {
            let style = GUIDE_COLOUR.stroke_width(2);
            chart
                .draw_series(DashedLineSeries::new(vec![(xr.0, *h), (xr.1, *h)], 2, 4, style))
                .map_err(draw_err)?
                .label(name.clone())
                .legend(move |(x, y)| DashedPathElement::new(vec![(x, y), (x + 20, y)], 2, 3, style));
        }
        draw_legend(&mut chart, SeriesLabelPosition::UpperRight)
    }
}

/// Roig03 Fig. 6: (a) histogram of the corrected spin rates with the binned least-squares fit of Eq. 44 and the
/// unbinned likelihood fits (free n, Maxwellian) scaled to counts per bin, every curve inside the y range;
/// (b) the empirical CDF with the likelihood fits' CDFs (drawn when the rates are given).
#[derive(Debug, Clone)]
pub struct SpinHistogram {
    /// Figure title.
    pub title: String,
    /// Bin centres (rad/s), evenly spaced.
    pub centres: Vec<f64>,
    /// Fragments per bin.
    pub counts: Vec<f64>,
    /// Least-squares fits of Eq. 44 to the bins (counts per bin) to draw.
    pub fits: Vec<SpinFit>,
    /// The spin rates themselves (rad/s), for the empirical CDF; empty: histogram only.
    pub rates: Vec<f64>,
    /// The unbinned likelihood fits ([`crate::analysis::spin_likelihood`]).
    pub likelihood: Option<SpinLikelihood>,
}

/// A curve of [`SpinHistogram`]: legend, points, colour, dashed.
type Curve = (String, Vec<(f64, f64)>, RGBColor, bool);

impl SpinHistogram {
    /// The likelihood fits as curves of `value(fit, x)` at `xs`.
    fn likelihood_curves(&self, xs: &[f64], value: impl Fn(&LikelihoodFit, f64) -> f64) -> Vec<Curve> {
        let Some(l) = &self.likelihood else {
            return Vec::new();
        };
        let [lo, hi] = l.free.n_interval.unwrap_or([f64::NAN; 2]);
        let p = |f: &LikelihoodFit| format!("KS p {}, AD p {}", format_p(f.goodness.ks_p), format_p(f.goodness.ad_p));
        vec![
            (
                format!(
                    "likelihood, n free: n = {:.2} [{lo:.2}, {hi:.2}], {}",
                    l.free.n,
                    p(&l.free)
                ),
                xs.iter().map(|&x| (x, value(&l.free, x))).collect(),
                FIT_COLOUR,
                false,
            ),
            (
                format!("likelihood, Maxwellian n = 2: {}", p(&l.maxwellian)),
                xs.iter().map(|&x| (x, value(&l.maxwellian, x))).collect(),
                SERIES_COLOURS[2],
                true,
            ),
        ]
    }

    fn histogram_panel<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>, caption: &str) -> PlotResult {
        let width = self.centres[1] - self.centres[0];
        let x1 = self.centres[self.centres.len() - 1] + width;
        let scale = self.counts.iter().sum::<f64>() * width;
        // from one step above 0: a density with n < 0 is infinite at 0
        let xs: Vec<f64> = linear_samples(0.0, x1, 400).into_iter().skip(1).collect();
        let mut curves: Vec<Curve> = self
            .fits
            .iter()
            .enumerate()
            .map(|(k, f)| {
                let how = if f.n_free { "free" } else { "fixed" };
                (
                    format!(
                        "least squares on the bins, n {how} = {:.2}: residual {:.3e}",
                        f.n, f.rss
                    ),
                    xs.iter().map(|&x| (x, f.evaluate(x))).collect(),
                    SERIES_COLOURS[(k + 3) % 4],
                    true,
                )
            })
            .collect();
        curves.extend(self.likelihood_curves(&xs, |f, x| scale * f.density(x)));
        let top = finite_extent(
            curves
                .iter()
                .flat_map(|c| c.1.iter().map(|p| p.1))
                .chain(self.counts.clone()),
        )
        .map_or(1.0, |e| e.1.max(1.0));
        // headroom for the legend; every curve's maximum inside
        let y1 = top * 1.45;
        let mut chart = figure_chart(area, caption, 64)
            .build_cartesian_2d(0.0..x1, 0.0..y1)
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .x_desc("spin rate ω, corrected (rad/s)")
            .y_desc("fragments per bin (count)")
            .axis_desc_style(label_style())
            .label_style(small_style())
            .x_label_formatter(&|v| format!("{v:.1e}"))
            .draw()
            .map_err(draw_err)?;
        chart
            .draw_series(self.centres.iter().zip(&self.counts).map(|(&c, &n)| {
                Rectangle::new(
                    [(c - 0.5 * width, 0.0), (c + 0.5 * width, n)],
                    DATA_COLOUR.mix(0.35).filled(),
                )
            }))
            .map_err(draw_err)?
            .label(format!("histogram ({:.0} fragments)", self.counts.iter().sum::<f64>()))
            .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 20, y + 5)], DATA_COLOUR.mix(0.35).filled()));
        draw_curves(&mut chart, curves, (0.0, x1), (0.0, y1))?;
        draw_legend(&mut chart, SeriesLabelPosition::UpperRight)
    }

    fn ecdf_panel<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> PlotResult {
        let mut sorted: Vec<f64> = self.rates.iter().copied().filter(|v| v.is_finite()).collect();
        sorted.sort_by(f64::total_cmp);
        let width = self.centres[1] - self.centres[0];
        let x1 = (self.centres[self.centres.len() - 1] + width).max(sorted.last().copied().unwrap_or(0.0));
        let mut chart = figure_chart(area, "(b) empirical CDF and the likelihood fits", 64)
            .build_cartesian_2d(0.0..x1, 0.0..1.05)
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .x_desc("spin rate ω, corrected (rad/s)")
            .y_desc("fraction ≤ ω (dimensionless)")
            .axis_desc_style(label_style())
            .label_style(small_style())
            .x_label_formatter(&|v| format!("{v:.1e}"))
            .draw()
            .map_err(draw_err)?;
        let n = sorted.len() as f64;
        let mut steps = vec![(0.0, 0.0)];
        for (i, &v) in sorted.iter().enumerate() {
            steps.push((v, i as f64 / n));
            steps.push((v, (i + 1) as f64 / n));
        }
        steps.push((x1, 1.0));
        let style = DATA_COLOUR.stroke_width(2);
        chart
            .draw_series(LineSeries::new(steps, style))
            .map_err(draw_err)?
            .label(format!("empirical CDF ({} rates)", sorted.len()))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
        let xs = linear_samples(0.0, x1, 400);
        draw_curves(
            &mut chart,
            self.likelihood_curves(&xs, |f, x| f.cdf(x)),
            (0.0, x1),
            (0.0, 1.05),
        )?;
        draw_legend(&mut chart, SeriesLabelPosition::LowerRight)
    }
}

/// Draws `curves` (solid or dashed, each with its legend entry) inside the axis ranges.
fn draw_curves<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    curves: Vec<Curve>,
    xr: (f64, f64),
    yr: (f64, f64),
) -> PlotResult {
    for (name, line, colour, dashed) in curves {
        let (on, off) = if dashed { (8, 5) } else { (1000, 0) };
        let style = (colour.stroke_width(2), on, off);
        draw_dashed(chart, &line, (xr, yr), style, &name, (20, on.min(20), off))?;
    }
    Ok(())
}

impl Figure for SpinHistogram {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> PlotResult {
        if self.centres.len() < 2 || self.centres.len() != self.counts.len() {
            return Err("histogram has fewer than 2 bins".into());
        }
        if self.rates.is_empty() {
            return self.histogram_panel(root, &self.title);
        }
        let body = root.titled(&self.title, title_style()).map_err(draw_err)?;
        let panels = body.split_evenly((2, 1));
        self.histogram_panel(&panels[0], "(a) histogram and fits")?;
        self.ecdf_panel(&panels[1])
    }
}

/// Roig03 Fig. 9: axis-rotation-mode measure (+1 pure SAM, −1 pure LAM, 0 intermediate axis) vs size.
#[derive(Debug, Clone)]
pub struct RotationModeVsSize {
    /// Figure title.
    pub title: String,
    /// `(size, measure)` per spinning target fragment.
    pub points: Vec<(f64, f64)>,
}

impl Figure for RotationModeVsSize {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> PlotResult {
        let pts: Vec<(f64, f64)> = self
            .points
            .iter()
            .copied()
            .filter(|(x, y)| *x > 0.0 && x.is_finite() && y.is_finite())
            .collect();
        let Some((x0, x1)) = finite_extent(pts.iter().map(|p| p.0)) else {
            return Err("no spinning fragment to plot".into());
        };
        let xr = padded_log(x0, x1, 1.25);
        let mut chart = figure_chart(root, &self.title, 64)
            .build_cartesian_2d((xr.0..xr.1).log_scale(), -1.15..1.15)
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .x_desc(SIZE_LABEL)
            .y_desc("rotation mode (I_eff − I₂) normalised (dimensionless)")
            .axis_desc_style(label_style())
            .label_style(small_style())
            .x_label_formatter(&log_tick)
            .y_label_formatter(&|v: &f64| format!("{:.1}", if v.abs() < 1e-9 { 0.0 } else { *v }))
            .draw()
            .map_err(draw_err)?;
        chart
            .draw_series(LineSeries::new(
                vec![(xr.0, 0.0), (xr.1, 0.0)],
                GUIDE_COLOUR.stroke_width(1),
            ))
            .map_err(draw_err)?;
        let left = xr.0 * (xr.1 / xr.0).powf(0.02);
        chart
            .draw_series([
                Text::new("SAM (short-axis mode) ↑", (left, 0.1), small_style()),
                Text::new("LAM (long-axis mode) ↓", (left, -0.03), small_style()),
            ])
            .map_err(draw_err)?;
        let n_sam = pts.iter().filter(|p| p.1 > 0.0).count();
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 3, DATA_COLOUR.mix(0.7).filled())))
            .map_err(draw_err)?
            .label(format!("target fragments: {} SAM, {} LAM", n_sam, pts.len() - n_sam))
            .legend(|(x, y)| Circle::new((x + 10, y), 3, DATA_COLOUR.filled()));
        draw_legend(&mut chart, SeriesLabelPosition::LowerRight)
    }
}

/// Roig03 Fig. 3: fragment ejection velocities (relative to the target barycentre) in the (v_x, v_y) and
/// (v_y, v_z) planes, equal aspect, with the escape-speed circle dotted and escaping fragments (Eq. 43)
/// in another colour.
#[derive(Debug, Clone)]
pub struct VelocityField {
    /// Figure title.
    pub title: String,
    /// Ejection velocity `Δv` (m/s) and whether the fragment escapes, per target fragment.
    pub fragments: Vec<([f64; 3], bool)>,
    /// Escape speed `v_esc` (m/s).
    pub escape_velocity: f64,
}

impl VelocityField {
    /// Width of the x-axis label area and of the y-axis label area of a panel (pixels).
    const LABEL_AREAS: (u32, u32) = (50, 70);

    /// One square panel of components `(i, j)` over `[−r, r]²`.
    fn panel<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>, (i, j): (usize, usize), r: f64) -> PlotResult {
        let (xl, yl) = Self::LABEL_AREAS;
        let (top, bottom, left, right) = square_margins(area.dim_in_pixel(), xl, yl, 10);
        let axis = ["x", "y", "z"];
        let mut chart = ChartBuilder::on(area)
            .margin_top(top)
            .margin_bottom(bottom)
            .margin_left(left)
            .margin_right(right)
            .x_label_area_size(xl)
            .y_label_area_size(yl)
            .build_cartesian_2d(-r..r, -r..r)
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .x_desc(format!("ejection velocity Δv_{} (m/s)", axis[i]))
            .y_desc(format!("ejection velocity Δv_{} (m/s)", axis[j]))
            .axis_desc_style(label_style())
            .label_style(small_style())
            .x_labels(7)
            .y_labels(7)
            .max_light_lines(1)
            .draw()
            .map_err(draw_err)?;
        let v = self.escape_velocity;
        if v > 0.0 && v.is_finite() {
            let circle: Vec<(f64, f64)> = linear_samples(0.0, std::f64::consts::TAU, 180)
                .into_iter()
                .map(|a| (v * a.cos(), v * a.sin()))
                .collect();
            chart
                .draw_series(DashedLineSeries::new(circle, 2, 4, GUIDE_COLOUR.stroke_width(2)))
                .map_err(draw_err)?;
        }
        for (escaping, colour) in [(false, DATA_COLOUR), (true, HIGHLIGHT_COLOUR)] {
            let pts = self
                .fragments
                .iter()
                .filter(|f| f.1 == escaping)
                .map(|f| (f.0[i], f.0[j]));
            chart
                .draw_series(pts.map(|p| Circle::new(p, 3, colour.mix(0.75).filled())))
                .map_err(draw_err)?;
        }
        Ok(())
    }

    /// The figure's legend in one row across `area`, below the panels, where it cannot hide a fragment
    /// (plotters' legends sit inside a plotting area).
    fn legend<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> PlotResult {
        let n_escaping = self.fragments.iter().filter(|f| f.1).count();
        let entries = [
            (
                Some(DATA_COLOUR),
                format!("bound fragments: {}", self.fragments.len() - n_escaping),
            ),
            (
                Some(HIGHLIGHT_COLOUR),
                format!("escaping fragments (Eq. 43): {n_escaping}"),
            ),
            (
                None,
                format!("escape-speed circle, v_esc = {:.1} m/s", self.escape_velocity),
            ),
        ];
        let style = small_style();
        let widths: Vec<i32> = entries
            .iter()
            .map(|e| area.estimate_text_size(&e.1, &style).map(|(w, _)| w as i32 + 60))
            .collect::<Result<_, _>>()
            .map_err(draw_err)?;
        let (w, _) = area.dim_in_pixel();
        let (mut x, y) = (((w as i32) - widths.iter().sum::<i32>()).max(0) / 2, 12);
        for ((marker, text), width) in entries.iter().zip(widths) {
            match marker {
                Some(c) => area.draw(&Circle::new((x + 10, y), 4, c.filled())),
                None => area.draw(&DashedPathElement::new(
                    vec![(x, y), (x + 24, y)],
                    2,
                    3,
                    GUIDE_COLOUR.stroke_width(2),
                )),
            }
            .map_err(draw_err)?;
            area.draw(&Text::new(text.clone(), (x + 30, y - 7), style.clone()))
                .map_err(draw_err)?;
            x += width;
        }
        Ok(())
    }
}

impl Figure for VelocityField {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> PlotResult {
        let biggest = self
            .fragments
            .iter()
            .flat_map(|f| f.0)
            .filter(|x| x.is_finite())
            .fold(0.0, |m: f64, x| m.max(x.abs()));
        let v = Some(self.escape_velocity).filter(|v| v.is_finite()).unwrap_or(0.0);
        let r = 1.1 * biggest.max(v);
        if self.fragments.is_empty() || r <= 0.0 {
            return Err("no fragment velocities to plot".into());
        }
        let body = root.titled(&self.title, title_style()).map_err(draw_err)?;
        // the panels as tall as their square plots need; the legend row below them
        let (w, h) = body.dim_in_pixel();
        let (xl, yl) = Self::LABEL_AREAS;
        let square = (w / 2).saturating_sub(yl + 20);
        let (top, bottom) = body.split_vertically((square + xl + 20).min(h));
        let panels = top.split_evenly((1, 2));
        self.panel(&panels[0], (0, 1), r)?;
        self.panel(&panels[1], (1, 2), r)?;
        self.legend(&bottom)
    }
}

/// Roig03 Fig. 2: (a) kinetic energies normalised to the projectile's initial one (log scale, since the
/// fragments keep only a few per cent); (b) relative drift of the total linear and angular momenta.
#[derive(Debug, Clone)]
pub struct EnergyPartition {
    /// Figure title.
    pub title: String,
    /// The curves ([`crate::analysis::figures::energy`]).
    pub series: EnergySeries,
    /// Legend names of `S_P` and `S_L`.
    pub scale_names: (String, String),
}

impl EnergyPartition {
    fn energies<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>, tr: (f64, f64)) -> PlotResult {
        let s = &self.series;
        let mut curves: Vec<(String, &Vec<f64>, usize, RGBColor)> = Vec::new();
        let (kin, rot) = match &s.tracks_note {
            None => (
                "fragments: total (translational + rotational) kinetic energy".to_string(),
                "fragments: rotational kinetic energy".to_string(),
            ),
            Some(why) => (
                format!("all bodies incl. projectile ({why}): total kinetic energy"),
                "all bodies incl. projectile: rotational kinetic energy".to_string(),
            ),
        };
        if let Some(p) = &s.projectile_kinetic {
            curves.push(("projectile: kinetic energy".into(), p, 0, SERIES_COLOURS[0]));
        }
        curves.push((kin, &s.fragments_kinetic, 1, SERIES_COLOURS[1]));
        curves.push((rot, &s.fragments_rotational, 2, SERIES_COLOURS[2]));
        let positive = curves.iter().flat_map(|c| c.1.iter().copied()).filter(|v| *v > 0.0);
        let Some((lo, hi)) = finite_extent(positive) else {
            return Err("no positive energy to plot".into());
        };
        let yr = padded_log(lo.max(hi * 1e-7), hi, 2.0);
        let y_desc = "E / K_projectile(0) (dimensionless)";
        let mut chart = time_log_panel(area, "(a) energy partition", (tr, yr), y_desc, &log_tick)?;
        for (name, values, dash, colour) in curves {
            let pts: Vec<(f64, f64)> = s.t.iter().copied().zip(values.iter().copied()).collect();
            // solid, dashed, dash-dotted-like short dashes: the paper's line styles, plus colour
            let (on, off) = [(1000, 0), (8, 5), (3, 3)][dash];
            let style = (colour.stroke_width(2), on, off);
            draw_dashed(&mut chart, &pts, (tr, yr), style, &name, (24, on.min(24), off))?;
        }
        draw_legend(&mut chart, SeriesLabelPosition::UpperRight)
    }

    fn momenta<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>, tr: (f64, f64)) -> PlotResult {
        let s = &self.series;
        let positive = s
            .momentum_drift
            .iter()
            .chain(&s.angular_momentum_drift)
            .copied()
            .filter(|v| *v > 0.0);
        let yr = match finite_extent(positive) {
            Some((lo, hi)) => padded_log(lo, hi, 3.0),
            None => (1e-18, 1e-14),
        };
        let caption = "(b) conservation of total momenta";
        let drift_tick = |v: &f64| format!("{v:.0e}");
        let mut chart = time_log_panel(area, caption, (tr, yr), "relative drift (dimensionless)", &drift_tick)?;
        let curves = [
            (
                format!("angular momentum |L(t) − L(0)| / {}", self.scale_names.1),
                &s.angular_momentum_drift,
                SERIES_COLOURS[0],
                (1000, 0),
            ),
            (
                format!("linear momentum |P(t) − P(0)| / {}", self.scale_names.0),
                &s.momentum_drift,
                SERIES_COLOURS[1],
                (8, 5),
            ),
        ];
        for (name, values, colour, (on, off)) in curves {
            let pts: Vec<(f64, f64)> = s.t.iter().copied().zip(values.iter().copied()).collect();
            let style = colour.stroke_width(2);
            let runs = inside_runs(&pts, tr, yr);
            // a legend entry even when the drift is exactly zero throughout (nothing to draw on a log axis)
            let first = runs.first().cloned().unwrap_or_default();
            chart
                .draw_series(DashedLineSeries::new(first, on, off, style))
                .map_err(draw_err)?
                .label(name)
                .legend(move |(x, y)| DashedPathElement::new(vec![(x, y), (x + 24, y)], on.min(24), off, style));
            for run in runs.into_iter().skip(1) {
                chart
                    .draw_series(DashedLineSeries::new(run, on, off, style))
                    .map_err(draw_err)?;
            }
        }
        // upper left: before the impact the drift sits at round-off, far below the top
        draw_legend(&mut chart, SeriesLabelPosition::UpperLeft)
    }
}

/// A chart with a linear time axis and a logarithmic y axis.
type TimeLogChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, LogCoord<f64>>>;

/// A panel of Fig. 2 on `area`: `caption`, time `tr` (s) along x, the positive range `yr` on a log y axis described
/// by `y_desc` with ticks labelled by `y_tick`.
fn time_log_panel<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: &str,
    (tr, yr): ((f64, f64), (f64, f64)),
    y_desc: &str,
    y_tick: &dyn Fn(&f64) -> String,
) -> Result<TimeLogChart<'a, DB>, crate::analysis::AnalysisError> {
    let mut chart = ChartBuilder::on(area)
        .caption(caption, label_style())
        .margin(8)
        .x_label_area_size(40)
        .y_label_area_size(78)
        .build_cartesian_2d(tr.0..tr.1, (yr.0..yr.1).log_scale())
        .map_err(draw_err)?;
    chart
        .configure_mesh()
        .x_desc("time t (s)")
        .y_desc(y_desc)
        .axis_desc_style(label_style())
        .label_style(small_style())
        .y_label_formatter(y_tick)
        .draw()
        .map_err(draw_err)?;
    Ok(chart)
}

impl Figure for EnergyPartition {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> PlotResult {
        let Some(tr) = finite_extent(self.series.t.iter().copied()) else {
            return Err("empty time series".into());
        };
        let tr = if tr.1 > tr.0 { tr } else { padded(tr.0, tr.1, 0.0) };
        let body = root.titled(&self.title, title_style()).map_err(draw_err)?;
        let panels = body.split_evenly((2, 1));
        self.energies(&panels[0], tr)?;
        self.momenta(&panels[1], tr)
    }
}

/// The inputs of Fig. 2 from a run's analysis: the projectile from the report, the momentum scales from the
/// t = 0 snapshot, or (when that cannot be read) the projectile's momentum `m_p v_p` and `m_p v_p R_eff`.
/// Returns the inputs and the legend names of the two scales.
pub fn energy_inputs(run_dir: &Path, report: &FragmentReport) -> Option<(EnergyInputs, (String, String))> {
    let p = report.fragments.iter().find(|f| f.is_projectile)?;
    let s = &report.summary;
    let snapshot = crate::analysis::run_analysis::snapshot_path(run_dir, 0.0)
        .and_then(|path| crate::analysis::fragments::read_snapshot_bodies(&path).ok())
        .filter(|b| b.len() == report.fragments.len());
    let ((s_p, s_l), names) = match snapshot {
        Some(bodies) => {
            let moments: Vec<[f64; 3]> = report.fragments.iter().map(|f| f.moments).collect();
            (
                momentum_scales(&bodies, &moments),
                (
                    "Σ m|v| at t = 0".to_string(),
                    "Σ (m|r × v| + |Iω|) at t = 0".to_string(),
                ),
            )
        }
        None => {
            let pp = p.mass * s.projectile_speed;
            (
                (pp, pp * s.target_radius),
                ("m_p v_p".to_string(), "m_p v_p R_eff".to_string()),
            )
        }
    };
    Some((
        EnergyInputs {
            projectile: p.index,
            projectile_mass: p.mass,
            projectile_moments: p.moments,
            target_mass: s.target_mass,
            summary_projectile_energy: s.projectile_kinetic_energy,
            momentum_scale: s_p,
            angular_momentum_scale: s_l,
        },
        names,
    ))
}

/// Writes the run figures (module docs) into `out` (default `run_dir/analysis/`); returns the files written and,
/// for each figure that could not be drawn, why (one line each; the other figures are still written).
pub fn write_run_figures(
    run_dir: &Path,
    out: Option<&Path>,
    analysis: &RunAnalysis,
    report: &FragmentReport,
) -> (Vec<String>, Vec<String>) {
    let dir = out.map_or_else(|| run_dir.join("analysis"), Path::to_path_buf);
    let target: Vec<_> = report.fragments.iter().filter(|f| !f.is_projectile).collect();
    let t_at = analysis.t_at;
    let mut log = FigureLog::default();

    let fig2 = energy_inputs(run_dir, report)
        .ok_or_else(|| "no projectile in the fragment report".to_string())
        .and_then(|(inputs, scale_names)| {
            let series = read_energy_series(run_dir, &inputs)?;
            let fig = EnergyPartition {
                title: "Energy partition and momentum conservation during the impact".into(),
                series,
                scale_names,
            };
            Ok(write_figure(&dir, "energy_partition", &fig)?)
        });
    log.record("energy_partition", fig2);

    let sfd = super::sfd::SizeFrequency::of(&analysis.clump_report, t_at);
    log.write(&dir, "sfd", &sfd);

    let fig3 = VelocityField {
        title: format!("Fragment ejection velocities relative to the target barycentre, t = {t_at} s"),
        fragments: target.iter().map(|f| (f.ejection_velocity, f.escaping)).collect(),
        escape_velocity: analysis.summary.escape_velocity,
    };
    log.write(&dir, "velocity_field", &fig3);

    let fig4 = SizeScatter {
        title: format!("Ejection speed vs size at t = {t_at} s"),
        y_label: "ejection speed |Δv| (m/s)".into(),
        points: target.iter().map(|f| (f.size, f.ejection_speed)).collect(),
        fit: analysis.ejection_speed_vs_size.ok().copied(),
        reference: Some((-1.5, "−3/2 power law (equipartition)".into())),
        horizontal: Some((
            analysis.summary.escape_velocity,
            format!("escape speed v_esc = {:.1} m/s", analysis.summary.escape_velocity),
        )),
    };
    log.write(&dir, "ejection_vs_size", &fig4);

    let fig6 = SpinHistogram {
        title: format!("Spin rates of the target fragments at t = {t_at} s"),
        centres: analysis.spin_histogram.0.clone(),
        counts: analysis.spin_histogram.1.clone(),
        // the free-n least-squares fit (the best fixed n when the free one failed)
        fits: match &analysis.spin_fits {
            Fit::Ok(c) => c
                .free
                .clone()
                .or_else(|| c.fixed.iter().find(|f| f.n == c.best_n).cloned())
                .into_iter()
                .collect(),
            Fit::Failed(_) => Vec::new(),
        },
        rates: target.iter().map(|f| f.spin_rate_corrected).collect(),
        likelihood: analysis.spin_likelihood.ok().cloned(),
    };
    log.write(&dir, "spin_histogram", &fig6);

    let fig8 = SizeScatter {
        title: format!("Spin rate vs size at t = {t_at} s"),
        y_label: "spin rate ω, corrected (rad/s)".into(),
        points: target.iter().map(|f| (f.size, f.spin_rate_corrected)).collect(),
        fit: analysis.spin_vs_size.ok().copied(),
        reference: Some((-2.5, "−5/2 power law (equipartition)".into())),
        horizontal: None,
    };
    log.write(&dir, "spin_vs_size", &fig8);

    let fig9 = RotationModeVsSize {
        title: format!("Axis rotation mode vs size at t = {t_at} s"),
        points: target
            .iter()
            .filter_map(|f| f.rotation_mode_measure.map(|m| (f.size, m)))
            .collect(),
    };
    log.write(&dir, "rotation_mode_vs_size", &fig9);
    (log.written, log.failed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::figures::testing::{assert_figure_files, assert_writes, temp_dir};

    fn fit(alpha: f64) -> PowerLawFit {
        PowerLawFit {
            c: 2.0,
            alpha,
            sigma_c: 0.1,
            sigma_alpha: 0.05,
            r_squared: 0.8,
            points: 5,
            skipped: 0,
        }
    }

    #[test]
    fn size_scatter_writes_svg_and_png_with_labels() {
        let dir = temp_dir("size-scatter");
        let fig = SizeScatter {
            title: "Ejection speed vs size".into(),
            y_label: "ejection speed |Δv| (m/s)".into(),
            points: vec![(0.1, 20.0), (0.2, 9.0), (0.3, 5.0), (0.5, 3.0), (0.05, -1.0)],
            fit: Some(fit(-0.4)),
            reference: Some((-1.5, "−3/2 power law (equipartition)".into())),
            horizontal: Some((15.0, "escape speed v_esc".into())),
        };
        let files = write_figure(&dir, "ejection_vs_size", &fig).unwrap();
        assert_eq!(files, ["ejection_vs_size.svg", "ejection_vs_size.png"]);
        let svg = assert_figure_files(&dir, "ejection_vs_size", &["ejection speed |Δv| (m/s)", SIZE_LABEL]);
        assert!(svg.contains("−3/2 power law") && svg.contains("power-law fit: exponent -0.40"));
        // the reference passes through the fit at the largest size
        assert!((fig.reference_coefficient(-1.5, &fig.points).unwrap() - 2.0 * 0.5f64.powf(1.1)).abs() < 1e-12);
        let nothing = SizeScatter {
            points: vec![(0.1, 0.0)],
            ..fig
        };
        std::fs::write(dir.join("empty.png"), b"stale").unwrap();
        assert!(write_figure(&dir, "empty", &nothing).is_err());
        // no blank SVG, no stale PNG left behind
        assert!(!dir.join("empty.svg").exists() && !dir.join("empty.png").exists());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn spin_histogram_writes_both_files() {
        let fig = SpinHistogram {
            title: "Spin rates".into(),
            centres: vec![0.5e-3, 1.5e-3, 2.5e-3, 3.5e-3],
            counts: vec![3.0, 6.0, 4.0, 1.0],
            fits: Vec::new(),
            rates: Vec::new(),
            likelihood: None,
        };
        assert_writes(
            "spin_histogram",
            &fig,
            &["spin rate ω, corrected (rad/s)", "fragments per bin"],
        );
        // with the rates: the likelihood fits in both panels, the ECDF below
        let rates = [
            0.4e-3, 0.7e-3, 1.1e-3, 1.3e-3, 1.6e-3, 2.2e-3, 2.4e-3, 2.9e-3, 3.3e-3, 3.9e-3,
        ];
        let fig = SpinHistogram {
            likelihood: crate::analysis::spin_likelihood::fit_spin_likelihood(
                &rates,
                crate::analysis::spin_likelihood::Weights::Number,
            )
            .ok(),
            rates: rates.to_vec(),
            ..fig
        };
        let svg = assert_writes(
            "spin_histogram",
            &fig,
            &[
                "fraction ≤ ω (dimensionless)",
                "empirical CDF (10 rates)",
                "likelihood, n free: n = ",
            ],
        );
        assert!(svg.contains("likelihood, Maxwellian n = 2: KS p"));
    }

    #[test]
    fn rotation_mode_writes_both_files_with_sam_and_lam() {
        let fig = RotationModeVsSize {
            title: "Axis rotation mode vs size".into(),
            points: vec![(0.1, 0.5), (0.3, -0.7), (0.6, 0.9), (0.2, -1.0)],
        };
        let svg = assert_writes("rotation_mode_vs_size", &fig, &[SIZE_LABEL, "(dimensionless)"]);
        assert!(svg.contains("SAM") && svg.contains("LAM") && svg.contains("2 SAM, 2 LAM"));
    }

    #[test]
    fn velocity_field_writes_both_files_with_its_legend() {
        let fig = VelocityField {
            title: "Fragment ejection velocities".into(),
            fragments: vec![
                ([1.0, -2.0, 0.5], false),
                ([30.0, 4.0, -12.0], true),
                ([-3.0, 1.0, 2.0], false),
            ],
            escape_velocity: 20.0,
        };
        let svg = assert_writes(
            "velocity_field",
            &fig,
            &[
                "ejection velocity Δv_x (m/s)",
                "ejection velocity Δv_z (m/s)",
                "escape-speed circle, v_esc = 20.0 m/s",
            ],
        );
        assert!(svg.contains("escaping fragments (Eq. 43): 1") && svg.contains("bound fragments: 2"));
    }

    #[test]
    fn energy_partition_reads_synthetic_run_and_writes_both_files() {
        let dir = temp_dir("energy-partition");
        crate::analysis::figures::energy::tests::write_synthetic_run(&dir, true);
        let inputs = crate::analysis::figures::energy::tests::inputs();
        let series = read_energy_series(&dir, &inputs).unwrap();
        assert!((series.projectile_kinetic.as_ref().unwrap()[1] - 0.5 / 11.0).abs() < 1e-12);
        let fig = EnergyPartition {
            title: "Energy partition".into(),
            series,
            scale_names: ("S_P".into(), "S_L".into()),
        };
        write_figure(&dir, "energy_partition", &fig).unwrap();
        let svg = assert_figure_files(
            &dir,
            "energy_partition",
            &[
                "time t (s)",
                "E / K_projectile(0) (dimensionless)",
                "relative drift (dimensionless)",
            ],
        );
        assert!(svg.contains("projectile: kinetic energy") && svg.contains("|P(t) − P(0)| / S_P"));
        // without tracks the totals are drawn, and the legend says why
        std::fs::remove_file(dir.join("tracks.csv")).unwrap();
        let series = read_energy_series(&dir, &inputs).unwrap();
        let fig = EnergyPartition { series, ..fig };
        write_figure(&dir, "energy_partition", &fig).unwrap();
        let svg = assert_figure_files(&dir, "energy_partition", &["time t (s)"]);
        assert!(svg.contains("no tracks.csv") && !svg.contains("projectile: kinetic energy"));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
