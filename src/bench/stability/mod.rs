//! The stability suite: the interacting-ellipsoids model (Roig03 §2, Eqs. 10–14, 28–41) pushed to its
//! regimes of trouble, each as an ordinary scene run through [`crate::driver::run_scene`].
//!
//! The cases ([`cases::all_cases`]) are (a) head-on impacts at the calibrated speed of Roig03 Eq. 14 and
//! above it (the contact-barrier detector of [`crate::ellipsoid::barrier`] must name the pair), (b) needles
//! and plates with C/A = 0.05, (c) a mass ratio of 1e-6, (d) attitudes at the Euler-angle singularity θ = 0,
//! (e) stiff dissipation F0 = 100 s m⁻², (f) κ from 1.6 to 50, (g) a cloud of N = 2000 collapsing,
//! (h) a resting contact held for 1e6 s. `rubblepile bench stability` runs them and writes `stability.csv`
//! and `stability.md`; `tests/stability.rs` runs the quick set.
//!
//! # Verdicts
//!
//! Every case states its numeric criteria in its row's `note`:
//! - **pass**: the run did what the case expects (completed, or stopped with the expected message) and
//!   every criterion holds, *including* an expected warning (the 3× impact must report its overrun);
//! - **warn**: the run completed and the hard criteria hold, but a soft one missed (e.g. the energy residual
//!   between the strict and the loose bound, or an unexpected barrier warning);
//! - **fail**: a hard criterion broke: a crash or a stop the case does not expect, NaN, an energy residual
//!   above the loose bound, a missing or wrong warning.

pub mod cases;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::driver::{RunError, RunOptions, RunSummary, run_scene};
use crate::ellipsoid::barrier::{BarrierSettings, contacts};
use crate::ellipsoid::body::{Body, Ellipsoid};
use crate::ellipsoid::equations::EllipsoidSystem;
use crate::ellipsoid::output::read_bodies_csv;
use crate::ellipsoid::scene::{LoadedScene, parse_scene};
use crate::integrate::{Tolerances, make_integrator};
use crate::math::{Vec3, Vec4};

/// Columns of `stability.csv`.
pub const CSV_COLUMNS: [&str; 11] = [
    "case",
    "description",
    "steps",
    "rejections",
    "rhs_evaluations",
    "wall_seconds",
    "energy_error",
    "max_quat_norm_error",
    "min_step",
    "verdict",
    "note",
];

/// A case's verdict (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Verdict {
    /// Everything as expected.
    Pass,
    /// Completed; a soft criterion missed.
    Warn,
    /// A hard criterion broke.
    Fail,
}

impl Verdict {
    /// `"pass"`, `"warn"` or `"fail"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Pass => "pass",
            Verdict::Warn => "warn",
            Verdict::Fail => "fail",
        }
    }
}

/// A verdict and the note that explains it (criteria and measured values).
#[derive(Debug, Clone, PartialEq)]
pub struct Judgement {
    /// The verdict.
    pub verdict: Verdict,
    /// One line: what was measured against which bound.
    pub note: String,
}

/// Builds a [`Judgement`] from named checks: each check is `(hard, ok, text)`; the verdict is fail if
/// a hard check failed, warn if a soft one did, else pass. The note joins the texts with `; `.
pub fn judge(checks: &[(bool, bool, String)]) -> Judgement {
    let verdict = if checks.iter().any(|(hard, ok, _)| *hard && !ok) {
        Verdict::Fail
    } else if checks.iter().any(|(_, ok, _)| !ok) {
        Verdict::Warn
    } else {
        Verdict::Pass
    };
    let note = checks
        .iter()
        .map(|(_, ok, text)| if *ok { text.clone() } else { format!("NOT MET: {text}") })
        .collect::<Vec<_>>()
        .join("; ");
    Judgement { verdict, note }
}

/// What a case's run left behind, handed to the case's check.
#[derive(Debug)]
pub struct CaseRun {
    /// The run directory.
    pub dir: PathBuf,
    /// The scene that ran.
    pub scene: LoadedScene,
    /// Its summary (also for a failed run).
    pub summary: RunSummary,
    /// The failure message when the run stopped early, `None` when it completed.
    pub failure: Option<String>,
}

impl CaseRun {
    /// The snapshots the run wrote, as `(t, bodies)`, in time order.
    pub fn snapshots(&self) -> Result<Vec<(f64, Vec<Body>)>, crate::bench::BenchError> {
        let mut out = Vec::new();
        for (k, &t) in self.scene.output.times.iter().enumerate() {
            let path = self.dir.join("snapshots").join(format!("{k}.csv"));
            if !path.exists() {
                break; // a stopped run
            }
            out.push((t, read_bodies(&path)?));
        }
        Ok(out)
    }

