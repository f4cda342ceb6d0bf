//! Figures of one run's analysis, as SVG (plotters' SVG backend needs no font files):
//! ejection speed vs size with its power-law fit and the escape line (Roig03 Fig. 4), the spin histogram with
//! the n = 0.5 and Maxwellian-like n = 2 fits (Fig. 6), and spin vs size with its fit (Fig. 8).

use std::path::Path;

use plotters::prelude::*;

use crate::analysis::fits::{PowerLawFit, SpinFit};
use crate::analysis::fragments::FragmentReport;
use crate::analysis::run_analysis::{Fit, RunAnalysis};

type PlotResult = Result<(), String>;

fn e(err: impl std::fmt::Display) -> String {
    err.to_string()
}

/// Log–log scatter of `(x, y)` with an optional power-law line and an optional horizontal line.
fn scatter_log_log(
    path: &Path,
    title: &str,
    (x_label, y_label): (&str, &str),
    points: &[(f64, f64)],
    fit: Option<&PowerLawFit>,
    horizontal: Option<(f64, &str)>,
) -> PlotResult {
    let pts: Vec<(f64, f64)> = points.iter().copied().filter(|(x, y)| *x > 0.0 && *y > 0.0).collect();
    if pts.is_empty() {
        return Err(format!("{}: nothing positive to plot", path.display()));
    }
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, 0.0_f64, f64::INFINITY, 0.0_f64);
    for &(x, y) in &pts {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    if let Some((h, _)) = horizontal {
        (y0, y1) = (y0.min(h), y1.max(h));
    }
    let root = SVGBackend::new(path, (720, 520)).into_drawing_area();
    root.fill(&WHITE).map_err(e)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(42)
        .y_label_area_size(72)
        .build_cartesian_2d((x0 * 0.8..x1 * 1.25).log_scale(), (y0 * 0.5..y1 * 2.0).log_scale())
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .x_label_formatter(&|v| format!("{v:.3}"))
        .y_label_formatter(&|v| format!("{v:.3e}"))
        .draw()
        .map_err(e)?;
    chart
        .draw_series(pts.iter().map(|&p| Circle::new(p, 3, BLUE.mix(0.6).filled())))
        .map_err(e)?
        .label("fragments");
    if let Some(f) = fit {
        let line: Vec<(f64, f64)> = (0..=50)
            .map(|k| x0 * (x1 / x0).powf(k as f64 / 50.0))
            .map(|x| (x, f.c * x.powf(f.alpha)))
            .collect();
        chart
            .draw_series(LineSeries::new(line, RED.stroke_width(2)))
            .map_err(e)?
            .label(format!("fit: exponent {:.2} ± {:.2}", f.alpha, f.sigma_alpha))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
    }
    if let Some((h, name)) = horizontal {
        chart
            .draw_series(LineSeries::new(
                vec![(x0 * 0.8, h), (x1 * 1.25, h)],
                BLACK.stroke_width(1),
            ))
            .map_err(e)?
            .label(name.to_string())
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(e)?;
    root.present().map_err(e)
}

/// The spin histogram (bars) with the fitted curves for the given exponents.
fn spin_histogram(path: &Path, centres: &[f64], counts: &[f64], fits: &[&SpinFit]) -> PlotResult {
    if centres.len() < 2 {
        return Err(format!("{}: histogram has fewer than 2 bins", path.display()));
    }
    let width = centres[1] - centres[0];
    let x1 = centres.last().unwrap() + width;
    let y1 = counts.iter().cloned().fold(1.0, f64::max) * 1.3;
    let root = SVGBackend::new(path, (720, 520)).into_drawing_area();
    root.fill(&WHITE).map_err(e)?;
    let mut chart = ChartBuilder::on(&root)
        .caption("Spin rates of the target fragments (corrected)", ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(42)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..x1, 0.0..y1)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("spin rate ω (rad/s)")
        .y_desc("fragments per bin")
        .x_label_formatter(&|v| format!("{v:.1e}"))
        .draw()
        .map_err(e)?;
    chart
        .draw_series(
            centres
                .iter()
                .zip(counts)
                .map(|(&c, &n)| Rectangle::new([(c - 0.5 * width, 0.0), (c + 0.5 * width, n)], BLUE.mix(0.3).filled())),
        )
        .map_err(e)?;
    for (k, f) in fits.iter().enumerate() {
        let colour = Palette99::pick(k + 1).to_rgba();
        let line: Vec<(f64, f64)> = (0..=200)
            .map(|i| x1 * i as f64 / 200.0)
            .map(|x| (x, f.evaluate(x)))
            .collect();
        chart
            .draw_series(LineSeries::new(line, colour.stroke_width(2)))
            .map_err(e)?
            .label(format!("a xⁿ exp(−x²/b²), n = {:.2}: residual {:.3e}", f.n, f.rss))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(e)?;
    root.present().map_err(e)
}

/// Writes `ejection_vs_size.svg`, `spin_histogram.svg` and `spin_vs_size.svg` into `dir`; returns the files
/// written and, for figures that could not be drawn, why.
pub fn write_run_figures(dir: &Path, analysis: &RunAnalysis, report: &FragmentReport) -> (Vec<String>, Vec<String>) {
    let target: Vec<_> = report.fragments.iter().filter(|f| !f.is_projectile).collect();
    let fit_of = |f: &Fit<PowerLawFit>| match f {
        Fit::Ok(p) => Some(*p),
        Fit::Failed(_) => None,
    };
    let mut written = Vec::new();
    let mut failed = Vec::new();
    let mut record = |name: &str, r: PlotResult| match r {
        Ok(()) => written.push(name.to_string()),
        Err(why) => failed.push(format!("{name}: {why}")),
    };
    let ejection: Vec<(f64, f64)> = target.iter().map(|f| (f.size, f.ejection_speed)).collect();
    record(
        "ejection_vs_size.svg",
        scatter_log_log(
            &dir.join("ejection_vs_size.svg"),
            &format!("Ejection speed vs size at t = {} s", analysis.t_at),
            ("size / parent-body effective radius", "ejection speed |Δv| (m/s)"),
            &ejection,
            fit_of(&analysis.ejection_speed_vs_size).as_ref(),
            Some((analysis.summary.escape_velocity, "escape speed v_esc")),
        ),
    );
    let spins: Vec<(f64, f64)> = target.iter().map(|f| (f.size, f.spin_rate_corrected)).collect();
    record(
        "spin_vs_size.svg",
        scatter_log_log(
            &dir.join("spin_vs_size.svg"),
            &format!("Spin rate vs size at t = {} s", analysis.t_at),
            ("size / parent-body effective radius", "spin rate ω, corrected (rad/s)"),
            &spins,
            fit_of(&analysis.spin_vs_size).as_ref(),
            None,
        ),
    );
    let fits: Vec<&SpinFit> = match &analysis.spin_fits {
        Fit::Ok(c) => c.fixed.iter().filter(|f| f.n == 0.5 || f.n == 2.0).collect(),
        Fit::Failed(_) => Vec::new(),
    };
    record(
        "spin_histogram.svg",
        spin_histogram(
            &dir.join("spin_histogram.svg"),
            &analysis.spin_histogram.0,
            &analysis.spin_histogram.1,
            &fits,
        ),
    );
    (written, failed)
}
