//! Analysis of one impact run directory (Roig03 §4): per-fragment table and per-run results.
//!
//! Reads `summary.json` (κ; from `scene.toml` while the run is still going), `scene.toml` (inertia model, G),
//! `impact.json` (projectile) and the snapshots at t = 0 and at `t_at` (default 400 s, "a few minutes after the
//! impact", or the run's end when sooner); writes `analysis/fragments.csv` and `analysis/analysis.json` inside the
//! run directory. Fits that cannot be made (too few fragments, say) are recorded with their reason instead of stopping the analysis.
//!
//! The analysis locks what it writes, `analysis/` ([`lock_analysis`]), not the run directory, so a run still going
//! can be analysed while it writes.

use std::path::{Path, PathBuf};

use crate::analysis::clumps::{ClumpReport, ClumpSummary, DEFAULT_GAP_FRACTION, analyse_clumps};
use crate::analysis::composition::{Composition, Origin, composition};
use crate::analysis::fits::{ExponentComparison, PowerLawFit, SpinFit, compare_exponents, fit_power_law, histogram};
use crate::analysis::fragments::{FragmentParams, FragmentReport, analyse_fragments, read_snapshot_bodies};
use crate::analysis::spin_likelihood::{SpinLikelihood, Weights, fit_spin_likelihood};
use crate::ellipsoid::equations::G_SI;
use crate::io::run_lock::{DirLock, LockError};

