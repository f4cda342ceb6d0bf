//! The `kind = "ellipsoids"` scene file (Roig03 §2): its validation and its conversion into the model's types
//! ([`Body`], [`ModelConfig`], [`Physics`]). Every key is documented once, on the struct that holds it (from
//! [`SceneFile`]), and listed by `rubblepile check --explain ellipsoids`; `rubblepile check --print-default` prints
//! the default scene and `targets/examples/` holds others. Bad input never panics: [`parse_scene`] and
//! [`load_scene`] return a [`SceneError`] whose message is one line naming the file, the field and what was
//! expected, e.g. `scene.toml: body[3].axes: need A >= B >= C > 0, got [1, 2, 3]`.

use std::path::{Path, PathBuf};

use scene_derive::SceneFields;
use serde::{Deserialize, Serialize};

use crate::ellipsoid::body::{Body, Ellipsoid, InertiaModel};
use crate::ellipsoid::calibration::{KappaReading, calibrate_kappa_read};
use crate::ellipsoid::equations::{ContactTerm, DissipationTerm, GravityTerm, ModelConfig, Physics};
use crate::ellipsoid::quaternion::to_unit_quaternion;
use crate::ellipsoid::tide::{FlybySpec, TideTerm, resolve_flyby};
use crate::integrate::Method;
use crate::io::scene_file::{
    MAX_BODIES, MIN_MEANINGFUL, MIN_RTOL, SI_G, SceneError, Validator, WORK_WARNING_STEPS, exact, fmt_list, fmt_num,
    parse_toml_as, read_scene_text,
};
use crate::math::{Vec3, Vec4};

/// Default contact cutoff (dimensionless): see [`ContactSpec::cutoff`].
pub const DEFAULT_CONTACT_CUTOFF: f64 = 1e-16;

/// Largest allowed `||q| − 1|` of an input quaternion.
pub const QUATERNION_NORM_TOLERANCE: f64 = 1e-6;

/// The built-in default scene (`targets/default.toml`), run by `rubblepile run` without a scene file.
pub const DEFAULT_SCENE_TOML: &str = include_str!("../../targets/default.toml");

/// The setup of the built-in scene's impact (`targets/default_impact.json`: Q, impact time, projectile, target),
/// written as `impact.json` beside its run so that `rubblepile analyze` reads it like any impact run.
pub const DEFAULT_IMPACT_JSON: &str = include_str!("../../targets/default_impact.json");

/// Name used for the built-in scene in messages.
pub const DEFAULT_SCENE_NAME: &str = "<built-in default scene>";

// The file model (what serde reads). Every struct rejects unknown keys.

/// A whole scene file. Tables: `[scene]`, `[model]`, `[physics]`, `[integrator]`, `[output]` and
/// one `[[body]]` table per body (or `scene.bodies_file` instead of the `[[body]]` tables).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, SceneFields)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// what is simulated and for how long (required)
    #[field(table)]
    pub scene: SceneSection,
    /// model constants: exactly one of kappa or calibrate (required)
    #[field(table)]
    pub model: ModelSection,
    /// the force terms; an absent term is not computed (absent table: bodies move freely)
    #[serde(default)]
    #[field(table)]
    pub physics: PhysicsSection,
    /// method and tolerances (optional)
    #[serde(default)]
    #[field(table)]
    pub integrator: IntegratorSection,
    /// snapshot times and time-series cadence (required)
    #[field(table)]
    pub output: OutputSection,
    /// `[[body]]`: one ellipsoid each, `body[0]`, `body[1]`, … in file order (or `scene.bodies_file`).
    #[serde(default, rename = "body", skip_serializing_if = "Vec::is_empty")]
    #[field(
        table,
        meaning = "one ellipsoid each, body[0], body[1], ... in file order (or scene.bodies_file)"
    )]
    pub bodies: Vec<BodySpec>,
    /// the run's budget: most steps and wall-clock seconds (optional)
    #[serde(default, skip_serializing_if = "crate::io::run_budget::RunSection::is_empty")]
    #[field(table)]
    pub run: crate::io::run_budget::RunSection,
}

/// `[scene]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "scene")]
#[serde(deny_unknown_fields)]
pub struct SceneSection {
    /// What is simulated. Required; `"ellipsoids"` (the Roig03 interacting-ellipsoids model) here;
    /// `"soft-spheres"` scenes are read by `granular::soft::scene` instead.
    #[field(unit = "text", default = "required", range = Rule("\"ellipsoids\""))]
    #[field(meaning = "which engine reads the scene")]
    pub kind: String,
    /// end time of the run; it starts at t = 0
    #[field(unit = "s", default = "required", range = Positive)]
    pub t_end: f64,
    /// Random seed (non-negative integer). Default 0. Recorded in `summary.json`; the ellipsoids
    /// model itself is deterministic and draws no random numbers.
    #[serde(default)]
    #[field(unit = "count", default = "0", range = Rule("integer >= 0"))]
    #[field(meaning = "recorded in summary.json; the model draws no random numbers")]
    pub seed: u64,
    /// Optional CSV file with the initial bodies, replacing the `[[body]]` tables. The path is
    /// relative to the scene file's directory. Columns as in the snapshots
    /// (`t,id,mass,a,b,c,x,y,z,vx,vy,vz,qa,qb,qc,qd,wx,wy,wz`; `t` and `id` may be present and are
    /// ignored; `w` is the body-frame spin, rad/s), so a snapshot can be used directly. Quaternions
    /// from a bodies file are used as written (checked to have unit norm within 1e-6, not
    /// renormalised) so that a run restarted from a snapshot continues bit-for-bit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "path", default = "none", range = Rule("readable CSV, <= 1e7 rows"))]
    #[field(meaning = "initial bodies (snapshot columns) instead of [[body]], relative to the scene file")]
    pub bodies_file: Option<String>,
}

/// `[model]`: give exactly one of `kappa` or `calibrate`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "model")]
#[serde(deny_unknown_fields)]
pub struct ModelSection {
    /// Width parameter κ of the Gaussian mass distribution (Roig03 Eq. 2), dimensionless, > 3/2.
    /// Larger κ = stiffer, more sharply bounded bodies.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "-", default = "(kappa or calibrate)", range = open_closed(1.5, MAX_KAPPA))]
    #[field(
        meaning = "width of the Gaussian mass distribution (Roig03 Eq. 2); larger = stiffer; exactly one of kappa, \
                   calibrate"
    )]
    pub kappa: Option<f64>,
    /// kappa from Roig03 Eq. 14 for the lightest and heaviest body, instead of model.kappa
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(table)]
    pub calibrate: Option<CalibrateSpec>,
    /// Moments of inertia: `"gaussian"` (Roig03 Eq. 4 with the model's κ, the paper's choice) or
    /// `"uniform"` (uniform-density ellipsoid, i.e. Eq. 4 with κ = 5/2). Default `"gaussian"`.
    #[serde(default)]
    #[field(unit = "text", default = "\"gaussian\"", range = Rule("\"gaussian\" | \"uniform\""))]
    #[field(meaning = "moments of inertia: Roig03 Eq. 4 with the model's kappa, or a uniform ellipsoid")]
    pub inertia: InertiaModel,
}

/// `model.calibrate`: κ from Roig03 Eq. 14 for the smallest (by mass) and the largest body of the
/// scene, with their equivalent radii `(A B C)^{1/3}` and the gravity term's G (SI G if gravity is off).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "model.calibrate")]
#[serde(deny_unknown_fields)]
pub struct CalibrateSpec {
    /// β of Eq. 14 (dimensionless, > 0): the contact barrier between the two bodies is β times
    /// their kinetic energy at relative speed `v`. Required.
    #[field(unit = "-", default = "required", range = Positive)]
    #[field(meaning = "contact barrier over the kinetic energy at speed v (Roig03 Eq. 14)")]
    pub beta: f64,
    /// relative speed the contact must withstand (Roig03 Eq. 14)
    #[field(unit = "m/s", default = "required", range = Positive)]
    pub v: f64,
    /// Which kinetic energy the barrier is β times (Roig03 Eq. 13's `K`): `"printed"` (`½ m_l v²`, Eq. 14
    /// as printed; the default), `"impactor"` (`½ m_k v²`) or `"reduced"` (`½ μ v²`, the pair's relative
    /// kinetic energy). See [`KappaReading`].
    #[serde(default)]
    #[field(unit = "text", default = "\"printed\"", range = Rule("\"printed\" | \"impactor\" | \"reduced\""))]
    #[field(meaning = "which kinetic energy the barrier is beta times (Roig03 Eq. 13's K)")]
    pub reading: KappaReading,
}

