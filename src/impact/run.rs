//! One impact run (Roig03 §3) as a library call: a projectile on a rubble-pile target, run to `t_end`.
//!
//! [`run_impact`] reads the target bodies file, adds the projectile ([`set_up_impact`]), writes into the run
//! directory
//! - `initial_bodies.csv`: target + projectile in the centre-of-mass frame (snapshot columns),
//! - `impact.json`: the [`ImpactSetup`] (Q, impact time, projectile, …) plus `"target"`, the target file,
//! - `scene.toml`: an ordinary scene whose `bodies_file` is `initial_bodies.csv` (κ calibrated with Roig03
//!   Eq. 14 over target + projectile at the impact speed; gravity, contact, dissipation; Bulirsch–Stoer),
//!
//! and runs that scene with [`run_scene`]; the same run again is `rubblepile run DIR/scene.toml --out OTHER`,
//! and an interrupted one continues with [`crate::driver::resume_run`]. `rubblepile impact` and
//! `rubblepile campaign` are thin wrappers around this module.

use std::path::{Path, PathBuf};

use crate::driver::{RunOptions, RunSummary, prepare_output_dir, run_scene};
use crate::ellipsoid::body::{Body, InertiaModel};
use crate::ellipsoid::calibration::{KappaReading, calibrate_kappa_read};
use crate::ellipsoid::equations::G_SI;
use crate::ellipsoid::output::write_snapshot;
use crate::ellipsoid::scene::{LoadedScene, parse_scene};
pub use crate::impact::error::{ImpactError, read_target};
use crate::impact::pile::{ProjectilePile, set_up_pile_impact};
use crate::impact::projectile::{ImpactSetup, ProjectileSpec, set_up_impact};
use crate::integrate::Method;
use crate::io::run_lock::DirLock;
use crate::io::scene_file::MAX_TIMESERIES_ROWS;

/// Default end time (s).
pub const DEFAULT_T_END: f64 = 10_000.0;
/// Default relative (and absolute, in m, m/s, rad/s) tolerance of Bulirsch–Stoer, over the whole run. 1e-6 costs the
/// same RHS evaluations as the per-step 1e-9 of earlier builds on the N200 impact and conserves energy better
/// (7e-12 against 4.6e-11; analysis/work_precision/REPORT.md).
pub const DEFAULT_RTOL: f64 = 1e-6;

/// Default tolerance of the Dormand–Prince methods, which apply it to each step: at 1e-8, Dop853 runs the N2000 + P2
/// impact to 10 000 s with an energy error of 1.6e-9 (analysis/n2000/REPORT.md).
pub const DEFAULT_RTOL_PER_STEP: f64 = 1e-8;

/// The impact's default tolerance for `method`: [`DEFAULT_RTOL`] for the Bulirsch–Stoer methods (of the whole run),
/// [`DEFAULT_RTOL_PER_STEP`] for the others.
pub fn default_rtol(method: Method) -> f64 {
    match method {
        Method::BulirschStoer | Method::BulirschStoerImplicit => DEFAULT_RTOL,
        _ => DEFAULT_RTOL_PER_STEP,
    }
}
/// Default dissipation coefficient F0 (s m⁻²): Roig03 §2.4's "F0 ≈ 1" in its kilometres and seconds (1 s km⁻²);
/// a scan made before that reading found 1e-6 reproduces the bound fraction, f_KE, spin–size exponent and best
/// spin-histogram n most closely (analysis/roig2003/F0_SCAN.md).
pub const DEFAULT_F0: f64 = 1e-6;
/// Default β of Roig03 Eq. 14.
pub const DEFAULT_BETA: f64 = 10.0;
/// Default time at which the surfaces first touch (s).
pub const DEFAULT_CONTACT_TIME: f64 = 90.0;
/// Default snapshot times (s).
pub const DEFAULT_SNAPSHOTS: [f64; 5] = [0.0, 100.0, 400.0, 1000.0, 10_000.0];
/// Default time-series cadence (s).
pub const DEFAULT_EVERY: f64 = 10.0;
/// Default impact angle ζ (degrees).
pub const DEFAULT_ANGLE_DEG: f64 = 45.0;
/// Default seed of the projectile's attitude.
pub const DEFAULT_SEED: u64 = 1;

