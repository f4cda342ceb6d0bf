//! The campaign file format (see [`super`]): its TOML schema and its parsing.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use super::*;

// ---------------------------------------------------------------------------------------------
// The file.
// ---------------------------------------------------------------------------------------------

/// A campaign file, as written (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CampaignFile {
    /// `[campaign]`: the grid and where it goes.
    pub campaign: CampaignSection,
    /// `[impact]`: overrides of the impact defaults shared by every run.
    #[serde(default)]
    pub impact: ImpactSection,
    /// `[[projectile]]`: custom projectiles.
    #[serde(default, rename = "projectile")]
    pub projectiles: Vec<CustomProjectile>,
    /// `[sweep]`: field path → list of values or grid ([`super::sweep`]); the runs are the product.
    #[serde(default, skip_serializing_if = "toml::Table::is_empty")]
    pub sweep: toml::Table,
}

/// `[campaign]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CampaignSection {
    /// Campaign directory (relative to the campaign file's directory); required.
    pub out: PathBuf,
    /// Target bodies files (relative to the campaign file's directory), at least one; the file stems name
    /// the runs, so they must differ.
    pub targets: Vec<PathBuf>,
    /// Projectiles: `P1`, `P2`, `P3` (Roig03 Table 2; any case) or ids of `[[projectile]]` tables.
    pub projectiles: Vec<String>,
    /// Impact angles ζ (degrees, in [0, 180]).
    pub angles: Vec<f64>,
    /// Seeds of the projectile's attitude (default `[1]`).
    #[serde(default = "default_seeds")]
    pub seeds: Vec<u64>,
    /// Runs at once (≥ 1; default: the number of cores).
    #[serde(default)]
    pub parallel: Option<usize>,
}

fn default_seeds() -> Vec<u64> {
    vec![1]
}

/// `[impact]`: every key optional; absent = the default of [`ImpactConfig::new`].
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImpactSection {
    /// End time (s; default 10 000).
    pub t_end: Option<f64>,
    /// Integrator: `"bulirsch-stoer"` (default), `"dop853"` or `"dopri5"`.
    pub method: Option<crate::integrate::Method>,
    /// Relative (= absolute) tolerance (of the whole run for Bulirsch–Stoer, default 1e-6; of each step otherwise,
    /// default 1e-8).
    pub rtol: Option<f64>,
    /// Dissipation coefficient F0 (s m⁻²; default 1e-6).
    pub f0: Option<f64>,
    /// β of Roig03 Eq. 14 (default 10).
    pub beta: Option<f64>,
    /// Which `K` of Roig03 Eq. 13 κ is calibrated against: `"printed"` (default), `"impactor"`, `"reduced"`.
    pub kappa_reading: Option<crate::ellipsoid::calibration::KappaReading>,
    /// Time at which the surfaces first touch (s; default 90).
    pub contact_time: Option<f64>,
    /// Time-series cadence (s; default 10).
    pub every: Option<f64>,
    /// Snapshot times (s; default 0, 100, 400, 1000, 10 000 cut to `t_end`, plus `t_end`).
    pub snapshots: Option<Vec<f64>>,
    /// Snapshot cadence (s, > 0), instead of `snapshots`: 0, S, 2S, … and `t_end` (at most 1e5 snapshots).
    pub snapshot_every: Option<f64>,
    /// Impact speed of P1–P3 and of custom projectiles without their own (km/s; default 5).
    pub speed_km_s: Option<f64>,
    /// Inertia model of the ellipsoids: `"gaussian"` (Roig03 Eq. 4, default) or `"uniform"`.
    pub inertia: Option<crate::ellipsoid::body::InertiaModel>,
    /// Impact parameter `b` (m, ≥ 0): the trajectory's offset from the target's centre of mass (default 0). At most
    /// one of `impact_parameter_m`, `impact_parameter_frac`, `impact_angle_deg` ([`crate::impact::geometry`]).
    pub impact_parameter_m: Option<f64>,
    /// `b` as a fraction of the target's radius R (in [0, 1)).
    pub impact_parameter_frac: Option<f64>,
    /// Impact angle θ between the trajectory and the target's surface normal at the aim point (degrees, [0, 90)).
    pub impact_angle_deg: Option<f64>,
    /// Azimuth ψ of the aim point around the approach direction (degrees, [0, 360); default 0).
    pub aim_azimuth_deg: Option<f64>,
    /// Spin of a single-ellipsoid projectile (rad/s, world frame `[x, y, z]`; default none).
    pub projectile_spin_rad_s: Option<[f64; 3]>,
    /// Attitude of a single-ellipsoid projectile: a quaternion `[x, y, z, w]` (scalar last, world → body, as the
    /// bodies files'; default a random one drawn from the seed).
    pub projectile_attitude: Option<[f64; 4]>,
}

impl ImpactSection {
    /// The geometry these keys ask for ([`crate::impact::geometry::ImpactGeometry::from_options`]).
    pub fn geometry(&self) -> Result<crate::impact::geometry::ImpactGeometry, crate::impact::run::ImpactError> {
        crate::impact::geometry::ImpactGeometry::from_options(
            [
                self.impact_parameter_m,
                self.impact_parameter_frac,
                self.impact_angle_deg,
            ],
            self.aim_azimuth_deg,
            self.projectile_spin_rad_s.as_ref().map(|v| &v[..]),
            self.projectile_attitude.as_ref().map(|v| &v[..]),
        )
    }
}

/// `[[projectile]]`: a custom projectile (density 3000 kg m⁻³, axis ratios 1 : 0.7 : 0.5), or a rubble-pile
/// projectile (`projectile_pile`, [`crate::impact::pile`]). Exactly one of `radius_km` and `projectile_pile`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CustomProjectile {
    /// Its name in `campaign.projectiles` and in run names: letters, digits, `_`, `-`; not P1–P3.
    pub id: String,
    /// Equivalent radius (km, > 0) of a single-ellipsoid projectile.
    #[serde(default)]
    pub radius_km: Option<f64>,
    /// A rubble-pile projectile: a bodies file such as `targets/N30_T4.csv` (relative to the campaign file),
    /// thrown whole; no default.
    #[serde(default)]
    pub projectile_pile: Option<PathBuf>,
    /// Whether the projectile pile is turned by a random attitude drawn from the run's seed (default true;
    /// false keeps the file's orientation). Only with `projectile_pile`.
    #[serde(default)]
    pub random_attitude: Option<bool>,
    /// Impact speed (km/s, > 0; default `impact.speed_km_s`).
    #[serde(default)]
    pub speed_km_s: Option<f64>,
}

/// Parses the TOML with the scene files' parser ([`crate::io::scene_file::parse_toml_as`]): the same one-line
/// messages naming the line and the field (`unknown field `x` in [campaign]`, `campaign.out: missing …`).
pub(crate) fn parse_toml(text: &str, name: &str) -> Result<CampaignFile, CampaignError> {
    crate::io::scene_file::parse_toml_as(text, name).map_err(|e| match e {
        crate::io::scene_file::SceneError::Syntax { .. } => CampaignError::File(e),
        other => CampaignError::File(crate::io::scene_file::SceneError::Syntax {
            file: name.to_string(),
            message: other.to_string(),
        }),
    })
}
