//! The Roig03 reproduction report: every published outcome of Roig et al. (2003) §4 beside ours, from one
//! analysed campaign (plus, optionally, the uniform-inertia partner run of §4.3).
//!
//! [`write_report`] writes `REPORT.md` and copies the figures it cites into `figures/` of the output directory.
//! Every number in the report is either one run's (named by its directory in the campaign index
//! `campaign.csv`) or an aggregate over a set of runs that the report names (all completed runs, or a stated
//! subset such as "the runs with P2"); the per-run appendix lists every run's numbers.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::kappa::{FIG4_EXPONENTS, FIG8_EXPONENTS, overrun_pairs};
use rubblepile::analysis::campaign_analysis::analyze_campaign;
use rubblepile::analysis::run_analysis::{AnalysisError, CampaignAnalysis, CampaignRun, Fit, SpinSelection};
use rubblepile::analysis::spin_likelihood::format_p;

/// A published outcome of Roig03 as a closed interval (with the paper's words).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Published {
    /// Lower end.
    pub low: f64,
    /// Upper end.
    pub high: f64,
}

impl Published {
    fn contains(&self, x: f64) -> bool {
        x >= self.low && x <= self.high
    }
}

/// Roig03 §4.1: f_KE between 1 and 5 %.
pub const F_KE: Published = Published { low: 0.01, high: 0.05 };
/// Roig03 §4.1: rotational share of the fragments' kinetic energy, 10–20 %.
pub const ROTATIONAL_SHARE: Published = Published { low: 0.10, high: 0.20 };
/// Roig03 §4.2: ejection speed vs size exponent, −0.50 … −0.10.
pub const EJECTION_EXPONENT: Published = Published {
    low: -0.50,
    high: -0.10,
};
/// Roig03 §4.3: spin rate vs size exponent, −1.4 … −1.0.
pub const SPIN_EXPONENT: Published = Published { low: -1.4, high: -1.0 };
/// Roig03 §4.3: the n = 2 (Maxwellian) residual is 2–3 times the best (n = 0.5) one.
pub const MAXWELLIAN_RATIO: Published = Published { low: 2.0, high: 3.0 };
/// Roig03 §4.2: typical ejection speeds, 0.01–0.05 % of the projectile speed (as printed).
pub const EJECTION_RELATIVE: Published = Published { low: 1e-4, high: 5e-4 };
/// Seed of Q*_D's bootstrap interval in the report.
const BOOTSTRAP_SEED: u64 = 1;

/// Roig03 §4.2 (Fig. 5): Q*_D ≈ 2.6e9 erg/g.
pub const Q_STAR_D: f64 = 2.6e9;
/// What the report needs besides the campaign analysis.
#[derive(Debug, Clone)]
pub struct ReportInputs<'a> {
    /// The analysed campaign.
    pub campaign: &'a CampaignAnalysis,
    /// Its directory (holding `campaign.csv` and the run directories).
    pub campaign_dir: &'a Path,
    /// The uniform-inertia campaign, analysed, and its directory (§4.3 spin bias), if there is one.
    pub uniform: Option<(&'a CampaignAnalysis, &'a Path)>,
    /// The same grid under another reading of Roig03 Eq. 13's `K`, analysed, and its directory, if there is one.
    pub other_kappa: Option<(&'a CampaignAnalysis, &'a Path)>,
    /// The command that regenerates the report, quoted in it.
    pub command: String,
}

/// The campaign directories a report is made from (see `rubblepile report roig2003 --help`).
#[derive(Debug, Clone, Copy)]
pub struct CampaignDirs<'a> {
    /// The main campaign (`analysis/roig2003/campaign.toml`).
    pub campaign: &'a Path,
    /// The uniform-inertia partner (`campaign_uniform.toml`), if any.
    pub uniform: Option<&'a Path>,
    /// The same grid under another reading of Eq. 13's `K` (`campaign_printed.toml`), if any.
    pub other_kappa: Option<&'a Path>,
}

impl CampaignDirs<'_> {
    /// The command that regenerates the report from these directories into `out` at `at` seconds.
    fn command(&self, out: &Path, at: f64) -> String {
        let mut command = format!(
            "rubblepile report roig2003 {} --out {}",
            self.campaign.display(),
            out.display()
        );
        for (flag, dir) in [("--uniform", self.uniform), ("--other-kappa", self.other_kappa)] {
            if let Some(d) = dir {
                command += &format!(" {flag} {}", d.display());
            }
        }
        if at != 400.0 {
            command += &format!(" --at-s {at}");
        }
        command + " --force"
    }
}

