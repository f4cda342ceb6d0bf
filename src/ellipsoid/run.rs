//! The ellipsoid engine as the run driver sees it ([`crate::engine::Engine`]): Roig03's equations of motion
//! ([`EllipsoidSystem`]) under an adaptive integrator (Bulirsch–Stoer by default), sampled at the scene's output
//! times.
//!
//! Its outputs, beside the driver's: `timeseries.csv` in [`TIMESERIES_COLUMNS`] (energies, the energy residual,
//! momenta); snapshots in [`crate::ellipsoid::output::SNAPSHOT_COLUMNS`]; `tracks.csv` (only when `output.track` lists bodies):
//! those bodies' rows at every sample; `barrier_overruns.csv` (only when a pair overran its contact barrier, see
//! [`crate::ellipsoid::barrier`]); `summary.json` as [`RunSummary`]. A sampled state with a non-finite diagnostic or a
//! quaternion norm off by more than [`QUATERNION_NORM_LIMIT`] stops the run, as does an integrator error (step-size
//! underflow, too many steps). With `integrator.project_attitudes` (the default for the Dormand–Prince methods) the
//! attitudes are pulled back onto `|q| = 1` after each advance to a sample
//! ([`EllipsoidSystem::project_attitudes`]); the norm error checked and reported is the one found before that.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::bits::{exact_f64, exact_f64_array, exact_f64_vec, fnv1a_hex};
use crate::ellipsoid::barrier::{BarrierMonitor, BarrierSettings, OVERRUN_FILE};
use crate::ellipsoid::body::InertiaModel;
use crate::ellipsoid::equations::{Diagnostics, EllipsoidSystem, Physics};
use crate::ellipsoid::output::{TIMESERIES_COLUMNS, TracksWriter, read_bodies_csv, snapshot_records, write_snapshot};
use crate::ellipsoid::quaternion::rotation_matrix;
use crate::ellipsoid::scene::{KappaSource, LoadedScene, default_scene, load_scene, parse_scene};
use crate::ellipsoid::summary::{CalibrationSummary, PhysicsSummary, RunSummary, Scales};
use crate::engine::{
    Engine, EngineError, Failure, Outcome, ParticleView, Resumed, RunReport, Sample, SampleError, Schedule,
    SnapshotView,
};
use crate::integrate::{Integrator, IntegratorState, Method, OdeSystem, Tolerances, make_integrator};
use crate::io::scene_file::SceneError;
use crate::math::Vec3;
use crate::phase::{Kind, Phase};

/// Quaternion norm errors above this mean the unit-norm constraint broke; the run stops.
pub const QUATERNION_NORM_LIMIT: f64 = 1e-3;

/// Running maxima of the conservation errors (absolute; made relative at the end), as stored in checkpoints.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ErrorTracker {
    #[serde(with = "exact_f64")]
    h0: f64,
    #[serde(with = "exact_f64")]
    dissipated0: f64,
    #[serde(with = "exact_f64_array")]
    p0: [f64; 3],
    #[serde(with = "exact_f64_array")]
    l0: [f64; 3],
    #[serde(with = "exact_f64_array")]
    scales0: [f64; 3],
    #[serde(with = "exact_f64_array")]
    scales_max: [f64; 3],
    #[serde(with = "exact_f64")]
    energy: f64,
    #[serde(with = "exact_f64")]
    momentum: f64,
    #[serde(with = "exact_f64")]
    angular: f64,
    #[serde(with = "exact_f64")]
    quaternion: f64,
    samples: u64,
    /// Largest `|∫ Σ F_tide dt|` and `|∫ Σ r × F_tide dt|` so far (0 without a tide; absent in older checkpoints).
    #[serde(default, with = "exact_f64")]
    tidal_impulse: f64,
    #[serde(default, with = "exact_f64")]
    tidal_torque_impulse: f64,
}

impl ErrorTracker {
    fn new(d0: &Diagnostics) -> Self {
        let s = [d0.energy_scale, d0.momentum_scale, d0.angular_momentum_scale];
        ErrorTracker {
            h0: d0.energy(),
            dissipated0: d0.dissipated,
            p0: [d0.momentum.x, d0.momentum.y, d0.momentum.z],
            l0: [d0.angular_momentum.x, d0.angular_momentum.y, d0.angular_momentum.z],
            scales0: s,
            scales_max: s,
            ..ErrorTracker::default()
        }
    }

