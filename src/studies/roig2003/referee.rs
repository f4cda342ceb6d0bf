//! Roig et al. (2003, Icarus 165) after the referee: the rotational share of §4.1 against F0, the
//! inertia model, the targets' own spin and a target relaxed at the impact's κ; Fig. 4's exponents fitted
//! above a Δv floor and on the escaping fragments only; the seed scatter with the target realisation in it;
//! §4.2's "small fragments from the impact point".
//!
//! Two steps, so that the tables can be rebuilt from committed files without the runs:
//! 1. [`collect`] reads the runs of `analysis/roig2003/referee_runs.sh` (`runs/referee/<group>/<run>/`,
//!    each analysed at 400 s, and `runs/referee/equilibrium/<target>_<reading>/`) into one row per run
//!    ([`RefereeRun`]) and one per equilibrium snapshot ([`EquilibriumRow`]); [`write_csvs`] writes them as
//!    `referee_runs.csv` and `referee_equilibrium.csv`.
//! 2. [`write_report`] reads those two files and writes `REFEREE.md` (tables) and `figures/referee_f0.svg`
//!    (and `.png`): the rotational share and f_KE against F0 with the paper's ranges.
//!
//! The fragment quantities are those of [`rubblepile::analysis::fragments`] (the same call `rubblepile analyze`
//! makes); the new ones come from [`super::ejection_fits`], [`super::rotational_split`]
//! and [`super::pile_equilibrium`].

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use super::ejection_fits::{ejected_sites, ejection_fits, fit_above_floor};
use super::pile_equilibrium::pile_drift;
use super::rotational_split::rotational_split;
use crate::studies::csv_rows::{read_rows, write_rows};
use rubblepile::analysis::AnalysisError;
use rubblepile::analysis::figures::lines::{LineChart, Mark, Series};
use rubblepile::analysis::figures::style::write_figure;
use rubblepile::analysis::fits::{PowerLawFit, fit_power_law};
use rubblepile::analysis::fragments::{FragmentParams, analyse_fragments, pearson, read_snapshot_bodies};
use rubblepile::analysis::run_analysis::snapshot_path;
use rubblepile::ellipsoid::body::Body;
use rubblepile::ellipsoid::equations::G_SI;
use rubblepile::math::mean_std;

/// The Δv floor of the Fig. 4 fits (m/s): above the largest ejection speed a fragment of a 4 h pile gets from
/// the pile's turning alone over 400 s, `2 sin(Ω t/2) Ω R ≈ 8.5 m/s` at the apparent radius 110 km.
pub const FLOOR: f64 = 10.0;

/// The analysis time of every run (s): Roig03's 400 s, ≈ 300 s after the impact.
pub const T_AT: f64 = 400.0;

/// The run groups of `referee_runs.sh`, in the order the tables use.
pub const GROUPS: [&str; 6] = ["f0", "gaussian", "uniform", "relaxed", "realisations", "per_n"];

/// The smaller piles whose seed scatter group `per_n` measures with the target included (Table 1's N30_T4 and
/// N100_T4 beside their `--seed 2` and `--seed 3` realisations).
pub const PER_N_TARGETS: [&str; 2] = ["N30_T4", "N100_T4"];

/// One analysed run: its coordinates and the measures the tables need. NaN where a fit had too few points.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RefereeRun {
    /// The group (directory under `runs/referee/`): f0, gaussian, uniform, relaxed, realisations or per_n.
    pub group: String,
    /// The run's directory name.
    pub run: String,
    /// Target name (e.g. `N200_T4`, `N200_T4_s2`, `N200_T4_reduced`).
    pub target: String,
    /// Projectile preset (P1, P2, P3).
    pub projectile: String,
    /// Seed of the projectile's attitude.
    pub seed: u64,
    /// Dissipation coefficient F0 (s m⁻²).
    pub f0: f64,
    /// Inertia model: gaussian or uniform.
    pub inertia: String,
    /// κ of the run.
    pub kappa: f64,
    /// f_KE (fraction).
    pub f_ke: f64,
    /// Bound mass fraction (Eq. 43).
    pub bound_fraction: f64,
    /// Escaping target fragments.
    pub n_escaping: usize,
    /// `K_R / (K_T + K_R)`, `K_T` in the system's frame (fraction).
    pub rot_share: f64,
    /// The same with `K_T` in the target's barycentric frame.
    pub rot_share_target_frame: f64,
    /// `K_R,add / (K_T + K_R)` in the frame of the target's initial spin.
    pub added_share: f64,
    /// `K_R(0) / K_R(t_at)`.
    pub kr_initial_ratio: f64,
    /// Pre-existing fraction of `K_R` in the frame of the initial spin.
    pub pre_existing: f64,
    /// Pre-existing fraction of `K_R` against each fragment's own initial spin.
    pub pre_existing_per_fragment: f64,
    /// Ejection speed–size exponent, all target fragments, and its standard error.
    pub alpha_all: f64,
    /// Standard error of `alpha_all`.
    pub se_all: f64,
    /// Fragments in that fit.
    pub n_all: usize,
    /// Exponent over the fragments with `Δv > FLOOR`.
    pub alpha_floor: f64,
    /// Its standard error.
    pub se_floor: f64,
    /// Fragments above the floor.
    pub n_floor: usize,
    /// Exponent over the fragments with `Δv > v_esc/2`.
    pub alpha_half_escape: f64,
    /// Its standard error.
    pub se_half_escape: f64,
    /// Fragments above `v_esc/2`.
    pub n_half_escape: usize,
    /// Exponent over the escaping fragments.
    pub alpha_escaping: f64,
    /// Its standard error.
    pub se_escaping: f64,
    /// Spin–size exponent (corrected spins, as `rubblepile analyze`).
    pub spin_alpha: f64,
    /// Its standard error.
    pub spin_se: f64,
    /// corr(ln size, impact-site cosine) of the faster half (the report's measure).
    pub site_corr_fast: f64,
    /// The same over the fragments with `Δv > v_esc/2`.
    pub site_corr_ejected: f64,
    /// Fragments with `Δv > v_esc/2` from the impact hemisphere.
    pub ejected_near: usize,
    /// Fragments with `Δv > v_esc/2` from the antipodal hemisphere.
    pub ejected_far: usize,
    /// Median normalised size of the former.
    pub size_near: f64,
    /// Median normalised size of the latter.
    pub size_far: f64,
    /// corr(ln size, distance from the target's centre at t = 0 over R_eff), all target fragments.
    pub size_radius_corr: f64,
    /// Relative energy error of the run.
    pub energy_error: f64,
}

