//! Zhang17 decided at the paper's scale: Table 3 by the decided protocol (HCP and RCP at the paper's grain counts,
//! the other four models scaled), the packing ordering RCP − HCP with `ordering.csv`, T_c,3 against the HCP
//! lattice's orientation, T_c,3 against the hold length, and the equilibrium bound on HCP's φ.
//!
//! The protocol: the Didymos primary of Naidu et al. (2020) ([`rubblepile::aggregate::triaxial_top`]), the bulk density
//! the paper's grain counts give ([`rubblepile::analysis::spinup::paper_bulk_density`]), the paper's creep criterion with zero
//! tolerance judged by rates ([`rubblepile::analysis::creep`]), every hold read over the length at which T_c,3 stops
//! moving ([`decided_hold_length`]).
//!
//! Layout read (compact copies, `analysis/zhang2017/compact.py`): `DIR/full/<name>/`, `DIR/scaled/<name>/` and
//! `DIR/orientation/<name>/` each with `path2/` (the search's base run: T_c1, T_c2, grains) and `critical/`
//! (`critical.csv`, `holds.csv`, `target.json`, the aggregate's report); `DIR/hold_length/<name>/critical/` for
//! searches kept only for their long holds. A name's model is its part before the first `_`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::creep_extrapolation::{ZeroRate, weakening_zeros};
use super::spin_limit::{critical_kappa, least_friction_angle};
use rubblepile::aggregate::report::AggregateReport;
use rubblepile::aggregate::triaxial_top::{NAIDU2020_EQUIVALENT_DIAMETER_M, NAIDU2020_EXTENTS_M};
use rubblepile::analysis::creep::CreepCriterionKind;
use rubblepile::analysis::critical::{
    Criteria, HoldSeries, HoldVerdict, critical_from_verdicts, read_critical_csv, read_holds_csv, rejudge,
};
use rubblepile::analysis::figures::lines::{LineChart, Mark, Series};
use rubblepile::analysis::figures::style::write_figure;
use rubblepile::analysis::spinup::{omega_of_hours, paper_bulk_density};
use rubblepile::io::scene_file::SI_G;

use super::rows::{ModelRow, TABLE3, opt, path_row};

/// The hold lengths (s) at which every search is read: the 16 000 s of the earlier searches and two and about
/// three times that.
pub const HOLD_LENGTHS: [f64; 3] = [16_000.0, 32_000.0, 50_000.0];

/// The groups of searches under the decided directory.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Group {
    /// HCP and RCP at the paper's grain counts.
    Full,
    /// The other four models, scaled.
    Scaled,
    /// The scaled HCP at several lattice orientations.
    Orientation,
    /// Searches kept only for T_c,3 against the hold length.
    HoldLength,
}

impl Group {
    /// All groups with their directory names.
    pub const ALL: [(Group, &'static str); 4] = [
        (Group::Full, "full"),
        (Group::Scaled, "scaled"),
        (Group::Orientation, "orientation"),
        (Group::HoldLength, "hold_length"),
    ];
}

/// One search of the decided study.
#[derive(Debug, Clone)]
pub struct DecidedSearch {
    /// Its group.
    pub group: Group,
    /// Its directory name (`hcp_full_random1`, `rcp_full`, `pp2`, …).
    pub name: String,
    /// Its model (the name up to the first `_`).
    pub model: String,
    /// The base run read as a path-2 row (T_c1, T_c2, grains), when `path2/` is there.
    pub row: Option<ModelRow>,
    /// The aggregate's report (`critical/target.json`), when there.
    pub target: Option<AggregateReport>,
    /// The holds as the search judged them (`critical.csv`).
    pub verdicts: Vec<HoldVerdict>,
    /// Every hold's record (`holds.csv`).
    pub series: Vec<(f64, HoldSeries)>,
}

impl DecidedSearch {
    /// The longest length (s) over which every hold that kept its forcing was recorded (the hold lengths it can
    /// be read at).
    pub fn recorded_s(&self) -> f64 {
        self.series
            .iter()
            .filter(|(_, s)| s.release_s.is_none())
            .map(|(_, s)| s.t_s.last().copied().unwrap_or(0.0))
            .fold(f64::INFINITY, f64::min)
    }

    /// The hold lengths of [`HOLD_LENGTHS`] it can be read at.
    pub fn lengths(&self) -> Vec<f64> {
        let recorded = self.recorded_s();
        HOLD_LENGTHS.iter().copied().filter(|&l| l <= recorded + 1.0).collect()
    }

    /// The holds judged by every criterion over their first `window` seconds, including those still running
    /// whose record is shorter than `window` (see [`DecidedSearch::is_pending`]).
    fn judged_all(&self, window: f64) -> Vec<HoldVerdict> {
        rejudge(
            &self.verdicts,
            &self.series,
            Some(window),
            &Criteria::default(),
            CreepCriterionKind::Paper,
        )
    }

    /// Whether the hold `h`, read at `window` seconds, is still running: not released, and its record (`holds.csv`)
    /// shorter than `window` (within a second, as [`DecidedSearch::lengths`]).
    fn is_pending(&self, h: &HoldVerdict, window: f64) -> bool {
        let recorded = self
            .series
            .iter()
            .find(|(t, _)| (t - h.t_final_hours).abs() < 1e-9)
            .and_then(|(_, s)| s.t_s.last().copied())
            .unwrap_or(0.0);
        !h.released && recorded + 1.0 < window
    }

