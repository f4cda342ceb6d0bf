//! `rubblepile spinup judge` (the holds of a T_c,3 search judged again, from its directory or its compact copy) and
//! `rubblepile spinup density-fit` (κ of Zhang17 Eq. 22 over bulk densities): the two commands that read the
//! Zhang17 study's searches and print their verdicts. The verdicts themselves are the library's
//! ([`rubblepile::analysis::critical`]).

use std::path::{Path, PathBuf};

use rubblepile::analysis::creep::CreepCriterionKind;
use rubblepile::analysis::critical::{
    SearchError, criteria, critical_csv, critical_from_verdicts, hold_series, judge_series, read_critical_csv,
    read_holds_csv, rejudge, undecided_note, verdict_line,
};
use rubblepile::analysis::spinup::fit_density;
use rubblepile::analysis::spinup_diagnostics::read_spinup_csv;
use rubblepile::io::messages::{Channel, emit};
use rubblepile::io::scene_file::SI_G;

/// `rubblepile spinup judge DIR`: judges again the holds of a compact copy (`critical.csv` and `holds.csv`) or of a
/// search directory, finished or still running (each hold run `T<X>/spinup.csv` as far as it has got), by every
/// criterion over their first `window` seconds; prints one line per hold and the T_c,3 and φ of each criterion.
/// Writes nothing but `csv_out` when given: the verdicts as a `critical.csv` (the compact copy of a search still
/// running, beside the `holds.csv` of `analysis/zhang2017/compact.py --search --running`); an existing file is
/// refused.
pub fn judge_dir(
    dir: &Path,
    window: Option<f64>,
    significance: Option<f64>,
    csv_out: Option<&Path>,
) -> Result<(), SearchError> {
    if let Some(out) = csv_out
        && out.exists()
    {
        return Err(SearchError::usage(format!(
            "--csv: {} exists; rubblepile does not overwrite it",
            out.display()
        )));
    }
    if let Some(w) = window
        && !(w.is_finite() && w > 0.0)
    {
        return Err(SearchError::usage(format!("--judge-window-s must be > 0 s, got {w}")));
    }
    let criteria = criteria(significance, None)?;
    let judged = match read_holds_csv(&dir.join("holds.csv")) {
        Ok(series) => {
            let csv = dir.join("critical.csv");
            let text =
                std::fs::read_to_string(&csv).map_err(|e| SearchError::usage(format!("{}: {e}", csv.display())))?;
            let verdicts =
                read_critical_csv(&text).map_err(|e| SearchError::usage(format!("{}: {e}", csv.display())))?;
            rejudge(&verdicts, &series, window, &criteria, CreepCriterionKind::Paper)
        }
        Err(_) => {
            // a search directory, finished or still running: every hold run `T<X>` as far as it has got
            let mut holds: Vec<(f64, PathBuf)> = std::fs::read_dir(dir)
                .map_err(|e| SearchError::usage(format!("{}: {e}", dir.display())))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.join("spinup.csv").is_file())
                .filter_map(|p| {
                    let name = p.file_name()?.to_string_lossy().into_owned();
                    Some((name.strip_prefix('T')?.parse::<f64>().ok()?, p))
                })
                .collect();
            if holds.is_empty() {
                return Err(SearchError::usage(format!(
                    "{}: neither holds.csv nor hold runs T<period>/spinup.csv",
                    dir.display()
                )));
            }
            holds.sort_by(|a, b| a.0.total_cmp(&b.0));
            let mut out = Vec::new();
            for (tf, run) in holds {
                let samples = read_spinup_csv(&run.join("spinup.csv")).map_err(SearchError::failed)?;
                let scene = rubblepile::granular::soft::scene::load_soft_scene(&run.join("scene.toml"))
                    .map_err(SearchError::failed)?;
                let t_final = scene.spinup.map_or(0.0, |s| s.path.t_final);
                let series = hold_series(&samples, t_final);
                if series.t_s.is_empty() {
                    continue;
                }
                out.push(judge_series(
                    &series,
                    window,
                    &criteria,
                    CreepCriterionKind::Paper,
                    tf,
                    run,
                ));
            }
            out
        }
    };
    for v in &judged {
        emit(Channel::Out, &verdict_line(v));
    }
    if let Some(out) = csv_out {
        rubblepile::io::safe_write::write_atomic(out, critical_csv(&judged))
            .map_err(|e| SearchError::failed(rubblepile::io::safe_write::describe(out, &e)))?;
    }
    for kind in CreepCriterionKind::ALL {
        match critical_from_verdicts(&judged, kind) {
            (Some(t), phi) => emit(
                Channel::Out,
                &format!(
                    "{} criterion: T_c3 = {t:.2} h, phi = {} deg",
                    kind.name(),
                    phi.map_or("-".into(), |p| format!("{p:.1}"))
                ),
            ),
            _ => emit(
                Channel::Out,
                &format!(
                    "{} criterion: no T_c3 among these holds{}",
                    kind.name(),
                    undecided_note(&judged, kind)
                ),
            ),
        }
    }
    Ok(())
}

/// Parses `RHO:T` pairs.
pub fn parse_points(points: &[String]) -> Result<Vec<(f64, f64)>, SearchError> {
    points
        .iter()
        .map(|p| {
            let (a, b) = p
                .split_once(':')
                .ok_or_else(|| SearchError::usage(format!("--points: expected RHO:T (kg/m^3:hours), got {p:?}")))?;
            let parse = |s: &str, what: &str| {
                s.trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite() && *x > 0.0)
                    .ok_or_else(|| {
                        SearchError::usage(format!("--points: {what} must be a number > 0, got {s:?} in {p:?}"))
                    })
            };
            Ok((parse(a, "the bulk density (kg/m^3)")?, parse(b, "the period (h)")?))
        })
        .collect()
}

/// Fits Zhang17 Eq. 22 to `points` (`RHO:T` pairs: kg/m³ and hours) and prints κ and the critical bulk density at
/// `period` hours.
pub fn density_fit(points: &[String], period: f64) -> Result<(), SearchError> {
    let pts = parse_points(points)?;
    if pts.is_empty() {
        return Err(SearchError::usage("--points: give at least one RHO:T pair"));
    }
    if !(period.is_finite() && period > 0.0) {
        return Err(SearchError::usage(format!(
            "--period-h must be > 0 hours, got {}",
            period
        )));
    }
    let fit = fit_density(&pts, SI_G, period).ok_or_else(|| SearchError::usage("--points: nothing to fit"))?;
    emit(
        Channel::Out,
        &format!(
            "kappa = {:.4} +- {:.4} from {} points; critical bulk density at T = {} h: {:.0} kg/m^3",
            fit.kappa,
            fit.sigma_kappa,
            pts.len(),
            period,
            fit.critical_density
        ),
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_parse_and_name_the_bad_one() {
        assert_eq!(
            parse_points(&["2100:2.4".into(), "2500:2.2".into()]).unwrap(),
            vec![(2100.0, 2.4), (2500.0, 2.2)]
        );
        let e = parse_points(&["2100-2.4".into()]).unwrap_err();
        assert!(e.to_string().contains("expected RHO:T"), "{}", e.to_string());
        let e = parse_points(&["2100:-1".into()]).unwrap_err();
        assert!(
            e.to_string().contains("the period (h) must be a number > 0"),
            "{}",
            e.to_string()
        );
    }
}
