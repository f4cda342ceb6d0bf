//! Figures of a campaign (Roig03 Figs. 5 and 7), written by `rubblepile analyze-campaign DIR` into
//! `DIR/analysis/` as SVG and PNG:
//!
//! | file stem | Roig03 | content |
//! |---|---|---|
//! | `bound_fraction_vs_q` | Fig. 5 | bound mass fraction vs Q: runs, per-projectile means with max-excursion bars, fit, paper's line, Q*_D; beside it each run's largest remnant over the total mass |
//! | `spin_distributions` | Fig. 7 | Eq. 45-normalised best fits `a xⁿ exp(−x²/b²)` of the spin histograms, one per projectile |
//!
//! Fig. 5 groups the runs by projectile: all runs with one projectile have (nearly) the same Q — the targets'
//! masses differ by a little — so a group's point is its mean Q and mean bound fraction, and its error bar
//! spans the group's smallest to largest bound fraction ("the error bars represent the maximum excursions").

use std::path::Path;

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use crate::analysis::figures::style::{
    DATA_COLOUR, FIT_COLOUR, Figure, FigureLog, GUIDE_COLOUR, PlotResult, REFERENCE_COLOUR, SERIES_COLOURS,
    draw_dashed, draw_err, draw_legend, figure_chart, finite_extent, inside_runs, label_style, linear_samples,
    small_style, write_figure,
};
use crate::analysis::fits::{LineCrossing, LineFit, spin_integral};
use crate::analysis::run_analysis::{CampaignAnalysis, Fit};

/// The paper's fit of Fig. 5: bound fraction `1.04 − 0.2 × 10⁻⁹ Q` (Q in erg/g).
pub const PAPER_BOUND_FRACTION: (f64, f64) = (1.04, -0.2e-9);

/// Roig03 Fig. 5: bound mass fraction vs specific impact energy.
#[derive(Debug, Clone)]
pub struct BoundFractionVsQ {
    /// Figure title.
    pub title: String,
    /// `(group label, Q (erg/g), bound mass fraction)` per run; runs are grouped by label.
    pub runs: Vec<(String, f64, f64)>,
    /// `(Q (erg/g), largest remnant over the mass of all bodies)` per run ([`crate::analysis::clumps`]), drawn
    /// beside the bound fractions.
    pub largest_remnant: Vec<(f64, f64)>,
    /// The least-squares line through all runs.
    pub fit: Option<LineFit>,
    /// Where that line crosses 0.5 (Q*_D, erg/g).
    pub q_star_d: Option<LineCrossing>,
}

/// One group of Fig. 5: label, mean Q, mean bound fraction, smallest and largest bound fraction.
#[derive(Debug, Clone, PartialEq)]
pub struct QGroup {
    /// Group label (the projectile).
    pub label: String,
    /// Mean Q of the group (erg/g).
    pub q: f64,
    /// Mean bound fraction.
    pub mean: f64,
    /// Smallest bound fraction.
    pub min: f64,
    /// Largest bound fraction.
    pub max: f64,
}

impl BoundFractionVsQ {
    /// The runs grouped by label, sorted by mean Q.
    pub fn groups(&self) -> Vec<QGroup> {
        let mut labels: Vec<&str> = self.runs.iter().map(|r| r.0.as_str()).collect();
        labels.sort_unstable();
        labels.dedup();
        let mut groups: Vec<QGroup> = labels
            .into_iter()
            .map(|label| {
                let members: Vec<_> = self.runs.iter().filter(|r| r.0 == label).collect();
                let n = members.len() as f64;
                QGroup {
                    label: label.to_string(),
                    q: members.iter().map(|r| r.1).sum::<f64>() / n,
                    mean: members.iter().map(|r| r.2).sum::<f64>() / n,
                    min: members.iter().map(|r| r.2).fold(f64::INFINITY, f64::min),
                    max: members.iter().map(|r| r.2).fold(f64::NEG_INFINITY, f64::max),
                }
            })
            .collect();
        groups.sort_by(|a, b| a.q.total_cmp(&b.q));
        groups
    }
}

