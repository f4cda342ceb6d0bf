//! Zhang17 Fig. 22, its closest analogue: θ_max, η_B and the coordination number through the holds of a T_c,3
//! search, for holds on both sides of T_c,3.
//!
//! The paper holds PP2 at the end of path 2 (2.26 h) with three bulk densities (2409, 2610 and 2811 kg/m³) and
//! shows creep in the first two and the stable signature in the third: η_B and the coordination number rise a
//! little after the forcing stops, then level off. Our searches hold one density at several periods instead. With
//! the grains rigid in the limit of small overlaps, the body's state depends on the spin only through Ω²/(Gρ_B)
//! (Eq. 22), so a hold at period T and density ρ_B stands for the paper's hold at 2.26 h with
//! ρ_B (T / 2.26 h)² ([`equivalent_density`]).
//!
//! Layout read: `<search>/holds.csv` (written by `analysis/zhang2017/compact.py --search`: `t_final_h`,
//! `t_hold_s` and the state variables per sample of each hold) beside the search's `critical.csv`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use rubblepile::analysis::creep::CreepCriterionKind;
use rubblepile::analysis::critical::{HoldVerdict, critical_from_verdicts, read_critical_csv};
use rubblepile::analysis::figures::lines::{Mark, Series};
use rubblepile::analysis::figures::stacked::{Panel, StackedLines};
use rubblepile::analysis::figures::style::write_figure;

use super::rows::DIDYMOS_PERIOD_HOURS;

/// The bulk density (kg/m³) at which a hold at the Didymos period has the Ω²/(Gρ_B) of a hold at `t_hours`
/// with density `rho`: Eq. 22 read backwards.
pub fn equivalent_density(rho: f64, t_hours: f64) -> f64 {
    rho * (t_hours / DIDYMOS_PERIOD_HOURS).powi(2)
}

/// One sample of one hold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HoldSample {
    /// The hold's period (h).
    pub t_final_hours: f64,
    /// Time since the hold began (s).
    pub t_hold_s: f64,
    /// Interior packing fraction η_B.
    pub packing: f64,
    /// Contacts per particle: the force-floored count where the run has it, else all overlaps.
    pub coordination: f64,
    /// Largest mobilized friction angle θ_max (°).
    pub theta_max_deg: f64,
}

/// Reads `holds.csv` ([`rubblepile::analysis::critical::read_holds_csv`]) as one row per sample; the coordination
/// number is `coordination_loaded` where every row has it.
pub fn read_holds(path: &Path) -> Result<Vec<HoldSample>, String> {
    let holds = rubblepile::analysis::critical::read_holds_csv(path)?;
    Ok(holds
        .iter()
        .flat_map(|(period, h)| {
            (0..h.t_s.len()).map(move |k| HoldSample {
                t_final_hours: *period,
                t_hold_s: h.t_s[k],
                packing: h.packing[k],
                coordination: h.coordination[k],
                theta_max_deg: h.theta_max_deg[k],
            })
        })
        .collect())
}

/// The holds a Fig. 22 analogue shows (at most four, by increasing T_final): the slowest hold that is not stable
/// by our criterion below T_c,3, T_c,3's hold and the one after it, and the slowest hold.
pub fn chosen_holds(verdicts: &[HoldVerdict]) -> Vec<f64> {
    let (t_c3, _) = critical_from_verdicts(verdicts, CreepCriterionKind::Ours);
    let mut t: Vec<f64> = Vec::new();
    let k = t_c3.and_then(|t| verdicts.iter().position(|v| v.t_final_hours == t));
    if let Some(k) = k {
        if k > 0 {
            t.push(verdicts[k - 1].t_final_hours);
        }
        t.extend(verdicts.iter().skip(k).take(2).map(|v| v.t_final_hours));
    } else if let Some(v) = verdicts.last() {
        t.push(v.t_final_hours);
    }
    if let Some(v) = verdicts.last() {
        t.push(v.t_final_hours);
    }
    t.sort_by(f64::total_cmp);
    t.dedup();
    t
}

fn verdict_word(v: &HoldVerdict, kind: CreepCriterionKind) -> &'static str {
    if v.released {
        "released"
    } else if v.stable_by(kind) {
        "stable"
    } else {
        "creeps"
    }
}

/// The Fig. 22-style figure of one search: one line per chosen hold in each of three panels.
pub fn hold_figure(title: String, samples: &[HoldSample], verdicts: &[HoldVerdict]) -> StackedLines {
    let holds = chosen_holds(verdicts);
    let panel = |y_label: &str, f: fn(&HoldSample) -> f64| Panel {
        y_label: y_label.into(),
        series: holds
            .iter()
            .enumerate()
            .map(|(j, &t)| {
                let v = verdicts.iter().find(|v| v.t_final_hours == t);
                Series {
                    label: format!(
                        "T = {t:.2} h: {}",
                        v.map_or("", |v| verdict_word(v, CreepCriterionKind::Ours))
                    ),
                    points: samples
                        .iter()
                        .filter(|s| (s.t_final_hours - t).abs() < 1e-6)
                        .map(|s| (s.t_hold_s / 3600.0, f(s)))
                        .collect(),
                    errors: vec![],
                    colour: j,
                    mark: Mark::Line,
                }
            })
            .collect(),
    };
    StackedLines {
        title,
        x_label: "time since the hold began (h)".into(),
        panels: vec![
            panel("θ_max (°)", |s| s.theta_max_deg),
            panel("η_B", |s| s.packing),
            panel("contacts per particle", |s| s.coordination),
        ],
    }
}