    /// Absolute signed energy residual `H − H0 − (dissipated − dissipated0)`.
    fn energy_residual(&self, d: &Diagnostics) -> f64 {
        d.energy() - self.h0 - (d.dissipated - self.dissipated0)
    }

    /// The energy scale used for the time series (energy_scale(0), or 1 J if that is 0).
    fn energy_scale_for_rows(&self) -> f64 {
        if self.scales0[0] > 0.0 && self.scales0[0].is_finite() {
            self.scales0[0]
        } else {
            1.0
        }
    }

    fn update(&mut self, d: &Diagnostics) {
        self.energy = self.energy.max(self.energy_residual(d).abs());
        // The tide's impulses are physics, not error: the residuals leave them out.
        self.momentum = self
            .momentum
            .max((d.momentum - Vec3::from(self.p0) - d.tidal_impulse).norm());
        self.angular = self
            .angular
            .max((d.angular_momentum - Vec3::from(self.l0) - d.tidal_torque_impulse).norm());
        self.tidal_impulse = self.tidal_impulse.max(d.tidal_impulse.norm());
        self.tidal_torque_impulse = self.tidal_torque_impulse.max(d.tidal_torque_impulse.norm());
        self.quaternion = self.quaternion.max(d.quaternion_norm_error);
        for (m, s) in self
            .scales_max
            .iter_mut()
            .zip([d.energy_scale, d.momentum_scale, d.angular_momentum_scale])
        {
            if s.is_finite() {
                *m = m.max(s);
            }
        }
        self.samples += 1;
    }

    /// `(scale, definition)` for each quantity: the value at t = 0, or, if that is zero, the largest value over the
    /// run (or 1 if that is zero too).
    fn scales(&self) -> Scales {
        let pick = |k: usize, def0: &str, unit: &str| -> (f64, String) {
            let s0 = self.scales0[k];
            if s0 > 0.0 && s0.is_finite() {
                (s0, format!("{def0} at t = 0 ({unit})"))
            } else if self.scales_max[k] > 0.0 {
                (
                    self.scales_max[k],
                    format!("{def0}: largest value over the sampled times, since it is 0 at t = 0 ({unit})"),
                )
            } else {
                (1.0, format!("1 {unit}: {def0} is 0 throughout, so errors are absolute"))
            }
        };
        // With a flyby the energy and this scale also hold the tidal energy E_tide (crate::ellipsoid::tide).
        let (energy, energy_definition) = pick(0, "K_T + K_R + |U_C| + |U_G|", "J");
        let (momentum, momentum_definition) = pick(1, "sum over bodies of m |v|", "kg m/s");
        let (angular_momentum, angular_momentum_definition) =
            pick(2, "sum over bodies of |r x m v| + |I w| (about the origin)", "kg m^2/s");
        Scales {
            energy,
            energy_definition,
            momentum,
            momentum_definition,
            angular_momentum,
            angular_momentum_definition,
        }
    }
}

fn diagnostics_finite(d: &Diagnostics) -> bool {
    [
        d.kinetic_translational,
        d.kinetic_rotational,
        d.potential_contact,
        d.potential_gravity,
        d.potential_tidal,
        d.dissipated,
        d.momentum_scale,
        d.angular_momentum_scale,
        d.energy_scale,
        d.quaternion_norm_error,
    ]
    .iter()
    .all(|x| x.is_finite())
        && d.momentum.iter().all(|x| x.is_finite())
        && d.angular_momentum.iter().all(|x| x.is_finite())
}

