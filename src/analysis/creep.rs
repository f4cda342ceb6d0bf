//! The creep test of a run held at T_final, behind the search for T_c,3 (Zhang17 §3.3.3, §4.3 and Fig. 22).
//!
//! **What the paper asks.** Zhang17 §3.3.3 holds the body at T_final after the spin-up and calls the hold creeping
//! when, after t_final, the shear load keeps growing or the interior keeps loosening: in its own diagnostics, a
//! gradual *rise* of the largest mobilized friction angle θ_max, or a gradual *fall* of the interior packing
//! fraction η_B and of the coordination number (mean contacts per particle). Its stable example (Fig. 22, PP2 at
//! 2811 kg/m³) shows η_B and the coordination number *rising* a little once the acceleration stops (the pile
//! re-compacts) and then levelling off; that is not creep. T_c,3 is the shortest T_final whose hold does not creep.
//! The paper gives no numbers for "gradual", and its sentence can be read as "η_B and the coordination number both
//! fall"; we read each of the three as a sign of creep on its own, because the paper lists them as indicators
//! and a hold in which any one of them keeps degrading has not settled.
//!
//! **The two criteria here** ([`CreepCriterionKind`]) judge the same thing, the change over the second half of the
//! hold of a least-squares line through each diagnostic ([`second_half_drift`]; the first half is left to the
//! transient that follows the end of the acceleration, so that "gradual" means a trend that persists):
//! - [`CreepCriterionKind::Paper`]: one-sided, as the paper words it, coordination number included: creep when θ_max
//!   rises by more than 0.5°, η_B falls by more than 0.0005 or the coordination number falls by more than 0.05
//!   (tolerances ours; the paper gives none);
//! - [`CreepCriterionKind::Ours`]: the criterion of the runs behind `analysis/zhang2017/REPORT.md` (23 Nov 2026):
//!   two-sided on θ_max (0.5°) and η_B (0.0005, half the T_c,2 threshold), the coordination number not judged. We
//!   dropped it because in our scaled RCP holds it fell by about 0.1 over the second half at every held period from
//!   2.74 h to 3.00 h (θ_max 25° at 3.00 h, far from yield) with θ_max and η_B flat: a slow loss of marginal
//!   contacts, not the creep that precedes failure.
//!
//! Either way a hold whose forcing was released (global disruption) is not stable; that is the search's business
//! (`analysis::spinup_search`, which uses these criteria).

use serde::Serialize;

use crate::analysis::spinup::PACKING_THRESHOLD;

/// Which reading of the creep test of Zhang17 §3.3.3 judges a hold (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CreepCriterionKind {
    /// The paper's: a rising θ_max, a falling η_B or a falling coordination number is creep.
    Paper,
    /// Ours (REPORT.md's T_c,3): θ_max or η_B moving either way is creep; the coordination number is not judged.
    Ours,
}

impl CreepCriterionKind {
    /// Both kinds, the paper's first.
    pub const ALL: [CreepCriterionKind; 2] = [CreepCriterionKind::Paper, CreepCriterionKind::Ours];

    /// The name used on the command line and in `critical.json`: `paper` or `ours`.
    pub fn name(self) -> &'static str {
        match self {
            CreepCriterionKind::Paper => "paper",
            CreepCriterionKind::Ours => "ours",
        }
    }
}

impl std::str::FromStr for CreepCriterionKind {
    type Err = String;
    /// Parses `paper` or `ours`; anything else is an error naming the expected values.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "paper" => Ok(CreepCriterionKind::Paper),
            "ours" => Ok(CreepCriterionKind::Ours),
            _ => Err(format!("creep criterion: expected `paper` or `ours`, got `{s}`")),
        }
    }
}

/// Largest change of the coordination number (contacts per particle) over the second half of a hold that the
/// paper's criterion lets pass by default. Ours, the paper gives no number: the tolerance of our first search
/// with the coordination number judged (Nov 2026), about 1 % of a coordination number of 5–6.
pub const PAPER_COORDINATION_TOLERANCE: f64 = 0.05;

