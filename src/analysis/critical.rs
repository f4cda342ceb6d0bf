//! The verdicts of a T_c,3 search (Zhang17 §3.3.3, §4.2; Eq. 22): each hold judged by the creep criteria of
//! [`crate::analysis::creep`], T_c,3 and φ under each criterion, the `critical.csv` / `holds.csv` /
//! `critical.json` formats. The search itself, which runs the holds, is one layer up (`experiment::critical_search`).

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::analysis::creep::{CreepCriterion, CreepCriterionKind, HoldDrift, HoldRates, RateFit};
use crate::analysis::spinup_diagnostics::SpinupSample;

/// Why a search or a fit could not be made: bad options or inputs (the caller's), or a run or file that failed.
#[derive(Debug, thiserror::Error)]
pub enum SearchError {
    /// Bad options or inputs.
    #[error("{0}")]
    Usage(String),
    /// A run failed or a file could not be written.
    #[error("{0}")]
    Failed(String),
}

impl SearchError {
    /// A [`SearchError::Usage`] saying `m`.
    pub fn usage(m: impl std::fmt::Display) -> Self {
        SearchError::Usage(m.to_string())
    }
    /// A [`SearchError::Failed`] saying `m`.
    pub fn failed(m: impl std::fmt::Display) -> Self {
        SearchError::Failed(m.to_string())
    }
}

/// One criterion's verdict on a hold.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CriterionVerdict {
    /// Diagnostics drifting beyond the criterion's tolerance over the second half of the hold (empty: none).
    pub drifting: Vec<&'static str>,
    /// Stable: the forcing was not released and nothing drifts.
    pub stable: bool,
}

impl CriterionVerdict {
    /// Whether the hold's record was too short to judge ([`TOO_SHORT`]): neither stable nor creeping. `critical.csv`
    /// keeps its vocabulary (`stable` false, drifting `record_too_short`); T_c,3 counts such a hold as not stable.
    pub fn undecided(&self) -> bool {
        self.drifting == [TOO_SHORT]
    }
}

/// One hold run judged by the creep criteria (Zhang17 §3.3.3; [`crate::analysis::creep`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HoldVerdict {
    /// T_final (h).
    pub t_final_hours: f64,
    /// Run directory.
    pub dir: PathBuf,
    /// Length of the hold judged (s): the judge window, or the hold's samples when shorter.
    pub hold_s: f64,
    /// Whether the forcing was released (global disruption) within the judged hold.
    pub released: bool,
    /// Time of the release after the hold's start (s).
    pub release_s: Option<f64>,
    /// The measured second-half changes of θ_max, η_B and the coordination number.
    pub drift: HoldDrift,
    /// Their rates over the second half, with standard errors (`None`: read from a `critical.csv` written before
    /// rates were recorded).
    pub rates: Option<HoldRates>,
    /// Largest θ_max during the hold (degrees).
    pub theta_max_deg: f64,
    /// The paper's criterion (zero tolerance, rates; `None` where no rates were recorded).
    pub paper: Option<CriterionVerdict>,
    /// The paper's reading with tolerances (the default of earlier searches).
    pub paper_tolerance: CriterionVerdict,
    /// Ours (two-sided on θ_max and η_B).
    pub ours: CriterionVerdict,
    /// The selected criterion's drifting diagnostics.
    pub drifting: Vec<&'static str>,
    /// The selected criterion's verdict.
    pub stable: bool,
    /// For a record too short to judge ([`TOO_SHORT`]): the judged length (s) that would give enough samples, where
    /// the record tells (`None` otherwise, and for holds read back from a `critical.csv`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub record_needed_s: Option<f64>,
}

impl HoldVerdict {
    /// The verdict of criterion `kind` (`None`: the paper's on a hold without recorded rates).
    pub fn verdict(&self, kind: CreepCriterionKind) -> Option<&CriterionVerdict> {
        match kind {
            CreepCriterionKind::Paper => self.paper.as_ref(),
            CreepCriterionKind::PaperTolerance => Some(&self.paper_tolerance),
            CreepCriterionKind::Ours => Some(&self.ours),
        }
    }

    /// Whether the hold is stable under `kind` (false where that verdict is missing).
    pub fn stable_by(&self, kind: CreepCriterionKind) -> bool {
        self.verdict(kind).is_some_and(|v| v.stable)
    }
}

/// T_c,3 and φ under one criterion.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CriterionResult {
    /// The criterion and its thresholds.
    pub criterion: CreepCriterion,
    /// T_c,3 (h): the shortest T_final from which every slower hold searched is stable under it.
    pub t_c3_hours: Option<f64>,
    /// φ (degrees): the largest θ_max of the hold at that T_c,3.
    pub friction_angle_deg: Option<f64>,
    /// Stable holds (T_final, h) below a creeping one, set aside by the monotone rule ([`set_aside`]).
    pub set_aside_hours: Vec<f64>,
}

/// `critical.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CriticalSearch {
    /// The selected criterion (the one behind `t_c3_hours` and `friction_angle_deg`).
    pub criterion: CreepCriterion,
    /// The judge window (s), when the holds were judged over their first part only.
    pub judge_window_s: Option<f64>,
    /// The runs, by increasing T_final.
    pub runs: Vec<HoldVerdict>,
    /// T_c,3 (h) under the selected criterion.
    pub t_c3_hours: Option<f64>,
    /// φ (degrees) under the selected criterion.
    pub friction_angle_deg: Option<f64>,
    /// T_c,3 and φ under the paper's criterion (zero tolerance, rates).
    pub paper: CriterionResult,
    /// Under the paper's reading with tolerances.
    pub paper_tolerance: CriterionResult,
    /// Under ours.
    pub ours: CriterionResult,
}

/// The coordination number the creep test judges: the force-floored `coordination_loaded` where the run has it,
/// else (files from before it) the raw count.
fn coordination_judged(s: &SpinupSample) -> f64 {
    if s.coordination_loaded.is_finite() {
        s.coordination_loaded
    } else {
        s.coordination_number
    }
}