/// Why a run could not be analysed. One line, naming the file.
#[derive(Debug, thiserror::Error)]
pub enum AnalysisError {
    /// Another rubblepile process writes the analysis directory ([`lock_analysis`]).
    #[error(transparent)]
    Locked(#[from] LockError),
    /// A file is missing or unreadable.
    #[error("{path}: {reason}")]
    Read {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// A file of the run is damaged (its manifest's checksum, a row cut short, a non-finite number).
    #[error("{reason}; not analysed")]
    Damaged {
        /// What is wrong, naming the file.
        reason: String,
    },
    /// The requested time is past the run's end (issue 57).
    #[error("{dir}: --at-s {t} s is past the run's end (t_end = {t_end} s)")]
    PastEnd {
        /// The run directory.
        dir: PathBuf,
        /// Requested time (s).
        t: f64,
        /// The run's end time (s).
        t_end: f64,
    },
    /// No snapshot at the requested time.
    #[error("{dir}: no snapshot at t = {t} s (snapshots at {available:?} s)")]
    NoSnapshot {
        /// The run directory.
        dir: PathBuf,
        /// Requested time (s).
        t: f64,
        /// Snapshot times found (s).
        available: Vec<f64>,
    },
    /// The analysis output exists already.
    #[error("{0}: exists; use --force to overwrite it")]
    Exists(PathBuf),
    /// The fragment analysis refused its input.
    #[error("{0}")]
    Fragments(String),
    /// A request that does not fit the campaign (an option naming a field or target it lacks).
    #[error("{0}")]
    Request(String),
    /// A report or its directory could not be written.
    #[error("{path}: {reason}")]
    Write {
        /// The file or directory.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
}

impl AnalysisError {
    /// An [`AnalysisError::Read`] of `path` saying `reason`.
    pub(crate) fn read(path: &Path, reason: impl std::fmt::Display) -> Self {
        AnalysisError::Read {
            path: path.to_path_buf(),
            reason: reason.to_string(),
        }
    }

    /// An [`AnalysisError::Write`] of `path` for the I/O error `e` ([`crate::io::safe_write::reason`]).
    pub(crate) fn write(path: &Path, e: &std::io::Error) -> Self {
        AnalysisError::Write {
            path: path.to_path_buf(),
            reason: crate::io::safe_write::reason(e),
        }
    }
}

/// A fit, or why it could not be made.
#[derive(Debug, Clone, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Fit<T> {
    /// The fit.
    Ok(T),
    /// Why not.
    Failed(String),
}

impl<T> Fit<T> {
    /// The fit of `r`, or its error's text.
    pub(crate) fn from<E: std::fmt::Display>(r: Result<T, E>) -> Self {
        match r {
            Ok(v) => Fit::Ok(v),
            Err(e) => Fit::Failed(e.to_string()),
        }
    }

    /// The fit, `None` when it failed.
    pub fn ok(&self) -> Option<&T> {
        match self {
            Fit::Ok(v) => Some(v),
            Fit::Failed(_) => None,
        }
    }
}

/// Per-run results (`analysis.json`).
#[derive(Debug, Clone, serde::Serialize)]
pub struct RunAnalysis {
    /// Time of the analysed snapshot (s).
    pub t_at: f64,
    /// κ of the run.
    pub kappa: f64,
    /// Energy partition, bound mass, v_esc, ejection statistics (see [`crate::analysis::fragments`]).
    pub summary: crate::analysis::fragments::FragmentSummary,
    /// Ejection speed vs normalised size, `|Δv| = c s^α` over target fragments (Fig. 4).
    pub ejection_speed_vs_size: Fit<PowerLawFit>,
    /// Corrected spin rate vs normalised size, `ω = c s^α` over spinning target fragments (Fig. 8).
    pub spin_vs_size: Fit<PowerLawFit>,
    /// Histogram of corrected spin rates (rad/s) of the target fragments: bin centres and counts (Fig. 6).
    pub spin_histogram: (Vec<f64>, Vec<f64>),
    /// Fits of `a xⁿ exp(−x²/b²)` to that histogram for n ∈ {0.5, 1, 1.5, 2} and free n (Eqs. 44–45).
    pub spin_fits: Fit<ExponentComparison>,
    /// Unbinned maximum-likelihood fits (Maxwellian and free n) of the same spin rates, each fragment counting once
    /// ([`crate::analysis::spin_likelihood`]).
    pub spin_likelihood: Fit<SpinLikelihood>,
    /// The same, each fragment weighted by its mass.
    pub spin_likelihood_by_mass: Fit<SpinLikelihood>,
    /// For a rubble-pile projectile only: clumps, largest remnant (mass, spin, composition) and mixing
    /// ([`crate::analysis::composition`]); its per-body table is `analysis/composition.csv`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub composition: Option<Composition>,
    /// The clumps of the analysed snapshot: the largest and second remnants and the counts
    /// ([`crate::analysis::clumps`]); the per-clump table is `analysis/clumps.csv`.
    #[serde(flatten)]
    pub clumps: ClumpSummary,
    /// Every clump (for `clumps.csv` and the size–frequency figure; not in `analysis.json`).
    #[serde(skip)]
    pub clump_report: ClumpReport,
}

impl RunAnalysis {
    /// The largest-remnant line ([`ClumpReport::summary_line`]) and, when the largest remnant holds more of the mass
    /// than the bound mass fraction, why: a clump bound to itself can move off faster than the system's escape speed,
    /// and Roig03's "bound" (README, "one meaning") is bound to the whole system's centre of mass.
    pub fn clump_lines(&self) -> String {
        let line = self.clump_report.summary_line();
        match self.clump_report.largest() {
            Some(lr) if lr.mass_fraction > self.summary.bound_mass_fraction + 0.05 => format!(
                "{line}\nnote: the largest remnant ({:.3} of all bodies' mass) is bound to itself, while only {:.3} of \
                 the target mass is bound to the system as a whole: the remnant moves off faster than the system's \
                 escape speed",
                lr.mass_fraction, self.summary.bound_mass_fraction
            ),
            _ => line,
        }
    }
}

/// `analysis.json` of a run that is not an impact (any ellipsoid run, soft or hard spheres): the clumps of one
/// snapshot.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ClumpRunAnalysis {
    /// Time of the analysed snapshot (s).
    pub t_at: f64,
    /// The largest and second remnants and the counts ([`crate::analysis::clumps`]).
    #[serde(flatten)]
    pub clumps: ClumpSummary,
    /// Every clump (for `clumps.csv` and the size–frequency figure; not in `analysis.json`).
    #[serde(skip)]
    pub clump_report: ClumpReport,
}

pub(crate) fn read_json(path: &Path) -> Result<serde_json::Value, AnalysisError> {
    let text = std::fs::read_to_string(path).map_err(|e| AnalysisError::read(path, e))?;
    serde_json::from_str(&text).map_err(|e| AnalysisError::read(path, e))
}

/// Refuses a snapshot of the run in `dir` that its manifest says is damaged, or that is cut short or holds a
/// non-finite number ([`crate::io::manifest::verify_file`]): one line naming it, never an analysis of it.
fn verified(dir: &Path, snapshot: &Path) -> Result<(), AnalysisError> {
    crate::io::manifest::verify_file(dir, snapshot, true).map_err(|reason| AnalysisError::Damaged { reason })
}

/// Snapshot times of a run directory, from the first line of each `snapshots/<k>.csv`.
fn snapshot_times(dir: &Path) -> Result<Vec<(f64, PathBuf)>, AnalysisError> {
    let snaps = dir.join("snapshots");
    let entries = std::fs::read_dir(&snaps).map_err(|e| AnalysisError::read(&snaps, e))?;
    let mut out = Vec::new();
    for entry in entries.flatten() {
        let path = entry.path();
        // A temporary file of a snapshot being written (crate::io::safe_write) is no snapshot yet.
        if path.extension().is_none_or(|e| e != "csv") || crate::io::safe_write::is_tmp_file(&entry.file_name()) {
            continue;
        }
        // Each is checked whole before its time is believed: a damaged or non-finite one is refused by name,
        // never passed over for another.
        verified(dir, &path)?;
        let mut rdr = csv::Reader::from_path(&path).map_err(|e| AnalysisError::read(&path, e))?;
        if let Some(Ok(rec)) = rdr.records().next()
            && let Some(t) = rec.get(0).and_then(|s| s.parse::<f64>().ok())
        {
            out.push((t, path));
        }
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(out)
}

/// The snapshot of `times` ([`snapshot_times`]) at time `t` (s, to 1e-9 relative), if there is one.
fn snapshot_at(times: &[(f64, PathBuf)], t: f64) -> Option<&(f64, PathBuf)> {
    times.iter().find(|(s, _)| (s - t).abs() <= 1e-9 * t.abs().max(1.0))
}

/// The snapshot of the run in `dir` at time `t` (s, to 1e-9 relative), if there is one.
pub fn snapshot_path(dir: &Path, t: f64) -> Option<PathBuf> {
    Some(snapshot_at(&snapshot_times(dir).ok()?, t)?.1.clone())
}

/// The κ the run in `dir` used: from its `summary.json`, or, while the run is still going (no summary yet, so that
/// the snapshots it has already written can be analysed), resolved from its `scene.toml` as the engine resolved
/// it at the start (given, or calibrated from the bodies by Roig03 Eq. 14).
fn run_kappa(dir: &Path) -> Result<f64, AnalysisError> {
    let summary_path = dir.join("summary.json");
    if summary_path.exists() {
        let summary = read_json(&summary_path)?;
        return summary["kappa"]
            .as_f64()
            .ok_or_else(|| AnalysisError::read(&summary_path, "no numeric `kappa`"));
    }
    let scene_path = dir.join("scene.toml");
    let scene = crate::ellipsoid::scene::load_scene(&scene_path).map_err(|e| {
        let why = format!("no summary.json (run not finished), and κ could not be resolved from the scene: {e}");
        AnalysisError::read(&scene_path, why)
    })?;
    Ok(scene.model.kappa)
}

/// Locks `dir/analysis/` for this process until the guard is dropped ([`crate::io::run_lock`]; the lock file is
/// `dir/.rubblepile-analysis.lock`), when `dir` holds `marker` (`scene.toml` for a run, `campaign.csv` for a
/// campaign): another directory is left to the reading to refuse, without a lock file left in it.
///
/// Errors: [`AnalysisError::Locked`] at once when another rubblepile process writes `dir/analysis/`.
pub fn lock_analysis(dir: &Path, marker: &str) -> Result<Option<DirLock>, AnalysisError> {
    if !dir.join(marker).is_file() {
        return Ok(None);
    }
    Ok(Some(DirLock::acquire_part(dir, "analysis")?))
}

/// Where an analysis of the run in `dir` goes: `out`, else `dir/analysis/`; and the lock of `dir/analysis/`
/// ([`lock_analysis`]) when it goes there (a run read elsewhere is only read).
fn analysis_out(dir: &Path, out: Option<&Path>) -> Result<(PathBuf, Option<DirLock>), AnalysisError> {
    match out {
        Some(o) => Ok((o.to_path_buf(), None)),
        None => Ok((dir.join("analysis"), lock_analysis(dir, "scene.toml")?)),
    }
}

/// The default analysis time of an impact run (s): Roig03's "a few minutes after the impact".
pub const DEFAULT_AT_S: f64 = 400.0;

/// The time `analyze` takes for the impact run in `dir` (s): `at` when given, else [`DEFAULT_AT_S`], or the run's
/// end (`scene.toml`'s `t_end`) when it ends sooner.
pub fn analysis_time(dir: &Path, at: Option<f64>) -> Result<f64, AnalysisError> {
    if let Some(at) = at {
        return Ok(at);
    }
    Ok(DEFAULT_AT_S.min(read_scene(dir)?.scene.t_end))
}

/// The ellipsoid scene of the run in `dir` (its `scene.toml`).
fn read_scene(dir: &Path) -> Result<crate::ellipsoid::scene::SceneFile, AnalysisError> {
    let scene_path = dir.join("scene.toml");
    let text = std::fs::read_to_string(&scene_path).map_err(|e| AnalysisError::read(&scene_path, e))?;
    crate::ellipsoid::scene::parse_toml(&text, &scene_path.display().to_string())
        .map_err(|e| AnalysisError::read(&scene_path, e))
}

/// Analyses the run in `dir` at `t_at` (s); writes `{fragments.csv, analysis.json}` into `out` (default
/// `dir/analysis/`) unless they exist (or `force`). Returns the per-run results and the per-fragment report.
pub fn analyze_run(
    dir: &Path,
    out: Option<&Path>,
    t_at: f64,
    force: bool,
) -> Result<(RunAnalysis, FragmentReport), AnalysisError> {
    let (out_dir, _lock) = analysis_out(dir, out)?;
    let (json_path, csv_path) = (out_dir.join("analysis.json"), out_dir.join("fragments.csv"));
    if !force && (json_path.exists() || csv_path.exists()) {
        return Err(AnalysisError::Exists(out_dir));
    }
    let kappa = run_kappa(dir)?;
    let impact = read_json(&dir.join("impact.json"))?;
    let projectile = impact["projectile_index"]
        .as_u64()
        .ok_or_else(|| AnalysisError::read(&dir.join("impact.json"), "no `projectile_index`"))?
        as usize;
    // A rubble-pile projectile: bodies `start..end` (crate::impact::pile::PileRecord).
    let pile_range = impact["projectile_pile"]["projectile_bodies"]
        .as_array()
        .and_then(|r| Some(r.first()?.as_u64()? as usize..r.get(1)?.as_u64()? as usize));
    let scene = read_scene(dir)?;
    if t_at > scene.scene.t_end * (1.0 + 1e-9) {
        return Err(AnalysisError::PastEnd {
            dir: dir.to_path_buf(),
            t: t_at,
            t_end: scene.scene.t_end,
        });
    }
    let g = scene.physics.gravity.and_then(|g| g.g).unwrap_or(G_SI);
    let times = snapshot_times(dir)?;
    let find = |t: f64| snapshot_at(&times, t).map(|(_, p)| p.clone());
    let missing = |t: f64| AnalysisError::NoSnapshot {
        dir: dir.to_path_buf(),
        t,
        available: times.iter().map(|x| x.0).collect(),
    };
    let (p0, pat) = (
        find(0.0).ok_or_else(|| missing(0.0))?,
        find(t_at).ok_or_else(|| missing(t_at))?,
    );
    let read = |p: &Path| {
        verified(dir, p)?;
        read_snapshot_bodies(p).map_err(|e| AnalysisError::read(p, e))
    };
    let (initial, at) = (read(&p0)?, read(&pat)?);
    let kappa_i = scene.model.inertia.inertia_kappa(kappa);
    let self_gravity = scene.physics.gravity.as_ref().map(|s| s.g.unwrap_or(G_SI));
    let clump_report = analyse_clumps(&at, DEFAULT_GAP_FRACTION, self_gravity, |b| {
        b.shape.principal_moments(kappa_i)
    });
    let params = FragmentParams {
        kappa,
        inertia: scene.model.inertia,
        g,
        projectile,
        projectile_count: pile_range.as_ref().map_or(1, |r| r.len()),
    };
    let report = analyse_fragments(&initial, &at, &params).map_err(|e| AnalysisError::Fragments(e.to_string()))?;
    let target: Vec<_> = report.fragments.iter().filter(|f| !f.is_projectile).collect();
    let sizes: Vec<f64> = target.iter().map(|f| f.size).collect();
    let speeds: Vec<f64> = target.iter().map(|f| f.ejection_speed).collect();
    let spins: Vec<f64> = target.iter().map(|f| f.spin_rate_corrected).collect();
    let (spin_histogram, spin_fits) = spin_histogram_fits(&spins);
    let masses: Vec<f64> = target.iter().map(|f| f.mass).collect();
    let analysis = RunAnalysis {
        t_at,
        kappa,
        summary: report.summary.clone(),
        ejection_speed_vs_size: Fit::from(fit_power_law(&sizes, &speeds)),
        spin_vs_size: Fit::from(fit_power_law(&sizes, &spins)),
        spin_fits,
        spin_histogram,
        spin_likelihood: Fit::from(fit_spin_likelihood(&spins, Weights::Number)),
        spin_likelihood_by_mass: Fit::from(fit_spin_likelihood(&spins, Weights::Mass(&masses))),
        composition: pile_range.and_then(|r| {
            let members: Vec<Vec<usize>> = clump_report.clumps.iter().map(|c| c.members.clone()).collect();
            composition(&at, r, &members, g, |b| b.shape.principal_moments(kappa_i))
        }),
        clumps: clump_report.summary(),
        clump_report,
    };
    crate::io::safe_write::ensure_dir(&out_dir).map_err(|e| AnalysisError::write(&out_dir, &e))?;
    write_fragments_csv(&csv_path, &report)?;
    if let Some(c) = &analysis.composition {
        write_composition_csv(&out_dir.join("composition.csv"), c)?;
    }
    write_text(&out_dir.join("clumps.csv"), &analysis.clump_report.csv())?;
    write_json(&json_path, &analysis)?;
    Ok((analysis, report))
}

/// Writes `text` to `path` atomically, never through a link ([`crate::io::safe_write`]).
pub(crate) fn write_text(path: &Path, text: &str) -> Result<(), AnalysisError> {
    crate::io::safe_write::write_atomic(path, text).map_err(|e| AnalysisError::write(path, &e))
}

/// Writes `value` to `path` as pretty-printed JSON with a final newline ([`write_text`]).
pub(crate) fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<(), AnalysisError> {
    write_text(path, &(serde_json::to_string_pretty(value).unwrap_or_default() + "\n"))
}

/// Whether `dir` holds an impact run (its `impact.json`, from `rubblepile impact`, a campaign or `run` of the
/// default scene), which [`analyze_run`] analyses in full; any other run gets [`analyze_clumps_run`].
pub fn is_impact_run(dir: &Path) -> bool {
    dir.join("impact.json").is_file()
}

/// The bodies of a snapshot of the run in `dir`, whatever its engine, with the gravitational constant of its
/// self-gravity (`None` without: a scene without gravity, a soft-sphere scene without `[gravity] self`, hard
/// spheres) and each body's principal moments (the run's inertia model for ellipsoids; uniform solid spheres,
/// `2/5 m r²`, for spheres, whose snapshots give the world-frame spin, kept as the body spin of an unrotated
/// body).
fn run_snapshot_bodies(
    dir: &Path,
    snapshot: &Path,
) -> Result<(Vec<crate::ellipsoid::body::Body>, Option<f64>, f64), AnalysisError> {
    use crate::driver::kind::SceneKind;
    let scene_path = dir.join("scene.toml");
    let text = std::fs::read_to_string(&scene_path).map_err(|e| AnalysisError::read(&scene_path, e))?;
    verified(dir, snapshot)?;
    match SceneKind::of_text(&text) {
        SceneKind::Ellipsoids => {
            let scene = crate::ellipsoid::scene::parse_toml(&text, &scene_path.display().to_string())
                .map_err(|e| AnalysisError::read(&scene_path, e))?;
            let kappa_i = scene.model.inertia.inertia_kappa(run_kappa(dir)?);
            let g = scene.physics.gravity.as_ref().map(|s| s.g.unwrap_or(G_SI));
            let bodies = read_snapshot_bodies(snapshot).map_err(|e| AnalysisError::read(snapshot, e))?;
            Ok((bodies, g, kappa_i))
        }
        kind => {
            let table: toml::Table = text.parse().map_err(|e| AnalysisError::read(&scene_path, e))?;
            let gravity = table.get("gravity");
            let g = (kind == SceneKind::SoftSpheres && gravity.and_then(|g| g.get("self")).is_some()).then(|| {
                gravity
                    .and_then(|g| g.get("G"))
                    .and_then(toml::Value::as_float)
                    .unwrap_or(G_SI)
            });
            let columns = ["mass", "radius", "x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz"];
            let rows = crate::io::particles::read_particles(snapshot, &columns, &[])
                .map_err(|e| AnalysisError::read(snapshot, e))?;
            let bodies = rows
                .iter()
                .map(|r| {
                    let v = &r.values;
                    crate::ellipsoid::body::Body {
                        shape: crate::ellipsoid::body::Ellipsoid {
                            axes: crate::math::Vec3::repeat(v[1]),
                            mass: v[0],
                        },
                        position: crate::math::Vec3::new(v[2], v[3], v[4]),
                        velocity: crate::math::Vec3::new(v[5], v[6], v[7]),
                        quaternion: crate::math::Vec4::new(0.0, 0.0, 0.0, 1.0),
                        spin_body: crate::math::Vec3::new(v[8], v[9], v[10]),
                    }
                })
                .collect();
            Ok((bodies, g, 2.5))
        }
    }
}

/// Analyses the clumps of the run in `dir` (any engine; [`crate::analysis::clumps`]) at its snapshot at `t_at`
/// (s; `None`: its last snapshot): writes `{clumps.csv, analysis.json}` into `out` (default `dir/analysis/`)
/// unless `analysis.json` exists (or `force`). The size–frequency figure is left to the caller
/// (`ClumpRunAnalysis::write_figure_and_describe`, in `analysis::figures::sfd`).
pub fn analyze_clumps_run(
    dir: &Path,
    out: Option<&Path>,
    t_at: Option<f64>,
    force: bool,
) -> Result<ClumpRunAnalysis, AnalysisError> {
    let (out_dir, _lock) = analysis_out(dir, out)?;
    let json_path = out_dir.join("analysis.json");
    if !force && json_path.exists() {
        return Err(AnalysisError::Exists(out_dir));
    }
    let times = snapshot_times(dir)?;
    let found = match t_at {
        Some(t) => snapshot_at(&times, t),
        None => times.last(),
    };
    let Some((t, snapshot)) = found.cloned() else {
        return Err(AnalysisError::NoSnapshot {
            dir: dir.to_path_buf(),
            t: t_at.unwrap_or(f64::NAN),
            available: times.iter().map(|x| x.0).collect(),
        });
    };
    let (bodies, g, kappa_i) = run_snapshot_bodies(dir, &snapshot)?;
    let report = analyse_clumps(&bodies, DEFAULT_GAP_FRACTION, g, |b| b.shape.principal_moments(kappa_i));
    let analysis = ClumpRunAnalysis {
        t_at: t,
        clumps: report.summary(),
        clump_report: report,
    };
    crate::io::safe_write::ensure_dir(&out_dir).map_err(|e| AnalysisError::write(&out_dir, &e))?;
    write_text(&out_dir.join("clumps.csv"), &analysis.clump_report.csv())?;
    write_json(&json_path, &analysis)?;
    Ok(analysis)
}

/// `composition.csv`: one row per body: its origin, its clump (0 = the largest remnant) and whether that is bound.
fn write_composition_csv(path: &Path, c: &Composition) -> Result<(), AnalysisError> {
    let mut text = String::from("index,origin,clump,clump_bound,clump_projectile_fraction\n");
    for (i, (origin, &k)) in c.origins.iter().zip(&c.clump_of).enumerate() {
        let origin = if *origin == Origin::Projectile {
            "projectile"
        } else {
            "target"
        };
        let clump = &c.clumps[k];
        text += &format!("{i},{origin},{k},{},{:e}\n", clump.bound, clump.projectile_fraction);
    }
    write_text(path, &text)
}

/// `fragments.csv`: one row per body.
fn write_fragments_csv(path: &Path, report: &FragmentReport) -> Result<(), AnalysisError> {
    let mut text = String::from(
        "index,is_projectile,mass,equivalent_radius,size,dvx,dvy,dvz,ejection_speed,kinetic_energy,rotational_energy,\
         binding_energy,escaping,spin_rate,spin_rate_corrected,effective_inertia,rotation_mode_measure,rotation_mode,\
         impact_site_cosine\n",
    );
    let opt = |x: Option<f64>| x.map_or_else(String::new, |x| format!("{x:e}"));
    for f in &report.fragments {
        let mode = serde_json::to_value(f.rotation_mode)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default();
        let [dvx, dvy, dvz] = f.ejection_velocity;
        text += &format!(
            "{},{},{:e},{:e},{:e},{dvx:e},{dvy:e},{dvz:e},{:e},{:e},{:e},{:e},{},{:e},{:e},{},{},{mode},{:e}\n",
            f.index,
            f.is_projectile,
            f.mass,
            f.equivalent_radius,
            f.size,
            f.ejection_speed,
            f.kinetic_energy,
            f.rotational_energy,
            f.binding_energy,
            f.escaping,
            f.spin_rate,
            f.spin_rate_corrected,
            opt(f.effective_inertia),
            opt(f.rotation_mode_measure),
            f.impact_site_cosine,
        );
    }
    write_text(path, &text)
}

/// One analysed run of a campaign (a row of `campaign_runs.csv`). Exponents and fit results are empty when the
/// run's fit failed (its `analysis.json` says why).
#[derive(Debug, Clone, serde::Serialize)]
pub struct CampaignRun {
    /// Run name (directory under the campaign directory).
    pub run: String,
    /// Target file stem.
    pub target: String,
    /// Projectile id.
    pub projectile: String,
    /// ζ (degrees).
    pub angle_deg: f64,
    /// Specific impact energy Q (erg/g).
    pub q_erg_per_g: f64,
    /// Number of target fragments.
    pub fragments: usize,
    /// Escaping target fragments (Eq. 43).
    pub escaping: usize,
    /// Fraction of the target mass that stays bound (Fig. 5).
    pub bound_mass_fraction: f64,
    /// Mass of the largest remnant (the most massive clump, [`crate::analysis::clumps`]) over the mass of all
    /// bodies; `None` when the snapshot has no bodies.
    pub largest_remnant_fraction: Option<f64>,
    /// Post-impact fragment kinetic energy over the projectile's.
    pub f_ke: f64,
    /// Rotational share of that energy.
    pub rotational_share: f64,
    /// Median ejection speed (m/s).
    pub ejection_speed_median: f64,
    /// Median ejection speed over the projectile speed.
    pub ejection_speed_median_relative: f64,
    /// Ejection speed vs size exponent (Fig. 4).
    pub ejection_exponent: Option<f64>,
    /// Its standard error.
    pub ejection_exponent_sigma: Option<f64>,
    /// Corrected spin rate vs size exponent (Fig. 8).
    pub spin_exponent: Option<f64>,
    /// Its standard error.
    pub spin_exponent_sigma: Option<f64>,
    /// The n ∈ {0.5, 1, 1.5, 2} with the smallest spin-histogram residual (Fig. 6).
    pub best_n: Option<f64>,
    /// Residual of the Maxwellian-like n = 2 fit over that of the best n (≥ 1).
    pub maxwellian_residual_ratio: Option<f64>,
    /// Free exponent n of the unbinned likelihood fit (by number; [`RunAnalysis::spin_likelihood`]).
    pub likelihood_n: Option<f64>,
    /// Lower end of its 95 % profile-likelihood interval.
    pub likelihood_n_low: Option<f64>,
    /// Upper end of that interval.
    pub likelihood_n_high: Option<f64>,
    /// KS p-value of the free-n likelihood fit.
    pub likelihood_ks_p: Option<f64>,
    /// KS p-value of the Maxwellian likelihood fit.
    pub maxwellian_ks_p: Option<f64>,
    /// AD p-value of the Maxwellian likelihood fit.
    pub maxwellian_ad_p: Option<f64>,
    /// Correlation of ln(size) with the impact-site cosine over the fast fragments (§4.2; < 0: small ones from
    /// the impact side).
    pub size_site_correlation: Option<f64>,
    /// Median size of the fast fragments from the impact hemisphere.
    pub impact_side_median_size: Option<f64>,
    /// Median size of the fast fragments from the antipodal hemisphere.
    pub antipodal_side_median_size: Option<f64>,
    /// The run's relative energy error (its `summary.json`).
    pub energy_error: Option<f64>,
    /// The run's wall-clock time (s; its `summary.json`).
    pub wall_seconds: Option<f64>,
}

/// The spin distribution of one projectile's runs (Roig03 Fig. 7): the corrected spin rates of the target
/// fragments of the selected runs, pooled into one histogram and fitted with Eq. 44 for n ∈ {0.5, 1, 1.5, 2} and
/// free n, and by unbinned likelihood. The curve of Fig. 7 is the best fixed-n fit normalised by Eq. 45
/// ([`SpinFit::density`]).
#[derive(Debug, Clone, serde::Serialize)]
pub struct SpinDistribution {
    /// Projectile id.
    pub projectile: String,
    /// Mean specific impact energy of the runs (erg/g).
    pub q_erg_per_g: f64,
    /// The runs pooled.
    pub runs: Vec<String>,
    /// How they were chosen: `"target T at zeta Z"` when the requested case exists, else
    /// `"target T, every angle (none at zeta Z)"`.
    pub selection: String,
    /// Number of spin rates pooled.
    pub fragments: usize,
    /// Histogram of the pooled corrected spin rates (rad/s): bin centres and counts.
    pub histogram: (Vec<f64>, Vec<f64>),
    /// Fits of Eq. 44 to it.
    pub fits: Fit<ExponentComparison>,
    /// Unbinned likelihood fits of the pooled rates (by number; [`crate::analysis::spin_likelihood`]).
    pub likelihood: Fit<SpinLikelihood>,
}

impl SpinDistribution {
    /// The best fixed-n fit (the curve of Fig. 7), if the fits succeeded.
    pub fn best(&self) -> Option<&SpinFit> {
        let c = self.fits.ok()?;
        c.fixed.iter().find(|f| f.n == c.best_n)
    }
}

/// Per-campaign results (`analysis/campaign_analysis.json` in the campaign directory).
#[derive(Debug, Clone, serde::Serialize)]
pub struct CampaignAnalysis {
    /// Time of the analysed snapshots (s).
    pub t_at: f64,
    /// The analysed (completed) runs.
    pub runs: Vec<CampaignRun>,
    /// Runs listed in `campaign.csv` but not completed, skipped.
    pub skipped: Vec<String>,
    /// The runs Q*_D and its line are fitted over: one target at one angle (`campaign_analysis::q_star_selection`).
    pub q_star_runs: QStarRuns,
    /// Bound mass fraction against Q (erg/g), least squares over [`Self::q_star_runs`] (Fig. 5).
    pub bound_fraction_vs_q: Fit<crate::analysis::fits::LineFit>,
    /// Q*_D: the Q at which that line gives a bound fraction of 0.5 (erg/g), with its propagated error.
    pub q_star_d: Fit<crate::analysis::fits::LineCrossing>,
    /// Q*_D with its bootstrap 95 % interval and the warning flag ([`crate::analysis::q_star_bootstrap`]).
    pub q_star_d_bootstrap: Fit<crate::analysis::q_star_bootstrap::QStarBootstrap>,
    /// Spin distributions per projectile, in the order the projectiles first appear (Fig. 7).
    pub spin_distributions: Vec<SpinDistribution>,
}

/// The runs of a campaign that Q*_D is fitted over (`campaign_analysis.json`'s `q_star_runs`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct QStarRuns {
    /// The target (file stem).
    pub target: String,
    /// The impact angle ζ (degrees); `None` when none could be chosen.
    pub angle_deg: Option<f64>,
    /// How many runs.
    pub runs: usize,
    /// Why no fit is made (several angles and none chosen, no run on the target); `None`: fitted.
    pub refused: Option<String>,
    /// Every run, pooled over targets and angles ([`SpinSelection::pool_q_star`]; Roig03 Fig. 5 fits its whole
    /// campaign at once); `target` and `angle_deg` are then not a restriction.
    pub pooled: bool,
}

impl QStarRuns {
    /// Whether `run` is one of them.
    pub fn holds(&self, run: &CampaignRun) -> bool {
        self.pooled || (run.target == self.target && Some(run.angle_deg) == self.angle_deg)
    }