    /// The largest `relative speed / calibrated speed` of any touching pair ([`crate::ellipsoid::barrier::contacts`])
    /// and the smallest centre distance in units of the touching distance, `(0, 1)` when no pair touched,
    /// sampled every `dt` s: the case's scene is integrated again (same physics, method and tolerances), so that
    /// the run itself can keep a coarse output grid and its step counts say what the dynamics costs. An
    /// integrator failure ends the sampling quietly (the run's own row reports it).
    pub fn contact_extremes(&self, dt: f64) -> Result<(f64, f64), crate::bench::BenchError> {
        let scene = &self.scene;
        let system = EllipsoidSystem::new(&scene.bodies, scene.model, scene.physics);
        let settings = scene.integrator;
        let tolerances = Tolerances::scale_free(settings.rtol, settings.atol, &system);
        let mut integrator =
            make_integrator(settings.method, tolerances, settings.step).map_err(|e| format!("integrator: {e}"))?;
        integrator.set_span(scene.t_end);
        let barrier = BarrierSettings::for_kappa_source(&scene.kappa_source);
        let (mut t, mut y) = (0.0, system.initial_state());
        let (mut ratio, mut sep) = (0.0_f64, 1.0_f64);
        loop {
            for c in contacts(&scene.model, &barrier, &system.bodies_at(t, &y)) {
                ratio = ratio.max(c.speed / c.calibrated_speed);
                sep = sep.min(c.separation_ratio());
            }
            if t >= scene.t_end {
                break;
            }
            let next = (t + dt).min(scene.t_end);
            if integrator.advance(&system, &mut t, &mut y, next).is_err() {
                break;
            }
        }
        Ok((ratio, sep))
    }

    /// Whether the run completed.
    pub fn completed(&self) -> bool {
        self.failure.is_none()
    }

    /// Number of distinct pairs the barrier detector reported.
    pub fn overrun_pairs(&self) -> usize {
        self.summary.barrier.as_ref().map_or(0, |b| b.overrun_pairs)
    }
}

/// Reads a snapshot file into bodies.
pub fn read_bodies(path: &Path) -> Result<Vec<Body>, crate::bench::BenchError> {
    let records = read_bodies_csv(path).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(records
        .iter()
        .map(|r| Body {
            shape: Ellipsoid {
                axes: Vec3::from(r.axes),
                mass: r.mass,
            },
            position: Vec3::from(r.position),
            velocity: Vec3::from(r.velocity),
            quaternion: Vec4::from(r.quaternion),
            spin_body: Vec3::from(r.spin_body),
        })
        .collect())
}

/// The check of a case: judges its run.
pub type Check = Box<dyn Fn(&CaseRun) -> Judgement + Send + Sync>;

/// One case: a scene and its check.
pub struct Case {
    /// Short id (`a2-headon-3x`), also the run directory's name.
    pub id: String,
    /// One line: the regime and its parameters.
    pub description: String,
    /// The scene (TOML text, as `rubblepile run` reads it).
    pub scene_toml: String,
    /// The case's judgement of its run.
    pub check: Check,
}

impl Case {
    /// The same case run by `method` instead of the suite's Bulirsch–Stoer (same tolerances): its scene's
    /// `[integrator] method` line replaced.
    pub fn with_method(self, method: crate::integrate::Method) -> Case {
        Case {
            scene_toml: self
                .scene_toml
                .replace("method = \"bulirsch-stoer\"\n", &format!("method = \"{method}\"\n")),
            ..self
        }
    }
}

impl std::fmt::Debug for Case {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Case")
            .field("id", &self.id)
            .field("description", &self.description)
            .finish_non_exhaustive()
    }
}

/// One row of `stability.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct StabilityRow {
    /// Case id.
    pub case: String,
    /// Case description.
    pub description: String,
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps.
    pub rejections: u64,
    /// Right-hand-side evaluations.
    pub rhs_evaluations: u64,
    /// Wall-clock time of the case (s): the run, including output.
    pub wall_seconds: f64,
    /// The run's relative energy residual `max |H − H0 − 2∫F| / energy scale` ([`RunSummary::energy_error`]).
    pub energy_error: f64,
    /// max over samples and bodies of `||q| − 1|`.
    pub max_quat_norm_error: f64,
    /// Smallest accepted step (s); NaN before the first step.
    pub min_step: f64,
    /// The verdict.
    pub verdict: Verdict,
    /// The criteria and measured values.
    pub note: String,
}

/// A case's result: its row and its run (for further checks by tests).
#[derive(Debug)]
pub struct CaseResult {
    /// The row.
    pub row: StabilityRow,
    /// The run.
    pub run: CaseRun,
}

/// Why the suite could not run. One-line messages.
#[derive(Debug, thiserror::Error)]
pub enum StabilityError {
    /// The output directory already holds results and `--force` was not given.
    #[error("--out: {} already holds stability results; use --force to overwrite them", .0.display())]
    OutputExists(PathBuf),
    /// A case's scene did not parse (a bug in the case definitions).
    #[error("case {case}: scene: {message}")]
    Scene {
        /// Case id.
        case: String,
        /// The scene error.
        message: String,
    },
    /// A run could not start or write its outputs.
    #[error("case {case}: {message}")]
    Run {
        /// Case id.
        case: String,
        /// The error.
        message: String,
    },
    /// Writing a result file failed.
    #[error("{}: {source}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
}