/// Fewest samples in the second half of a hold's record for its trends to be judged (with fewer, the hold is not
/// stable under any criterion and its verdict names [`TOO_SHORT`]).
pub const MIN_SECOND_HALF_SAMPLES: usize = 4;

/// The name a verdict gives a hold whose record is too short to judge.
pub const TOO_SHORT: &str = "record_too_short";

/// One hold's record: times since the hold's start (s) and the three diagnostics, and when the forcing was
/// released (s after the start). What [`judge_series`] judges; read from a run's `spinup.csv` ([`hold_series`]) or
/// from a compact copy's `holds.csv`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct HoldSeries {
    /// Time since the hold began (s).
    pub t_s: Vec<f64>,
    /// θ_max (degrees).
    pub theta_max_deg: Vec<f64>,
    /// η_B.
    pub packing: Vec<f64>,
    /// Contacts per particle.
    pub coordination: Vec<f64>,
    /// Release time after the hold's start (s; negative: before it), if the forcing was released.
    pub release_s: Option<f64>,
}

/// The hold of a run (samples at or after `t_final`, s) as a [`HoldSeries`].
pub fn hold_series(samples: &[SpinupSample], t_final: f64) -> HoldSeries {
    let hold: Vec<&SpinupSample> = samples.iter().filter(|s| s.t >= t_final).collect();
    let col = |f: fn(&SpinupSample) -> f64| hold.iter().map(|s| f(s)).collect::<Vec<f64>>();
    HoldSeries {
        t_s: hold.iter().map(|s| s.t - t_final).collect(),
        theta_max_deg: col(|s| s.theta_max_deg),
        packing: col(|s| s.packing_fraction),
        coordination: col(coordination_judged),
        release_s: samples.iter().find(|s| !s.forcing).map(|s| s.t - t_final),
    }
}

/// The criteria of one search: the paper's (rates), the paper's with tolerances, ours.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Criteria {
    /// Zero tolerance, rates.
    pub paper: CreepCriterion,
    /// With tolerances.
    pub paper_tolerance: CreepCriterion,
    /// Two-sided.
    pub ours: CreepCriterion,
}

impl Default for Criteria {
    /// Every criterion with its default thresholds.
    fn default() -> Self {
        Criteria {
            paper: CreepCriterion::of_kind(CreepCriterionKind::Paper),
            paper_tolerance: CreepCriterion::of_kind(CreepCriterionKind::PaperTolerance),
            ours: CreepCriterion::of_kind(CreepCriterionKind::Ours),
        }
    }
}

/// Judges one hold's record over its first `window` seconds (`None`: all of it) by every criterion; `selected`
/// fills [`HoldVerdict::stable`] and [`HoldVerdict::drifting`].
pub fn judge_series(
    series: &HoldSeries,
    window: Option<f64>,
    criteria: &Criteria,
    selected: CreepCriterionKind,
    t_final_hours: f64,
    dir: PathBuf,
) -> HoldVerdict {
    // within a second: a hold's last sample lands a step's rounding past its nominal length (16 000.1 s of 16 000)
    let end = window.unwrap_or(f64::INFINITY) + 1.0;
    let n = series.t_s.iter().take_while(|&&t| t <= end).count();
    let (t, theta, eta, cn) = (
        &series.t_s[..n],
        &series.theta_max_deg[..n],
        &series.packing[..n],
        &series.coordination[..n],
    );
    let release_s = series.release_s.filter(|&r| r <= end);
    let released = release_s.is_some();
    let drift = HoldDrift::of(t, theta, eta, cn);
    let rates = HoldRates::of(t, theta, eta, cn);
    let theta_max_deg = theta.iter().cloned().fold(f64::NAN, f64::max);
    // a record with too few samples in its second half to fit a trend cannot show that the hold settled
    let too_short = !released && n / 2 < MIN_SECOND_HALF_SAMPLES;
    // the hold time of the sample that would make the second half long enough: read off the record when it runs
    // past the window, else extrapolated at its sample spacing
    let needed = 2 * MIN_SECOND_HALF_SAMPLES - 1;
    let record_needed_s = too_short
        .then(|| match series.t_s.get(needed) {
            Some(&t) => Some(t),
            None if series.t_s.len() >= 2 => {
                let (first, last) = (series.t_s[0], series.t_s[series.t_s.len() - 1]);
                Some(first + needed as f64 * (last - first) / (series.t_s.len() - 1) as f64)
            }
            None => None,
        })
        .flatten();
    let verdict = |c: &CreepCriterion| {
        let drifting = if too_short {
            vec![TOO_SHORT]
        } else {
            c.judge(&drift, &rates)
        };
        CriterionVerdict {
            stable: !released && drifting.is_empty(),
            drifting,
        }
    };
    let mut judged = HoldVerdict {
        t_final_hours,
        dir,
        hold_s: t.last().copied().unwrap_or(0.0).min(end),
        released,
        release_s,
        drift,
        rates: Some(rates),
        theta_max_deg,
        paper: Some(verdict(&criteria.paper)),
        paper_tolerance: verdict(&criteria.paper_tolerance),
        ours: verdict(&criteria.ours),
        drifting: Vec::new(),
        stable: false,
        record_needed_s,
    };
    let chosen = judged.verdict(selected).expect("every criterion judged").clone();
    (judged.drifting, judged.stable) = (chosen.drifting, chosen.stable);
    judged
}

