//! The creep test of a run held at T_final, behind the search for T_c,3 (Zhang17 §3.3.3, §4.3, Fig. 22). The paper
//! calls a hold creeping when, after t_final, θ_max gradually rises or η_B and the coordination number gradually
//! fall (a small rise then levelling off, as in Fig. 22, is re-compaction, not creep); T_c,3 is the shortest T_final
//! that does not creep. It gives no tolerance.
//!
//! The criteria ([`CreepCriterionKind`]) judge the second half of the hold (the first is the transient):
//! [`CreepCriterionKind::Paper`] (default), the one-sided rule with zero tolerance on rates: a diagnostic creeps when
//! its weakening least-squares slope exceeds [`DEFAULT_SIGNIFICANCE`] standard errors ([`RateFit`], per 1000 s, the
//! error widened for serial correlation), so a longer hold only sharpens a verdict;
//! [`CreepCriterionKind::PaperTolerance`], one-sided with (our) tolerances on the change (θ_max +0.5°, η_B −0.0005,
//! contacts −0.05); [`CreepCriterionKind::Ours`], two-sided on θ_max and η_B only (scaled RCP holds lose contacts
//! while θ_max stays put). A released hold is not stable either: that is `analysis::critical`'s business.

use serde::Serialize;

use crate::analysis::spinup::PACKING_THRESHOLD;

/// Which reading of the creep test of Zhang17 §3.3.3 judges a hold (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum CreepCriterionKind {
    /// The paper's, zero tolerance: a significantly rising θ_max, falling η_B or falling coordination number.
    Paper,
    /// The paper's one-sided reading with tolerances on the second-half change (the default of earlier searches).
    PaperTolerance,
    /// Ours: θ_max or η_B moving either way beyond a tolerance; the coordination number not judged.
    Ours,
}

impl CreepCriterionKind {
    /// All kinds, the default (the paper's) first.
    pub const ALL: [CreepCriterionKind; 3] = [
        CreepCriterionKind::Paper,
        CreepCriterionKind::PaperTolerance,
        CreepCriterionKind::Ours,
    ];

    /// The name used on the command line and in `critical.json`: `paper`, `paper-tolerance` or `ours`.
    pub fn name(self) -> &'static str {
        match self {
            CreepCriterionKind::Paper => "paper",
            CreepCriterionKind::PaperTolerance => "paper-tolerance",
            CreepCriterionKind::Ours => "ours",
        }
    }
}

impl std::str::FromStr for CreepCriterionKind {
    type Err = String;
    /// Parses `paper`, `paper-tolerance` or `ours`; anything else is an error naming the expected values.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        CreepCriterionKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| format!("creep criterion: expected `paper`, `paper-tolerance` or `ours`, got `{s}`"))
    }
}

/// Largest change of the coordination number (contacts per particle) over the second half of a hold that the
/// paper-tolerance criterion lets pass by default: about 1 % of a coordination number of 5–6 (ours).
pub const PAPER_COORDINATION_TOLERANCE: f64 = 0.05;

/// Standard errors by which a weakening rate must exceed zero for the paper's criterion to call it creep: 2, a
/// one-sided false-alarm probability of 2.3 % per diagnostic for a hold that has settled.
pub const DEFAULT_SIGNIFICANCE: f64 = 2.0;

/// A creep criterion: its kind and its thresholds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CreepCriterion {
    /// Which reading (see [`CreepCriterionKind`]).
    pub kind: CreepCriterionKind,
    /// Largest allowed change of θ_max over the second half (degrees); 0 for the paper's (rates).
    pub theta_max_deg: f64,
    /// Largest allowed change of η_B (dimensionless); 0 for the paper's.
    pub packing: f64,
    /// Largest allowed change of the coordination number (contacts per particle), or `None` where it is not
    /// judged (ours).
    pub coordination: Option<f64>,
    /// The paper's: standard errors a weakening rate must exceed ([`DEFAULT_SIGNIFICANCE`]); `None` for the
    /// tolerance criteria.
    pub significance: Option<f64>,
}

/// The signed changes over the second half of a hold of the least-squares lines through θ_max (degrees), η_B and
/// the coordination number (contacts per particle) ([`second_half_drift`]): what the tolerance criteria judge.
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
    let fit = line_fit(t, y);
    if fit.stt == 0.0 {
        return 0.0;
    }
    fit.slope * (t[t.len() - 1] - t[0])
}