    /// `N30_T4 at zeta = 45 deg, 6 runs` (what the fit is of).
    pub fn label(&self) -> String {
        if self.pooled {
            return format!("every run pooled over targets and angles, {} runs", self.runs);
        }
        match self.angle_deg {
            Some(a) => format!("{} at zeta = {a} deg, {} runs", self.target, self.runs),
            None => self.target.clone(),
        }
    }
}

impl CampaignAnalysis {
    /// Q*_D for a summary line: `Q ± σ erg/g (bootstrap 95 % interval low to high, seed s; TARGET at zeta = A deg,
    /// N runs)`, or why there is none.
    pub fn q_star_text(&self) -> String {
        let of = self.q_star_runs.label();
        match (&self.q_star_d, &self.q_star_d_bootstrap) {
            (Fit::Ok(c), Fit::Ok(b)) => format!(
                "{:.3e} ± {:.1e} erg/g (bootstrap 95 % interval {:.3e} to {:.3e}, seed {}; {of})",
                c.x, c.sigma_x, b.low, b.high, b.seed
            ),
            (Fit::Ok(c), Fit::Failed(why)) => {
                format!("{:.3e} ± {:.1e} erg/g (no bootstrap: {why}; {of})", c.x, c.sigma_x)
            }
            (Fit::Failed(why), _) => format!("n/a ({why}; {of})"),
        }
    }