/// Reads the `holds.csv` of a search's compact copy (`analysis/zhang2017/compact.py --search`: `t_final_h`,
/// `t_hold_s`, `packing_fraction`, `coordination_number`, `coordination_loaded`, `theta_max_deg` and, since Dec
/// 2026, `forcing` as 1/0, one row per sample of every hold) into one [`HoldSeries`] per hold, by increasing
/// T_final (h). The coordination number is `coordination_loaded` where every row has it. Without a `forcing`
/// column the release is unknown (`release_s` is `None`).
pub fn read_holds_csv(path: &Path) -> Result<Vec<(f64, HoldSeries)>, String> {
    use crate::io::table::{Cells, read_table};
    let table = read_table(path, Cells::Lenient).map_err(|e| e.to_string())?;
    let col = |name: &str| {
        table
            .column(name)
            .ok_or(format!("{}: no column {name}", path.display()))
    };
    let (tf, th, eta, cn, theta) = (
        col("t_final_h")?,
        col("t_hold_s")?,
        col("packing_fraction")?,
        col("coordination_number")?,
        col("theta_max_deg")?,
    );
    let loaded = table
        .column("coordination_loaded")
        .filter(|&k| table.rows.iter().all(|r| r.get(k).is_some_and(|v| v.is_finite())));
    let forcing = table.column("forcing");
    let get = |r: &[f64], k: usize| r.get(k).copied().unwrap_or(f64::NAN);
    let mut out: Vec<(f64, HoldSeries)> = Vec::new();
    for r in &table.rows {
        let period = get(r, tf);
        if out.last().is_none_or(|(p, _)| *p != period) {
            out.push((period, HoldSeries::default()));
        }
        let h = &mut out.last_mut().expect("just pushed").1;
        let t = get(r, th);
        h.t_s.push(t);
        h.theta_max_deg.push(get(r, theta));
        h.packing.push(get(r, eta));
        h.coordination.push(get(r, loaded.unwrap_or(cn)));
        if forcing.is_some_and(|k| get(r, k) == 0.0) && h.release_s.is_none() {
            h.release_s = Some(t);
        }
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(out)
}

/// Judges again, by `criteria` over the first `window` seconds, the holds of `verdicts` (a `critical.csv` read
/// back) that have a record in `series` ([`read_holds_csv`]): how searches made before the paper's criterion
/// judged rates get its verdict, and how one set of long holds is read at several hold lengths. A hold released
/// within its record keeps its release; one the CSV calls released but whose record has no release time (an old
/// `holds.csv`) stays released. Holds without a record are left as they are.
pub fn rejudge(
    verdicts: &[HoldVerdict],
    series: &[(f64, HoldSeries)],
    window: Option<f64>,
    criteria: &Criteria,
    selected: CreepCriterionKind,
) -> Vec<HoldVerdict> {
    verdicts
        .iter()
        .map(|v| {
            let Some((_, s)) = series.iter().find(|(p, _)| (p - v.t_final_hours).abs() < 1e-6) else {
                return v.clone();
            };
            let mut s = s.clone();
            if v.released && s.release_s.is_none() {
                // released at an unknown time: inside any window
                s.release_s = Some(0.0);
            }
            judge_series(&s, window, criteria, selected, v.t_final_hours, v.dir.clone())
        })
        .collect()
}

/// Judges the hold (samples at or after `t_final`, s) of one run of T_final = `t_final_hours` in `dir` over its
/// first `window` seconds ([`judge_series`] of [`hold_series`]).
pub fn judge_hold(
    samples: &[SpinupSample],
    t_final: f64,
    window: Option<f64>,
    criteria: &Criteria,
    selected: CreepCriterionKind,
    t_final_hours: f64,
    dir: PathBuf,
) -> HoldVerdict {
    judge_series(
        &hold_series(samples, t_final),
        window,
        criteria,
        selected,
        t_final_hours,
        dir,
    )
}

/// Index of the first run of the trailing block of holds stable under `kind` (runs by increasing T_final): the
/// shortest T_final from which every slower hold searched is stable. `None` when the slowest hold creeps or a
/// hold lacks that criterion's verdict.
fn stable_from(runs: &[HoldVerdict], kind: CreepCriterionKind) -> Option<usize> {
    if runs.iter().any(|r| r.verdict(kind).is_none()) {
        return None;
    }
    let start = runs.iter().rposition(|r| !r.stable_by(kind)).map_or(0, |i| i + 1);
    (start < runs.len()).then_some(start)
}

/// Reduces judged runs (by increasing T_final) to T_c,3 and φ under criterion `kind`. T_c,3 is the shortest T_final
/// from which every slower hold is stable (the verdict made monotone: a stable hold below a creeping one does not
/// count, see [`set_aside`]); φ the largest θ_max of the hold at T_c,3: Zhang17 §3.3.3 takes φ as the largest
/// mobilized angle *at the critical state*, the stable hold.
pub fn critical_from_verdicts(runs: &[HoldVerdict], kind: CreepCriterionKind) -> (Option<f64>, Option<f64>) {
    let Some(i) = stable_from(runs, kind) else {
        return (None, None);
    };
    let phi = runs[i].theta_max_deg;
    (Some(runs[i].t_final_hours), phi.is_finite().then_some(phi))
}

/// The T_final (h) of holds stable under `kind` that lie below a creeping or disrupted one: where the verdict is
/// not monotone in the spin. [`critical_from_verdicts`] sets them aside; a finer search between them and the next
/// creeping hold says whether they were luck.
pub fn set_aside(runs: &[HoldVerdict], kind: CreepCriterionKind) -> Vec<f64> {
    // an undecided hold (record too short) is not a creeping one
    let last_unstable = runs
        .iter()
        .rposition(|r| !r.stable_by(kind) && !r.verdict(kind).is_some_and(CriterionVerdict::undecided));
    runs.iter()
        .enumerate()
        .filter(|(i, r)| last_unstable.is_some_and(|u| *i < u) && r.stable_by(kind))
        .map(|(_, r)| r.t_final_hours)
        .collect()
}

/// Whether the search may stop after `runs`: under every criterion the slowest two holds are stable (T_c,3 and a
/// judged hold after it: a T_c,3 is only trusted with a slower stable hold beside it).
pub fn search_done(runs: &[HoldVerdict]) -> bool {
    CreepCriterionKind::ALL
        .iter()
        .all(|&k| stable_from(runs, k).is_some_and(|f| runs.len() > f + 1))
}

/// Whether the search stops after `runs`: when it is done ([`search_done`]), unless `all_holds` asks for the whole
/// grid.
pub fn search_stops(runs: &[HoldVerdict], all_holds: bool) -> bool {
    !all_holds && search_done(runs)
}

/// The number of leading runs (by increasing T_final) a search that judges them one after another keeps: up to and
/// including the first after which it stops ([`search_stops`]). A parallel search that ran more keeps as many.
pub fn sequential_stop(runs: &[HoldVerdict], all_holds: bool) -> usize {
    (1..=runs.len())
        .find(|&k| search_stops(&runs[..k], all_holds))
        .unwrap_or(runs.len())
}

/// One line per hold of the verdicts by every criterion (printed as the search goes).
pub fn verdict_line(r: &HoldVerdict) -> String {
    let word = |v: Option<&CriterionVerdict>| match v {
        None => "not judged".to_string(),
        Some(v) if v.stable => "stable".to_string(),
        Some(_) if r.released => "disrupted".to_string(),
        Some(v) if v.undecided() => format!(
            "undecided (record too short: {:.0} s judged, need {})",
            r.hold_s,
            r.record_needed_s
                .map_or(format!("{} samples", 2 * MIN_SECOND_HALF_SAMPLES), |s| format!(
                    "{s:.0} s"
                ))
        ),
        Some(v) => format!("creeps ({})", v.drifting.join(", ")),
    };
    let too_short = CreepCriterionKind::ALL
        .iter()
        .all(|&k| r.verdict(k).is_none_or(CriterionVerdict::undecided));
    // the rates of too few samples are meaningless (standard errors of inf)
    let rates = r.rates.filter(|_| !too_short).map_or(String::new(), |q| {
        format!(
            "; rates per 1000 s: theta_max {:+.3} +- {:.3} deg, eta_B {:+.2e} +- {:.1e}, coordination {:+.4} +- {:.4}",
            q.theta_max_deg.rate_per_ks,
            q.theta_max_deg.se_per_ks,
            q.packing.rate_per_ks,
            q.packing.se_per_ks,
            q.coordination.rate_per_ks,
            q.coordination.se_per_ks
        )
    });
    format!(
        "T_final = {:.2} h ({:.0} s judged): paper {}, paper-tolerance {}, ours {}; drift over the second half: \
         theta_max {:+.2} deg, eta_B {:+.5}, coordination {:+.3}{rates}",
        r.t_final_hours,
        r.hold_s,
        word(r.verdict(CreepCriterionKind::Paper)),
        word(r.verdict(CreepCriterionKind::PaperTolerance)),
        word(r.verdict(CreepCriterionKind::Ours)),
        r.drift.theta_max_deg,
        r.drift.packing,
        r.drift.coordination
    )
}

/// `" (undecided, record too short: 2.50, 2.60 h)"` when holds of `runs` are undecided under `kind`, else empty: why a
/// search may have no T_c,3 that is not creep.
pub fn undecided_note(runs: &[HoldVerdict], kind: CreepCriterionKind) -> String {
    let t: Vec<String> = runs
        .iter()
        .filter(|r| r.verdict(kind).is_some_and(CriterionVerdict::undecided))
        .map(|r| format!("{:.2}", r.t_final_hours))
        .collect();
    if t.is_empty() {
        String::new()
    } else {
        format!(" (undecided, record too short: {} h)", t.join(", "))
    }
}

/// The `critical.csv` header written before Dec 2026 (one-sided tolerance verdicts in `paper_*`, no rates); still
/// read by [`read_critical_csv`].
pub const CRITICAL_CSV_HEADER_V1: &str = "t_final_h,released,theta_max_deg,drift_theta_max_deg,drift_packing,drift_coordination,paper_stable,paper_drifting,ours_stable,ours_drifting\n";

/// The `critical.csv` header: one row per hold with the judged length, the release, the drifts, the rates and
/// their standard errors (per 1000 s) and the verdicts of the three criteria.
pub const CRITICAL_CSV_HEADER: &str = "t_final_h,hold_s,released,release_s,theta_max_deg,drift_theta_max_deg,drift_packing,drift_coordination,rate_theta_max_deg_per_ks,se_theta_max_deg_per_ks,rate_packing_per_ks,se_packing_per_ks,rate_coordination_per_ks,se_coordination_per_ks,paper_stable,paper_drifting,paper_tolerance_stable,paper_tolerance_drifting,ours_stable,ours_drifting\n";

/// `critical.csv`: [`CRITICAL_CSV_HEADER`] and one row per hold (drifting diagnostics joined by `;`; a missing
/// value is empty).
pub fn critical_csv(runs: &[HoldVerdict]) -> String {
    let mut out = CRITICAL_CSV_HEADER.to_string();
    for r in runs {
        // the rate and its standard error of each diagnostic (six empty cells without rates)
        let rates = r.rates.map_or(",,,,,".to_string(), |q| {
            let cells = [q.theta_max_deg, q.packing, q.coordination]
                .map(|x| format!("{:.6e},{:.6e}", x.rate_per_ks, x.se_per_ks));
            cells.join(",")
        });
        let verdict = |v: Option<&CriterionVerdict>| {
            v.map_or(",".to_string(), |v| format!("{},{}", v.stable, v.drifting.join(";")))
        };
        out += &format!(
            "{:.2},{:.1},{},{},{:.3},{:.4},{:.6},{:.4},{rates},{},{},{}\n",
            r.t_final_hours,
            r.hold_s,
            r.released,
            r.release_s.map_or(String::new(), |v| format!("{v:.1}")),
            r.theta_max_deg,
            r.drift.theta_max_deg,
            r.drift.packing,
            r.drift.coordination,
            verdict(r.paper.as_ref()),
            verdict(Some(&r.paper_tolerance)),
            verdict(Some(&r.ours)),
        );
    }
    out
}

/// Reads a `critical.csv` ([`critical_csv`], or the older [`CRITICAL_CSV_HEADER_V1`] layout, whose `paper_*`
/// columns are the paper-tolerance verdicts and which has no rates) back into judged holds (the run directories
/// are not in it: `dir` is empty; the selected criterion is the paper's where recorded, else the paper's with
/// tolerances), so that T_c,3 and φ can be re-derived by [`critical_from_verdicts`] from a committed copy without
/// the runs. A malformed row is an error naming its line and column.
pub fn read_critical_csv(text: &str) -> Result<Vec<HoldVerdict>, String> {
    const NAMES: [&str; 4] = ["theta_max", "packing_fraction", "coordination_number", TOO_SHORT];
    let mut lines = text.lines();
    let header = lines.next().map(str::trim);
    let v1 = header == Some(CRITICAL_CSV_HEADER_V1.trim());
    if !v1 && header != Some(CRITICAL_CSV_HEADER.trim()) {
        return Err(format!(
            "not a critical.csv: the header must be {}",
            CRITICAL_CSV_HEADER.trim()
        ));
    }
    let columns: Vec<&str> = header.unwrap_or_default().split(',').collect();
    let mut out = Vec::new();
    for (k, line) in lines.enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let at = |col: &str| format!("line {}: column {col}", k + 2);
        let c: Vec<&str> = line.split(',').collect();
        if c.len() != columns.len() {
            return Err(format!(
                "line {}: {} columns, expected {}",
                k + 2,
                c.len(),
                columns.len()
            ));
        }
        let cell = |col: &str| c[columns.iter().position(|n| *n == col).expect("known column")].trim();
        let num = |col: &str| {
            cell(col)
                .parse::<f64>()
                .map_err(|_| format!("{}: not a number", at(col)))
        };
        let opt_num = |col: &str| (!cell(col).is_empty()).then(|| num(col)).transpose();
        let flag = |col: &str| {
            cell(col)
                .parse::<bool>()
                .map_err(|_| format!("{}: not true/false", at(col)))
        };
        let names = |col: &str| -> Result<Vec<&'static str>, String> {
            cell(col)
                .split(';')
                .filter(|n| !n.is_empty())
                .map(|n| {
                    NAMES
                        .into_iter()
                        .find(|m| *m == n)
                        .ok_or_else(|| format!("{}: unknown {n}", at(col)))
                })
                .collect()
        };
        let verdict = |prefix: &str| -> Result<CriterionVerdict, String> {
            Ok(CriterionVerdict {
                stable: flag(&format!("{prefix}_stable"))?,
                drifting: names(&format!("{prefix}_drifting"))?,
            })
        };
        let (paper, paper_tolerance, rates, hold_s, release_s) = if v1 {
            (None, verdict("paper")?, None, f64::NAN, None)
        } else {
            let fit = |name: &str| -> Result<Option<RateFit>, String> {
                let rate = opt_num(&format!("rate_{name}_per_ks"))?;
                let se = opt_num(&format!("se_{name}_per_ks"))?;
                let fit = |(rate_per_ks, se_per_ks)| RateFit {
                    rate_per_ks,
                    se_per_ks,
                    samples: 0,
                };
                Ok(rate.zip(se).map(fit))
            };
            let rates = match (fit("theta_max_deg")?, fit("packing")?, fit("coordination")?) {
                (Some(theta_max_deg), Some(packing), Some(coordination)) => Some(HoldRates {
                    theta_max_deg,
                    packing,
                    coordination,
                }),
                _ => None,
            };
            let paper = (!cell("paper_stable").is_empty())
                .then(|| verdict("paper"))
                .transpose()?;
            (
                paper,
                verdict("paper_tolerance")?,
                rates,
                num("hold_s")?,
                opt_num("release_s")?,
            )
        };
        let selected = paper.clone().unwrap_or_else(|| paper_tolerance.clone());
        out.push(HoldVerdict {
            t_final_hours: num("t_final_h")?,
            dir: PathBuf::new(),
            hold_s,
            released: flag("released")?,
            release_s,
            drift: HoldDrift {
                theta_max_deg: num("drift_theta_max_deg")?,
                packing: num("drift_packing")?,
                coordination: num("drift_coordination")?,
            },
            rates,
            theta_max_deg: num("theta_max_deg")?,
            paper,
            paper_tolerance,
            ours: verdict("ours")?,
            drifting: selected.drifting,
            stable: selected.stable,
            record_needed_s: None,
        });
    }
    Ok(out)
}

