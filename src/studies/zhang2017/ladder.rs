//! The resolution ladder: one model's path-2 run and T_c,3 search at several grain counts, the same
//! body and material with lengths scaled by the grain radius (`analysis/zhang2017/ladder/README.md`), against
//! the paper's value at its own count (Zhang17 Tables 2 and 3: RCP, 36 523 grains of ≈ 10 m; HCP, 42 062). Does
//! the packing dependence of T_c,3 appear as N grows? Rungs of several models (`rcp_8k`, `hcp_full`) share one
//! ladder directory; a rung's model is its name up to the first `_`.
//!
//! Each rung is a directory `<rung>/path2` (a run, or its compact copy: `spinup.csv`, `timeseries.csv`,
//! `summary.json`, `scene.toml`, `particles.json`) with zero or more searches `<rung>/critical*/critical.json`.
//! Of several searches the one with the finest step of T_final that found a T_c,3 is used (a coarse search
//! brackets, a fine one refines).

use std::fmt::Write as _;
use std::path::Path;

use rubblepile::analysis::critical::read_critical;
use rubblepile::analysis::figures::lines::{LineChart, Mark, Series};
use rubblepile::analysis::figures::style::write_figure;

use super::rows::{
    ModelRow, PaperRow, TABLE3, base_model, flagged, mode, model_dirs, model_row, opt, search_subdirs, warn_settling,
};

/// The search of a rung: its T_c,3 (h) and φ (°) by the paper-tolerance criterion and by ours, its step of T_final (h),
/// and its directory name.
#[derive(Debug, Clone, PartialEq)]
pub struct RungSearch {
    /// Directory name under the rung (`critical`, `critical_fine`, …).
    pub name: String,
    /// Smallest difference between two holds' T_final (h).
    pub step_hours: f64,
    /// T_c,3 (h) and φ (°) by the paper's criterion with tolerances (`paper-tolerance`).
    pub paper: (Option<f64>, Option<f64>),
    /// T_c,3 (h) and φ (°) by ours.
    pub ours: (Option<f64>, Option<f64>),
    /// Number of holds run.
    pub holds: usize,
}

/// Reads one search of `rubblepile spinup critical` ([`read_critical`]: its `critical.json` or `critical.csv`);
/// `None` if neither is there or readable.
pub fn read_search(dir: &Path) -> Option<RungSearch> {
    let v = read_critical(dir)?;
    let mut t: Vec<f64> = v["runs"]
        .as_array()?
        .iter()
        .filter_map(|r| r["t_final_hours"].as_f64())
        .collect();
    t.sort_by(f64::total_cmp);
    let step_hours = t.windows(2).map(|w| w[1] - w[0]).fold(f64::INFINITY, f64::min);
    let pair = |c: &serde_json::Value| (c["t_c3_hours"].as_f64(), c["friction_angle_deg"].as_f64());
    let top = pair(&v);
    Some(RungSearch {
        name: dir.file_name()?.to_string_lossy().into_owned(),
        step_hours,
        paper: if v["paper_tolerance"].is_object() {
            pair(&v["paper_tolerance"])
        } else {
            top
        },
        ours: if v["ours"].is_object() { pair(&v["ours"]) } else { top },
        holds: t.len(),
    })
}

/// The search a rung's row shows: of those that found a T_c,3 by the paper-tolerance criterion the finest; else the
/// finest of all.
pub fn chosen_search(searches: &[RungSearch]) -> Option<&RungSearch> {
    let by_step = |a: &&RungSearch, b: &&RungSearch| a.step_hours.total_cmp(&b.step_hours);
    searches
        .iter()
        .filter(|s| s.paper.0.is_some())
        .min_by(by_step)
        .or_else(|| searches.iter().min_by(by_step))
}

/// Zhang17 Table 2's grain counts of the models a ladder climbs: the rung the paper ran.
pub const PAPER_GRAINS: [(&str, usize); 2] = [("hcp", 42_062), ("rcp", 36_523)];

/// The model a rung belongs to: its directory name up to the first `_` (`rcp_8k` → `rcp`, `hcp_full` → `hcp`).
pub fn rung_model(rung: &str) -> String {
    base_model(rung).split('_').next().unwrap_or("").to_lowercase()
}

/// A rung: its model, its path-2 row and its searches.
struct Rung {
    model: String,
    row: ModelRow,
    searches: Vec<RungSearch>,
}

impl Rung {
    fn chosen(&self) -> Option<&RungSearch> {
        chosen_search(&self.searches)
    }
}