    /// The holds judged by every criterion over their first `window` seconds: those released, and those recorded
    /// for the whole window. A hold still running (copied before it reached `window`) has no verdict at that length
    /// yet: read over its shorter record it would pass for stable.
    pub fn judged(&self, window: f64) -> Vec<HoldVerdict> {
        let mut judged = self.judged_all(window);
        judged.retain(|h| !self.is_pending(h, window));
        judged
    }

    /// T_c,3 (h) and φ (°) by `kind` over holds read at `window` seconds.
    pub fn t_c3(&self, window: f64, kind: CreepCriterionKind) -> (Option<f64>, Option<f64>) {
        critical_from_verdicts(&self.judged(window), kind)
    }

    /// The shortest T_final (h) from which no hold searched is released within `window` seconds: the pile's
    /// failure (global disruption, Zhang17 §3.3.3) stops there, whether or not it still creeps. `None` when the
    /// slowest hold is released.
    pub fn no_release_from(&self, window: f64) -> Option<f64> {
        let judged = self.judged(window);
        let last_released = judged.iter().rposition(|h| h.released);
        let first = last_released.map_or(0, |i| i + 1);
        judged.get(first).map(|h| h.t_final_hours)
    }

    /// [`DecidedSearch::no_release_from`] as a table cell: `≤ T` when not even the fastest hold searched is released
    /// (the failure stops at or before it), `–` when the slowest is.
    pub fn no_release_cell(&self, window: f64) -> String {
        let none_released = self.judged(window).iter().all(|h| !h.released);
        match self.no_release_from(window) {
            Some(t) if none_released => format!("≤ {t:.2}"),
            t => hours(t),
        }
    }