/// Refuses a scene whose state at t = 0 has a non-finite energy, momentum or right-hand side although every field
/// passed validation (the terms combine bodies: a pair's force can overflow where each body alone is fine), as a
/// scene error naming the term's parameter: each term on its own is evaluated in a system of its own (so the run's
/// system and its caches are untouched), and the first whose energy or rates are not finite is named
/// (`physics.gravity.G`, `model.kappa` or `model.calibrate`, `physics.dissipation.F0`, `physics.flyby`), with the
/// first body whose rates are not finite.
fn check_initial_state(scene: &LoadedScene, initial: &Diagnostics, y: &[f64]) -> Result<(), EngineError> {
    let rates_finite = |system: &EllipsoidSystem| {
        let mut dy = vec![0.0; y.len()];
        system.rhs(0.0, y, &mut dy);
        // components past the bodies' (the dissipation integral, the tide's impulses) are charged to the last body
        dy.iter()
            .position(|x| !x.is_finite())
            .map(|k| (k / system.stride()).min(system.n_bodies().saturating_sub(1)))
    };
    let whole = EllipsoidSystem::new(&scene.bodies, scene.model, scene.physics).with_tide(scene.tide);
    let bad_body = rates_finite(&whole);
    if diagnostics_finite(initial) && bad_body.is_none() {
        return Ok(());
    }
    let p = scene.physics;
    let none = Physics::default();
    let kappa_field = match scene.kappa_source {
        KappaSource::Given => "model.kappa",
        KappaSource::Calibrated { .. } => "model.calibrate",
    };
    // Each term on its own: a system with only that term (or only the tide) enabled.
    let (mut gravity, mut contact, mut dissipation) = (none, none, none);
    (gravity.gravity, contact.contact, dissipation.dissipation) = (p.gravity, p.contact, p.dissipation);
    let terms = [
        ("gravity", "physics.gravity.G", gravity, None),
        ("contact", kappa_field, contact, None),
        ("dissipation", "physics.dissipation.F0", dissipation, None),
        ("flyby tide", "physics.flyby", none, scene.tide),
    ];
    let (term, field, body, energy) = terms
        .iter()
        .filter(|t| t.2 != none || t.3.is_some())
        .find_map(|(term, field, physics, tide)| {
            let system = EllipsoidSystem::new(&scene.bodies, scene.model, *physics).with_tide(*tide);
            let d = system.diagnostics_at(0.0, y);
            let body = rates_finite(&system);
            (!diagnostics_finite(&d) || body.is_some()).then_some((*term, *field, body, d.energy()))
        })
        .unwrap_or(("combined", "physics", bad_body, initial.energy()));
    let at = body.map_or(String::new(), |k| format!(", first non-finite rate on body[{k}]"));
    Err(EngineError::Scene(SceneError::Invalid {
        file: scene.name.clone(),
        field: field.to_string(),
        message: format!(
            "gives a non-finite energy or force at t = 0 with these bodies ({term} term: energy {energy:e} J{at}); the bodies' masses, sizes and separations overflow it"
        ),
    }))
}

/// What went wrong with a sampled state, if anything.
fn check_state(t: f64, d: &Diagnostics, projected: bool) -> Option<String> {
    if !diagnostics_finite(d) {
        return Some(format!(
            "non-finite diagnostics at t = {t} s (energy {}, |P| {}, |L| {})",
            d.energy(),
            d.momentum.norm(),
            d.angular_momentum.norm()
        ));
    }
    if d.quaternion_norm_error > QUATERNION_NORM_LIMIT {
        return Some(format!(
            "quaternion norm constraint broken at t = {t} s: max||q|-1| = {:.3e} > {QUATERNION_NORM_LIMIT:e}{}",
            d.quaternion_norm_error,
            if projected {
                " within one output interval: tighten integrator.rtol or shorten output.every"
            } else {
                "; integrator.project_attitudes = true pulls |q| back at every output sample"
            }
        ));
    }
    None
}

/// A body as the output formats see it.
fn particle_view(id: usize, b: &crate::ellipsoid::body::Body) -> ParticleView {
    // R(q) maps world to body; its transpose takes body vectors to the world. The state's quaternion is unit only
    // to the integrator's constraint error (~1e-10 after a hard impact): normalised, R is a rotation to round-off.
    let to_world = rotation_matrix(&b.quaternion.normalize()).transpose();
    ParticleView {
        id,
        mass: b.shape.mass,
        position: b.position,
        velocity: b.velocity,
        spin_world: to_world * b.spin_body,
        axes: b.shape.axes,
        rotation: to_world,
    }
}

/// Fingerprint of a scene's initial bodies: FNV-1a of their lossless snapshot rows.
fn bodies_hash(scene: &LoadedScene) -> String {
    let mut text = String::new();
    for row in snapshot_records(0.0, &scene.bodies) {
        text.push_str(&row.join(","));
        text.push('\n');
    }
    fnv1a_hex(text.as_bytes())
}

/// What an ellipsoid run's checkpoint holds beside the driver's envelope.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EllipsoidState {
    /// Fingerprint of the initial bodies (a replaced `bodies_file` is refused).
    bodies_hash: String,
    /// Bodies.
    n_bodies: usize,
    /// The ODE state.
    #[serde(with = "exact_f64_vec")]
    y: Vec<f64>,
    /// The integrator's complete internal state.
    integrator: IntegratorState,
    /// Error maxima and t = 0 references.
    errors: ErrorTracker,
}

