//! One case of the stability suite and its judgement: the [`Case`] (a scene and its check), what its run left
//! behind ([`CaseRun`]), and the [`Verdict`] with its note ([`judge`]; pass, warn and fail as the suite's module
//! docs define them). In a file of its own so that the cases (`stability::cases`) build and judge runs without
//! naming `stability/mod.rs`, which runs them.

use std::path::{Path, PathBuf};

use rubblepile::driver::RunSummary;
use rubblepile::ellipsoid::barrier::{BarrierSettings, contacts};
use rubblepile::ellipsoid::body::{Body, Ellipsoid};
use rubblepile::ellipsoid::equations::EllipsoidSystem;
use rubblepile::ellipsoid::output::read_bodies_csv;
use rubblepile::ellipsoid::scene::LoadedScene;
use rubblepile::integrate::{Tolerances, make_integrator};
use rubblepile::math::{Vec3, Vec4};

/// A case's verdict (see the module docs of `suite`).
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
    pub fn snapshots(&self) -> Result<Vec<(f64, Vec<Body>)>, String> {
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

    /// The largest `relative speed / calibrated speed` of any touching pair ([`rubblepile::ellipsoid::barrier::contacts`])
    /// and the smallest centre distance in units of the touching distance, `(0, 1)` when no pair touched,
    /// sampled every `dt` s: the case's scene is integrated again (same physics, method and tolerances), so that
    /// the run itself can keep a coarse output grid and its step counts say what the dynamics costs. An
    /// integrator failure ends the sampling quietly (the run's own row reports it).
    pub fn contact_extremes(&self, dt: f64) -> Result<(f64, f64), String> {
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
    #[cfg_attr(not(test), allow(dead_code, reason = "read by the suite's tests"))]
    pub fn completed(&self) -> bool {
        self.failure.is_none()
    }

    /// Number of distinct pairs the barrier detector reported.
    pub fn overrun_pairs(&self) -> usize {
        self.summary.barrier.as_ref().map_or(0, |b| b.overrun_pairs)
    }
}

/// Reads a snapshot file into bodies.
pub fn read_bodies(path: &Path) -> Result<Vec<Body>, String> {
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
    pub fn with_method(self, method: rubblepile::integrate::Method) -> Case {
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