/// One snapshot of a target run alone ([`super::pile_equilibrium`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EquilibriumRow {
    /// Target name.
    pub target: String,
    /// Reading of Eq. 13 that set κ.
    pub reading: String,
    /// κ.
    pub kappa: f64,
    /// Time (s).
    pub time: f64,
    /// `K_rel / K`.
    pub non_rigid_fraction: f64,
    /// `K_rel` (J).
    pub kinetic_relative: f64,
    /// rms displacement from the initial rigid rotation (m).
    pub rms_displacement: f64,
    /// Largest displacement (m).
    pub max_displacement: f64,
    /// Relative energy error of the run.
    pub energy_error: f64,
}

fn read_text(path: &Path) -> Result<String, AnalysisError> {
    std::fs::read_to_string(path).map_err(|e| AnalysisError::Input(format!("{}: {e}", path.display())))
}

fn read_json(path: &Path) -> Result<serde_json::Value, AnalysisError> {
    serde_json::from_str(&read_text(path)?).map_err(|e| AnalysisError::Input(format!("{}: {e}", path.display())))
}

fn snapshot(dir: &Path, t: f64) -> Result<Vec<Body>, AnalysisError> {
    let path = snapshot_path(dir, t)
        .ok_or_else(|| AnalysisError::Input(format!("{}: no snapshot at t = {t} s", dir.display())))?;
    read_snapshot_bodies(&path).map_err(|e| AnalysisError::Input(format!("{}: {e}", path.display())))
}

fn number(json: &serde_json::Value, key: &str, path: &Path) -> Result<f64, AnalysisError> {
    json[key]
        .as_f64()
        .ok_or_else(|| AnalysisError::Input(format!("{}: no numeric `{key}`", path.display())))
}

/// `(target, projectile, seed)` from a run name `TARGET_Pk_zANGLE_sSEED[_fF0]`.
pub fn parse_run_name(name: &str) -> Option<(String, String, u64)> {
    let tokens: Vec<&str> = name.split('_').collect();
    let k = tokens
        .iter()
        .position(|t| t.len() == 2 && t.starts_with('P') && t[1..].chars().all(|c| c.is_ascii_digit()))?;
    let seed = tokens[k..]
        .iter()
        .find_map(|t| t.strip_prefix('s').and_then(|s| s.parse::<u64>().ok()))?;
    (k > 0).then(|| (tokens[..k].join("_"), tokens[k].to_string(), seed))
}

fn alpha(fit: &Result<PowerLawFit, rubblepile::analysis::fits::FitError>) -> (f64, f64, usize) {
    fit.as_ref()
        .map_or((f64::NAN, f64::NAN, 0), |f| (f.alpha, f.sigma_alpha, f.points))
}

