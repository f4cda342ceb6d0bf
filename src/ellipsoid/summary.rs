//! `summary.json`: what a run did and how well it conserved what it should.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::ellipsoid::barrier::BarrierReport;
use crate::ellipsoid::calibration::KappaReading;
use crate::ellipsoid::equations::Physics;

/// The scales that make the conservation errors relative.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scales {
    /// Energy scale (J).
    pub energy: f64,
    /// How [`Scales::energy`] is defined.
    pub energy_definition: String,
    /// Linear-momentum scale (kg m/s).
    pub momentum: f64,
    /// How [`Scales::momentum`] is defined.
    pub momentum_definition: String,
    /// Angular-momentum scale (kg m²/s).
    pub angular_momentum: f64,
    /// How [`Scales::angular_momentum`] is defined.
    pub angular_momentum_definition: String,
}

/// Which physics terms were on, with their parameters (`null` = off).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct PhysicsSummary {
    /// Gravity: `{ "G": … }` or null.
    pub gravity: Option<GravitySummary>,
    /// Contact: `{ "cutoff": … }` or null.
    pub contact: Option<ContactSummary>,
    /// Dissipation: `{ "F0": … }` or null.
    pub dissipation: Option<DissipationSummary>,
}

/// Gravity parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GravitySummary {
    /// G (m³ kg⁻¹ s⁻²).
    #[serde(rename = "G")]
    pub g: f64,
}

/// Contact parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ContactSummary {
    /// Relative cutoff.
    pub cutoff: f64,
}

/// Dissipation parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DissipationSummary {
    /// F0 (s m⁻²).
    #[serde(rename = "F0")]
    pub f0: f64,
}

impl From<&Physics> for PhysicsSummary {
    fn from(p: &Physics) -> Self {
        PhysicsSummary {
            gravity: p.gravity.map(|g| GravitySummary { g: g.g }),
            contact: p.contact.map(|c| ContactSummary { cutoff: c.cutoff }),
            dissipation: p.dissipation.map(|d| DissipationSummary { f0: d.f0 }),
        }
    }
}

/// The content of `summary.json`. Errors are maxima over all sampled times (every time-series row)
/// of the run, relative to the scales in [`RunSummary::scales`]. Non-finite numbers are written as `null`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunSummary {
    /// `"completed"`, or the cause of the failure (with the time).
    pub status: String,
    /// Wall-clock time of the integration (s).
    pub wall_seconds: f64,
    /// Last time reached (s): `t_end` when completed, else the last good time.
    pub final_time: f64,
    /// Requested end time (s).
    pub t_end: f64,
    /// Accepted integrator steps.
    pub steps_accepted: u64,
    /// Rejected integrator steps.
    pub steps_rejected: u64,
    /// The Bulirsch–Stoer methods' rejected steps by cause (error test, stability check, divergence, non-finite values);
    /// absent for the other methods. Tells whether a run's step was set by accuracy or by stiffness.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rejections: Option<crate::integrate::bulirsch_stoer::Rejections>,
    /// Right-hand-side evaluations.
    pub rhs_evaluations: u64,
    /// Smallest accepted step (s); null before the first step.
    pub smallest_step: Option<f64>,
    /// max |H(t) − H0 − dissipated(t)| / energy scale (dissipated = 2∫F dt since t = 0).
    pub energy_error: f64,
    /// max |P(t) − P0 − ∫F_tide dt| / momentum scale (the tide's impulse, in a flyby, is not an error).
    pub linear_momentum_error: f64,
    /// max |L(t) − L0 − ∫τ_tide dt| / angular-momentum scale (τ_tide the flyby tide's torque about the origin).
    pub angular_momentum_error: f64,
    /// In a flyby (planet mass > 0): max |∫F_tide dt| / momentum scale, the momentum the tide gave the pile
    /// (physics, not an error); absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tidal_impulse: Option<f64>,
    /// In a flyby: max |∫τ_tide dt| / angular-momentum scale, the angular momentum the tide's torque gave the pile
    /// (physics, not an error); absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tidal_torque_impulse: Option<f64>,
    /// max over sampled times and bodies of ||q| − 1|.
    pub quaternion_norm_error: f64,
    /// Scales of the three relative errors and their definitions.
    pub scales: Scales,
    /// Number of sampled times (time-series rows written).
    pub samples: u64,
    /// κ used.
    pub kappa: f64,
    /// `"given"` or `"calibrated"` (then `calibration` holds β and v).
    pub kappa_source: String,
    /// `{ "beta": …, "v": … }` when κ was calibrated.
    pub calibration: Option<CalibrationSummary>,
    /// Moments of inertia (`"gaussian"` or `"uniform"`).
    pub inertia: String,
    /// Integrator method.
    pub integrator: String,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Fixed (rk4) or initial step (s), if given.
    pub step: Option<f64>,
    /// Whether the attitudes were projected onto `|q| = 1` at every output sample (`integrator.project_attitudes`;
    /// false in summaries written before the option existed).
    #[serde(default)]
    pub project_attitudes: bool,
    /// Number of bodies.
    pub n_bodies: usize,
    /// Whether attitudes were integrated.
    pub rotation_integrated: bool,
    /// Physics terms on.
    pub physics: PhysicsSummary,
    /// The scene's seed.
    pub seed: u64,
    /// Contact-barrier overruns found at the sampled times ([`crate::ellipsoid::barrier`]); null when the
    /// contact term is off (and in summaries written before the detector existed).
    #[serde(default)]
    pub barrier: Option<BarrierReport>,
}