impl Figure for BoundFractionVsQ {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> PlotResult {
        let runs: Vec<&(String, f64, f64)> = self
            .runs
            .iter()
            .filter(|r| r.1.is_finite() && r.2.is_finite())
            .collect();
        let Some((_, q_max)) = finite_extent(runs.iter().map(|r| r.1)) else {
            return Err("no run to plot".into());
        };
        let q_star = self.q_star_d.map(|c| c.x).filter(|x| x.is_finite() && *x > 0.0);
        // Q from 0, so the intercepts of the fitted and published lines are visible.
        let x1 = 1.15 * q_max.max(q_star.unwrap_or(0.0)).max(3.0e9);
        let (xr, yr) = ((0.0, x1), (0.0, 1.15));
        let mut chart = figure_chart(root, &self.title, 64)
            .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .x_desc("specific impact energy Q (erg/g)")
            .y_desc("bound fraction of the target mass; largest remnant (dimensionless)")
            .axis_desc_style(label_style())
            .label_style(small_style())
            .x_label_formatter(&|v| format!("{v:.1e}"))
            .draw()
            .map_err(draw_err)?;
        let qs = linear_samples(xr.0, xr.1, 100);
        let guide = GUIDE_COLOUR.stroke_width(1);
        chart
            .draw_series(DashedLineSeries::new(vec![(xr.0, 0.5), (xr.1, 0.5)], 2, 4, guide))
            .map_err(draw_err)?
            .label("half the target mass")
            .legend(move |(x, y)| DashedPathElement::new(vec![(x, y), (x + 20, y)], 2, 3, guide));
        let (a, b) = PAPER_BOUND_FRACTION;
        let paper: Vec<(f64, f64)> = qs.iter().map(|&q| (q, a + b * q)).collect();
        let (reference, name) = (
            (REFERENCE_COLOUR.stroke_width(2), 8, 5),
            "Roig et al. (2003): 1.04 − 0.2×10⁻⁹ Q",
        );
        draw_dashed(&mut chart, &paper, (xr, yr), reference, name, (20, 6, 3))?;
        if let Some(f) = &self.fit {
            let line: Vec<(f64, f64)> = qs.iter().map(|&q| (q, f.intercept + f.slope * q)).collect();
            for (k, run) in inside_runs(&line, xr, yr).into_iter().enumerate() {
                let s = chart
                    .draw_series(LineSeries::new(run, FIT_COLOUR.stroke_width(2)))
                    .map_err(draw_err)?;
                if k == 0 {
                    s.label(format!(
                        "fit: {:.3} {} {:.3}×10⁻⁹ Q",
                        f.intercept,
                        if f.slope < 0.0 { "−" } else { "+" },
                        (f.slope * 1e9).abs()
                    ))
                    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], FIT_COLOUR.stroke_width(2)));
                }
            }
        }
        if let Some(q) = q_star.filter(|q| *q <= xr.1) {
            let style = FIT_COLOUR.stroke_width(1);
            let sigma = self.q_star_d.map_or(f64::NAN, |c| c.sigma_x);
            chart
                .draw_series(DashedLineSeries::new(vec![(q, yr.0), (q, yr.1)], 2, 4, style))
                .map_err(draw_err)?
                .label(format!("Q*_D = {q:.2e} ± {sigma:.1e} erg/g"))
                .legend(move |(x, y)| DashedPathElement::new(vec![(x, y), (x + 20, y)], 2, 3, style));
        }
        chart
            .draw_series(
                runs.iter()
                    .map(|r| Circle::new((r.1, r.2), 3, DATA_COLOUR.mix(0.45).filled())),
            )
            .map_err(draw_err)?
            .label(format!("runs ({})", runs.len()))
            .legend(|(x, y)| Circle::new((x + 10, y), 3, DATA_COLOUR.mix(0.45).filled()));
        let remnants: Vec<(f64, f64)> = self
            .largest_remnant
            .iter()
            .copied()
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .collect();
        if !remnants.is_empty() {
            let colour = SERIES_COLOURS[2];
            let marker = move |(x, y): (i32, i32)| {
                PathElement::new(
                    vec![(x - 4, y + 3), (x + 4, y + 3), (x, y - 4), (x - 4, y + 3)],
                    colour.stroke_width(2),
                )
            };
            chart
                .draw_series(remnants.iter().map(|&p| EmptyElement::at(p) + marker((0, 0))))
                .map_err(draw_err)?
                .label(format!("largest remnant / total mass ({} runs)", remnants.len()))
                .legend(move |(x, y)| marker((x + 10, y)));
        }
        let groups = self.groups();
        let bar = BLACK.stroke_width(2);
        chart
            .draw_series(groups.iter().map(|g| {
                let cap = 0.012 * xr.1;
                PathElement::new(
                    vec![
                        (g.q - cap, g.min),
                        (g.q + cap, g.min),
                        (g.q, g.min),
                        (g.q, g.max),
                        (g.q - cap, g.max),
                        (g.q + cap, g.max),
                    ],
                    bar,
                )
            }))
            .map_err(draw_err)?;
        chart
            .draw_series(groups.iter().map(|g| Circle::new((g.q, g.mean), 5, BLACK.filled())))
            .map_err(draw_err)?
            .label("mean per projectile, bars: max excursion")
            .legend(|(x, y)| Circle::new((x + 10, y), 5, BLACK.filled()));
        chart
            .draw_series(
                groups
                    .iter()
                    .map(|g| Text::new(g.label.clone(), (g.q + 0.018 * xr.1, g.mean), small_style())),
            )
            .map_err(draw_err)?;
        draw_legend(&mut chart, SeriesLabelPosition::UpperRight)
    }
}