/// Runs one case into `runs_dir/<id>` (`force`: overwrite a previous run there) and judges it.
pub fn run_case(case: &Case, runs_dir: &Path, force: bool) -> Result<CaseResult, StabilityError> {
    let name = format!("{}.toml", case.id);
    let scene = parse_scene(&case.scene_toml, &name, None).map_err(|e| StabilityError::Scene {
        case: case.id.clone(),
        message: e.to_string(),
    })?;
    let dir = runs_dir.join(&case.id);
    let options = RunOptions {
        force,
        progress: false,
        checkpoint_every: None,
        checkpoint_every_sim: None,
        formats: crate::driver::formats::Formats::NONE,
        stop_after_checkpoints: None,
        ..RunOptions::default()
    };
    let started = Instant::now();
    let (summary, failure) = match run_scene(&scene, &dir, &options) {
        Ok(s) => (s, None),
        Err(RunError::Failed { cause, summary, .. }) => (*summary, Some(cause)),
        Err(e) => {
            return Err(StabilityError::Run {
                case: case.id.clone(),
                message: e.to_string(),
            });
        }
    };
    let wall_seconds = started.elapsed().as_secs_f64();
    let run = CaseRun {
        dir,
        scene,
        summary,
        failure,
    };
    let j = (case.check)(&run);
    let s = &run.summary;
    let row = StabilityRow {
        case: case.id.clone(),
        description: case.description.clone(),
        steps: s.steps_accepted,
        rejections: s.steps_rejected,
        rhs_evaluations: s.rhs_evaluations,
        wall_seconds,
        energy_error: s.energy_error,
        max_quat_norm_error: s.quaternion_norm_error,
        min_step: s.smallest_step.unwrap_or(f64::NAN),
        verdict: j.verdict,
        note: j.note,
    };
    Ok(CaseResult { row, run })
}

/// The result files of the suite in `out`.
pub fn result_paths(out: &Path) -> [PathBuf; 2] {
    [out.join("stability.csv"), out.join("stability.md")]
}

/// Refuses an `out` that already holds results unless `force`; creates it.
pub fn prepare_out(out: &Path, force: bool) -> Result<(), StabilityError> {
    if !force && (result_paths(out).iter().any(|p| p.exists()) || out.join("runs").exists()) {
        return Err(StabilityError::OutputExists(out.to_path_buf()));
    }
    std::fs::create_dir_all(out.join("runs")).map_err(|source| StabilityError::Io {
        path: out.join("runs"),
        source,
    })
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Writes `stability.csv` (columns [`CSV_COLUMNS`]).
pub fn write_csv(path: &Path, rows: &[StabilityRow]) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(f, "{}", CSV_COLUMNS.join(","))?;
    for r in rows {
        writeln!(
            f,
            "{},{},{},{},{},{:.3},{:.3e},{:.3e},{:.3e},{},{}",
            csv_field(&r.case),
            csv_field(&r.description),
            r.steps,
            r.rejections,
            r.rhs_evaluations,
            r.wall_seconds,
            r.energy_error,
            r.max_quat_norm_error,
            r.min_step,
            r.verdict.as_str(),
            csv_field(&r.note)
        )?;
    }
    f.flush()
}

/// Writes `stability.md`: one table row per case, notes below.
pub fn write_markdown(path: &Path, rows: &[StabilityRow], title: &str) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(f, "# {title}\n")?;
    writeln!(
        f,
        "| case | steps | rejected | RHS | wall (s) | energy error | max \\|\\|q\\|-1\\| | min step (s) | verdict |"
    )?;
    writeln!(f, "|---|---:|---:|---:|---:|---:|---:|---:|---|")?;
    for r in rows {
        writeln!(
            f,
            "| {} | {} | {} | {} | {:.2} | {:.1e} | {:.1e} | {:.1e} | {} |",
            r.case,
            r.steps,
            r.rejections,
            r.rhs_evaluations,
            r.wall_seconds,
            r.energy_error,
            r.max_quat_norm_error,
            r.min_step,
            r.verdict.as_str()
        )?;
    }
    writeln!(f, "\n## Cases and criteria\n")?;
    for r in rows {
        writeln!(
            f,
            "- **{}** ({}): {}. {}",
            r.case,
            r.verdict.as_str(),
            r.description,
            r.note
        )?;
    }
    f.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn judge_orders_verdicts() {
        let ok = |hard| (hard, true, "x".to_string());
        let bad = |hard| (hard, false, "y".to_string());
        assert_eq!(judge(&[ok(true), ok(false)]).verdict, Verdict::Pass);
        assert_eq!(judge(&[ok(true), bad(false)]).verdict, Verdict::Warn);
        let j = judge(&[bad(true), bad(false)]);
        assert_eq!(j.verdict, Verdict::Fail);
        assert_eq!(j.note, "NOT MET: y; NOT MET: y");
    }

    #[test]
    fn csv_fields_are_quoted() {
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("say \"x\""), "\"say \"\"x\"\"\"");
        assert_eq!(csv_field("plain"), "plain");
    }
}