/// Least squares of `y` on `t`: slope, Σ(t − t̄)², residuals.
struct LineFit {
    slope: f64,
    stt: f64,
    residuals: Vec<f64>,
}

fn line_fit(t: &[f64], y: &[f64]) -> LineFit {
    let m = t.len() as f64;
    let (tm, ym) = (t.iter().sum::<f64>() / m, y.iter().sum::<f64>() / m);
    let (mut sty, mut stt) = (0.0, 0.0);
    for (a, b) in t.iter().zip(y) {
        sty += (a - tm) * (b - ym);
        stt += (a - tm) * (a - tm);
    }
    let slope = if stt == 0.0 { 0.0 } else { sty / stt };
    let residuals = t.iter().zip(y).map(|(a, b)| b - ym - slope * (a - tm)).collect();
    LineFit { slope, stt, residuals }
}

/// The rate of one diagnostic over the second half of a hold: the least-squares slope per 1000 s and its
/// standard error. The ordinary error `s / √Σ(t − t̄)²` assumes independent samples; the diagnostics of a pile
/// sampled every 200 s are not, so it is widened by `√((n − 2)/(n_eff − 2))` with the effective count
/// `n_eff = n (1 − ρ₁)/(1 + ρ₁)` of an AR(1) series of lag-1 autocorrelation ρ₁ (of the residuals, clamped to
/// [0, 0.9]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RateFit {
    /// Slope (unit of the diagnostic per 1000 s).
    pub rate_per_ks: f64,
    /// Its standard error (same unit); infinite with fewer than 4 samples.
    pub se_per_ks: f64,
    /// Samples in the fit.
    pub samples: usize,
}

impl RateFit {
    /// The rate of `y` sampled at `t` (s) over the second half of the samples.
    pub fn second_half(t: &[f64], y: &[f64]) -> Self {
        let n = t.len().min(y.len());
        RateFit::of(&t[n / 2..n], &y[n / 2..n])
    }

    /// The rate of `y` sampled at `t` (s) over all the samples given.
    pub fn of(t: &[f64], y: &[f64]) -> Self {
        let n = t.len().min(y.len());
        let (t, y) = (&t[..n], &y[..n]);
        if n < 4 || t.iter().chain(y).any(|v| !v.is_finite()) {
            return RateFit {
                rate_per_ks: if n >= 2 { line_fit(t, y).slope * 1e3 } else { 0.0 },
                se_per_ks: f64::INFINITY,
                samples: n,
            };
        }
        let fit = line_fit(t, y);
        if fit.stt == 0.0 {
            return RateFit {
                rate_per_ks: 0.0,
                se_per_ks: f64::INFINITY,
                samples: n,
            };
        }
        let ss: f64 = fit.residuals.iter().map(|r| r * r).sum();
        let lag: f64 = fit.residuals.windows(2).map(|w| w[0] * w[1]).sum();
        let rho = if ss > 0.0 { (lag / ss).clamp(0.0, 0.9) } else { 0.0 };
        let nf = n as f64;
        let n_eff = nf * (1.0 - rho) / (1.0 + rho);
        let se_ols = (ss / (nf - 2.0) / fit.stt).sqrt();
        let se = se_ols * ((nf - 2.0) / (n_eff - 2.0).max(1.0)).sqrt();
        RateFit {
            rate_per_ks: fit.slope * 1e3,
            se_per_ks: se * 1e3,
            samples: n,
        }
    }

    /// Whether the rate is beyond `z` standard errors in the direction `sign` (+1: rising, −1: falling).
    pub fn significant(&self, sign: f64, z: f64) -> bool {
        sign * self.rate_per_ks > z * self.se_per_ks
    }
}

/// The rates of θ_max (°/ks), η_B (1/ks) and the coordination number (contacts per particle per ks) over the second
/// half of a hold: what the paper's criterion judges.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HoldRates {
    /// θ_max.
    pub theta_max_deg: RateFit,
    /// η_B.
    pub packing: RateFit,
    /// Coordination number.
    pub coordination: RateFit,
}

impl HoldRates {
    /// The rates of the three series sampled at times `t` (s), over their second half.
    pub fn of(t: &[f64], theta_max_deg: &[f64], packing: &[f64], coordination: &[f64]) -> Self {
        HoldRates {
            theta_max_deg: RateFit::second_half(t, theta_max_deg),
            packing: RateFit::second_half(t, packing),
            coordination: RateFit::second_half(t, coordination),
        }
    }
}

