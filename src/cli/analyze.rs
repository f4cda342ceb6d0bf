//! `rubblepile analyze RUN_DIR [--at-s T]`: per-fragment and per-run analysis of an impact run (Roig03 §4); of a
//! flyby run, the largest remnant before and after (`analysis/flyby.json`).

use std::path::PathBuf;

use crate::cli::common::CliError;
use rubblepile::analysis::run_analysis::{AnalysisError, Fit, analysis_time, analyze_run};

/// `rubblepile analyze`.
#[derive(Debug, clap::Args)]
pub struct AnalyzeArgs {
    /// An impact run directory (from `rubblepile impact` or a campaign), or a flyby run (`rubblepile flyby`, or any
    /// scene with `[physics.flyby]`), or any other run (ellipsoids, soft or hard spheres: its clumps only).
    pub dir: PathBuf,
    /// Time of a snapshot to analyse (s) [default: 400 s for an impact, its t_end if sooner; else the last one].
    #[arg(long = "at-s")]
    pub at: Option<f64>,
    /// Overwrite an earlier analysis in DIR/analysis (or in --out).
    #[arg(long)]
    pub force: bool,
    /// Write the analysis here instead of DIR/analysis, e.g. for a run one may not write to (the run is only read);
    /// an analysis already there is kept unless --force. Not for flyby runs.
    #[arg(long, value_name = "OUT_DIR")]
    pub out: Option<PathBuf>,
}

impl AnalyzeArgs {
    /// Where the analysis goes.
    fn analysis_dir(&self) -> PathBuf {
        self.out.clone().unwrap_or_else(|| self.dir.join("analysis"))
    }
}

/// Runs `analyze`, holding the lock of `DIR/analysis/` from the first check to the last figure (so a second
/// `analyze` of the run is refused at once, while the run itself may still be writing `DIR`).
pub fn analyze(args: &AnalyzeArgs) -> Result<(), CliError> {
    let _lock = match args.out {
        Some(_) => None,
        None => rubblepile::analysis::run_analysis::lock_analysis(&args.dir, "scene.toml").map_err(CliError::usage)?,
    };
    if rubblepile::analysis::flyby::is_flyby_run(&args.dir) {
        if args.out.is_some() {
            return Err(CliError::usage("--out: a flyby run is analysed into DIR/analysis only"));
        }
        return analyze_flyby_run(args);
    }
    if let Some(at) = args.at
        && !(at.is_finite() && at >= 0.0)
    {
        return Err(CliError::usage(format!("--at-s: must be a time >= 0 s, got {at}")));
    }
    if !rubblepile::analysis::run_analysis::is_impact_run(&args.dir) {
        return analyze_clumps_of_run(args);
    }
    if args.at == Some(0.0) {
        return Err(CliError::usage(
            "--at-s: an impact run is analysed after the impact: must be a time > 0 s, got 0",
        ));
    }
    let out = args.out.as_deref();
    let at = analysis_time(&args.dir, args.at).map_err(CliError::usage)?;
    let (a, report) = analyze_run(&args.dir, out, at, args.force).map_err(|e| match e {
        AnalysisError::Fragments(_) => CliError::failed(e),
        _ => CliError::usage(e),
    })?;
    let (figures, not_drawn) = rubblepile::analysis::figures::write_run_figures(&args.dir, out, &a, &report);
    for why in &not_drawn {
        eprintln!("warning: figure not drawn: {why}");
    }
    let s = &a.summary;
    let alpha = |f: &Fit<rubblepile::analysis::fits::PowerLawFit>| match f {
        Fit::Ok(p) => format!("{:.2} ± {:.2}", p.alpha, p.sigma_alpha),
        Fit::Failed(why) => format!("n/a ({why})"),
    };
    // The best of the fixed exponents is only a choice among {0.5, 1, 1.5, 2}: shown as such, after the free fit
    // (issue 57: it was printed as if it were the fitted n).
    let binned = match &a.spin_fits {
        Fit::Ok(c) => {
            let free = c.free.as_ref().map_or_else(
                || "free n n/a".to_string(),
                |f| format!("free n {:.2} ± {:.2}", f.n, f.sigma_n),
            );
            format!(
                "{free}, least residual among fixed n ∈ {{0.5, 1, 1.5, 2}}: {}",
                c.best_n
            )
        }
        Fit::Failed(why) => format!("n/a ({why})"),
    };
    println!(
        "analysis at t = {} s: f_KE {:.3} %, rotational share {:.1} %; fragments (Roig03): {:.3} of the target mass \
         bound, {} escaping; \
         median ejection {:.3} m/s ({:.4} % of v_p), v_esc {:.1} m/s; ejection-size exponent {}, spin-size exponent {}, \
         spin-histogram least squares ({} bins): {}; wrote {} (fragments.csv, analysis.json, {})",
        a.t_at,
        100.0 * s.f_ke,
        100.0 * s.rotational_share,
        s.bound_mass_fraction,
        s.n_escaping,
        s.ejection_speed_median,
        100.0 * s.ejection_speed_median_relative,
        s.escape_velocity,
        alpha(&a.ejection_speed_vs_size),
        alpha(&a.spin_vs_size),
        a.spin_histogram.0.len(),
        binned,
        args.analysis_dir().display(),
        figures.join(", ")
    );
    for (fit, by) in [(&a.spin_likelihood, "number"), (&a.spin_likelihood_by_mass, "mass")] {
        match fit {
            Fit::Ok(l) => println!("{}", l.summary_line()),
            Fit::Failed(why) => println!("spin rates by unbinned likelihood (weighted by {by}): n/a ({why})"),
        }
    }
    println!("{}", a.clump_lines());
    if let Some(c) = &a.composition {
        println!("{}", c.summary_line());
    }
    Ok(())
}

