//! The rows of the Zhang17 report: the paper's Tables 1, 3 and 4, and one spin-up run read into a [`ModelRow`]
//! (its critical limits, T_c,3 by both creep criteria, sizes, overlap, path error, wall time), shared by the report
//! (`report.rs`) and its spin-up-path section (`paths.rs`), which both read rows from here and not each other.
//! Zhang et al. (2017, Icarus 294), Tables 1, 3 and 4, §4.2.

use rubblepile::io::table::{Cells, read_header, read_table};
use std::path::Path;

use rubblepile::analysis::critical::read_critical;
use rubblepile::analysis::spinup::{
    AXIS_RATIO_THRESHOLD, CriticalLimits, DIDYMOS_MASS, DensityFit, FailureMode, PACKING_THRESHOLD, critical_limits,
    dynamical_time, first_departure, fit_density, smoothed_critical_limits,
};
use rubblepile::analysis::spinup_diagnostics::{SpinupSample, read_spinup_csv};
use rubblepile::io::scene_file::SI_G;

use super::body::{Body, body_of};
use super::settling::{SettlingWarning, settling_warnings};

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

/// The model a run directory belongs to: `rcp_rho1800` → `rcp` (bulk-density variants are `<model>_rho<ρ_B>`,
/// material variants `<model>_beta<β>_mus<μ_s>`, Table 7).
pub fn base_model(name: &str) -> &str {
    let name = name.split("_rho").next().unwrap_or(name);
    if is_material_variant(name) {
        name.split("_beta").next().unwrap_or(name)
    } else {
        name
    }
}

/// Whether a run directory's name is a material variant (`<model>_beta<β>_mus<μ_s>`, Zhang17 Table 7).
pub fn is_material_variant(name: &str) -> bool {
    name.split_once("_beta").is_some_and(|(_, rest)| rest.contains("_mus"))
}

/// The limits fitted over bulk densities: T_c,1, T_c,2, T_c,3 by the paper's creep criterion and by ours.
pub const DENSITY_LIMITS: usize = 4;

/// One model over its bulk densities: the points (ρ_B in kg/m³, T_c1, T_c2, T_c3 by the paper's creep criterion
/// and T_c3 by ours, in h where found) and the Eq. 22 fit of each limit over the points that have it.
#[derive(Debug, Clone, PartialEq)]
pub struct DensitySeries {
    /// Model name.
    pub model: String,
    /// (ρ_B, [T_c1, T_c2, T_c3 paper-tolerance, T_c3 ours]) by increasing density.
    pub points: Vec<(f64, [Option<f64>; DENSITY_LIMITS])>,
    /// Fit of limit i (κ_i ± σ, critical bulk density at [`DIDYMOS_PERIOD_HOURS`]) over at least 2 densities.
    pub fits: [Option<DensityFit>; DENSITY_LIMITS],
}

/// The bulk density of a row (kg/m³): `ρ_B = 2100 M/M_P` (Zhang17 §4.2).
pub(crate) fn bulk_density(row: &ModelRow) -> f64 {
    2100.0 * row.mass / DIDYMOS_MASS
}