impl CreepCriterion {
    /// The paper's criterion (the default): zero tolerance, a weakening rate beyond `significance` standard errors
    /// is creep ([`DEFAULT_SIGNIFICANCE`] by default).
    pub fn paper(significance: f64) -> Self {
        CreepCriterion {
            kind: CreepCriterionKind::Paper,
            theta_max_deg: 0.0,
            packing: 0.0,
            coordination: Some(0.0),
            significance: Some(significance),
        }
    }

    /// The paper's reading with tolerances: θ_max rising by > 0.5°, η_B falling by > 0.0005 (half the T_c,2
    /// threshold) or the coordination number falling by > `coordination` (contacts per particle) over the second
    /// half.
    pub fn paper_tolerance(coordination: f64) -> Self {
        CreepCriterion {
            kind: CreepCriterionKind::PaperTolerance,
            theta_max_deg: 0.5,
            packing: 0.5 * PACKING_THRESHOLD,
            coordination: Some(coordination),
            significance: None,
        }
    }

    /// Ours: θ_max changing by > 0.5° or η_B by > 0.0005 either way; the coordination number not judged.
    pub fn ours() -> Self {
        CreepCriterion {
            kind: CreepCriterionKind::Ours,
            theta_max_deg: 0.5,
            packing: 0.5 * PACKING_THRESHOLD,
            coordination: None,
            significance: None,
        }
    }

    /// The criterion of `kind` with its default thresholds.
    pub fn of_kind(kind: CreepCriterionKind) -> Self {
        match kind {
            CreepCriterionKind::Paper => CreepCriterion::paper(DEFAULT_SIGNIFICANCE),
            CreepCriterionKind::PaperTolerance => CreepCriterion::paper_tolerance(PAPER_COORDINATION_TOLERANCE),
            CreepCriterionKind::Ours => CreepCriterion::ours(),
        }
    }

    /// The diagnostics whose trend this criterion calls creep (`theta_max`, `packing_fraction`,
    /// `coordination_number`; empty: the hold has settled), from the second-half changes `d` (tolerance criteria)
    /// or rates `r` (the paper's).
    pub fn judge(&self, d: &HoldDrift, r: &HoldRates) -> Vec<&'static str> {
        let mut out = Vec::new();
        if let Some(z) = self.significance {
            // the weakening directions: more shear, looser, fewer contacts
            if r.theta_max_deg.significant(1.0, z) {
                out.push("theta_max");
            }
            if r.packing.significant(-1.0, z) {
                out.push("packing_fraction");
            }
            if r.coordination.significant(-1.0, z) {
                out.push("coordination_number");
            }
            return out;
        }
        // the paper's reading counts only the direction that weakens the pile
        let one_sided = self.kind == CreepCriterionKind::PaperTolerance;
        let beyond = |weakening: f64, tol: f64| {
            if one_sided {
                weakening > tol
            } else {
                weakening.abs() > tol
            }
        };
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
        self.judge(
            &HoldDrift::of(t, theta_max_deg, packing, coordination),
            &HoldRates::of(t, theta_max_deg, packing, coordination),
        )
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
            CreepCriterion::of_kind(CreepCriterionKind::PaperTolerance).drifting(t, theta, eta, cn),
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

    /// Regression guard (the coordination number had once dropped out of the creep test). The coordination
    /// number falls by 0.2 over the hold (0.1 over its second half), θ_max and η_B settled: creep for the paper,
    /// stable for ours — the case of our scaled RCP holds.
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
        let paper = CreepCriterion::paper_tolerance(0.05);
        let flat = vec![0.65; N];
        let theta = vec![30.0; N];
        let under = ramp(5.5, -0.049 / half);
        let over = ramp(5.5, -0.051 / half);
        assert!(paper.drifting(&t, &theta, &flat, &under).is_empty());
        assert_eq!(paper.drifting(&t, &theta, &flat, &over), vec!["coordination_number"]);
        // a looser tolerance lets the same fall pass
        assert!(
            CreepCriterion::paper_tolerance(0.06)
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
        assert!(
            e.contains("expected `paper`, `paper-tolerance` or `ours`, got `Paper`"),
            "{e}"
        );
        let j = serde_json::to_value(CreepCriterion::ours()).unwrap();
        assert_eq!(j["kind"], "ours");
        assert!(j["coordination"].is_null());
        let j = serde_json::to_value(CreepCriterion::of_kind(CreepCriterionKind::PaperTolerance)).unwrap();
        assert_eq!(j["coordination"], PAPER_COORDINATION_TOLERANCE);
        let j = serde_json::to_value(CreepCriterion::of_kind(CreepCriterionKind::Paper)).unwrap();
        assert_eq!(j["significance"], DEFAULT_SIGNIFICANCE);
    }