/// A creep criterion: its kind and its tolerances, each the largest change over the second half of the hold of
/// the least-squares line through a diagnostic that still counts as settled.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CreepCriterion {
    /// Which reading: one-sided with the coordination number (paper) or two-sided without it (ours).
    pub kind: CreepCriterionKind,
    /// Largest allowed change of θ_max (degrees).
    pub theta_max_deg: f64,
    /// Largest allowed change of η_B (dimensionless).
    pub packing: f64,
    /// Largest allowed change of the coordination number (contacts per particle), or `None` where it is not
    /// judged (ours).
    pub coordination: Option<f64>,
}

/// The signed changes over the second half of a hold of the least-squares lines through θ_max (degrees), η_B and
/// the coordination number (contacts per particle) ([`second_half_drift`]): what both criteria judge.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HoldDrift {
    /// Change of θ_max (degrees; positive: rising).
    pub theta_max_deg: f64,
    /// Change of η_B (negative: loosening).
    pub packing: f64,
    /// Change of the coordination number (negative: contacts lost).
    pub coordination: f64,
}

impl HoldDrift {
    /// The drifts of the series `theta_max_deg`, `packing` and `coordination` sampled at times `t` (s).
    pub fn of(t: &[f64], theta_max_deg: &[f64], packing: &[f64], coordination: &[f64]) -> Self {
        HoldDrift {
            theta_max_deg: second_half_drift(t, theta_max_deg),
            packing: second_half_drift(t, packing),
            coordination: second_half_drift(t, coordination),
        }
    }
}

/// Change over the second half of `(t, y)` of its least-squares line (0 for fewer than 3 points there).
pub fn second_half_drift(t: &[f64], y: &[f64]) -> f64 {
    let n = t.len().min(y.len());
    let (t, y) = (&t[n / 2..n], &y[n / 2..n]);
    if t.len() < 3 {
        return 0.0;
    }
    let m = t.len() as f64;
    let (tm, ym) = (t.iter().sum::<f64>() / m, y.iter().sum::<f64>() / m);
    let (mut sty, mut stt) = (0.0, 0.0);
    for (a, b) in t.iter().zip(y) {
        sty += (a - tm) * (b - ym);
        stt += (a - tm) * (a - tm);
    }
    if stt == 0.0 {
        return 0.0;
    }
    sty / stt * (t[t.len() - 1] - t[0])
}

impl CreepCriterion {
    /// The paper's criterion with our tolerances: θ_max rising by > 0.5°, η_B falling by > 0.0005 (half the
    /// T_c,2 threshold) or the coordination number falling by > `coordination` (contacts per particle).
    pub fn paper(coordination: f64) -> Self {
        CreepCriterion {
            kind: CreepCriterionKind::Paper,
            theta_max_deg: 0.5,
            packing: 0.5 * PACKING_THRESHOLD,
            coordination: Some(coordination),
        }
    }

    /// Ours: θ_max changing by > 0.5° or η_B by > 0.0005 either way; the coordination number not judged.
    pub fn ours() -> Self {
        CreepCriterion {
            kind: CreepCriterionKind::Ours,
            theta_max_deg: 0.5,
            packing: 0.5 * PACKING_THRESHOLD,
            coordination: None,
        }
    }

    /// The criterion of `kind` with its default tolerances ([`PAPER_COORDINATION_TOLERANCE`] for the paper's).
    pub fn of_kind(kind: CreepCriterionKind) -> Self {
        match kind {
            CreepCriterionKind::Paper => CreepCriterion::paper(PAPER_COORDINATION_TOLERANCE),
            CreepCriterionKind::Ours => CreepCriterion::ours(),
        }
    }