/// The criteria of a search: the paper's with `significance` standard errors, the paper's with the coordination
/// tolerance `tol` (contacts per particle), ours (`None`: defaults); a usage error naming the option when a value
/// is not a positive number.
pub fn criteria(significance: Option<f64>, tol: Option<f64>) -> Result<Criteria, SearchError> {
    let positive = |x: Option<f64>, what: &str| match x {
        Some(c) if !(c.is_finite() && c > 0.0) => Err(SearchError::usage(format!("{what}, got {c}"))),
        _ => Ok(x),
    };
    let tol = positive(
        tol,
        "--coordination-tolerance must be a change of the coordination number > 0 (contacts per particle)",
    )?;
    let z = positive(significance, "--significance must be a number of standard errors > 0")?;
    Ok(Criteria {
        paper: CreepCriterion::paper(z.unwrap_or(crate::analysis::creep::DEFAULT_SIGNIFICANCE)),
        paper_tolerance: CreepCriterion::paper_tolerance(
            tol.unwrap_or(crate::analysis::creep::PAPER_COORDINATION_TOLERANCE),
        ),
        ours: CreepCriterion::ours(),
    })
}

/// The time (s) at which the path `p` (without rests) passes the period `period_h` (hours), between `t_inter` and
/// `t_final`; `None` outside `[T_final, T_inter]`.
pub fn path_time_at_period(p: &crate::granular::soft::spinup::SpinupPath, period_h: f64) -> Option<f64> {
    let x = period_h * 3600.0;
    let (hi, lo) = (p.period_inter, p.period_final);
    if !(lo - 1e-9..=hi + 1e-9).contains(&x) {
        return None;
    }
    if hi - lo <= 0.0 {
        return Some(p.t_final);
    }
    Some(p.t_inter + (hi - x) / (hi - lo) * (p.t_final - p.t_inter))
}

