//! The spin-up-path section of the Zhang17 report (Zhang et al. 2017, Table 5 paths, §4.3, Table 6): T_c,1 and
//! T_c,2 of one model spun up along paths 1, 2 and 3, beside the paper's Table 6 (HCP at 2100, 2208 and
//! 2309 kg/m³; its PP2 rows are not carried, PP2 is not built).
//!
//! The paths differ only in how fast the spin period is driven from its intermediate value `T_inter` to 2.26 h:
//! path 1 (3 h, six stages with five rests of 7000 s, 320 000 s), path 2 (3 h → 2.26 h by 32 000 s) and path 3
//! (4 h → 2.26 h by 32 000 s). The paper's §4.3: the faster the path, the shorter the periods at which the body
//! first responds (T_c,1, T_c,2); T_c,3 does not depend on the path.

use std::fmt::Write as _;
use std::path::Path;

use crate::studies::zhang2017::rows::{TABLE3, flagged, mode, opt, path_row, t_end_of, warn_settling};

/// The spin-up paths, by the run directory's name.
pub const PATHS: [&str; 3] = ["path1", "path2", "path3"];

/// Zhang17 Table 6 for HCP: the run directory's model name (`hcp` at 2100 kg/m³, `hcp_rho<ρ_B>` for the density
/// variants) and T_c,1, T_c,2, T_c,3 (h) for paths 1, 2 and 3.
pub const TABLE6_HCP: [(&str, [[f64; 3]; 3]); 3] = [
    ("hcp", [[2.38, 2.36, 2.40], [2.30, 2.27, 2.40], [2.26, 2.26, 2.40]]),
    (
        "hcp_rho2208",
        [[2.35, 2.28, 2.36], [2.26, 2.26, 2.36], [2.26, 2.26, 2.36]],
    ),
    (
        "hcp_rho2309",
        [[2.27, 2.26, 2.29], [2.26, 2.26, 2.29], [2.26, 2.26, 2.29]],
    ),
];

/// The paper's values of one model and path: Table 6 for HCP and its density variants; Table 3 (path 1 only) for
/// the others.
fn paper(model: &str, path: usize) -> String {
    let fmt = |v: [f64; 3]| format!("{:.2} / {:.2} / {:.2}", v[0], v[1], v[2]);
    if let Some((_, rows)) = TABLE6_HCP.iter().find(|r| r.0 == model) {
        return format!("{} (Table 6)", fmt(rows[path]));
    }
    match TABLE3.iter().find(|r| r.0 == model) {
        Some(r) if path == 0 => format!("{} (Table 3)", fmt([r.3, r.4, r.5])),
        _ => "– (no Table 6 row)".into(),
    }
}

/// Appends the section: one row per path for every model under `paths` with a `path1` or `path3` run (path 2 is
/// read from `runs/<model>/path2`, the run of the Table 3 section), with the T_c,3 search of that path where one
/// was made (`critical_path1/`, `critical/`, `critical_path3/`). A run still going is read as far as it got.
pub fn write_paths_section(md: &mut String, runs: &Path, paths: &Path) -> Result<(), String> {
    let mut models: Vec<_> = std::fs::read_dir(paths)
        .map_err(|e| format!("{}: {e}", paths.display()))?
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| {
            ["path1", "path3"]
                .iter()
                .any(|q| p.join(q).join("spinup.csv").is_file())
        })
        .collect();
    models.sort();
    if models.is_empty() {
        return Err(format!(
            "{}: no <model>/path1 or path3 with a spinup.csv",
            paths.display()
        ));
    }
    let _ = writeln!(md, "\n## Spin-up paths (Table 5, §4.3, Table 6)\n");
    let _ = writeln!(
        md,
        "Paths 1 and 3 from the runs under `{}`, path 2 from `{}`; limits read as in Table 3 above (sampled, and \
         smoothed over the dynamical time). Paper: T_c1 / T_c2 / T_c3; Table 6 gives all three paths for HCP at \
         2100 kg/m³ only, Table 3 path 1 for the others. §4.3: faster paths give shorter T_c1, T_c2.\n",
        paths.display(),
        runs.display()
    );
    let _ = writeln!(
        md,
        "| model | path | T_c1 (h) | T_c2 (h) | smoothed T_c1/T_c2 | T_c3 (h), paper-tolerance / our creep criterion | failure mode | status | simulated / t_end (s) | wall (s) | largest overlap / radius | paper T_c1 / T_c2 / T_c3 (h) |"
    );
    let _ = writeln!(
        md,
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    for m in &models {
        let name = m
            .file_name()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        for (k, path) in PATHS.iter().enumerate() {
            let dir = if *path == "path2" { runs.join(&name) } else { m.clone() };
            if !dir.join(path).join("spinup.csv").is_file() {
                continue;
            }
            let (r, _) = path_row(&dir, path).map_err(|e| e.to_string())?;
            warn_settling(&r);
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {}/{} | {} | {} | {} | {:.0} / {} | {:.0} | {} | {} |",
                name.to_uppercase(),
                k + 1,
                flagged(&r, "T_c1", opt(r.limits.t_c1_hours, 3)),
                flagged(&r, "T_c2", opt(r.limits.t_c2_hours, 3)),
                opt(r.limits_smoothed.t_c1_hours, 3),
                opt(r.limits_smoothed.t_c2_hours, 3),
                match r.t_c3_by_criterion {
                    Some([paper, ours]) => format!("{} / {}", opt(paper.0, 2), opt(ours.0, 2)),
                    None => "– (not searched)".into(),
                },
                mode(r.limits.failure_mode),
                r.status,
                r.final_time,
                opt(t_end_of(&dir.join(path)), 0),
                r.wall_seconds,
                if r.max_overlap.is_finite() {
                    format!("{:.2e}", r.max_overlap)
                } else {
                    "–".into()
                },
                paper(&name, k),
            );
        }
    }
    Ok(())
}