/// `[physics]`: every term is optional; an absent term is not computed at all.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize, SceneFields)]
#[scene(table = "physics")]
#[serde(deny_unknown_fields)]
pub struct PhysicsSection {
    /// monopole gravity between centres of mass (Roig03 Eq. 6); `gravity = {}` turns it on
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(table)]
    pub gravity: Option<GravitySpec>,
    /// Gaussian-overlap contact potential (Roig03 Eqs. 7-12); `contact = {}` turns it on
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(table)]
    pub contact: Option<ContactSpec>,
    /// point dissipation (Roig03 Eqs. 40-41)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(table)]
    pub dissipation: Option<DissipationSpec>,
    /// tide of a planet on a prescribed Kepler orbit (none if absent)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(table)]
    pub flyby: Option<FlybySpec>,
}

/// `physics.gravity`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize, SceneFields)]
#[scene(table = "physics.gravity")]
#[serde(deny_unknown_fields)]
pub struct GravitySpec {
    /// Gravitational constant `G` (m³ kg⁻¹ s⁻²), > 0. Default 6.674e-11 (SI). Also used in the
    /// contact amplitude U0 (Roig03 Eq. 11) and in `model.calibrate`.
    #[serde(default, rename = "G", skip_serializing_if = "Option::is_none")]
    #[field(unit = "m^3 kg^-1 s^-2", default = "6.674e-11", range = Positive)]
    #[field(meaning = "gravitational constant; also sets the contact amplitude U0 (Roig03 Eq. 11)")]
    pub g: Option<f64>,
    /// How the pair sum is done: `"direct"` (exact, O(N²)), `"tree"` (Barnes–Hut octree, O(N log N)) or
    /// `"auto"` (exact below 5000 bodies, tree from there on). Default `"auto"`. See
    /// [`crate::ellipsoid::gravity_tree`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "text", default = "\"auto\"", range = Rule("\"auto\" | \"direct\" | \"tree\""))]
    #[field(meaning = "exact O(N^2) sum, Barnes-Hut tree, or exact below 5000 bodies and tree from there")]
    pub method: Option<GravityMethodSpec>,
    /// Opening angle θ of the tree (dimensionless, in (0, 1]): a node is used whole beyond `side/θ` from a
    /// body. Default 0.5. Ignored by `"direct"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "-", default = "0.5", range = open_closed(0.0, crate::ellipsoid::gravity_tree::MAX_THETA))]
    #[field(meaning = "tree opening angle: a node is used whole beyond side/theta; ignored by \"direct\"")]
    pub theta: Option<f64>,
}

/// `physics.gravity.method`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GravityMethodSpec {
    /// Exact pair sum.
    Direct,
    /// Barnes–Hut octree at any N.
    Tree,
    /// Exact below [`crate::ellipsoid::gravity_tree::TREE_FROM`] bodies, tree from there on.
    #[default]
    Auto,
}

/// `physics.contact`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize, SceneFields)]
#[scene(table = "physics.contact")]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Relative amplitude below which far pairs are skipped (dimensionless, in (0, 1)): a pair whose
    /// contact potential is provably below `cutoff × U0` is not evaluated. Default 1e-16.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "-", default = "1e-16", range = open(0.0, 1.0))]
    #[field(meaning = "pairs whose contact potential is provably below cutoff x U0 are skipped (also >= 1e-300)")]
    pub cutoff: Option<f64>,
}

/// `physics.dissipation`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "physics.dissipation")]
#[serde(deny_unknown_fields)]
pub struct DissipationSpec {
    /// Dissipation coefficient `F0` (s m⁻², ≥ 0) of Roig03 Eq. 41. Required. The dissipation is
    /// weighted by the contact overlap, so it acts only on touching pairs.
    #[serde(rename = "F0")]
    #[field(unit = "s m^-2", default = "required", range = NonNegative)]
    #[field(meaning = "dissipation coefficient (Roig03 Eq. 41), acting on touching pairs only")]
    pub f0: f64,
}

/// `[integrator]`. The whole table is optional.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize, SceneFields)]
#[scene(table = "integrator")]
#[serde(deny_unknown_fields)]
pub struct IntegratorSection {
    /// `"bulirsch-stoer"` (adaptive Gragg–Bulirsch–Stoer, Roig03's choice; the default), `"dop853"`, `"dopri5"`
    /// (adaptive Dormand–Prince), `"rk4"` (fixed step; needs `step`, takes no `rtol` or `atol`) or
    /// `"bulirsch-stoer-implicit"` (linearly implicit Euler extrapolation, [`crate::integrate::linearly_implicit`],
    /// with the dissipation's analytic Jacobian, [`crate::ellipsoid::dissipation_jacobian`]). The implicit method
    /// pays when the dissipation damps a touching pair (at the rate `2 F0 U_C / μ`, μ the reduced mass) faster than
    /// its contact oscillates (overdamped, sticking regimes): an explicit method must resolve the damping time.
    /// Below that (Roig03's F0 = 1e-6 s m⁻²) `"bulirsch-stoer"` is cheaper per unit of accuracy.
    #[serde(default)]
    #[field(unit = "text", default = "\"bulirsch-stoer\"")]
    #[field(range = Rule("\"bulirsch-stoer\" | \"dop853\" | \"dopri5\" | \"rk4\" | \"bulirsch-stoer-implicit\""))]
    #[field(
        meaning = "adaptive Gragg-Bulirsch-Stoer, Dormand-Prince 8(5,3) or 5(4), fixed-step RK4, or linearly implicit \
                   extrapolation for stiff dissipation (contact damping time well below the contact period; `check` \
                   advises it)"
    )]
    pub method: Method,
    /// Relative tolerance (dimensionless, in `[1e-15, 1)`, [`MIN_RTOL`]). Default 1e-10. The error norm is
    /// scale-free: every state is judged in the units a user thinks in (m, m/s, rad/s, a unit quaternion, the
    /// dissipated energy relative to the initial energy scale), whatever the body's mass. With the two
    /// Bulirsch–Stoer methods it bounds the whole run's error (the local errors to `t_end` add up to about a
    /// quarter of it); the other methods apply it to each step. Refused with `"rk4"`, which has no error control.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "-", default = "1e-10", range = closed_open(MIN_RTOL, 1.0))]
    #[field(meaning = "relative tolerance of the adaptive methods (refused with \"rk4\")")]
    pub rtol: Option<f64>,
    /// Absolute tolerance (≥ 0, finite). Default 1e-10. In the user units above: m for positions, m/s for
    /// velocities, rad/s for spins (the integrator scales it by each body's mass and moment of inertia). Only for the
    /// adaptive methods (refused with `"rk4"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "m, m/s, rad/s", default = "1e-10", range = NonNegative)]
    #[field(meaning = "absolute tolerance in each state's own unit (refused with \"rk4\")")]
    pub atol: Option<f64>,
    /// The fixed step of `"rk4"` (s, required there, ≥ `t_end × 1e-12` and ≥ 1e-300). Refused with the adaptive
    /// methods, which choose their own steps.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "s", default = "required by \"rk4\"", range = Rule(">= t_end x 1e-12; \"rk4\" only"))]
    #[field(meaning = "the fixed step of \"rk4\"")]
    pub step: Option<f64>,
    /// Whether to pull the attitudes back onto `|q| = 1` at every output sample (`true`/`false`; see
    /// [`crate::ellipsoid::equations::EllipsoidSystem::project_attitudes`]). Default: `true` for `"dop853"`,
    /// `"dopri5"` and `"rk4"`, whose per-step error norm lets a fast-spinning body's `|q|` drift; `false` for the
    /// two Bulirsch–Stoer methods, whose run-wide error norm keeps the constraint. The run's
    /// `quaternion_norm_error` is the largest `||q| − 1|` before projection; above 1e-3 it still stops the run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "bool", default = "true (false for bulirsch-stoer)", range = Rule("true | false"))]
    #[field(meaning = "pull the attitudes back onto |q| = 1 at every output sample")]
    pub project_attitudes: Option<bool>,
}

