//! The analysis of a whole impact campaign (Roig03 §4, Figs. 5 and 7): every completed run of
//! `CAMPAIGN_DIR/campaign.csv` analysed with its figures, the campaign's table, fits and spin distributions, and
//! the campaign figures. Above both the per-run analysis (`analysis::run_analysis`) and the figures
//! (`analysis::figures`), which it calls in turn.

use std::path::Path;

use crate::analysis::run_analysis::{
    AnalysisError, CampaignAnalysis, CampaignRun, Fit, QStarRuns, SpinSelection, analyze_run, lock_analysis, read_json,
    spin_distributions,
};
use crate::io::messages::{Channel, emit};

/// Analyses every completed run listed in `CAMPAIGN_DIR/campaign.csv` at `t_at` (each run's own
/// `analysis/` is written or, with `force`, rewritten, figures included) and writes
/// `CAMPAIGN_DIR/analysis/campaign_analysis.json`, `campaign_runs.csv` and the campaign figures (Roig03 Figs. 5
/// and 7, [`crate::analysis::figures::write_campaign_figures`]; a figure that cannot be drawn is a warning on
/// stderr). The spin distributions are of one target ([`SpinSelection::resolve`], checked before any run is
/// analysed); Q*_D's bootstrap draws from `bootstrap_seed`.
pub fn analyze_campaign(
    dir: &Path,
    t_at: f64,
    force: bool,
    selection: &SpinSelection,
    bootstrap_seed: u64,
) -> Result<CampaignAnalysis, AnalysisError> {
    let _lock = lock_analysis(dir, "campaign.csv")?;
    let out_dir = dir.join("analysis");
    let json_path = out_dir.join("campaign_analysis.json");
    if !force && json_path.exists() {
        return Err(AnalysisError::Exists(out_dir));
    }
    let index = dir.join("campaign.csv");
    let err = |e: &dyn std::fmt::Display| AnalysisError::read(&index, e);
    let names = ["run", "target", "projectile", "angle_deg", "q_erg_per_g", "status"];
    let (mut rdr, [c_run, c_target, c_proj, c_angle, c_q, c_status]) =
        crate::io::table::open_columns(&index, names).map_err(|e| err(&e))?;
    let records: Vec<csv::StringRecord> = rdr.records().collect::<Result<_, _>>().map_err(|e| err(&e))?;
    let mut targets: Vec<String> = Vec::new();
    for rec in records.iter().filter(|r| &r[c_status] == "completed") {
        if !targets.iter().any(|t| t == &rec[c_target]) {
            targets.push(rec[c_target].to_string());
        }
    }
    let spin_target = match targets.is_empty() {
        true => String::new(),
        false => selection.resolve(&targets)?,
    };
    let mut runs = Vec::new();
    let mut spins: Vec<Vec<f64>> = Vec::new();
    let mut skipped = Vec::new();
    for rec in records {
        let run = rec[c_run].to_string();
        if &rec[c_status] != "completed" {
            skipped.push(run);
            continue;
        }
        let run_dir = dir.join(&run);
        // The run's analysis and its figures under one lock.
        let _run_lock = lock_analysis(&run_dir, "scene.toml")?;
        let (a, report) = match analyze_run(&run_dir, None, t_at, force) {
            Err(AnalysisError::Exists(_)) => analyze_run(&run_dir, None, t_at, true)?,
            other => other?,
        };
        let (_, not_drawn) = crate::analysis::figures::write_run_figures(&run_dir, None, &a, &report);
        for why in &not_drawn {
            emit(Channel::Warning, &format!("warning: {run}: figure not drawn: {why}"));
        }
        spins.push(
            report
                .fragments
                .iter()
                .filter(|f| !f.is_projectile)
                .map(|f| f.spin_rate_corrected)
                .collect(),
        );
        let num = |c: usize| rec[c].parse::<f64>().map_err(|e| err(&format!("{run}: {e}")));
        let run_summary = read_json(&run_dir.join("summary.json")).ok();
        let from_summary = |key: &str| run_summary.as_ref().and_then(|v| v[key].as_f64());
        let (ej, sp) = (a.ejection_speed_vs_size.ok(), a.spin_vs_size.ok());
        let (best_n, maxwell) = match &a.spin_fits {
            Fit::Ok(c) => {
                let rss = |n: f64| c.fixed.iter().find(|f| f.n == n).map(|f| f.rss);
                let ratio = match (rss(2.0), rss(c.best_n)) {
                    (Some(m), Some(b)) if b > 0.0 => Some(m / b),
                    _ => None,
                };
                (Some(c.best_n), ratio)
            }
            Fit::Failed(_) => (None, None),
        };
        let ml = a.spin_likelihood.ok();
        let s = &a.summary;
        runs.push(CampaignRun {
            target: rec[c_target].to_string(),
            projectile: rec[c_proj].to_string(),
            angle_deg: num(c_angle)?,
            q_erg_per_g: num(c_q)?,
            fragments: s.n_fragments,
            escaping: s.n_escaping,
            bound_mass_fraction: s.bound_mass_fraction,
            largest_remnant_fraction: a.clumps.largest_remnant.as_ref().map(|r| r.mass_fraction),
            f_ke: s.f_ke,
            rotational_share: s.rotational_share,
            ejection_speed_median: s.ejection_speed_median,
            ejection_speed_median_relative: s.ejection_speed_median_relative,
            ejection_exponent: ej.map(|f| f.alpha),
            ejection_exponent_sigma: ej.map(|f| f.sigma_alpha),
            spin_exponent: sp.map(|f| f.alpha),
            spin_exponent_sigma: sp.map(|f| f.sigma_alpha),
            best_n,
            maxwellian_residual_ratio: maxwell,
            likelihood_n: ml.map(|l| l.free.n),
            likelihood_n_low: ml.and_then(|l| Some(l.free.n_interval?[0])),
            likelihood_n_high: ml.and_then(|l| Some(l.free.n_interval?[1])),
            likelihood_ks_p: ml.map(|l| l.free.goodness.ks_p),
            maxwellian_ks_p: ml.map(|l| l.maxwellian.goodness.ks_p),
            maxwellian_ad_p: ml.map(|l| l.maxwellian.goodness.ad_p),
            size_site_correlation: s.ejection_sites.size_cosine_correlation,
            impact_side_median_size: s.ejection_sites.impact_side_median_size,
            antipodal_side_median_size: s.ejection_sites.antipodal_side_median_size,
            energy_error: from_summary("energy_error"),
            wall_seconds: from_summary("wall_seconds"),
            run,
        });
    }
    let q_star_runs = q_star_selection(&runs, &spin_target, selection.angle_deg, selection.pool_q_star);
    let (bound_fraction_vs_q, q_star_d, q_star_d_bootstrap) = match &q_star_runs.refused {
        Some(why) => (
            Fit::Failed(why.clone()),
            Fit::Failed(why.clone()),
            Fit::Failed(why.clone()),
        ),
        None => {
            let chosen: Vec<&CampaignRun> = runs.iter().filter(|r| q_star_runs.holds(r)).collect();
            let q: Vec<f64> = chosen.iter().map(|r| r.q_erg_per_g).collect();
            let bound: Vec<f64> = chosen.iter().map(|r| r.bound_mass_fraction).collect();
            let line = crate::analysis::fits::fit_line(&q, &bound);
            let q_star_d = match &line {
                Ok(l) => Fit::from(crate::analysis::fits::line_crossing(l, 0.5)),
                Err(e) => Fit::Failed(e.to_string()),
            };
            let bootstrap = Fit::from(crate::analysis::q_star_bootstrap::q_star_bootstrap(
                &q,
                &bound,
                crate::analysis::q_star_bootstrap::DEFAULT_RESAMPLES,
                bootstrap_seed,
            ));
            (Fit::from(line), q_star_d, bootstrap)
        }
    };
    let spin_distributions = spin_distributions(&runs, &spins, &spin_target, selection.angle_deg);
    let analysis = CampaignAnalysis {
        t_at,
        runs,
        skipped,
        q_star_runs,
        bound_fraction_vs_q,
        q_star_d,
        q_star_d_bootstrap,
        spin_distributions,
    };
    crate::io::safe_write::ensure_dir(&out_dir).map_err(|e| AnalysisError::write(&out_dir, &e))?;
    let csv_path = out_dir.join("campaign_runs.csv");
    let werr = |e: &dyn std::fmt::Display| AnalysisError::read(&csv_path, e);
    let file =
        crate::io::safe_write::AtomicFile::create(&csv_path).map_err(|e| werr(&crate::io::safe_write::reason(&e)))?;
    let mut w = csv::Writer::from_writer(file);
    for r in &analysis.runs {
        w.serialize(r).map_err(|e| werr(&e))?;
    }
    w.into_inner().map_err(|e| werr(&e))?.finish().map_err(|e| werr(&e))?;
    crate::analysis::run_analysis::write_json(&json_path, &analysis)?;
    // here rather than in the CLI, so every caller (analyze-campaign, report roig2003) gets them
    let (_, not_drawn) = crate::analysis::figures::write_campaign_figures(dir, &analysis);
    for why in &not_drawn {
        emit(Channel::Warning, &format!("warning: figure not drawn: {why}"));
    }
    Ok(analysis)
}

