//! Shared look and output of the Roig03 figures (Figs. 2–9): the embedded font, sizes, colours, range and
//! clipping helpers, and [`write_figure`], which renders one [`Figure`] into both an SVG and a PNG file.
//!
//! Each figure is drawn by a single generic [`Figure::draw`] on a `DrawingArea<DB, Shift>`, and
//! [`write_figure`] calls it once with plotters' `SVGBackend` and once with its `BitMapBackend`: the two files
//! cannot diverge.
//!
//! Text: plotters' `ab_glyph` feature lays out and rasterises glyphs in pure Rust from a font registered at
//! run time ([`ensure_font`]); the font is DejaVu Sans, embedded in the binary from
//! `src/analysis/figures/fonts/DejaVuSans.ttf` (licence beside it), so neither output needs system font
//! libraries or font files. The SVG files name the family `sans-serif` and the viewer picks its own font; the
//! embedded one still sizes the label areas and legends.

use std::path::Path;
use std::sync::OnceLock;

use plotters::chart::ChartContext;
use plotters::coord::{CoordTranslate, Shift};
use plotters::prelude::*;

/// Font family name every figure uses, the one the embedded font is registered under.
pub const FONT_FAMILY: &str = "sans-serif";
/// Size of every figure (pixels; also the SVG's user units). Small, so the PNGs stay light.
pub const FIGURE_SIZE: (u32, u32) = (800, 560);
/// Font size of figure titles (pixels).
pub const TITLE_FONT: u32 = 19;
/// Font size of axis labels (pixels).
pub const LABEL_FONT: u32 = 15;
/// Font size of legends, tick labels and annotations (pixels).
pub const SMALL_FONT: u32 = 13;

/// Colour of data points.
pub const DATA_COLOUR: RGBColor = RGBColor(31, 119, 180);
/// Colour of data points singled out (escaping fragments, per-Q means …).
pub const HIGHLIGHT_COLOUR: RGBColor = RGBColor(214, 39, 40);
/// Colour of fitted lines.
pub const FIT_COLOUR: RGBColor = RGBColor(200, 30, 30);
/// Colour of theoretical or published reference lines.
pub const REFERENCE_COLOUR: RGBColor = RGBColor(40, 40, 40);
/// Colour of guide lines (zero, one half, escape speed).
pub const GUIDE_COLOUR: RGBColor = RGBColor(110, 110, 110);
/// Distinct colours for several curves in one panel.
pub const SERIES_COLOURS: [RGBColor; 4] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
];

/// DejaVu Sans 2.37 (Bitstream Vera licence, `fonts/LICENSE-DejaVu.txt`).
static DEJAVU_SANS: &[u8] = include_bytes!("fonts/DejaVuSans.ttf");

/// A drawing result: the reason as one line when a figure could not be drawn.
pub type PlotResult = Result<(), crate::analysis::AnalysisError>;

/// Turns a plotters error (or any other) into the one-line reason of [`PlotResult`].
pub fn draw_err(err: impl std::fmt::Display) -> String {
    err.to_string()
}

/// Registers the embedded font as [`FONT_FAMILY`] (once per process). Every figure needs it, the SVG ones
/// too: plotters measures text with it to size label areas and legends.
pub fn ensure_font() -> PlotResult {
    static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            plotters::style::register_font(FONT_FAMILY, FontStyle::Normal, DEJAVU_SANS)
                .map_err(|_| "the embedded DejaVu Sans font could not be parsed".to_string())
        })
        .clone()
        .map_err(crate::analysis::AnalysisError::Output)
}

/// One figure, drawn the same way on any plotters backend.
pub trait Figure {
    /// Draws the whole figure on `root` (already filled white; [`write_figure`] presents it afterwards).
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> PlotResult;
}

fn render<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, figure: &impl Figure) -> PlotResult {
    root.fill(&WHITE).map_err(draw_err)?;
    figure.draw(root)?;
    Ok(root.present().map_err(draw_err)?)
}