/// Default `rtol` and `atol`.
const DEFAULT_TOLERANCE: f64 = 1e-10;

/// `[output]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "output")]
#[serde(deny_unknown_fields)]
pub struct OutputSection {
    /// Snapshot times (s): strictly increasing, each in `[0, t_end]`. The integrator lands on each
    /// exactly and writes `snapshots/<k>.csv` for the k-th time. Default `[0, t_end]`; `[]` = no snapshots.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "s", default = "[0, t_end]", range = Rule("increasing, in [0, t_end], <= 1e5"))]
    #[field(meaning = "snapshot times (snapshots/<k>.csv); [] = none; not with snapshot_every")]
    pub times: Option<Vec<f64>>,
    /// Snapshot cadence (s, > 0), instead of `times`: snapshots at `0, snapshot_every, 2·snapshot_every, …` and at
    /// `t_end` (each `k × snapshot_every`, the last exactly `t_end`), at most 1e5. Give `times` or this, not both.
    /// Default: none (`times` decides).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "s", default = "none", range = Rule(">= 1e-300, <= 1e5 snapshots"))]
    #[field(meaning = "snapshot cadence instead of times: 0, every, 2 every, ... and t_end")]
    pub snapshot_every: Option<f64>,
    /// Time-series cadence (s, > 0): a row of `timeseries.csv` every `every` seconds from 0 to
    /// `t_end` inclusive (plus one at each snapshot time). Required. At most 1e8 rows.
    #[field(unit = "s", default = "required", range = Rule(">= t_end / 1e8"))]
    #[field(meaning = "time-series cadence: a row of timeseries.csv every `every` seconds")]
    pub every: f64,
    /// Bodies (indices into the scene's body list, 0-based) whose full state is written to `tracks.csv` at every
    /// time-series row, in the snapshot columns (e.g. the projectile of an impact). Each index at most once.
    /// Default `[]`: no `tracks.csv`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "count", default = "[]", range = Rule("body indices < number of bodies, each once"))]
    #[field(meaning = "bodies whose full state is written to tracks.csv at every time-series row")]
    pub track: Option<Vec<usize>>,
    /// Also write every snapshot as VTK for ParaView (`vtk/*.vtp` and the collection `vtk/run.pvd`), as
    /// `--format vtk` does. Default false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    #[field(unit = "bool", default = "false", range = Rule("true | false"))]
    #[field(meaning = "also write every snapshot as VTK (vtk/*.vtp, vtk/run.pvd)")]
    pub vtk: bool,
}

/// `[[body]]`: one ellipsoid and its initial state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "body")]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// semi-axes along the body x, y, z axes
    #[serde(deserialize_with = "exact::array")]
    #[field(unit = "m", default = "required", range = Rule("[A, B, C], A >= B >= C >= 1e-300"))]
    pub axes: [f64; 3],
    /// mass; exactly one of mass, density
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "kg", default = "(mass or density)", range = Positive)]
    pub mass: Option<f64>,
    /// Bulk density (kg/m³, finite, ≥ 1e-300); then `mass = density · 4/3 π A B C` (which must be finite and
    /// ≥ 1e-300 too). Give exactly one of `mass` and `density`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "kg/m^3", default = "(mass or density)", range = Positive)]
    #[field(meaning = "bulk density: mass = density 4/3 pi A B C")]
    pub density: Option<f64>,
    /// Centre-of-mass position `[x, y, z]` (m, finite), world frame. Required. No two bodies' centres may lie
    /// closer than [`MIN_CENTRE_SEPARATION`] times the smaller of their smallest semi-axes.
    #[serde(deserialize_with = "exact::array")]
    #[field(unit = "m", default = "required", range = Rule("finite; centres >= 0.5 x the smaller C apart"))]
    #[field(meaning = "centre of mass, world frame")]
    pub position: [f64; 3],
    /// Centre-of-mass velocity `[vx, vy, vz]` (m/s, finite, with a finite kinetic energy and momentum), world frame.
    /// Default `[0, 0, 0]`.
    #[serde(default, deserialize_with = "exact::array")]
    #[field(unit = "m/s", default = "[0, 0, 0]", range = Rule("3 finite numbers"))]
    #[field(meaning = "centre-of-mass velocity, world frame")]
    pub velocity: [f64; 3],
    /// Attitude quaternion `[α, β, γ, δ]` (vector part first, scalar last; Roig03 Eq. 19), whose
    /// rotation matrix R(q) (Eq. 21) maps world to body coordinates. Must have unit norm within 1e-6;
    /// it is then normalised. Default `[0, 0, 0, 1]` (body axes = world axes).
    #[serde(default, deserialize_with = "exact::option", skip_serializing_if = "Option::is_none")]
    #[field(unit = "-", default = "[0, 0, 0, 1]", range = Rule("|q| = 1 within 1e-6"))]
    #[field(meaning = "attitude [alpha, beta, gamma, delta], scalar last; R(q) maps world to body (Roig03 Eq. 21)")]
    pub quaternion: Option<[f64; 4]>,
    /// Spin `[ω1, ω2, ω3]` (rad/s, finite, with a finite rotational energy) about the body's principal axes
    /// (A, B, C). At most one of `spin_body` and `spin_world`; default no spin.
    #[serde(default, deserialize_with = "exact::option", skip_serializing_if = "Option::is_none")]
    #[field(unit = "rad/s", default = "[0, 0, 0]", range = Rule("3 finite numbers"))]
    #[field(meaning = "spin about the body's principal axes (A, B, C); at most one of spin_body, spin_world")]
    pub spin_body: Option<[f64; 3]>,
    /// Spin `[ωx, ωy, ωz]` (rad/s) in the world frame; converted with `spin_body = R(q) · spin_world`.
    /// At most one of `spin_body` and `spin_world`; default no spin.
    #[serde(default, deserialize_with = "exact::option", skip_serializing_if = "Option::is_none")]
    #[field(unit = "rad/s", default = "[0, 0, 0]", range = Rule("3 finite numbers"))]
    #[field(meaning = "spin in the world frame (spin_body = R(q) spin_world)")]
    pub spin_world: Option<[f64; 3]>,
}

// The resolved scene.

/// How κ was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum KappaSource {
    /// Given as `model.kappa`.
    Given,
    /// From `model.calibrate` (Roig03 Eq. 14).
    Calibrated {
        /// β used.
        beta: f64,
        /// v used (m/s).
        v: f64,
        /// Which `K` of Eq. 13 (see [`KappaReading`]).
        reading: KappaReading,
    },
}

/// Validated integrator settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct IntegratorSettings {
    /// Method.
    pub method: Method,
    /// Relative tolerance (> 0).
    pub rtol: f64,
    /// Absolute tolerance (≥ 0).
    pub atol: f64,
    /// Fixed (rk4) or initial step (s).
    pub step: Option<f64>,
    /// Whether attitudes are projected onto `|q| = 1` at every output sample (resolved default: all methods but
    /// the two Bulirsch–Stoer ones).
    pub project_attitudes: bool,
}

/// Validated output settings.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OutputSettings {
    /// Snapshot times (s), strictly increasing, in `[0, t_end]`.
    pub times: Vec<f64>,
    /// Time-series cadence (s, > 0).
    pub every: f64,
    /// Tracked bodies (indices, distinct, each < the number of bodies); empty: no `tracks.csv`.
    pub track: Vec<usize>,
}

