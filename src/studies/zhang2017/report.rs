//! `rubblepile report zhang2017 RUNS --out analysis/zhang2017 [--force]`: the scaled-down reproduction of
//! Zhang17 Table 3 (critical spin limits of the rubble-pile models under spin-up path 2 of Table 5) from the runs
//! under `RUNS`, with Fig. 5-style time series.
//!
//! Layout read: `RUNS/<model>/path2/` (a soft-sphere run with `[spinup]`: `spinup.csv`, `summary.json`,
//! `snapshots/0.csv`) and, optionally, `RUNS/<model>/critical/critical.json` (from `rubblepile spinup
//! critical`, giving T_c,3 and φ). Also read: a run directory `RUNS/<run>/` with `spinup.csv` directly in it (a
//! user's `rubblepile run` of a spin-up scene), or RUNS being one such run directory ([`model_dirs`]); the report
//! says which layout it read. Models: every such directory; the paper's Table 3 row is printed beside ours for HCP,
//! RCP, RCPC, PP1, PP2 and PPC, "–" for any other name.
//!
//! The body's size and bulk density in the text are read from each run ([`crate::studies::zhang2017::body`]); a
//! T_c,1 or T_c,2 read within one dynamical time of t_start is marked as the settling's, in its cell, in a warning
//! line and on stderr ([`crate::studies::zhang2017::settling`]).
//!
//! Per model: N and the particle radii (the radius scaling against the paper's sizes), T_c,1 and T_c,2 from the
//! forced part after `t_start` ([`rubblepile::analysis::spinup::critical_limits`]), the failure mode, T_c,3 and φ, κ₃
//! of Eq. 22 with `ρ_B = 2100 M/M_P` (Zhang17 §4.2, M_P = 5.23e11 kg), the largest overlap, the largest departure
//! of the spin period from the path while forced, and the run's wall time.
//!
//! Bulk-density variants (Zhang17 §4.2, Fig. 19, Table 4) are runs of the same target with scaled masses, in
//! directories named `<model>_rho<ρ_B>` (e.g. `rcp_rho1800`): they are left out of the Table 3 rows and go, with
//! the nominal run, into an Eq. 22 section: κ₁, κ₂, κ₃ fitted over the densities ([`density_series`]) and the
//! critical bulk density at the Didymos period, beside the paper's Table 4.
//!
//! When a `critical.json` records T_c,3 by both creep criteria ([`rubblepile::analysis::creep`]), a section gives both
//! beside Table 3. The hand-written `NOTES.md` in the output directory (the paper-vs-ours table over every table
//! and figure of Zhang17, what is missing and what would decide it) is appended verbatim at the end
//! ([`crate::studies::report_notes`]).

use rubblepile::io::table::{Cells, read_table};
use std::fmt::Write as _;
use std::path::Path;

use super::spinup_figures::SpinupTimeSeries;
use rubblepile::analysis::figures::style::write_figure;
use rubblepile::analysis::spinup::{DensityFit, fit_density};
use rubblepile::analysis::spinup_diagnostics::SpinupSample;
use rubblepile::io::scene_file::SI_G;

use super::body::BodySource;
use super::rows::*;

