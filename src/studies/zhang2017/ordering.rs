//! Does the paper's packing ordering of T_c,3 (Zhang17 Table 3: HCP strongest at 2.40 h, RCP weakest at 2.83 h)
//! depend on the contact law? The HCP and RCP models' T_c,3 searches with the twisting and rolling resistance of
//! Zhang17 Eqs. 11–12 changed: the measured reason the ordering is or is not reproduced.
//!
//! Layout read: `ORDERING/<model>_<variant>/critical*/critical.csv` (compact copies of `rubblepile spinup critical`
//! directories: a coarse search and, where it bracketed T_c,3, a finer one), `<variant>` one of [`VARIANTS`]; the
//! nominal material's searches are the Table 3 ones, `RUNS/<model>/critical`. The holds of all of a variant's
//! searches are judged together ([`union_search`]: every hold branches off the same path, so a fine search only adds
//! holds). A variant that found no stable hold is shown as "> its slowest hold".

use std::fmt::Write as _;
use std::path::Path;

use rubblepile::analysis::creep::CreepCriterionKind;
use rubblepile::analysis::critical::{HoldVerdict, critical_from_verdicts, read_critical_csv};

use super::ladder::RungSearch;
use super::rows::{TABLE3, opt, search_subdirs};

/// The contact-law variants, strongest rolling and twisting resistance first: directory suffix and what changes
/// against Zhang17 §2.3.3's nominal material (β = 0.5, μ_T = 1.3, μ_R = 1.05) and our k_N (`kn5`: the stiffness
/// check of item 4, scenes `<model>_path2_kn5.toml`).
pub const VARIANTS: [(&str, &str); 5] = [
    ("caps_x2", "twisting and rolling caps × 2 (μ_T 2.6, μ_R 2.1)"),
    ("nominal", "Zhang17 Eqs. 11–12 as written (β 0.5, μ_T 1.3, μ_R 1.05)"),
    ("kn5", "as written, k_N × 5 and dt / √5 (overlaps ≲ 1 %)"),
    ("caps_half", "twisting and rolling caps × ½ (μ_T 0.65, μ_R 0.525)"),
    ("beta0", "β = 0: no twisting or rolling resistance"),
];

/// The two models whose order the paper's Table 3 sets apart most (T_c,3 2.40 h and 2.83 h).
pub const MODELS: [&str; 2] = ["hcp", "rcp"];

/// All holds of one model under one variant, judged together ([`union_search`]).
#[derive(Debug, Clone)]
pub struct VariantSearch {
    /// T_c,3 and φ by both criteria, the finest step and the number of holds.
    pub search: RungSearch,
    /// The slowest hold (h).
    pub slowest_hours: f64,
    /// The shortest period above every released hold (h): where the pile stops failing, whatever either creep
    /// criterion says of the holds (a θ_max that keeps falling by more than 0.5° over a slow hold's second half
    /// makes ours reject it, a loss of contacts the paper's, and the trailing-run rule then every faster hold too).
    pub after_release_hours: Option<f64>,
    /// θ_max (°) of that hold: the friction angle mobilized where the pile stops failing.
    pub after_release_theta_deg: Option<f64>,
    /// Whether any hold was released: without one, `after_release_hours` is only an upper bound.
    pub bracketed: bool,
    /// The holds by our criterion, fastest first: `R` released, `S` stable, `C` creeping, with the periods.
    pub holds: String,
}

/// One variant's searches: per model of [`MODELS`], the search if it was run.
#[derive(Debug, Clone)]
pub struct VariantRow {
    /// What the variant changes.
    pub what: &'static str,
    /// The HCP and RCP searches, in [`MODELS`] order.
    pub searches: [Option<VariantSearch>; 2],
}

/// T_c,3 as a cell: the value and φ, or "> slowest hold" when no hold was stable.
fn cell(s: &Option<VariantSearch>, paper_criterion: bool) -> String {
    match s {
        None => "not run".into(),
        Some(v) => {
            let (t, phi) = if paper_criterion { v.search.paper } else { v.search.ours };
            match t {
                Some(t) => format!("{t:.2} h, {}°", opt(phi, 1)),
                None => format!("> {:.2} h", v.slowest_hours),
            }
        }
    }
}