/// `analyze` of a run that is not an impact (no `impact.json`): the clumps of one snapshot
/// (`analysis/clumps.csv`, `analysis.json`, the size–frequency figure `analysis/sfd.svg`).
fn analyze_clumps_of_run(args: &AnalyzeArgs) -> Result<(), CliError> {
    let a = rubblepile::analysis::run_analysis::analyze_clumps_run(&args.dir, args.out.as_deref(), args.at, args.force)
        .map_err(CliError::usage)?;
    println!("{}", a.write_figure_and_describe(&args.analysis_dir()));
    Ok(())
}

/// `rubblepile analyze-campaign`.
#[derive(Debug, clap::Args)]
pub struct AnalyzeCampaignArgs {
    /// A campaign directory (holding campaign.csv).
    pub dir: PathBuf,
    /// Time of the post-impact snapshots to analyse (s) [default: the campaign's end time, shared by its completed
    /// runs].
    #[arg(long = "at-s")]
    pub at: Option<f64>,
    /// Rewrite earlier analyses.
    #[arg(long)]
    pub force: bool,
    /// Tabulate and plot the outcomes against this field of campaign.csv (e.g. impact.speed_km_s, angle_deg, q,
    /// target), seed-only differences grouped, rows sorted numerically [default: the one [sweep] field, else q].
    #[arg(long, value_name = "FIELD")]
    pub by: Option<String>,
    /// Q*_D and the spin distributions (Roig03 Figs. 5 and 7) of the runs on this target (file stem) [default: the
    /// campaign's only target, or N200_T12 among several; runs on different targets are never pooled] ...
    #[arg(long)]
    pub spin_target: Option<String>,
    /// ... at this impact angle ζ (degrees; Q*_D: the target's only angle if one); else spins pool every angle.
    #[arg(long = "spin-angle-deg", default_value_t = 45.0)]
    pub spin_angle: f64,
    /// Seed of Q*_D's bootstrap interval (resampling the runs within each Q value).
    #[arg(long, default_value_t = 1)]
    pub bootstrap_seed: u64,
}