/// The full-size section: one row per model under `full` (`<model>/path2`), finished or not, with its wall
/// time on this machine, and its Fig. 5-style figure `fig5_<model>_full`.
fn write_full_section(md: &mut String, full: &Path, out: &Path) -> Result<(), String> {
    let models = model_dirs(full)?;
    let _ = writeln!(md, "\n## Full size\n");
    let _ = writeln!(
        md,
        "Runs under `{}` at the paper's particle count (lengths unscaled); limits as in Table 3 above. A run still \
         going is read as far as it has got (`simulated` against the scene's `t_end`; wall time from the last row of \
         `timeseries.csv`, summed over resumes).\n",
        full.display()
    );
    let _ = writeln!(
        md,
        "| model | N | radius (m) | η_B | T_c1 (h) | T_c2 (h) | failure mode | status | simulated / t_end (s) | wall (s) | largest overlap / radius | energy / L residual |"
    );
    let _ = writeln!(
        md,
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    let mut figures = Vec::new();
    for m in &models {
        let (r, samples) = model_row(m)?;
        let ts = timeseries_worst(&run_dir(m, "path2"));
        let _ = writeln!(
            md,
            "| {} | {} | {:.2} | {:.4} | {} | {} | {} | {} | {:.0} / {} | {:.0} | {} | {} |",
            r.model.to_uppercase(),
            r.n,
            r.radius_range.1,
            r.packing,
            flagged(&r, "T_c1", opt(r.limits.t_c1_hours, 3)),
            flagged(&r, "T_c2", opt(r.limits.t_c2_hours, 3)),
            mode(r.limits.failure_mode),
            r.status,
            r.final_time,
            opt(t_end_of(&run_dir(m, "path2")), 0),
            r.wall_seconds,
            if r.max_overlap.is_finite() {
                format!("{:.2e}", r.max_overlap)
            } else {
                ts.map_or("–".into(), |t| format!("{:.2e} (so far)", t.0))
            },
            r.residuals
                .map(|(e, l)| format!("{e:.1e} / {l:.1e}"))
                .or(ts.map(|t| format!("{:.1e} / {:.1e} (so far)", t.1, t.2)))
                .unwrap_or_else(|| "–".into()),
        );
        warn_settling(&r);
        let title = format!("{} (N = {}), full size, spin-up path 2", r.model.to_uppercase(), r.n);
        figures.extend(fig5(out, format!("fig5_{}_full", r.model), title, samples));
    }
    for f in &figures {
        let _ = writeln!(md, "\n![{f}]({f}.png)");
    }
    Ok(())
}

/// Writes the Fig. 5-style figure `out/<stem>.{svg,png}`; returns the stem, or warns and returns `None`.
fn fig5(out: &Path, stem: String, title: String, samples: Vec<SpinupSample>) -> Option<String> {
    match write_figure(out, &stem, &SpinupTimeSeries { title, samples }) {
        Ok(_) => Some(stem),
        Err(e) => {
            eprintln!("warning: {stem}: {e}");
            None
        }
    }
}

/// Largest overlap fraction, and the largest |energy residual| and |L residual|, over the rows of the run's
/// `timeseries.csv` so far.
fn timeseries_worst(run: &Path) -> Option<(f64, f64, f64)> {
    let table = read_table(&run.join("timeseries.csv"), Cells::Lenient).ok()?;
    let col = |name: &str| table.column(name);
    let (o, e, l) = (
        col("max_overlap_fraction")?,
        col("energy_residual")?,
        col("angular_momentum_error")?,
    );
    let mut worst = (0.0f64, 0.0f64, 0.0f64);
    for v in &table.rows {
        let get = |k: usize| v.get(k).copied().unwrap_or(0.0).abs();
        worst = (worst.0.max(get(o)), worst.1.max(get(e)), worst.2.max(get(l)));
    }
    Some(worst)
}

/// Writes `out/REPORT.md` and `out/fig5_<model>.{svg,png}` from the runs under `runs` (and, with `full`, a
/// full-size section from the runs under it); refuses to overwrite an existing report without `force`. Returns
/// the report's path.
/// Where the report reads from: the runs of Table 3 and the directories of its optional sections.
#[derive(Debug, Clone, Copy)]
pub struct ReportSources<'a> {
    /// The runs (`<model>/path2`, `<model>/critical`).
    pub runs: &'a Path,
    /// Full-size runs ("Full size" section).
    pub full: Option<&'a Path>,
    /// Paths 1 and 3 ("Spin-up paths").
    pub paths: Option<&'a Path>,
    /// A resolution ladder.
    pub ladder: Option<&'a Path>,
    /// Contact-law variants ("Packing ordering").
    pub ordering: Option<&'a Path>,
    /// The decided study ([`crate::studies::zhang2017::decided`]), which also writes `ordering.csv`.
    pub decided: Option<&'a Path>,
}

impl<'a> ReportSources<'a> {
    /// The runs alone, no optional section.
    #[cfg(test)]
    pub fn new(runs: &'a Path) -> Self {
        ReportSources {
            runs,
            full: None,
            paths: None,
            ladder: None,
            ordering: None,
            decided: None,
        }
    }
}