/// Which runs Q*_D is fitted over: those on `target` at one impact angle, never pooled across targets or angles
/// (each has its own Q*_D). The angle is the runs' only one on `target`, else `angle_deg` when they have it; with
/// several angles and none at `angle_deg` the fit is refused, naming `--spin-angle-deg` and the angles. `pooled`:
/// every run instead ([`SpinSelection::pool_q_star`]).
pub fn q_star_selection(runs: &[CampaignRun], target: &str, angle_deg: f64, pooled: bool) -> QStarRuns {
    if pooled {
        return QStarRuns {
            target: "all".into(),
            angle_deg: None,
            runs: runs.len(),
            refused: runs.is_empty().then(|| "no analysed run".to_string()),
            pooled: true,
        };
    }
    let mut angles: Vec<f64> = Vec::new();
    for r in runs.iter().filter(|r| r.target == target) {
        if !angles.contains(&r.angle_deg) {
            angles.push(r.angle_deg);
        }
    }
    angles.sort_by(f64::total_cmp);
    let angle = match angles[..] {
        [one] => Some(one),
        _ => angles.iter().copied().find(|&a| a == angle_deg),
    };
    let refused = match (angle, angles.is_empty()) {
        (_, true) => Some(format!("no analysed run on the target `{target}`")),
        (None, false) => Some(format!(
            "the runs on {target} are at several impact angles ({angles:?} deg) and none at {angle_deg} deg; Q*_D is \
             of one target at one angle: pick one with --spin-angle-deg (and the target with --spin-target)"
        )),
        (Some(_), false) => None,
    };
    let mut selection = QStarRuns {
        target: target.to_string(),
        angle_deg: angle,
        runs: 0,
        refused,
        pooled: false,
    };
    selection.runs = runs.iter().filter(|r| selection.holds(r)).count();
    selection
}

