//! The spin-up searches behind `rubblepile spinup …` (Zhang17 §3.3.3, §4.2; Eq. 22):
//!
//! - `rubblepile spinup critical --scene BASE.toml --from 2.30 --to 2.60 [--step 0.01] --out DIR [--force]`:
//!   the search for T_c,3. For T_final = from, from + step, … (hours) it writes `DIR/T<T_final>/scene.toml`
//!   (BASE with `spinup.T_final` replaced), runs it (a run already completed there is reused), and judges the hold
//!   after `t_final` with the creep criterion ([`CreepCriterion`], defaults tested in `analysis::spinup`): the body
//!   is stable when the forcing was never released and neither θ_max nor η_B (nor, with
//!   `--coordination-tolerance`, the coordination number) drifts over the second half of the hold. The first stable T_final is T_c,3; φ is the largest θ_max over the holds of the
//!   runs within ±0.01 h of it. Writes `DIR/critical.json` ([`CriticalSearch`]).
//!   With `--branch [--hold SECONDS]` the hold runs share one run of BASE's path (`DIR/base`): the hold at
//!   T_final = X starts where BASE's path passes X, with BASE's spin-up rate (Zhang17 §4.3 finds T_c,3
//!   independent of the rate), branched off the base run's checkpoint at the output sample at or before that time
//!   ([`crate::driver::branch`]); its scene (`DIR/T<X>/scene.toml`) has `t_final` at that time and holds
//!   for SECONDS. Each hold then costs only its hold; the result equals the hold scene run from t = 0 bit for bit
//!   when the shortened path's periods round alike (tested).
//! - `rubblepile spinup density-fit --points RHO:T,RHO:T,… [--period 2.26]`: κ of Eq. 22 by least squares
//!   through the origin from (bulk density kg/m³, critical period h) pairs, its standard error, and the critical
//!   bulk density for the given period.
//! - `rubblepile report zhang2017 RUNS --out DIR [--force]`: see [`crate::analysis::report_zhang2017`].

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::analysis::spinup::{CreepCriterion, fit_density};
use crate::analysis::spinup_diagnostics::{SpinupSample, read_spinup_csv};
use crate::driver::RunOptions;
use crate::io::scene_file::SI_G;

/// The options of a T_c,3 search (those of `rubblepile spinup critical`).
#[derive(Debug, Clone, PartialEq)]
pub struct CriticalOptions {
    /// Soft-sphere scene with a `[spinup]` table whose run lasts past `t_final` (the hold).
    pub scene: PathBuf,
    /// First T_final (hours).
    pub from: f64,
    /// Last T_final (hours).
    pub to: f64,
    /// Step of T_final (hours).
    pub step: f64,
    /// Directory of the hold runs and `critical.json`.
    pub out: PathBuf,
    /// Overwrite an earlier `critical.json` in `out` (completed runs are still reused).
    pub force: bool,
    /// Branch the hold runs off one run of the scene's path (`out/base`) instead of running each from t = 0.
    pub branch: bool,
    /// Also judge the coordination number: largest allowed change over the second half of a hold.
    pub coordination_tolerance: Option<f64>,
    /// Length of each hold (s) with `branch`; default: the scene's `t_end − t_final`.
    pub hold: Option<f64>,
}

/// Why a search or a fit could not be made: bad options or inputs (the caller's), or a run or file that failed.
#[derive(Debug, thiserror::Error)]
pub enum SearchError {
    /// Bad options or inputs.
    #[error("{0}")]
    Usage(String),
    /// A run failed or a file could not be written.
    #[error("{0}")]
    Failed(String),
}

impl SearchError {
    fn usage(m: impl std::fmt::Display) -> Self {
        SearchError::Usage(m.to_string())
    }
    fn failed(m: impl std::fmt::Display) -> Self {
        SearchError::Failed(m.to_string())
    }
}

/// One hold run judged by the creep criterion.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HoldVerdict {
    /// T_final (h).
    pub t_final_hours: f64,
    /// Run directory.
    pub dir: PathBuf,
    /// Whether the forcing was released (global disruption).
    pub released: bool,
    /// Diagnostics drifting over the second half of the hold (empty: none).
    pub drifting: Vec<&'static str>,
    /// Largest θ_max during the hold (degrees).
    pub theta_max_deg: f64,
    /// Stable: not released and nothing drifting.
    pub stable: bool,
}