    /// What a reader must be told: Q*_D underdetermined (fewer than two Q values on a side of it) or refused
    /// (several angles, none chosen), spin distributions pooled over every angle for want of runs at the requested
    /// one.
    pub fn warnings(&self) -> Vec<String> {
        let q = match &self.q_star_runs.refused {
            Some(why) => Some(format!("Q*_D not fitted: {why}")),
            None => self.q_star_d_bootstrap.ok().and_then(|b| b.warning()),
        };
        let spins = self
            .spin_distributions
            .iter()
            .filter(|d| !d.selection.contains(" at zeta "));
        q.into_iter()
            .chain(spins.map(|d| format!("spin distribution of {}: {}", d.projectile, d.selection)))
            .collect()
    }
}

/// Which runs make each projectile's spin distribution (Fig. 7): those on `target` at ζ = `angle_deg`, when the
/// campaign has them (the paper uses N200_T12 at 45°); otherwise the projectile's runs on `target` at every angle.
/// Runs on different targets are never pooled.
#[derive(Debug, Clone, PartialEq)]
pub struct SpinSelection {
    /// Target file stem; `None`: the campaign's own ([`SpinSelection::resolve`]).
    pub target: Option<String>,
    /// ζ (degrees).
    pub angle_deg: f64,
    /// Fit Q*_D over every run at once, pooled over targets and angles, as Roig03 Fig. 5 does (its reproduction
    /// compares that line); `false` (default): over the target and angle above only, since each has its own Q*_D.
    pub pool_q_star: bool,
}

impl Default for SpinSelection {
    /// The campaign's own target at 45°; Q*_D not pooled.
    fn default() -> Self {
        SpinSelection {
            target: None,
            angle_deg: 45.0,
            pool_q_star: false,
        }
    }
}

impl SpinSelection {
    /// The target stem for a campaign on `targets`: the one asked for, which must be among them; else the only one,
    /// or N200_T12 (Roig03's case) when it is among several; else an error naming them.
    pub fn resolve(&self, targets: &[String]) -> Result<String, AnalysisError> {
        let list = || targets.join(", ");
        match &self.target {
            Some(t) if targets.contains(t) => Ok(t.clone()),
            Some(t) => Err(AnalysisError::Request(format!(
                "--spin-target: the campaign has no target `{t}`; its targets are {}",
                list()
            ))),
            None if targets.len() == 1 => Ok(targets[0].clone()),
            None if targets.iter().any(|t| t == "N200_T12") => Ok("N200_T12".into()),
            None => Err(AnalysisError::Request(format!(
                "--spin-target: the campaign has several targets ({}); name the one whose Q*_D and spin distributions to draw \
                 (runs on different targets are not pooled)",
                list()
            ))),
        }
    }
}

/// The histogram of the spin rates `spins` (√N bins, 5 to 40) and its fits of Eq. 44 for n ∈ {0.5, 1, 1.5, 2}.
fn spin_histogram_fits(spins: &[f64]) -> ((Vec<f64>, Vec<f64>), Fit<ExponentComparison>) {
    let bins = ((spins.len() as f64).sqrt().round() as usize).clamp(5, 40);
    let hist = histogram(spins, bins, None).unwrap_or_default();
    let fits = Fit::from(compare_exponents(&hist.0, &hist.1, &[0.5, 1.0, 1.5, 2.0]));
    (hist, fits)
}

/// One [`SpinDistribution`] per projectile with runs on `target` (in order of first appearance), of those runs at ζ =
/// `angle_deg` (degrees), or at every angle when there are none, from their target fragments' corrected spin rates
/// (`spins[k]` belongs to `runs[k]`).
pub fn spin_distributions(
    runs: &[CampaignRun],
    spins: &[Vec<f64>],
    target: &str,
    angle_deg: f64,
) -> Vec<SpinDistribution> {
    let mut projectiles: Vec<&str> = Vec::new();
    for r in runs.iter().filter(|r| r.target == target) {
        if !projectiles.contains(&r.projectile.as_str()) {
            projectiles.push(&r.projectile);
        }
    }
    projectiles
        .into_iter()
        .map(|p| {
            let of_p: Vec<usize> = (0..runs.len())
                .filter(|&k| runs[k].projectile == p && runs[k].target == target)
                .collect();
            let case: Vec<usize> = of_p
                .iter()
                .copied()
                .filter(|&k| runs[k].angle_deg == angle_deg)
                .collect();
            let (chosen, how) = if case.is_empty() {
                (of_p, format!("target {target}, every angle (none at zeta {angle_deg})"))
            } else {
                (case, format!("target {target} at zeta {angle_deg}"))
            };
            let pooled: Vec<f64> = chosen.iter().flat_map(|&k| spins[k].iter().copied()).collect();
            let (hist, fits) = spin_histogram_fits(&pooled);
            SpinDistribution {
                projectile: p.to_string(),
                q_erg_per_g: chosen.iter().map(|&k| runs[k].q_erg_per_g).sum::<f64>() / chosen.len() as f64,
                runs: chosen.iter().map(|&k| runs[k].run.clone()).collect(),
                selection: how,
                fragments: pooled.len(),
                histogram: hist,
                fits,
                likelihood: Fit::from(fit_spin_likelihood(&pooled, Weights::Number)),
            }
        })
        .collect()
}

/// Per-body results of an analysed run (`analysis/fragments.csv`), as scalars for visualisation files and
/// pictures: `bound` (1 when the body stays bound, 0 when it escapes) and `ejection_speed` (m/s), both as found at
/// the analysed time.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FragmentFields {
    /// `(bound, ejection_speed)` by body index.
    by_index: std::collections::BTreeMap<usize, (f64, f64)>,
}

