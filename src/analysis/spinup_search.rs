//! The spin-up searches behind `rubblepile spinup …` (Zhang17 §3.3.3, §4.2; Eq. 22):
//!
//! - `rubblepile spinup critical --scene BASE.toml --from 2.30 --to 2.60 [--step 0.01] --out DIR [--force]
//!   [--creep-criterion paper|ours] [--coordination-tolerance C]`: the search for T_c,3. For T_final = from,
//!   from + step, … (hours) it writes `DIR/T<T_final>/scene.toml` (BASE with `spinup.T_final` replaced), runs it (a
//!   run already completed there is reused), and judges the hold after `t_final` by both creep criteria of
//!   [`crate::analysis::creep`]: the paper's (a rising θ_max, a falling η_B or a falling coordination number over
//!   the second half of the hold is creep; `C` is the largest fall of the coordination number let pass, default
//!   0.05) and ours (θ_max or η_B moving either way; the coordination number not judged). A hold is stable under a
//!   criterion when the forcing was never released and nothing drifts by it. T_c,3 under a criterion is its first
//!   stable T_final, and φ the largest θ_max of that hold (the critical state's). The search goes on until both
//!   criteria have a stable hold and one step beyond it (for φ), or to `--to`. `critical.json` ([`CriticalSearch`])
//!   holds both T_c,3 values (`paper`, `ours`), the measured drifts and both verdicts per hold; its top-level
//!   `t_c3_hours` and `friction_angle_deg` are those of `--creep-criterion` (default `paper`). `critical.csv` is
//!   the same per hold as a table, and the verdicts are printed as each hold is judged.
//!   With `--branch [--hold SECONDS]` the hold runs share one run of BASE's path (`DIR/base`): the hold at
//!   T_final = X starts where BASE's path passes X, with BASE's spin-up rate (Zhang17 §4.3 finds T_c,3
//!   independent of the rate), branched off the base run's checkpoint at the output sample at or before that time
//!   ([`crate::driver::branch`]); its scene (`DIR/T<X>/scene.toml`) has `t_final` at that time and holds
//!   for SECONDS. Each hold then costs only its hold; the result equals the hold scene run from t = 0 bit for bit
//!   when the shortened path's periods round alike (tested).
//! - `rubblepile spinup density-fit --points RHO:T,RHO:T,… [--period 2.26]`: κ of Eq. 22 by least squares
//!   through the origin from (bulk density kg/m³, critical period h) pairs, its standard error, and the critical
//!   bulk density for the given period.
//! - `rubblepile report zhang2017 RUNS --out DIR [--force]`: the report on these searches' runs, written
//!   one layer up (`src/studies/zhang2017/report.rs`).

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::analysis::creep::{CreepCriterion, CreepCriterionKind, HoldDrift};
use crate::analysis::spinup::fit_density;
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
    /// The criterion whose T_c,3 and φ are `critical.json`'s top-level values (both are always judged).
    pub criterion: CreepCriterionKind,
    /// Largest fall of the coordination number (contacts per particle) over the second half of a hold that the
    /// paper's criterion lets pass; default [`crate::analysis::creep::PAPER_COORDINATION_TOLERANCE`].
    pub coordination_tolerance: Option<f64>,
    /// Length of each hold (s) with `branch`; default: the scene's `t_end − t_final`.
    pub hold: Option<f64>,
    /// Run every hold of the grid, also after both criteria have a stable hold (whether the verdicts stay stable
    /// at slower spins); default: stop there.
    pub all_holds: bool,
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

/// One criterion's verdict on a hold.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CriterionVerdict {
    /// Diagnostics drifting beyond the criterion's tolerance over the second half of the hold (empty: none).
    pub drifting: Vec<&'static str>,
    /// Stable: the forcing was not released and nothing drifts.
    pub stable: bool,
}