/// [`DEFAULT_SNAPSHOTS`] cut to `[0, t_end]`, with `t_end` added when it is not among them: the snapshot
/// times of a run to `t_end` when none are given.
pub fn default_snapshots(t_end: f64) -> Vec<f64> {
    let mut times: Vec<f64> = DEFAULT_SNAPSHOTS.iter().copied().filter(|&t| t < t_end).collect();
    times.push(t_end);
    times
}

/// The snapshot times of an impact to `t_end` (s): the `list` when given, else those of a cadence `every` (s,
/// checked: [`crate::io::output_times::checked_cadence_times`], errors naming `--snapshot-every` and `--t-end`),
/// else [`default_snapshots`].
pub fn snapshot_times(t_end: f64, list: Option<&[f64]>, every: Option<f64>) -> Result<Vec<f64>, String> {
    match (list, every) {
        (Some(times), _) => Ok(times.to_vec()),
        (None, Some(every)) => {
            crate::io::output_times::checked_cadence_times(t_end, every, "--snapshot-every", "--t-end")
        }
        (None, None) => Ok(default_snapshots(t_end)),
    }
}

/// Everything that defines one impact run. SI units unless the name says otherwise; the defaults (of
/// [`ImpactConfig::new`]) are those of `rubblepile impact`.
#[derive(Debug, Clone, PartialEq)]
pub struct ImpactConfig {
    /// Target bodies file (snapshot columns, e.g. `targets/N200_T4.csv` from `rubblepile target build`).
    pub target: PathBuf,
    /// The projectile (radius, speed, density, shape); see [`ProjectileSpec::preset`].
    pub projectile: ProjectileSpec,
    /// Angle ζ between the trajectory and the target's spin axis z (degrees, 0–180; default 45).
    pub angle_deg: f64,
    /// Seed of the projectile's attitude (default 1); also the scene's seed.
    pub seed: u64,
    /// Time at which the surfaces first touch (s, ≥ 0; default 90).
    pub contact_time: f64,
    /// End time (s, > 0; default 10 000).
    pub t_end: f64,
    /// Integrator (default Bulirsch–Stoer, Roig03's; `Dop853` and `Dopri5` project the attitudes onto
    /// `|q| = 1` at every sample, see [`crate::ellipsoid::scene::IntegratorSection::project_attitudes`]).
    pub method: Method,
    /// Relative and absolute tolerance (> 0; default 1e-6). Bulirsch–Stoer applies it to the whole run, the
    /// Dormand–Prince methods to each step.
    pub rtol: f64,
    /// Dissipation coefficient F0 (s m⁻², ≥ 0; default 1e-6).
    pub f0: f64,
    /// β of Roig03 Eq. 14 (> 0; default 10): κ is calibrated over target + projectile at the impact speed.
    pub beta: f64,
    /// Which kinetic energy the barrier is β times (Roig03 Eq. 13's `K`; default printed, `½ m_l v²`).
    pub kappa_reading: KappaReading,
    /// Snapshot times (s), strictly increasing in `[0, t_end]` (default 0, 100, 400, 1000, 10 000).
    pub snapshots: Vec<f64>,
    /// Time-series cadence (s, > 0; default 10).
    pub every: f64,
    /// Inertia model of the ellipsoids (default Gaussian, Roig03 Eq. 4; `Uniform` = homogeneous solids, to show
    /// the spin bias of §4.3).
    pub inertia: InertiaModel,
    /// A rubble-pile projectile ([`crate::impact::pile`]; default none): when given, it is thrown instead of
    /// the single ellipsoid, at `projectile.speed` (`projectile` then describes the same-mass ellipsoid, see
    /// [`ProjectilePile::equivalent_spec`]).
    pub pile: Option<ProjectilePile>,
}

impl ImpactConfig {
    /// The default impact of `projectile` on `target` (see the field docs for the defaults).
    pub fn new(target: PathBuf, projectile: ProjectileSpec) -> Self {
        ImpactConfig {
            target,
            projectile,
            angle_deg: DEFAULT_ANGLE_DEG,
            seed: DEFAULT_SEED,
            contact_time: DEFAULT_CONTACT_TIME,
            t_end: DEFAULT_T_END,
            method: Method::BulirschStoer,
            rtol: DEFAULT_RTOL,
            f0: DEFAULT_F0,
            beta: DEFAULT_BETA,
            kappa_reading: KappaReading::Printed,
            snapshots: DEFAULT_SNAPSHOTS.to_vec(),
            every: DEFAULT_EVERY,
            inertia: InertiaModel::Gaussian,
            pile: None,
        }
    }