/// The [`RefereeRun`] of the analysed impact run in `dir`, in `group`.
pub fn collect_run(dir: &Path, group: &str) -> Result<RefereeRun, AnalysisError> {
    let name = dir
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    let (target, projectile, seed) = parse_run_name(&name)
        .ok_or_else(|| AnalysisError::Input(format!("{}: not a TARGET_Pk_zANGLE_sSEED run name", dir.display())))?;
    let summary_path = dir.join("summary.json");
    let summary = read_json(&summary_path)?;
    let kappa = number(&summary, "kappa", &summary_path)?;
    let impact_path = dir.join("impact.json");
    let projectile_index = number(&read_json(&impact_path)?, "projectile_index", &impact_path)? as usize;
    let scene_path = dir.join("scene.toml");
    let scene = rubblepile::ellipsoid::scene::parse_toml(&read_text(&scene_path)?, &scene_path.display().to_string())
        .map_err(|e| AnalysisError::Input(e.to_string()))?;
    let g = scene.physics.gravity.and_then(|g| g.g).unwrap_or(G_SI);
    let (initial, at) = (snapshot(dir, 0.0)?, snapshot(dir, T_AT)?);
    let params = FragmentParams {
        kappa,
        inertia: scene.model.inertia,
        g,
        projectile: projectile_index,
        projectile_count: 1,
    };
    let report = analyse_fragments(&initial, &at, &params)
        .map_err(|e| AnalysisError::Input(format!("{}: {e}", dir.display())))?;
    let s = &report.summary;
    let kappa_i = scene.model.inertia.inertia_kappa(kappa);
    let split = rotational_split(&initial, &at, kappa_i, |i| i != projectile_index)
        .ok_or_else(|| AnalysisError::Input(format!("{}: no target fragments", dir.display())))?;
    let fits = ejection_fits(&report.fragments, FLOOR);
    let targets: Vec<_> = report.fragments.iter().filter(|f| !f.is_projectile).collect();
    let sizes: Vec<f64> = targets.iter().map(|f| f.size).collect();
    let speeds: Vec<f64> = targets.iter().map(|f| f.ejection_speed).collect();
    let spins: Vec<f64> = targets.iter().map(|f| f.spin_rate_corrected).collect();
    let half = fit_above_floor(&sizes, &speeds, 0.5 * s.escape_velocity);
    let sites = ejected_sites(&report.fragments, 0.5 * s.escape_velocity);
    let centre = {
        let bodies = initial.iter().enumerate().filter(|(i, _)| *i != projectile_index);
        let (r, m) = bodies.fold((rubblepile::math::Vec3::zeros(), 0.0), |(r, m), (_, b)| {
            (r + b.position * b.shape.mass, m + b.shape.mass)
        });
        r / m
    };
    let radii: Vec<f64> = targets
        .iter()
        .map(|f| (initial[f.index].position - centre).norm() / s.target_radius)
        .collect();
    let ln_sizes: Vec<f64> = sizes.iter().map(|x| x.ln()).collect();
    let ((a_all, se_all, n_all), (a_fl, se_fl, n_fl), (a_h, se_h, n_h), (a_e, se_e, _), (a_s, se_s, _)) = (
        alpha(&fits.all),
        alpha(&fits.above_floor),
        alpha(&half),
        alpha(&fits.escaping),
        alpha(&fit_power_law(&sizes, &spins)),
    );
    Ok(RefereeRun {
        group: group.to_string(),
        run: name,
        target,
        projectile,
        seed,
        f0: scene.physics.dissipation.map_or(0.0, |d| d.f0),
        inertia: format!("{:?}", scene.model.inertia).to_lowercase(),
        kappa,
        f_ke: s.f_ke,
        bound_fraction: s.bound_mass_fraction,
        n_escaping: s.n_escaping,
        rot_share: split.share(),
        rot_share_target_frame: split.share_target_frame(),
        added_share: split.added_share(),
        kr_initial_ratio: split.rotational_initial / split.rotational,
        pre_existing: split.pre_existing_fraction(),
        pre_existing_per_fragment: split.pre_existing_fraction_per_fragment(),
        alpha_all: a_all,
        se_all,
        n_all,
        alpha_floor: a_fl,
        se_floor: se_fl,
        n_floor: n_fl,
        alpha_half_escape: a_h,
        se_half_escape: se_h,
        n_half_escape: n_h,
        alpha_escaping: a_e,
        se_escaping: se_e,
        spin_alpha: a_s,
        spin_se: se_s,
        site_corr_fast: s.ejection_sites.size_cosine_correlation.unwrap_or(f64::NAN),
        site_corr_ejected: sites.size_cosine_correlation.unwrap_or(f64::NAN),
        ejected_near: sites.impact_side,
        ejected_far: sites.antipodal_side,
        size_near: sites.impact_side_median_size.unwrap_or(f64::NAN),
        size_far: sites.antipodal_side_median_size.unwrap_or(f64::NAN),
        size_radius_corr: pearson(&ln_sizes, &radii).unwrap_or(f64::NAN),
        energy_error: summary["energy_error"].as_f64().unwrap_or(f64::NAN),
    })
}

/// The [`EquilibriumRow`]s (one per snapshot after `t = 0`) of a target run alone in `dir`, named
/// `TARGET_READING`.
pub fn collect_equilibrium(dir: &Path) -> Result<Vec<EquilibriumRow>, AnalysisError> {
    let name = dir
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    let (target, reading) = name
        .rsplit_once('_')
        .ok_or_else(|| AnalysisError::Input(format!("{}: not a TARGET_READING name", dir.display())))?;
    let summary_path = dir.join("summary.json");
    let summary = read_json(&summary_path)?;
    let kappa = number(&summary, "kappa", &summary_path)?;
    let initial = snapshot(dir, 0.0)?;
    let mut rows = Vec::new();
    for t in [100.0, 200.0, 300.0, T_AT] {
        let at = snapshot(dir, t)?;
        let drift = pile_drift(&initial, &at, t, kappa)
            .ok_or_else(|| AnalysisError::Input(format!("{}: snapshots differ", dir.display())))?;
        rows.push(EquilibriumRow {
            target: target.to_string(),
            reading: reading.to_string(),
            kappa,
            time: t,
            non_rigid_fraction: drift.non_rigid_fraction,
            kinetic_relative: drift.kinetic_relative,
            rms_displacement: drift.rms_displacement,
            max_displacement: drift.max_displacement,
            energy_error: summary["energy_error"].as_f64().unwrap_or(f64::NAN),
        });
    }
    Ok(rows)
}

fn subdirs(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut out: Vec<_> = std::fs::read_dir(dir)
        .map(|e| e.flatten().map(|e| e.path()).filter(|p| p.is_dir()).collect())
        .unwrap_or_default();
    out.sort();
    out
}

/// Every analysed run under `runs` (`runs/<group>/<run>/` for the [`GROUPS`]) and every equilibrium run
/// (`runs/equilibrium/<target>_<reading>/`).
pub fn collect(runs: &Path) -> Result<(Vec<RefereeRun>, Vec<EquilibriumRow>), AnalysisError> {
    let mut out = Vec::new();
    for group in GROUPS {
        for dir in subdirs(&runs.join(group)) {
            if dir.join("analysis/analysis.json").exists() {
                out.push(collect_run(&dir, group)?);
            }
        }
    }
    let mut equilibrium = Vec::new();
    for dir in subdirs(&runs.join("equilibrium")) {
        if dir.join("summary.json").exists() {
            equilibrium.extend(collect_equilibrium(&dir)?);
        }
    }
    Ok((out, equilibrium))
}

/// Reads one of the two compact CSVs (rows of `T`).
pub fn read_csv<T: serde::de::DeserializeOwned>(path: &Path) -> Result<Vec<T>, AnalysisError> {
    read_rows(path)
}