/// Re-analyses every campaign of `dirs` at `at` seconds (rewriting their `analysis/`) and writes `out/REPORT.md`;
/// returns its path and the main campaign's analysis.
pub fn regenerate(dirs: &CampaignDirs<'_>, at: f64, out: &Path) -> Result<(PathBuf, CampaignAnalysis), AnalysisError> {
    // Roig03 Fig. 5 fits its whole campaign at once: the reproduction pools Q*_D the same way.
    let pooled = SpinSelection {
        pool_q_star: true,
        ..SpinSelection::default()
    };
    let analyse = |dir: &Path| analyze_campaign(dir, at, true, &pooled, BOOTSTRAP_SEED);
    let campaign = analyse(dirs.campaign)?;
    let uniform = dirs.uniform.map(|d| analyse(d).map(|a| (a, d))).transpose()?;
    let other_kappa = dirs.other_kappa.map(|d| analyse(d).map(|a| (a, d))).transpose()?;
    let inputs = ReportInputs {
        campaign: &campaign,
        campaign_dir: dirs.campaign,
        uniform: uniform.as_ref().map(|(a, d)| (a, *d)),
        other_kappa: other_kappa.as_ref().map(|(a, d)| (a, *d)),
        command: dirs.command(out, at),
    };
    let write_error = |e: std::io::Error| AnalysisError::Write {
        path: out.to_path_buf(),
        reason: e.to_string(),
    };
    std::fs::create_dir_all(out).map_err(write_error)?;
    let path = write_report(&inputs, out).map_err(write_error)?;
    Ok((path, campaign))
}

/// Runs of `runs` whose values `f` are finite, as (value, run name).
fn values(runs: &[CampaignRun], f: impl Fn(&CampaignRun) -> Option<f64>) -> Vec<(f64, &str)> {
    runs.iter()
        .filter_map(|r| f(r).filter(|v| v.is_finite()).map(|v| (v, r.run.as_str())))
        .collect()
}

/// Median of the values of `v` (NaN when empty).
fn median(v: &[(f64, &str)]) -> f64 {
    rubblepile::math::median(&v.iter().map(|p| p.0).collect::<Vec<_>>())
}

/// "min (run) … max (run), median m; k of n inside [low, high]".
fn summary_cell(v: &[(f64, &str)], published: Option<Published>, fmt: &dyn Fn(f64) -> String) -> String {
    if v.is_empty() {
        return "no run has this value".into();
    }
    let lo = v.iter().min_by(|a, b| a.0.total_cmp(&b.0)).expect("non-empty");
    let hi = v.iter().max_by(|a, b| a.0.total_cmp(&b.0)).expect("non-empty");
    let mut s = format!(
        "{} (`{}`) … {} (`{}`); median {}",
        fmt(lo.0),
        lo.1,
        fmt(hi.0),
        hi.1,
        fmt(median(v))
    );
    if let Some(p) = published {
        let inside = v.iter().filter(|x| p.contains(x.0)).count();
        let below = v.iter().filter(|x| x.0 < p.low).count();
        let _ = write!(s, "; {inside} of {} runs inside, {below} below", v.len());
    }
    s
}

fn pct(x: f64) -> String {
    format!("{:.2} %", 100.0 * x)
}

fn num2(x: f64) -> String {
    format!("{x:.2}")
}

fn opt(x: Option<f64>, fmt: &dyn Fn(f64) -> String) -> String {
    x.map_or_else(|| "–".into(), fmt)
}

/// Copies `run_dir/analysis/<stem>.{svg,png}` to `figures/<prefix>_<run>.{svg,png}`; returns the markdown
/// image link (PNG when there is one, else SVG) or a note that the figure is missing.
fn copy_figure(figures: &Path, run_dir: &Path, run: &str, stem: &str, prefix: &str) -> String {
    let mut link = None;
    for ext in ["svg", "png"] {
        let from = run_dir.join("analysis").join(format!("{stem}.{ext}"));
        let name = format!("{prefix}_{run}.{ext}");
        if from.is_file() && std::fs::copy(&from, figures.join(&name)).is_ok() && (ext == "png" || link.is_none()) {
            link = Some(name);
        }
    }
    match link {
        Some(name) => format!("![{prefix} {run}](figures/{name})"),
        None => format!("*({stem} of `{run}` was not drawn)*"),
    }
}

fn find<'a>(runs: &'a [CampaignRun], target: &str, projectile: &str, angle: f64) -> Option<&'a CampaignRun> {
    runs.iter()
        .find(|r| r.target == target && r.projectile == projectile && r.angle_deg == angle)
}