/// Draws `figure` into `dir/<stem>.svg` and `dir/<stem>.png` ([`FIGURE_SIZE`]), creating `dir`; returns the
/// two file names. On a drawing error neither file is left behind (plotters' backends write their file when
/// dropped, even after a failed drawing), so a stale or blank figure never passes for a good one.
pub fn write_figure(
    dir: &Path,
    stem: &str,
    figure: &impl Figure,
) -> Result<[String; 2], crate::analysis::AnalysisError> {
    ensure_font()?;
    use crate::io::safe_write;
    let io = |p: &Path, e: std::io::Error| format!("{}: {}", p.display(), safe_write::reason(&e));
    safe_write::ensure_dir(dir).map_err(|e| io(dir, e))?;
    let (svg, png) = (format!("{stem}.svg"), format!("{stem}.png"));
    let (svg_path, png_path) = (dir.join(&svg), dir.join(&png));
    // Both drawn into temporaries first (the SVG in memory, the PNG into a fresh file beside it: plotters' bitmap
    // backend writes only to a path), then renamed into place: never through a link, never half a figure.
    // On a drawing error the figure's old files go too: a stale figure must not pass for this one.
    let stale = || {
        for p in [&svg_path, &png_path] {
            if safe_write::refuse_symlink(p).is_ok() {
                let _ = std::fs::remove_file(p);
            }
        }
    };
    let mut svg_text = String::new();
    let drawn = render(
        &SVGBackend::with_string(&mut svg_text, FIGURE_SIZE).into_drawing_area(),
        figure,
    );
    if let Err(why) = drawn {
        stale();
        return Err(why);
    }
    let (png_tmp, _) = safe_write::temp_beside(&png_path).map_err(|e| io(&png_path, e))?;
    let drawn = render(&BitMapBackend::new(&png_tmp, FIGURE_SIZE).into_drawing_area(), figure);
    // the backend is dropped (and has written whatever it holds) by now
    if let Err(why) = drawn {
        let _ = std::fs::remove_file(&png_tmp);
        stale();
        return Err(why);
    }
    safe_write::write_atomic(&svg_path, &svg_text).map_err(|e| io(&svg_path, e))?;
    safe_write::rename_into(&png_tmp, &png_path).map_err(|e| io(&png_path, e))?;
    Ok([svg, png])
}

/// What writing a set of figures gave: the files written and, for each figure that could not be drawn, why
/// (`stem: reason`, one line each; the other figures are still written).
#[derive(Debug, Default)]
pub struct FigureLog {
    /// File names written.
    pub written: Vec<String>,
    /// `stem: reason` of each figure not drawn.
    pub failed: Vec<String>,
}

impl FigureLog {
    /// Books the outcome of the figure `stem`.
    pub fn record(&mut self, stem: &str, outcome: Result<[String; 2], String>) {
        match outcome {
            Ok(files) => self.written.extend(files),
            Err(why) => self.failed.push(format!("{stem}: {why}")),
        }
    }

    /// Writes `figure` as `dir/<stem>.svg` and `.png` ([`write_figure`]) and books the outcome.
    pub fn write(&mut self, dir: &Path, stem: &str, figure: &impl Figure) {
        self.record(stem, write_figure(dir, stem, figure).map_err(String::from));
    }
}

/// Text style of titles.
pub fn title_style() -> TextStyle<'static> {
    (FONT_FAMILY, TITLE_FONT).into_font().into()
}

/// Text style of axis labels.
pub fn label_style() -> TextStyle<'static> {
    (FONT_FAMILY, LABEL_FONT).into_font().into()
}

/// Text style of legends, ticks and annotations.
pub fn small_style() -> TextStyle<'static> {
    (FONT_FAMILY, SMALL_FONT).into_font().into()
}

/// The chart builder of a one-panel figure on `root`: `title` as its caption, the common margins, and a y label
/// area `y_label_width` px wide (room for the tick labels).
pub fn figure_chart<'a, 'b, DB: DrawingBackend>(
    root: &'a DrawingArea<DB, Shift>,
    title: &str,
    y_label_width: u32,
) -> ChartBuilder<'a, 'b, DB> {
    let mut builder = ChartBuilder::on(root);
    builder
        .caption(title, title_style())
        .margin(12)
        .margin_right(30)
        .x_label_area_size(46)
        .y_label_area_size(y_label_width);
    builder
}

/// A chart with logarithmic x and y axes.
pub type LogLogChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>;

/// A log–log [`figure_chart`] over the positive ranges `xr` and `yr`, its mesh drawn with the axis descriptions
/// `x_desc`, `y_desc` and [`log_tick`] labels.
pub fn log_log_chart<'a, DB: DrawingBackend>(
    root: &'a DrawingArea<DB, Shift>,
    title: &str,
    y_label_width: u32,
    (xr, yr): ((f64, f64), (f64, f64)),
    x_desc: &str,
    y_desc: &str,
) -> Result<LogLogChart<'a, DB>, crate::analysis::AnalysisError> {
    let mut chart = figure_chart(root, title, y_label_width)
        .build_cartesian_2d((xr.0..xr.1).log_scale(), (yr.0..yr.1).log_scale())
        .map_err(draw_err)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .axis_desc_style(label_style())
        .label_style(small_style())
        .x_label_formatter(&log_tick)
        .y_label_formatter(&log_tick)
        .draw()
        .map_err(draw_err)?;
    Ok(chart)
}

