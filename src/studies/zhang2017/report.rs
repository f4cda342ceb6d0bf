//! `rubblepile report zhang2017 RUNS --out analysis/zhang2017 [--force]`: the scaled-down reproduction of
//! Zhang17 Table 3 (critical spin limits of the rubble-pile models under spin-up path 2 of Table 5) from the runs
//! under `RUNS`, with Fig. 5-style time series.
//!
//! Layout read: `RUNS/<model>/path2/` (a soft-sphere run with `[spinup]`: `spinup.csv`, `summary.json`,
//! `snapshots/0.csv`) and, optionally, `RUNS/<model>/critical/critical.json` (from `rubblepile spinup
//! critical`, giving T_c,3 and φ). Models: any directory under RUNS with a `path2` run; the paper's Table 3 row is
//! printed beside ours for HCP, RCP, RCPC, PP1, PP2 and PPC.
//!
//! Per model: N and the particle radii (the radius scaling against the paper's sizes), T_c,1 and T_c,2 from the
//! forced part after `t_start` ([`critical_limits`]), the failure mode, T_c,3 and φ, κ₃ of Eq. 22 with
//! `ρ_B = 2100 M/M_P` (Zhang17 §4.2, M_P = 5.23e11 kg), the largest overlap, the largest departure of the spin
//! period from the path while forced, and the run's wall time.
//!
//! Bulk-density variants (Zhang17 §4.2, Fig. 19, Table 4) are runs of the same target with scaled masses, in
//! directories named `<model>_rho<ρ_B>` (e.g. `rcp_rho1800`): they are left out of the Table 3 rows and go, with
//! the nominal run, into an Eq. 22 section: κ₁, κ₂, κ₃ fitted over the densities ([`density_series`]) and the
//! critical bulk density at the Didymos period, beside the paper's Table 4.
//!
//! When a `critical.json` records T_c,3 by both creep criteria ([`crate::analysis::creep`]), a section gives both
//! beside Table 3. The hand-written `NOTES.md` in the output directory (the paper-vs-ours table over every table
//! and figure of Zhang17, what is missing and what would decide it) is appended verbatim at the end
//! ([`crate::studies::report_notes`]).

use crate::io::table::{Cells, read_header, read_table};
use std::fmt::Write as _;
use std::path::Path;

use crate::analysis::figures::spinup_figures::SpinupTimeSeries;
use crate::analysis::figures::style::write_figure;
use crate::analysis::spinup::{
    AXIS_RATIO_THRESHOLD, CriticalLimits, DensityFit, FailureMode, critical_limits, dynamical_time, first_departure,
    fit_density, smoothed_critical_limits,
};
use crate::analysis::spinup_diagnostics::{SpinupSample, read_spinup_csv};
use crate::io::scene_file::SI_G;

/// Zhang17 Table 1: the nominal mass of the Didymos primary (kg), the reference of `ρ_B = 2100 M/M_P`.
pub const DIDYMOS_MASS: f64 = 5.23e11;

/// T_c,3 (h) and φ (°) under one creep criterion, either missing when that criterion found no stable hold.
pub type LimitAndAngle = (Option<f64>, Option<f64>);

/// One row of [`TABLE3`]: model, η, φ (°), T_c1, T_c2, T_c3 (h), κ₃, failure mode.
pub type PaperRow = (&'static str, f64, f64, f64, f64, f64, Option<f64>, &'static str);

/// Zhang17 Table 3 (nominal material, path 1) and the κ₃ of §4.2.
pub const TABLE3: [PaperRow; 6] = [
    ("hcp", 0.739, 43.0, 2.38, 2.36, 2.40, Some(0.946), "surface shedding"),
    ("rcp", 0.641, 30.0, 2.51, 2.53, 2.83, Some(0.806), "internal failure"),
    // Zhang17 §4.1 names RCPC the exception: its shell sheds while the body deforms (T_c1 = T_c2), neither of the
    // two modes alone.
    ("rcpc", 0.695, 32.0, 2.46, 2.46, 2.76, None, "shedding with deformation"),
    ("pp1", 0.820, 39.0, 2.41, 2.44, 2.53, Some(0.902), "internal failure"),
    ("pp2", 0.750, 38.0, 2.41, 2.44, 2.54, None, "internal failure"),
    ("ppc", 0.820, 39.0, 2.46, 2.41, 2.49, None, "surface shedding"),
];