/// Writes `out/referee_runs.csv` and `out/referee_equilibrium.csv`.
pub fn write_csvs(out: &Path, runs: &[RefereeRun], equilibrium: &[EquilibriumRow]) -> Result<(), AnalysisError> {
    write_rows(&out.join("referee_runs.csv"), runs)?;
    write_rows(&out.join("referee_equilibrium.csv"), equilibrium)
}

/// `mean ± sd` of the finite values with `digits` decimals (`–` when none).
fn mean_sd(values: &[f64], digits: usize) -> String {
    let v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return "–".into();
    }
    let (m, s) = mean_std(&v);
    format!("{m:.digits$} ± {s:.digits$}")
}

/// `mean ± sd` of a column over `rows`, scaled (100 for percentages).
fn column(rows: &[&RefereeRun], f: impl Fn(&RefereeRun) -> f64, scale: f64, digits: usize) -> String {
    mean_sd(&rows.iter().map(|r| f(r) * scale).collect::<Vec<_>>(), digits)
}

/// One statistics column of a table: a run's value, its scale (100 for percentages) and its decimals.
type Stat = (fn(&RefereeRun) -> f64, f64, usize);

/// A table row `| lead | runs | mean ± sd | … |` of `rows`, one cell per stat ([`column`]).
fn stats_row(md: &mut String, lead: &str, rows: &[&RefereeRun], stats: &[Stat]) {
    let cells: Vec<String> = stats
        .iter()
        .map(|&(f, scale, digits)| column(rows, f, scale, digits))
        .collect();
    let _ = writeln!(md, "| {lead} | {} | {} |", rows.len(), cells.join(" | "));
}

/// Roig03's Fig. 4 and Fig. 8 exponents (P1, P2, P3).
const PAPER_EJECTION: [(&str, f64); 3] = [("P1", -0.42), ("P2", -0.28), ("P3", -0.32)];
const PAPER_SPIN: [(&str, f64); 3] = [("P1", -1.09), ("P2", -1.11), ("P3", -1.13)];

fn select(runs: &[RefereeRun], keep: impl Fn(&RefereeRun) -> bool) -> Vec<&RefereeRun> {
    runs.iter().filter(|r| keep(r)).collect()
}

/// The rows of the target realisations of one projectile: the committed target (group gaussian) and the
/// two built with other seeds (group realisations).
fn realisation_rows<'a>(runs: &'a [RefereeRun], projectile: &str) -> Vec<&'a RefereeRun> {
    select(runs, |r| {
        r.projectile == projectile && (r.group == "gaussian" || r.group == "realisations")
    })
}

fn f0_table(runs: &[RefereeRun], md: &mut String) {
    let fig2 = |r: &RefereeRun| r.group == "f0" && r.projectile == "P2";
    let mut f0s: Vec<f64> = select(runs, fig2).iter().map(|r| r.f0).collect();
    f0s.sort_by(|a, b| b.total_cmp(a));
    f0s.dedup();
    md.push_str(
        "| F0 (s m⁻²) | runs | f_KE (%) | rot. share (%) | rot. share, K_T in the target's frame (%) | \
         impact's own K_R share (%) | bound fraction | escaping | ejection α | spin α |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    for f0 in f0s {
        let rows = select(runs, |r| fig2(r) && r.f0 == f0);
        let stats: [Stat; 8] = [
            (|r| r.f_ke, 100.0, 2),
            (|r| r.rot_share, 100.0, 1),
            (|r| r.rot_share_target_frame, 100.0, 1),
            (|r| r.added_share, 100.0, 1),
            (|r| r.bound_fraction, 1.0, 3),
            (|r| r.n_escaping as f64, 1.0, 0),
            (|r| r.alpha_all, 1.0, 2),
            (|r| r.spin_alpha, 1.0, 2),
        ];
        stats_row(md, &format!("{f0:.0e}"), &rows, &stats);
    }
}

fn split_table(runs: &[RefereeRun], md: &mut String) {
    md.push_str(
        "| runs (F0 = 1e-6) | projectile | runs | rot. share (%) | K_R(0) / K_R(400 s) (%) | pre-existing part of \
         K_R, frame of the initial spin (%) | pre-existing part, per fragment (%) | impact's own K_R share (%) |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    let label = |g: &str| match g {
        "gaussian" => "committed N200_T4, Gaussian moments",
        "uniform" => "committed N200_T4, uniform moments",
        "relaxed" => "N200_T4 relaxed at κ = 11.44",
        _ => "N200_T4 seeds 2, 3 (Gaussian)",
    };
    for group in ["gaussian", "uniform", "relaxed", "realisations"] {
        for (p, _) in PAPER_EJECTION {
            let rows = select(runs, |r| r.group == group && r.projectile == p);
            if rows.is_empty() {
                continue;
            }
            let stats: [Stat; 5] = [
                (|r| r.rot_share, 100.0, 1),
                (|r| r.kr_initial_ratio, 100.0, 2),
                (|r| r.pre_existing, 100.0, 2),
                (|r| r.pre_existing_per_fragment, 100.0, 2),
                (|r| r.added_share, 100.0, 1),
            ];
            stats_row(md, &format!("{} | {p}", label(group)), &rows, &stats);
        }
    }
}

/// A variant: its label and which runs belong to it.
type Variant<'a> = (&'a str, &'a dyn Fn(&RefereeRun) -> bool);