/// The models run at two or more bulk densities, with their Eq. 22 fits (Zhang17 Fig. 19, Table 4); material
/// variants ([`is_material_variant`]) are another material, not another density, and are left out.
pub fn density_series(rows: &[ModelRow]) -> Vec<DensitySeries> {
    let rows: Vec<&ModelRow> = rows.iter().filter(|r| !is_material_variant(&r.model)).collect();
    let mut models: Vec<&str> = rows.iter().map(|r| base_model(&r.model)).collect();
    models.sort();
    models.dedup();
    let mut out = Vec::new();
    for m in models {
        let mut points: Vec<(f64, [Option<f64>; DENSITY_LIMITS])> = rows
            .iter()
            .filter(|r| base_model(&r.model) == m && r.mass.is_finite())
            .map(|r| {
                let ours = r.t_c3_by_criterion.and_then(|[_, ours]| ours.0);
                (
                    bulk_density(r),
                    [r.limits.t_c1_hours, r.limits.t_c2_hours, r.t_c3, ours],
                )
            })
            .collect();
        if points.len() < 2 {
            continue;
        }
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        let fits = std::array::from_fn(|i| {
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
/// [`rubblepile::analysis::spinup::PACKING_THRESHOLD`]. The report reads single samples (`window == spacing`), which
/// the scaled runs with the rotation-free open test resolve (`analysis/zhang2017/MODULE_NOTES.md`).
pub fn t_c2_resolved(noise: f64, window: f64, spacing: f64) -> bool {
    let samples = (window / spacing).max(1.0);
    noise / samples.sqrt() < 0.5 * rubblepile::analysis::spinup::PACKING_THRESHOLD
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
    /// T_c,3 (h) and φ (°) from `critical.json` by the paper's creep criterion with tolerances (`paper-tolerance`),
    /// the rule of the searches made before Dec 2026 that the report's tables keep.
    pub t_c3: Option<f64>,
    /// See `t_c3`.
    pub phi: Option<f64>,
    /// T_c,3 (h) and φ (°) by the paper-tolerance creep criterion and by ours, from a `critical.json` that records both
    /// (searches made after the paper's criterion came in; [`rubblepile::analysis::creep`]); `None` for older ones.
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
    /// Largest sampled overlap / radius (`timeseries.csv`) up to the sample at which the later of T_c,1 and T_c,2
    /// was found (all forced samples when neither was): the overlaps of the part of the run that sets them, before
    /// the failure's collisions (Zhang17 §2.3.3 keeps overlaps under 1 % of the smallest radius).
    pub max_overlap_before_failure: Option<f64>,
    /// Largest energy and angular-momentum residuals of the run (`summary.json`), forcing work and torque
    /// booked; `None` for runs made before the forcing was booked (their residuals include the forcing).
    pub residuals: Option<(f64, f64)>,
    /// The body's size and bulk density read from the run ([`crate::studies::zhang2017::body`]), if found.
    pub body: Option<Body>,
    /// T_c,1 / T_c,2 read within the body's settling ([`crate::studies::zhang2017::settling`]).
    pub settling: Vec<SettlingWarning>,
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

/// The file of a compact run directory (no snapshots; `analysis/zhang2017/compact.py`) that keeps what
/// [`radii_mass_and_volume`] reads from the first snapshot: `n`, `radius_min_m`, `radius_max_m`, `mass_kg`.
pub const PARTICLES_SUMMARY: &str = "particles.json";

/// Smallest and largest radius (m), total mass (kg), count and volume Σ (4/3)π r³ (m³) of the particles at t = 0:
/// from the first snapshot, or from [`PARTICLES_SUMMARY`] in a compact run directory that keeps no snapshots (the
/// volume there only when the grains are all of one radius).
fn radii_mass_and_volume(dir: &Path) -> Option<(f64, f64, f64, usize, Option<f64>)> {
    let ball = |r: f64| 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
    if !dir.join("snapshots/0.csv").is_file() {
        let text = std::fs::read_to_string(dir.join(PARTICLES_SUMMARY)).ok()?;
        let v: serde_json::Value = serde_json::from_str(&text).ok()?;
        let n = usize::try_from(v["n"].as_u64()?).ok()?;
        let (lo, hi) = (v["radius_min_m"].as_f64()?, v["radius_max_m"].as_f64()?);
        let volume = (lo == hi).then(|| n as f64 * ball(lo));
        return Some((lo, hi, v["mass_kg"].as_f64()?, n, volume));
    }
    let table = read_table(&dir.join("snapshots/0.csv"), Cells::Lenient).ok()?;
    let (km, kr) = (table.column("mass")?, table.column("radius")?);
    let (mut lo, mut hi, mut m, mut n, mut volume) = (f64::INFINITY, 0.0f64, 0.0, 0, 0.0);
    for v in table.rows.iter().filter(|v| v.len() > km.max(kr)) {
        m += v[km];
        volume += ball(v[kr]);
        lo = lo.min(v[kr]);
        hi = hi.max(v[kr]);
        n += 1;
    }
    (m > 0.0).then_some((lo, hi, m, n, Some(volume)))
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

/// The largest `max_overlap_fraction` of the run's `timeseries.csv` rows at `t ≤ t_max` (s).
fn sampled_max_overlap(run: &Path, t_max: f64) -> Option<f64> {
    let table = read_table(&run.join("timeseries.csv"), Cells::Lenient).ok()?;
    let (t, o) = (table.column("t")?, table.column("max_overlap_fraction")?);
    table
        .rows
        .iter()
        .filter(|v| v.get(t).is_some_and(|&x| x <= t_max))
        .filter_map(|v| v.get(o).copied())
        .filter(|x| x.is_finite())
        .reduce(f64::max)
}

/// Whether the run's `timeseries.csv` books the spin-up forcing (has the `forcing_work` column).
fn books_forcing(run: &Path) -> bool {
    read_header(&run.join("timeseries.csv")).is_ok_and(|h| h.iter().any(|c| c == "forcing_work"))
}

/// Reads one model's runs under `RUNS/<model>`: its path-2 run and its T_c,3 search.
pub fn model_row(model_dir: &Path) -> Result<(ModelRow, Vec<SpinupSample>), rubblepile::analysis::AnalysisError> {
    path_row(model_dir, "path2")
}

/// Reads the run `RUNS/<model>/<path>` (e.g. `path1`, `path3`) and the T_c,3 search on that path
/// (`critical/` for path 2, `critical_<path>/` for the others).
pub fn path_row(
    model_dir: &Path,
    path: &str,
) -> Result<(ModelRow, Vec<SpinupSample>), rubblepile::analysis::AnalysisError> {
    let model = dir_name(model_dir);
    let run = run_dir(model_dir, path);
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
    let (lo, hi, mass, n, grains) = radii_mass_and_volume(&run).unwrap_or((f64::NAN, f64::NAN, f64::NAN, 0, None));
    let rho_b = 2100.0 * mass / DIDYMOS_MASS;
    let packing = forced.first().map(|s| s.packing_fraction).unwrap_or(f64::NAN);
    let body = body_of(&run, mass, grains, packing);
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
    // the sections made before Dec 2026 read the one-sided criterion with tolerances (`paper_tolerance`)
    let critical = read_critical(&model_dir.join(search));
    let t_c3 = critical
        .as_ref()
        .and_then(|c| c["paper_tolerance"]["t_c3_hours"].as_f64());
    let phi = critical
        .as_ref()
        .and_then(|c| c["paper_tolerance"]["friction_angle_deg"].as_f64());
    let t_c3_by_criterion = critical.as_ref().and_then(|c| {
        let get = |k: &str| {
            c.get(k)
                .map(|r| (r["t_c3_hours"].as_f64(), r["friction_angle_deg"].as_f64()))
        };
        Some([get("paper_tolerance")?, get("ours")?])
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
    let settling = settling_warnings(
        &col(|s| s.t),
        [
            (shape_change < forced.len()).then_some(shape_change),
            first_departure(&col(|s| s.packing_fraction), PACKING_THRESHOLD),
        ],
        dynamical_time(SI_G, body.map_or(rho_b, |b| b.bulk_density)),
    );
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
    let last_limit = [limits.t_c1_hours, limits.t_c2_hours]
        .into_iter()
        .flatten()
        .reduce(f64::min);
    let t_failure = match last_limit {
        Some(p) => forced.iter().find(|s| s.period_h <= p).map(|s| s.t),
        None => forced.last().map(|s| s.t),
    };
    let max_overlap_before_failure = t_failure.and_then(|t| sampled_max_overlap(&run, t));
    let row = ModelRow {
        max_overlap_before_failure,
        path_error_before_t_c1,
        model,
        n,
        radius_range: (lo, hi),
        mass,
        packing,
        body,
        settling,
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

/// The T_c1 or T_c2 cell `value` of `r`, marked when that limit was read within the body's settling.
pub(crate) fn flagged(r: &ModelRow, limit: &str, value: String) -> String {
    if r.settling.iter().any(|w| w.limit == limit) {
        format!("{value} ⚠ settling")
    } else {
        value
    }
}

/// One line on stderr per limit of `r` read within the body's settling (the report marks its cell).
pub(crate) fn warn_settling(r: &ModelRow) {
    for w in &r.settling {
        eprintln!("warning: {}", w.describe(&r.model.to_uppercase()));
    }
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

/// The model directories under `runs`, sorted by name: those with a `path2/spinup.csv` (this project's layout)
/// or with a `spinup.csv` directly in them (a user's `rubblepile run` of a spin-up scene); `runs` alone when it
/// is such a run directory itself. A T_c,3 search directory ([`is_search_dir`]) is refused with the layout expected:
/// its holds are not models.
pub fn model_dirs(runs: &Path) -> Result<Vec<std::path::PathBuf>, String> {
    if runs.join("spinup.csv").is_file() {
        return Ok(vec![runs.to_path_buf()]);
    }
    if is_search_dir(runs) {
        let base = if runs.join("base/spinup.csv").is_file() {
            format!("{}/base", runs.display())
        } else {
            "PATH2_RUN".to_string()
        };
        return Err(format!(
            "{0}: a `spinup critical` search directory (critical.json or hold runs T<period>/), not a directory of \
             models; the report reads RUNS/<model>/path2/ (the path-2 spin-up run) and RUNS/<model>/critical/ (its \
             search), e.g. mkdir -p R/rcp && ln -s \"$PWD/{base}\" R/rcp/path2 && ln -s \"$PWD/{0}\" R/rcp/critical, \
             then report zhang2017 R",
            runs.display()
        ));
    }
    let mut models: Vec<_> = std::fs::read_dir(runs)
        .map_err(|e| format!("{}: {e}", runs.display()))?
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.join("path2/spinup.csv").is_file() || p.join("spinup.csv").is_file())
        .collect();
    models.sort();
    Ok(models)
}

/// Whether `dir` is the output of `rubblepile spinup critical` (its `critical.json` or `critical.csv`, or its
/// `--branch` base run `base/` beside hold runs `T<period>/`) rather than a directory of models.
pub fn is_search_dir(dir: &Path) -> bool {
    let hold = |p: &Path| {
        p.join("spinup.csv").is_file()
            && p.file_name()
                .and_then(|n| n.to_str()?.strip_prefix('T')?.parse::<f64>().ok())
                .is_some()
    };
    dir.join("critical.json").is_file()
        || dir.join("critical.csv").is_file()
        || (dir.join("base/spinup.csv").is_file()
            && std::fs::read_dir(dir)
                .into_iter()
                .flatten()
                .filter_map(|e| e.ok())
                .any(|e| hold(&e.path())))
}

/// The run directory of `model_dir`'s spin-up path `path`: `model_dir/path`, or for path 2 `model_dir` itself
/// when it holds the `spinup.csv` directly (see [`model_dirs`]).
pub fn run_dir(model_dir: &Path, path: &str) -> std::path::PathBuf {
    let nested = model_dir.join(path);
    if path == "path2" && !nested.join("spinup.csv").is_file() && model_dir.join("spinup.csv").is_file() {
        model_dir.to_path_buf()
    } else {
        nested
    }
}

/// A directory's name (`.` and paths ending in `..` by their canonical name), the model's name of its row.
pub fn dir_name(dir: &Path) -> String {
    dir.file_name()
        .map(|s| s.to_os_string())
        .or_else(|| dir.canonicalize().ok()?.file_name().map(|s| s.to_os_string()))
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default()
}

/// The `critical*` subdirectories of `dir` (the T_c,3 searches of a run or variant: a coarse one, a finer one, …),
/// sorted by name; empty when there are none or `dir` cannot be read.
pub fn search_subdirs(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut subs: Vec<_> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.is_dir()
                && p.file_name()
                    .is_some_and(|n| n.to_string_lossy().starts_with("critical"))
        })
        .collect();
    subs.sort();
    subs
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bulk-density and material variants belong to their base model.
    #[test]
    fn a_variant_belongs_to_its_base_model() {
        assert_eq!(base_model("rcp_rho1800"), "rcp");
        assert_eq!(base_model("hcp_beta0.3_mus0.5"), "hcp");
        assert_eq!(base_model("hcp"), "hcp");
    }

    /// A material variant names both β and μ_s; a bulk-density variant is none.
    #[test]
    fn material_variants_name_beta_and_mu_s() {
        assert!(is_material_variant("pp2_beta0.6_mus1.3"));
        assert!(!is_material_variant("rcp_rho1800"));
    }
}