/// One row of [`TABLE4`]: model and, for limits 1, 2, 3, the critical bulk density (kg/m³) and κ.
pub type Table4Row = (&'static str, [(f64, f64); 3]);

/// Zhang17 Table 4: critical bulk densities at the Didymos period and κ of Eq. 22, per limit.
pub const TABLE4: [Table4Row; 6] = [
    ("hcp", [(2349.0, 0.953), (2269.0, 0.970), (2383.0, 0.946)]),
    ("rcp", [(2583.0, 0.909), (2662.0, 0.895), (3284.0, 0.806)]),
    ("rcpc", [(2478.0, 0.928), (2478.0, 0.928), (3077.0, 0.833)]),
    ("pp1", [(2388.0, 0.945), (2443.0, 0.935), (2626.0, 0.902)]),
    ("pp2", [(2419.0, 0.939), (2457.0, 0.932), (2662.0, 0.895)]),
    ("ppc", [(2469.0, 0.930), (2378.0, 0.947), (2519.0, 0.920)]),
];

/// Zhang17: the observed spin period of the Didymos primary (h), at which critical bulk densities are given.
pub const DIDYMOS_PERIOD_HOURS: f64 = 2.26;

/// The model a run directory belongs to: `rcp_rho1800` → `rcp` (bulk-density variants are `<model>_rho<ρ_B>`).
///
/// ```
/// use rubblepile::studies::zhang2017::report::base_model;
/// assert_eq!(base_model("rcp_rho1800"), "rcp");
/// assert_eq!(base_model("hcp"), "hcp");
/// ```
pub fn base_model(name: &str) -> &str {
    name.split("_rho").next().unwrap_or(name)
}

/// One model over its bulk densities: the points (ρ_B in kg/m³, T_c1, T_c2, T_c3 in h where found) and the
/// Eq. 22 fit of each limit over the points that have it.
#[derive(Debug, Clone, PartialEq)]
pub struct DensitySeries {
    /// Model name.
    pub model: String,
    /// (ρ_B, [T_c1, T_c2, T_c3]) by increasing density.
    pub points: Vec<(f64, [Option<f64>; 3])>,
    /// Fit of limit i (κ_i ± σ, critical bulk density at [`DIDYMOS_PERIOD_HOURS`]) over at least 2 densities.
    pub fits: [Option<DensityFit>; 3],
}

/// The bulk density of a row (kg/m³): `ρ_B = 2100 M/M_P` (Zhang17 §4.2).
fn bulk_density(row: &ModelRow) -> f64 {
    2100.0 * row.mass / DIDYMOS_MASS
}

/// The models run at two or more bulk densities, with their Eq. 22 fits (Zhang17 Fig. 19, Table 4).
pub fn density_series(rows: &[ModelRow]) -> Vec<DensitySeries> {
    let mut models: Vec<&str> = rows.iter().map(|r| base_model(&r.model)).collect();
    models.sort();
    models.dedup();
    let mut out = Vec::new();
    for m in models {
        let mut points: Vec<(f64, [Option<f64>; 3])> = rows
            .iter()
            .filter(|r| base_model(&r.model) == m && r.mass.is_finite())
            .map(|r| (bulk_density(r), [r.limits.t_c1_hours, r.limits.t_c2_hours, r.t_c3]))
            .collect();
        if points.len() < 2 {
            continue;
        }
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        let fits = [0, 1, 2].map(|i| {
            let xy: Vec<(f64, f64)> = points.iter().filter_map(|(rho, t)| t[i].map(|t| (*rho, t))).collect();
            (xy.len() >= 2)
                .then(|| fit_density(&xy, SI_G, DIDYMOS_PERIOD_HOURS))
                .flatten()
        });
        out.push(DensitySeries {
            model: m.to_string(),
            points,
            fits,
        });
    }
    out
}

/// RMS of the successive differences of `values` over √2 (the standard deviation of white noise; a slow trend
/// adds little); 0 with fewer than two values.
pub fn successive_scatter(values: &[f64]) -> f64 {
    if values.len() < 2 {
        return 0.0;
    }
    let sum: f64 = values.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum();
    (sum / (values.len() - 1) as f64 / 2.0).sqrt()
}

/// Whether η_B with sample scatter `noise`, averaged over a window of `window` s of samples `spacing` s apart,
/// resolves the T_c,2 threshold: the scatter of the mean, `noise/√(window/spacing)`, must be below half of
/// [`crate::analysis::spinup::PACKING_THRESHOLD`]. The report reads single samples (`window == spacing`), which
/// the scaled runs with the rotation-free open test resolve (sample scatter 2.6e-5 to 1.0e-4, 23 Nov 2026).
pub fn t_c2_resolved(noise: f64, window: f64, spacing: f64) -> bool {
    let samples = (window / spacing).max(1.0);
    noise / samples.sqrt() < 0.5 * crate::analysis::spinup::PACKING_THRESHOLD
}

/// One model's row.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ModelRow {
    /// Model name (directory).
    pub model: String,
    /// Particles.
    pub n: usize,
    /// Smallest and largest particle radius (m).
    pub radius_range: (f64, f64),
    /// Total mass (kg).
    pub mass: f64,
    /// η_B at t_start.
    pub packing: f64,
    /// T_c1, T_c2 and the failure mode from the samples themselves (the paper's rule as written).
    pub limits: CriticalLimits,
    /// The same from b/a, c/a and η_B averaged over the body's dynamical time ([`smoothed_critical_limits`]):
    /// a check on the sampled values, biased towards longer periods by the window's look-ahead.
    pub limits_smoothed: CriticalLimits,
    /// Sample-to-sample scatter of η_B while forced and before the shape changes: the RMS of successive
    /// differences over √2 (for white noise, its standard deviation).
    pub packing_noise: f64,
    /// Whether that scatter of single samples is below half the T_c,2 threshold, so that T_c,2 measures the
    /// packing and not the scatter ([`t_c2_resolved`] with a window of one sample).
    pub t_c2_resolved: bool,
    /// T_c,3 (h) and φ (°) from `critical.json`.
    pub t_c3: Option<f64>,
    /// See `t_c3`.
    pub phi: Option<f64>,
    /// T_c,3 (h) and φ (°) by the paper's creep criterion and by ours, from a `critical.json` that records both
    /// (searches made after the paper's criterion came in; [`crate::analysis::creep`]); `None` for older ones.
    pub t_c3_by_criterion: Option<[LimitAndAngle; 2]>,
    /// κ₃ of Eq. 22.
    pub kappa3: Option<f64>,
    /// Largest |T/T_path − 1| while forced.
    pub path_error: f64,
    /// Largest |T/T_path − 1| while forced and before T_c,1 (before the shape changes; the angular-momentum
    /// rule lets a body that has started to expand spin slower than the path, see `granular::soft::spinup`).
    pub path_error_before_t_c1: f64,
    /// Time the forcing was released (s), if it was.
    pub release_time: Option<f64>,
    /// Largest overlap / radius.
    pub max_overlap: f64,
    /// Largest energy and angular-momentum residuals of the run (`summary.json`), forcing work and torque
    /// booked; `None` for runs made before the forcing was booked (their residuals include the forcing).
    pub residuals: Option<(f64, f64)>,
    /// Wall time (s), simulated time (s), status.
    pub wall_seconds: f64,
    /// See `wall_seconds`.
    pub final_time: f64,
    /// See `wall_seconds`.
    pub status: String,
}