/// β and v of a calibration.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CalibrationSummary {
    /// β.
    pub beta: f64,
    /// v (m/s).
    pub v: f64,
    /// Which `K` of Roig03 Eq. 13 (runs written before the option existed used `printed`).
    #[serde(default)]
    pub reading: KappaReading,
}

impl RunSummary {
    /// Whether the run reached `t_end`.
    pub fn completed(&self) -> bool {
        self.status == "completed"
    }

    /// Warnings to print after the run (one line each): the contact-barrier overruns.
    pub fn warnings(&self) -> Vec<String> {
        self.barrier.as_ref().map(BarrierReport::warnings).unwrap_or_default()
    }

    /// The one-line report printed after a run, e.g.
    /// `done: t = 200 s, wall 1.23 s, steps 456 (12 rejected), RHS 7890, energy error 3.1e-11, |dP| 1e-16, |dL| 2e-15, max||q|-1| 1e-12`:
    /// the time to six significant digits ([`crate::io::messages::fmt_time`]), the errors relative to their
    /// [`Scales`]. A flyby adds the tide's impulse and torque impulse in N s and N m s, each also as a fraction of
    /// its scale, beside the momentum errors they are not.
    pub fn one_line(&self) -> String {
        let head = if self.completed() { "done" } else { "stopped" };
        let tide = match (self.tidal_impulse, self.tidal_torque_impulse) {
            (Some(p), Some(l)) => format!(
                " (tide's impulse, not errors: |int F dt| {:.1e} N s ({p:.1e} of the momentum scale), |int tau dt| \
                 {:.1e} N m s ({l:.1e} of the angular-momentum scale))",
                p * self.scales.momentum,
                l * self.scales.angular_momentum
            ),
            _ => String::new(),
        };
        format!(
            "{head}: t = {} s, wall {:.2} s, steps {} ({} rejected), RHS {}, energy error {:.1e}, |dP| {:.1e}, |dL| {:.1e}, max||q|-1| {:.1e}{tide}",
            crate::io::messages::fmt_time(self.final_time),
            self.wall_seconds,
            self.steps_accepted,
            self.steps_rejected,
            self.rhs_evaluations,
            self.energy_error,
            self.linear_momentum_error,
            self.angular_momentum_error,
            self.quaternion_norm_error,
        )
    }
}

/// Writes `summary` as pretty JSON to `path`.
pub fn write_summary(path: &Path, summary: &RunSummary) -> std::io::Result<()> {
    let mut text = serde_json::to_string_pretty(summary).map_err(std::io::Error::other)?;
    text.push('\n');
    crate::io::safe_write::write_atomic(path, text)
}

/// Reads a `summary.json` (non-finite numbers, written as `null`, cannot be read back).
pub fn read_summary(path: &Path) -> std::io::Result<RunSummary> {
    let text = std::fs::read_to_string(path)?;
    serde_json::from_str(&text).map_err(std::io::Error::other)
}