/// A validated scene, ready to run.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadedScene {
    /// How the scene is named in messages (the path as given, or [`DEFAULT_SCENE_NAME`]).
    pub name: String,
    /// The scene file's text (copied into the output directory as `scene.toml`).
    pub source: String,
    /// The scene file's directory (where `bodies_file` is resolved), if it came from a file.
    pub base_dir: Option<PathBuf>,
    /// The parsed file, as written.
    pub file: SceneFile,
    /// End time (s).
    pub t_end: f64,
    /// Seed.
    pub seed: u64,
    /// Initial bodies, in file order (their index is the `id` column of the outputs).
    pub bodies: Vec<Body>,
    /// Model constants (κ resolved).
    pub model: ModelConfig,
    /// How κ was obtained.
    pub kappa_source: KappaSource,
    /// Physics terms.
    pub physics: Physics,
    /// The flyby tide of `[physics.flyby]`, if any.
    pub tide: Option<TideTerm>,
    /// Integrator settings.
    pub integrator: IntegratorSettings,
    /// Output settings.
    pub output: OutputSettings,
    /// Warnings about the scene, one line each naming the file (printed by `rubblepile check` and at the start of
    /// `rubblepile run` as `warning: …`): the work estimate, when the scene's fastest time scale implies more than
    /// [`WORK_WARNING_STEPS`] integrator steps; the advice to use `bulirsch-stoer-implicit` when the contact damping
    /// is more than [`STIFF_ADVICE_RATIO`] times faster than the contact ([`contact_stiffness`]).
    pub warnings: Vec<String>,
    /// The work estimate: about how many integrator steps the run needs to `t_end` ([`STEPS_PER_TIME_SCALE`] per
    /// fastest time scale); `None` without a time scale (nothing spins, touches or moves relative to the rest).
    /// The run driver refuses a scene estimated above its step budget ([`crate::io::run_budget`]).
    pub work_steps: Option<f64>,
}

// Entry points.

/// Reads and validates a scene file. Errors name the file as given by `path`.
pub fn load_scene(path: &Path) -> Result<LoadedScene, SceneError> {
    let s = read_scene_text(path)?;
    parse_scene(&s.text, &s.name, Some(&s.base_dir))
}

/// The built-in default scene ([`DEFAULT_SCENE_TOML`]).
pub fn default_scene() -> Result<LoadedScene, SceneError> {
    parse_scene(DEFAULT_SCENE_TOML, DEFAULT_SCENE_NAME, None)
}

/// Parses and validates scene text. `name` is used in messages; `base_dir` resolves a relative
/// `bodies_file` (the current directory when `None`).
pub fn parse_scene(text: &str, name: &str, base_dir: Option<&Path>) -> Result<LoadedScene, SceneError> {
    let file = parse_toml(text, name)?;
    let v = Validator { file: name };
    v.resolve(text, file, base_dir)
}

/// Parses TOML into a [`SceneFile`] without validating values.
pub fn parse_toml(text: &str, name: &str) -> Result<SceneFile, SceneError> {
    parse_toml_as(text, name)
}

// Validation.

/// A body before conversion, from either a `[[body]]` table or a bodies-file row.
struct RawBody {
    /// Field prefix in messages, e.g. `body[2]` or `body[2] (bodies.csv line 4)`.
    label: String,
    axes: [f64; 3],
    mass: Option<f64>,
    density: Option<f64>,
    position: [f64; 3],
    velocity: [f64; 3],
    quaternion: Option<[f64; 4]>,
    normalise_quaternion: bool,
    spin_body: Option<[f64; 3]>,
    spin_world: Option<[f64; 3]>,
}

/// Largest κ accepted (`model.kappa`, or the one `model.calibrate` gives): every pair's contact amplitude holds
/// `e^{κλ}` with `λ ≤ 2` (Roig03 Eq. 12), and at κ = 175 that factor is 1e152, half the range of an `f64`; the other
/// half is left for `G m_i m_j (R_i + R_j)²`.
pub const MAX_KAPPA: f64 = 175.0;

/// Two bodies whose centres lie closer than this fraction of the smaller of their smallest semi-axes are refused
/// at t = 0 as coincident or deeply overlapping (their contact energy is near its full-overlap maximum and their
/// monopole gravity near its singularity); relaxed piles touch and overlap only slightly.
pub const MIN_CENTRE_SEPARATION: f64 = 0.5;

// The numbers written into the rows' words, held to the constants they restate.
const _: () = assert!(MIN_CENTRE_SEPARATION == 0.5);
const _: () = assert!(crate::ellipsoid::gravity_tree::TREE_FROM == 5000);
const _: () = assert!(crate::ellipsoid::gravity_tree::DEFAULT_THETA == 0.5);

/// Integrator steps assumed per fastest time scale of a scene, for its work estimate (see [`LoadedScene::warnings`]):
/// an adaptive step resolves a spin turn or a contact in a few to a few tens of steps.
pub const STEPS_PER_TIME_SCALE: f64 = 10.0;

/// The ratio of contact period to damping time above which `rubblepile check` advises
/// `integrator.method = "bulirsch-stoer-implicit"` ([`contact_stiffness`]): at 10 an explicit method spends at least
/// ten times the steps the contact needs.
pub const STIFF_ADVICE_RATIO: f64 = 10.0;

/// The stiffest body of a scene's contacts ([`contact_stiffness`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactStiffness {
    /// Index of the body.
    pub body: usize,
    /// Period of two copies of it touching at rest, `2π √(R C² / (G m κ))` (s).
    pub contact_period: f64,
    /// Damping time of that contact, `4κR / (F0 G m)` (s).
    pub damping_time: f64,
    /// `contact_period / damping_time`: how many times faster the damping is than the contact.
    pub ratio: f64,
}

/// The body whose contact is stiffest (largest contact period over damping time, see [`ContactStiffness`]), or
/// `None` without several bodies, contact and a positive F0.
pub fn contact_stiffness(bodies: &[Body], model: &ModelConfig, physics: &Physics) -> Option<ContactStiffness> {
    let f0 = physics.dissipation.map_or(0.0, |d| d.f0);
    if bodies.len() < 2 || physics.contact.is_none() || f0 <= 0.0 {
        return None;
    }
    let (g, kappa) = (model.contact_g, model.kappa);
    bodies
        .iter()
        .enumerate()
        .map(|(k, b)| {
            let (c, m) = (b.shape.axes.z, b.shape.mass);
            let r = equivalent_radius(&[b.shape.axes.x, b.shape.axes.y, c]);
            let contact_period = std::f64::consts::TAU * (r * c * c / (g * m * kappa)).sqrt();
            let damping_time = 4.0 * kappa * r / (f0 * g * m);
            ContactStiffness {
                body: k,
                contact_period,
                damping_time,
                ratio: contact_period / damping_time,
            }
        })
        .filter(|s| s.ratio.is_finite())
        .max_by(|a, b| a.ratio.total_cmp(&b.ratio))
}

/// `|v|` without overflowing the squares of large components (`[1e200, 0, 0]` has the norm 1e200, not infinity).
fn robust_norm(v: &Vec3) -> f64 {
    let m = v.amax();
    if m > 0.0 && m.is_finite() {
        m * (v / m).norm()
    } else {
        m
    }
}

/// `(A B C)^{1/3}` (m) without overflowing the product of three large axes.
fn equivalent_radius(axes: &[f64; 3]) -> f64 {
    axes[0].cbrt() * axes[1].cbrt() * axes[2].cbrt()
}