fn t_start_of(dir: &Path) -> f64 {
    std::fs::read_to_string(dir.join("scene.toml"))
        .ok()
        .and_then(|t| t.parse::<toml::Table>().ok())
        .and_then(|t| t.get("spinup")?.get("t_start")?.as_float())
        .unwrap_or(0.0)
}

/// Smallest and largest radius (m), total mass (kg) and count of the particles at t = 0.
fn radii_and_mass(dir: &Path) -> Option<(f64, f64, f64, usize)> {
    let table = read_table(&dir.join("snapshots/0.csv"), Cells::Lenient).ok()?;
    let (km, kr) = (table.column("mass")?, table.column("radius")?);
    let (mut lo, mut hi, mut m, mut n) = (f64::INFINITY, 0.0f64, 0.0, 0);
    for v in table.rows.iter().filter(|v| v.len() > km.max(kr)) {
        m += v[km];
        lo = lo.min(v[kr]);
        hi = hi.max(v[kr]);
        n += 1;
    }
    (m > 0.0).then_some((lo, hi, m, n))
}

/// The `wall_seconds` of the last row of the run's `timeseries.csv` (cumulative over resumes): the wall time
/// so far of a run that has not finished.
fn last_wall_seconds(run: &Path) -> Option<f64> {
    let table = read_table(&run.join("timeseries.csv"), Cells::Lenient).ok()?;
    let col = table.column("wall_seconds")?;
    table.rows.last()?.get(col).copied().filter(|x| x.is_finite())
}