/// Writes `out/REPORT.md` (and its figures) from `sources`; refuses to overwrite it unless `force`.
pub fn write_report(
    sources: &ReportSources<'_>,
    out: &Path,
    force: bool,
) -> Result<std::path::PathBuf, rubblepile::analysis::AnalysisError> {
    let ReportSources {
        runs,
        full,
        paths,
        ladder,
        ordering,
        decided,
    } = *sources;
    let report = out.join("REPORT.md");
    if report.exists() && !force {
        return Err(format!("{} exists (use --force to overwrite it)", report.display()).into());
    }
    let models = model_dirs(runs)?;
    if models.is_empty() {
        return Err(format!(
            "{}: no spin-up run found (expected <model>/path2/spinup.csv, <run>/spinup.csv, or a spinup.csv in it)",
            runs.display()
        )
        .into());
    }
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut rows = Vec::new();
    let mut figures = Vec::new();
    for m in &models {
        let (row, samples) = model_row(m)?;
        if base_model(&row.model) != row.model {
            rows.push(row);
            continue;
        }
        let title = format!("{} (N = {}), spin-up path 2", row.model.to_uppercase(), row.n);
        figures.extend(fig5(out, format!("fig5_{}", row.model), title, samples));
        rows.push(row);
    }
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Zhang et al. (2017) Table 3, scaled down: critical spin limits under spin-up path 2\n"
    );
    let _ = writeln!(
        md,
        "Generated by `rubblepile report zhang2017 {}{}{}{}{}{} --out {}{}` from the runs under `{}` (layout and \
         definitions: `src/studies/zhang2017/report.rs`; scenes and the commands that make the runs: \
         `analysis/zhang2017/README.md`). Do not edit by hand.\n",
        runs.display(),
        full.map(|f| format!(" --full {}", f.display())).unwrap_or_default(),
        paths.map(|p| format!(" --paths {}", p.display())).unwrap_or_default(),
        ladder.map(|l| format!(" --ladder {}", l.display())).unwrap_or_default(),
        ordering
            .map(|o| format!(" --ordering {}", o.display()))
            .unwrap_or_default(),
        decided
            .map(|d| format!(" --decided {}", d.display()))
            .unwrap_or_default(),
        out.display(),
        if force { " --force" } else { "" },
        runs.display()
    );
    let _ = writeln!(md, "{}\n", layout_sentence(runs, &models));
    let _ = writeln!(
        md,
        "Ours: T_c1/T_c2 from `spinup.csv` by the paper's rule as written: the first sample, after t_start and \
         while forced, at which b/a or c/a has changed by > 0.01, or η_B by > 0.001, from its value at t_start. \
         T_c2 is marked unresolved when the sample-to-sample scatter of η_B exceeds half that threshold. The \
         column 'smoothed' applies the rule to running means over the body's dynamical time 1/√(Gρ_B) ≈ 2700 s, a \
         check that the limits are not set by one sample; its look-ahead of half a window moves them to longer \
         periods by up to ≈ 0.05 h on path 2. η_B counts closed Voronoi cells by the rotation-free test \
         (`VoronoiCell::reaches`; the axis-aligned test used before 23 Nov 2026 made η_B wiggle by ±5e-4 with a \
         quarter of the spin period). T_c3/φ from `critical/critical.json` (`rubblepile spinup critical`) by the \
         paper's creep criterion read with tolerances (`paper-tolerance`: θ_max rising by > 0.5°, η_B falling by > \
         0.0005 or the coordination number by > 0.05 over a hold's second half, the rule of the searches made before \
         Dec 2026; the paper's criterion with zero tolerance, `spinup critical`'s default, is the decided section's) \
         and by ours (section below), κ₃ of Eq. 22 from each with ρ_B = 2100 M/M_P. Paper: Table 3 (path 1, full size; §4.3: T_c3 does not depend on the path, \
         T_c1 and T_c2 do — faster paths give shorter ones).\n"
    );
    let _ = writeln!(
        md,
        "| model | N | radius (m) | η_B | T_c1 (h) | T_c2 (h) | T_c3 (h), paper-tolerance / ours | φ (°), paper-tolerance / ours | κ₃, paper-tolerance / ours | failure mode | smoothed T_c1/T_c2, mode | paper η, φ, T_c1/2/3, κ₃, mode |"
    );
    let _ = writeln!(
        md,
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    let nominal: Vec<&ModelRow> = rows.iter().filter(|r| base_model(&r.model) == r.model).collect();
    for r in &nominal {
        let paper = TABLE3
            .iter()
            .find(|p| p.0 == r.model)
            .map(|p| {
                format!(
                    "{:.3}, {}°, {:.2}/{:.2}/{:.2} h, {}, {}",
                    p.1,
                    p.2,
                    p.3,
                    p.4,
                    p.5,
                    opt(p.6, 3),
                    p.7
                )
            })
            .unwrap_or_else(|| "–".into());
        // T_c3 by our creep criterion where the search recorded both (`critical.json` or `critical.csv`)
        let ours = r.t_c3_by_criterion.map_or((None, None), |[_, ours]| ours);
        let kappa3_ours = ours
            .0
            .and_then(|t| fit_density(&[(bulk_density(r), t)], SI_G, t))
            .map(|f| f.kappa);
        let both = |a: Option<f64>, b: Option<f64>, digits: usize| {
            if a.is_none() && b.is_none() {
                "–".to_string()
            } else {
                format!("{} / {}", opt(a, digits), opt(b, digits))
            }
        };
        let radius = if (r.radius_range.1 - r.radius_range.0).abs() < 1e-9 * r.radius_range.1 {
            format!("{:.1}", r.radius_range.0)
        } else {
            format!("{:.1}–{:.1}", r.radius_range.0, r.radius_range.1)
        };
        let _ = writeln!(
            md,
            "| {} | {} | {radius} | {:.4} | {} | {} | {} | {} | {} | {} | {}/{}, {} | {paper} |",
            r.model.to_uppercase(),
            r.n,
            r.packing,
            flagged(r, "T_c1", opt(r.limits.t_c1_hours, 3)),
            if r.t_c2_resolved {
                flagged(r, "T_c2", opt(r.limits.t_c2_hours, 3))
            } else {
                format!(
                    "unresolved ({}; η_B scatter {:.1e})",
                    opt(r.limits.t_c2_hours, 3),
                    r.packing_noise
                )
            },
            both(r.t_c3, ours.0, 2),
            both(r.phi, ours.1, 1),
            both(r.kappa3, kappa3_ours, 3),
            if r.t_c2_resolved {
                mode(r.limits.failure_mode)
            } else {
                "– (needs T_c2)"
            },
            opt(r.limits_smoothed.t_c1_hours, 3),
            opt(r.limits_smoothed.t_c2_hours, 3),
            mode(r.limits_smoothed.failure_mode),
        );
    }
    let warnings: Vec<String> = nominal
        .iter()
        .flat_map(|r| r.settling.iter().map(|w| w.describe(&r.model.to_uppercase())))
        .collect();
    for w in &warnings {
        let _ = writeln!(md, "\n**Warning** (settling, Zhang17 §2.3.4): {w}.");
        eprintln!("warning: {w}");
    }
    let _ = writeln!(
        md,
        "\nRadius scaling: the paper's HCP/RCP spheres are ≈ 10 m (42 062 and 36 523 particles in \
         the 780 m body) and PP1's 4–32 m; ours keep the body ({}) and use fewer, larger \
         particles (radius column), i.e. lengths scaled by (N_paper/N)^(1/3).\n",
        bodies_sentence(&nominal)
    );
    write_criterion_section(&mut md, &nominal);
    let _ = writeln!(md, "## Runs\n");
    let _ = writeln!(
        md,
        "| model | status | simulated (s) | wall (s) | largest overlap / radius: run, sampled before failure | largest \\|T/T_path − 1\\| while forced: before T_c1 / all | forcing released at (s) | energy / L residual |"
    );
    let _ = writeln!(md, "| --- | --- | --- | --- | --- | --- | --- | --- |");
    for r in &rows {
        let _ = writeln!(
            md,
            "| {} | {} | {:.0} | {:.0} | {:.2e}, {} | {:.1e} / {:.1e} | {} | {} |",
            r.model.to_uppercase(),
            r.status,
            r.final_time,
            r.wall_seconds,
            r.max_overlap,
            r.max_overlap_before_failure.map_or("–".into(), |o| format!("{o:.2e}")),
            r.path_error_before_t_c1,
            r.path_error,
            opt(r.release_time, 0),
            r.residuals
                .map_or("– (forcing not booked)".to_string(), |(e, l)| format!(
                    "{e:.1e} / {l:.1e}"
                ))
        );
    }
    write_density_section(&mut md, &rows);
    crate::studies::zhang2017::materials::write_materials_section(&mut md, runs, &rows);
    if let Some(full) = full {
        write_full_section(&mut md, full, out)?;
    }
    if let Some(paths) = paths {
        crate::studies::zhang2017::paths::write_paths_section(&mut md, runs, paths)?;
    }
    if let Some(ladder) = ladder {
        crate::studies::zhang2017::ladder::write_ladder_section(&mut md, ladder, out)?;
    }
    if let Some(ordering) = ordering {
        crate::studies::zhang2017::ordering::write_ordering_section(&mut md, runs, ordering);
    }
    crate::studies::zhang2017::holds::write_holds_section(&mut md, &hold_searches(runs, ladder, ordering), out);
    if let Some(decided) = decided {
        crate::studies::zhang2017::decided::write_decided_section(&mut md, decided, out)?;
    }
    let _ = writeln!(md, "\n## Time series (Fig. 5 style)\n");
    for f in &figures {
        let _ = writeln!(md, "![{f}]({f}.png)\n");
    }
    // the hand-written discussion (paper vs ours, what is missing), kept across regenerations
    crate::studies::report_notes::append_notes(&mut md, out);
    std::fs::write(&report, md).map_err(|e| format!("{}: {e}", report.display()))?;
    Ok(report)
}