/// One hold run judged by both creep criteria (Zhang17 §3.3.3; [`crate::analysis::creep`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HoldVerdict {
    /// T_final (h).
    pub t_final_hours: f64,
    /// Run directory.
    pub dir: PathBuf,
    /// Whether the forcing was released (global disruption).
    pub released: bool,
    /// The measured second-half changes of θ_max, η_B and the coordination number.
    pub drift: HoldDrift,
    /// Largest θ_max during the hold (degrees).
    pub theta_max_deg: f64,
    /// The paper's criterion (one-sided, coordination number included).
    pub paper: CriterionVerdict,
    /// Ours (two-sided on θ_max and η_B).
    pub ours: CriterionVerdict,
    /// The selected criterion's drifting diagnostics (as `paper` or `ours`).
    pub drifting: Vec<&'static str>,
    /// The selected criterion's verdict.
    pub stable: bool,
}

impl HoldVerdict {
    /// The verdict of criterion `kind`.
    pub fn verdict(&self, kind: CreepCriterionKind) -> &CriterionVerdict {
        match kind {
            CreepCriterionKind::Paper => &self.paper,
            CreepCriterionKind::Ours => &self.ours,
        }
    }
}

/// T_c,3 and φ under one criterion.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CriterionResult {
    /// The criterion and its tolerances.
    pub criterion: CreepCriterion,
    /// T_c,3 (h): the shortest T_final from which every slower hold searched is stable under it.
    pub t_c3_hours: Option<f64>,
    /// φ (degrees): the largest θ_max of the hold at that T_c,3.
    pub friction_angle_deg: Option<f64>,
    /// Stable holds (T_final, h) below a creeping one, set aside by the monotone rule ([`set_aside`]).
    pub set_aside_hours: Vec<f64>,
}

/// `critical.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CriticalSearch {
    /// The selected criterion (the one behind `t_c3_hours` and `friction_angle_deg`).
    pub criterion: CreepCriterion,
    /// The runs, by increasing T_final.
    pub runs: Vec<HoldVerdict>,
    /// T_c,3 (h) under the selected criterion.
    pub t_c3_hours: Option<f64>,
    /// φ (degrees) under the selected criterion.
    pub friction_angle_deg: Option<f64>,
    /// T_c,3 and φ under the paper's criterion.
    pub paper: CriterionResult,
    /// T_c,3 and φ under ours.
    pub ours: CriterionResult,
}

/// The coordination number the creep test judges: the force-floored `coordination_loaded` where the run has it,
/// else (files from before it) the raw count.
fn coordination_judged(s: &SpinupSample) -> f64 {
    if s.coordination_loaded.is_finite() {
        s.coordination_loaded
    } else {
        s.coordination_number
    }
}

/// Judges the hold (samples at or after `t_final`, s) of one run of T_final = `t_final_hours` in `dir` by both
/// criteria; `selected` fills [`HoldVerdict::stable`] and [`HoldVerdict::drifting`].
pub fn judge_hold(
    samples: &[SpinupSample],
    t_final: f64,
    paper: &CreepCriterion,
    ours: &CreepCriterion,
    selected: CreepCriterionKind,
    t_final_hours: f64,
    dir: PathBuf,
) -> HoldVerdict {
    let hold: Vec<&SpinupSample> = samples.iter().filter(|s| s.t >= t_final).collect();
    let released = samples.iter().any(|s| !s.forcing);
    let col = |f: fn(&SpinupSample) -> f64| hold.iter().map(|s| f(s)).collect::<Vec<f64>>();
    let theta = col(|s| s.theta_max_deg);
    let drift = HoldDrift::of(
        &col(|s| s.t),
        &theta,
        &col(|s| s.packing_fraction),
        &col(coordination_judged),
    );
    let theta_max_deg = theta.iter().cloned().fold(f64::NAN, f64::max);
    let verdict = |c: &CreepCriterion| {
        let drifting = c.judge(&drift);
        CriterionVerdict {
            stable: !released && drifting.is_empty(),
            drifting,
        }
    };
    let (paper, ours) = (verdict(paper), verdict(ours));
    let chosen = match selected {
        CreepCriterionKind::Paper => &paper,
        CreepCriterionKind::Ours => &ours,
    }
    .clone();
    HoldVerdict {
        t_final_hours,
        dir,
        released,
        drift,
        theta_max_deg,
        paper,
        ours,
        drifting: chosen.drifting,
        stable: chosen.stable,
    }
}