/// A run of interacting ellipsoids (Roig03).
pub struct EllipsoidEngine {
    scene: LoadedScene,
    system: EllipsoidSystem,
    integrator: Box<dyn Integrator + Send>,
    t: f64,
    y: Vec<f64>,
    tracker: ErrorTracker,
    /// `(t, y)` of the last good state (the last sample, or where the integrator stopped).
    last_good: (f64, Vec<f64>),
    barrier: BarrierMonitor,
    tracks: Option<(TracksWriter, PathBuf)>,
    /// The largest `||q| − 1|` the last projection removed (0 without projection): the sample checks and
    /// reports it, so projecting never hides a drift.
    projected_drift: f64,
}

impl EllipsoidEngine {
    /// The engine for a validated scene, at t = 0. Errors: the integrator cannot be built from the scene's settings.
    pub fn new(scene: LoadedScene) -> Result<Self, EngineError> {
        let system = EllipsoidSystem::new(&scene.bodies, scene.model, scene.physics).with_tide(scene.tide);
        let settings = scene.integrator;
        let tolerances = Tolerances::scale_free(settings.rtol, settings.atol, &system);
        // atol is in user units (m, m/s, rad/s) and scaled by each body's mass and moment of inertia: a huge atol
        // times a huge mass overflows, which is the scene's atol to name, not an integrator failure.
        if let Some(k) = tolerances.atol.iter().position(|a| !a.is_finite()) {
            return Err(EngineError::Scene(SceneError::Invalid {
                file: scene.name.clone(),
                field: "integrator.atol".into(),
                message: format!(
                    "times the scale of body[{}] (its mass, moment of inertia or the energy scale) is not finite, got \
                     {:e}",
                    k / (system.dim() / system.n_bodies().max(1)).max(1),
                    settings.atol
                ),
            }));
        }
        let mut integrator = make_integrator(settings.method, tolerances, settings.step)
            .map_err(|e| EngineError::Setup(format!("integrator setup: {e}")))?;
        // The error budget is the run's: rtol bounds the accumulated error, not each step's. Not with tree
        // gravity under an integrator that does not fix the tree's lists per step (`OdeSystem::begin_step`):
        // freshly walked forces jump (by about the multipole error) wherever a body's interaction list changes,
        // and a step's share h/T of rtol falls below those jumps on long runs. There each step's error is bounded
        // by rtol (ODEX's rule).
        if system.forces_are_smooth()
            || matches!(settings.method, Method::BulirschStoer | Method::BulirschStoerImplicit)
        {
            integrator.set_span(scene.t_end);
        }
        let y = system.initial_state();
        let initial = system.diagnostics_at(0.0, &y);
        check_initial_state(&scene, &initial, &y)?;
        let tracker = ErrorTracker::new(&initial);
        let barrier = BarrierMonitor::new(
            BarrierSettings::for_kappa_source(&scene.kappa_source),
            scene.physics.contact.is_some(),
            None,
        );
        Ok(EllipsoidEngine {
            scene,
            system,
            integrator,
            t: 0.0,
            last_good: (0.0, y.clone()),
            y,
            tracker,
            barrier,
            tracks: None,
            projected_drift: 0.0,
        })
    }

    /// Loads and validates the scene file at `path`. Errors are one line naming the field.
    pub fn load(path: &Path) -> Result<Self, EngineError> {
        EllipsoidEngine::new(load_scene(path)?)
    }

    /// The built-in default scene.
    pub fn default_scene() -> Result<Self, EngineError> {
        EllipsoidEngine::new(default_scene()?)
    }

    /// The scene being run.
    pub fn scene(&self) -> &LoadedScene {
        &self.scene
    }

    /// The scene's warnings ([`LoadedScene::warnings`]), printed by `rubblepile check` and before a run.
    pub fn scene_warnings(&self) -> &[String] {
        &self.scene.warnings
    }

    /// The bodies now: shapes, positions (m), velocities (m/s), attitude quaternions and body-frame spins (rad/s).
    pub fn bodies(&self) -> Vec<crate::ellipsoid::body::Body> {
        self.system.bodies_at(self.t, &self.y)
    }