    /// The holds as letters by the paper's criterion at `window`: `R` released, `C` creeping, `S` stable, `…` still
    /// running and not yet recorded for `window` seconds.
    pub fn letters(&self, window: f64) -> String {
        self.judged_all(window)
            .iter()
            .map(|h| {
                let letter = if h.released {
                    'R'
                } else if self.is_pending(h, window) {
                    '…'
                } else if h.stable_by(CreepCriterionKind::Paper) {
                    'S'
                } else {
                    'C'
                };
                format!("{letter} {:.2}", h.t_final_hours)
            })
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The lattice orientation of its target (`perpendicular` for an HCP whose target report predates orientations
    /// or was not copied, `–` for a model without a lattice).
    pub fn orientation(&self) -> String {
        match &self.target {
            Some(t) => t.lattice_orientation.clone().unwrap_or_else(|| {
                if t.model == "hcp" {
                    "perpendicular".into()
                } else {
                    "–".into()
                }
            }),
            // a copy made before targets were recorded: every HCP lattice was then stacked along the spin axis
            None if self.model == "hcp" => "perpendicular".into(),
            None => "–".into(),
        }
    }

    /// Grains: the base run's, else the target's.
    pub fn grains(&self) -> Option<usize> {
        self.row.as_ref().map(|r| r.n).or(self.target.as_ref().map(|t| t.n))
    }
}

/// Reads every search under `dir` (see the module docs), by group and name.
pub fn read_decided(dir: &Path) -> Vec<DecidedSearch> {
    let mut out = Vec::new();
    for (group, sub) in Group::ALL {
        let Ok(entries) = std::fs::read_dir(dir.join(sub)) else {
            continue;
        };
        let mut names: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
        names.sort();
        for d in names {
            let critical = d.join("critical");
            let Ok(text) = std::fs::read_to_string(critical.join("critical.csv")) else {
                continue;
            };
            let Ok(verdicts) = read_critical_csv(&text) else {
                continue;
            };
            let name = d
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            out.push(DecidedSearch {
                group,
                model: name.split('_').next().unwrap_or("").to_string(),
                row: path_row(&d, "path2").ok().map(|r| r.0),
                target: std::fs::read_to_string(critical.join("target.json"))
                    .ok()
                    .and_then(|t| serde_json::from_str(&t).ok()),
                series: read_holds_csv(&critical.join("holds.csv")).unwrap_or_default(),
                verdicts,
                name,
            });
        }
    }
    out
}

/// The hold length (s) at which T_c,3 stops moving: the shortest of [`HOLD_LENGTHS`] from which every search read
/// at two or more lengths gives the same T_c,3 (paper's criterion) at every longer length it has. 16 000 s when no
/// search has two lengths.
pub fn decided_hold_length(searches: &[DecidedSearch]) -> f64 {
    let settled = |l: f64| {
        searches.iter().all(|s| {
            let lengths = s.lengths();
            let at_l = s.t_c3(l, CreepCriterionKind::Paper).0;
            lengths
                .iter()
                .filter(|&&m| m >= l)
                .all(|&m| s.t_c3(m, CreepCriterionKind::Paper).0 == at_l)
        })
    };
    HOLD_LENGTHS
        .iter()
        .copied()
        .find(|&l| settled(l))
        .unwrap_or(HOLD_LENGTHS[HOLD_LENGTHS.len() - 1])
}

/// The paper's Table 3 T_c,3 (h) and φ (°) of `model`.
fn paper_t_c3(model: &str) -> Option<(f64, f64)> {
    TABLE3.iter().find(|p| p.0 == model).map(|p| (p.5, p.2))
}

fn hours(x: Option<f64>) -> String {
    opt(x, 2)
}

/// `ordering.csv`: one row per full-size search (`model, grains, orientation, criterion, hold_s, T_c3_h,
/// phi_deg`), then `RCP-HCP` whose `T_c3_h` is the RCP search's T_c,3 less the mean of the HCP searches'.
pub fn ordering_csv(full: &[&DecidedSearch], hold_s: f64) -> String {
    let mut out = String::from("model,grains,orientation,criterion,hold_s,T_c3_h,phi_deg\n");
    let cell = |x: Option<f64>, d: usize| x.map_or(String::new(), |v| format!("{v:.d$}"));
    for s in full {
        let (t, phi) = s.t_c3(hold_s, CreepCriterionKind::Paper);
        out += &format!(
            "{},{},{},paper,{hold_s:.0},{},{}\n",
            s.model.to_uppercase(),
            s.grains().map_or(String::new(), |n| n.to_string()),
            s.orientation(),
            cell(t, 2),
            cell(phi, 1)
        );
    }
    out += &format!(
        "RCP-HCP,,,paper,{hold_s:.0},{},\n",
        cell(ordering_difference(full, hold_s), 2)
    );
    out
}

/// RCP's T_c,3 less the mean of the HCP searches' (h), by the paper's criterion at `hold_s`; `None` unless every
/// one has a T_c,3.
pub fn ordering_difference(full: &[&DecidedSearch], hold_s: f64) -> Option<f64> {
    let of = |model: &str| -> Option<Vec<f64>> {
        let v: Vec<Option<f64>> = full
            .iter()
            .filter(|s| s.model == model)
            .map(|s| s.t_c3(hold_s, CreepCriterionKind::Paper).0)
            .collect();
        if v.is_empty() { None } else { v.into_iter().collect() }
    };
    let (rcp, hcp) = (of("rcp")?, of("hcp")?);
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    Some(mean(&rcp) - mean(&hcp))
}

fn mean_and_sd(v: &[f64]) -> Option<(f64, f64)> {
    if v.is_empty() {
        return None;
    }
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let sd = if v.len() > 1 {
        (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    } else {
        0.0
    };
    Some((m, sd))
}

/// The Naidu et al. (2020) body as a homogeneous ellipsoid of its semi-extents' ratios and its volume (m).
pub fn naidu_ellipsoid() -> [f64; 3] {
    let semi = NAIDU2020_EXTENTS_M.map(|e| 0.5 * e);
    let r_eq = 0.5 * NAIDU2020_EQUIVALENT_DIAMETER_M;
    let scale = (r_eq.powi(3) / (semi[0] * semi[1] * semi[2])).cbrt();
    semi.map(|a| a * scale)
}

/// The table "Where creep stops": for each search, read at the longest hold length it has, the period at which
/// the weakening rates of its held (not released) holds reach zero ([`super::creep_extrapolation::zero_rate_period`]).
fn write_zero_rates(md: &mut String, searches: &[DecidedSearch]) {
    let _ = writeln!(md, "\n### Where creep stops: the weakening rates' zero\n");
    let _ = writeln!(
        md,
        "With zero tolerance a hold creeps whenever a rate is significant, however small. Here the weakening rates \
         (coordination number and η_B falling, θ_max rising, over each hold's second half) of the holds that kept \
         their forcing are fitted by a line against T_final, read at the longest length every such hold has; its \
         zero is the period from which no hold would weaken (`studies/zhang2017/creep_extrapolation.rs`; the error from the \
         rates' scatter about the line). \"largest\" is the slowest of the three: the period from which the paper's \
         test would call every hold stable.\n"
    );
    let _ = writeln!(
        md,
        "| search | hold read (s) | holds fitted | coordination (h) | η_B (h) | θ_max (h) | largest (h) |"
    );
    let _ = writeln!(md, "| --- | --- | --- | --- | --- | --- | --- |");
    for s in searches {
        let Some(&window) = s.lengths().last() else {
            continue;
        };
        let judged = s.judged(window);
        let zeros = weakening_zeros(&judged);
        let cell = |z: &Option<ZeroRate>| z.map_or("–".into(), |z| format!("{:.2} ± {:.2}", z.period_h, z.se_h));
        let held = judged.iter().filter(|v| !v.released).count();
        let largest = zeros.iter().flatten().max_by(|a, b| a.period_h.total_cmp(&b.period_h));
        let _ = writeln!(
            md,
            "| {} | {window:.0} | {held} | {} | {} | {} | {} |",
            s.name,
            cell(&zeros[0]),
            cell(&zeros[1]),
            cell(&zeros[2]),
            cell(&largest.copied())
        );
    }
}

/// The decided section of the report; writes `ordering.csv` and `decided_hold_length.{svg,png}` into `out`.
pub fn write_decided_section(md: &mut String, dir: &Path, out: &Path) -> Result<(), String> {
    let searches = read_decided(dir);
    let hold = decided_hold_length(&searches);
    let (rho, volume) = paper_bulk_density();
    let _ = writeln!(md, "\n## Decided at the paper's scale\n");
    let _ = writeln!(
        md,
        "From the compact copies under `{}` (`src/studies/zhang2017/decided.rs`; commands in \
         `analysis/zhang2017/decide/README.md`). Protocol: the Didymos primary of Naidu et al. (2020) (`--shape \
         didymos`: extents 832 × 838 × 786 m, D_eq 780 m, an equatorial bulge); the bulk density the paper's own \
         grain counts give, ρ_B = M_P / V̄ = {rho:.1} kg/m³ (HCP's 42 062 and RCP's 36 523 grains of 10 m at \
         Table 3's η_B fill V̄ = {volume:.4e} m³, D_eq {:.0} m); the paper's creep criterion with zero tolerance, \
         judged by rates (a weakening trend of θ_max, η_B or the coordination number beyond 2 standard errors over \
         a hold's second half is creep); every hold read over its first **{hold:.0} s**, the length at which T_c,3 \
         stops moving (table \"Hold length\" below). T_c1/T_c2 are those of each search's base run (path 2).\n",
        dir.display(),
        (6.0 * volume / std::f64::consts::PI).cbrt()
    );
    let in_group = |g: Group| searches.iter().filter(move |s| s.group == g).collect::<Vec<_>>();
    // Table 3 by the decided protocol
    let _ = writeln!(md, "### Table 3 by the decided protocol\n");
    let _ = writeln!(
        md,
        "| model | grains | lattice | T_c1 / T_c2 (h) | T_c3 (h), paper's criterion | φ (°) | T_c3 paper-tolerance / \
         ours (h) | no release from (h) | holds (R released, C creeps, S stable) | paper T_c3, φ | T_c3 − paper (h) |"
    );
    let _ = writeln!(
        md,
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    let table: Vec<&DecidedSearch> = in_group(Group::Full)
        .into_iter()
        .chain(in_group(Group::Scaled))
        .collect();
    for s in &table {
        let (t, phi) = s.t_c3(hold, CreepCriterionKind::Paper);
        let paper = paper_t_c3(&s.model);
        let _ = writeln!(
            md,
            "| {}{} | {} | {} | {} / {} | {} | {} | {} / {} | {} | {} | {} | {} |",
            s.model.to_uppercase(),
            if s.group == Group::Full { " (full)" } else { "" },
            s.grains().map_or("–".into(), |n| n.to_string()),
            s.orientation(),
            hours(s.row.as_ref().and_then(|r| r.limits.t_c1_hours)),
            hours(s.row.as_ref().and_then(|r| r.limits.t_c2_hours)),
            hours(t),
            opt(phi, 1),
            hours(s.t_c3(hold, CreepCriterionKind::PaperTolerance).0),
            hours(s.t_c3(hold, CreepCriterionKind::Ours).0),
            s.no_release_cell(hold),
            s.letters(hold),
            paper.map_or("–".into(), |(t, p)| format!("{t:.2} h, {p}°")),
            match (t, paper) {
                (Some(t), Some((p, _))) => format!("{:+.2}", t - p),
                _ => "–".into(),
            }
        );
    }
    // the ordering
    let full = in_group(Group::Full);
    let csv = ordering_csv(&full, hold);
    rubblepile::io::safe_write::write_atomic(&out.join("ordering.csv"), &csv)
        .map_err(|e| format!("{}: {e}", out.join("ordering.csv").display()))?;
    let _ = writeln!(
        md,
        "\n### The packing ordering at the paper's grain counts (`ordering.csv`)\n"
    );
    let diff = ordering_difference(&full, hold);
    let _ = writeln!(
        md,
        "RCP − HCP = **{}** (RCP's T_c3 less the mean over the HCP lattice orientations searched at full size; the \
         paper's Table 3: +0.43 h).\n",
        diff.map_or("– (a full-size search without T_c3)".into(), |d| format!("{d:+.2} h"))
    );
    let _ = writeln!(md, "```\n{}```\n", csv);
    // orientation
    let orient = in_group(Group::Orientation);
    if !orient.is_empty() {
        let _ = writeln!(md, "### T_c,3 against the HCP lattice's orientation (scaled)\n");
        let _ = writeln!(
            md,
            "| lattice | stacking axis from the spin axis (°) | grains | T_c1 / T_c2 (h) | T_c3 (h) | φ (°) | no release \
             from (h), at the longest length | holds |"
        );
        let _ = writeln!(md, "| --- | --- | --- | --- | --- | --- | --- | --- |");
        let mut random = Vec::new();
        let mut all = Vec::new();
        for s in &orient {
            let (t, phi) = s.t_c3(hold, CreepCriterionKind::Paper);
            if let Some(t) = t {
                all.push(t);
                if s.orientation().starts_with("random") {
                    random.push(t);
                }
            }
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} / {} | {} | {} | {} | {} |",
                s.orientation(),
                s.target
                    .as_ref()
                    .and_then(|t| t.lattice_tilt_deg)
                    .map_or("–".into(), |d| format!("{d:.1}")),
                s.grains().map_or("–".into(), |n| n.to_string()),
                hours(s.row.as_ref().and_then(|r| r.limits.t_c1_hours)),
                hours(s.row.as_ref().and_then(|r| r.limits.t_c2_hours)),
                hours(t),
                opt(phi, 1),
                s.lengths()
                    .last()
                    .map_or("–".into(), |&l| format!("{} ({l:.0} s)", s.no_release_cell(l))),
                s.letters(hold)
            );
        }
        let stat = |v: &[f64]| {
            mean_and_sd(v).map_or("–".into(), |(m, sd)| {
                let (lo, hi) = (
                    v.iter().cloned().fold(f64::INFINITY, f64::min),
                    v.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
                );
                format!("{m:.3} ± {sd:.3} h (n = {}, range {lo:.2}–{hi:.2} h)", v.len())
            })
        };
        let _ = writeln!(
            md,
            "\nT_c3 over the random orientations: {}; over all orientations: {}.\n",
            stat(&random),
            stat(&all)
        );
    }
    // hold length
    let _ = writeln!(md, "### Hold length\n");
    let _ = writeln!(
        md,
        "T_c3 (paper's criterion) of every search whose holds are long enough, each hold read over its first L \
         seconds (`spinup critical --judge-window-s`): T_c3 stops moving at **{hold:.0} s**.\n"
    );
    let _ = writeln!(
        md,
        "| search | {} |",
        HOLD_LENGTHS.map(|l| format!("L = {l:.0} s")).join(" | ")
    );
    let _ = writeln!(md, "| --- |{}", " --- |".repeat(HOLD_LENGTHS.len()));
    let mut series = Vec::new();
    for (k, s) in searches.iter().filter(|s| s.lengths().len() >= 2).enumerate() {
        let lengths = s.lengths();
        let cells: Vec<String> = HOLD_LENGTHS
            .iter()
            .map(|&l| {
                if lengths.contains(&l) {
                    let (t, phi) = s.t_c3(l, CreepCriterionKind::Paper);
                    format!("{}, {}° ({})", hours(t), opt(phi, 1), s.letters(l))
                } else {
                    "–".into()
                }
            })
            .collect();
        let _ = writeln!(md, "| {} | {} |", s.name, cells.join(" | "));
        series.push(Series {
            label: s.name.clone(),
            errors: vec![],
            points: lengths
                .iter()
                .filter_map(|&l| s.t_c3(l, CreepCriterionKind::Paper).0.map(|t| (l, t)))
                .collect(),
            colour: k,
            mark: Mark::Points,
        });
    }
    // a search with no T_c3 at any length has no point to draw
    series.retain(|s| !s.points.is_empty());
    if series.is_empty() {
        let _ = writeln!(
            md,
            "\nNo search has a T_c3 by the paper's criterion at any hold length yet: no figure.\n"
        );
    } else {
        let chart = LineChart {
            title: "T_c3 against the hold length (paper's criterion)".into(),
            x_label: "hold length read (s)".into(),
            y_label: "T_c3 (h)".into(),
            series,
            log_x: false,
        };
        write_figure(out, "decided_hold_length", &chart).map_err(|e| e.to_string())?;
        let _ = writeln!(md, "\n![T_c3 against the hold length](decided_hold_length.png)\n");
    }
    write_zero_rates(md, &searches);
    // the equilibrium bound on HCP's φ
    let body = naidu_ellipsoid();
    let sphere = [0.5 * NAIDU2020_EQUIVALENT_DIAMETER_M; 3];
    let bound = |axes: [f64; 3], rho: f64, t_h: f64| {
        least_friction_angle(axes, rho, t_h * 3600.0).map_or("> 90° (tensile)".into(), |p| format!("{p:.1}°"))
    };
    let _ = writeln!(
        md,
        "\n### The equilibrium bound on φ (Holsapple 2001; `studies/zhang2017/spin_limit.rs`)\n"
    );
    let _ = writeln!(
        md,
        "Averaged over the whole body, a cohesionless pile holds its spin only with a friction angle at least the \
         bound below; the largest angle mobilised in an RVE, φ, cannot be lower. The Naidu ellipsoid has the \
         radar body's axis ratios and volume ({:.1} × {:.1} × {:.1} m semi-axes).\n",
        body[0], body[1], body[2]
    );
    let _ = writeln!(
        md,
        "| case | ρ_B (kg/m³) | T (h) | bound, sphere | bound, Naidu ellipsoid | φ |"
    );
    let _ = writeln!(md, "| --- | --- | --- | --- | --- | --- |");
    for (model, t, phi) in [("hcp", 2.40, 43.0), ("rcp", 2.83, 30.0)] {
        let _ = writeln!(
            md,
            "| paper's {} | 2100 | {t:.2} | {} | {} | {phi}° |",
            model.to_uppercase(),
            bound(sphere, 2100.0, t),
            bound(body, 2100.0, t)
        );
    }
    for s in &full {
        if let (Some(t), phi) = s.t_c3(hold, CreepCriterionKind::Paper) {
            let _ = writeln!(
                md,
                "| ours: {} | {rho:.1} | {t:.2} | {} | {} | {}° |",
                s.name,
                bound(sphere, rho, t),
                bound(body, rho, t),
                opt(phi, 1)
            );
        }
    }
    write_fig23(md, &searches, hold, rho, out)?;
    write_slopes(md, rho, out)?;
    Ok(())
}

/// Zhang17 Fig. 2's analogue: the surface slopes of the decided shape (and of the top of the earlier runs)
/// as homogeneous bodies of the decided density spinning at the Didymos period ([`super::surface_slopes`]);
/// writes `decided_slopes.{svg,png}` (slope against latitude, every longitude).
fn write_slopes(md: &mut String, rho: f64, out: &Path) -> Result<(), String> {
    use super::surface_slopes::slope_map;
    use rubblepile::aggregate::shape::Shape;
    let _ = writeln!(md, "\n### Fig. 2: surface slopes at the Didymos period\n");
    let _ = writeln!(
        md,
        "The angle between the inward normal and self-gravity plus the centrifugal pull, at 2.26 h and {rho:.1} \
         kg/m³, on a grid of 24 latitudes × 48 longitudes (gravity of the homogeneous body from 80³ cells; a degree \
         or so of error). The paper maps the radar model (its Fig. 2) and finds slopes above 50° in places; ours are \
         analytic shapes with the radar model's extents, without its small-scale relief.\n"
    );
    let _ = writeln!(
        md,
        "| shape | largest slope (°) | mean (°) | surface above 30° / 40° / 50° |"
    );
    let _ = writeln!(md, "| --- | --- | --- | --- |");
    let mut series = Vec::new();
    for (k, (label, spec)) in [
        ("didymos (Naidu et al. 2020)", "didymos"),
        ("top (before Dec 2026)", "top"),
    ]
    .into_iter()
    .enumerate()
    {
        let shape = Shape::parse(spec, 1.0).map_err(|e| e.to_string())?;
        let contains = |p: &rubblepile::math::Vec3| shape.contains(p);
        let map = slope_map(
            &contains,
            1.02 * shape.bounding_radius(),
            shape.volume(),
            rho,
            super::rows::DIDYMOS_PERIOD_HOURS * 3600.0,
            24,
            40,
        );
        // area weights: the grid is uniform in latitude, so a cell's area goes with cos(latitude)
        let weight = |lat: f64| lat.to_radians().cos();
        let total: f64 = map.iter().map(|s| weight(s.lat_deg)).sum();
        let above = |a: f64| {
            100.0
                * map
                    .iter()
                    .filter(|s| s.slope_deg > a)
                    .map(|s| weight(s.lat_deg))
                    .sum::<f64>()
                / total
        };
        let mean = map.iter().map(|s| s.slope_deg * weight(s.lat_deg)).sum::<f64>() / total;
        let largest = map.iter().map(|s| s.slope_deg).fold(0.0, f64::max);
        let _ = writeln!(
            md,
            "| {label} | {largest:.1} | {mean:.1} | {:.1} % / {:.1} % / {:.1} % |",
            above(30.0),
            above(40.0),
            above(50.0)
        );
        series.push(Series {
            label: label.into(),
            errors: vec![],
            points: map.iter().map(|s| (s.lat_deg, s.slope_deg)).collect(),
            colour: k,
            mark: Mark::Points,
        });
    }
    let chart = LineChart {
        title: "Fig. 2 analogue: surface slope against latitude at 2.26 h".into(),
        x_label: "latitude (deg)".into(),
        y_label: "slope (deg)".into(),
        series,
        log_x: false,
    };
    write_figure(out, "decided_slopes", &chart).map_err(|e| e.to_string())?;
    let _ = writeln!(md, "\n![Fig. 2 analogue](decided_slopes.png)\n");
    Ok(())
}

/// κ of Eq. 22 of a T_c,3 (h) at bulk density `rho` (kg/m³).
pub fn kappa_of(t_c3_hours: f64, rho: f64) -> f64 {
    omega_of_hours(t_c3_hours) / (4.0 * std::f64::consts::PI * SI_G * rho / 3.0).sqrt()
}

/// Zhang17 Fig. 23's analogue: κ₃ against φ, the paper's six models and ours (decided protocol) beside the continuum
/// upper spin limit (the volume-averaged bound of [`super::spin_limit`]) of a sphere and of the Naidu
/// ellipsoid; a table says which points lie above the limit. Writes `decided_fig23.{svg,png}`.
fn write_fig23(md: &mut String, searches: &[DecidedSearch], hold: f64, rho: f64, out: &Path) -> Result<(), String> {
    let body = naidu_ellipsoid();
    let _ = writeln!(md, "\n### Fig. 23: κ₃ against φ beside the continuum upper limit\n");
    let _ = writeln!(
        md,
        "κ₃ = Ω_c3 / √(4πGρ_B/3) (Eq. 22; the paper's from its T_c3 at 2100 kg/m³, ours at {rho:.1} kg/m³). The upper \
         limit is the κ at which the volume-averaged stress needs exactly φ (Holsapple 2001; a point above it holds \
         a spin no homogeneous continuum of that φ can). The local lower limit of Hirabayashi (2015) is not drawn.\n"
    );
    let _ = writeln!(
        md,
        "| model | φ (°) | κ₃ | upper limit at φ: sphere / Naidu ellipsoid | above the limit? |"
    );
    let _ = writeln!(md, "| --- | --- | --- | --- | --- |");
    let mut points: Vec<(String, f64, f64)> = TABLE3
        .iter()
        .map(|p| (format!("paper {}", p.0.to_uppercase()), p.2, kappa_of(p.5, 2100.0)))
        .collect();
    for s in searches
        .iter()
        .filter(|s| matches!(s.group, Group::Full | Group::Scaled))
    {
        if let (Some(t), Some(phi)) = s.t_c3(hold, CreepCriterionKind::Paper) {
            points.push((format!("ours {}", s.name), phi, kappa_of(t, rho)));
        }
    }
    for (label, phi, kappa) in &points {
        let (sphere, ell) = (critical_kappa([1.0; 3], *phi), critical_kappa(body, *phi));
        let _ = writeln!(
            md,
            "| {label} | {phi:.1} | {kappa:.3} | {sphere:.3} / {ell:.3} | {} |",
            if *kappa > ell.max(sphere) {
                "above"
            } else if *kappa < ell.min(sphere) {
                "below"
            } else {
                "between the two shapes' limits"
            }
        );
    }
    let curve = |axes: [f64; 3]| -> Vec<(f64, f64)> {
        (10..=80)
            .step_by(2)
            .map(|d| (d as f64, critical_kappa(axes, d as f64)))
            .collect()
    };
    let mut series = vec![
        Series {
            label: "upper limit, sphere".into(),
            errors: vec![],
            points: curve([1.0; 3]),
            colour: 0,
            mark: Mark::Dashed,
        },
        Series {
            label: "upper limit, Naidu ellipsoid".into(),
            errors: vec![],
            points: curve(body),
            colour: 1,
            mark: Mark::Dashed,
        },
    ];
    for (k, (label, phi, kappa)) in points.iter().enumerate() {
        series.push(Series {
            label: label.clone(),
            errors: vec![],
            points: vec![(*phi, *kappa)],
            colour: 2 + k,
            mark: Mark::Points,
        });
    }
    let chart = LineChart {
        title: "Fig. 23 analogue: kappa_3 against the friction angle".into(),
        x_label: "phi (deg)".into(),
        y_label: "kappa_3".into(),
        series,
        log_x: false,
    };
    write_figure(out, "decided_fig23", &chart).map_err(|e| e.to_string())?;
    let _ = writeln!(md, "\n![Fig. 23 analogue](decided_fig23.png)\n");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn series(release: Option<f64>, loss_after: f64, len: f64) -> HoldSeries {
        let n = (len / 200.0) as usize + 1;
        let t: Vec<f64> = (0..n).map(|k| 200.0 * k as f64).collect();
        HoldSeries {
            coordination: t
                .iter()
                .map(|&x| {
                    if x <= loss_after {
                        5.5
                    } else {
                        5.5 - 1e-5 * (x - loss_after)
                    }
                })
                .collect(),
            theta_max_deg: vec![30.0; n],
            packing: vec![0.65; n],
            release_s: release,
            t_s: t,
        }
    }

    fn search(name: &str, holds: Vec<(f64, HoldSeries)>) -> DecidedSearch {
        let verdicts = holds
            .iter()
            .map(|(tf, s)| {
                rubblepile::analysis::critical::judge_series(
                    s,
                    None,
                    &Criteria::default(),
                    CreepCriterionKind::Paper,
                    *tf,
                    PathBuf::new(),
                )
            })
            .collect();
        DecidedSearch {
            group: Group::Full,
            name: name.into(),
            model: name.split('_').next().unwrap().into(),
            row: None,
            target: None,
            verdicts,
            series: holds,
        }
    }

    /// The hold length is decided where T_c,3 stops moving: a hold at 2.60 h that starts losing contacts after
    /// 20 000 s is stable read over 16 000 s and creeps over 32 000 and 50 000 s, so RCP's T_c,3 moves from 2.60 to
    /// 2.65 h between 16 000 and 32 000 s and no further: 32 000 s. `ordering.csv` has one row per search and the
    /// difference row.
    #[test]
    fn hold_length_is_where_t_c3_stops_moving_and_ordering_csv_has_the_difference() {
        let rcp = search(
            "rcp_full",
            vec![
                (2.55, series(Some(3000.0), f64::INFINITY, 6000.0)),
                (2.60, series(None, 20_000.0, 50_000.0)),
                (2.65, series(None, f64::INFINITY, 50_000.0)),
                (2.70, series(None, f64::INFINITY, 50_000.0)),
            ],
        );
        assert_eq!(rcp.lengths(), HOLD_LENGTHS.to_vec());
        assert_eq!(rcp.t_c3(16_000.0, CreepCriterionKind::Paper).0, Some(2.60));
        assert_eq!(rcp.t_c3(32_000.0, CreepCriterionKind::Paper).0, Some(2.65));
        assert_eq!(rcp.t_c3(50_000.0, CreepCriterionKind::Paper).0, Some(2.65));
        let hcp = search(
            "hcp_full",
            vec![
                (2.40, series(Some(1000.0), f64::INFINITY, 2000.0)),
                (2.45, series(None, f64::INFINITY, 32_000.0)),
                (2.50, series(None, f64::INFINITY, 32_000.0)),
            ],
        );
        assert_eq!(hcp.lengths(), vec![16_000.0, 32_000.0]);
        let both = [rcp, hcp];
        assert_eq!(decided_hold_length(&both), 32_000.0);
        let full: Vec<&DecidedSearch> = both.iter().collect();
        let csv = ordering_csv(&full, 32_000.0);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines[0], "model,grains,orientation,criterion,hold_s,T_c3_h,phi_deg");
        assert_eq!(lines[1], "RCP,,–,paper,32000,2.65,30.0");
        // no target report copied: an HCP from before orientations were recorded, stacked along the spin axis
        assert_eq!(lines[2], "HCP,,perpendicular,paper,32000,2.45,30.0");
        assert_eq!(lines[3], "RCP-HCP,,,paper,32000,0.20,");
    }

    /// A decided directory whose long searches have no T_c3 by the paper's criterion at any hold length (every hold
    /// creeps) still gives its section: the hold-length table without a figure, not the error "nothing to plot".
    #[test]
    fn hold_length_section_without_any_t_c3_is_written_without_a_figure() {
        let dir = std::env::temp_dir().join(format!("rubblepile-decided-no-tc3-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let critical = dir.join("orientation/hcp_3k_random1/critical");
        std::fs::create_dir_all(&critical).unwrap();
        let creeping = search(
            "hcp_3k_random1",
            vec![
                (2.50, series(None, 1000.0, 32_000.0)),
                (2.55, series(None, 1000.0, 32_000.0)),
            ],
        );
        assert_eq!(creeping.t_c3(16_000.0, CreepCriterionKind::Paper).0, None);
        let mut holds = String::from("t_final_h,t_hold_s,packing_fraction,coordination_number,theta_max_deg\n");
        for (tf, h) in &creeping.series {
            for k in 0..h.t_s.len() {
                holds += &format!(
                    "{tf},{},{},{},{}\n",
                    h.t_s[k], h.packing[k], h.coordination[k], h.theta_max_deg[k]
                );
            }
        }
        std::fs::write(critical.join("holds.csv"), holds).unwrap();
        std::fs::write(
            critical.join("critical.csv"),
            rubblepile::analysis::critical::critical_csv(&creeping.verdicts),
        )
        .unwrap();
        let out = dir.join("out");
        std::fs::create_dir_all(&out).unwrap();
        let mut md = String::new();
        write_decided_section(&mut md, &dir, &out).unwrap();
        assert!(
            md.contains("No search has a T_c3 by the paper's criterion at any hold length yet"),
            "{md}"
        );
        assert!(!out.join("decided_hold_length.png").exists());
        // two held holds are too few for the rates' zero
        assert!(md.contains("| hcp_3k_random1 | 32000 | 2 | – | – | – | – |"), "{md}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Regression guard: a hold copied while still running, recorded for less than the hold length read, has no
    /// verdict there (read over its short record it would pass for stable and give a T_c,3), and the holds list
    /// shows it as `…`.
    #[test]
    fn a_hold_still_running_is_not_judged_at_a_longer_length() {
        let s = search(
            "hcp_3k_random3",
            vec![
                (2.35, series(Some(3000.0), f64::INFINITY, 6000.0)),
                (2.45, series(None, 1000.0, 50_000.0)),
                (2.50, series(None, f64::INFINITY, 10_208.0)),
            ],
        );
        assert_eq!(s.t_c3(16_000.0, CreepCriterionKind::Paper).0, None);
        assert_eq!(s.judged(16_000.0).len(), 2);
        assert_eq!(s.letters(16_000.0), "R 2.35, C 2.45, … 2.50");
        // read at a length it has reached, it is judged (stable: it never creeps)
        assert_eq!(s.t_c3(8000.0, CreepCriterionKind::Paper).0, Some(2.50));
    }

    /// The failure stops at the slowest released hold's successor, whatever the creep verdicts: a hold released
    /// after 20 000 s counts at 32 000 s and not at 16 000 s; a search whose slowest hold is released has none.
    #[test]
    fn no_release_from_is_the_hold_after_the_slowest_released_one() {
        let s = search(
            "hcp_3k_perpendicular",
            vec![
                (2.45, series(Some(3000.0), f64::INFINITY, 6000.0)),
                (2.50, series(Some(20_000.0), f64::INFINITY, 22_000.0)),
                (2.55, series(None, 1000.0, 32_000.0)),
                (2.60, series(None, 1000.0, 32_000.0)),
            ],
        );
        assert_eq!(s.no_release_from(16_000.0), Some(2.50));
        assert_eq!(s.no_release_from(32_000.0), Some(2.55));
        assert_eq!(
            s.t_c3(32_000.0, CreepCriterionKind::Paper).0,
            None,
            "every held hold creeps"
        );
        assert_eq!(s.no_release_cell(32_000.0), "2.55");
        let all_released = search("hcp_x", vec![(2.45, series(Some(3000.0), f64::INFINITY, 6000.0))]);
        assert_eq!(all_released.no_release_from(16_000.0), None);
        assert_eq!(all_released.no_release_cell(16_000.0), "–");
        let none_released = search("hcp_y", vec![(2.45, series(None, 1000.0, 32_000.0))]);
        assert_eq!(
            none_released.no_release_cell(16_000.0),
            "≤ 2.45",
            "failure stops at or before the fastest"
        );
    }

    /// The Naidu ellipsoid keeps the radar extents' ratios and the 780 m body's volume.
    #[test]
    fn naidu_ellipsoid_has_the_volume_of_d_eq_780() {
        let [a, b, c] = naidu_ellipsoid();
        assert!(((a * b * c).cbrt() - 390.0).abs() < 1e-9);
        assert!((b / a - 838.0 / 832.0).abs() < 1e-12 && (c / a - 786.0 / 832.0).abs() < 1e-12);
    }
}