/// `critical.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CriticalSearch {
    /// The criterion used.
    pub criterion: CreepCriterion,
    /// The runs, by increasing T_final.
    pub runs: Vec<HoldVerdict>,
    /// T_c,3 (h): the first stable T_final.
    pub t_c3_hours: Option<f64>,
    /// φ (degrees): the largest θ_max over the holds within ±0.01 h of T_c,3.
    pub friction_angle_deg: Option<f64>,
}

/// Judges the hold (samples at or after `t_final`, s) of one run.
pub fn judge_hold(
    samples: &[SpinupSample],
    t_final: f64,
    criterion: &CreepCriterion,
) -> (bool, Vec<&'static str>, f64) {
    let hold: Vec<&SpinupSample> = samples.iter().filter(|s| s.t >= t_final).collect();
    let released = samples.iter().any(|s| !s.forcing);
    let t: Vec<f64> = hold.iter().map(|s| s.t).collect();
    let theta: Vec<f64> = hold.iter().map(|s| s.theta_max_deg).collect();
    let eta: Vec<f64> = hold.iter().map(|s| s.packing_fraction).collect();
    let coord: Vec<f64> = hold.iter().map(|s| s.coordination_number).collect();
    let drifting = criterion.drifting(&t, &theta, &eta, &coord);
    let theta_max = theta.iter().cloned().fold(f64::NAN, f64::max);
    (released, drifting, theta_max)
}

/// Reduces judged runs to T_c,3 and φ (see the module docs).
pub fn critical_from_verdicts(runs: &[HoldVerdict]) -> (Option<f64>, Option<f64>) {
    let t_c3 = runs.iter().find(|r| r.stable).map(|r| r.t_final_hours);
    let phi = t_c3.and_then(|t| {
        let m = runs
            .iter()
            .filter(|r| (r.t_final_hours - t).abs() <= 0.01 + 1e-9)
            .map(|r| r.theta_max_deg)
            .fold(f64::NAN, f64::max);
        m.is_finite().then_some(m)
    });
    (t_c3, phi)
}