    /// Checks every value is in range. Errors are [`ImpactError::Invalid`], naming the field as in this
    /// struct (`angle_deg`, `projectile.speed`, `snapshots[2]`, …).
    pub fn validate(&self) -> Result<(), ImpactError> {
        let invalid = |field: &str, message: String| {
            Err(ImpactError::Invalid {
                field: field.to_string(),
                message,
            })
        };
        let positive = |x: f64| x.is_finite() && x > 0.0;
        let p = &self.projectile;
        if !positive(p.equivalent_radius) {
            return invalid(
                "projectile.equivalent_radius",
                format!("must be > 0 m, got {}", p.equivalent_radius),
            );
        }
        if !positive(p.speed) {
            return invalid("projectile.speed", format!("must be > 0 m/s, got {}", p.speed));
        }
        if !positive(p.density) {
            return invalid("projectile.density", format!("must be > 0 kg/m^3, got {}", p.density));
        }
        let [b, c] = p.axis_ratios;
        if !(b <= 1.0 && c <= b && c > 0.0) {
            return invalid(
                "projectile.axis_ratios",
                format!("need 1 >= B/A >= C/A > 0, got [{b}, {c}]"),
            );
        }
        if !(0.0..=180.0).contains(&self.angle_deg) {
            return invalid(
                "angle_deg",
                format!("expected 0 to 180 degrees, got {}", self.angle_deg),
            );
        }
        if !(self.contact_time >= 0.0 && self.contact_time.is_finite()) {
            return invalid("contact_time", format!("must be >= 0 s, got {}", self.contact_time));
        }
        if !positive(self.t_end) {
            return invalid("t_end", format!("must be > 0 s and finite, got {}", self.t_end));
        }
        if self.method == Method::Rk4 {
            return invalid(
                "method",
                "must be bulirsch-stoer, dop853 or dopri5, or bulirsch-stoer-implicit (rk4 has a fixed step, which an \
                 impact cannot choose)"
                    .into(),
            );
        }
        let min_rtol = crate::io::scene_file::MIN_RTOL;
        if !(self.rtol.is_finite() && (min_rtol..1.0).contains(&self.rtol)) {
            return invalid(
                "rtol",
                format!(
                    "must be in [{min_rtol:e}, 1), got {:e} (1 or more controls nothing; below {min_rtol:e} the error \
                     estimate is round-off)",
                    self.rtol
                ),
            );
        }
        if !(self.f0 >= 0.0 && self.f0.is_finite()) {
            return invalid("f0", format!("must be >= 0 s m^-2 and finite, got {}", self.f0));
        }
        if !positive(self.beta) {
            return invalid("beta", format!("must be > 0 and finite, got {}", self.beta));
        }
        if !positive(self.every) {
            return invalid("every", format!("must be > 0 s and finite, got {}", self.every));
        }
        if self.t_end / self.every > MAX_TIMESERIES_ROWS {
            return invalid(
                "every",
                format!(
                    "too small for t_end = {} s: would write {:e} time-series rows (at most 1e8), got {}",
                    self.t_end,
                    self.t_end / self.every,
                    self.every
                ),
            );
        }
        for (k, &t) in self.snapshots.iter().enumerate() {
            if !(t.is_finite() && (0.0..=self.t_end).contains(&t)) {
                return invalid(
                    &format!("snapshots[{k}]"),
                    format!("must be in [0, t_end = {}] s, got {t}", self.t_end),
                );
            }
            if k > 0 && t <= self.snapshots[k - 1] {
                return invalid(
                    "snapshots",
                    format!("must be strictly increasing, got {} then {t}", self.snapshots[k - 1]),
                );
            }
        }
        Ok(())
    }