    fn paper(t: &[f64], theta: &[f64], eta: &[f64], cn: &[f64]) -> Vec<&'static str> {
        CreepCriterion::of_kind(CreepCriterionKind::Paper).drifting(t, theta, eta, cn)
    }

    /// The rate of a line is its slope per 1000 s, with a standard error at rounding level; on white noise the
    /// error matches the scatter of the slope over many draws (the AR(1) widening stays near 1 there).
    #[test]
    fn rate_fit_reads_slopes_and_honest_errors() {
        let t = times();
        let f = RateFit::of(&t, &ramp(5.5, -0.2));
        let slope = -0.2 / ((N - 1) as f64 * 100.0) * 1e3;
        assert!((f.rate_per_ks - slope).abs() < 1e-12 && f.se_per_ks < 1e-12, "{f:?}");
        let mut rng = crate::random::generator(5);
        let draws: Vec<RateFit> = (0..400)
            .map(|_| {
                let y: Vec<f64> = (0..N).map(|_| crate::random::symmetric(&mut rng, 1.0)).collect();
                RateFit::of(&t, &y)
            })
            .collect();
        let spread = (draws.iter().map(|d| d.rate_per_ks.powi(2)).sum::<f64>() / draws.len() as f64).sqrt();
        let mean_se = draws.iter().map(|d| d.se_per_ks).sum::<f64>() / draws.len() as f64;
        assert!((mean_se / spread - 1.0).abs() < 0.15, "se {mean_se} vs spread {spread}");
        // a random walk (strongly correlated samples) gets a wider error than the white-noise formula gives
        let mut walk = vec![0.0; N];
        for k in 1..N {
            walk[k] = walk[k - 1] + crate::random::symmetric(&mut rng, 1.0);
        }
        let f = RateFit::of(&t, &walk);
        let line = line_fit(&t, &walk);
        let ss: f64 = line.residuals.iter().map(|r| r * r).sum();
        let se_ols = (ss / (N as f64 - 2.0) / line.stt).sqrt() * 1e3;
        assert!(f.se_per_ks > 2.0 * se_ols, "{} vs {se_ols}", f.se_per_ks);
        assert_eq!(RateFit::of(&t[..3], &walk[..3]).se_per_ks, f64::INFINITY);
    }

    /// The paper's criterion has no tolerance: the coordination number falling by 0.01 over the hold (a fifth of
    /// the old tolerance) on a quiet record is creep; the same fall buried in scatter 20 times larger is not
    /// (yet); rising or flat diagnostics never are.
    #[test]
    fn paper_criterion_has_zero_tolerance_and_judges_rates_by_their_error() {
        let t = times();
        let quiet = |level: f64, change: f64, scatter: f64| -> Vec<f64> {
            ramp(level, change)
                .iter()
                .zip(noisy(0.0, scatter))
                .map(|(a, b)| a + b)
                .collect()
        };
        let theta = noisy(30.0, 1e-3);
        let eta = noisy(0.65, 1e-5);
        assert_eq!(
            paper(&t, &theta, &eta, &quiet(5.5, -0.01, 1e-3)),
            vec!["coordination_number"]
        );
        assert!(paper(&t, &theta, &eta, &quiet(5.5, -0.01, 0.2)).is_empty());
        assert!(paper(&t, &theta, &eta, &quiet(5.5, 0.2, 1e-3)).is_empty());
        assert!(paper(&t, &theta, &eta, &noisy(5.5, 1e-3)).is_empty());
        // θ_max relaxing and η_B compacting are the stable signature, rising θ_max or falling η_B creep
        assert!(
            paper(
                &t,
                &quiet(30.0, -1.0, 1e-3),
                &quiet(0.65, 1e-3, 1e-5),
                &noisy(5.5, 1e-3)
            )
            .is_empty()
        );
        assert_eq!(
            paper(
                &t,
                &quiet(30.0, 0.1, 1e-3),
                &quiet(0.65, -1e-4, 1e-6),
                &noisy(5.5, 1e-3)
            ),
            vec!["theta_max", "packing_fraction"]
        );
    }
}