    /// The diagnostics whose drift this criterion calls creep (`theta_max`, `packing_fraction`,
    /// `coordination_number`; empty: the hold has settled).
    pub fn judge(&self, d: &HoldDrift) -> Vec<&'static str> {
        // the paper's reading counts only the direction that weakens the pile (more shear, looser, fewer contacts)
        let one_sided = self.kind == CreepCriterionKind::Paper;
        let beyond = |weakening: f64, tol: f64| {
            if one_sided {
                weakening > tol
            } else {
                weakening.abs() > tol
            }
        };
        let mut out = Vec::new();
        if beyond(d.theta_max_deg, self.theta_max_deg) {
            out.push("theta_max");
        }
        if beyond(-d.packing, self.packing) {
            out.push("packing_fraction");
        }
        if self.coordination.is_some_and(|tol| beyond(-d.coordination, tol)) {
            out.push("coordination_number");
        }
        out
    }

    /// [`CreepCriterion::judge`] on the series themselves, sampled at times `t` (s) after t_final.
    pub fn drifting(
        &self,
        t: &[f64],
        theta_max_deg: &[f64],
        packing: &[f64],
        coordination: &[f64],
    ) -> Vec<&'static str> {
        self.judge(&HoldDrift::of(t, theta_max_deg, packing, coordination))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const N: usize = 200;

    fn times() -> Vec<f64> {
        (0..N).map(|k| k as f64 * 100.0).collect()
    }

    /// Deterministic scatter in [−0.5, 0.5) × `scale`.
    fn noisy(level: f64, scale: f64) -> Vec<f64> {
        (0..N)
            .map(|k| level + scale * ((k * 7919 % 101) as f64 / 101.0 - 0.5))
            .collect()
    }

    /// A line from `level` changing by `change` over the whole hold (so by `change / 2` over its second half).
    fn ramp(level: f64, change: f64) -> Vec<f64> {
        (0..N).map(|k| level + change * k as f64 / (N - 1) as f64).collect()
    }

    fn both(t: &[f64], theta: &[f64], eta: &[f64], cn: &[f64]) -> (Vec<&'static str>, Vec<&'static str>) {
        (
            CreepCriterion::of_kind(CreepCriterionKind::Paper).drifting(t, theta, eta, cn),
            CreepCriterion::of_kind(CreepCriterionKind::Ours).drifting(t, theta, eta, cn),
        )
    }

    /// Everything settled (scatter only): both criteria call the hold stable.
    #[test]
    fn settled_hold_is_stable_under_both_criteria() {
        let t = times();
        let (p, o) = both(&t, &noisy(30.0, 1e-3), &noisy(0.65, 1e-4), &noisy(5.5, 1e-3));
        assert!(p.is_empty() && o.is_empty(), "paper {p:?}, ours {o:?}");
    }

    /// Regression guard (issue 21: the coordination number had dropped out of the creep test). The coordination
    /// number falls by 0.2 over the hold (0.1 over its second half), θ_max and η_B settled: creep for the paper,
    /// stable for ours — the case of our RCP holds of 23 Nov 2026.
    #[test]
    fn paper_criterion_judges_the_coordination_number_that_ours_dropped() {
        let t = times();
        let (p, o) = both(&t, &noisy(30.0, 1e-3), &noisy(0.65, 1e-4), &ramp(5.5, -0.2));
        assert_eq!(p, vec!["coordination_number"]);
        assert!(o.is_empty(), "ours {o:?}");
    }

    /// The coordination number rising (re-compaction after the acceleration stops, Zhang17 Fig. 22's stable
    /// case) is not creep for either.
    #[test]
    fn rising_coordination_is_not_creep() {
        let t = times();
        let (p, o) = both(&t, &noisy(30.0, 1e-3), &noisy(0.65, 1e-4), &ramp(5.5, 0.2));
        assert!(p.is_empty() && o.is_empty(), "paper {p:?}, ours {o:?}");
    }

    /// η_B falling by 0.002 over the hold: creep for both; only η_B is named.
    #[test]
    fn falling_packing_alone_is_creep_for_both() {
        let t = times();
        let (p, o) = both(&t, &noisy(30.0, 1e-3), &ramp(0.65, -0.002), &noisy(5.5, 1e-3));
        assert_eq!(p, vec!["packing_fraction"]);
        assert_eq!(o, vec!["packing_fraction"]);
    }

    /// η_B rising by 0.002 (compaction): creep for ours (two-sided), not for the paper.
    #[test]
    fn rising_packing_is_creep_only_for_ours() {
        let t = times();
        let (p, o) = both(&t, &noisy(30.0, 1e-3), &ramp(0.65, 0.002), &noisy(5.5, 1e-3));
        assert!(p.is_empty(), "paper {p:?}");
        assert_eq!(o, vec!["packing_fraction"]);
    }

    /// θ_max rising by 2° over the hold: creep for both. θ_max falling by 1.2° (relaxing away from yield, as
    /// our HCP holds at 2.60–2.64 h): creep only for ours.
    #[test]
    fn theta_max_rising_is_creep_for_both_falling_only_for_ours() {
        let t = times();
        let (p, o) = both(&t, &ramp(30.0, 2.0), &noisy(0.65, 1e-4), &noisy(5.5, 1e-3));
        assert_eq!(p, vec!["theta_max"]);
        assert_eq!(o, vec!["theta_max"]);
        let (p, o) = both(&t, &ramp(30.0, -1.2), &noisy(0.65, 1e-4), &noisy(5.5, 1e-3));
        assert!(p.is_empty(), "paper {p:?}");
        assert_eq!(o, vec!["theta_max"]);
    }

    /// A transient confined to the first half (the settling right after t_final) is not creep.
    #[test]
    fn first_half_transient_is_not_creep() {
        let t = times();
        let settling: Vec<f64> = (0..N)
            .map(|k| 5.5 - if k < 80 { 0.5 * (1.0 - k as f64 / 80.0) } else { 0.0 })
            .collect();
        let theta: Vec<f64> = (0..N)
            .map(|k| 30.0 + if k < 80 { 5.0 * (1.0 - k as f64 / 80.0) } else { 0.0 })
            .collect();
        let (p, o) = both(&t, &theta, &noisy(0.65, 1e-4), &settling);
        assert!(p.is_empty() && o.is_empty(), "paper {p:?}, ours {o:?}");
    }

    /// Tolerances sit at the edge: a second-half change just under the tolerance passes, just over fails; and
    /// the line fit reads the change of a ramp exactly.
    #[test]
    fn tolerances_are_edges_of_the_second_half_change() {
        let t = times();
        // ramp over the whole hold by 2c changes by c·(N/2 − 1)/(N − 1) ≈ c over the second half
        let half = (N / 2 - 1) as f64 / (N - 1) as f64;
        assert!((second_half_drift(&t, &ramp(5.5, -0.2)) + 0.2 * half).abs() < 1e-12);
        let paper = CreepCriterion::paper(0.05);
        let flat = vec![0.65; N];
        let theta = vec![30.0; N];
        let under = ramp(5.5, -0.049 / half);
        let over = ramp(5.5, -0.051 / half);
        assert!(paper.drifting(&t, &theta, &flat, &under).is_empty());
        assert_eq!(paper.drifting(&t, &theta, &flat, &over), vec!["coordination_number"]);
        // a looser tolerance lets the same fall pass
        assert!(
            CreepCriterion::paper(0.06)
                .drifting(&t, &theta, &flat, &over)
                .is_empty()
        );
    }

    /// Regression guard for the option names and the JSON spelling of `critical.json`.
    #[test]
    fn criterion_kinds_parse_and_serialise_by_name() {
        for k in CreepCriterionKind::ALL {
            assert_eq!(k.name().parse::<CreepCriterionKind>(), Ok(k));
            assert_eq!(serde_json::to_value(k).unwrap(), serde_json::json!(k.name()));
        }
        let e = "Paper".parse::<CreepCriterionKind>().unwrap_err();
        assert!(e.contains("expected `paper` or `ours`, got `Paper`"), "{e}");
        let j = serde_json::to_value(CreepCriterion::ours()).unwrap();
        assert_eq!(j["kind"], "ours");
        assert!(j["coordination"].is_null());
        let j = serde_json::to_value(CreepCriterion::of_kind(CreepCriterionKind::Paper)).unwrap();
        assert_eq!(j["coordination"], PAPER_COORDINATION_TOLERANCE);
    }
}