/// The end time shared by the completed runs of `dir/campaign.csv` (their `final_time`, s): `analyze-campaign`'s
/// default `--at-s`. Errors ([`AnalysisError::Request`]) when no run completed or the runs end at different times.
pub fn campaign_end_time(dir: &Path) -> Result<f64, AnalysisError> {
    let index = dir.join("campaign.csv");
    let err = |e: &dyn std::fmt::Display| AnalysisError::read(&index, e);
    let (mut rdr, [c_status, c_end]) =
        crate::io::table::open_columns(&index, ["status", "final_time"]).map_err(|e| err(&e))?;
    let mut ends: Vec<f64> = Vec::new();
    for rec in rdr.records() {
        let rec = rec.map_err(|e| err(&e))?;
        if &rec[c_status] == "completed"
            && let Ok(t) = rec[c_end].parse::<f64>()
            && !ends.contains(&t)
        {
            ends.push(t);
        }
    }
    ends.sort_by(f64::total_cmp);
    match ends[..] {
        [t] => Ok(t),
        [] => Err(AnalysisError::Request(format!(
            "--at-s: no completed run in {} to take the end time from; give --at-s",
            index.display()
        ))),
        _ => Err(AnalysisError::Request(format!(
            "--at-s: the runs end at different times ({ends:?} s); give --at-s, a time with a snapshot in every run"
        ))),
    }
}