/// Which layout of run directories was read: `<model>/path2/` ones, run directories with `spinup.csv` in them,
/// or `runs` itself as one run.
fn layout_sentence(runs: &Path, models: &[std::path::PathBuf]) -> String {
    if models.len() == 1 && models[0] == runs {
        return format!(
            "Layout read: `{}` is one run directory (`spinup.csv` directly in it), its row named after it.",
            runs.display()
        );
    }
    let (nested, direct): (Vec<_>, Vec<_>) = models.iter().partition(|m| m.join("path2/spinup.csv").is_file());
    let names = |v: &[&std::path::PathBuf]| v.iter().map(|m| dir_name(m)).collect::<Vec<_>>().join(", ");
    let mut parts = Vec::new();
    if !nested.is_empty() {
        parts.push(format!("`<model>/path2/spinup.csv` for {} models", nested.len()));
    }
    if !direct.is_empty() {
        parts.push(format!(
            "run directories with `spinup.csv` directly in them for {}",
            names(&direct)
        ));
    }
    let unknown: Vec<&std::path::PathBuf> = models
        .iter()
        .filter(|m| {
            let n = dir_name(m);
            !TABLE3.iter().any(|p| p.0 == base_model(&n))
        })
        .collect();
    let mut s = format!("Layout read under `{}`: {}.", runs.display(), parts.join("; "));
    if !unknown.is_empty() {
        let _ = write!(
            s,
            " Not models of the paper's Table 3 (hcp, rcp, rcpc, pp1, pp2, ppc), so – in its columns: {}.",
            names(&unknown)
        );
    }
    s
}

