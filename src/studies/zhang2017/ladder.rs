//! The resolution ladder (issue 40): one model's path-2 run and T_c,3 search at several grain counts, the same
//! body and material with lengths scaled by the grain radius (`analysis/zhang2017/ladder/README.md`), against
//! the paper's value at its own count (Zhang17 Table 3: RCP, 36 523 grains of ≈ 10 m). Does the packing
//! dependence of T_c,3 appear as N grows?
//!
//! Each rung is a directory `<rung>/path2` (a run, or its compact copy: `spinup.csv`, `timeseries.csv`,
//! `summary.json`, `scene.toml`, `particles.json`) with zero or more searches `<rung>/critical*/critical.json`.
//! Of several searches the one with the finest step of T_final that found a T_c,3 is used (a coarse search
//! brackets, a fine one refines).

use std::fmt::Write as _;
use std::path::Path;

use crate::analysis::figures::lines::{LineChart, Mark, Series};
use crate::analysis::figures::style::write_figure;

use super::rows::{ModelRow, TABLE3, base_model, mode, model_dirs, model_row, opt, read_critical, search_subdirs};

/// The search of a rung: its T_c,3 (h) and φ (°) by the paper's criterion and by ours, its step of T_final (h),
/// and its directory name.
#[derive(Debug, Clone, PartialEq)]
pub struct RungSearch {
    /// Directory name under the rung (`critical`, `critical_fine`, …).
    pub name: String,
    /// Smallest difference between two holds' T_final (h).
    pub step_hours: f64,
    /// T_c,3 (h) and φ (°) by the paper's criterion.
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
        paper: if v["paper"].is_object() { pair(&v["paper"]) } else { top },
        ours: if v["ours"].is_object() { pair(&v["ours"]) } else { top },
        holds: t.len(),
    })
}

/// The search a rung's row shows: of those that found a T_c,3 by the paper's criterion the finest; else the
/// finest of all.
pub fn chosen_search(searches: &[RungSearch]) -> Option<&RungSearch> {
    let by_step = |a: &&RungSearch, b: &&RungSearch| a.step_hours.total_cmp(&b.step_hours);
    searches
        .iter()
        .filter(|s| s.paper.0.is_some())
        .min_by(by_step)
        .or_else(|| searches.iter().min_by(by_step))
}

/// A rung: its path-2 row and its searches.
struct Rung {
    row: ModelRow,
    searches: Vec<RungSearch>,
}

fn rungs(ladder: &Path) -> Result<Vec<Rung>, String> {
    let mut out = Vec::new();
    for dir in model_dirs(ladder)? {
        let (row, _) = model_row(&dir).map_err(|e| e.to_string())?;
        let subdirs = search_subdirs(&dir);
        let searches = subdirs.iter().filter_map(|d| read_search(d)).collect();
        out.push(Rung { row, searches });
    }
    out.sort_by_key(|r| r.row.n);
    Ok(out)
}

fn pair(p: (Option<f64>, Option<f64>)) -> String {
    format!("{} h, {}°", opt(p.0, 2), opt(p.1, 1))
}

/// Writes the "Resolution ladder" section of the rungs under `ladder` and its figure `out/ladder.{svg,png}`
/// (T_c,1, smoothed T_c,2 and T_c,3 by both criteria against the grain count, the paper's values as dashed lines).
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
         search that found one (`critical*/critical.json`), by the paper's criterion and by ours. The paper's row is \
         Table 3 (path 1; its T_c,3 does not depend on the path, §4.3).\n",
        ladder.display()
    );
    let _ = writeln!(
        md,
        "| rung | grains | radius (m) | η_B | T_c1 / T_c2 (h) | smoothed T_c1 / T_c2 (h) | mode | T_c3, φ: paper's criterion | T_c3, φ: ours | search (step, holds) | largest overlap / r | wall (s) |"
    );
    let _ = writeln!(
        md,
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    for r in &rungs {
        let s = chosen_search(&r.searches);
        let _ = writeln!(
            md,
            "| {} | {} | {:.2} | {:.4} | {} / {} | {} / {} | {} | {} | {} | {} | {:.2e} | {:.0} |",
            r.row.model,
            r.row.n,
            r.row.radius_range.1,
            r.row.packing,
            opt(r.row.limits.t_c1_hours, 3),
            opt(r.row.limits.t_c2_hours, 3),
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
    let model = base_model(&rungs[0].row.model)
        .split('_')
        .next()
        .unwrap_or("")
        .to_string();
    let paper = TABLE3.iter().find(|p| p.0 == model);
    if let Some(p) = paper {
        let _ = writeln!(
            md,
            "| paper ({}) | {} | ≈ 10 | {:.3} | {:.2} / {:.2} | | {} | {:.2} h, {:.0}° | | | < 1e-2 | |",
            p.0.to_uppercase(),
            if p.0 == "rcp" { "36 523" } else { "–" },
            p.1,
            p.3,
            p.4,
            p.7,
            p.5,
            p.2
        );
    }
    let n_range = (
        rungs[0].row.n as f64 * 0.8,
        rungs[rungs.len() - 1].row.n.max(36_523) as f64 * 1.25,
    );
    let series = |label: &str, colour, mark, points: Vec<(f64, f64)>| Series {
        label: label.into(),
        errors: vec![],
        points,
        colour,
        mark,
    };
    let of = |f: &dyn Fn(&Rung) -> Option<f64>| -> Vec<(f64, f64)> {
        rungs.iter().filter_map(|r| f(r).map(|y| (r.row.n as f64, y))).collect()
    };
    let mut chart = LineChart {
        title: format!(
            "{}: critical spins against the grain count (path 2)",
            model.to_uppercase()
        ),
        x_label: "grains".into(),
        y_label: "spin period (h)".into(),
        series: vec![
            series("T_c1 (sampled)", 0, Mark::Points, of(&|r| r.row.limits.t_c1_hours)),
            series(
                "T_c2 (smoothed)",
                1,
                Mark::Points,
                of(&|r| r.row.limits_smoothed.t_c2_hours),
            ),
            series(
                "T_c3 (paper's criterion)",
                2,
                Mark::Points,
                of(&|r| chosen_search(&r.searches).and_then(|s| s.paper.0)),
            ),
            series(
                "T_c3 (our criterion)",
                3,
                Mark::Points,
                of(&|r| chosen_search(&r.searches).and_then(|s| s.ours.0)),
            ),
        ],
        log_x: true,
    };
    if let Some(p) = paper {
        let line = |v: f64| vec![(n_range.0, v), (n_range.1, v)];
        chart
            .series
            .push(series(&format!("paper T_c1 {:.2} h", p.3), 0, Mark::Dashed, line(p.3)));
        chart
            .series
            .push(series(&format!("paper T_c2 {:.2} h", p.4), 1, Mark::Dashed, line(p.4)));
        chart
            .series
            .push(series(&format!("paper T_c3 {:.2} h", p.5), 2, Mark::Dashed, line(p.5)));
    }
    write_figure(out, "ladder", &chart).map_err(|e| e.to_string())?;
    let _ = writeln!(md, "\n![ladder](ladder.png)");
    Ok(())
}