/// Runs the T_c,3 search (Zhang17 §3.3.3) and writes `critical.json` in `args.out`.
pub fn critical(args: &CriticalOptions) -> Result<(), SearchError> {
    let ok = |x: f64| x.is_finite() && x > 0.0;
    if !ok(args.from) || !ok(args.to) || args.to < args.from {
        return Err(SearchError::usage(format!(
            "--from and --to must be periods in hours with 0 < from <= to, got {} and {}",
            args.from, args.to
        )));
    }
    if !ok(args.step) {
        return Err(SearchError::usage(format!(
            "--step must be > 0 hours, got {}",
            args.step
        )));
    }
    let json = args.out.join("critical.json");
    if json.exists() && !args.force {
        return Err(SearchError::usage(format!(
            "{} exists (use --force to overwrite it)",
            json.display()
        )));
    }
    let text = std::fs::read_to_string(&args.scene)
        .map_err(|e| SearchError::usage(format!("{}: {e}", args.scene.display())))?;
    let base = crate::granular::soft::scene::load_soft_scene(&args.scene).map_err(SearchError::usage)?;
    let Some(settings) = base.spinup else {
        return Err(SearchError::usage(format!(
            "{}: spinup: missing (need a [spinup] table)",
            args.scene.display()
        )));
    };
    if base.t_end <= settings.path.t_final && !(args.branch && args.hold.is_some()) {
        return Err(SearchError::usage(format!(
            "{}: scene.t_end must exceed spinup.t_final = {} s to leave a hold, got {}",
            args.scene.display(),
            settings.path.t_final,
            base.t_end
        )));
    }
    let mut table: toml::Table = toml::from_str(&text).map_err(|e| SearchError::usage(e.to_string()))?;
    // a particles_file is resolved against the base scene's directory
    let scene_dir = args.scene.parent().map(Path::to_path_buf).unwrap_or_default();
    if let Some(toml::Value::String(f)) = table.get("scene").and_then(|s| s.get("particles_file")).cloned() {
        let abs = std::path::absolute(scene_dir.join(&f)).map_err(|e| SearchError::usage(e.to_string()))?;
        table["scene"]["particles_file"] = toml::Value::String(abs.display().to_string());
    }
    std::fs::create_dir_all(&args.out).map_err(|e| SearchError::usage(format!("{}: {e}", args.out.display())))?;
    if let Some(c) = args.coordination_tolerance
        && !(c.is_finite() && c > 0.0)
    {
        return Err(SearchError::usage(format!(
            "--coordination-tolerance must be > 0, got {c}"
        )));
    }
    let criterion = CreepCriterion {
        coordination: args.coordination_tolerance,
        ..CreepCriterion::default()
    };
    let n = ((args.to - args.from) / args.step + 1e-9).floor() as usize;
    let grid: Vec<f64> = (0..=n)
        .map(|k| ((args.from + k as f64 * args.step) * 1e4).round() / 1e4)
        .collect();
    for &tf in &grid {
        if tf * 3600.0 > settings.path.period_inter + 1e-9 {
            return Err(SearchError::usage(format!(
                "T_final = {tf} h is above the scene's T_inter = {} h",
                settings.path.period_inter / 3600.0
            )));
        }
    }
    let branches = if args.branch {
        Some(prepare_branches(args, &table, &base, &settings.path, &grid)?)
    } else {
        None
    };
    let mut runs = Vec::new();
    for (k, &tf) in grid.iter().enumerate() {
        let dir = args.out.join(format!("T{tf:.2}"));
        let completed = std::fs::read_to_string(dir.join("summary.json")).is_ok_and(|s| s.contains("\"completed\""));
        let options = RunOptions {
            force: true,
            progress: false,
            checkpoint_every: Some(crate::driver::DEFAULT_CHECKPOINT_EVERY),
            checkpoint_every_sim: None,
            formats: crate::driver::formats::Formats::NONE,
            stop_after_checkpoints: None,
        };
        let t_final = branches.as_ref().map_or(settings.path.t_final, |b| b[k]);
        if !completed {
            eprintln!("spinup critical: running T_final = {tf} h into {}", dir.display());
            if branches.is_some() {
                crate::driver::resume_soft(&dir, &options).map_err(|e| SearchError::failed(e.to_string()))?;
            } else {
                table["spinup"]["T_final"] = toml::Value::Float(tf);
                let scene_text = toml::to_string(&table).map_err(|e| SearchError::usage(e.to_string()))?;
                let path = args.out.join(format!("T{tf:.2}.toml"));
                std::fs::write(&path, &scene_text)
                    .map_err(|e| SearchError::failed(format!("{}: {e}", path.display())))?;
                let scene = crate::granular::soft::scene::load_soft_scene(&path).map_err(SearchError::usage)?;
                crate::driver::run_soft(&scene, &dir, &options).map_err(|e| SearchError::failed(e.to_string()))?;
            }
        }
        let samples = read_spinup_csv(&dir.join("spinup.csv")).map_err(SearchError::failed)?;
        let (released, drifting, theta) = judge_hold(&samples, t_final, &criterion);
        let stable = !released && drifting.is_empty();
        println!(
            "T_final = {tf:.2} h: {}{}",
            if stable { "stable" } else { "creeps" },
            if released {
                " (disrupted)".to_string()
            } else if drifting.is_empty() {
                String::new()
            } else {
                format!(" ({} drifting)", drifting.join(", "))
            }
        );
        runs.push(HoldVerdict {
            t_final_hours: tf,
            dir,
            released,
            drifting,
            theta_max_deg: theta,
            stable,
        });
        // stop one step after the first stable T_final: φ looks ±0.01 h around T_c,3
        let first_stable = runs.iter().position(|r| r.stable);
        if first_stable.is_some_and(|f| runs.len() > f + 1) {
            break;
        }
    }
    let (t_c3_hours, friction_angle_deg) = critical_from_verdicts(&runs);
    let out = CriticalSearch {
        criterion,
        runs,
        t_c3_hours,
        friction_angle_deg,
    };
    std::fs::write(&json, serde_json::to_string_pretty(&out).expect("serialises") + "\n")
        .map_err(|e| SearchError::failed(format!("{}: {e}", json.display())))?;
    match (t_c3_hours, friction_angle_deg) {
        (Some(t), Some(p)) => println!("T_c3 = {t:.2} h, phi = {p:.1} deg ({})", json.display()),
        _ => println!("no stable T_final up to {} h ({})", args.to, json.display()),
    }
    Ok(())
}