    /// Replaces the state now by `bodies` (one per body, in order, shapes and masses the scene's): positions (m),
    /// velocities (m/s), attitude quaternions (normalised here) and body-frame spins (rad/s). For a run between
    /// two samples (e.g. from Python); the run continues from the new state, its conserved quantities measured
    /// against those at t = 0 as before (so a change of energy counts in the energy error). Attitudes and spins
    /// cannot change where they are not integrated ([`EllipsoidSystem::rotation_integrated`]).
    ///
    /// Errors ([`EngineError::State`], one line, nothing changed): another number of bodies, another shape or
    /// mass, a non-finite value, a changed attitude or spin that is not integrated.
    pub fn set_bodies(&mut self, bodies: &[crate::ellipsoid::body::Body]) -> Result<(), EngineError> {
        let now = self.bodies();
        if bodies.len() != now.len() {
            return Err(EngineError::State(format!(
                "{} bodies given, the run has {}",
                bodies.len(),
                now.len()
            )));
        }
        for (i, (b, old)) in bodies.iter().zip(&now).enumerate() {
            if b.shape != old.shape {
                return Err(EngineError::State(format!(
                    "body[{i}]: its shape and mass are the scene's and cannot change"
                )));
            }
            let finite = [b.position, b.velocity, b.spin_body]
                .iter()
                .all(|v| v.iter().all(|x| x.is_finite()))
                && b.quaternion.iter().all(|x| x.is_finite())
                && b.quaternion.norm() > 0.0;
            if !finite {
                return Err(EngineError::State(format!(
                    "body[{i}]: a non-finite value (or a zero quaternion)"
                )));
            }
            if !self.system.rotation_integrated() && (b.quaternion != old.quaternion || b.spin_body != old.spin_body) {
                return Err(EngineError::State(format!(
                    "body[{i}]: attitudes and spins are not integrated in this run (spheres without dissipation); \
                     only positions and velocities can change"
                )));
            }
        }
        let mut y = self.y.clone();
        self.system.pack_bodies(bodies, &mut y);
        // The integrator's compensated sums belong to the old state.
        let mut state = self.integrator.save_state();
        let compensation = match &mut state {
            crate::integrate::IntegratorState::BulirschStoer(s) => Some(&mut s.compensation),
            crate::integrate::IntegratorState::LinearlyImplicit(s) => Some(&mut s.compensation),
            _ => None,
        };
        if let Some(c) = compensation {
            c.iter_mut().for_each(|c| *c = 0.0);
            self.integrator
                .restore_state(&state)
                .map_err(|e| EngineError::State(format!("integrator: {e}")))?;
        }
        self.y = y;
        self.last_good = (self.t, self.y.clone());
        Ok(())
    }

    /// What the scene resolves to, for `rubblepile check` (κ, physics terms, integrator, outputs, bodies).
    pub fn describe(&self) -> Vec<String> {
        let s = &self.scene;
        let kappa = match s.kappa_source {
            KappaSource::Given => format!("kappa = {} (given)", s.model.kappa),
            KappaSource::Calibrated { beta, v, reading } => {
                format!(
                    "kappa = {} (calibrated: beta = {beta}, v = {v} m/s, reading {reading})",
                    s.model.kappa
                )
            }
        };
        let mut lines = vec![
            format!("{}: ok", s.name),
            format!("  {} bodies, t_end = {} s, {kappa}", s.bodies.len(), s.t_end),
        ];
        let p = &s.physics;
        let mut terms = Vec::new();
        if let Some(g) = p.gravity {
            terms.push(format!("gravity (G = {:e})", g.g));
        }
        if let Some(c) = p.contact {
            terms.push(format!("contact (cutoff = {:e})", c.cutoff));
        }
        if let Some(d) = p.dissipation {
            terms.push(format!("dissipation (F0 = {})", d.f0));
        }
        if let Some(t) = &s.tide {
            terms.push(format!(
                "flyby tide (GM = {:e} m^3/s^2, q = {:e} m, e = {}, t_perigee = {} s)",
                t.gm, t.orbit.q, t.orbit.e, t.orbit.t_perigee
            ));
        }
        if terms.is_empty() {
            terms.push("none (free motion)".into());
        }
        lines.push(format!("  physics: {}", terms.join(", ")));
        lines.push(format!(
            "  integrator: {} (rtol {:e}, atol {:e}{}{})",
            s.integrator.method,
            s.integrator.rtol,
            s.integrator.atol,
            s.integrator.step.map(|h| format!(", step {h} s")).unwrap_or_default(),
            if s.integrator.project_attitudes {
                "; attitudes projected onto |q| = 1 at every output sample"
            } else {
                ""
            }
        ));
        lines.push(format!(
            "  output: every {} s, {} snapshots",
            s.output.every,
            s.output.times.len()
        ));
        for (k, b) in s.bodies.iter().enumerate() {
            lines.push(format!(
                "  body[{k}]: axes [{}, {}, {}] m, mass {:e} kg, R_eq {:.4e} m, at [{:e}, {:e}, {:e}] m",
                b.shape.axes.x,
                b.shape.axes.y,
                b.shape.axes.z,
                b.shape.mass,
                b.shape.equivalent_radius(),
                b.position.x,
                b.position.y,
                b.position.z
            ));
        }
        lines
    }