/// The result of a T_c,3 search directory, re-derived from its judged holds (`critical.csv`) by
/// [`critical_from_verdicts`], so that every search is read by today's rule whenever it ran: `t_c3_hours` and
/// `friction_angle_deg` (the paper's criterion, the search's default), `paper`, `paper_tolerance`, `ours`, and
/// `runs` (their `t_final_hours`). A search made before the paper's criterion judged rates is judged again from its
/// `holds.csv` where the compact copy has one ([`rejudge`]); without it, its `paper` values are null. A directory
/// with only `critical.json` is read as written. `None` when neither file is there or readable.
pub fn read_critical(search_dir: &Path) -> Option<serde_json::Value> {
    let Some(csv) = std::fs::read_to_string(search_dir.join("critical.csv")).ok() else {
        let text = std::fs::read_to_string(search_dir.join("critical.json")).ok()?;
        let mut v: serde_json::Value = serde_json::from_str(&text).ok()?;
        // a critical.json of before Dec 2026: its `paper` is today's paper-tolerance criterion
        if v.get("paper_tolerance").is_none() {
            let old = v.get("paper").cloned().unwrap_or_else(
                || serde_json::json!({ "t_c3_hours": v["t_c3_hours"], "friction_angle_deg": v["friction_angle_deg"] }),
            );
            v["paper_tolerance"] = old;
            v["paper"] = serde_json::json!({ "t_c3_hours": null, "friction_angle_deg": null });
        }
        return Some(v);
    };
    let mut holds = read_critical_csv(&csv).ok()?;
    if holds.iter().any(|h| h.paper.is_none())
        && let Ok(series) = read_holds_csv(&search_dir.join("holds.csv"))
    {
        holds = rejudge(&holds, &series, None, &Criteria::default(), CreepCriterionKind::Paper);
    }
    let of = |kind| {
        let (t, phi) = critical_from_verdicts(&holds, kind);
        serde_json::json!({ "t_c3_hours": t, "friction_angle_deg": phi })
    };
    let paper = of(CreepCriterionKind::Paper);
    Some(serde_json::json!({
        "t_c3_hours": paper["t_c3_hours"],
        "friction_angle_deg": paper["friction_angle_deg"],
        "paper": paper,
        "paper_tolerance": of(CreepCriterionKind::PaperTolerance),
        "ours": of(CreepCriterionKind::Ours),
        "runs": holds.iter().map(|h| serde_json::json!({ "t_final_hours": h.t_final_hours })).collect::<Vec<_>>(),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(t: f64, theta: f64, eta: f64, coord: f64, forcing: bool) -> SpinupSample {
        SpinupSample {
            t,
            path_period_h: 2.3,
            period_h: 2.3,
            forcing,
            body_particles: 100,
            body_mass_fraction: 1.0,
            a: 1.0,
            b: 1.0,
            c: 1.0,
            b_over_a: 1.0,
            c_over_a: 1.0,
            packing_fraction: eta,
            interior_particles: 50,
            coordination_number: coord,
            coordination_loaded: f64::NAN,
            fraction_0_contacts: 0.0,
            fraction_1_contact: 0.0,
            rves: 5,
            s_max: 1.0,
            p_max: 1.0,
            theta_max_deg: theta,
        }
    }

    fn hold(theta: impl Fn(f64) -> f64, eta: impl Fn(f64) -> f64, coord: impl Fn(f64) -> f64) -> Vec<SpinupSample> {
        (0..100)
            .map(|k| {
                let x = k as f64 / 99.0;
                sample(1000.0 + 10.0 * k as f64, theta(x), eta(x), coord(x), true)
            })
            .collect()
    }

    fn verdict(tf: f64, s: &[SpinupSample], selected: CreepCriterionKind) -> HoldVerdict {
        judge_hold(s, 1000.0, None, &Criteria::default(), selected, tf, PathBuf::new())
    }

    /// The creep criteria on synthetic holds: a steady θ_max is stable, a θ_max rising by 2° over the hold creeps
    /// under both; T_c,3 is the first stable T_final (every slower one stable too) and φ the largest θ_max of
    /// that hold, not of the creeping one beside it.
    #[test]
    fn hold_verdicts_give_t_c3_and_phi() {
        let flat = |v: f64| move |_: f64| v;
        let runs = vec![
            verdict(
                2.40,
                &hold(|x| 40.0 + 2.0 * x, flat(0.74), flat(9.0)),
                CreepCriterionKind::Paper,
            ),
            verdict(
                2.41,
                &hold(flat(39.0), flat(0.74), flat(9.0)),
                CreepCriterionKind::Paper,
            ),
            verdict(
                2.42,
                &hold(flat(37.5), flat(0.74), flat(9.0)),
                CreepCriterionKind::Paper,
            ),
        ];
        assert!(!runs[0].stable && runs[0].drifting == vec!["theta_max"]);
        assert_eq!(runs[0].ours.drifting, vec!["theta_max"]);
        assert_eq!(runs[0].paper_tolerance.drifting, vec!["theta_max"]);
        assert!(runs[1].stable && runs[2].stable);
        for k in CreepCriterionKind::ALL {
            assert_eq!(critical_from_verdicts(&runs, k), (Some(2.41), Some(39.0)));
        }
        assert!(search_done(&runs) && !search_done(&runs[..2]));
        // `--all-holds` never stops early; the default stops exactly when the search is done
        assert!(search_stops(&runs, false) && !search_stops(&runs, true) && !search_stops(&runs[..2], false));
        // a released run is never stable, under either criterion
        let mut s = hold(flat(30.0), flat(0.74), flat(9.0));
        s[50].forcing = false;
        let v = verdict(2.5, &s, CreepCriterionKind::Paper);
        assert!(!v.stable && !v.stable_by(CreepCriterionKind::Paper) && !v.ours.stable && v.released);
        assert!(
            verdict_line(&v).contains("paper disrupted, paper-tolerance disrupted, ours disrupted"),
            "{}",
            verdict_line(&v)
        );
    }

    /// The verdict made monotone: a hold that happens to be stable below a creeping one is set aside, T_c,3 is where
    /// the trailing run of stable holds begins, and the search is not done while the slowest hold creeps.
    #[test]
    fn a_stable_hold_below_a_creeping_one_is_set_aside() {
        let flat = |v: f64| move |_: f64| v;
        let rising = |x: f64| 40.0 + 2.0 * x;
        let kinds = [
            (2.40, false),
            (2.45, true), // lucky: stable below a creeping hold
            (2.50, false),
            (2.55, true),
            (2.60, true),
        ];
        let runs: Vec<HoldVerdict> = kinds
            .iter()
            .map(|&(tf, stable)| {
                let s = if stable {
                    hold(flat(38.0), flat(0.74), flat(9.0))
                } else {
                    hold(rising, flat(0.74), flat(9.0))
                };
                verdict(tf, &s, CreepCriterionKind::Paper)
            })
            .collect();
        for k in CreepCriterionKind::ALL {
            assert_eq!(critical_from_verdicts(&runs, k), (Some(2.55), Some(38.0)));
            assert_eq!(set_aside(&runs, k), vec![2.45]);
            // after the hold at 2.50 h the search is not done although 2.45 h was stable with one hold after it
            assert!(!search_done(&runs[..3]) && !search_done(&runs[..4]) && search_done(&runs));
            // the slowest hold creeping: no T_c,3 at all
            assert_eq!(critical_from_verdicts(&runs[..3], k), (None, None));
        }
    }

    /// Every T_c,3 from one search: holds at 2.55–2.58 h lose 0.2 contacts per particle over the hold with
    /// θ_max and η_B flat (our RCP holds), 2.59 h and later keep them. Ours finds T_c,3 = 2.55 h, the paper's
    /// (either reading) 2.59 h; the selected criterion fills the top-level verdict, and the search is done only
    /// once all have a stable hold and one more.
    #[test]
    fn both_criteria_give_their_own_t_c3_when_only_the_coordination_number_drifts() {
        let grid = [2.55, 2.56, 2.57, 2.58, 2.59, 2.60];
        let runs: Vec<HoldVerdict> = grid
            .iter()
            .map(|&tf| {
                let loss = if tf < 2.585 { 0.2 } else { 0.0 };
                let theta = 50.0 - 10.0 * (tf - 2.55);
                verdict(
                    tf,
                    &hold(move |_| theta, |_| 0.65, move |x| 5.5 - loss * x),
                    CreepCriterionKind::Ours,
                )
            })
            .collect();
        assert!(runs[0].stable && !runs[0].stable_by(CreepCriterionKind::Paper));
        assert_eq!(runs[0].paper_tolerance.drifting, vec!["coordination_number"]);
        assert_eq!(runs[0].paper.as_ref().unwrap().drifting, vec!["coordination_number"]);
        assert!(runs[0].drift.coordination < -0.09 && runs[0].drift.coordination > -0.11);
        let (t_ours, phi_ours) = critical_from_verdicts(&runs, CreepCriterionKind::Ours);
        let (t_paper, phi_paper) = critical_from_verdicts(&runs, CreepCriterionKind::Paper);
        assert_eq!(
            critical_from_verdicts(&runs, CreepCriterionKind::PaperTolerance).0,
            Some(2.59)
        );
        assert_eq!(t_ours, Some(2.55));
        assert_eq!(t_paper, Some(2.59));
        assert!((phi_ours.unwrap() - 50.0).abs() < 1e-9);
        assert!((phi_paper.unwrap() - (50.0 - 10.0 * 0.04)).abs() < 1e-9);
        assert!(!search_done(&runs[..4]) && !search_done(&runs[..5]) && search_done(&runs));
        let csv = critical_csv(&runs);
        assert!(csv.starts_with(CRITICAL_CSV_HEADER));
        assert!(
            csv.lines()
                .nth(1)
                .unwrap()
                .ends_with(",false,coordination_number,false,coordination_number,true,"),
            "{csv}"
        );
        assert_eq!(csv.lines().count(), grid.len() + 1);
        // the table reads back to the same verdicts (rates to the printed digits)
        let back = read_critical_csv(&csv).unwrap();
        for (a, b) in runs.iter().zip(&back) {
            for k in CreepCriterionKind::ALL {
                assert_eq!(a.verdict(k).map(|v| v.stable), b.verdict(k).map(|v| v.stable));
            }
            let (x, y) = (a.rates.unwrap().coordination, b.rates.unwrap().coordination);
            assert!((x.rate_per_ks - y.rate_per_ks).abs() <= 1e-6 * x.rate_per_ks.abs().max(1e-12));
        }
        assert_eq!(sequential_stop(&runs, false), runs.len());
        assert_eq!(sequential_stop(&runs[..5], true), 5);
    }

    /// Regression guard: a bad `--coordination-tolerance` is refused with the option's name and the expected
    /// value, before any run starts.
    #[test]
    fn coordination_tolerance_and_significance_must_be_positive() {
        for bad in [0.0, -0.1, f64::NAN] {
            let e = criteria(None, Some(bad)).unwrap_err().to_string();
            assert!(
                e.contains("--coordination-tolerance must be") && e.contains("> 0"),
                "{e}"
            );
            let e = criteria(Some(bad), None).unwrap_err().to_string();
            assert!(e.contains("--significance must be") && e.contains("> 0"), "{e}");
        }
        let c = criteria(Some(3.0), Some(0.1)).unwrap();
        assert_eq!(c.paper_tolerance.coordination, Some(0.1));
        assert_eq!(c.paper.significance, Some(3.0));
    }

    /// The judge window reads a long hold as a shorter one: a hold that releases its forcing at 20 000 s is
    /// stable when judged over its first 16 000 s and released over 32 000 s; the window's second half is the one
    /// fitted.
    #[test]
    fn judge_window_reads_the_first_part_of_a_hold() {
        let n = 161;
        let series = HoldSeries {
            t_s: (0..n).map(|k| 200.0 * k as f64).collect(),
            theta_max_deg: vec![30.0; n],
            packing: vec![0.65; n],
            // contacts lost only after 16 000 s
            coordination: (0..n)
                .map(|k| if k <= 80 { 5.5 } else { 5.5 - 0.0005 * (k - 80) as f64 })
                .collect(),
            release_s: Some(20_000.0),
        };
        let c = Criteria::default();
        let short = judge_series(
            &series,
            Some(16_000.0),
            &c,
            CreepCriterionKind::Paper,
            2.5,
            PathBuf::new(),
        );
        assert!(short.stable && !short.released && short.hold_s == 16_000.0, "{short:?}");
        let long = judge_series(
            &series,
            Some(32_000.0),
            &c,
            CreepCriterionKind::Paper,
            2.5,
            PathBuf::new(),
        );
        assert!(long.released && !long.stable && long.release_s == Some(20_000.0));
        let mut kept = series.clone();
        kept.release_s = None;
        let long = judge_series(&kept, None, &c, CreepCriterionKind::Paper, 2.5, PathBuf::new());
        assert_eq!(long.drifting, vec!["coordination_number"]);
        // 0.04 contacts per particle lost over the second half: under the old tolerance of 0.05, creep by rates
        assert!(long.paper_tolerance.stable, "{long:?}");
    }

    /// A hold of 16 000 s whose last sample lands at 16 000.1 s (the hold's start is off the output grid) is read
    /// whole by a 16 000 s window: the judged length and the verdicts are those of the hold without a window.
    #[test]
    fn a_window_keeps_the_sample_a_rounding_past_its_end() {
        let mut t_s: Vec<f64> = (0..80).map(|k| 200.0 * k as f64).collect();
        t_s.push(16_000.1);
        let n = t_s.len();
        let series = HoldSeries {
            // θ_max jumps by 5° in the last sample only (a fitted rise of 0.7°): the tolerance verdict turns on it
            theta_max_deg: (0..n).map(|k| if k + 1 == n { 35.0 } else { 30.0 }).collect(),
            t_s,
            packing: vec![0.65; n],
            coordination: vec![5.5; n],
            release_s: None,
        };
        let c = Criteria::default();
        let whole = judge_series(&series, None, &c, CreepCriterionKind::Paper, 2.75, PathBuf::new());
        let read = judge_series(
            &series,
            Some(16_000.0),
            &c,
            CreepCriterionKind::Paper,
            2.75,
            PathBuf::new(),
        );
        assert_eq!(read.hold_s, 16_000.1);
        assert!(
            !whole.paper_tolerance.stable && !read.paper_tolerance.stable,
            "{read:?}"
        );
        assert_eq!(read.drifting, whole.drifting);
    }

    /// A hold whose judged record has too few samples is undecided, not creeping: its line says how long a record it
    /// needs and prints no rates of ± inf, a stable hold below it is not set aside as non-monotone, and the search
    /// says why it has no T_c,3. `critical.csv` keeps its vocabulary (`false`, `record_too_short`).
    #[test]
    fn a_record_too_short_is_undecided_not_creeping() {
        let series = |n: usize| HoldSeries {
            t_s: (0..n).map(|k| 108.0 + 200.0 * k as f64).collect(),
            theta_max_deg: vec![30.0; n],
            packing: vec![0.65; n],
            coordination: vec![5.0; n],
            release_s: None,
        };
        let criteria = Criteria::default();
        let short = judge_series(
            &series(5),
            None,
            &criteria,
            CreepCriterionKind::Paper,
            2.70,
            PathBuf::new(),
        );
        let line = verdict_line(&short);
        assert!(
            line.contains("paper undecided (record too short: 908 s judged, need 1508 s)"),
            "{line}"
        );
        assert!(!line.contains("creeps") && !line.contains("inf"), "{line}");
        assert!(
            CreepCriterionKind::ALL
                .iter()
                .all(|&k| short.verdict(k).unwrap().undecided())
        );
        // a window that cuts a longer record: the needed length is read off the record
        let cut = judge_series(
            &series(20),
            Some(1000.0),
            &criteria,
            CreepCriterionKind::Paper,
            2.70,
            PathBuf::new(),
        );
        assert_eq!(cut.record_needed_s, Some(1508.0));
        let long = judge_series(
            &series(20),
            None,
            &criteria,
            CreepCriterionKind::Paper,
            2.60,
            PathBuf::new(),
        );
        assert!(long.stable && long.record_needed_s.is_none(), "{}", verdict_line(&long));
        let runs = [long, short];
        for kind in CreepCriterionKind::ALL {
            assert!(set_aside(&runs, kind).is_empty());
            assert_eq!(critical_from_verdicts(&runs, kind), (None, None));
            assert_eq!(undecided_note(&runs, kind), " (undecided, record too short: 2.70 h)");
        }
        let csv = critical_csv(&runs);
        assert!(
            csv.lines().nth(2).unwrap().ends_with(",false,record_too_short"),
            "{csv}"
        );
        let back = read_critical_csv(&csv).unwrap();
        assert!(back[1].paper.as_ref().unwrap().undecided() && back[1].ours.undecided());
    }
}