/// The rungs under `ladder`, by model and then by grain count.
fn rungs(ladder: &Path) -> Result<Vec<Rung>, String> {
    let mut out = Vec::new();
    for dir in model_dirs(ladder)? {
        let (row, _) = model_row(&dir).map_err(|e| e.to_string())?;
        warn_settling(&row);
        let subdirs = search_subdirs(&dir);
        let searches = subdirs.iter().filter_map(|d| read_search(d)).collect();
        out.push(Rung {
            model: rung_model(&row.model),
            row,
            searches,
        });
    }
    out.sort_by(|a, b| a.model.cmp(&b.model).then(a.row.n.cmp(&b.row.n)));
    Ok(out)
}

fn pair(p: (Option<f64>, Option<f64>)) -> String {
    format!("{} h, {}°", opt(p.0, 2), opt(p.1, 1))
}

/// The paper's row of a model's rungs: Zhang17 Table 3 at the grain count of Table 2.
fn paper_row(model: &str) -> Option<String> {
    let p = TABLE3.iter().find(|p| p.0 == model)?;
    let grains = PAPER_GRAINS
        .iter()
        .find(|g| g.0 == model)
        .map_or("–".to_string(), |g| thousands(g.1));
    Some(format!(
        "| paper ({}) | {grains} | ≈ 10 | {:.3} | {:.2} / {:.2} | | {} | {:.2} h, {:.0}° | | | < 1e-2 | |",
        model.to_uppercase(),
        p.1,
        p.3,
        p.4,
        p.7,
        p.5,
        p.2
    ))
}

/// `42062` → `42 062` (the paper's grain counts as the tables print them).
fn thousands(n: usize) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