/// Eq. 45: the normalised density `f(x) = a xⁿ exp(−x²/b²)` with `a = 2/(bⁿ⁺¹ Γ((n+1)/2))`, so that
/// `∫₀^∞ f = 1` (n > −1, b > 0).
pub fn normalised_spin_density(x: f64, n: f64, b: f64) -> f64 {
    // xⁿ is 0 at x = 0 for n > 0 (powf would give it too, but 0 · exp is explicit); nothing below 0
    if x < 0.0 || (x == 0.0 && n > 0.0) {
        return 0.0;
    }
    x.powf(n) * (-(x * x) / (b * b)).exp() / spin_integral(1.0, b, n)
}

/// Roig03 Fig. 7: the Eq. 45-normalised best fits of the spin distributions, one curve per projectile
/// (P1 dash-dotted, P2 dashed, P3 solid in the paper; here the k-th curve gets the k-th of those styles from
/// the last, plus a colour).
#[derive(Debug, Clone)]
pub struct SpinDistributions {
    /// Figure title.
    pub title: String,
    /// `(label, n, b)` per curve, `b` in `x_unit`.
    pub fits: Vec<(String, f64, f64)>,
    /// Unit of the spin rate `x` (and of `b`), e.g. `rad/s`.
    pub x_unit: String,
}

impl Figure for SpinDistributions {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> PlotResult {
        let fits: Vec<&(String, f64, f64)> = self
            .fits
            .iter()
            .filter(|f| f.1 > -1.0 && f.2 > 0.0 && f.1.is_finite() && f.2.is_finite())
            .collect();
        if fits.is_empty() {
            return Err("no usable fit (need n > −1 and b > 0)".into());
        }
        let b_max = fits.iter().map(|f| f.2).fold(0.0, f64::max);
        let x1 = 3.0 * b_max;
        let xs = linear_samples(0.0, x1, 400);
        let curves: Vec<Vec<(f64, f64)>> = fits
            .iter()
            .map(|f| xs.iter().map(|&x| (x, normalised_spin_density(x, f.1, f.2))).collect())
            .collect();
        let peak = curves
            .iter()
            .flatten()
            .map(|p| p.1)
            .filter(|y| y.is_finite())
            .fold(0.0, f64::max);
        let yr = (0.0, 1.2 * peak);
        let mut chart = figure_chart(root, &self.title, 78)
            .build_cartesian_2d(0.0..x1, yr.0..yr.1)
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .x_desc(format!("spin rate x ({})", self.x_unit))
            .y_desc(format!("normalised distribution f(x) (1/({}))", self.x_unit))
            .axis_desc_style(label_style())
            .label_style(small_style())
            .x_label_formatter(&|v| format!("{v:.1e}"))
            .y_label_formatter(&|v| format!("{v:.1e}"))
            .draw()
            .map_err(draw_err)?;
        let count = fits.len();
        for (k, (f, curve)) in fits.iter().zip(curves).enumerate() {
            // the last curve solid, the one before dashed, the others short-dashed, as the paper's P3, P2, P1
            let (on, off) = match count - 1 - k {
                0 => (1000, 0),
                1 => (8, 5),
                _ => (3, 3),
            };
            let style = (SERIES_COLOURS[k % SERIES_COLOURS.len()].stroke_width(2), on, off);
            let name = format!("{}: n = {}, b = {:.3e} {}", f.0, f.1, f.2, self.x_unit);
            draw_dashed(&mut chart, &curve, ((0.0, x1), yr), style, &name, (24, on.min(24), off))?;
        }
        draw_legend(&mut chart, SeriesLabelPosition::UpperRight)
    }
}