/// The time (s) at which the path `p` (without rests) passes the period `period_h` (hours), between `t_inter` and
/// `t_final`; `None` outside `[T_final, T_inter]`.
pub fn path_time_at_period(p: &crate::granular::soft::spinup::SpinupPath, period_h: f64) -> Option<f64> {
    let x = period_h * 3600.0;
    let (hi, lo) = (p.period_inter, p.period_final);
    if !(lo - 1e-9..=hi + 1e-9).contains(&x) {
        return None;
    }
    if hi - lo <= 0.0 {
        return Some(p.t_final);
    }
    Some(p.t_inter + (hi - x) / (hi - lo) * (p.t_final - p.t_inter))
}

/// `--branch`: runs the scene's path once in `OUT/base`, stopping at the output sample at or before each hold's
/// start `t_X` (the time the path passes X = T_final, latest first), and writes the hold run `OUT/T<X>` there as
/// a branch ([`crate::granular::soft::branch`]) whose scene follows the same path to X at `t_X` and holds it for
/// the hold length. Branches already written are kept. Returns `t_X` (s) per grid entry.
fn prepare_branches(
    args: &CriticalOptions,
    table: &toml::Table,
    base: &crate::granular::soft::scene::SoftScene,
    path: &crate::granular::soft::spinup::SpinupPath,
    grid: &[f64],
) -> Result<Vec<f64>, SearchError> {
    use crate::driver::branch::{branch_soft, checkpoint_time};
    use crate::driver::{resume_soft, run_soft};
    use crate::granular::soft::run::sample_steps;
    if path.rests > 0 {
        return Err(SearchError::usage(format!(
            "{}: spinup.rests = {}: --branch needs a path without rests (a shorter path with rests is not a prefix)",
            args.scene.display(),
            path.rests
        )));
    }
    let hold = args.hold.unwrap_or(base.t_end - path.t_final);
    if !(hold.is_finite() && hold > 0.0) {
        return Err(SearchError::usage(format!("--hold must be > 0 s, got {hold}")));
    }
    let mut starts = Vec::with_capacity(grid.len());
    for &tf in grid {
        starts.push(path_time_at_period(path, tf).ok_or_else(|| {
            SearchError::usage(format!(
                "T_final = {tf} h is outside the scene's path from T_inter = {} h to T_final = {} h",
                path.period_inter / 3600.0,
                path.period_final / 3600.0
            ))
        })?);
    }
    let dt = base.dt;
    let every = base.every_steps as f64 * dt;
    let times: Vec<f64> = table
        .get("output")
        .and_then(|o| o.get("times"))
        .and_then(|t| t.as_array())
        .map(|a| a.iter().filter_map(|v| v.as_float()).collect())
        .unwrap_or_else(|| vec![0.0]);
    // the base scene: the path run to just past the earliest hold's start
    let t_base_end = starts.iter().cloned().fold(0.0, f64::max) + 2.0 * every;
    let mut table = table.clone();
    table
        .entry("output")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    let mut base_table = table.clone();
    base_table["scene"]["t_end"] = toml::Value::Float(t_base_end);
    let keep = |limit: f64| -> toml::Value {
        toml::Value::Array(
            times
                .iter()
                .filter(|&&t| t <= limit + 1e-9)
                .map(|&t| toml::Value::Float(t))
                .collect(),
        )
    };
    base_table["output"]["times"] = keep(t_base_end);
    let base_text = toml::to_string(&base_table).map_err(|e| SearchError::usage(e.to_string()))?;
    let parent = args
        .scene
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let scene_dir =
        std::path::absolute(parent).map_err(|e| SearchError::usage(format!("{}: {e}", parent.display())))?;
    let base_scene = crate::granular::soft::scene::parse_soft_scene(&base_text, "base", Some(&scene_dir))
        .map_err(SearchError::usage)?;
    let plan = sample_steps(&base_scene);
    let base_dir = args.out.join("base");
    // a base run from an earlier search over a shorter span cannot be extended (its scene is fixed)
    if let Ok(text) = std::fs::read_to_string(base_dir.join("scene.toml"))
        && text != base_text
        && grid.iter().any(|tf| {
            let dir = args.out.join(format!("T{tf:.2}"));
            !(dir.join("checkpoint.json").is_file() || dir.join("summary.json").is_file())
        })
    {
        return Err(SearchError::usage(format!(
            "{}: the base run was made for another range of T_final; remove that directory to start it again \
             (the hold runs already branched are kept)",
            base_dir.display()
        )));
    }
    let failed =
        |e: crate::driver::RunError<crate::granular::soft::run::SoftSummary>| SearchError::failed(e.to_string());
    // latest hold first: the base run only moves forward
    let mut order: Vec<usize> = (0..grid.len()).collect();
    order.sort_by(|&a, &b| starts[a].total_cmp(&starts[b]));
    for k in order {
        let tf = grid[k];
        let dir = args.out.join(format!("T{tf:.2}"));
        if dir.join("checkpoint.json").is_file() || dir.join("summary.json").is_file() {
            continue;
        }
        let s_x = (starts[k] / dt + 1e-9).floor() as u64;
        let s_ck = plan
            .iter()
            .map(|p| p.0)
            .filter(|&s| s <= s_x && s > 0)
            .max()
            .unwrap_or(0);
        if s_ck == 0 {
            return Err(SearchError::usage(format!(
                "T_final = {tf} h is reached before the first output sample"
            )));
        }
        let t_ck = s_ck as f64 * dt;
        let here = if base_dir.join("checkpoint.json").is_file() {
            Some(checkpoint_time(&base_dir).map_err(failed)?.0)
        } else {
            None
        };
        if here.is_some_and(|h| h > s_ck) {
            return Err(SearchError::usage(format!(
                "{}: the base run is past the start of T_final = {tf} h; remove the base directory to redo it",
                base_dir.display()
            )));
        }
        if here != Some(s_ck) {
            let t_here = here.map_or(0.0, |h| h as f64 * dt);
            let options = RunOptions {
                force: true,
                progress: false,
                checkpoint_every: None,
                checkpoint_every_sim: Some(t_ck - t_here - 0.5 * dt),
                formats: crate::driver::formats::Formats::NONE,
                stop_after_checkpoints: Some(1),
            };
            eprintln!(
                "spinup critical: base run to t = {t_ck} s (T_final = {tf} h starts at {} s)",
                starts[k]
            );
            let result = match here {
                Some(_) => resume_soft(&base_dir, &options),
                None => run_soft(&base_scene, &base_dir, &options),
            };
            match result {
                Err(crate::driver::RunError::Stopped { .. }) => {}
                Err(e) => return Err(failed(e)),
                Ok(_) => {
                    return Err(SearchError::failed(format!(
                        "{}: the base run ended before t = {t_ck} s",
                        base_dir.display()
                    )));
                }
            }
        }
        let mut hold_table = table.clone();
        hold_table["spinup"]["T_final"] = toml::Value::Float(tf);
        hold_table["spinup"]["t_final"] = toml::Value::Float(starts[k]);
        hold_table["scene"]["t_end"] = toml::Value::Float(starts[k] + hold);
        let mut snaps = match keep(t_ck) {
            toml::Value::Array(a) => a,
            _ => Vec::new(),
        };
        for t in [starts[k], starts[k] + hold] {
            if snaps
                .last()
                .and_then(|v| v.as_float())
                .is_none_or(|last| t >= last + dt)
            {
                snaps.push(toml::Value::Float(t));
            }
        }
        hold_table["output"]["times"] = toml::Value::Array(snaps);
        let hold_text = toml::to_string(&hold_table).map_err(|e| SearchError::usage(e.to_string()))?;
        if dir.exists() {
            std::fs::remove_dir_all(&dir).map_err(|e| SearchError::failed(format!("{}: {e}", dir.display())))?;
        }
        branch_soft(&base_dir, &hold_text, &scene_dir, &dir).map_err(failed)?;
    }
    Ok(starts)
}