/// The bodies of `rows` as read from the runs: one "D = …, ρ_B = …" when all agree at the printed precision,
/// else each value with the models that have it; where each was read from.
fn bodies_sentence(rows: &[&ModelRow]) -> String {
    let mut groups: Vec<(String, Vec<String>)> = Vec::new();
    for r in rows {
        let key = match &r.body {
            Some(b) => format!(
                "{} ({})",
                b.describe(),
                match b.source {
                    BodySource::Aggregate => "the aggregate's record",
                    BodySource::GrainsOverPacking => "the grains' volume over η_B at t_start",
                }
            ),
            None => "size not found in the run".to_string(),
        };
        match groups.iter_mut().find(|g| g.0 == key) {
            Some(g) => g.1.push(r.model.to_uppercase()),
            None => groups.push((key, vec![r.model.to_uppercase()])),
        }
    }
    if groups.len() == 1 {
        return groups.remove(0).0;
    }
    groups
        .iter()
        .map(|(k, m)| format!("{k} for {}", m.join(", ")))
        .collect::<Vec<_>>()
        .join("; ")
}

/// The searches whose holds the Fig. 22 analogue may show: PP2's T_c,3 searches under `runs` (the paper's model, at
/// each bulk density run), every `critical*` search of the ladder's rungs and every
/// search under the ordering directory (`<model>_<variant>`), labelled by their directories, with the bulk density
/// (kg/m³, `ρ_B = 2100 M/M_P`) of the rung's path-2 run or of the model's run under `runs`.
fn hold_searches(
    runs: &Path,
    ladder: Option<&Path>,
    ordering: Option<&Path>,
) -> Vec<(String, std::path::PathBuf, f64)> {
    let rho = |model_dir: &Path| model_row(model_dir).map_or(f64::NAN, |(r, _)| bulk_density(&r));
    let subdirs = |d: &Path| -> Vec<std::path::PathBuf> {
        let mut v: Vec<_> = std::fs::read_dir(d)
            .into_iter()
            .flatten()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.is_dir())
            .collect();
        v.sort();
        v
    };
    let name = |p: &Path| {
        p.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    let mut out = Vec::new();
    // Fig. 22's own model, PP2, at each bulk density run (Table 3's run and the Eq. 22 variants)
    for model_dir in subdirs(runs) {
        let n = name(&model_dir);
        if base_model(&n) == "pp2" && !is_material_variant(&n) {
            out.push((
                format!("runs {n} critical"),
                model_dir.join("critical"),
                rho(&model_dir),
            ));
        }
    }
    for rung in ladder.map(subdirs).unwrap_or_default() {
        let rho = rho(&rung);
        for s in search_subdirs(&rung) {
            out.push((format!("ladder {} {}", name(&rung), name(&s)), s, rho));
        }
    }
    for variant in ordering.map(subdirs).unwrap_or_default() {
        let model = name(&variant).split('_').next().unwrap_or_default().to_string();
        let rho = rho(&runs.join(model));
        for s in crate::studies::zhang2017::ordering::search_dirs(&variant) {
            let label = if s == variant {
                format!("contact law {}", name(&variant))
            } else {
                format!("contact law {} {}", name(&variant), name(&s))
            };
            out.push((label, s, rho));
        }
    }
    out
}