/// Writes the "Holds (Fig. 22 analogue)" section: for each `(label, search directory, bulk density kg/m³)` with a
/// `holds.csv`, a table of its holds (equivalent density, drifts, verdicts) and the figure `fig22_<stem>`.
pub fn write_holds_section(md: &mut String, searches: &[(String, PathBuf, f64)], out: &Path) {
    let with: Vec<_> = searches
        .iter()
        .filter(|(_, d, _)| d.join("holds.csv").is_file())
        .collect();
    if with.is_empty() {
        return;
    }
    let _ = writeln!(md, "\n## Holds (Zhang17 Fig. 22, closest analogue)\n");
    let _ = writeln!(
        md,
        "Fig. 22 holds PP2 at 2.26 h with ρ_B = 2409 and 2610 kg/m³ (creep) and 2811 kg/m³ (stable: η_B and the \
         coordination number rise a little, then level off). Ours hold one density at several periods; by Eq. 22 a \
         hold at T stands for a hold at 2.26 h with ρ_B (T/2.26 h)² (column 'ρ_B at 2.26 h'). Drifts are over each \
         hold's second half, as both creep criteria judge them; the coordination number is the force-floored count \
         where the run has it. Figures: the last hold below T_c3 that is not stable by ours, T_c3's hold and the \
         next, and the slowest hold.\n"
    );
    for (label, dir, rho) in with {
        let verdicts = std::fs::read_to_string(dir.join("critical.csv"))
            .map_err(|e| e.to_string())
            .and_then(|t| read_critical_csv(&t));
        let (verdicts, samples) = match (verdicts, read_holds(&dir.join("holds.csv"))) {
            (Ok(v), Ok(s)) => (v, s),
            (Err(e), _) | (_, Err(e)) => {
                let _ = writeln!(md, "{label}: unreadable ({e})\n");
                continue;
            }
        };
        let _ = writeln!(md, "### {label}\n");
        let _ = writeln!(
            md,
            "| T_final (h) | ρ_B at 2.26 h (kg/m³) | released | Δθ_max (°) | Δη_B | Δ contacts per particle | ours | paper-tolerance |"
        );
        let _ = writeln!(md, "| --- | --- | --- | --- | --- | --- | --- | --- |");
        for v in &verdicts {
            let _ = writeln!(
                md,
                "| {:.2} | {:.0} | {} | {:+.2} | {:+.1e} | {:+.3} | {} | {} |",
                v.t_final_hours,
                equivalent_density(*rho, v.t_final_hours),
                if v.released { "yes" } else { "no" },
                v.drift.theta_max_deg,
                v.drift.packing,
                v.drift.coordination,
                verdict_word(v, CreepCriterionKind::Ours),
                verdict_word(v, CreepCriterionKind::PaperTolerance),
            );
        }
        let stem = format!(
            "fig22_{}",
            label
                .chars()
                .map(|c| if c.is_ascii_alphanumeric() {
                    c.to_ascii_lowercase()
                } else {
                    '_'
                })
                .collect::<String>()
                .split('_')
                .filter(|s| !s.is_empty())
                .collect::<Vec<_>>()
                .join("_")
        );
        match write_figure(out, &stem, &hold_figure(format!("{label}: holds"), &samples, &verdicts)) {
            Ok(_) => {
                let _ = writeln!(md, "\n![{stem}]({stem}.png)\n");
            }
            Err(e) => eprintln!("warning: {stem}: {e}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str = "t_final_h,released,theta_max_deg,drift_theta_max_deg,drift_packing,drift_coordination,\
                          paper_stable,paper_drifting,ours_stable,ours_drifting";

    #[test]
    fn the_figure_shows_the_hold_below_t_c3_t_c3_the_next_and_the_slowest() {
        let csv = format!(
            "{HEADER}\n\
             2.40,true,60.0,1.0,-0.002,-0.3,false,packing_fraction,false,packing_fraction\n\
             2.45,false,55.0,0.9,-0.001,-0.1,false,theta_max,false,theta_max\n\
             2.50,false,50.0,0.1,0.00001,-0.01,true,,true,\n\
             2.55,false,48.0,0.1,0.00001,-0.09,false,coordination_number,true,\n\
             2.60,false,46.0,0.1,0.00001,-0.09,false,coordination_number,true,\n\
             2.65,false,45.0,0.1,0.00001,-0.09,false,coordination_number,true,\n"
        );
        let v = read_critical_csv(&csv).unwrap();
        assert_eq!(chosen_holds(&v), vec![2.45, 2.50, 2.55, 2.65]);
        assert_eq!(verdict_word(&v[0], CreepCriterionKind::Ours), "released");
        assert_eq!(verdict_word(&v[1], CreepCriterionKind::Ours), "creeps");
        assert_eq!(verdict_word(&v[3], CreepCriterionKind::PaperTolerance), "creeps");
        assert_eq!(verdict_word(&v[3], CreepCriterionKind::Ours), "stable");
        // no stable hold: the slowest only
        assert_eq!(chosen_holds(&v[..2]), vec![2.45]);
    }

    #[test]
    fn a_hold_at_a_longer_period_stands_for_a_denser_body_at_the_didymos_period() {
        assert!((equivalent_density(2095.0, DIDYMOS_PERIOD_HOURS) - 2095.0).abs() < 1e-9);
        // Ω²/(Gρ) equal: (2π/T)²/ρ at T = 2.60 h, 2095 kg/m³ against 2.26 h
        let rho = equivalent_density(2095.0, 2.60);
        let w = |t: f64| (2.0 * std::f64::consts::PI / (t * 3600.0)).powi(2);
        assert!((w(2.60) / 2095.0 - w(DIDYMOS_PERIOD_HOURS) / rho).abs() < 1e-12 * w(2.60) / 2095.0);
    }
}