/// Writes the "Resolution ladder" section of the rungs under `ladder` (a table per model, closed by the paper's
/// row) and its figures in `out`: `ladder.{svg,png}` (T_c,3 by both criteria against the grain count),
/// `ladder_phi.{svg,png}` (φ) and `ladder_limits.{svg,png}` (T_c,1 and the smoothed T_c,2), each model in its
/// colours with the paper's value (Zhang17 Table 3) as a dashed line.
pub fn write_ladder_section(md: &mut String, ladder: &Path, out: &Path) -> Result<(), String> {
    let rungs = rungs(ladder)?;
    if rungs.is_empty() {
        return Err(format!("{}: no <rung>/path2/spinup.csv found", ladder.display()));
    }
    let _ = writeln!(md, "\n## Resolution ladder\n");
    let _ = writeln!(
        md,
        "Rungs under `{}`: the same body, material and path 2 at several grain counts (lengths scaled with the grain \
         radius). T_c,1/T_c,2 by the rule of Table 3 above (sampled, then smoothed); T_c,3 and φ from the rung's finest \
         search that found one (`critical*/critical.json`), by the paper's criterion with tolerances (`paper-tolerance`) and by ours. The paper's row is \
         Table 3 (path 1; its T_c,3 does not depend on the path, §4.3) at the grain count of its Table 2. In the figures \
         each model has its colours, the paper's value is the dashed line, and the points of our criterion sit 4 % to \
         the right of the rung's grain count so that they do not hide the paper-tolerance criterion's.\n",
        ladder.display()
    );
    let _ = writeln!(
        md,
        "| rung | grains | radius (m) | η_B | T_c1 / T_c2 (h) | smoothed T_c1 / T_c2 (h) | mode | T_c3, φ: paper-tolerance | T_c3, φ: ours | search (step, holds) | largest overlap / r | wall (s) |"
    );
    let _ = writeln!(
        md,
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    let mut models: Vec<String> = rungs.iter().map(|r| r.model.clone()).collect();
    models.dedup();
    for model in &models {
        for r in rungs.iter().filter(|r| &r.model == model) {
            let s = r.chosen();
            let _ = writeln!(
                md,
                "| {} | {} | {:.2} | {:.4} | {} / {} | {} / {} | {} | {} | {} | {} | {:.2e} | {:.0} |",
                r.row.model,
                r.row.n,
                r.row.radius_range.1,
                r.row.packing,
                flagged(&r.row, "T_c1", opt(r.row.limits.t_c1_hours, 3)),
                flagged(&r.row, "T_c2", opt(r.row.limits.t_c2_hours, 3)),
                opt(r.row.limits_smoothed.t_c1_hours, 3),
                opt(r.row.limits_smoothed.t_c2_hours, 3),
                mode(r.row.limits.failure_mode),
                s.map_or("not searched".into(), |s| pair(s.paper)),
                s.map_or("–".into(), |s| pair(s.ours)),
                s.map_or("–".into(), |s| format!(
                    "`{}`: {:.2} h, {}",
                    s.name, s.step_hours, s.holds
                )),
                r.row.max_overlap,
                r.row.wall_seconds,
            );
        }
        if let Some(row) = paper_row(model) {
            let _ = writeln!(md, "{row}");
        }
    }
    let most = rungs
        .iter()
        .map(|r| r.row.n)
        .chain(PAPER_GRAINS.iter().map(|g| g.1))
        .max();
    let n_range = (
        rungs.iter().map(|r| r.row.n).min().unwrap_or(1) as f64 * 0.8,
        most.unwrap_or(1) as f64 * 1.25,
    );
    // one figure per quantity: each model's rungs as points, the paper's value as a dashed line of its colour
    type Of<'a> = &'a dyn Fn(&Rung) -> Option<f64>;
    type Paper = Option<fn(&PaperRow) -> f64>;
    let figure = |name: &str, title: &str, y_label: &str, quantities: &[(&str, Of, Paper)]| {
        let mut series = Vec::new();
        for (m, model) in models.iter().enumerate() {
            let paper = TABLE3.iter().find(|p| p.0 == model);
            for (q, (label, of, paper_value)) in quantities.iter().enumerate() {
                let colour = m * quantities.len() + q;
                let points = rungs
                    .iter()
                    .filter(|r| &r.model == model)
                    // the second criterion's points sit 4 % to the right, so that equal values stay visible
                    .filter_map(|r| of(r).map(|y| (r.row.n as f64 * (1.0 + 0.04 * q as f64), y)))
                    .collect();
                series.push(Series {
                    label: format!("{} {label}", model.to_uppercase()),
                    errors: vec![],
                    points,
                    colour,
                    mark: Mark::Points,
                });
                if let (Some(p), Some(value)) = (paper, paper_value) {
                    let v = value(p);
                    series.push(Series {
                        label: format!("{} paper (Table 3): {v}", model.to_uppercase()),
                        errors: vec![],
                        points: vec![(n_range.0, v), (n_range.1, v)],
                        colour,
                        mark: Mark::Dashed,
                    });
                }
            }
        }
        let chart = LineChart {
            title: title.into(),
            x_label: "grains".into(),
            y_label: y_label.into(),
            series,
            log_x: true,
        };
        write_figure(out, name, &chart).map_err(|e| e.to_string())
    };
    // the paper's value is drawn once per model: beside the paper-tolerance criterion (Table 3 gives one T_c,3 and φ)
    figure(
        "ladder",
        "T_c3 against the grain count (path 2)",
        "T_c3 (h)",
        &[
            (
                "T_c3 (paper-tolerance criterion)",
                &|r| r.chosen().and_then(|s| s.paper.0),
                Some(|p| p.5),
            ),
            ("T_c3 (our criterion)", &|r| r.chosen().and_then(|s| s.ours.0), None),
        ],
    )?;
    figure(
        "ladder_phi",
        "Friction angle at T_c3 against the grain count (path 2)",
        "phi (deg)",
        &[
            (
                "phi (paper-tolerance criterion)",
                &|r| r.chosen().and_then(|s| s.paper.1),
                Some(|p| p.2),
            ),
            ("phi (our criterion)", &|r| r.chosen().and_then(|s| s.ours.1), None),
        ],
    )?;
    figure(
        "ladder_limits",
        "T_c1 and T_c2 against the grain count (path 2)",
        "spin period (h)",
        &[
            ("T_c1 (sampled)", &|r| r.row.limits.t_c1_hours, Some(|p| p.3)),
            ("T_c2 (smoothed)", &|r| r.row.limits_smoothed.t_c2_hours, Some(|p| p.4)),
        ],
    )?;
    let _ = writeln!(md, "\n![ladder: T_c3](ladder.png)\n");
    let _ = writeln!(md, "![ladder: φ](ladder_phi.png)\n");
    let _ = writeln!(md, "![ladder: T_c1 and T_c2](ladder_limits.png)");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rung's model is its directory name up to the first `_`.
    #[test]
    fn a_rung_belongs_to_the_model_its_name_starts_with() {
        assert_eq!(rung_model("rcp_8k"), "rcp");
        assert_eq!(rung_model("hcp_full"), "hcp");
    }
}