/// Draws Fig. 7 (`spin_distributions.svg` / `.png`) into `dir` from plain `(label, n, b)` fits, `b` in
/// `x_unit` (corrected spin rates, §4.3, when they come from the campaign analysis). Returns the files written.
pub fn write_spin_distributions(
    dir: &Path,
    fits: &[(&str, f64, f64)],
    x_unit: &str,
) -> Result<[String; 2], crate::analysis::AnalysisError> {
    let fig = SpinDistributions {
        title: "Normalised best fits of the fragments' corrected spin distributions (Eq. 45)".into(),
        fits: fits.iter().map(|&(l, n, b)| (l.to_string(), n, b)).collect(),
        x_unit: x_unit.to_string(),
    };
    write_figure(dir, "spin_distributions", &fig)
}

/// The curves of Fig. 7 from the campaign's per-projectile spin distributions: `(label, n, b)` of each best
/// fixed-n fit (b in rad/s, corrected spins), sorted by Q so the most energetic projectile comes last (solid, as
/// the paper's P3); plus a note for each projectile whose fits failed.
pub fn spin_distribution_curves(analysis: &CampaignAnalysis) -> (Vec<(String, f64, f64)>, Vec<String>) {
    let mut dists: Vec<_> = analysis.spin_distributions.iter().collect();
    dists.sort_by(|a, b| a.q_erg_per_g.total_cmp(&b.q_erg_per_g));
    let mut curves = Vec::new();
    let mut missing = Vec::new();
    for d in dists {
        match (d.best(), &d.fits) {
            (Some(f), _) => curves.push((
                format!(
                    "{} (Q = {:.2e} erg/g, {} fragments)",
                    d.projectile, d.q_erg_per_g, d.fragments
                ),
                f.n,
                f.b,
            )),
            (None, Fit::Failed(why)) => missing.push(format!("{}: no fit ({why})", d.projectile)),
            (None, Fit::Ok(_)) => missing.push(format!("{}: no fit", d.projectile)),
        }
    }
    (curves, missing)
}