/// Draws the legend of `chart` (the series given a `.label`) at `position`, boxed on a light background.
pub fn draw_legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
) -> PlotResult {
    chart
        .configure_series_labels()
        .position(position)
        .label_font(small_style())
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(|e| crate::analysis::AnalysisError::Output(draw_err(e)))
}

/// Draws the sampled `line` inside the axis ranges ([`inside_runs`]) in `style`, dashed `on` px on and `off` off
/// (`(1000, 0)`: solid); the first run puts `name` in the legend beside a dashed sample `(length, on, off)` px.
pub fn draw_dashed<'a, DB: DrawingBackend + 'a, CT: CoordTranslate<From = (f64, f64)>>(
    chart: &mut ChartContext<'a, DB, CT>,
    line: &[(f64, f64)],
    (xr, yr): ((f64, f64), (f64, f64)),
    (style, on, off): (ShapeStyle, i32, i32),
    name: &str,
    (length, sample_on, sample_off): (i32, i32, i32),
) -> PlotResult {
    for (k, run) in inside_runs(line, xr, yr).into_iter().enumerate() {
        let s = chart
            .draw_series(DashedLineSeries::new(run, on, off, style))
            .map_err(draw_err)?;
        if k == 0 {
            s.label(name).legend(move |(x, y)| {
                plotters::element::DashedPathElement::new(vec![(x, y), (x + length, y)], sample_on, sample_off, style)
            });
        }
    }
    Ok(())
}

/// The smallest and largest of the finite values (`None` without any).
pub fn finite_extent(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold(None, |acc, v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
}

/// A linear axis range around `[lo, hi]` widened by `pad` of its span on each side (a unit span when the
/// values coincide, so plotters always gets a non-empty range).
pub fn padded(lo: f64, hi: f64, pad: f64) -> (f64, f64) {
    let span = hi - lo;
    if span > 0.0 {
        (lo - pad * span, hi + pad * span)
    } else {
        let half = if lo != 0.0 { 0.5 * lo.abs() } else { 0.5 };
        (lo - half, hi + half)
    }
}

/// A logarithmic axis range around the positive `[lo, hi]` widened by the factor `pad` (> 1) on each side
/// (a decade each side when the values coincide), then down to the power of ten below when it would hold
/// none: plotters places log-axis ticks from the first power of ten in the range, so a range inside one
/// decade would get no tick labels at all.
pub fn padded_log(lo: f64, hi: f64, pad: f64) -> (f64, f64) {
    let (lo, hi) = if hi > lo {
        (lo / pad, hi * pad)
    } else {
        (lo / 10.0, hi * 10.0)
    };
    let below = 10f64.powf(lo.log10().floor());
    // a hair below the power of ten, so plotters' `ceil(ln lo / ln 10)` cannot round past it
    if below * 10.0 > hi {
        (below * (1.0 - 1e-6), hi)
    } else {
        (lo, hi)
    }
}

/// `n + 1` points from `x0` to `x1`, evenly spaced in `ln x` (both must be > 0).
pub fn log_samples(x0: f64, x1: f64, n: usize) -> Vec<f64> {
    (0..=n).map(|k| x0 * (x1 / x0).powf(k as f64 / n as f64)).collect()
}

/// `n + 1` points from `x0` to `x1`, evenly spaced.
pub fn linear_samples(x0: f64, x1: f64, n: usize) -> Vec<f64> {
    (0..=n).map(|k| x0 + (x1 - x0) * k as f64 / n as f64).collect()
}

/// Splits a sampled curve into the runs of consecutive points that lie inside the axis ranges. Plotters does
/// not clip lines to the plotting area, so a curve leaving it would be drawn over the labels; drawing each run
/// separately keeps it inside (to within one sample step).
pub fn inside_runs(points: &[(f64, f64)], (x0, x1): (f64, f64), (y0, y1): (f64, f64)) -> Vec<Vec<(f64, f64)>> {
    let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut current = Vec::new();
    for &(x, y) in points {
        if x.is_finite() && y.is_finite() && (x0..=x1).contains(&x) && (y0..=y1).contains(&y) {
            current.push((x, y));
        } else if !current.is_empty() {
            runs.push(std::mem::take(&mut current));
        }
    }
    if !current.is_empty() {
        runs.push(current);
    }
    runs.retain(|r| r.len() >= 2);
    runs
}

/// Margins `(top, bottom, left, right)` (pixels) that make the plotting area of a chart built on an area of
/// `dim` pixels square, given its label-area sizes and a minimum margin: the spare length of the longer side is
/// split between its two margins. Used for the equal-aspect velocity panels (Roig03 Fig. 3).
pub fn square_margins(dim: (u32, u32), x_label_area: u32, y_label_area: u32, margin: u32) -> (u32, u32, u32, u32) {
    let width = dim.0.saturating_sub(y_label_area + 2 * margin);
    let height = dim.1.saturating_sub(x_label_area + 2 * margin);
    let side = width.min(height);
    let (extra_w, extra_h) = (width - side, height - side);
    (
        margin + extra_h / 2,
        margin + extra_h - extra_h / 2,
        margin + extra_w / 2,
        margin + extra_w - extra_w / 2,
    )
}

/// Tick label for a log axis: plain decimals between 0.01 and 1000, scientific outside.
pub fn log_tick(v: &f64) -> String {
    let a = v.abs();
    if (0.01..1000.0).contains(&a) {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.0e}")
    }
}