    /// `cause` with the contact barrier's hint, when overruns may explain the failure.
    fn failure(&self, cause: String) -> Failure {
        Failure::new(match self.barrier.failure_hint() {
            Some(hint) => format!("{cause}; {hint}"),
            None => cause,
        })
    }
}

impl RunReport for RunSummary {
    fn one_line(&self) -> String {
        RunSummary::one_line(self)
    }
    fn warnings(&self) -> Vec<String> {
        RunSummary::warnings(self)
    }
}

// The work at an output sample (`rubblepile bench scaling`, see [`crate::phase`]): the diagnostics (exact gravity
// potential and pair terms, parallel) and the barrier monitor's contact sweep (parallel from 256 bodies).
static PHASE_DIAGNOSTICS: Phase = Phase::new("ellipsoid.sample_diagnostics", Kind::Parallel);
static PHASE_BARRIER: Phase = Phase::new("ellipsoid.sample_barrier", Kind::Parallel);

impl Engine for EllipsoidEngine {
    type Summary = RunSummary;
    type State = EllipsoidState;
    const KIND: &'static str = "ellipsoids";

    fn from_scene_text(text: &str, name: &str, base_dir: Option<&Path>) -> Result<Self, EngineError> {
        EllipsoidEngine::new(parse_scene(text, name, base_dir)?)
    }

    fn useful_threads(&self) -> usize {
        self.system.useful_threads()
    }

    fn scene_source(&self) -> &str {
        &self.scene.source
    }

    fn estimated_steps(&self) -> Option<f64> {
        self.scene.work_steps
    }

    /// Step attempts (accepted and rejected): what a stiff or spinning scene spends its time on.
    fn steps_taken(&self) -> u64 {
        let s = self.integrator.stats();
        s.steps_accepted + s.steps_rejected
    }

    /// The integrator's own cap on the attempts of one advance (1e8) lowered to what is left of the budget.
    fn limit_steps(&mut self, most: u64) {
        self.integrator
            .set_max_steps(most.min(crate::integrate::bulirsch_stoer::DEFAULT_MAX_STEPS));
    }

    fn set_deadline(&mut self, deadline: Option<std::time::Instant>) {
        self.integrator.set_deadline(deadline);
    }

    fn error_so_far(&self) -> Option<(&'static str, f64)> {
        Some(("energy error", self.tracker.energy / self.tracker.scales().energy))
    }

    fn scene_base_dir(&self) -> Option<&Path> {
        self.scene.base_dir.as_deref()
    }

    fn t_end(&self) -> f64 {
        self.scene.t_end
    }

    fn time(&self) -> f64 {
        self.t
    }

    fn samples(&self) -> Vec<Sample> {
        Schedule::new(self.scene.t_end, self.scene.output.every, &self.scene.output.times).collect()
    }

    fn timeseries_header(&self) -> String {
        TIMESERIES_COLUMNS.join(",") + "\n"
    }

    fn open_outputs(&mut self, dir: &Path) -> std::io::Result<()> {
        self.barrier = BarrierMonitor::new(
            BarrierSettings::for_kappa_source(&self.scene.kappa_source),
            self.scene.physics.contact.is_some(),
            Some(&dir.join(OVERRUN_FILE)),
        );
        if !self.scene.output.track.is_empty() {
            let path = dir.join("tracks.csv");
            self.tracks = Some((TracksWriter::create(&path)?, path));
        }
        Ok(())
    }

    fn advance(&mut self, _index: usize, to: &Sample, _progress: &mut dyn FnMut(f64)) -> Result<(), Failure> {
        if to.t > self.t
            && let Err(e) = self.integrator.advance(&self.system, &mut self.t, &mut self.y, to.t)
        {
            // The integrator stopped at its last accepted step: that is the last good state.
            self.last_good = (self.t, self.y.clone());
            if matches!(e, crate::integrate::IntegrateError::Deadline { .. }) {
                return Err(Failure::deadline(self.t));
            }
            return Err(self.failure(format!("integrator error: {e}")));
        }
        if self.scene.integrator.project_attitudes {
            self.projected_drift = self.system.project_attitudes(&mut self.y);
        }
        Ok(())
    }