/// T_c,3 and φ by both creep criteria (Zhang17 §3.3.3; [`rubblepile::analysis::creep`]) for the models whose
/// `critical.json` records both; nothing when none does (searches made before the paper's criterion came in).
fn write_criterion_section(md: &mut String, rows: &[&ModelRow]) {
    let with: Vec<(&ModelRow, [LimitAndAngle; 2])> = rows
        .iter()
        .filter_map(|r| r.t_c3_by_criterion.map(|b| (*r, b)))
        .collect();
    if with.is_empty() {
        return;
    }
    let _ = writeln!(md, "## T_c,3 by creep criterion (Zhang17 §3.3.3)\n");
    let _ = writeln!(
        md,
        "Both verdicts on the same holds (`critical.json`): the paper's criterion with tolerances (`paper-tolerance`) \
         counts θ_max rising by > 0.5°, η_B falling by > 0.0005 or the coordination number falling by > 0.05 over \
         the second half of a hold as creep; ours counts θ_max or η_B \
         moving either way and does not judge the coordination number (`src/analysis/creep.rs`).\n"
    );
    let _ = writeln!(
        md,
        "| model | paper-tolerance: T_c3 (h), φ (°) | ours: T_c3 (h), φ (°) | paper Table 3: T_c3 (h), φ (°) |"
    );
    let _ = writeln!(md, "| --- | --- | --- | --- |");
    for (r, [(tp, pp), (to, po)]) in with {
        let paper = TABLE3
            .iter()
            .find(|p| p.0 == r.model)
            .map(|p| format!("{:.2}, {}", p.5, p.2))
            .unwrap_or_else(|| "–".into());
        let _ = writeln!(
            md,
            "| {} | {}, {} | {}, {} | {paper} |",
            r.model.to_uppercase(),
            opt(tp, 2),
            opt(pp, 1),
            opt(to, 2),
            opt(po, 1)
        );
    }
    let _ = writeln!(md);
}

/// The Eq. 22 section: per model run at several bulk densities, the limits per density and the fits beside
/// Table 4 (nothing when no model has two densities).
fn write_density_section(md: &mut String, rows: &[ModelRow]) {
    let series = density_series(rows);
    if series.is_empty() {
        return;
    }
    let _ = writeln!(
        md,
        "\n## Eq. 22 over bulk densities (Zhang17 §4.2, Fig. 19, Table 4)\n\nThe same target with every mass \
         scaled (`rubblepile aggregate density`, ρ_B = 2100 M/M_P; runs `<model>_rho<ρ_B>`), path 2 and T_c,3 \
         searches as for the nominal run. Fit of Ω_c = κ √(4πGρ_B/3) through the origin by least squares over the \
         densities (± its standard error), and the critical bulk density ρ_B^c at which Ω_c is the Didymos spin \
         (P = {DIDYMOS_PERIOD_HOURS} h). T_c,3 by the paper-tolerance creep criterion and by ours (section \"T_c,3 \
         by creep criterion\"); the paper's κ₃ stands beside both.\n"
    );
    for s in &series {
        let _ = writeln!(md, "### {}\n", s.model.to_uppercase());
        let _ = writeln!(
            md,
            "| ρ_B (kg/m³) | T_c1 (h) | T_c2 (h) | T_c3 (h), paper-tolerance / ours | κ₁ | κ₂ | κ₃ (single point), paper-tolerance / ours |"
        );
        let _ = writeln!(md, "| --- | --- | --- | --- | --- | --- | --- |");
        for (rho, t) in &s.points {
            let kappa = |t: Option<f64>| {
                t.and_then(|t| fit_density(&[(*rho, t)], SI_G, DIDYMOS_PERIOD_HOURS))
                    .map(|f| f.kappa)
            };
            let _ = writeln!(
                md,
                "| {rho:.0} | {} | {} | {} / {} | {} | {} | {} / {} |",
                opt(t[0], 3),
                opt(t[1], 3),
                opt(t[2], 2),
                opt(t[3], 2),
                opt(kappa(t[0]), 3),
                opt(kappa(t[1]), 3),
                opt(kappa(t[2]), 3),
                opt(kappa(t[3]), 3)
            );
        }
        let paper = TABLE4.iter().find(|p| p.0 == s.model);
        let _ = writeln!(
            md,
            "\n| limit | points | κ (fit) | ρ_B^c (kg/m³) | paper κ, ρ_B^c (full size, path 1) |"
        );
        let _ = writeln!(md, "| --- | --- | --- | --- | --- |");
        for (i, fit) in s.fits.iter().enumerate() {
            let n = s.points.iter().filter(|p| p.1[i].is_some()).count();
            let fitted = fit
                .as_ref()
                .map_or("– (fewer than 2 densities) | –".to_string(), |f: &DensityFit| {
                    format!("{:.3} ± {:.3} | {:.0}", f.kappa, f.sigma_kappa, f.critical_density)
                });
            // the paper has one κ₃, set beside both of ours
            let k = i.min(2);
            let p = paper.map_or("–".to_string(), |p| format!("{:.3}, {:.0}", p.1[k].1, p.1[k].0));
            let name = match i {
                0..=1 => format!("T_c,{}", i + 1),
                2 => "T_c,3 (paper-tolerance)".to_string(),
                _ => "T_c,3 (ours)".to_string(),
            };
            let _ = writeln!(md, "| {name} | {n} | {fitted} | {p} |");
        }
        let _ = writeln!(md);
    }
}