/// Parses `RHO:T` pairs.
pub fn parse_points(points: &[String]) -> Result<Vec<(f64, f64)>, SearchError> {
    points
        .iter()
        .map(|p| {
            let (a, b) = p
                .split_once(':')
                .ok_or_else(|| SearchError::usage(format!("--points: expected RHO:T (kg/m^3:hours), got {p:?}")))?;
            let parse = |s: &str, what: &str| {
                s.trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite() && *x > 0.0)
                    .ok_or_else(|| {
                        SearchError::usage(format!("--points: {what} must be a number > 0, got {s:?} in {p:?}"))
                    })
            };
            Ok((parse(a, "the bulk density (kg/m^3)")?, parse(b, "the period (h)")?))
        })
        .collect()
}

/// Fits Zhang17 Eq. 22 to `points` (`RHO:T` pairs: kg/m³ and hours) and prints κ and the critical bulk density at
/// `period` hours.
pub fn density_fit(points: &[String], period: f64) -> Result<(), SearchError> {
    let pts = parse_points(points)?;
    if pts.is_empty() {
        return Err(SearchError::usage("--points: give at least one RHO:T pair"));
    }
    if !(period.is_finite() && period > 0.0) {
        return Err(SearchError::usage(format!(
            "--period must be > 0 hours, got {}",
            period
        )));
    }
    let fit = fit_density(&pts, SI_G, period).ok_or_else(|| SearchError::usage("--points: nothing to fit"))?;
    println!(
        "kappa = {:.4} +- {:.4} from {} points; critical bulk density at T = {} h: {:.0} kg/m^3",
        fit.kappa,
        fit.sigma_kappa,
        pts.len(),
        period,
        fit.critical_density
    );
    Ok(())
}