/// Writes the campaign figures into `campaign_dir/analysis/`: Fig. 5 `bound_fraction_vs_q` and Fig. 7
/// `spin_distributions` (from [`spin_distribution_curves`]). Returns the files written and, for each figure that
/// could not be drawn (or projectile left out of Fig. 7), why.
pub fn write_campaign_figures(campaign_dir: &Path, analysis: &CampaignAnalysis) -> (Vec<String>, Vec<String>) {
    let dir = campaign_dir.join("analysis");
    let mut log = FigureLog::default();
    // the runs of Q*_D's fit (one target at one angle; all the target's runs when no angle could be chosen)
    let selection = &analysis.q_star_runs;
    let fitted = || {
        analysis
            .runs
            .iter()
            .filter(|r| selection.holds(r) || (selection.angle_deg.is_none() && r.target == selection.target))
    };
    let fig5 = BoundFractionVsQ {
        title: format!(
            "Bound mass fraction vs specific impact energy, {}, at t = {} s",
            analysis.q_star_runs.label(),
            analysis.t_at
        ),
        runs: fitted()
            .map(|r| (r.projectile.clone(), r.q_erg_per_g, r.bound_mass_fraction))
            .collect(),
        largest_remnant: fitted()
            .filter_map(|r| Some((r.q_erg_per_g, r.largest_remnant_fraction?)))
            .collect(),
        fit: analysis.bound_fraction_vs_q.ok().copied(),
        q_star_d: analysis.q_star_d.ok().copied(),
    };
    log.write(&dir, "bound_fraction_vs_q", &fig5);
    let (curves, missing) = spin_distribution_curves(analysis);
    for m in missing {
        log.record("spin_distributions", Err(m));
    }
    let fits: Vec<(&str, f64, f64)> = curves.iter().map(|(l, n, b)| (l.as_str(), *n, *b)).collect();
    let drawn = write_spin_distributions(&dir, &fits, "rad/s");
    log.record("spin_distributions", drawn.map_err(String::from));
    (log.written, log.failed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::figures::testing::{assert_figure_files, assert_writes, temp_dir};

    /// ∫₀^∞ of the plotted curve is 1 (Eq. 45), by the trapezoidal rule on x = b u², which removes the
    /// xⁿ cusp at 0 for small n; the integrand is negligible beyond 12 b.
    #[test]
    fn eq45_normalised_curves_integrate_to_one() {
        for (n, b) in [(0.5, 3e-4), (1.0, 1.0), (1.5, 2e-3), (2.0, 7.5), (0.0, 0.2)] {
            let (steps, u_max) = (200_000, 12f64.sqrt());
            let h = u_max / steps as f64;
            let integral: f64 = (0..=steps)
                .map(|k| {
                    let u = k as f64 * h;
                    let w = if k == 0 || k == steps { 0.5 } else { 1.0 };
                    // dx = 2 b u du
                    w * normalised_spin_density(b * u * u, n, b) * 2.0 * b * u * h
                })
                .sum();
            assert!((integral - 1.0).abs() < 1e-3, "n = {n}, b = {b}: ∫ = {integral}");
        }
        // and it is the fit's own normalised amplitude a₁ = 2/(bⁿ⁺¹ Γ((n+1)/2)): for n = 1, a₁ = 2/b²
        assert!((normalised_spin_density(1.0, 1.0, 2.0) - 0.5 * (-0.25f64).exp()).abs() < 1e-12);
    }

    #[test]
    fn spin_distributions_writes_both_files() {
        let dir = temp_dir("spin-distributions");
        let files = write_spin_distributions(
            &dir,
            &[("P1", 0.5, 2e-4), ("P2", 0.5, 4e-4), ("P3", 1.0, 6e-4)],
            "rad/s",
        )
        .unwrap();
        assert_eq!(files, ["spin_distributions.svg", "spin_distributions.png"]);
        let svg = assert_figure_files(&dir, "spin_distributions", &["spin rate x (rad/s)", "f(x) (1/(rad/s))"]);
        assert!(svg.contains("P1: n = 0.5") && svg.contains("P3: n = 1"));
        assert!(write_spin_distributions(&dir, &[("bad", 0.5, -1.0)], "rad/s").is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn bound_fraction_groups_and_writes_both_files() {
        let fig = BoundFractionVsQ {
            title: "Bound mass fraction vs Q".into(),
            runs: vec![
                ("P1".into(), 0.44e9, 0.97),
                ("P1".into(), 0.45e9, 0.93),
                ("P2".into(), 1.49e9, 0.74),
                ("P3".into(), 3.54e9, 0.31),
                ("P3".into(), 3.50e9, 0.35),
            ],
            largest_remnant: vec![(0.44e9, 0.99), (1.49e9, 0.62)],
            fit: crate::analysis::fits::fit_line(&[0.44e9, 1.49e9, 3.54e9], &[0.95, 0.74, 0.33]).ok(),
            q_star_d: Some(LineCrossing { x: 2.6e9, sigma_x: 1e8 }),
        };
        let g = fig.groups();
        assert_eq!(g.len(), 3);
        assert_eq!(g[0].label, "P1");
        assert!((g[0].q - 0.445e9).abs() < 1.0 && (g[0].mean - 0.95).abs() < 1e-12);
        assert_eq!((g[2].min, g[2].max), (0.31, 0.35));
        let svg = assert_writes(
            "bound_fraction_vs_q",
            &fig,
            &[
                "specific impact energy Q (erg/g)",
                "bound fraction of the target mass; largest remnant (dimensionless)",
            ],
        );
        assert!(svg.contains("Q*_D = 2.60e9") && svg.contains("1.04 − 0.2×10⁻⁹ Q"));
        assert!(svg.contains("largest remnant / total mass (2 runs)"));
    }
}