    /// The scene file of this impact (bodies in `initial_bodies.csv` beside it); `title` becomes its first,
    /// comment, line.
    pub fn scene_toml(&self, title: &str, projectile_index: usize) -> String {
        let times: Vec<String> = self.snapshots.iter().map(|t| format!("{t:?}")).collect();
        let inertia = match self.inertia {
            InertiaModel::Gaussian => "gaussian",
            InertiaModel::Uniform => "uniform",
        };
        format!(
            "# {title}\n# Generated by `rubblepile impact`; the same run: `rubblepile run scene.toml --out OTHER_DIR`.\n\
             [scene]\nkind = \"ellipsoids\"\nt_end = {t_end:?}\nseed = {seed}\nbodies_file = \"initial_bodies.csv\"\n\n\
             [model]\ncalibrate = {{ beta = {beta:?}, v = {speed:?}, reading = \"{reading}\" }}\ninertia = \"{inertia}\"\n\n\
             [physics]\ngravity = {{}}\ncontact = {{}}\ndissipation = {{ F0 = {f0:?} }}\n\n\
             [integrator]\nmethod = \"{method}\"\nrtol = {rtol:?}\natol = {rtol:?}\n\n\
             [output]\ntimes = [{times}]\nevery = {every:?}\ntrack = [{projectile_index}]\n",
            t_end = self.t_end,
            seed = self.seed,
            beta = self.beta,
            reading = self.kappa_reading,
            speed = self.projectile.speed,
            f0 = self.f0,
            method = self.method,
            rtol = self.rtol,
            times = times.join(", "),
            every = self.every,
        )
    }

    /// κ that the run's scene will calibrate (Roig03 Eq. 14 over the lightest and the heaviest body of
    /// `target` + projectile, at the impact speed), or why there is none.
    pub fn kappa(&self, target: &[Body]) -> Result<f64, ImpactError> {
        let projectile = self.projectile.shape();
        let incoming: Vec<_> = match &self.pile {
            Some(pile) => pile.bodies.iter().map(|b| b.shape).collect(),
            None => vec![projectile],
        };
        let masses = target.iter().map(|b| b.shape).chain(incoming);
        let small = masses
            .clone()
            .min_by(|a, b| a.mass.total_cmp(&b.mass))
            .unwrap_or(projectile);
        let large = masses.max_by(|a, b| a.mass.total_cmp(&b.mass)).unwrap_or(projectile);
        let kappa = calibrate_kappa_read(
            self.kappa_reading,
            self.beta,
            self.projectile.speed,
            (small.equivalent_radius(), small.mass),
            (large.equivalent_radius(), large.mass),
            G_SI,
        )
        .map_err(|e| ImpactError::Invalid {
            field: "projectile".into(),
            message: format!("kappa calibration over target + projectile fails: {e}"),
        })?;
        if !(kappa.is_finite() && kappa > 1.5) {
            return Err(ImpactError::Invalid {
                field: "projectile".into(),
                message: format!("kappa calibration over target + projectile gave {kappa}, need > 1.5"),
            });
        }
        Ok(kappa)
    }

    /// The impact in memory: bodies, setup, title and scene text (nothing is written).
    pub fn plan(&self, target: &[Body]) -> ImpactPlan {
        let (bodies, setup) = match &self.pile {
            Some(pile) => set_up_pile_impact(
                target,
                pile,
                &self.projectile,
                self.angle_deg,
                self.contact_time,
                self.seed,
            ),
            None => set_up_impact(target, &self.projectile, self.angle_deg, self.contact_time, self.seed),
        };
        let what = match &self.pile {
            Some(pile) => format!("the rubble pile {} (N = {})", pile.file.display(), pile.bodies.len()),
            None => self.projectile.id.clone(),
        };
        let title = format!(
            "Impact of {} ({:.2} km, {:.1} km/s) on {} at zeta = {} deg; Q = {:.3e} erg/g",
            what,
            self.projectile.equivalent_radius / 1e3,
            self.projectile.speed / 1e3,
            self.target.display(),
            self.angle_deg,
            setup.q_erg_per_g
        );
        let scene_toml = self.scene_toml(&title, setup.projectile_index);
        ImpactPlan {
            bodies,
            setup,
            title,
            scene_toml,
        }
    }
}