/// Index of the first run of the trailing block of holds stable under `kind` (runs by increasing T_final): the
/// shortest T_final from which every slower hold searched is stable. `None` when the slowest hold creeps.
fn stable_from(runs: &[HoldVerdict], kind: CreepCriterionKind) -> Option<usize> {
    let start = runs.iter().rposition(|r| !r.verdict(kind).stable).map_or(0, |i| i + 1);
    (start < runs.len()).then_some(start)
}

/// Reduces judged runs (by increasing T_final) to T_c,3 and φ under criterion `kind`. T_c,3 is the shortest T_final
/// from which every slower hold is stable (the verdict made monotone: a stable hold below a creeping one does not
/// count, see [`set_aside`]); φ the largest θ_max of the hold at T_c,3: Zhang17 §3.3.3 takes φ as the largest
/// mobilized angle *at the critical state*, the stable hold. (Until 28 Nov 2026 φ was the largest θ_max within
/// ±0.01 h of T_c,3, which on a 0.01 h grid took the disrupted hold's θ_max, a post-failure value.)
pub fn critical_from_verdicts(runs: &[HoldVerdict], kind: CreepCriterionKind) -> (Option<f64>, Option<f64>) {
    let Some(i) = stable_from(runs, kind) else {
        return (None, None);
    };
    let phi = runs[i].theta_max_deg;
    (Some(runs[i].t_final_hours), phi.is_finite().then_some(phi))
}

/// The T_final (h) of holds stable under `kind` that lie below a creeping or disrupted one: where the verdict is
/// not monotone in the spin. [`critical_from_verdicts`] sets them aside; a search with `--step 0.01` between them
/// and the next creeping hold says whether they were luck.
pub fn set_aside(runs: &[HoldVerdict], kind: CreepCriterionKind) -> Vec<f64> {
    let last_unstable = runs.iter().rposition(|r| !r.verdict(kind).stable);
    runs.iter()
        .enumerate()
        .filter(|(i, r)| last_unstable.is_some_and(|u| *i < u) && r.verdict(kind).stable)
        .map(|(_, r)| r.t_final_hours)
        .collect()
}

/// Whether the search may stop after `runs`: under every criterion the slowest two holds are stable (T_c,3 and a
/// judged hold after it: a T_c,3 is only trusted with a slower stable hold beside it).
pub fn search_done(runs: &[HoldVerdict]) -> bool {
    CreepCriterionKind::ALL
        .iter()
        .all(|&k| stable_from(runs, k).is_some_and(|f| runs.len() > f + 1))
}

/// Whether the search stops after `runs`: when it is done ([`search_done`]), unless `all_holds` asks for the whole
/// grid.
pub fn search_stops(runs: &[HoldVerdict], all_holds: bool) -> bool {
    !all_holds && search_done(runs)
}

/// One line per hold of the verdicts by both criteria (printed as the search goes).
pub fn verdict_line(r: &HoldVerdict) -> String {
    let word = |v: &CriterionVerdict| {
        if v.stable {
            "stable".to_string()
        } else if r.released {
            "disrupted".to_string()
        } else {
            format!("creeps ({})", v.drifting.join(", "))
        }
    };
    format!(
        "T_final = {:.2} h: paper {}, ours {}; drift over the second half: theta_max {:+.2} deg, eta_B {:+.5}, \
         coordination {:+.3}",
        r.t_final_hours,
        word(&r.paper),
        word(&r.ours),
        r.drift.theta_max_deg,
        r.drift.packing,
        r.drift.coordination
    )
}

/// The `critical.csv` header: one row per hold with the drifts and both verdicts.
pub const CRITICAL_CSV_HEADER: &str = "t_final_h,released,theta_max_deg,drift_theta_max_deg,drift_packing,drift_coordination,paper_stable,paper_drifting,ours_stable,ours_drifting\n";

/// `critical.csv`: [`CRITICAL_CSV_HEADER`] and one row per hold (drifting diagnostics joined by `;`).
pub fn critical_csv(runs: &[HoldVerdict]) -> String {
    let mut out = CRITICAL_CSV_HEADER.to_string();
    for r in runs {
        out += &format!(
            "{:.2},{},{:.3},{:.4},{:.6},{:.4},{},{},{},{}\n",
            r.t_final_hours,
            r.released,
            r.theta_max_deg,
            r.drift.theta_max_deg,
            r.drift.packing,
            r.drift.coordination,
            r.paper.stable,
            r.paper.drifting.join(";"),
            r.ours.stable,
            r.ours.drifting.join(";"),
        );
    }
    out
}