fn variant_table(runs: &[RefereeRun], variants: [Variant<'_>; 2], md: &mut String) {
    md.push_str(
        "| projectile | runs | f_KE (%) | rot. share (%) | bound fraction | ejection α | ejection α, escaping only | \
         spin α | κ |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for (p, _) in PAPER_EJECTION {
        for (label, keep) in variants {
            let rows = select(runs, |r| keep(r) && r.projectile == p);
            if rows.is_empty() {
                continue;
            }
            let stats: [Stat; 7] = [
                (|r| r.f_ke, 100.0, 2),
                (|r| r.rot_share, 100.0, 1),
                (|r| r.bound_fraction, 1.0, 3),
                (|r| r.alpha_all, 1.0, 2),
                (|r| r.alpha_escaping, 1.0, 2),
                (|r| r.spin_alpha, 1.0, 2),
                (|r| r.kappa, 1.0, 2),
            ];
            stats_row(md, &format!("{p}, {label}"), &rows, &stats);
        }
    }
}

fn equilibrium_table(rows: &[EquilibriumRow], md: &mut String) {
    md.push_str(
        "| target | reading (κ) | t (s) | K_rel / K | K_rel (J) | rms displacement from the rigid rotation (m) | \
         largest (m) | energy error |\n|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let _ = writeln!(
            md,
            "| {} | {} ({:.2}) | {:.0} | {:.2e} | {:.2e} | {:.1} | {:.1} | {:.1e} |",
            r.target,
            r.reading,
            r.kappa,
            r.time,
            r.non_rigid_fraction,
            r.kinetic_relative,
            r.rms_displacement,
            r.max_displacement,
            r.energy_error
        );
    }
}

/// `mean ± sd [σ mean fit error] (mean points)` of one fit over `rows`.
fn fit_cell(
    rows: &[&RefereeRun],
    alpha: fn(&RefereeRun) -> f64,
    sigma: fn(&RefereeRun) -> f64,
    points: fn(&RefereeRun) -> f64,
) -> String {
    let sigmas: Vec<f64> = rows.iter().map(|r| sigma(r)).filter(|x| x.is_finite()).collect();
    let mean_sigma = if sigmas.is_empty() {
        "–".to_string()
    } else {
        format!("{:.2}", mean_std(&sigmas).0)
    };
    format!(
        "{} [σ {mean_sigma}] ({})",
        column(rows, alpha, 1.0, 2),
        column(rows, points, 1.0, 0)
    )
}

fn fig4_table(runs: &[RefereeRun], md: &mut String) {
    md.push_str(
        "| projectile | target | runs | paper | all fragments | Δv > 10 m/s | Δv > v_esc/2 | escaping only |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    for (p, paper) in PAPER_EJECTION {
        let all = realisation_rows(runs, p);
        let mut targets: Vec<&str> = all.iter().map(|r| r.target.as_str()).collect();
        targets.dedup();
        let mut blocks: Vec<(String, Vec<&RefereeRun>)> = targets
            .iter()
            .map(|t| (t.to_string(), all.iter().copied().filter(|r| r.target == *t).collect()))
            .collect();
        blocks.push(("**all three**".into(), all.clone()));
        for (t, rows) in blocks {
            let _ = writeln!(
                md,
                "| {p} | {t} | {} | {paper:.2} | {} | {} | {} | {} |",
                rows.len(),
                fit_cell(&rows, |r| r.alpha_all, |r| r.se_all, |r| r.n_all as f64),
                fit_cell(&rows, |r| r.alpha_floor, |r| r.se_floor, |r| r.n_floor as f64),
                fit_cell(
                    &rows,
                    |r| r.alpha_half_escape,
                    |r| r.se_half_escape,
                    |r| r.n_half_escape as f64
                ),
                fit_cell(&rows, |r| r.alpha_escaping, |r| r.se_escaping, |r| r.n_escaping as f64),
            );
        }
    }
}

/// Within-target (over the projectile's seeds) and between-target standard deviations of one quantity.
fn scatter(rows: &[&RefereeRun], f: &dyn Fn(&RefereeRun) -> f64) -> (f64, f64, f64) {
    let mut by_target: BTreeMap<&str, Vec<f64>> = BTreeMap::new();
    for r in rows {
        by_target.entry(r.target.as_str()).or_default().push(f(r));
    }
    let within: Vec<f64> = by_target.values().map(|v| mean_std(v).1).collect();
    let means: Vec<f64> = by_target.values().map(|v| mean_std(v).0).collect();
    let all: Vec<f64> = rows.iter().map(|r| f(r)).collect();
    (mean_std(&within).0, mean_std(&means).1, mean_std(&all).1)
}