/// `rubblepile report zhang2017`.
#[derive(Debug, clap::Args)]
pub struct ReportZhang2017Args {
    /// Directory of the runs (e.g. runs/zhang2017).
    pub runs: std::path::PathBuf,
    /// Directory of full-size runs (`<model>/path2`, e.g. runs/zhang2017_full), read into a "Full size" section,
    /// finished or still running.
    #[arg(long, value_name = "DIR")]
    pub full: Option<std::path::PathBuf>,
    /// Directory of spin-up path 1 and 3 runs (`<model>/path1`, `<model>/path3`, e.g. runs/zhang2017_paths), read
    /// into a "Spin-up paths" section beside the path-2 runs and the paper's Table 6.
    #[arg(long, value_name = "DIR")]
    pub paths: Option<std::path::PathBuf>,
    /// Directory of a resolution ladder (`<rung>/path2`, `<rung>/critical*/critical.json`, e.g.
    /// analysis/zhang2017/ladder), read into a "Resolution ladder" section and its figure `ladder.{svg,png}`.
    #[arg(long, value_name = "DIR")]
    pub ladder: Option<std::path::PathBuf>,
    /// Directory of the contact-law variants' T_c,3 searches (`<model>_<variant>/critical.{json,csv}`, e.g.
    /// analysis/zhang2017/ordering), read with the nominal searches of RUNS into a "Packing ordering" section.
    #[arg(long, value_name = "DIR")]
    pub ordering: Option<std::path::PathBuf>,
    /// Directory of the study that decides Zhang17 at the paper's scale (`full/`, `scaled/`, `orientation/`,
    /// `hold_length/` of compact searches, e.g. analysis/zhang2017/decided), read into a "Decided at the paper's
    /// scale" section; writes `ordering.csv` beside REPORT.md.
    #[arg(long, value_name = "DIR")]
    pub decided: Option<std::path::PathBuf>,
    /// Where REPORT.md and the figures go.
    #[arg(long, value_name = "DIR", default_value = "analysis/zhang2017")]
    pub out: std::path::PathBuf,
    /// Overwrite an existing REPORT.md.
    #[arg(long)]
    pub force: bool,
}