/// An impact set up in memory by [`ImpactConfig::plan`].
#[derive(Debug, Clone, PartialEq)]
pub struct ImpactPlan {
    /// Target + projectile (the last body) in the centre-of-mass frame: `initial_bodies.csv`.
    pub bodies: Vec<Body>,
    /// The setup: `impact.json` (with `"target"` added).
    pub setup: ImpactSetup,
    /// One-line description (projectile, target, angle, Q), printed by `rubblepile impact`.
    pub title: String,
    /// `scene.toml`.
    pub scene_toml: String,
}

/// An impact whose run directory is written, ready for [`run_scene`].
#[derive(Debug)]
pub struct PreparedImpact {
    /// The scene read back from the run directory's `scene.toml`.
    pub scene: LoadedScene,
    /// What was written.
    pub plan: ImpactPlan,
    /// The run directory's lock ([`crate::io::run_lock`]): keep it until the run has ended, so that no other
    /// process writes the directory between its preparation and the run.
    pub lock: DirLock,
}

/// Validates `cfg`, reads its target, prepares `out` ([`prepare_output_dir`]: refused when not empty unless
/// `force`) and writes `initial_bodies.csv`, `impact.json` and `scene.toml` into it; returns the scene read
/// back, with the directory's lock. Nothing is run.
pub fn prepare_impact(cfg: &ImpactConfig, out: &Path, force: bool) -> Result<PreparedImpact, ImpactError> {
    cfg.validate()?;
    let target = read_target(&cfg.target)?;
    let lock = prepare_output_dir(out, force)?;
    let plan = cfg.plan(&target);
    let io = |p: &Path| {
        let path = p.to_path_buf();
        move |source| ImpactError::Io { path, source }
    };
    let bodies_path = out.join("initial_bodies.csv");
    write_snapshot(&bodies_path, 0.0, &plan.bodies).map_err(io(&bodies_path))?;
    let json_path = out.join("impact.json");
    let mut json = serde_json::to_value(&plan.setup).map_err(|e| ImpactError::Io {
        path: json_path.clone(),
        source: std::io::Error::other(e),
    })?;
    json["target"] = serde_json::Value::String(cfg.target.display().to_string());
    crate::io::safe_write::write_atomic(
        &json_path,
        serde_json::to_string_pretty(&json).unwrap_or_default() + "\n",
    )
    .map_err(io(&json_path))?;
    let scene_path = out.join("scene.toml");
    crate::io::safe_write::write_atomic(&scene_path, &plan.scene_toml).map_err(io(&scene_path))?;
    let scene = parse_scene(&plan.scene_toml, &scene_path.display().to_string(), Some(out))?;
    Ok(PreparedImpact { scene, plan, lock })
}

/// Runs the impact `cfg` in `out`: [`prepare_impact`] (with `options.force`), then [`run_scene`] with the
/// other `options` (checkpoints, progress bar). Prints nothing but the progress bar.
pub fn run_impact(cfg: &ImpactConfig, out: &Path, options: &RunOptions) -> Result<RunSummary, ImpactError> {
    let prepared = prepare_impact(cfg, out, options.force)?;
    let options = RunOptions {
        force: true,
        ..*options
    };
    Ok(run_scene(&prepared.scene, out, &options)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_snapshots_are_cut_at_t_end() {
        assert_eq!(default_snapshots(150.0), vec![0.0, 100.0, 150.0]);
        assert_eq!(default_snapshots(10_000.0), DEFAULT_SNAPSHOTS.to_vec());
        assert_eq!(default_snapshots(20_000.0).last(), Some(&20_000.0));
        assert_eq!(default_snapshots(20_000.0).len(), 6);
    }

    #[test]
    fn validate_names_the_field() {
        let p = ProjectileSpec::preset("P1").unwrap();
        let mut cfg = ImpactConfig::new("t.csv".into(), p);
        assert!(cfg.validate().is_ok());
        cfg.angle_deg = 181.0;
        assert!(cfg.validate().unwrap_err().to_string().starts_with("angle_deg: "));
        cfg.angle_deg = 0.0;
        cfg.t_end = 150.0;
        assert!(cfg.validate().unwrap_err().to_string().starts_with("snapshots[2]: "));
        cfg.snapshots = default_snapshots(150.0);
        assert!(cfg.validate().is_ok());
    }
}