/// The scene's `t_end` (s) of a run directory.
pub(crate) fn t_end_of(dir: &Path) -> Option<f64> {
    std::fs::read_to_string(dir.join("scene.toml"))
        .ok()?
        .parse::<toml::Table>()
        .ok()?
        .get("scene")?
        .get("t_end")?
        .as_float()
}

/// Whether the run's `timeseries.csv` books the spin-up forcing (has the `forcing_work` column).
fn books_forcing(run: &Path) -> bool {
    read_header(&run.join("timeseries.csv")).is_ok_and(|h| h.iter().any(|c| c == "forcing_work"))
}

/// Reads one model's runs under `RUNS/<model>`: its path-2 run and its T_c,3 search.
pub fn model_row(model_dir: &Path) -> Result<(ModelRow, Vec<SpinupSample>), crate::analysis::AnalysisError> {
    path_row(model_dir, "path2")
}

/// Reads the run `RUNS/<model>/<path>` (e.g. `path1`, `path3`) and the T_c,3 search on that path
/// (`critical/` for path 2, `critical_<path>/` for the others).
pub fn path_row(model_dir: &Path, path: &str) -> Result<(ModelRow, Vec<SpinupSample>), crate::analysis::AnalysisError> {
    let model = model_dir
        .file_name()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    let run = model_dir.join(path);
    let samples = read_spinup_csv(&run.join("spinup.csv")).map_err(|e| e.to_string())?;
    let summary: serde_json::Value = std::fs::read_to_string(run.join("summary.json"))
        .ok()
        .and_then(|s| serde_json::from_str(&s).ok())
        .unwrap_or(serde_json::Value::Null);
    let t_start = t_start_of(&run);
    let forced: Vec<&SpinupSample> = samples.iter().filter(|s| s.t >= t_start && s.forcing).collect();
    let col = |f: fn(&SpinupSample) -> f64| forced.iter().map(|s| f(s)).collect::<Vec<f64>>();
    let limits = critical_limits(
        &col(|s| s.period_h),
        &col(|s| s.b_over_a),
        &col(|s| s.c_over_a),
        &col(|s| s.packing_fraction),
    );
    let (lo, hi, mass, n) = radii_and_mass(&run).unwrap_or((f64::NAN, f64::NAN, f64::NAN, 0));
    let rho_b = 2100.0 * mass / DIDYMOS_MASS;
    // the smoothing window of the check on the limits
    let window = dynamical_time(SI_G, rho_b);
    let limits_smoothed = smoothed_critical_limits(
        &col(|s| s.t),
        &col(|s| s.period_h),
        &col(|s| s.b_over_a),
        &col(|s| s.c_over_a),
        &col(|s| s.packing_fraction),
        window,
    );
    // the T_c,3 search of path 2 is `critical/`, that of another path `critical_<path>/`
    let search = if path == "path2" {
        "critical".to_string()
    } else {
        format!("critical_{path}")
    };
    let critical: Option<serde_json::Value> = std::fs::read_to_string(model_dir.join(search).join("critical.json"))
        .ok()
        .and_then(|s| serde_json::from_str(&s).ok());
    let t_c3 = critical.as_ref().and_then(|c| c["t_c3_hours"].as_f64());
    let phi = critical.as_ref().and_then(|c| c["friction_angle_deg"].as_f64());
    let t_c3_by_criterion = critical.as_ref().and_then(|c| {
        let get = |k: &str| {
            c.get(k)
                .map(|r| (r["t_c3_hours"].as_f64(), r["friction_angle_deg"].as_f64()))
        };
        Some([get("paper")?, get("ours")?])
    });
    let kappa3 = t_c3.and_then(|t| fit_density(&[(rho_b, t)], SI_G, t)).map(|f| f.kappa);
    let path_error = samples
        .iter()
        .filter(|s| s.forcing)
        .map(|s| (s.period_h / s.path_period_h - 1.0).abs())
        .fold(0.0, f64::max);
    let shape_change = [
        first_departure(&col(|s| s.b_over_a), AXIS_RATIO_THRESHOLD),
        first_departure(&col(|s| s.c_over_a), AXIS_RATIO_THRESHOLD),
    ]
    .into_iter()
    .flatten()
    .min()
    .unwrap_or(forced.len());
    let before: Vec<f64> = forced[..shape_change].iter().map(|s| s.packing_fraction).collect();
    let packing_noise = successive_scatter(&before);
    let spacing = match (forced.first(), forced.get(1)) {
        (Some(a), Some(b)) => b.t - a.t,
        _ => window,
    };
    // the limits are read from single samples: the window of the resolution test is one sample
    let resolved = t_c2_resolved(packing_noise, spacing, spacing);
    let path_error_before_t_c1 = forced[..shape_change]
        .iter()
        .map(|s| (s.period_h / s.path_period_h - 1.0).abs())
        .fold(0.0, f64::max);
    let release_time = samples.iter().find(|s| !s.forcing).map(|s| s.t);
    let row = ModelRow {
        path_error_before_t_c1,
        model,
        n,
        radius_range: (lo, hi),
        mass,
        packing: forced.first().map(|s| s.packing_fraction).unwrap_or(f64::NAN),
        limits,
        limits_smoothed,
        packing_noise,
        t_c2_resolved: resolved,
        t_c3,
        phi,
        t_c3_by_criterion,
        kappa3,
        path_error,
        release_time,
        max_overlap: summary["max_overlap_fraction"].as_f64().unwrap_or(f64::NAN),
        residuals: books_forcing(&run)
            .then(|| {
                summary["energy_error"]
                    .as_f64()
                    .zip(summary["angular_momentum_error"].as_f64())
            })
            .flatten(),
        wall_seconds: summary["wall_seconds"]
            .as_f64()
            .or_else(|| last_wall_seconds(&run))
            .unwrap_or(f64::NAN),
        final_time: samples.last().map(|s| s.t).unwrap_or(0.0),
        status: summary["status"]
            .as_str()
            .unwrap_or("running (no summary.json)")
            .to_string(),
    };
    Ok((row, samples))
}