/// Reads a `critical.csv` ([`critical_csv`]) back into judged holds (the run directories are not in it: `dir`
/// is empty; the selected criterion is the paper's), so that T_c,3 and φ can be re-derived by
/// [`critical_from_verdicts`] from a committed copy without the runs. A malformed row is an error naming its
/// line and column.
pub fn read_critical_csv(text: &str) -> Result<Vec<HoldVerdict>, String> {
    const NAMES: [&str; 3] = ["theta_max", "packing_fraction", "coordination_number"];
    let mut lines = text.lines();
    if lines.next().map(str::trim) != Some(CRITICAL_CSV_HEADER.trim()) {
        return Err(format!(
            "not a critical.csv: the header must be {}",
            CRITICAL_CSV_HEADER.trim()
        ));
    }
    let mut out = Vec::new();
    for (k, line) in lines.enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let at = |col: &str| format!("line {}: column {col}", k + 2);
        let c: Vec<&str> = line.split(',').collect();
        if c.len() != 10 {
            return Err(format!("line {}: {} columns, expected 10", k + 2, c.len()));
        }
        let num = |i: usize, col: &str| {
            c[i].trim()
                .parse::<f64>()
                .map_err(|_| format!("{}: not a number", at(col)))
        };
        let flag = |i: usize, col: &str| {
            c[i].trim()
                .parse::<bool>()
                .map_err(|_| format!("{}: not true/false", at(col)))
        };
        let names = |i: usize, col: &str| -> Result<Vec<&'static str>, String> {
            c[i].split(';')
                .filter(|n| !n.is_empty())
                .map(|n| {
                    NAMES
                        .into_iter()
                        .find(|m| *m == n)
                        .ok_or_else(|| format!("{}: unknown {n}", at(col)))
                })
                .collect()
        };
        let paper = CriterionVerdict {
            stable: flag(6, "paper_stable")?,
            drifting: names(7, "paper_drifting")?,
        };
        out.push(HoldVerdict {
            t_final_hours: num(0, "t_final_h")?,
            dir: PathBuf::new(),
            released: flag(1, "released")?,
            drift: HoldDrift {
                theta_max_deg: num(3, "drift_theta_max_deg")?,
                packing: num(4, "drift_packing")?,
                coordination: num(5, "drift_coordination")?,
            },
            theta_max_deg: num(2, "theta_max_deg")?,
            drifting: paper.drifting.clone(),
            stable: paper.stable,
            paper,
            ours: CriterionVerdict {
                stable: flag(8, "ours_stable")?,
                drifting: names(9, "ours_drifting")?,
            },
        });
    }
    Ok(out)
}