/// Where a model's runs live under the report's RUNS directory.
pub fn model_dir(runs: &Path, model: &str) -> PathBuf {
    runs.join(model)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(t: f64, theta: f64, eta: f64, coord: f64, forcing: bool) -> SpinupSample {
        SpinupSample {
            t,
            path_period_h: 2.3,
            period_h: 2.3,
            forcing,
            body_particles: 100,
            body_mass_fraction: 1.0,
            a: 1.0,
            b: 1.0,
            c: 1.0,
            b_over_a: 1.0,
            c_over_a: 1.0,
            packing_fraction: eta,
            interior_particles: 50,
            coordination_number: coord,
            fraction_0_contacts: 0.0,
            fraction_1_contact: 0.0,
            rves: 5,
            s_max: 1.0,
            p_max: 1.0,
            theta_max_deg: theta,
        }
    }

    /// The creep criterion on synthetic holds: a steady θ_max is stable, a θ_max rising by 2° over the hold creeps;
    /// T_c,3 is the first stable T_final and φ the largest θ_max within ±0.01 h of it.
    #[test]
    fn hold_verdicts_give_t_c3_and_phi() {
        let hold = |rise: f64, level: f64| -> Vec<SpinupSample> {
            (0..100)
                .map(|k| {
                    sample(
                        1000.0 + 10.0 * k as f64,
                        level + rise * k as f64 / 99.0,
                        0.74,
                        9.0,
                        true,
                    )
                })
                .collect()
        };
        let c = CreepCriterion::default();
        let verdict = |tf: f64, s: &[SpinupSample]| {
            let (released, drifting, theta) = judge_hold(s, 1000.0, &c);
            HoldVerdict {
                t_final_hours: tf,
                dir: PathBuf::new(),
                released,
                stable: !released && drifting.is_empty(),
                drifting,
                theta_max_deg: theta,
            }
        };
        let runs = vec![
            verdict(2.40, &hold(2.0, 40.0)),
            verdict(2.41, &hold(0.0, 39.0)),
            verdict(2.42, &hold(0.0, 37.5)),
        ];
        assert!(!runs[0].stable && runs[0].drifting == vec!["theta_max"]);
        assert!(runs[1].stable && runs[2].stable);
        let (t, phi) = critical_from_verdicts(&runs);
        assert_eq!(t, Some(2.41));
        assert_eq!(phi, Some(42.0));
        // a released run is never stable
        let mut s = hold(0.0, 30.0);
        s[50].forcing = false;
        assert!(!verdict(2.5, &s).stable);
    }

    #[test]
    fn points_parse_and_name_the_bad_one() {
        assert_eq!(
            parse_points(&["2100:2.4".into(), "2500:2.2".into()]).unwrap(),
            vec![(2100.0, 2.4), (2500.0, 2.2)]
        );
        let e = parse_points(&["2100-2.4".into()]).unwrap_err();
        assert!(e.to_string().contains("expected RHO:T"), "{}", e.to_string());
        let e = parse_points(&["2100:-1".into()]).unwrap_err();
        assert!(
            e.to_string().contains("the period (h) must be a number > 0"),
            "{}",
            e.to_string()
        );
    }
}