/// The seed-scatter table: for each projectile, the rows `rows_of(projectile)` (3 targets × 3 seeds).
fn scatter_table<'a>(rows_of: impl Fn(&str) -> Vec<&'a RefereeRun>, md: &mut String) {
    md.push_str(
        "| projectile | quantity | sd over the projectile's seeds (mean over 3 targets) | sd of the 3 targets' means | \
         sd over all 9 runs |\n|---|---|---|---|---|\n",
    );
    type Quantity = (&'static str, fn(&RefereeRun) -> f64, usize);
    let quantities: [Quantity; 6] = [
        ("bound fraction", |r| r.bound_fraction, 3),
        ("f_KE (%)", |r| 100.0 * r.f_ke, 2),
        ("rot. share (%)", |r| 100.0 * r.rot_share, 1),
        ("ejection α", |r| r.alpha_all, 2),
        ("ejection α, escaping only", |r| r.alpha_escaping, 2),
        ("spin α", |r| r.spin_alpha, 2),
    ];
    for (p, _) in PAPER_EJECTION {
        let rows = rows_of(p);
        for (name, f, d) in quantities {
            let (w, b, a) = scatter(&rows, &f);
            // A fit with too few points in some run (no escaping fragment) leaves no spread to show.
            let cell = |x: f64| {
                if x.is_finite() {
                    format!("{x:.d$}")
                } else {
                    "–".into()
                }
            };
            let _ = writeln!(md, "| {p} | {name} | {} | {} | {} |", cell(w), cell(b), cell(a));
        }
    }
}

/// Whether a target-name suffix after the base name marks the base target itself or one of its seed
/// realisations (`""`, `"_s2"`, `"_s3"`…), so that `N30_T4` does not also take `N30_T4_reduced`.
fn is_realisation(suffix: &str) -> bool {
    suffix.is_empty() || suffix.strip_prefix("_s").is_some_and(|s| s.parse::<u64>().is_ok())
}

/// One line per (target, projectile) cell of a per-N group: the outcome means ± sd over the seeds, so the
/// reader sees which target moves which number.
fn variant_summary(rows: &[&RefereeRun], md: &mut String) {
    let mut cells: BTreeMap<(&str, &str), Vec<&RefereeRun>> = BTreeMap::new();
    for r in rows {
        cells
            .entry((r.projectile.as_str(), r.target.as_str()))
            .or_default()
            .push(r);
    }
    md.push_str(
        "\n| projectile | target | runs | bound fraction | f_KE (%) | rot. share (%) | ejection α | spin α |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    for ((p, t), cell) in &cells {
        let _ = writeln!(
            md,
            "| {p} | {t} | {} | {} | {} | {} | {} | {} |",
            cell.len(),
            column(cell, |r| r.bound_fraction, 1.0, 3),
            column(cell, |r| r.f_ke, 100.0, 2),
            column(cell, |r| r.rot_share, 100.0, 1),
            column(cell, |r| r.alpha_all, 1.0, 2),
            column(cell, |r| r.spin_alpha, 1.0, 2),
        );
    }
}

fn spin_table(runs: &[RefereeRun], md: &mut String) {
    md.push_str(
        "| projectile | paper | N200_T4 (3 seeds) | 3 targets × 3 seeds | mean fit σ |\n|---|---|---|---|---|\n",
    );
    for (p, paper) in PAPER_SPIN {
        let all = realisation_rows(runs, p);
        let committed: Vec<&RefereeRun> = all.iter().copied().filter(|r| r.group == "gaussian").collect();
        let _ = writeln!(
            md,
            "| {p} | {paper:.2} | {} | {} | {} |",
            column(&committed, |r| r.spin_alpha, 1.0, 2),
            column(&all, |r| r.spin_alpha, 1.0, 2),
            column(&all, |r| r.spin_se, 1.0, 2),
        );
    }
}

fn sites_table(runs: &[RefereeRun], md: &mut String) {
    md.push_str(
        "| projectile | runs | corr(ln size, site cosine), faster half | the same, Δv > v_esc/2 | Δv > v_esc/2 from the \
         impact side / antipodal side | median size, impact side / antipodal side | corr(ln size, r₀/R_eff), all fragments |\n\
         |---|---|---|---|---|---|---|\n",
    );
    for (p, _) in PAPER_EJECTION {
        let rows = realisation_rows(runs, p);
        let _ = writeln!(
            md,
            "| {p} | {} | {} | {} | {} / {} | {} / {} | {} |",
            rows.len(),
            column(&rows, |r| r.site_corr_fast, 1.0, 2),
            column(&rows, |r| r.site_corr_ejected, 1.0, 2),
            column(&rows, |r| r.ejected_near as f64, 1.0, 0),
            column(&rows, |r| r.ejected_far as f64, 1.0, 0),
            column(&rows, |r| r.size_near, 1.0, 3),
            column(&rows, |r| r.size_far, 1.0, 3),
            column(&rows, |r| r.size_radius_corr, 1.0, 2),
        );
    }
}

/// The rotational share and f_KE of the Fig. 2 cell against 1/F0 (weaker dissipation to the right, so that the
/// legend sits over the small values), with the paper's ranges.
fn f0_figure(runs: &[RefereeRun]) -> LineChart {
    let rows = select(runs, |r| r.group == "f0" && r.projectile == "P2");
    let mut f0s: Vec<f64> = rows.iter().map(|r| r.f0).collect();
    f0s.sort_by(f64::total_cmp);
    f0s.dedup();
    let stats = |f: fn(&RefereeRun) -> f64| -> (Vec<(f64, f64)>, Vec<f64>) {
        f0s.iter()
            .map(|&f0| {
                let v: Vec<f64> = rows.iter().filter(|r| r.f0 == f0).map(|r| 100.0 * f(r)).collect();
                let (m, s) = mean_std(&v);
                ((1.0 / f0, m), s)
            })
            .unzip()
    };
    let points = |label: &str, (points, errors): (Vec<(f64, f64)>, Vec<f64>), colour| Series {
        label: label.into(),
        points,
        errors,
        colour,
        mark: Mark::Points,
    };
    let band = |label: &str, y: f64, colour| Series {
        label: label.into(),
        points: vec![(1.0 / f0s[f0s.len() - 1], y), (1.0 / f0s[0], y)],
        errors: vec![],
        colour,
        mark: Mark::Dashed,
    };
    LineChart {
        title: "N200_T4 + P2, ζ = 45°, 400 s: mean ± sd of 3 seeds per F0".into(),
        x_label: "1 / F0 (m² s⁻¹); the campaign: 1e6".into(),
        y_label: "per cent".into(),
        series: vec![
            points("rotational share of the fragment KE", stats(|r| r.rot_share), 0),
            points("f_KE", stats(|r| r.f_ke), 1),
            band("paper: rotational share 20 %", 20.0, 0),
            band("paper: rotational share 10 %", 10.0, 0),
            band("paper: f_KE 5 %", 5.0, 1),
            band("paper: f_KE 1 %", 1.0, 1),
        ],
        log_x: true,
    }
}

/// Reads `out/referee_runs.csv` and `out/referee_equilibrium.csv` and writes `out/REFEREE.md` and
/// `out/figures/referee_f0.{svg,png}`; returns the path of `REFEREE.md`.
pub fn write_report(out: &Path) -> Result<std::path::PathBuf, AnalysisError> {
    let runs: Vec<RefereeRun> = read_csv(&out.join("referee_runs.csv"))?;
    let equilibrium: Vec<EquilibriumRow> = read_csv(&out.join("referee_equilibrium.csv"))?;
    write_figure(&out.join("figures"), "referee_f0", &f0_figure(&runs))?;
    let mut md = String::new();
    md.push_str(
        "# Roig03 after the referee: the measurements\n\n\
         Generated by `analysis/roig2003/referee_tables.sh` from `referee_runs.csv` (one row per run) and \
         `referee_equilibrium.csv`, which it collects from the runs of `analysis/roig2003/referee_runs.sh` \
         (`runs/referee/`, not committed). Do not edit by hand: the verdicts are in `DISCUSSION.md`. Every run is \
         N200_T4-type (§8's second and third tables: N30_T4- and N100_T4-type) at ζ = 45°, κ from the reduced reading of Eq. 13, rtol 1e-6, analysed at t = 400 s; mean ± \
         sample standard deviation over the runs of a row.\n\n",
    );
    md.push_str("## 1. The rotational share against F0 (Fig. 2 cell: N200_T4 + P2, ζ = 45°, seeds 1–3)\n\n");
    f0_table(&runs, &mut md);
    md.push_str(
        "\nRoig03: f_KE 1–5 %, rotational share 10–20 %, bound fraction ≈ 1.04 − 0.2 × 1.5 = 0.74 at this Q, \
         ejection α −0.28, spin α −1.11.\n\n![rotational share and f_KE against 1/F0](figures/referee_f0.png)\n\n",
    );
    md.push_str("## 2. Whose rotation: K_R split into the targets' own spin and the impact's (F0 = 1e-6)\n\n");
    split_table(&runs, &mut md);
    md.push_str("\n## 3. Gaussian (Eq. 4) against uniform moments of inertia (committed N200_T4, 3 seeds)\n\n");
    let gaussian = |r: &RefereeRun| r.group == "gaussian";
    variant_table(
        &runs,
        [
            ("Gaussian", &gaussian),
            ("uniform", &|r: &RefereeRun| r.group == "uniform"),
        ],
        &mut md,
    );
    md.push_str(
        "\n## 4. The committed target against one relaxed at the impact's κ (seed 1 pile, 3 projectile seeds)\n\n",
    );
    variant_table(
        &runs,
        [
            ("committed", &gaussian),
            ("relaxed at κ = 11.44", &|r: &RefereeRun| r.group == "relaxed"),
        ],
        &mut md,
    );
    md.push_str("\n## 4b. The Fig. 2/4/8 cells at F0 = 1e-6 and 5e-7 s m⁻² (committed N200_T4, 3 seeds)\n\n");
    variant_table(
        &runs,
        [
            ("F0 = 1e-6", &gaussian),
            ("F0 = 5e-7", &|r: &RefereeRun| r.group == "f0" && r.f0 == 5e-7),
        ],
        &mut md,
    );
    md.push_str("\n## 5. The targets alone for 400 s at the impact's κ and at their own (F0 = 1e-6)\n\n");
    equilibrium_table(&equilibrium, &mut md);
    md.push_str(
        "\n## 6. Fig. 4: ejection speed–size exponents by which fragments are fitted (3 targets × 3 seeds)\n\n\
         Targets: the committed N200_T4 and two realisations built with `target build --seed 2` and `--seed 3`. \
         Each cell is the mean ± sd over the runs of α, fitted by least squares in (ln size, ln Δv), then [σ the \
         mean standard error of one run's fit] and (the mean number of fragments in the fit).\n\n",
    );
    fig4_table(&runs, &mut md);
    md.push_str("\n## 7. Fig. 8: spin–size exponents with the target in the scatter\n\n");
    spin_table(&runs, &mut md);
    md.push_str("\n## 8. Seed scatter: the projectile's attitude against the target realisation\n\n");
    scatter_table(|p| realisation_rows(&runs, p), &mut md);
    for base in PER_N_TARGETS {
        let rows_of = |p: &str| {
            select(&runs, |r| {
                r.group == "per_n" && r.projectile == p && r.target.strip_prefix(base).is_some_and(is_realisation)
            })
        };
        if rows_of("P1").is_empty() {
            continue;
        }
        let _ = writeln!(
            md,
            "\n### {base} and its two realisations (`target build --fragments {n} --seed 2`, `--seed 3`), ζ = 45°\n",
            n = base.trim_start_matches('N').split('_').next().unwrap_or(base)
        );
        scatter_table(rows_of, &mut md);
        variant_summary(
            &select(&runs, |r| {
                r.group == "per_n" && r.target.strip_prefix(base).is_some_and(is_realisation)
            }),
            &mut md,
        );
    }
    md.push_str(
        "\n## 9. §4.2: where the ejected fragments started (3 targets × 3 seeds)\n\n\
         Site cosine: the cosine between a fragment's position at t = 0 and the projectile's, both from the \
         target's barycentre (+1 at the impact point). A negative correlation with ln size is the paper's \
         \"small fragments from the impact point, large ones from the antipode\". The last column is the piles' \
         own structure: large fragments sit near the centre when it is negative.\n\n",
    );
    sites_table(&runs, &mut md);
    let path = out.join("REFEREE.md");
    std::fs::write(&path, md).map_err(|e| AnalysisError::Output(format!("{}: {e}", path.display())))?;
    Ok(path)
}

/// The collected rows with the committed CSVs' rows of every group that `rows` lacks (and the committed
/// equilibrium rows when none were collected), so that collecting one new group of runs keeps the others'
/// rows instead of dropping them. Groups present in `rows` replace their committed rows.
pub fn merge_with_committed(
    out: &Path,
    mut rows: Vec<RefereeRun>,
    equilibrium: Vec<EquilibriumRow>,
) -> Result<(Vec<RefereeRun>, Vec<EquilibriumRow>), AnalysisError> {
    let runs_csv = out.join("referee_runs.csv");
    if runs_csv.exists() {
        let fresh: std::collections::BTreeSet<String> = rows.iter().map(|r| r.group.clone()).collect();
        let kept: Vec<RefereeRun> = read_csv::<RefereeRun>(&runs_csv)?
            .into_iter()
            .filter(|r| !fresh.contains(&r.group))
            .collect();
        rows.extend(kept);
        let order = |g: &str| GROUPS.iter().position(|x| *x == g).unwrap_or(GROUPS.len());
        rows.sort_by(|a, b| (order(&a.group), &a.run).cmp(&(order(&b.group), &b.run)));
    }
    let equilibrium_csv = out.join("referee_equilibrium.csv");
    let equilibrium = if equilibrium.is_empty() && equilibrium_csv.exists() {
        read_csv(&equilibrium_csv)?
    } else {
        equilibrium
    };
    Ok((rows, equilibrium))
}

/// `rubblepile report roig2003-referee …`: the two steps of this module.
#[derive(Debug, clap::Subcommand)]
pub enum RefereeArgs {
    /// Read the runs of `analysis/roig2003/referee_runs.sh` under RUNS into OUT/referee_runs.csv and
    /// OUT/referee_equilibrium.csv.
    Collect {
        /// Directory of the referee runs (e.g. runs/referee).
        runs: std::path::PathBuf,
        /// Where the two CSVs go (e.g. analysis/roig2003).
        out: std::path::PathBuf,
    },
    /// Write OUT/REFEREE.md and OUT/figures/referee_f0.{svg,png} from OUT's two CSVs (no runs needed).
    Report {
        /// Directory holding referee_runs.csv and referee_equilibrium.csv (e.g. analysis/roig2003).
        out: std::path::PathBuf,
    },
}

/// Runs one step of [`RefereeArgs`] and says what it wrote.
pub fn referee_command(args: &RefereeArgs) -> Result<(), AnalysisError> {
    match args {
        RefereeArgs::Collect { runs, out } => {
            let (rows, equilibrium) = collect(runs)?;
            let (rows, equilibrium) = merge_with_committed(out, rows, equilibrium)?;
            write_csvs(out, &rows, &equilibrium)?;
            println!(
                "collected {} runs and {} equilibrium rows into {}",
                rows.len(),
                equilibrium.len(),
                out.display()
            );
        }
        RefereeArgs::Report { out } => println!("wrote {}", write_report(out)?.display()),
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn run_names_give_target_projectile_and_seed() {
        let parse = parse_run_name;
        assert_eq!(parse("N200_T4_P2_z45_s3"), Some(("N200_T4".into(), "P2".into(), 3)));
        assert_eq!(
            parse("N200_T4_s2_P1_z45_s1"),
            Some(("N200_T4_s2".into(), "P1".into(), 1))
        );
        assert_eq!(
            parse("N200_T4_P2_z45_s2_f3e-7"),
            Some(("N200_T4".into(), "P2".into(), 2))
        );
        assert_eq!(
            parse("N200_T4_reduced_P3_z45_s1"),
            Some(("N200_T4_reduced".into(), "P3".into(), 1))
        );
        assert_eq!(parse("P2_z45_s1"), None);
        assert_eq!(parse("N200_T4_printed"), None);
    }

    /// Guards `report roig2003-referee collect` against dropping committed rows: collecting one new group (here a
    /// `per_n` row) keeps every other group's committed rows in their order, and a collected group replaces its
    /// own committed rows.
    #[test]
    fn collecting_one_group_keeps_the_committed_rows_of_the_others() {
        let committed = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("analysis/roig2003");
        let rows: Vec<RefereeRun> = read_csv(&committed.join("referee_runs.csv")).unwrap();
        let equilibrium: Vec<EquilibriumRow> = read_csv(&committed.join("referee_equilibrium.csv")).unwrap();
        let committed_only: Vec<RefereeRun> = rows.iter().filter(|r| r.group != "per_n").cloned().collect();
        let dir = std::env::temp_dir().join(format!("rubblepile-referee-merge-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        write_csvs(&dir, &committed_only, &equilibrium).unwrap();

        let (same, eq) = merge_with_committed(&dir, Vec::new(), Vec::new()).unwrap();
        // Debug text, not `==`: the rows hold NaN where a fit had too few points.
        let text = |rows: &[RefereeRun]| format!("{rows:?}");
        assert!(
            text(&same) == text(&committed_only),
            "nothing collected: the committed rows, unchanged and in order"
        );
        assert_eq!(eq.len(), equilibrium.len());

        let mut new = committed_only[0].clone();
        new.group = "per_n".into();
        new.run = "N30_T4_P1_z45_s1".into();
        new.target = "N30_T4".into();
        let (merged, _) = merge_with_committed(&dir, vec![new.clone()], Vec::new()).unwrap();
        assert_eq!(merged.len(), committed_only.len() + 1);
        assert!(
            text(&merged[merged.len() - 1..]) == text(&[new]),
            "per_n sorts after the committed groups"
        );

        let mut replaced = committed_only[0].clone();
        replaced.f_ke = 0.5;
        let group = replaced.group.clone();
        let (merged, _) = merge_with_committed(&dir, vec![replaced.clone()], Vec::new()).unwrap();
        let in_group: Vec<&RefereeRun> = merged.iter().filter(|r| r.group == group).collect();
        assert_eq!(
            in_group,
            vec![&replaced],
            "a collected group replaces its committed rows"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