/// Key points for a log axis over `lo..hi` (both > 0): the 1–2–5 values of every decade inside it, or, where
/// that leaves fewer than three (a range under about a factor of 5), every integer multiple 1–9 of each decade.
/// plotters' own log ticks crowd the top of a decade and repeat labels when the range is narrow.
pub fn log_key_points(lo: f64, hi: f64) -> Vec<f64> {
    let within = |mantissas: &[f64]| -> Vec<f64> {
        let (d0, d1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
        (d0..=d1)
            .flat_map(|d| mantissas.iter().map(move |m| m * 10f64.powi(d)))
            .filter(|v| (lo..=hi).contains(v))
            .collect()
    };
    let coarse = within(&[1.0, 2.0, 5.0]);
    if coarse.len() >= 3 {
        coarse
    } else {
        within(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
    }
}

/// Of the ascending `values`, those at least `min_ratio` (> 1) above the last one kept: key points of a log
/// axis whose labels would otherwise print on top of each other (N = 2000 and 2001, say).
pub fn spread_on_log_axis(values: &[f64], min_ratio: f64) -> Vec<f64> {
    let mut kept: Vec<f64> = Vec::with_capacity(values.len());
    for &v in values {
        if kept.last().is_none_or(|&last| v >= last * min_ratio) {
            kept.push(v);
        }
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_key_points_are_one_two_five_per_decade() {
        assert_eq!(
            log_key_points(300.0, 16_000.0),
            vec![500.0, 1000.0, 2000.0, 5000.0, 10_000.0]
        );
        // under a factor of 5 the 1–2–5 values are too few: every multiple of the decade
        assert_eq!(
            log_key_points(2200.0, 7100.0),
            vec![3000.0, 4000.0, 5000.0, 6000.0, 7000.0]
        );
    }

    #[test]
    fn spread_on_log_axis_drops_values_too_close_to_the_last_kept() {
        assert_eq!(
            spread_on_log_axis(&[200.0, 2000.0, 2001.0, 10_000.0], 1.1),
            vec![200.0, 2000.0, 10_000.0]
        );
    }

    #[test]
    fn font_registers_and_measures_text() {
        ensure_font().unwrap();
        let (w, h) = plotters::style::FontDesc::new(FONT_FAMILY.into(), 20.0, FontStyle::Normal)
            .box_size("spin rate ω (rad/s)")
            .unwrap();
        assert!(w > 100 && h > 10, "{w} × {h}");
    }

    #[test]
    fn inside_runs_splits_at_the_border() {
        let pts = [(0.0, 0.0), (1.0, 1.0), (2.0, 5.0), (3.0, 1.0), (4.0, 1.0), (5.0, 9.0)];
        let runs = inside_runs(&pts, (0.0, 10.0), (0.0, 2.0));
        assert_eq!(runs, vec![vec![(0.0, 0.0), (1.0, 1.0)], vec![(3.0, 1.0), (4.0, 1.0)]]);
    }

    #[test]
    fn square_margins_give_a_square() {
        let (t, b, l, r) = square_margins((400, 520), 40, 60, 10);
        assert_eq!(400 - 60 - l - r, 520 - 40 - t - b);
        assert_eq!((l, r), (10, 10));
    }

    #[test]
    fn ranges_are_never_empty() {
        assert_eq!(padded(2.0, 2.0, 0.1), (1.0, 3.0));
        assert_eq!(padded(0.0, 0.0, 0.1), (-0.5, 0.5));
        assert_eq!(padded_log(1.0, 1.0, 2.0), (0.1, 10.0));
        // inside one decade: extended down to the power of ten, so the axis has ticks
        let (lo, hi) = padded_log(0.2, 0.5, 1.1);
        assert!(lo < 0.1 && lo > 0.0999 && (hi - 0.55).abs() < 1e-12, "{lo} {hi}");
        assert_eq!(padded_log(0.05, 0.5, 1.0), (0.05, 0.5));
        assert_eq!(finite_extent([f64::NAN, 3.0, -1.0]), Some((-1.0, 3.0)));
        assert_eq!(finite_extent([f64::NAN]), None);
    }
}