/// The paper's criterion with the coordination tolerance `tol` (contacts per particle; `None`: the default), or
/// a usage error naming `--coordination-tolerance` when it is not a positive number.
pub fn paper_criterion(tol: Option<f64>) -> Result<CreepCriterion, SearchError> {
    match tol {
        None => Ok(CreepCriterion::of_kind(CreepCriterionKind::Paper)),
        Some(c) if c.is_finite() && c > 0.0 => Ok(CreepCriterion::paper(c)),
        Some(c) => Err(SearchError::usage(format!(
            "--coordination-tolerance must be a change of the coordination number > 0 (contacts per particle), \
             got {c}"
        ))),
    }
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
    let (paper, ours) = (paper_criterion(args.coordination_tolerance)?, CreepCriterion::ours());
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
            ..RunOptions::default()
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
        let verdict = judge_hold(&samples, t_final, &paper, &ours, args.criterion, tf, dir);
        println!("{}", verdict_line(&verdict));
        runs.push(verdict);
        if search_stops(&runs, args.all_holds) {
            break;
        }
    }
    let result = |criterion: CreepCriterion| {
        let (t_c3_hours, friction_angle_deg) = critical_from_verdicts(&runs, criterion.kind);
        CriterionResult {
            criterion,
            t_c3_hours,
            friction_angle_deg,
            set_aside_hours: set_aside(&runs, criterion.kind),
        }
    };
    let (paper, ours) = (result(paper), result(ours));
    let selected = match args.criterion {
        CreepCriterionKind::Paper => paper.clone(),
        CreepCriterionKind::Ours => ours.clone(),
    };
    let (t_c3_hours, friction_angle_deg) = (selected.t_c3_hours, selected.friction_angle_deg);
    let csv = args.out.join("critical.csv");
    std::fs::write(&csv, critical_csv(&runs)).map_err(|e| SearchError::failed(format!("{}: {e}", csv.display())))?;
    let out = CriticalSearch {
        criterion: selected.criterion,
        runs,
        t_c3_hours,
        friction_angle_deg,
        paper,
        ours,
    };
    std::fs::write(&json, serde_json::to_string_pretty(&out).expect("serialises") + "\n")
        .map_err(|e| SearchError::failed(format!("{}: {e}", json.display())))?;
    for r in [&out.paper, &out.ours] {
        if let (Some(first), Some(last)) = (r.set_aside_hours.first(), r.set_aside_hours.last()) {
            println!(
                "{} criterion: stable holds at {:?} h lie below creeping ones and are set aside (the verdict is not \
                 monotone there: refine with --step 0.01 from {first:.2} h to the next creeping hold above {last:.2} h)",
                r.criterion.kind.name(),
                r.set_aside_hours
            );
        }
        match (r.t_c3_hours, r.friction_angle_deg) {
            (Some(t), Some(p)) => println!(
                "{} criterion: T_c3 = {t:.2} h, phi = {p:.1} deg",
                r.criterion.kind.name()
            ),
            _ => println!(
                "{} criterion: no stable T_final up to {} h",
                r.criterion.kind.name(),
                args.to
            ),
        }
    }
    println!(
        "selected ({}): {} ({})",
        args.criterion.name(),
        t_c3_hours.map_or("no T_c3".to_string(), |t| format!("T_c3 = {t:.2} h")),
        json.display()
    );
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

/// How many checkpointed legs the base run of `--branch` is cut into over its whole span (a stopped search loses
/// at most one leg of the path: about 15 min of a full-size base run on two cores).
const BASE_LEGS: u64 = 8;