    fn sample(&mut self, _to: &Sample, wall_seconds: f64) -> Result<String, SampleError> {
        let mut d = PHASE_DIAGNOSTICS.time(|| self.system.diagnostics_at(self.t, &self.y));
        d.quaternion_norm_error = d.quaternion_norm_error.max(self.projected_drift);
        if let Some(cause) = check_state(self.t, &d, self.scene.integrator.project_attitudes) {
            return Err(self.failure(cause).into());
        }
        self.tracker.update(&d);
        let barrier_path = || PathBuf::from(OVERRUN_FILE);
        PHASE_BARRIER
            .time(|| self.barrier.observe(self.t, &self.system, &self.y))
            .map_err(|source| SampleError::Io {
                path: barrier_path(),
                source,
            })?;
        if let Some((w, path)) = self.tracks.as_mut() {
            let bodies = self.system.bodies_at(self.t, &self.y);
            w.write_sample(self.t, &bodies, &self.scene.output.track)
                .map_err(|source| SampleError::Io {
                    path: path.clone(),
                    source,
                })?;
        }
        self.last_good.0 = self.t;
        self.last_good.1.copy_from_slice(&self.y);
        let fields = [
            self.t,
            d.kinetic_translational,
            d.kinetic_rotational,
            d.potential_contact,
            d.potential_gravity,
            d.dissipated,
            self.tracker.energy_residual(&d) / self.tracker.energy_scale_for_rows(),
        ];
        let momenta = crate::engine::momentum_values(&d.momentum, &d.angular_momentum);
        let mut row = String::with_capacity(TIMESERIES_COLUMNS.len() * 24);
        for (k, &x) in fields.iter().chain(&momenta).chain(&[wall_seconds]).enumerate() {
            if k > 0 {
                row.push(',');
            }
            crate::io::push_f64(&mut row, x);
        }
        row.push('\n');
        Ok(row)
    }

    fn write_snapshot(&self, path: &Path) -> std::io::Result<()> {
        write_snapshot(path, self.t, &self.system.bodies_at(self.t, &self.y))
    }

    fn particles(&self) -> Vec<ParticleView> {
        let bodies = self.system.bodies_at(self.t, &self.y);
        bodies.iter().enumerate().map(|(id, b)| particle_view(id, b)).collect()
    }

    const SPHERES: bool = false;

    fn view_of_snapshot(&self, path: &Path) -> Result<SnapshotView, EngineError> {
        let file_error = |reason: String| EngineError::File {
            path: path.to_path_buf(),
            reason,
        };
        let records = read_bodies_csv(path).map_err(|e| file_error(e.to_string()))?;
        let times = crate::io::particles::read_particles(path, &["t"], &[]).map_err(|e| file_error(e.to_string()))?;
        Ok(SnapshotView {
            t: times.first().map_or(0.0, |r| r.values[0]),
            spheres: false,
            // As written: the state's quaternion, not renormalised, so the view is the one the run showed.
            particles: records
                .iter()
                .enumerate()
                .map(|(id, r)| particle_view(id, &r.to_body_as_written()))
                .collect(),
            ..Default::default()
        })
    }

    fn scene_vtk(&self) -> bool {
        self.scene.file.output.vtk
    }

    fn write_last_good_state(&self, path: &Path) -> std::io::Result<f64> {
        let (t, y) = &self.last_good;
        write_snapshot(path, *t, &self.system.bodies_at(*t, y))?;
        Ok(*t)
    }