/// RCP's minus HCP's shortest period above their last released hold (h), when both have one and both
/// searches reached a released hold (else it is only a bound): positive is the paper's order.
pub fn rcp_minus_hcp(row: &VariantRow) -> Option<f64> {
    let t = |k: usize| {
        row.searches[k]
            .as_ref()
            .filter(|v| v.bracketed)
            .and_then(|v| v.after_release_hours)
    };
    Some(t(1)? - t(0)?)
}

/// Reads the variants' searches: nominal from `runs/<model>/critical`, the others from `ordering/<model>_<variant>`.
pub fn read_variants(runs: &Path, ordering: &Path) -> Vec<VariantRow> {
    VARIANTS
        .iter()
        .map(|&(variant, what)| {
            let dir = |model: &str| {
                if variant == "nominal" {
                    runs.join(model).join("critical")
                } else {
                    ordering.join(format!("{model}_{variant}"))
                }
            };
            VariantRow {
                what,
                searches: MODELS.map(|m| union_search(&dir(m))),
            }
        })
        .collect()
}

/// The search directories of a variant: its `critical*` subdirectories, or `dir` itself when it has none.
pub fn search_dirs(dir: &Path) -> Vec<std::path::PathBuf> {
    let subs = search_subdirs(dir);
    if subs.is_empty() { vec![dir.to_path_buf()] } else { subs }
}

/// All holds of the searches under `dir` ([`search_dirs`]) judged together: by increasing T_final, a hold run twice
/// kept once (the later search's); T_c,3 and φ by both criteria from [`critical_from_verdicts`]. `None` without
/// any readable `critical.csv`.
pub fn union_search(dir: &Path) -> Option<VariantSearch> {
    let mut holds: Vec<HoldVerdict> = Vec::new();
    for d in search_dirs(dir) {
        let Ok(text) = std::fs::read_to_string(d.join("critical.csv")) else {
            continue;
        };
        for h in read_critical_csv(&text).ok()? {
            holds.retain(|k| (k.t_final_hours - h.t_final_hours).abs() > 1e-9);
            holds.push(h);
        }
    }
    holds.sort_by(|a, b| a.t_final_hours.total_cmp(&b.t_final_hours));
    let slowest_hours = holds.last()?.t_final_hours;
    let step_hours = holds
        .windows(2)
        .map(|w| w[1].t_final_hours - w[0].t_final_hours)
        .fold(f64::INFINITY, f64::min);
    let last_release = holds.iter().rposition(|h| h.released).map_or(0, |k| k + 1);
    let after_release_hours = holds.get(last_release).map(|h| h.t_final_hours);
    let after_release_theta_deg = holds.get(last_release).map(|h| h.theta_max_deg);
    let letter = |h: &HoldVerdict| match (h.released, h.ours.stable) {
        (true, _) => 'R',
        (false, true) => 'S',
        (false, false) => 'C',
    };
    let summary = holds
        .iter()
        .map(|h| format!("{} {:.2}", letter(h), h.t_final_hours))
        .collect::<Vec<_>>()
        .join(", ");
    Some(VariantSearch {
        search: RungSearch {
            name: dir.file_name()?.to_string_lossy().into_owned(),
            step_hours,
            paper: critical_from_verdicts(&holds, CreepCriterionKind::PaperTolerance),
            ours: critical_from_verdicts(&holds, CreepCriterionKind::Ours),
            holds: holds.len(),
        },
        slowest_hours,
        after_release_hours,
        after_release_theta_deg,
        bracketed: holds.iter().any(|h| h.released),
        holds: summary,
    })
}