impl FragmentFields {
    /// The fields of the run in `dir`; `None` when it has not been analysed (no `analysis/fragments.csv`).
    pub fn read(dir: &Path) -> Result<Option<FragmentFields>, AnalysisError> {
        let path = dir.join("analysis").join("fragments.csv");
        if !path.exists() {
            return Ok(None);
        }
        let err = |reason: String| AnalysisError::read(&path, reason);
        let mut rdr = csv::Reader::from_path(&path).map_err(|e| err(e.to_string()))?;
        let headers = rdr.headers().map_err(|e| err(e.to_string()))?.clone();
        let col = |name: &str| {
            headers
                .iter()
                .position(|h| h == name)
                .ok_or_else(|| err(format!("missing column `{name}`")))
        };
        let (i_index, i_escaping, i_speed) = (col("index")?, col("escaping")?, col("ejection_speed")?);
        let mut by_index = std::collections::BTreeMap::new();
        for (row, rec) in rdr.records().enumerate() {
            let rec = rec.map_err(|e| err(e.to_string()))?;
            let bad = |column: &str| err(format!("row {}: bad `{column}` value", row + 1));
            let index: usize = rec[i_index].parse().map_err(|_| bad("index"))?;
            let escaping: bool = rec[i_escaping].parse().map_err(|_| bad("escaping"))?;
            let speed: f64 = rec[i_speed].parse().map_err(|_| bad("ejection_speed"))?;
            by_index.insert(index, (if escaping { 0.0 } else { 1.0 }, speed));
        }
        Ok(Some(FragmentFields { by_index }))
    }

    /// The `bound` and `ejection_speed` columns for the bodies `ids` (NaN for a body the analysis does not list).
    pub fn columns(&self, ids: impl Iterator<Item = usize> + Clone) -> Vec<(String, Vec<f64>)> {
        let get = |k: usize| {
            ids.clone()
                .map(|id| {
                    self.by_index
                        .get(&id)
                        .map_or(f64::NAN, |v| if k == 0 { v.0 } else { v.1 })
                })
                .collect()
        };
        vec![("bound".to_string(), get(0)), ("ejection_speed".to_string(), get(1))]
    }
}