/// Runs `analyze-campaign`.
pub fn analyze_campaign(args: &AnalyzeCampaignArgs) -> Result<(), CliError> {
    use rubblepile::analysis::{campaign_analysis as ca, campaign_by, figures::by_field, run_analysis::SpinSelection};
    let at = args
        .at
        .map_or_else(|| ca::campaign_end_time(&args.dir), Ok)
        .map_err(CliError::usage)?;
    if !(at.is_finite() && at > 0.0) {
        return Err(CliError::usage(format!("--at-s: must be a time > 0 s, got {at}")));
    }
    let field = campaign_by::by_field_name(&args.dir, args.by.as_deref()).map_err(CliError::usage)?;
    let selection = SpinSelection {
        target: args.spin_target.clone(),
        angle_deg: args.spin_angle,
        ..SpinSelection::default()
    };
    let a = ca::analyze_campaign(&args.dir, at, args.force, &selection, args.bootstrap_seed).map_err(|e| match e {
        AnalysisError::Fragments(_) => CliError::failed(e),
        _ => CliError::usage(e),
    })?;
    a.warnings().iter().for_each(|w| eprintln!("warning: {w}"));
    let by = campaign_by::by_field_table(&args.dir, &a, Some(&field)).map_err(CliError::usage)?;
    let (csv, not_drawn) = by_field::write_by_field(&args.dir, &by, at).map_err(CliError::failed)?;
    not_drawn
        .iter()
        .for_each(|why| eprintln!("warning: figure not drawn: {}: {why}", by.stem()));
    println!(
        "outcomes against {} ({}):\n  {}",
        by.field,
        csv.display(),
        by.lines().join("\n  ")
    );
    println!(
        "campaign analysis at t = {} s: {} runs analysed, {} skipped (not completed); Q*_D {}; wrote {} \
         (campaign_analysis.json, campaign_runs.csv, {}.csv, Figs. 5 and 7 as SVG and PNG; each run's figures in its \
         analysis/)",
        a.t_at,
        a.runs.len(),
        a.skipped.len(),
        a.q_star_text(),
        args.dir.join("analysis").display(),
        by.stem(),
    );
    Ok(())
}

/// `rubblepile report roig2003`.
#[derive(Debug, clap::Args)]
pub struct ReportRoig2003Args {
    /// The campaign directory of analysis/roig2003/campaign.toml (holding campaign.csv).
    pub campaign: PathBuf,
    /// The campaign directory of analysis/roig2003/campaign_uniform.toml (the §4.3 spin-bias partner run).
    #[arg(long)]
    pub uniform: Option<PathBuf>,
    /// A campaign directory of the same grid under another reading of Roig03 Eq. 13's K
    /// (analysis/roig2003/campaign_printed.toml): its outcomes are shown beside this campaign's.
    #[arg(long)]
    pub other_kappa: Option<PathBuf>,
    /// Where REPORT.md and figures/ go (DISCUSSION.md there is included in the report).
    #[arg(long)]
    pub out: PathBuf,
    /// Time of the post-impact snapshots to analyse (s).
    #[arg(long = "at-s", default_value_t = 400.0)]
    pub at: f64,
    /// Replace an existing OUT/REPORT.md.
    #[arg(long)]
    pub force: bool,
}

/// Runs `report roig2003`: re-analyses the campaign(s) (rewriting their `analysis/`), then writes the report.
pub fn report_roig2003(args: &ReportRoig2003Args) -> Result<(), CliError> {
    if !(args.at.is_finite() && args.at > 0.0) {
        return Err(CliError::usage(format!(
            "--at-s: must be a time > 0 s, got {}",
            args.at
        )));
    }
    let report = args.out.join("REPORT.md");
    if report.exists() && !args.force {
        return Err(CliError::usage(format!(
            "{}: exists; use --force to replace it",
            report.display()
        )));
    }
    let dirs = crate::studies::roig2003::report::CampaignDirs {
        campaign: &args.campaign,
        uniform: args.uniform.as_deref(),
        other_kappa: args.other_kappa.as_deref(),
    };
    let (path, campaign) =
        crate::studies::roig2003::report::regenerate(&dirs, args.at, &args.out).map_err(|e| match e {
            AnalysisError::Fragments(_) | AnalysisError::Write { .. } => CliError::failed(e),
            _ => CliError::usage(e),
        })?;
    println!(
        "report of {} runs ({} not completed) written to {}",
        campaign.runs.len(),
        campaign.skipped.len(),
        path.display()
    );
    Ok(())
}

/// `analyze` of a flyby run (from `rubblepile flyby` or any scene with `[physics.flyby]`): the first and last
/// snapshots' largest remnant into `DIR/analysis/flyby.json` (`--at-s` does not apply).
fn analyze_flyby_run(args: &AnalyzeArgs) -> Result<(), CliError> {
    let out = args.dir.join("analysis/flyby.json");
    if out.exists() && !args.force {
        return Err(CliError::usage(format!(
            "{} exists: use --force to analyse the flyby run again",
            out.display()
        )));
    }
    let o = rubblepile::analysis::flyby::analyze_flyby(&args.dir).map_err(|e| match e {
        rubblepile::analysis::flyby::FlybyAnalysisError::Locked(_) => CliError::usage(e),
        _ => CliError::failed(e),
    })?;
    println!("{} (wrote {})", o.one_line(), out.display());
    Ok(())
}