/// `rubblepile report zhang2017`: [`write_report`] from the arguments, saying where it wrote.
pub fn report_command(args: &ReportZhang2017Args) -> Result<(), String> {
    let sources = ReportSources {
        runs: &args.runs,
        full: args.full.as_deref(),
        paths: args.paths.as_deref(),
        ladder: args.ladder.as_deref(),
        ordering: args.ordering.as_deref(),
        decided: args.decided.as_deref(),
    };
    let path = write_report(&sources, &args.out, args.force)?;
    println!("wrote {}", path.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rubblepile::analysis::spinup::{CriticalLimits, DIDYMOS_MASS};

    fn row(model: &str, rho: f64, t: [Option<f64>; 3]) -> ModelRow {
        ModelRow {
            model: model.into(),
            n: 1,
            radius_range: (1.0, 1.0),
            mass: rho / 2100.0 * DIDYMOS_MASS,
            packing: 0.6,
            limits: CriticalLimits {
                t_c1_hours: t[0],
                t_c2_hours: t[1],
                failure_mode: None,
            },
            limits_smoothed: CriticalLimits {
                t_c1_hours: None,
                t_c2_hours: None,
                failure_mode: None,
            },
            packing_noise: 0.0,
            t_c2_resolved: true,
            t_c3: t[2],
            phi: None,
            t_c3_by_criterion: None,
            kappa3: None,
            path_error: 0.0,
            path_error_before_t_c1: 0.0,
            release_time: None,
            max_overlap: 0.0,
            max_overlap_before_failure: None,
            residuals: None,
            body: None,
            settling: Vec::new(),
            wall_seconds: 0.0,
            final_time: 0.0,
            status: "completed".into(),
        }
    }

    /// Periods made exactly by Eq. 22 with κ = 0.8 give κ = 0.8 back with zero spread, and the critical density
    /// at 2.26 h solves Eq. 22; a model at one density only and a limit found at one density only are not fitted.
    #[test]
    fn density_series_recovers_the_kappa_of_synthetic_periods() {
        let period = |kappa: f64, rho: f64| {
            let omega = kappa * (4.0 * std::f64::consts::PI * SI_G * rho / 3.0).sqrt();
            Some(2.0 * std::f64::consts::PI / omega / 3600.0)
        };
        let rows = vec![
            row(
                "rcp",
                2100.0,
                [period(0.9, 2100.0), period(0.85, 2100.0), period(0.8, 2100.0)],
            ),
            row(
                "rcp_rho1800",
                1800.0,
                [period(0.9, 1800.0), period(0.85, 1800.0), period(0.8, 1800.0)],
            ),
            ModelRow {
                t_c3_by_criterion: Some([(None, None), (Some(2.30), Some(45.0))]),
                ..row("rcp_rho2400", 2400.0, [period(0.9, 2400.0), period(0.85, 2400.0), None])
            },
            row("hcp", 2100.0, [Some(2.4), None, None]),
        ];
        let series = density_series(&rows);
        assert_eq!(series.len(), 1, "only RCP has several densities");
        let s = &series[0];
        assert_eq!(s.model, "rcp");
        assert_eq!(
            s.points.iter().map(|p| p.0.round()).collect::<Vec<_>>(),
            vec![1800.0, 2100.0, 2400.0]
        );
        for (i, kappa) in [0.9, 0.85, 0.8].into_iter().enumerate() {
            let f = s.fits[i].as_ref().expect("fitted");
            assert!((f.kappa - kappa).abs() < 1e-12, "κ{} = {}", i + 1, f.kappa);
            assert!(f.sigma_kappa < 1e-12);
            let t = period(kappa, f.critical_density).unwrap();
            assert!((t - DIDYMOS_PERIOD_HOURS).abs() < 1e-9, "ρ_c gives {t} h");
        }
        let mut md = String::new();
        write_density_section(&mut md, &rows);
        assert!(md.contains("### RCP") && !md.contains("### HCP"));
        // κ₃ from 2 of the 3 densities
        assert!(md.contains("| T_c,3 (paper-tolerance) | 2 | 0.800 ± 0.000"), "{md}");
        // ours: only the 2400 kg/m³ run records both criteria, one point, no fit
        assert!(md.contains("| T_c,3 (ours) | 1 | – (fewer than 2 densities)"), "{md}");
        assert!(md.contains("| – / 2.30 |"), "{md}");
    }

    /// The scatter estimate sees white noise and not a slow trend; the resolution rule separates the scaled RCP
    /// (2e-4 scatter, 13 samples per window) from PP1 (3e-3).
    #[test]
    fn packing_scatter_and_t_c2_resolution() {
        let alternating: Vec<f64> = (0..100).map(|k| 0.6 + if k % 2 == 0 { 1e-3 } else { -1e-3 }).collect();
        // successive differences of 2e-3: RMS/√2 = 1.41e-3
        assert!((successive_scatter(&alternating) - 2e-3 / 2f64.sqrt()).abs() < 1e-12);
        let trend: Vec<f64> = (0..100).map(|k| 0.6 - 1e-5 * k as f64).collect();
        assert!(successive_scatter(&trend) < 1e-5);
        assert_eq!(successive_scatter(&[0.6]), 0.0);
        assert!(t_c2_resolved(2e-4, 2700.0, 200.0));
        assert!(!t_c2_resolved(3e-3, 2700.0, 200.0));
        // single samples (the report's limits): resolved below half the threshold only
        assert!(t_c2_resolved(4e-4, 200.0, 200.0));
        assert!(!t_c2_resolved(6e-4, 200.0, 200.0));
    }
}