impl Validator<'_> {
    /// Validates every section in order and builds the scene (each section's rules in its own function below).
    fn resolve(&self, text: &str, file: SceneFile, base_dir: Option<&Path>) -> Result<LoadedScene, SceneError> {
        let t_end = self.scene_section(&file)?;
        crate::io::run_budget::validate(self, &file.run)?;
        self.model_section(&file.model)?;
        let physics = self.physics_section(&file.physics)?;
        let g = physics.gravity.map_or(SI_G, |g| g.g);
        let tide = file.physics.flyby.map(|f| resolve_flyby(self, &f, g)).transpose()?;
        let integrator = self.integrator_section(&file.integrator, t_end)?;
        let output = self.output_section(&file.output, t_end)?;
        let bodies = self.bodies_section(&file, base_dir)?;
        self.track_section(&output.track, bodies.len())?;
        let (model, kappa_source) = self.kappa_section(&file.model, &bodies, &physics)?;
        self.separated(&bodies)?;
        self.contact_amplitudes(&bodies, &model, &kappa_source, &physics)?;
        let (work_steps, work_warning) = self.work_estimate(&bodies, &model, &physics, t_end);
        let warnings = work_warning
            .into_iter()
            .chain(self.stiffness_advice(&bodies, &model, &physics, integrator.method))
            .collect();
        Ok(LoadedScene {
            name: self.file.to_string(),
            source: text.to_string(),
            base_dir: base_dir.map(Path::to_path_buf),
            t_end,
            seed: file.scene.seed,
            file,
            bodies,
            model,
            kappa_source,
            physics,
            tide,
            integrator,
            output,
            warnings,
            work_steps,
        })
    }

    /// `[scene]`: the kind and `t_end` (s).
    fn scene_section(&self, file: &SceneFile) -> Result<f64, SceneError> {
        if file.scene.kind != "ellipsoids" {
            return Err(self.invalid(
                "scene.kind",
                format!(
                    "must be one of \"ellipsoids\", \"soft-spheres\", \"hard-spheres\", got {:?}",
                    file.scene.kind
                ),
            ));
        }
        self.field(&SceneSection::T_END, file.scene.t_end)
    }

    /// `[model]`: exactly one of `kappa` (in (1.5, [`MAX_KAPPA`]]) or `calibrate` (β, v > 0); κ itself is computed
    /// after the bodies ([`Validator::kappa_section`]), since calibration needs them.
    fn model_section(&self, m: &ModelSection) -> Result<(), SceneError> {
        match (m.kappa, m.calibrate) {
            (Some(k), None) => self.kappa_value("model.kappa", k)?,
            (None, Some(c)) => {
                self.field(&CalibrateSpec::BETA, c.beta)?;
                self.field(&CalibrateSpec::V, c.v)?;
            }
            (k, _) => return Err(self.exactly_one("model", "kappa", "calibrate", k.is_some())),
        }
        Ok(())
    }

    /// The error of `field`, which needs exactly one of the keys `a` and `b`, when it got `both` or neither.
    pub(crate) fn exactly_one(&self, field: impl Into<String>, a: &str, b: &str, both: bool) -> SceneError {
        let got = if both { "both" } else { "neither" };
        self.invalid(field, format!("give exactly one of `{a}` or `{b}`, got {got}"))
    }

    /// κ in (1.5, [`MAX_KAPPA`]].
    fn kappa_value(&self, field: &str, k: f64) -> Result<(), SceneError> {
        if ModelSection::KAPPA.range.contains(k) {
            Ok(())
        } else if k.is_finite() && k > MAX_KAPPA {
            Err(self.invalid(
                field,
                format!(
                    "must be at most {MAX_KAPPA}, in {} (MAX_KAPPA: the contact amplitude holds e^(2 kappa), which \
                     overflows beyond it), got {}",
                    ModelSection::KAPPA.range,
                    fmt_num(k)
                ),
            ))
        } else {
            Err(self.invalid(
                field,
                format!(
                    "must be > 1.5 and finite, in {}, got {}",
                    ModelSection::KAPPA.range,
                    fmt_num(k)
                ),
            ))
        }
    }

    /// `[physics]`: each term optional (absent = not computed).
    fn physics_section(&self, p: &PhysicsSection) -> Result<Physics, SceneError> {
        use crate::ellipsoid::gravity_tree::{DEFAULT_THETA, GravityMethod};
        let gravity = p.gravity.map(|g| {
            let theta = self.field(&GravitySpec::THETA, g.theta.unwrap_or(DEFAULT_THETA))?;
            Ok(GravityTerm {
                g: self.field(&GravitySpec::G, g.g.unwrap_or(SI_G))?,
                method: match g.method.unwrap_or_default() {
                    GravityMethodSpec::Direct => GravityMethod::Direct,
                    GravityMethodSpec::Tree => GravityMethod::Tree { theta },
                    GravityMethodSpec::Auto => GravityMethod::Auto { theta },
                },
            })
        });
        let contact = p.contact.map(|c| {
            let cutoff = self.field(&ContactSpec::CUTOFF, c.cutoff.unwrap_or(DEFAULT_CONTACT_CUTOFF))?;
            if cutoff < MIN_MEANINGFUL {
                return Err(self.invalid(
                    "physics.contact.cutoff",
                    format!("is below the smallest meaningful value ({MIN_MEANINGFUL:e}), got {cutoff:e}"),
                ));
            }
            Ok(ContactTerm { cutoff })
        });
        let dissipation = p.dissipation.map(|d| {
            Ok(DissipationTerm {
                f0: self.field(&DissipationSpec::F0, d.f0)?,
            })
        });
        Ok(Physics {
            gravity: gravity.transpose()?,
            contact: contact.transpose()?,
            dissipation: dissipation.transpose()?,
        })
    }

    /// `[integrator]`: method, tolerances (`rtol` in [[`MIN_RTOL`], 1), `atol` finite and ≥ 0; adaptive methods
    /// only), the fixed step of `"rk4"` (≥ `t_end ×` [`crate::io::scene_file::MIN_STEP_FRACTION`]; `"rk4"` only).
    fn integrator_section(&self, i: &IntegratorSection, t_end: f64) -> Result<IntegratorSettings, SceneError> {
        let rtol = i.rtol.unwrap_or(DEFAULT_TOLERANCE);
        if !IntegratorSection::RTOL.range.contains(rtol) {
            return Err(self.invalid(
                IntegratorSection::RTOL.key,
                format!(
                    "must be in {}, got {rtol:e}: a relative tolerance of 1 or more controls nothing, \
                     and below {MIN_RTOL:e} the integrators' error estimates are round-off (f64 epsilon is 2.2e-16)",
                    IntegratorSection::RTOL.range
                ),
            ));
        }
        let atol = self.field(&IntegratorSection::ATOL, i.atol.unwrap_or(DEFAULT_TOLERANCE))?;
        let step = i.step.map(|h| self.step("integrator.step", h, t_end)).transpose()?;
        if i.method == Method::Rk4 {
            if step.is_none() {
                return Err(self.invalid("integrator.step", "method \"rk4\" needs a fixed step: step = <s> (> 0)"));
            }
            for (field, given) in [("integrator.rtol", i.rtol), ("integrator.atol", i.atol)] {
                if let Some(x) = given {
                    return Err(self.invalid(
                        field,
                        format!(
                            "not used by method \"rk4\" (a fixed step has no error control; give `step` only), got {}",
                            fmt_num(x)
                        ),
                    ));
                }
            }
        } else if let Some(h) = step {
            return Err(self.invalid(
                "integrator.step",
                format!(
                    "not used by method \"{}\" (an adaptive method chooses its own steps; `step` is the fixed step of \
                     \"rk4\"): remove it, got {h}",
                    i.method
                ),
            ));
        }
        Ok(IntegratorSettings {
            method: i.method,
            rtol,
            atol,
            step,
            project_attitudes: i.project_attitudes.unwrap_or(!matches!(
                i.method,
                Method::BulirschStoer | Method::BulirschStoerImplicit
            )),
        })
    }

    /// `[output]`: time-series cadence `every` (s), snapshot times (s) in [0, t_end] (a list or a cadence), tracked
    /// body ids.
    fn output_section(&self, o: &OutputSection, t_end: f64) -> Result<OutputSettings, SceneError> {
        let every = self.cadence("output.every", o.every, t_end)?;
        let times = self.output_times(o.times.as_deref(), o.snapshot_every, t_end)?;
        let track = o.track.clone().unwrap_or_default();
        Ok(OutputSettings { times, every, track })
    }

    /// The bodies: `[[body]]` tables or `scene.bodies_file` (at most [`MAX_BODIES`]), each validated
    /// ([`Validator::body`]).
    fn bodies_section(&self, file: &SceneFile, base_dir: Option<&Path>) -> Result<Vec<Body>, SceneError> {
        let raw = match (&file.scene.bodies_file, file.bodies.is_empty()) {
            (Some(_), false) => {
                return Err(self.invalid(
                    "scene.bodies_file",
                    "give either `bodies_file` or [[body]] tables, got both",
                ));
            }
            (None, true) => {
                return Err(self.invalid("body", "no bodies: give [[body]] tables or scene.bodies_file"));
            }
            (None, false) => {
                self.count("body", file.bodies.len(), MAX_BODIES, "bodies (MAX_BODIES)")?;
                file.bodies
                    .iter()
                    .enumerate()
                    .map(|(k, b)| RawBody {
                        label: format!("body[{k}]"),
                        axes: b.axes,
                        mass: b.mass,
                        density: b.density,
                        position: b.position,
                        velocity: b.velocity,
                        quaternion: b.quaternion,
                        normalise_quaternion: true,
                        spin_body: b.spin_body,
                        spin_world: b.spin_world,
                    })
                    .collect::<Vec<_>>()
            }
            (Some(rel), true) => self.read_bodies_file(rel, base_dir)?,
        };
        raw.iter().map(|b| self.body(b)).collect()
    }

    /// `output.track`: body ids below the number of bodies, each at most once.
    fn track_section(&self, track: &[usize], n_bodies: usize) -> Result<(), SceneError> {
        for (k, &id) in track.iter().enumerate() {
            if id >= n_bodies {
                return Err(self.invalid(
                    format!("output.track[{k}]"),
                    format!(
                        "must be a body index below {} (the number of bodies), got {id}",
                        n_bodies
                    ),
                ));
            }
            if track[..k].contains(&id) {
                return Err(self.invalid(
                    format!("output.track[{k}]"),
                    format!("body {id} is listed twice; give each body at most once"),
                ));
            }
        }
        Ok(())
    }

    /// κ: given, or calibrated from the bodies (Roig03 Eq. 14) with β and v of `[model]`.
    fn kappa_section(
        &self,
        m: &ModelSection,
        bodies: &[Body],
        physics: &Physics,
    ) -> Result<(ModelConfig, KappaSource), SceneError> {
        let gravity = physics.gravity;
        let contact_g = gravity.map(|g| g.g).unwrap_or(SI_G);
        let (kappa, kappa_source) = match (m.kappa, m.calibrate) {
            (Some(k), _) => (k, KappaSource::Given),
            (None, Some(c)) => {
                let by_mass = |a: &&Body, b: &&Body| a.shape.mass.total_cmp(&b.shape.mass);
                let radius_mass = |b: Option<&Body>| {
                    let b = b.expect("at least one body (checked above)");
                    (b.shape.equivalent_radius(), b.shape.mass)
                };
                let small = radius_mass(bodies.iter().min_by(by_mass));
                let large = radius_mass(bodies.iter().max_by(by_mass));
                let k = calibrate_kappa_read(c.reading, c.beta, c.v, small, large, contact_g).map_err(|source| {
                    SceneError::Calibration {
                        file: self.file.to_string(),
                        message: source.to_string(),
                    }
                })?;
                if !(k.is_finite() && k > 1.5) {
                    return Err(self.invalid("model.calibrate", format!("calibration gave kappa = {k}, need > 1.5")));
                }
                if k > MAX_KAPPA {
                    return Err(self.invalid(
                        "model.calibrate",
                        format!(
                            "calibration gave kappa = {k}, more than {MAX_KAPPA} (MAX_KAPPA: the contact amplitude \
                             holds e^(2 kappa), which overflows beyond it); lower beta or v"
                        ),
                    ));
                }
                (
                    k,
                    KappaSource::Calibrated {
                        beta: c.beta,
                        v: c.v,
                        reading: c.reading,
                    },
                )
            }
            (None, None) => unreachable!("checked above"),
        };
        Ok((
            ModelConfig {
                kappa,
                inertia: m.inertia,
                contact_g,
            },
            kappa_source,
        ))
    }

    /// Refuses two bodies whose centres lie closer than [`MIN_CENTRE_SEPARATION`] times the smaller of their
    /// smallest semi-axes (coincident or deeply overlapping at t = 0), naming both.
    fn separated(&self, bodies: &[Body]) -> Result<(), SceneError> {
        let centres: Vec<Vec3> = bodies.iter().map(|b| b.position).collect();
        // Pairs closer than the mean of the two reaches contain every pair closer than the smaller one.
        let reach: Vec<f64> = bodies
            .iter()
            .map(|b| 0.5 * MIN_CENTRE_SEPARATION * b.shape.axes.z)
            .collect();
        for (i, j) in crate::geometry::neighbours::sphere_pairs(&centres, &reach) {
            let c = bodies[i].shape.axes.z.min(bodies[j].shape.axes.z);
            let d = (centres[j] - centres[i]).norm();
            if d < MIN_CENTRE_SEPARATION * c {
                return Err(self.invalid(
                    format!("body[{j}].position"),
                    format!(
                        "coincides with body[{i}] at t = 0: their centres are {d:e} m apart, less than \
                         {MIN_CENTRE_SEPARATION} x the smaller smallest semi-axis ({c:e} m); bodies this deep inside \
                         one another have a near-singular gravity and contact energy"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// With the contact or dissipation term on: every body's contact energy at full overlap with a copy of itself,
    /// `U0 m² (κ/π)^{3/2} / √det(2Σ)` (Roig03 Eqs. 10–11), must be finite, and so must `F0` times it (the
    /// dissipation, Eq. 41). A failure names the input that contributes most to the overflow: `G`, κ, the mass or
    /// the axes (small axes make the Gaussian sharp), or `F0`.
    fn contact_amplitudes(
        &self,
        bodies: &[Body],
        model: &ModelConfig,
        kappa_source: &KappaSource,
        physics: &Physics,
    ) -> Result<(), SceneError> {
        if physics.contact.is_none() && physics.dissipation.is_none() {
            return Ok(());
        }
        let ln_max = f64::MAX.ln();
        let g = model.contact_g;
        let kappa = model.kappa;
        for (k, b) in bodies.iter().enumerate() {
            let [a, bb, c] = [b.shape.axes.x, b.shape.axes.y, b.shape.axes.z];
            let m = b.shape.mass;
            // ln of U_full = ½ G (2R)² e^{2κ} / (2κ · 2^{3/2}) m² / (2√2 A B C), R = (ABC)^{1/3}, in its parts.
            let parts = [
                ("G", (0.5 * g).ln()),
                ("kappa", 2.0 * kappa - (2.0 * kappa).ln() - 3.0 * std::f64::consts::LN_2),
                ("mass", 2.0 * m.ln()),
                ("axes", 2.0 * std::f64::consts::LN_2 - (a.ln() + bb.ln() + c.ln()) / 3.0),
            ];
            let ln_u: f64 = parts.iter().map(|p| p.1).sum();
            if ln_u.is_nan() || ln_u >= ln_max {
                let worst = parts.iter().max_by(|x, y| x.1.total_cmp(&y.1)).map_or("mass", |p| p.0);
                let field = match worst {
                    "G" => "physics.gravity.G".to_string(),
                    "kappa" if *kappa_source == KappaSource::Given => "model.kappa".to_string(),
                    "kappa" => "model.calibrate".to_string(),
                    "axes" => format!("body[{k}].axes"),
                    _ => format!("body[{k}].mass"),
                };
                return Err(self.invalid(
                    field,
                    format!(
                        "gives body[{k}] a non-finite contact energy at full overlap (U0 m^2 (kappa/pi)^(3/2) / \
                         sqrt(det 2 Sigma) = e^{ln_u:.1} J with G = {g:e}, kappa = {kappa}, mass {m:e} kg, axes {} m)",
                        fmt_list(&[a, bb, c])
                    ),
                ));
            }
            if let Some(d) = physics.dissipation
                && d.f0 > 0.0
                && d.f0.ln() + ln_u >= ln_max
            {
                return Err(self.invalid(
                    "physics.dissipation.F0",
                    format!(
                        "times the contact energy of body[{k}] at full overlap (e^{ln_u:.1} J) overflows: the \
                         dissipation F0 U_C v^2 would be infinite, got {:e}",
                        d.f0
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The scene's work estimate: [`STEPS_PER_TIME_SCALE`] steps per fastest time scale over `t_end`. The time
    /// scales of each body: its spin period `2π/|ω|`; with contact between several bodies, the contact time
    /// `2π √(R C² / (G m κ))` of two copies of it touching along their smallest semi-axis C (R its equivalent
    /// radius) and the time `C / |v − v_cm|` to cross C; with dissipation, the damping time `4κR / (F0 G m)` at
    /// contact. Returns the estimate (`None` without a time scale) and a warning (one line, naming the scale and its
    /// body) when it exceeds [`WORK_WARNING_STEPS`].
    fn work_estimate(
        &self,
        bodies: &[Body],
        model: &ModelConfig,
        physics: &Physics,
        t_end: f64,
    ) -> (Option<f64>, Option<String>) {
        let several = bodies.len() > 1;
        let total_mass: f64 = bodies.iter().map(|b| b.shape.mass).sum();
        let v_cm: Vec3 = bodies.iter().map(|b| b.velocity * (b.shape.mass / total_mass)).sum();
        let g = model.contact_g;
        let kappa = model.kappa;
        let mut fastest: Option<(f64, String)> = None;
        let mut consider = |tau: f64, what: String| {
            if tau.is_finite() && tau > 0.0 && fastest.as_ref().is_none_or(|f| tau < f.0) {
                fastest = Some((tau, what));
            }
        };
        for (k, b) in bodies.iter().enumerate() {
            let w = b.spin_body.norm();
            if w > 0.0 {
                consider(
                    std::f64::consts::TAU / w,
                    format!("the spin period of body[{k}] (|w| = {w:e} rad/s)"),
                );
            }
            if !several {
                continue;
            }
            let c = b.shape.axes.z;
            let m = b.shape.mass;
            let r = equivalent_radius(&[b.shape.axes.x, b.shape.axes.y, c]);
            if physics.contact.is_some() {
                consider(
                    std::f64::consts::TAU * (r * c * c / (g * m * kappa)).sqrt(),
                    format!("the contact time of body[{k}] (smallest semi-axis {c:e} m, mass {m:e} kg, kappa {kappa})"),
                );
                let v = (b.velocity - v_cm).norm();
                if v > 0.0 {
                    consider(
                        c / v,
                        format!("the time body[{k}] takes to cross its smallest semi-axis ({c:e} m at {v:e} m/s)"),
                    );
                }
            }
            if let Some(d) = physics.dissipation
                && d.f0 > 0.0
            {
                consider(
                    4.0 * kappa * r / (d.f0 * g * m),
                    format!("the damping time of body[{k}] in contact (F0 = {:e})", d.f0),
                );
            }
        }
        let Some((tau, what)) = fastest else {
            return (None, None);
        };
        let steps = STEPS_PER_TIME_SCALE * t_end / tau;
        let warning = (steps > WORK_WARNING_STEPS).then(|| {
            format!(
                "{}: the fastest time scale is {what}: {tau:.2e} s, so about {steps:.1e} integrator steps to t_end = \
                 {t_end} s (more than {WORK_WARNING_STEPS:e}); the run may not end in useful time",
                self.file
            )
        });
        (Some(steps), warning)
    }

    /// Advice to use `bulirsch-stoer-implicit` when the dissipation is stiff: for each body, two copies of it
    /// touching at rest (as in [`Self::work_estimate`]) have the contact period `T = 2π √(R C² / (G m κ))` and the
    /// damping time `τ = 4κR / (F0 G m)` (`targets/README.md`, "Choosing κ and F0"); when `T/τ` exceeds
    /// [`STIFF_ADVICE_RATIO`] for some body and the method is an explicit one, one line naming the body, both times
    /// and the ratio. Deeper overlaps (impacts) raise the contact weight `U_C` and with it the ratio, so a scene
    /// below the threshold at rest may still be stiff during an impact.
    fn stiffness_advice(
        &self,
        bodies: &[Body],
        model: &ModelConfig,
        physics: &Physics,
        method: Method,
    ) -> Option<String> {
        let stiffness = contact_stiffness(bodies, model, physics)?;
        (stiffness.ratio > STIFF_ADVICE_RATIO && method != Method::BulirschStoerImplicit).then(|| {
            format!(
                "{}: physics.dissipation.F0 makes the damping stiff: body[{}] in contact damps in {:.2e} s, {:.0}x \
                 faster than its contact period {:.2e} s (above {STIFF_ADVICE_RATIO}); an explicit method steps at \
                 the damping time, integrator.method = \"bulirsch-stoer-implicit\" at the contact's",
                self.file, stiffness.body, stiffness.damping_time, stiffness.ratio, stiffness.contact_period
            )
        })
    }

    fn read_bodies_file(&self, rel: &str, base_dir: Option<&Path>) -> Result<Vec<RawBody>, SceneError> {
        let path = match base_dir {
            Some(dir) => dir.join(rel),
            None => PathBuf::from(rel),
        };
        let records = crate::ellipsoid::output::read_bodies_csv(&path).map_err(|e| match e {
            crate::ellipsoid::output::BodiesFileError::Read(reason) => self.invalid(
                "scene.bodies_file",
                format!("cannot read {}: {}", path.display(), reason),
            ),
            crate::ellipsoid::output::BodiesFileError::Format { line, message } => self.invalid(
                "scene.bodies_file",
                format!("{} line {line}: {message}", path.display()),
            ),
        })?;
        if records.is_empty() {
            return Err(self.invalid(
                "scene.bodies_file",
                format!("{}: no bodies (no data rows)", path.display()),
            ));
        }
        Ok(records
            .into_iter()
            .enumerate()
            .map(|(k, r)| RawBody {
                label: format!("body[{k}] ({} line {})", rel, r.line),
                axes: r.axes,
                mass: Some(r.mass),
                density: None,
                position: r.position,
                velocity: r.velocity,
                quaternion: Some(r.quaternion),
                normalise_quaternion: false,
                spin_body: Some(r.spin_body),
                spin_world: None,
            })
            .collect())
    }

    /// One body: every field finite and meaningful, and every quantity derived from it (volume, mass from density,
    /// the bounds of its moments of inertia over κ in (1.5, [`MAX_KAPPA`]], its kinetic and rotational energies,
    /// momentum and angular momentum) finite, each failure naming the field whose value caused it.
    fn body(&self, b: &RawBody) -> Result<Body, SceneError> {
        let f = |name: &str| format!("{}.{name}", b.label);
        let axes_field = f("axes");
        self.finite_vec(&axes_field, &b.axes)?;
        let [a, bb, c] = b.axes;
        if !(a >= bb && bb >= c && c > 0.0) {
            return Err(self.invalid(axes_field, format!("need A >= B >= C > 0, got {}", fmt_list(&b.axes))));
        }
        if c < MIN_MEANINGFUL {
            return Err(self.invalid(
                axes_field,
                format!(
                    "C is below the smallest meaningful value ({MIN_MEANINGFUL:e}), got {}",
                    fmt_list(&b.axes)
                ),
            ));
        }
        let mass = match (b.mass, b.density) {
            (Some(m), None) => self.within(&BodySpec::MASS, &f("mass"), m)?,
            (None, Some(rho)) => {
                let rho = self.within(&BodySpec::DENSITY, &f("density"), rho)?;
                let volume = 4.0 / 3.0 * std::f64::consts::PI * a * bb * c;
                if !(volume.is_finite() && volume >= MIN_MEANINGFUL) {
                    return Err(self.invalid(
                        axes_field,
                        format!(
                            "give a volume 4/3 pi A B C = {volume:e} m^3 outside [{MIN_MEANINGFUL:e}, finite] (needed \
                             for the mass from the density), got {}",
                            fmt_list(&b.axes)
                        ),
                    ));
                }
                let m = rho * volume;
                if !(m.is_finite() && m >= MIN_MEANINGFUL) {
                    return Err(self.invalid(
                        f("density"),
                        format!("gives a mass of {m:e} kg, need finite and >= {MIN_MEANINGFUL:e}"),
                    ));
                }
                m
            }
            (m, _) => return Err(self.exactly_one(b.label.clone(), "mass", "density", m.is_some())),
        };
        // Moments of inertia m/(2κ) (B²+C², C²+A², A²+B²) (Roig03 Eq. 4): the smallest is at least
        // m (B²+C²)/(2 MAX_KAPPA), the largest at most m (A²+B²)/3. Both must be normal numbers: the equations of
        // motion divide by them.
        let (small_sq, large_sq) = (bb * bb + c * c, a * a + bb * bb);
        let (i_min, i_max) = (mass * small_sq / (2.0 * MAX_KAPPA), mass * large_sq / 3.0);
        if !i_max.is_finite() {
            return Err(self.invalid(
                if large_sq.is_finite() {
                    f("mass")
                } else {
                    axes_field.clone()
                },
                format!(
                    "gives a moment of inertia m (A^2 + B^2)/(2 kappa) of up to {i_max:e} kg m^2, not finite (mass \
                     {mass:e} kg, axes {})",
                    fmt_list(&b.axes)
                ),
            ));
        }
        if i_min.is_nan() || i_min < f64::MIN_POSITIVE {
            return Err(self.invalid(
                if small_sq >= f64::MIN_POSITIVE {
                    f("mass")
                } else {
                    axes_field.clone()
                },
                format!(
                    "gives a moment of inertia m (B^2 + C^2)/(2 kappa) as small as {i_min:e} kg m^2, which underflows \
                     (mass {mass:e} kg, axes {})",
                    fmt_list(&b.axes)
                ),
            ));
        }
        self.finite_vec(&f("position"), &b.position)?;
        self.finite_vec(&f("velocity"), &b.velocity)?;

        let q = match b.quaternion {
            Some(q) => {
                let field = f("quaternion");
                self.finite_vec(&field, &q)?;
                let v = Vec4::new(q[0], q[1], q[2], q[3]);
                let norm = v.norm();
                if (norm - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
                    return Err(self.invalid(
                        field,
                        format!("must have unit norm within 1e-6, got {} (norm {norm})", fmt_list(&q)),
                    ));
                }
                if b.normalise_quaternion { v / norm } else { v }
            }
            None => Vec4::new(0.0, 0.0, 0.0, 1.0),
        };

        let (spin_body, spin_field) = match (b.spin_body, b.spin_world) {
            (Some(_), Some(_)) => {
                return Err(self.invalid(
                    b.label.clone(),
                    "give at most one of `spin_body` or `spin_world`, got both",
                ));
            }
            (Some(w), None) => {
                self.finite_vec(&f("spin_body"), &w)?;
                (Vec3::new(w[0], w[1], w[2]), f("spin_body"))
            }
            (None, Some(w)) => {
                self.finite_vec(&f("spin_world"), &w)?;
                (world_to_body(&q, &Vec3::new(w[0], w[1], w[2])), f("spin_world"))
            }
            (None, None) => (Vec3::zeros(), f("spin_body")),
        };

        // Energies and momenta at t = 0 (finite inputs can still overflow: 1e300 m/s gives an infinite energy).
        let position = Vec3::new(b.position[0], b.position[1], b.position[2]);
        let velocity = Vec3::new(b.velocity[0], b.velocity[1], b.velocity[2]);
        let speed = robust_norm(&velocity);
        if !(0.5 * mass * speed * speed).is_finite() || !(mass * speed).is_finite() {
            return Err(self.invalid(
                f("velocity"),
                format!(
                    "gives a non-finite kinetic energy or momentum at t = 0 (mass {mass:e} kg, |v| = {speed:e} m/s)"
                ),
            ));
        }
        if !(mass * position.norm() * speed).is_finite() {
            return Err(self.invalid(
                f("position"),
                "gives a non-finite angular momentum at t = 0 (|r| |m v| overflows)",
            ));
        }
        let w = robust_norm(&spin_body);
        if !(0.5 * i_max * w * w).is_finite() || !(i_max * w).is_finite() {
            return Err(self.invalid(
                spin_field,
                format!(
                    "gives a non-finite rotational energy or spin angular momentum at t = 0 (|w| = {w:.3e} rad/s, \
                     moments of inertia up to {i_max:.3e} kg m^2)"
                ),
            ));
        }

        Ok(Body {
            shape: Ellipsoid {
                axes: Vec3::new(a, bb, c),
                mass,
            },
            position,
            velocity,
            quaternion: q,
            spin_body,
        })
    }
}

/// `R(q) · v`: a world-frame vector in body coordinates (Roig03 Eq. 21; `q = (α, β, γ, δ)`, scalar last).
///
/// R(q) is the transpose of nalgebra's rotation matrix of the unit quaternion `δ + α i + β j + γ k`.
pub fn world_to_body(q: &Vec4, v: &Vec3) -> Vec3 {
    to_unit_quaternion(q).to_rotation_matrix().matrix().transpose() * v
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
[scene]
kind = "ellipsoids"
t_end = 200.0
seed = 1
[model]
kappa = 10.0
inertia = "gaussian"
[physics]
gravity = { G = 6.674e-11 }
contact = {}
dissipation = { F0 = 1.0 }
[integrator]
method = "bulirsch-stoer"
rtol = 1e-10
atol = 1e-10
[output]
times = [0.0, 100.0, 200.0]
every = 1.0
[[body]]
axes = [3.0, 2.0, 1.0]
mass = 1000.0
position = [0.0, 0.0, 0.0]
velocity = [0.0, 0.0, 0.0]
quaternion = [0.0, 0.0, 0.0, 1.0]
spin_body = [0.01, 0.5, 0.02]
[[body]]
axes = [2, 2, 2]
density = 3000
position = [10.0, 0.0, 0.0]
spin_world = [0.0, 0.0, 0.1]
quaternion = [0.0, 0.0, 0.7071067811865476, 0.7071067811865476]
"#;

    #[test]
    fn good_scene_parses() {
        let s = parse_scene(GOOD, "scene.toml", None).unwrap();
        assert_eq!(s.bodies.len(), 2);
        assert_eq!(s.model.kappa, 10.0);
        assert_eq!(s.physics.gravity.unwrap().g, 6.674e-11);
        assert_eq!(s.physics.contact.unwrap().cutoff, 1e-16);
        assert_eq!(s.output.times, vec![0.0, 100.0, 200.0]);
        let m = 3000.0 * 4.0 / 3.0 * std::f64::consts::PI * 8.0;
        assert!((s.bodies[1].shape.mass - m).abs() < 1e-9 * m);
        // A 90° turn about z: the world z spin stays about the body z axis.
        let w = s.bodies[1].spin_body;
        assert!((w - Vec3::new(0.0, 0.0, 0.1)).norm() < 1e-15);
    }

    #[test]
    fn spin_world_conversion_matches_eq21() {
        // 90° about z: body x axis = world y axis. A world-x spin is then about body −y.
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let q = Vec4::new(0.0, 0.0, h, h);
        let w = world_to_body(&q, &Vec3::new(1.0, 0.0, 0.0));
        assert!((w - Vec3::new(0.0, -1.0, 0.0)).norm() < 1e-15, "{w}");
        // Explicit Roig03 Eq. 21 for a generic quaternion.
        let q = Vec4::new(0.1, -0.3, 0.5, 0.8).normalize();
        let (a, b, c, d) = (q[0], q[1], q[2], q[3]);
        let r = crate::math::Mat3::new(
            a * a - b * b - c * c + d * d,
            2.0 * (a * b + c * d),
            2.0 * (a * c - b * d),
            2.0 * (a * b - c * d),
            -a * a + b * b - c * c + d * d,
            2.0 * (b * c + a * d),
            2.0 * (a * c + b * d),
            2.0 * (b * c - a * d),
            -a * a - b * b + c * c + d * d,
        );
        let v = Vec3::new(0.3, -1.2, 2.0);
        assert!((world_to_body(&q, &v) - r * v).norm() < 1e-14);
    }

    #[test]
    fn defaults() {
        let text = r#"
[scene]
kind = "ellipsoids"
t_end = 5
[model]
kappa = 4
[output]
every = 1
[[body]]
axes = [1, 1, 1]
mass = 1
position = [0, 0, 0]
"#;
        let s = parse_scene(text, "x.toml", None).unwrap();
        assert_eq!(s.integrator.method, Method::BulirschStoer);
        assert_eq!(s.integrator.rtol, 1e-10);
        assert_eq!(s.output.times, vec![0.0, 5.0]);
        assert_eq!(s.physics, Physics::default());
        assert_eq!(s.bodies[0].quaternion, Vec4::new(0.0, 0.0, 0.0, 1.0));
        assert_eq!(s.model.contact_g, SI_G);
    }

    #[test]
    fn unknown_field_message() {
        let text = GOOD.replace("contact = {}", "contact = {}\nfoo = 1");
        let e = parse_scene(&text, "scene.toml", None).unwrap_err().to_string();
        assert!(e.starts_with("scene.toml: unknown field `foo` in [physics]"), "{e}");
        let text = GOOD.replace("contact = {}", "contact = { cutof = 1e-10 }");
        let e = parse_scene(&text, "scene.toml", None).unwrap_err().to_string();
        assert!(e.contains("unknown field `cutof` in [physics.contact]"), "{e}");
    }

    #[test]
    fn default_scene_parses_without_calibration_errors_in_toml() {
        // Only the TOML layer: calibration needs the physics.
        parse_toml(DEFAULT_SCENE_TOML, DEFAULT_SCENE_NAME).unwrap();
    }
}