    fn summary(&self, outcome: Outcome<'_>, _samples: u64, wall_seconds: f64) -> RunSummary {
        let scene = &self.scene;
        let settings = scene.integrator;
        let stats = self.integrator.stats();
        let scales = self.tracker.scales();
        let calibration = match scene.kappa_source {
            KappaSource::Given => None,
            KappaSource::Calibrated { beta, v, reading } => Some(CalibrationSummary { beta, v, reading }),
        };
        let (status, final_time) = match outcome {
            Outcome::Completed => ("completed".to_string(), self.t),
            Outcome::Failed(f) => (f.cause.clone(), self.last_good.0),
        };
        RunSummary {
            status,
            wall_seconds,
            final_time,
            t_end: scene.t_end,
            steps_accepted: stats.steps_accepted,
            steps_rejected: stats.steps_rejected,
            rejections: match self.integrator.save_state() {
                IntegratorState::BulirschStoer(s) => Some(s.columns.rejections),
                IntegratorState::LinearlyImplicit(s) => Some(s.columns.rejections),
                _ => None,
            },
            rhs_evaluations: stats.rhs_evaluations,
            smallest_step: stats.smallest_step.is_finite().then_some(stats.smallest_step),
            energy_error: self.tracker.energy / scales.energy,
            linear_momentum_error: self.tracker.momentum / scales.momentum,
            angular_momentum_error: self.tracker.angular / scales.angular_momentum,
            tidal_impulse: self
                .system
                .tide_impulse_index()
                .map(|_| self.tracker.tidal_impulse / scales.momentum),
            tidal_torque_impulse: self
                .system
                .tide_impulse_index()
                .map(|_| self.tracker.tidal_torque_impulse / scales.angular_momentum),
            quaternion_norm_error: self.tracker.quaternion,
            scales,
            samples: self.tracker.samples,
            kappa: scene.model.kappa,
            kappa_source: if calibration.is_some() { "calibrated" } else { "given" }.into(),
            calibration,
            inertia: match scene.model.inertia {
                InertiaModel::Gaussian => "gaussian".into(),
                InertiaModel::Uniform => "uniform".into(),
            },
            integrator: settings.method.to_string(),
            rtol: settings.rtol,
            atol: settings.atol,
            step: settings.step,
            project_attitudes: settings.project_attitudes,
            n_bodies: self.system.n_bodies(),
            rotation_integrated: self.system.rotation_integrated(),
            physics: PhysicsSummary::from(&scene.physics),
            seed: scene.seed,
            barrier: self.barrier.report(),
        }
    }

    fn save(&mut self) -> std::io::Result<EllipsoidState> {
        Ok(EllipsoidState {
            bodies_hash: bodies_hash(&self.scene),
            n_bodies: self.system.n_bodies(),
            y: self.y.clone(),
            integrator: self.integrator.save_state(),
            errors: self.tracker.clone(),
        })
    }

    fn restore(&mut self, state: EllipsoidState, dir: &Path, at: Resumed) -> Result<(), EngineError> {
        self.restore_from(state, dir, at).map_err(EngineError::State)
    }
}

impl EllipsoidEngine {
    /// [`Engine::restore`] with one-line `String` errors (made [`EngineError::State`] there).
    fn restore_from(&mut self, state: EllipsoidState, dir: &Path, at: Resumed) -> Result<(), String> {
        if state.bodies_hash != bodies_hash(&self.scene) || state.n_bodies != self.scene.bodies.len() {
            let from = match (&self.scene.file.scene.bodies_file, &self.scene.base_dir) {
                (Some(f), Some(base)) => format!(" (bodies_file {})", base.join(f).display()),
                (Some(f), None) => format!(" (bodies_file {f})"),
                _ => String::new(),
            };
            return Err(format!(
                "the scene's bodies{from} differ from those the run started with"
            ));
        }
        if state.y.len() != self.system.dim() {
            return Err(format!(
                "the checkpoint's state has {} components, the scene's system {}",
                state.y.len(),
                self.system.dim()
            ));
        }
        if !state.y.iter().all(|v| v.is_finite()) {
            return Err("the checkpoint's state is not finite".into());
        }
        let method = self.scene.integrator.method;
        if state.integrator.method() != method {
            return Err(format!(
                "the checkpoint is of a {} run, the scene asks for {method}",
                state.integrator.method()
            ));
        }
        self.integrator
            .restore_state(&state.integrator)
            .map_err(|e| format!("integrator: {e}"))?;
        self.t = at.t;
        self.y = state.y;
        self.last_good = (self.t, self.y.clone());
        self.tracker = state.errors;
        if !self.scene.output.track.is_empty() {
            // Each sample wrote one row per tracked body.
            let rows = at.samples_done * self.scene.output.track.len() as u64;
            let path = dir.join("tracks.csv");
            let writer = TracksWriter::open_truncated(&path, rows).map_err(|e| format!("{}: {e}", path.display()))?;
            self.tracks = Some((writer, path));
        }
        let log = dir.join(OVERRUN_FILE);
        self.barrier = BarrierMonitor::resume(
            BarrierSettings::for_kappa_source(&self.scene.kappa_source),
            self.scene.physics.contact.is_some(),
            &log,
            at.t,
        )
        .map_err(|e| format!("{}: {e}", log.display()))?;
        Ok(())
    }
}