pub(crate) fn opt(x: Option<f64>, digits: usize) -> String {
    x.map(|v| format!("{v:.digits$}")).unwrap_or_else(|| "–".into())
}

pub(crate) fn mode(m: Option<FailureMode>) -> &'static str {
    match m {
        Some(FailureMode::SurfaceShedding) => "surface shedding",
        Some(FailureMode::InternalFailure) => "internal failure",
        None => "–",
    }
}

/// Model directories under `runs` that hold `path2/spinup.csv`, sorted.
fn model_dirs(runs: &Path) -> Result<Vec<std::path::PathBuf>, String> {
    let mut models: Vec<_> = std::fs::read_dir(runs)
        .map_err(|e| format!("{}: {e}", runs.display()))?
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.join("path2/spinup.csv").is_file())
        .collect();
    models.sort();
    Ok(models)
}

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
        let ts = timeseries_worst(&m.join("path2"));
        let _ = writeln!(
            md,
            "| {} | {} | {:.2} | {:.4} | {} | {} | {} | {} | {:.0} / {} | {:.0} | {} | {} |",
            r.model.to_uppercase(),
            r.n,
            r.radius_range.1,
            r.packing,
            opt(r.limits.t_c1_hours, 3),
            opt(r.limits.t_c2_hours, 3),
            mode(r.limits.failure_mode),
            r.status,
            r.final_time,
            opt(t_end_of(&m.join("path2")), 0),
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
pub fn write_report(
    runs: &Path,
    full: Option<&Path>,
    paths: Option<&Path>,
    out: &Path,
    force: bool,
) -> Result<std::path::PathBuf, crate::analysis::AnalysisError> {
    let report = out.join("REPORT.md");
    if report.exists() && !force {
        return Err(format!("{} exists (use --force to overwrite it)", report.display()).into());
    }
    let models = model_dirs(runs)?;
    if models.is_empty() {
        return Err(format!("{}: no <model>/path2/spinup.csv found", runs.display()).into());
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
        "Generated by `rubblepile report zhang2017 {}{}{} --out {} --force` from the runs under `{}` (layout and \
         definitions: `src/studies/zhang2017/report.rs`; scenes and the commands that make the runs: \
         `analysis/zhang2017/README.md`). Do not edit by hand.\n",
        runs.display(),
        full.map(|f| format!(" --full {}", f.display())).unwrap_or_default(),
        paths.map(|p| format!(" --paths {}", p.display())).unwrap_or_default(),
        out.display(),
        runs.display()
    );
    let _ = writeln!(
        md,
        "Ours: T_c1/T_c2 from `spinup.csv` by the paper's rule as written: the first sample, after t_start and \
         while forced, at which b/a or c/a has changed by > 0.01, or η_B by > 0.001, from its value at t_start. \
         T_c2 is marked unresolved when the sample-to-sample scatter of η_B exceeds half that threshold. The \
         column 'smoothed' applies the rule to running means over the body's dynamical time 1/√(Gρ_B) ≈ 2700 s, a \
         check that the limits are not set by one sample; its look-ahead of half a window moves them to longer \
         periods by up to ≈ 0.05 h on path 2. η_B counts closed Voronoi cells by the rotation-free test \
         (`VoronoiCell::reaches`; the axis-aligned test used before 23 Nov 2026 made η_B wiggle by ±5e-4 with a \
         quarter of the spin period). T_c3/φ from `critical/critical.json` (`rubblepile spinup critical`), κ₃ of \
         Eq. 22 with ρ_B = 2100 M/M_P. Paper: Table 3 (path 1, full size; §4.3: T_c3 does not depend on the path, \
         T_c1 and T_c2 do — faster paths give shorter ones).\n"
    );
    let _ = writeln!(
        md,
        "| model | N | radius (m) | η_B | T_c1 (h) | T_c2 (h) | T_c3 (h) | φ (°) | κ₃ | failure mode | smoothed T_c1/T_c2, mode | paper η, φ, T_c1/2/3, κ₃, mode |"
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
            opt(r.limits.t_c1_hours, 3),
            if r.t_c2_resolved {
                opt(r.limits.t_c2_hours, 3)
            } else {
                format!(
                    "unresolved ({}; η_B scatter {:.1e})",
                    opt(r.limits.t_c2_hours, 3),
                    r.packing_noise
                )
            },
            opt(r.t_c3, 2),
            opt(r.phi, 1),
            opt(r.kappa3, 3),
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
    let _ = writeln!(
        md,
        "\nRadius scaling: the paper's HCP/RCP spheres are ≈ 10 m (42 062 and 36 523 particles in \
         the 780 m body) and PP1's 4–32 m; ours keep the body (D = 780 m, ρ_B = 2100 kg/m³) and use fewer, larger \
         particles (radius column), i.e. lengths scaled by (N_paper/N)^(1/3).\n"
    );
    write_criterion_section(&mut md, &nominal);
    let _ = writeln!(md, "## Runs\n");
    let _ = writeln!(
        md,
        "| model | status | simulated (s) | wall (s) | largest overlap / radius | largest \\|T/T_path − 1\\| while forced: before T_c1 / all | forcing released at (s) | energy / L residual |"
    );
    let _ = writeln!(md, "| --- | --- | --- | --- | --- | --- | --- | --- |");
    for r in &rows {
        let _ = writeln!(
            md,
            "| {} | {} | {:.0} | {:.0} | {:.2e} | {:.1e} / {:.1e} | {} | {} |",
            r.model.to_uppercase(),
            r.status,
            r.final_time,
            r.wall_seconds,
            r.max_overlap,
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
    if let Some(full) = full {
        write_full_section(&mut md, full, out)?;
    }
    if let Some(paths) = paths {
        crate::studies::zhang2017::paths::write_paths_section(&mut md, runs, paths)?;
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

/// T_c,3 and φ by both creep criteria (Zhang17 §3.3.3; [`crate::analysis::creep`]) for the models whose
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
        "Both verdicts on the same holds (`critical.json`): the paper's criterion counts a rising θ_max, a falling \
         η_B or a falling coordination number over the second half of a hold as creep; ours counts θ_max or η_B \
         moving either way and does not judge the coordination number (`src/analysis/creep.rs`).\n"
    );
    let _ = writeln!(
        md,
        "| model | paper's criterion: T_c3 (h), φ (°) | ours: T_c3 (h), φ (°) | paper Table 3: T_c3 (h), φ (°) |"
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
         (P = {DIDYMOS_PERIOD_HOURS} h).\n"
    );
    for s in &series {
        let _ = writeln!(md, "### {}\n", s.model.to_uppercase());
        let _ = writeln!(
            md,
            "| ρ_B (kg/m³) | T_c1 (h) | T_c2 (h) | T_c3 (h) | κ₁ | κ₂ | κ₃ (single point) |"
        );
        let _ = writeln!(md, "| --- | --- | --- | --- | --- | --- | --- |");
        for (rho, t) in &s.points {
            let kappa = |t: Option<f64>| {
                t.and_then(|t| fit_density(&[(*rho, t)], SI_G, DIDYMOS_PERIOD_HOURS))
                    .map(|f| f.kappa)
            };
            let _ = writeln!(
                md,
                "| {rho:.0} | {} | {} | {} | {} | {} | {} |",
                opt(t[0], 3),
                opt(t[1], 3),
                opt(t[2], 2),
                opt(kappa(t[0]), 3),
                opt(kappa(t[1]), 3),
                opt(kappa(t[2]), 3)
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
            let p = paper.map_or("–".to_string(), |p| format!("{:.3}, {:.0}", p.1[i].1, p.1[i].0));
            let _ = writeln!(md, "| T_c,{} | {n} | {fitted} | {p} |", i + 1);
        }
        let _ = writeln!(md);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
            residuals: None,
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
            row("rcp_rho2400", 2400.0, [period(0.9, 2400.0), period(0.85, 2400.0), None]),
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
        assert!(md.contains("| T_c,3 | 2 | 0.800 ± 0.000"), "{md}");
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