/// Writes `out_dir/REPORT.md` and `out_dir/figures/` (replacing earlier ones); returns the report's path.
pub fn write_report(inputs: &ReportInputs<'_>, out_dir: &Path) -> std::io::Result<PathBuf> {
    let c = inputs.campaign;
    let runs = &c.runs;
    let figures = out_dir.join("figures");
    std::fs::create_dir_all(&figures)?;
    let mut md = String::new();
    let w = &mut md;
    let _ = writeln!(w, "# Roig et al. (2003) §4, reproduced\n");
    let _ = writeln!(
        w,
        "Generated by `{}` from the analysed campaign `{}` ({} completed runs, {} not completed: {}), at t = {} s \
         (≈ 300 s after first contact, as the paper). Do not edit by hand: edit the generator \
         (`src/studies/roig2003/report.rs`) or `DISCUSSION.md`, which is included below as written.\n",
        inputs.command,
        inputs.campaign_dir.display(),
        runs.len(),
        c.skipped.len(),
        if c.skipped.is_empty() {
            "none".to_string()
        } else {
            c.skipped.join(", ")
        },
        c.t_at
    );
    let _ = writeln!(
        w,
        "Run names are directories of the campaign (`TARGET_PROJECTILE_zANGLE_sSEED`), each listed in its \
         `campaign.csv`; a range names the runs at its ends. Every run's numbers are in the appendix.\n"
    );

    // ---------------------------------------------------------------- outcomes
    let _ = writeln!(w, "## Published outcomes beside ours\n");
    let _ = writeln!(w, "| outcome (Roig03) | published | ours, over all completed runs |");
    let _ = writeln!(w, "|---|---|---|");
    let row = |w: &mut String, name: &str, published: &str, cell: String| {
        let _ = writeln!(w, "| {name} | {published} | {cell} |");
    };
    row(
        w,
        "f_KE: fragment KE / projectile KE (§4.1)",
        "1–5 %",
        summary_cell(&values(runs, |r| Some(r.f_ke)), Some(F_KE), &pct),
    );
    row(
        w,
        "rotational share of the fragment KE (§4.1)",
        "10–20 %",
        summary_cell(
            &values(runs, |r| Some(r.rotational_share)),
            Some(ROTATIONAL_SHARE),
            &pct,
        ),
    );
    row(
        w,
        "ejection speed ∝ size^α: α (§4.2, Fig. 4)",
        "−0.50 … −0.10",
        summary_cell(&values(runs, |r| r.ejection_exponent), Some(EJECTION_EXPONENT), &num2),
    );
    row(
        w,
        "spin rate ∝ size^α: α (§4.3, Fig. 8)",
        "−1.4 … −1.0",
        summary_cell(&values(runs, |r| r.spin_exponent), Some(SPIN_EXPONENT), &num2),
    );
    let best: Vec<(f64, &str)> = values(runs, |r| r.best_n);
    let half = best.iter().filter(|b| b.0 == 0.5).count();
    let mut counts = String::new();
    for n in [0.5, 1.0, 1.5, 2.0] {
        let k = best.iter().filter(|b| b.0 == n).count();
        let _ = write!(counts, "n = {n}: {k}; ");
    }
    row(
        w,
        "best n of f(x) = a xⁿ exp(−x²/b²) among 0.5, 1, 1.5, 2 (§4.3, Fig. 6)",
        "0.5",
        format!(
            "{half} of {} runs give 0.5 ({})",
            best.len(),
            counts.trim_end_matches("; ")
        ),
    );
    row(
        w,
        "residual of the n = 2 (Maxwellian) fit / best fit (§4.3)",
        "2–3",
        summary_cell(
            &values(runs, |r| r.maxwellian_residual_ratio),
            Some(MAXWELLIAN_RATIO),
            &num2,
        ),
    );
    row(
        w,
        "n of f(ω) ∝ ωⁿ exp(−ω²/b²) by unbinned maximum likelihood, n free (not in the paper)",
        "–",
        summary_cell(&values(runs, |r| r.likelihood_n), None, &num2),
    );
    let rejected = |p: fn(&CampaignRun) -> Option<f64>| {
        let v = values(runs, p);
        format!("{} of {}", v.iter().filter(|x| x.0 < 0.05).count(), v.len())
    };
    row(
        w,
        "runs whose likelihood-fitted Maxwellian (n = 2) is rejected at 5 % (p-values optimistic: fitted σ)",
        "–",
        format!(
            "KS: {}; AD: {}",
            rejected(|r| r.maxwellian_ks_p),
            rejected(|r| r.maxwellian_ad_p)
        ),
    );
    row(
        w,
        "median ejection speed / projectile speed (§4.2)",
        "0.01–0.05 % (as printed; see the discussion)",
        summary_cell(
            &values(runs, |r| Some(r.ejection_speed_median_relative)),
            Some(EJECTION_RELATIVE),
            &|x| format!("{:.3} %", 100.0 * x),
        ),
    );
    let interval = match &c.q_star_d_bootstrap {
        Fit::Ok(b) => format!(
            "; bootstrap 95 % interval {:.2e}–{:.2e} erg/g (seed {}){}",
            b.low,
            b.high,
            b.seed,
            b.warning().map_or(String::new(), |w| format!(" — **warning**: {w}"))
        ),
        Fit::Failed(_) => String::new(),
    };
    let q_star = match &c.q_star_d {
        Fit::Ok(x) => format!(
            "{:.2e} ± {:.1e} erg/g ({:.2} × the paper's){interval}",
            x.x,
            x.sigma_x,
            x.x / Q_STAR_D
        ),
        Fit::Failed(why) => format!("no crossing: {why}"),
    };
    row(
        w,
        "Q*_D, where the bound-fraction line crosses 0.5 (Fig. 5)",
        "≈ 2.6e9 erg/g",
        q_star,
    );
    let line = match &c.bound_fraction_vs_q {
        Fit::Ok(l) => format!(
            "{:.3} ± {:.3} {} {:.3e} ± {:.1e} Q ({} runs, r² = {:.2})",
            l.intercept,
            l.sigma_intercept,
            if l.slope < 0.0 { "−" } else { "+" },
            l.slope.abs(),
            l.sigma_slope,
            l.points,
            l.r_squared
        ),
        Fit::Failed(why) => format!("no fit: {why}"),
    };
    row(w, "bound fraction vs Q (erg/g) (Fig. 5)", "1.04 − 2e-10 Q", line);
    let sites = values(runs, |r| r.size_site_correlation);
    let negative = sites.iter().filter(|s| s.0 < 0.0).count();
    let smaller = runs
        .iter()
        .filter(|r| matches!((r.impact_side_median_size, r.antipodal_side_median_size), (Some(a), Some(b)) if a < b))
        .count();
    let both = runs
        .iter()
        .filter(|r| r.impact_side_median_size.is_some() && r.antipodal_side_median_size.is_some())
        .count();
    row(
        w,
        "small fragments ejected at the impact point, large ones at the antipode (§4.2)",
        "all runs; clearer with few fragments",
        format!(
            "corr(ln size, impact-site cosine) of the fast half < 0 in {negative} of {} runs ({}); the impact-side \
             median size is the smaller in {smaller} of {both} runs with fast fragments on both sides",
            sites.len(),
            summary_cell(&sites, None, &num2)
        ),
    );
    let _ = writeln!(w);

    // ---------------------------------------------------------------- seed scatter
    seed_scatter(w, runs);

    // ---------------------------------------------------------------- by target size and projectile
    let _ = writeln!(w, "### By target and projectile\n");
    let _ = writeln!(
        w,
        "Medians over the runs of each group (all angles; both spin periods). The paper reports smaller ejection \
         speeds for targets of fewer (larger) fragments and wider spin distributions for larger Q.\n"
    );
    let _ = writeln!(
        w,
        "| group | runs | bound fraction | f_KE | rotational share | median ejection speed (m/s) | ejection α | spin α | \
         best n = 0.5 | n=2 / best | size–site corr. |"
    );
    let _ = writeln!(w, "|---|---|---|---|---|---|---|---|---|---|---|");
    // target-size groups first (N30, N100, …), then projectiles, each in order of appearance
    let mut groups: Vec<String> = Vec::new();
    for pass in 0..2 {
        for r in runs {
            let g = if pass == 0 {
                r.target.split('_').next().unwrap_or(&r.target).to_string()
            } else {
                r.projectile.clone()
            };
            if !groups.contains(&g) {
                groups.push(g);
            }
        }
    }
    for g in &groups {
        let sel: Vec<CampaignRun> = runs
            .iter()
            .filter(|r| r.projectile == *g || r.target.split('_').next() == Some(g.as_str()))
            .cloned()
            .collect();
        let med = |f: &dyn Fn(&CampaignRun) -> Option<f64>| median(&values(&sel, f));
        let half = sel.iter().filter(|r| r.best_n == Some(0.5)).count();
        let _ = writeln!(
            w,
            "| {g} | {} | {:.3} | {} | {} | {:.1} | {:.2} | {:.2} | {half} of {} | {:.2} | {:.2} |",
            sel.len(),
            med(&|r| Some(r.bound_mass_fraction)),
            pct(med(&|r| Some(r.f_ke))),
            pct(med(&|r| Some(r.rotational_share))),
            med(&|r| Some(r.ejection_speed_median)),
            med(&|r| r.ejection_exponent),
            med(&|r| r.spin_exponent),
            sel.len(),
            med(&|r| r.maxwellian_residual_ratio),
            med(&|r| r.size_site_correlation),
        );
    }
    let _ = writeln!(w);

    // ---------------------------------------------------------------- spin period of the target
    let mut pairs = Vec::new();
    for r in runs.iter().filter(|r| r.target.ends_with("_T4")) {
        let partner = r.target.trim_end_matches("_T4").to_string() + "_T12";
        if let Some(q) = find(runs, &partner, &r.projectile, r.angle_deg) {
            pairs.push((r, q));
        }
    }
    if !pairs.is_empty() {
        let more = pairs
            .iter()
            .filter(|(a, b)| a.bound_mass_fraction < b.bound_mass_fraction)
            .count();
        let equal = pairs
            .iter()
            .filter(|(a, b)| a.bound_mass_fraction == b.bound_mass_fraction)
            .count();
        let _ = writeln!(
            w,
            "**Target spin (§4.2: a 4 h target loses more mass than a 12 h one).** Of {} run pairs that differ only \
             in the target's period (same N, projectile and ζ), the 4 h target keeps less mass in {more}, the same \
             in {equal}, more in {}.\n",
            pairs.len(),
            pairs.len() - more - equal
        );
    }

    // ---------------------------------------------------------------- Fig. 4 and Fig. 8 exponents
    exponent_table(
        w,
        runs,
        "**Fig. 4 (N200_T4, ζ = 45°).** Ejection speed–size exponents, paper vs ours:",
        &FIG4_EXPONENTS,
        |r| (r.ejection_exponent, r.ejection_exponent_sigma),
    );
    exponent_table(
        w,
        runs,
        "**Fig. 8 (N200_T4, ζ = 45°).** Spin–size exponents, paper vs ours:",
        &FIG8_EXPONENTS,
        |r| (r.spin_exponent, r.spin_exponent_sigma),
    );

    // ---------------------------------------------------------------- κ readings
    crate::studies::roig2003::kappa::write_kappa_section(
        w,
        c,
        inputs.campaign_dir,
        inputs.other_kappa,
        rubblepile::ellipsoid::equations::G_SI,
    );

    // ---------------------------------------------------------------- spin bias
    if let Some((u, u_dir)) = inputs.uniform {
        let _ = writeln!(w, "## The spin bias of the Gaussian moments of inertia (§4.3)\n");
        for ur in &u.runs {
            let Some(gr) = find(runs, &ur.target, &ur.projectile, ur.angle_deg) else {
                continue;
            };
            let g_spin = median_spin(&inputs.campaign_dir.join(&gr.run));
            let u_spin = median_spin(&u_dir.join(&ur.run));
            let _ = writeln!(
                w,
                "`{}` of `{}` (inertia = \"uniform\", homogeneous ellipsoids) beside `{}` of this campaign \
                 (Gaussian, Eq. 4 with the model's κ):\n",
                ur.run,
                u_dir.display(),
                gr.run
            );
            let _ = writeln!(w, "| | Gaussian | uniform |");
            let _ = writeln!(w, "|---|---|---|");
            let _ = writeln!(
                w,
                "| median raw spin rate of the target fragments (rad/s) | {} | {} |",
                opt(g_spin.map(|s| s.0), &|x| format!("{x:.3e}")),
                opt(u_spin.map(|s| s.0), &|x| format!("{x:.3e}"))
            );
            let _ = writeln!(
                w,
                "| median corrected spin rate, × √(5/(2κ_I)) (rad/s) | {} | {} |",
                opt(g_spin.map(|s| s.1), &|x| format!("{x:.3e}")),
                opt(u_spin.map(|s| s.1), &|x| format!("{x:.3e}"))
            );
            let _ = writeln!(
                w,
                "| rotational share of the fragment KE | {} | {} |",
                pct(gr.rotational_share),
                pct(ur.rotational_share)
            );
            let _ = writeln!(
                w,
                "| spin–size exponent | {} | {} |",
                opt(gr.spin_exponent, &num2),
                opt(ur.spin_exponent, &num2)
            );
            let _ = writeln!(
                w,
                "| bound mass fraction | {:.3} | {:.3} |",
                gr.bound_mass_fraction, ur.bound_mass_fraction
            );
            if let (Some(g), Some(un)) = (g_spin, u_spin) {
                let factor = g.2;
                let _ = writeln!(
                    w,
                    "\nRaw median spin, Gaussian / uniform: **{:.2}**; the paper's estimate √(2κ/5) with this run's κ: \
                     **{:.2}**.\n",
                    g.0 / un.0,
                    1.0 / factor
                );
            }
        }
    }

    // ---------------------------------------------------------------- figures
    let _ = writeln!(w, "## Figures\n");
    let dir = inputs.campaign_dir;
    let fig = |w: &mut String, title: &str, target: &str, p: &str, angle: f64, stem: &str, prefix: &str| {
        let _ = writeln!(w, "**{title}**\n");
        match find(runs, target, p, angle) {
            Some(r) => {
                let _ = writeln!(
                    w,
                    "{}\n",
                    copy_figure(&figures, &dir.join(&r.run), &r.run, stem, prefix)
                );
            }
            None => {
                let _ = writeln!(w, "*({target} + {p} at ζ = {angle}° is not in this campaign)*\n");
            }
        }
    };
    fig(
        w,
        "Fig. 2 — energy partition and momentum drift, N200_T4 + P2, ζ = 45°",
        "N200_T4",
        "P2",
        45.0,
        "energy_partition",
        "fig2",
    );
    fig(
        w,
        "Fig. 3 — velocity field, N200_T12 + P2, ζ = 0°",
        "N200_T12",
        "P2",
        0.0,
        "velocity_field",
        "fig3",
    );
    fig(
        w,
        "Fig. 3 — velocity field, N200_T12 + P2, ζ = 90°",
        "N200_T12",
        "P2",
        90.0,
        "velocity_field",
        "fig3",
    );
    for p in ["P1", "P2", "P3"] {
        fig(
            w,
            &format!("Fig. 4 — ejection speed vs size, N200_T4 + {p}, ζ = 45°"),
            "N200_T4",
            p,
            45.0,
            "ejection_vs_size",
            "fig4",
        );
    }
    for stem in ["bound_fraction_vs_q", "spin_distributions"] {
        let label = if stem == "bound_fraction_vs_q" {
            "Fig. 5 — bound mass fraction vs Q"
        } else {
            "Fig. 7 — normalised spin distributions per projectile"
        };
        let _ = writeln!(w, "**{label}**\n");
        let mut link = None;
        for ext in ["svg", "png"] {
            let from = dir.join("analysis").join(format!("{stem}.{ext}"));
            let name = format!("{stem}.{ext}");
            if from.is_file() && std::fs::copy(&from, figures.join(&name)).is_ok() && (ext == "png" || link.is_none()) {
                link = Some(name);
            }
        }
        let _ = writeln!(
            w,
            "{}\n",
            link.map_or_else(
                || format!("*({stem} was not drawn)*"),
                |n| format!("![{stem}](figures/{n})")
            )
        );
    }
    for d in &c.spin_distributions {
        if let Fit::Ok(l) = &d.likelihood {
            let _ = writeln!(w, "- {} (least squares below): {}", d.projectile, l.summary_line());
        }
        if let Some(b) = d.best() {
            let _ = writeln!(
                w,
                "- {} ({}; runs {}; {} fragments): best n = {}, b = {:.3e} ± {:.1e} rad/s",
                d.projectile,
                d.selection,
                d.runs.iter().map(|r| format!("`{r}`")).collect::<Vec<_>>().join(", "),
                d.fragments,
                b.n,
                b.b,
                b.sigma_b
            );
        }
    }
    let _ = writeln!(w);
    fig(
        w,
        "Fig. 6 — spin histogram and empirical CDF with the least-squares (n free) and likelihood fits, N200_T4 + P2, ζ = 0°",
        "N200_T4",
        "P2",
        0.0,
        "spin_histogram",
        "fig6",
    );
    for p in ["P1", "P2", "P3"] {
        fig(
            w,
            &format!("Fig. 8 — spin rate vs size, N200_T4 + {p}, ζ = 45°"),
            "N200_T4",
            p,
            45.0,
            "spin_vs_size",
            "fig8",
        );
    }
    fig(
        w,
        "Fig. 9 — SAM/LAM measure vs size, N200_T12 + P2, ζ = 90°",
        "N200_T12",
        "P2",
        90.0,
        "rotation_mode_vs_size",
        "fig9",
    );

    // ---------------------------------------------------------------- discussion
    let discussion = out_dir.join("DISCUSSION.md");
    if let Ok(text) = std::fs::read_to_string(&discussion) {
        let _ = writeln!(w, "{}\n", text.trim_end());
    }

    // ---------------------------------------------------------------- appendix
    let _ = writeln!(w, "## Appendix: every run\n");
    let _ = writeln!(
        w,
        "| run | Q (erg/g) | bound | largest remnant | escaping / fragments | f_KE | rot. share | median Δv (m/s) | ejection α | spin α | best n | n=2 / best | likelihood n [95 %] | Maxwellian KS p / AD p | energy error | barrier overruns | wall (s) |"
    );
    let _ = writeln!(
        w,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    let mut overrun_runs = (0, 0);
    for r in runs {
        let overruns = overrun_pairs(&inputs.campaign_dir.join(&r.run));
        if let Some(k) = overruns {
            overrun_runs.0 += usize::from(k > 0);
            overrun_runs.1 += 1;
        }
        let _ = writeln!(
            w,
            "| `{}` | {:.3e} | {:.3} | {} | {} / {} | {} | {} | {:.1} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.run,
            r.q_erg_per_g,
            r.bound_mass_fraction,
            opt(r.largest_remnant_fraction, &|x| format!("{x:.3}")),
            r.escaping,
            r.fragments,
            pct(r.f_ke),
            pct(r.rotational_share),
            r.ejection_speed_median,
            opt(r.ejection_exponent, &num2),
            opt(r.spin_exponent, &num2),
            opt(r.best_n, &|x| format!("{x}")),
            opt(r.maxwellian_residual_ratio, &num2),
            match (r.likelihood_n, r.likelihood_n_low, r.likelihood_n_high) {
                (Some(n), Some(lo), Some(hi)) => format!("{n:.2} [{lo:.2}, {hi:.2}]"),
                _ => "–".into(),
            },
            match (r.maxwellian_ks_p, r.maxwellian_ad_p) {
                (Some(k), Some(a)) => format!("{} / {}", format_p(k), format_p(a)),
                _ => "–".into(),
            },
            opt(r.energy_error, &|x| format!("{x:.1e}")),
            overruns.map_or_else(|| "–".to_string(), |k| k.to_string()),
            opt(r.wall_seconds, &|x| format!("{x:.1}")),
        );
    }
    let total_wall: f64 = runs.iter().filter_map(|r| r.wall_seconds).sum();
    let worst = values(runs, |r| r.energy_error)
        .into_iter()
        .max_by(|a, b| a.0.total_cmp(&b.0));
    let _ = writeln!(
        w,
        "\nSum of the runs' wall-clock times: {:.0} s; largest relative energy error: {}.",
        total_wall,
        worst.map_or_else(|| "–".into(), |(e, r)| format!("{e:.1e} (`{r}`)"))
    );
    let _ = writeln!(
        w,
        "\nContact-barrier overruns (pairs that went deeper than the calibrated barrier allows, `barrier.overrun_pairs` \
         of each `summary.json`; `barrier_overruns.csv` lists them): {} of the {} runs that record them had any; {} \
         runs predate the detector.",
        overrun_runs.0,
        overrun_runs.1,
        runs.len() - overrun_runs.1
    );
    let path = out_dir.join("REPORT.md");
    std::fs::write(&path, md)?;
    Ok(path)
}

/// A "paper vs ours" table of per-run power-law exponents of the N200_T4, ζ = 45° runs (`value` gives the exponent
/// and its standard error).
fn exponent_table(
    w: &mut String,
    runs: &[CampaignRun],
    title: &str,
    paper: &[(&str, f64)],
    value: impl Fn(&CampaignRun) -> (Option<f64>, Option<f64>),
) {
    let _ = writeln!(w, "{title}\n");
    let _ = writeln!(w, "| projectile | paper | ours | run |");
    let _ = writeln!(w, "|---|---|---|---|");
    for &(p, published) in paper {
        let cell = cell_runs(runs, "N200_T4", p, 45.0);
        if cell.is_empty() {
            let _ = writeln!(w, "| {p} | {published:.2} | not run | – |");
            continue;
        }
        let per_seed: Vec<String> = cell
            .iter()
            .map(|r| {
                let (x, sigma) = value(r);
                format!("{} ± {}", opt(x, &num2), opt(sigma, &num2))
            })
            .collect();
        let xs: Vec<f64> = cell.iter().filter_map(|r| value(r).0).collect();
        let ours = match mean_sd(&xs) {
            Some((m, sd)) if xs.len() > 1 => {
                format!("{m:.2} ± {sd:.2} over {} seeds ({})", xs.len(), per_seed.join("; "))
            }
            _ => per_seed.join("; "),
        };
        let names: Vec<String> = cell.iter().map(|r| format!("`{}`", r.run)).collect();
        let _ = writeln!(w, "| {p} | {published:.2} | {ours} | {} |", names.join(", "));
    }
    let _ = writeln!(w);
}

/// The runs of one grid cell (all seeds), in campaign order.
fn cell_runs<'a>(runs: &'a [CampaignRun], target: &str, projectile: &str, angle: f64) -> Vec<&'a CampaignRun> {
    runs.iter()
        .filter(|r| r.target == target && r.projectile == projectile && r.angle_deg == angle)
        .collect()
}