/// Writes the "Packing ordering and the contact law" section.
pub fn write_ordering_section(md: &mut String, runs: &Path, ordering: &Path) {
    let rows = read_variants(runs, ordering);
    let paper = |m: &str| TABLE3.iter().find(|p| p.0 == m).map(|p| (p.5, p.2));
    let _ = writeln!(md, "\n## Packing ordering and the contact law\n");
    let _ = writeln!(
        md,
        "Zhang17 Table 3 orders the models by strength, HCP strongest (T_c3 2.40 h) and RCP weakest (2.83 h). The \
         scaled HCP (3033 grains) and RCP (2083 grains) searched with the twisting and rolling resistance of Eqs. \
         11–12 changed, everything else as in Table 3 above (searches under `{}`, the nominal ones under `{}`; \
         holds of 16 000 s branched off one path-2 run each). T_c3 by our creep criterion (θ_max and η_B) and by \
         the paper's with tolerances (`paper-tolerance`, also the coordination number), each where the trailing run of stable holds begins; \"> X\" \
         when the slowest hold, X h, is not stable. 'Stops failing' is the shortest period held above every \
         released hold, whatever the creep criteria say (they differ from it where slow holds relax, θ_max falling \
         by more than 0.5°, or lose contacts); '≤' when no hold was released. Holds: R released, S stable, C creeping, by ours. The last column is RCP's 'stops failing' minus \
         HCP's: positive is the paper's order.\n",
        ordering.display(),
        runs.display()
    );
    let _ = writeln!(
        md,
        "| contact law | HCP: ours | HCP: paper-tolerance | HCP: stops failing | HCP holds | RCP: ours | RCP: paper-tolerance | RCP: stops failing | RCP holds | RCP − HCP (h) |"
    );
    let _ = writeln!(md, "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    let stops = |s: &Option<VariantSearch>| {
        s.as_ref()
            .and_then(|v| v.after_release_hours.map(|t| (t, v.bracketed)))
            .map_or("–".into(), |(t, b)| format!("{}{t:.2} h", if b { "" } else { "≤ " }))
    };
    let holds = |s: &Option<VariantSearch>| s.as_ref().map_or("–".into(), |v| v.holds.clone());
    for r in &rows {
        if r.searches.iter().all(Option::is_none) {
            continue;
        }
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.what,
            cell(&r.searches[0], false),
            cell(&r.searches[0], true),
            stops(&r.searches[0]),
            holds(&r.searches[0]),
            cell(&r.searches[1], false),
            cell(&r.searches[1], true),
            stops(&r.searches[1]),
            holds(&r.searches[1]),
            rcp_minus_hcp(r).map_or("–".into(), |d| format!("{d:+.2}")),
        );
    }
    if let (Some(h), Some(c)) = (paper("hcp"), paper("rcp")) {
        let _ = writeln!(
            md,
            "| paper (Table 3, full size) | {:.2} h, {:.0}° | | | | {:.2} h, {:.0}° | | | | {:+.2} |",
            h.0,
            h.1,
            c.0,
            c.1,
            c.0 - h.0
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn search(ours: Option<f64>) -> Option<VariantSearch> {
        Some(VariantSearch {
            search: RungSearch {
                name: "critical".into(),
                step_hours: 0.05,
                paper: (None, None),
                ours: (ours, Some(45.0)),
                holds: 5,
            },
            slowest_hours: 2.9,
            after_release_hours: ours,
            after_release_theta_deg: Some(45.0),
            bracketed: true,
            holds: String::new(),
        })
    }

    #[test]
    fn the_ordering_is_rcp_minus_hcp_and_needs_both() {
        let row = |h, r| VariantRow {
            what: "",
            searches: [search(h), search(r)],
        };
        assert_eq!(
            rcp_minus_hcp(&row(Some(2.40), Some(2.83))).map(|d| (d * 100.0).round()),
            Some(43.0)
        );
        assert!(rcp_minus_hcp(&row(Some(2.64), Some(2.60))).unwrap() < 0.0);
        assert_eq!(rcp_minus_hcp(&row(None, Some(2.6))), None);
        assert_eq!(cell(&search(None), false), "> 2.90 h");
        assert_eq!(cell(&search(Some(2.6)), false), "2.60 h, 45.0°");
        assert_eq!(cell(&search(Some(2.6)), true), "> 2.90 h");
        assert_eq!(cell(&None, true), "not run");
        // an unbracketed search is only a bound: no difference
        let mut r = row(Some(2.40), Some(2.83));
        r.searches[0].as_mut().unwrap().bracketed = false;
        assert_eq!(rcp_minus_hcp(&r), None);
    }
}