/// The output-sample steps at which the base run stops and checkpoints on its way from step `from` to `to` (an
/// output sample): legs of at most `leg_steps` steps where the samples allow (a leg shorter than the sample spacing
/// ends at the next sample), the last one at `to`; empty when `from >= to`.
fn base_legs(samples: &[u64], from: u64, to: u64, leg_steps: u64) -> Vec<u64> {
    let mut legs = Vec::new();
    let mut at = from;
    while at < to {
        let reach = at.saturating_add(leg_steps.max(1)).min(to);
        let next = samples
            .iter()
            .copied()
            .filter(|&s| s > at && s <= reach)
            .max()
            .or_else(|| samples.iter().copied().filter(|&s| s > at && s <= to).min())
            .unwrap_or(to);
        legs.push(next);
        at = next;
    }
    legs
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
    let sample_list: Vec<u64> = plan.iter().map(|p| p.0).collect();
    let leg_steps = sample_list.last().copied().unwrap_or(0).div_ceil(BASE_LEGS).max(1);
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
        // The base run advances in legs, each ending in a checkpoint, so that one stopped before this hold's
        // start (a full-size path takes hours) resumes from its last leg, not from the previous hold's start. A
        // resumed run continues bit for bit (`crate::driver`), so the legs change no result.
        let mut here = here;
        for s_leg in base_legs(&sample_list, here.unwrap_or(0), s_ck, leg_steps) {
            let t_here = here.map_or(0.0, |h| h as f64 * dt);
            let t_leg = s_leg as f64 * dt;
            let options = RunOptions {
                force: true,
                progress: false,
                checkpoint_every: None,
                checkpoint_every_sim: Some(t_leg - t_here - 0.5 * dt),
                formats: crate::driver::formats::Formats::NONE,
                stop_after_checkpoints: Some(1),
                ..RunOptions::default()
            };
            eprintln!(
                "spinup critical: base run to t = {t_leg} s of {t_ck} s (T_final = {tf} h starts at {} s)",
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
                        "{}: the base run ended before t = {t_leg} s",
                        base_dir.display()
                    )));
                }
            }
            here = Some(s_leg);
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
            coordination_loaded: f64::NAN,
            fraction_0_contacts: 0.0,
            fraction_1_contact: 0.0,
            rves: 5,
            s_max: 1.0,
            p_max: 1.0,
            theta_max_deg: theta,
        }
    }

    fn hold(theta: impl Fn(f64) -> f64, eta: impl Fn(f64) -> f64, coord: impl Fn(f64) -> f64) -> Vec<SpinupSample> {
        (0..100)
            .map(|k| {
                let x = k as f64 / 99.0;
                sample(1000.0 + 10.0 * k as f64, theta(x), eta(x), coord(x), true)
            })
            .collect()
    }

    fn verdict(tf: f64, s: &[SpinupSample], selected: CreepCriterionKind) -> HoldVerdict {
        let paper = paper_criterion(None).unwrap();
        judge_hold(s, 1000.0, &paper, &CreepCriterion::ours(), selected, tf, PathBuf::new())
    }

    /// The creep criteria on synthetic holds: a steady θ_max is stable, a θ_max rising by 2° over the hold creeps
    /// under both; T_c,3 is the first stable T_final (every slower one stable too) and φ the largest θ_max of
    /// that hold, not of the creeping one beside it.
    #[test]
    fn hold_verdicts_give_t_c3_and_phi() {
        let flat = |v: f64| move |_: f64| v;
        let runs = vec![
            verdict(
                2.40,
                &hold(|x| 40.0 + 2.0 * x, flat(0.74), flat(9.0)),
                CreepCriterionKind::Paper,
            ),
            verdict(
                2.41,
                &hold(flat(39.0), flat(0.74), flat(9.0)),
                CreepCriterionKind::Paper,
            ),
            verdict(
                2.42,
                &hold(flat(37.5), flat(0.74), flat(9.0)),
                CreepCriterionKind::Paper,
            ),
        ];
        assert!(!runs[0].stable && runs[0].drifting == vec!["theta_max"]);
        assert_eq!(runs[0].ours.drifting, vec!["theta_max"]);
        assert!(runs[1].stable && runs[2].stable);
        for k in CreepCriterionKind::ALL {
            assert_eq!(critical_from_verdicts(&runs, k), (Some(2.41), Some(39.0)));
        }
        assert!(search_done(&runs) && !search_done(&runs[..2]));
        // `--all-holds` never stops early; the default stops exactly when the search is done
        assert!(search_stops(&runs, false) && !search_stops(&runs, true) && !search_stops(&runs[..2], false));
        // a released run is never stable, under either criterion
        let mut s = hold(flat(30.0), flat(0.74), flat(9.0));
        s[50].forcing = false;
        let v = verdict(2.5, &s, CreepCriterionKind::Paper);
        assert!(!v.stable && !v.paper.stable && !v.ours.stable && v.released);
        assert!(
            verdict_line(&v).contains("paper disrupted, ours disrupted"),
            "{}",
            verdict_line(&v)
        );
    }

    /// The verdict made monotone: a hold that happens to be stable below a creeping one is set aside, T_c,3 is where
    /// the trailing run of stable holds begins, and the search is not done while the slowest hold creeps.
    #[test]
    fn a_stable_hold_below_a_creeping_one_is_set_aside() {
        let flat = |v: f64| move |_: f64| v;
        let rising = |x: f64| 40.0 + 2.0 * x;
        let kinds = [
            (2.40, false),
            (2.45, true), // lucky: stable below a creeping hold
            (2.50, false),
            (2.55, true),
            (2.60, true),
        ];
        let runs: Vec<HoldVerdict> = kinds
            .iter()
            .map(|&(tf, stable)| {
                let s = if stable {
                    hold(flat(38.0), flat(0.74), flat(9.0))
                } else {
                    hold(rising, flat(0.74), flat(9.0))
                };
                verdict(tf, &s, CreepCriterionKind::Paper)
            })
            .collect();
        for k in CreepCriterionKind::ALL {
            assert_eq!(critical_from_verdicts(&runs, k), (Some(2.55), Some(38.0)));
            assert_eq!(set_aside(&runs, k), vec![2.45]);
            // after the hold at 2.50 h the search is not done although 2.45 h was stable with one hold after it
            assert!(!search_done(&runs[..3]) && !search_done(&runs[..4]) && search_done(&runs));
            // the slowest hold creeping: no T_c,3 at all
            assert_eq!(critical_from_verdicts(&runs[..3], k), (None, None));
        }
    }

    /// Both T_c,3 values from one search: holds at 2.55–2.58 h lose 0.2 contacts per particle over the hold with
    /// θ_max and η_B flat (our RCP holds), 2.59 h and later keep them. Ours finds T_c,3 = 2.55 h, the paper's
    /// 2.59 h; the selected criterion fills the top-level verdict, and the search is done only once both have a
    /// stable hold and one more.
    #[test]
    fn both_criteria_give_their_own_t_c3_when_only_the_coordination_number_drifts() {
        let grid = [2.55, 2.56, 2.57, 2.58, 2.59, 2.60];
        let runs: Vec<HoldVerdict> = grid
            .iter()
            .map(|&tf| {
                let loss = if tf < 2.585 { 0.2 } else { 0.0 };
                let theta = 50.0 - 10.0 * (tf - 2.55);
                verdict(
                    tf,
                    &hold(move |_| theta, |_| 0.65, move |x| 5.5 - loss * x),
                    CreepCriterionKind::Ours,
                )
            })
            .collect();
        assert!(runs[0].stable && !runs[0].paper.stable);
        assert_eq!(runs[0].paper.drifting, vec!["coordination_number"]);
        assert!(runs[0].drift.coordination < -0.09 && runs[0].drift.coordination > -0.11);
        let (t_ours, phi_ours) = critical_from_verdicts(&runs, CreepCriterionKind::Ours);
        let (t_paper, phi_paper) = critical_from_verdicts(&runs, CreepCriterionKind::Paper);
        assert_eq!(t_ours, Some(2.55));
        assert_eq!(t_paper, Some(2.59));
        assert!((phi_ours.unwrap() - 50.0).abs() < 1e-9);
        assert!((phi_paper.unwrap() - (50.0 - 10.0 * 0.04)).abs() < 1e-9);
        assert!(!search_done(&runs[..4]) && !search_done(&runs[..5]) && search_done(&runs));
        let csv = critical_csv(&runs);
        assert!(csv.starts_with(CRITICAL_CSV_HEADER));
        assert!(
            csv.lines()
                .nth(1)
                .unwrap()
                .ends_with(",false,coordination_number,true,"),
            "{csv}"
        );
        assert_eq!(csv.lines().count(), grid.len() + 1);
    }

    /// Regression guard: a bad `--coordination-tolerance` is refused with the option's name and the expected
    /// value, before any run starts.
    #[test]
    fn base_run_legs_end_on_samples_and_reach_the_hold_start() {
        let samples: Vec<u64> = (0..=20).map(|k| k * 10).collect();
        // 0 → 200 in legs of at most 45 steps: the last sample within each reach
        assert_eq!(base_legs(&samples, 0, 200, 45), [40, 80, 120, 160, 200]);
        // a resumed base run starts from its checkpoint
        assert_eq!(base_legs(&samples, 120, 200, 45), [160, 200]);
        // legs shorter than the sample spacing still advance, one sample at a time
        assert_eq!(base_legs(&samples, 0, 30, 3), [10, 20, 30]);
        assert!(base_legs(&samples, 200, 200, 45).is_empty());
    }

    #[test]
    fn coordination_tolerance_must_be_positive() {
        for bad in [0.0, -0.1, f64::NAN] {
            let e = paper_criterion(Some(bad)).unwrap_err().to_string();
            assert!(
                e.contains("--coordination-tolerance must be") && e.contains("> 0"),
                "{e}"
            );
        }
        assert_eq!(paper_criterion(Some(0.1)).unwrap().coordination, Some(0.1));
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