/// Mean and sample standard deviation (0 for one value); `None` when empty.
fn mean_sd(x: &[f64]) -> Option<(f64, f64)> {
    if x.is_empty() {
        return None;
    }
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let var = if x.len() > 1 {
        x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0)
    } else {
        0.0
    };
    Some((m, var.sqrt()))
}

/// The scatter over seeds (the projectile's attitude) of every grid cell's outcomes: mean ± sample standard
/// deviation per cell, and the median standard deviation over the cells, the error bar of a single run.
fn seed_scatter(w: &mut String, runs: &[CampaignRun]) {
    let mut cells: Vec<(String, String, f64)> = Vec::new();
    for r in runs {
        let key = (r.target.clone(), r.projectile.clone(), r.angle_deg);
        if !cells.contains(&key) {
            cells.push(key);
        }
    }
    let seeds = cells
        .iter()
        .map(|(t, p, a)| cell_runs(runs, t, p, *a).len())
        .max()
        .unwrap_or(0);
    if seeds < 2 {
        let _ = writeln!(w, "One seed per grid cell: the outcomes above carry no seed scatter.\n");
        return;
    }
    type Outcome = (&'static str, fn(&CampaignRun) -> Option<f64>, fn(f64) -> String);
    let outcomes: [Outcome; 8] = [
        ("bound", |r| Some(r.bound_mass_fraction), |x| format!("{x:.3}")),
        ("f_KE (%)", |r| Some(100.0 * r.f_ke), |x| format!("{x:.2}")),
        (
            "rot. share (%)",
            |r| Some(100.0 * r.rotational_share),
            |x| format!("{x:.1}"),
        ),
        (
            "median Δv (m/s)",
            |r| Some(r.ejection_speed_median),
            |x| format!("{x:.1}"),
        ),
        ("ejection α", |r| r.ejection_exponent, |x| format!("{x:.2}")),
        ("spin α", |r| r.spin_exponent, |x| format!("{x:.2}")),
        ("best n", |r| r.best_n, |x| format!("{x:.2}")),
        ("likelihood n", |r| r.likelihood_n, |x| format!("{x:.2}")),
    ];
    let _ = writeln!(w, "### Seed scatter\n");
    let _ = writeln!(
        w,
        "Each grid cell was run with {seeds} attitudes of the projectile (seeds 1–{seeds}; everything else equal). Mean ± \
         sample standard deviation over the seeds:\n"
    );
    let header: Vec<&str> = outcomes.iter().map(|o| o.0).collect();
    let _ = writeln!(w, "| cell | seeds | {} |", header.join(" | "));
    let _ = writeln!(w, "|---|---|{}", "---|".repeat(outcomes.len()));
    let mut sds: Vec<Vec<f64>> = vec![Vec::new(); outcomes.len()];
    for (t, p, a) in &cells {
        let cell = cell_runs(runs, t, p, *a);
        let mut row = format!("| {t} {p} ζ = {a}° | {} |", cell.len());
        for (k, (_, f, fmt)) in outcomes.iter().enumerate() {
            let xs: Vec<f64> = cell.iter().filter_map(|r| f(r)).filter(|x| x.is_finite()).collect();
            match mean_sd(&xs) {
                Some((m, sd)) => {
                    if xs.len() > 1 {
                        sds[k].push(sd);
                    }
                    let _ = write!(row, " {} ± {} |", fmt(m), fmt(sd));
                }
                None => row.push_str(" – |"),
            }
        }
        let _ = writeln!(w, "{row}");
    }
    let typical: Vec<String> = outcomes
        .iter()
        .zip(&sds)
        .map(|((name, _, fmt), s)| format!("{name} {}", fmt(rubblepile::math::median(s))))
        .collect();
    let _ = writeln!(
        w,
        "\nMedian over the cells of the seed standard deviation (the error bar of one run): {}.\n",
        typical.join(", ")
    );
}

/// Median raw and corrected spin rates of the target fragments of an analysed run (from its
/// `analysis/fragments.csv`), and the correction factor √(5/(2κ_I)).
fn median_spin(run_dir: &Path) -> Option<(f64, f64, f64)> {
    let mut rdr = csv::Reader::from_path(run_dir.join("analysis/fragments.csv")).ok()?;
    let headers = rdr.headers().ok()?.clone();
    let col = |name: &str| headers.iter().position(|h| h == name);
    let (cp, cr, cc) = (col("is_projectile")?, col("spin_rate")?, col("spin_rate_corrected")?);
    let (mut raw, mut corrected) = (Vec::new(), Vec::new());
    for rec in rdr.records().flatten() {
        if &rec[cp] == "true" {
            continue;
        }
        raw.push((rec[cr].parse::<f64>().ok()?, ""));
        corrected.push((rec[cc].parse::<f64>().ok()?, ""));
    }
    let (r, c) = (median(&raw), median(&corrected));
    (r > 0.0).then_some((r, c, c / r))
}

#[cfg(test)]
mod tests {
    use super::{CampaignRun, exponent_table, mean_sd, overrun_pairs, seed_scatter};

    fn run(name: &str, projectile: &str, bound: f64, spin: Option<f64>) -> CampaignRun {
        CampaignRun {
            run: name.into(),
            target: "N200_T4".into(),
            projectile: projectile.into(),
            angle_deg: 45.0,
            q_erg_per_g: 1.5e9,
            fragments: 200,
            escaping: 3,
            bound_mass_fraction: bound,
            largest_remnant_fraction: Some(bound),
            f_ke: 0.02,
            rotational_share: 0.05,
            ejection_speed_median: 40.0,
            ejection_speed_median_relative: 0.008,
            ejection_exponent: Some(-0.3),
            ejection_exponent_sigma: Some(0.1),
            spin_exponent: spin,
            spin_exponent_sigma: Some(0.2),
            best_n: Some(0.5),
            maxwellian_residual_ratio: Some(2.0),
            likelihood_n: Some(0.4),
            likelihood_n_low: Some(0.1),
            likelihood_n_high: Some(0.7),
            likelihood_ks_p: Some(0.5),
            maxwellian_ks_p: Some(0.01),
            maxwellian_ad_p: Some(0.005),
            size_site_correlation: None,
            impact_side_median_size: None,
            antipodal_side_median_size: None,
            energy_error: Some(1e-12),
            wall_seconds: Some(1.0),
        }
    }

    /// Mean and sample standard deviation: (1, 2, 3) → 2 ± 1; one value → ± 0; none → nothing.
    #[test]
    fn mean_sd_is_the_sample_one() {
        assert_eq!(mean_sd(&[1.0, 2.0, 3.0]), Some((2.0, 1.0)));
        assert_eq!(mean_sd(&[4.0]), Some((4.0, 0.0)));
        assert_eq!(mean_sd(&[]), None);
    }

    /// Three seeds of a cell give its mean ± standard deviation (bound 0.8, 0.9, 1.0 → 0.900 ± 0.100) and the
    /// exponent table quotes the seeds; one seed per cell says that there is no scatter.
    #[test]
    fn seed_scatter_and_exponents_use_every_seed_of_a_cell() {
        let runs = vec![
            run("N200_T4_P2_z45_s1", "P2", 0.8, Some(-1.0)),
            run("N200_T4_P2_z45_s2", "P2", 0.9, Some(-1.2)),
            run("N200_T4_P2_z45_s3", "P2", 1.0, Some(-1.4)),
        ];
        let mut w = String::new();
        seed_scatter(&mut w, &runs);
        assert!(w.contains("| N200_T4 P2 ζ = 45° | 3 | 0.900 ± 0.100 |"), "{w}");
        let mut t = String::new();
        exponent_table(&mut t, &runs, "title", &[("P2", -1.11)], |r| {
            (r.spin_exponent, r.spin_exponent_sigma)
        });
        assert!(t.contains("| P2 | -1.11 | -1.20 ± 0.20 over 3 seeds"), "{t}");
        let mut one = String::new();
        seed_scatter(&mut one, &runs[..1]);
        assert!(one.contains("One seed per grid cell"), "{one}");
    }

    /// The overrun count is read from `barrier.overrun_pairs`; a summary without it (a run from before the
    /// detector) or no summary gives `None`, never 0.
    #[test]
    fn overrun_pairs_reads_the_barrier_record_or_nothing() {
        let dir = std::env::temp_dir().join(format!("rubblepile_overrun_pairs_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        assert_eq!(overrun_pairs(&dir), None);
        std::fs::write(dir.join("summary.json"), r#"{"status": "completed"}"#).unwrap();
        assert_eq!(overrun_pairs(&dir), None);
        std::fs::write(dir.join("summary.json"), r#"{"barrier": {"overrun_pairs": 3}}"#).unwrap();
        assert_eq!(overrun_pairs(&dir), Some(3));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
