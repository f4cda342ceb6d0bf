//! The `kind = "hard-spheres"` scene file (Richardson11 §2; its walls "from a text file" are `[[wall]]` tables):
//! `[scene]`, `[stepping]`, `[gravity]`, `[material]`, `[output]`, `[[particle]]` (optionally `stuck_to` a wall)
//! and `[[wall]]` (plane, disk, cylinder, ring, point, line). Every field's unit, default, range and meaning is
//! written once, on the structs below, and listed by `rubblepile check --explain hard-spheres`;
//! `targets/examples/hard_spheres.toml` is a complete scene. The names are the soft-sphere scene's wherever the
//! concept is the same ([`crate::granular::vocabulary`]); old names are read with a warning
//! ([`crate::granular::migrate`]). Bad input never panics: every error is one line naming the field and what was
//! expected.

use std::path::{Path, PathBuf};

use scene_derive::SceneFields;
use serde::{Deserialize, Serialize};

use super::particle::{Attachment, Particle};
use super::stepper::{DEFAULT_SKIN_STEPS, StepperSettings};
use crate::geometry::walls::{Shape, Wall, WallMotion};
use crate::granular::vocabulary::{
    OscillationSpec, check_inertia, check_start_overlaps, check_uniform_gravity, hundredths, oscillation, unit, vector,
};
use crate::io::scene_file::{MAX_BODIES, MAX_EVENTS_PER_STEP, SceneError, WORK_WARNING_STEPS, exact, parse_toml_as};
use crate::math::Vec3;

// The default written into `stepping.skin_steps`'s row, held to the constant it restates.
const _: () = assert!(DEFAULT_SKIN_STEPS == 16.0);

/// The scene kind this module reads.
pub const KIND: &str = crate::granular::vocabulary::HARD_KIND;

/// Required columns of a particles file (the snapshots add [`STUCK_COLUMN`]).
pub const PARTICLE_COLUMNS: [&str; 13] = [
    "t", "id", "mass", "radius", "x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz",
];

/// Optional particles-file column: index of the wall the particle is attached to from t = 0 (moving rigidly with
/// it, as an infinite mass), or −1 (or empty) for a free particle.
pub const STUCK_COLUMN: &str = "stuck_to";

/// One row of a particles file: the [`PARTICLE_COLUMNS`] in order and the [`STUCK_COLUMN`] if given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParticleRow {
    /// `t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz`.
    pub values: [f64; 13],
    /// Wall index, if attached.
    pub stuck_to: Option<usize>,
}

/// The whole file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, SceneFields)]
#[serde(deny_unknown_fields)]
pub struct HardSceneFile {
    /// what is simulated and for how long (required)
    #[field(table)]
    pub scene: HardSceneSection,
    /// the kick-drift-kick step and the event guards (required)
    #[field(table)]
    pub stepping: SteppingSection,
    /// uniform field (optional; absent = none)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(table)]
    pub gravity: Option<GravitySection>,
    /// restitution of every particle unless its own table overrides it (optional)
    #[serde(default)]
    #[field(table)]
    pub material: MaterialSection,
    /// snapshot times and time-series cadence (required)
    #[field(table)]
    pub output: HardOutputSection,
    /// one sphere each (or scene.particles_file)
    #[serde(default, rename = "particle", skip_serializing_if = "Vec::is_empty")]
    #[field(table)]
    pub particles: Vec<ParticleSpec>,
    /// one wall each: plane, disk, cylinder, ring, point or line, possibly moving
    #[serde(default, rename = "wall", skip_serializing_if = "Vec::is_empty")]
    #[field(table)]
    pub walls: Vec<WallSpec>,
    /// the run's budget: most steps and wall-clock seconds (optional)
    #[serde(default, skip_serializing_if = "crate::io::run_budget::RunSection::is_empty")]
    #[field(table)]
    pub run: crate::io::run_budget::RunSection,
}

/// `[scene]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "scene")]
#[serde(deny_unknown_fields)]
pub struct HardSceneSection {
    /// which engine reads the scene
    #[field(unit = "text", default = "required", range = Rule("\"hard-spheres\""))]
    pub kind: String,
    /// end time of the run; it starts at t = 0
    #[field(unit = "s", default = "required", range = Positive)]
    pub t_end: f64,
    /// recorded in summary.json; the engine draws no random numbers
    #[serde(default)]
    #[field(unit = "count", default = "0", range = Rule("integer >= 0"))]
    pub seed: u64,
    /// CSV of the initial particles, relative to the scene file's directory (a snapshot works; restitution from
    /// `[material]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "path", default = "none", range = Rule("readable CSV, <= 1e7 rows"))]
    #[field(meaning = "initial particles (t,id,mass,radius,x,...,wz[,stuck_to]) instead of [[particle]]")]
    pub particles_file: Option<String>,
}

/// `[stepping]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "stepping")]
#[serde(deny_unknown_fields)]
pub struct SteppingSection {
    /// Kick–drift–kick step (s), at least 1e-300; more than 1e9 steps are run with a warning.
    #[field(unit = "s", default = "required", range = Rule(">= t_end x 1e-12"))]
    #[field(meaning = "kick-drift-kick step, shortened to land on output times")]
    pub dt: f64,
    /// Inelastic-collapse guard (m/s): a collision whose normal approach speed is below this is elastic.
    #[serde(default)]
    #[field(unit = "m/s", default = "0 (off)", range = NonNegative)]
    #[field(meaning = "inelastic-collapse guard: slower normal approaches bounce elastically")]
    pub collapse_speed: f64,
    /// Most events one step may process (at most [`MAX_EVENTS_PER_STEP`]); beyond it the run stops as stalled.
    #[serde(default = "default_max_events")]
    #[field(unit = "count", default = "1e7", range = closed(1.0, MAX_EVENTS_PER_STEP as f64))]
    #[field(meaning = "most events one step may process; beyond it the run stops as stalled")]
    pub max_events_per_step: u64,
    /// Neighbour-list skin in steps: the list is kept across steps, re-listing a particle that could leave its
    /// allowance.
    #[serde(default = "default_skin_steps")]
    #[field(unit = "steps", default = "16", range = NonNegative)]
    #[field(meaning = "neighbour-list skin, about skin_steps |v| dt per particle; 0 = a fresh list every step")]
    pub skin_steps: f64,
}

fn default_max_events() -> u64 {
    10_000_000
}

fn default_skin_steps() -> f64 {
    DEFAULT_SKIN_STEPS
}

/// `[gravity]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "gravity")]
#[serde(deny_unknown_fields)]
pub struct GravitySection {
    /// uniform acceleration
    #[serde(deserialize_with = "exact::array")]
    #[field(unit = "m/s^2", default = "required", range = Rule("3 finite numbers"))]
    pub uniform: [f64; 3],
}

/// `[material]`: restitution of every particle unless its own table overrides it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "material")]
#[serde(deny_unknown_fields)]
pub struct MaterialSection {
    /// normal coefficient of restitution of every particle
    #[serde(default = "hundredths::<100>")]
    #[field(unit = "-", default = "1 (elastic)", range = closed(0.0, 1.0))]
    pub eps_n: f64,
    /// tangential coefficient of restitution of every particle
    #[serde(default = "hundredths::<100>")]
    #[field(unit = "-", default = "1 (smooth)", range = closed(-1.0, 1.0))]
    pub eps_t: f64,
}

impl Default for MaterialSection {
    fn default() -> Self {
        MaterialSection { eps_n: 1.0, eps_t: 1.0 }
    }
}

/// `[output]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "output")]
#[serde(deny_unknown_fields)]
pub struct HardOutputSection {
    /// Snapshot times (`snapshots/<k>.csv`); not with `snapshot_every`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "s", default = "[0, t_end]", range = Rule("increasing, in [0, t_end], <= 1e5"))]
    #[field(meaning = "snapshot times (snapshots/<k>.csv); not with snapshot_every")]
    pub times: Option<Vec<f64>>,
    /// Snapshot cadence (s), instead of `times`; the last snapshot is exactly at `t_end`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "s", default = "none", range = Rule(">= 1e-300, <= 1e5 snapshots"))]
    #[field(meaning = "snapshot cadence instead of times: 0, every, 2 every, ... and t_end")]
    pub snapshot_every: Option<f64>,
    /// time-series cadence (timeseries.csv rows)
    #[field(unit = "s", default = "required", range = Rule(">= t_end / 1e8"))]
    pub every: f64,
    /// Also write every snapshot as VTK for ParaView, as `--format vtk` does.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    #[field(unit = "bool", default = "false", range = Rule("true | false"))]
    #[field(meaning = "also write every snapshot as VTK (vtk/*.vtp, vtk/run.pvd)")]
    pub vtk: bool,
}

/// `[[particle]]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "particle")]
#[serde(deny_unknown_fields)]
pub struct ParticleSpec {
    /// mass
    #[field(unit = "kg", default = "required", range = Positive)]
    pub mass: f64,
    /// radius
    #[field(unit = "m", default = "required", range = Positive)]
    pub radius: f64,
    /// Centre; at t = 0 it may overlap a sphere or a wall by at most [`MAX_START_OVERLAP`] of its radius.
    #[serde(deserialize_with = "exact::array")]
    #[field(unit = "m", default = "required", range = Rule("3 finite numbers; overlaps <= 1e-3 of the radius"))]
    #[field(meaning = "centre")]
    pub position: [f64; 3],
    /// velocity
    #[serde(default, deserialize_with = "exact::array")]
    #[field(unit = "m/s", default = "[0, 0, 0]", range = Rule("3 finite numbers"))]
    pub velocity: [f64; 3],
    /// spin, world frame
    #[serde(default, deserialize_with = "exact::array")]
    #[field(unit = "rad/s", default = "[0, 0, 0]", range = Rule("3 finite numbers"))]
    pub spin: [f64; 3],
    /// this particle's eps_n; a pair uses the mean of its two values
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "-", default = "material.eps_n", range = closed(0.0, 1.0))]
    pub eps_n: Option<f64>,
    /// this particle's eps_t
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "-", default = "material.eps_t", range = closed(-1.0, 1.0))]
    pub eps_t: Option<f64>,
    /// The wall this particle is attached to from t = 0, moving with it as an infinite mass (a rough lining).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "count", default = "free", range = Rule("a wall index"))]
    #[field(meaning = "wall this particle is attached to from t = 0 (moves rigidly with it)")]
    pub stuck_to: Option<usize>,
}

/// `[[wall]]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "wall")]
#[serde(deny_unknown_fields)]
pub struct WallSpec {
    /// the wall's shape
    #[field(unit = "text", default = "required", range = Rule("plane | disk | cylinder | ring | point | line"))]
    pub kind: String,
    /// a point of the plane at t = 0
    #[serde(default, deserialize_with = "exact::option", skip_serializing_if = "Option::is_none")]
    #[field(unit = "m", default = "[0, 0, 0]", range = Rule("3 finite numbers; plane only"))]
    pub point: Option<[f64; 3]>,
    /// plane normal (normalised)
    #[serde(default, deserialize_with = "exact::option", skip_serializing_if = "Option::is_none")]
    #[field(unit = "-", default = "[0, 0, 1]", range = Rule("3 finite numbers, non-zero; plane only"))]
    pub normal: Option<[f64; 3]>,
    /// The centre at t = 0 of a wall that is not a plane.
    #[serde(default, deserialize_with = "exact::option", skip_serializing_if = "Option::is_none")]
    #[field(unit = "m", default = "[0, 0, 0]", range = Rule("3 finite numbers; not a plane"))]
    #[field(meaning = "centre at t = 0 of a disk, ring or point; middle of a cylinder's or line's axis")]
    pub centre: Option<[f64; 3]>,
    /// disk/ring normal, cylinder/line axis (normalised)
    #[serde(default, deserialize_with = "exact::option", skip_serializing_if = "Option::is_none")]
    #[field(unit = "-", default = "[0, 0, 1]", range = Rule("3 finite numbers, non-zero; not a plane"))]
    pub axis: Option<[f64; 3]>,
    /// Radius of a disk, ring or cylinder.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "m", default = "required by disk, ring, cylinder")]
    #[field(range = Rule(">= 1e-300 (disk); 0 or >= 1e-300 (ring, cylinder)"))]
    #[field(meaning = "radius; a ring of 0 is a point, a cylinder of 0 a line")]
    pub radius: Option<f64>,
    /// Length (m, 0 or ≥ 1e-300) of a cylinder or line, centred on `centre`; absent = infinite. A cylinder of length
    /// 0 is a ring.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "m", default = "infinite", range = Rule("0 or >= 1e-300; cylinder, line"))]
    #[field(meaning = "length centred on centre; a cylinder of length 0 is a ring")]
    pub length: Option<f64>,
    /// constant translation velocity
    #[serde(default, deserialize_with = "exact::array")]
    #[field(unit = "m/s", default = "[0, 0, 0]", range = Rule("3 finite numbers"))]
    pub velocity: [f64; 3],
    /// sinusoidal translation A (sin(omega t + phi) - sin phi) along direction (optional)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(table)]
    pub oscillation: Option<OscillationSpec>,
    /// spin about the axis (right-handed): moves the surface tangentially
    #[serde(default)]
    #[field(unit = "rad/s", default = "0", range = Rule("finite"))]
    pub spin: f64,
    /// eps_n of collisions with this wall
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "-", default = "the particle's", range = closed(0.0, 1.0))]
    pub eps_n: Option<f64>,
    /// eps_t of collisions with this wall
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "-", default = "the particle's", range = closed(-1.0, 1.0))]
    pub eps_t: Option<f64>,
    /// particles that touch it stay attached and move with it
    #[serde(default)]
    #[field(unit = "bool", default = "false", range = Rule("true | false; not with absorbing"))]
    pub sticky: bool,
    /// particles that touch it are removed and counted
    #[serde(default)]
    #[field(unit = "bool", default = "false", range = Rule("true | false"))]
    pub absorbing: bool,
}

/// A validated hard-sphere scene.
#[derive(Debug, Clone)]
pub struct HardScene {
    /// Name in messages.
    pub name: String,
    /// The scene text (copied to the output directory).
    pub source: String,
    /// Directory a relative `scene.particles_file` was resolved against.
    pub base_dir: PathBuf,
    /// The parsed file.
    pub file: HardSceneFile,
    /// End time (s).
    pub t_end: f64,
    /// Step (s).
    pub dt: f64,
    /// Seed.
    pub seed: u64,
    /// Particles at t = 0.
    pub particles: Vec<Particle>,
    /// Walls.
    pub walls: Vec<Wall>,
    /// Stepper settings.
    pub settings: StepperSettings,
    /// Snapshot times (s).
    pub times: Vec<f64>,
    /// Time-series cadence (s).
    pub every: f64,
    /// Warnings, one line each naming the file (printed by `check` and before a run): more than
    /// [`WORK_WARNING_STEPS`] steps.
    pub warnings: Vec<String>,
}

use crate::io::scene_file::Validator as V;

/// Reads and validates a hard-sphere scene file.
pub fn load_hard_scene(path: &Path) -> Result<HardScene, SceneError> {
    let s = crate::io::scene_file::read_scene_text(path)?;
    parse_hard_scene(&s.text, &s.name, &s.base_dir)
}

/// Parses and validates hard-sphere scene text; `base_dir` resolves a relative `particles_file`.
pub fn parse_hard_scene(text: &str, name: &str, base_dir: &Path) -> Result<HardScene, SceneError> {
    // Old names are read as the new ones, each with a warning.
    let migration = crate::granular::migrate::migrate(text);
    let file: HardSceneFile = parse_toml_as(&migration.text, name)?;
    let v = V { file: name };
    if file.scene.kind != KIND {
        return Err(v.invalid(
            "scene.kind",
            format!("must be \"{KIND}\" here, got {:?}", file.scene.kind),
        ));
    }
    let t_end = v.field(&HardSceneSection::T_END, file.scene.t_end)?;
    crate::io::run_budget::validate(&v, &file.run)?;
    let dt = v.step("stepping.dt", file.stepping.dt, t_end)?;
    let collapse_speed = v.field(&SteppingSection::COLLAPSE_SPEED, file.stepping.collapse_speed)?;
    let skin_steps = v.field(&SteppingSection::SKIN_STEPS, file.stepping.skin_steps)?;
    let max_events = file.stepping.max_events_per_step;
    // A count above 2^53 rounds as an f64, but every such count is far beyond the range's upper end (1e9).
    if !SteppingSection::MAX_EVENTS_PER_STEP.range.contains(max_events as f64) {
        return Err(v.invalid(
            SteppingSection::MAX_EVENTS_PER_STEP.key,
            format!("must be in [1, {MAX_EVENTS_PER_STEP}] (MAX_EVENTS_PER_STEP), got {max_events}"),
        ));
    }
    let gravity = file
        .gravity
        .map(|g| vector(&v, "gravity.uniform", g.uniform))
        .transpose()?;
    let eps_n = v.field(&MaterialSection::EPS_N, file.material.eps_n)?;
    let eps_t = v.field(&MaterialSection::EPS_T, file.material.eps_t)?;
    let every = v.cadence("output.every", file.output.every, t_end)?;
    let times = v.output_times(file.output.times.as_deref(), file.output.snapshot_every, t_end)?;

    let mut walls = Vec::new();
    for (k, w) in file.walls.iter().enumerate() {
        walls.push(wall(&v, k, w)?);
    }
    let attach = |field: String, w: Option<usize>, p: &Particle| -> Result<Option<Attachment>, SceneError> {
        match w {
            None => Ok(None),
            Some(w) if w < walls.len() => Ok(Some(Attachment {
                wall: w,
                offset: walls[w].to_local(&(p.position - walls[w].origin_at(0.0))),
                t_stuck: 0.0,
            })),
            Some(w) => Err(v.invalid(
                field,
                format!("must be a wall index in [0, {}) or -1, got {w}", walls.len()),
            )),
        }
    };
    let mut particles = Vec::new();
    match (&file.scene.particles_file, file.particles.is_empty()) {
        (Some(_), false) => {
            return Err(v.invalid(
                "scene.particles_file",
                "give either particles_file or [[particle]] tables, got both",
            ));
        }
        (None, true) => {
            return Err(v.invalid(
                "particle",
                "no particles: give [[particle]] tables or scene.particles_file",
            ));
        }
        (None, false) => {
            v.count("particle", file.particles.len(), MAX_BODIES, "particles (MAX_BODIES)")?;
            for (k, p) in file.particles.iter().enumerate() {
                let f = |x: &str| format!("particle[{k}].{x}");
                let motion = [("position", p.position), ("velocity", p.velocity), ("spin", p.spin)];
                let mut q = sphere(&v, k, &f, p.mass, p.radius, motion)?;
                q.eps_n = v.within(&ParticleSpec::EPS_N, &f("eps_n"), p.eps_n.unwrap_or(eps_n))?;
                q.eps_t = v.within(&ParticleSpec::EPS_T, &f("eps_t"), p.eps_t.unwrap_or(eps_t))?;
                q.stuck = attach(f("stuck_to"), p.stuck_to, &q)?;
                particles.push(q);
            }
        }
        (Some(rel), true) => {
            let path: PathBuf = base_dir.join(rel);
            let rows = read_particles_csv(&path)
                .map_err(|m| v.invalid("scene.particles_file", format!("{}: {m}", path.display())))?;
            if rows.is_empty() {
                return Err(v.invalid("scene.particles_file", format!("{}: no data rows", path.display())));
            }
            for (k, row) in rows.iter().enumerate() {
                let r = &row.values;
                let f = |x: &str| format!("scene.particles_file row {}: {x}", k + 1);
                let motion = [
                    ("x,y,z", [r[4], r[5], r[6]]),
                    ("vx,vy,vz", [r[7], r[8], r[9]]),
                    ("wx,wy,wz", [r[10], r[11], r[12]]),
                ];
                let mut q = sphere(&v, k, &f, r[2], r[3], motion)?;
                q.eps_n = eps_n;
                q.eps_t = eps_t;
                q.stuck = attach(f(STUCK_COLUMN), row.stuck_to, &q)?;
                particles.push(q);
            }
        }
    }
    reject_deep_overlaps(&v, &particles)?;
    reject_wall_overlaps(&v, &particles, &walls)?;
    crate::io::scene_file::check_finite_motion(
        particles
            .iter()
            .map(|p| (p.mass, p.radius, p.position, p.velocity, p.spin)),
    )
    .map_err(|(field, message)| v.invalid(field, message))?;
    if let Some(g) = gravity {
        // The potential energy m g·x of every particle enters the energy book.
        check_uniform_gravity(&v, g.norm(), particles.iter().map(|p| (p.mass, p.position)), dt)?;
    }
    let steps = t_end / dt;
    let mut warnings = migration.warnings(name);
    if steps > WORK_WARNING_STEPS {
        warnings.push(format!(
            "{name}: stepping.dt = {dt:e} s means {steps:.1e} steps to t_end = {t_end} s (more than \
             {WORK_WARNING_STEPS:e}); the run may not end in useful time"
        ));
    }
    Ok(HardScene {
        name: name.to_string(),
        source: text.to_string(),
        base_dir: base_dir.to_path_buf(),
        t_end,
        dt,
        seed: file.scene.seed,
        particles,
        walls,
        settings: StepperSettings {
            gravity,
            collapse_speed,
            max_events_per_step: file.stepping.max_events_per_step,
            skin_steps,
            prune_predictions: true,
        },
        times,
        every,
        warnings,
        file,
    })
}

/// Particle `k` from its mass (kg), radius (m) and `(key, vector)` of its position, velocity and spin, checked
/// ([`check_inertia`]); `f` names its keys.
fn sphere(
    v: &V,
    k: usize,
    f: &dyn Fn(&str) -> String,
    mass: f64,
    radius: f64,
    [x, u, w]: [(&str, [f64; 3]); 3],
) -> Result<Particle, SceneError> {
    let mass = v.within(&ParticleSpec::MASS, &f("mass"), mass)?;
    let radius = v.within(&ParticleSpec::RADIUS, &f("radius"), radius)?;
    let r2 = radius * radius;
    check_inertia(v, f, mass, radius, !r2.is_finite() || r2 < f64::MIN_POSITIVE)?;
    let [x, u, w] = [x, u, w].map(|(key, value)| vector(v, &f(key), value));
    Ok(Particle::new(k, mass, radius, x?, u?, w?))
}

/// Refuses a start where a sphere overlaps a wall by more than [`MAX_START_OVERLAP`] of its radius (as the
/// soft-sphere engine does): the event loop would bounce it in place. A sphere stuck to that wall is exempt (a
/// lining is placed against its wall).
fn reject_wall_overlaps(v: &V, particles: &[Particle], walls: &[Wall]) -> Result<(), SceneError> {
    for (k, w) in walls.iter().enumerate() {
        let origin = w.origin_at(0.0);
        for (i, p) in particles.iter().enumerate() {
            if p.stuck.as_ref().is_some_and(|a| a.wall == k) {
                continue;
            }
            let (dist, _) = w.nearest(&origin, &p.position);
            let overlap = p.radius - dist;
            if overlap > MAX_START_OVERLAP * p.radius {
                return Err(v.invalid(
                    format!("particle[{i}].position"),
                    format!(
                        "overlaps wall[{k}] ({}) by {overlap:e} m = {:.4} of its radius at the start; hard spheres may \
                         overlap a wall by at most {MAX_START_OVERLAP} of it",
                        w.shape.name(),
                        overlap / p.radius
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Largest initial overlap of two hard spheres accepted, as a fraction of the smaller radius. Touching and
/// round-off overlaps are resolved at once by the event loop; a sphere placed deep inside another would bounce in
/// place forever and stall it, so such a start is refused.
pub const MAX_START_OVERLAP: f64 = 1e-3;
// The `particle.position` row writes this number into its rule ("overlaps <= 1e-3 of the radius").
const _: () = assert!(MAX_START_OVERLAP == 1e-3);

/// Refuses a start where two spheres, not both stuck to walls, overlap by more than [`MAX_START_OVERLAP`].
fn reject_deep_overlaps(v: &V, particles: &[Particle]) -> Result<(), SceneError> {
    let centres: Vec<Vec3> = particles.iter().map(|p| p.position).collect();
    let radii: Vec<f64> = particles.iter().map(|p| p.radius).collect();
    let stuck = |i: usize| particles[i].stuck.is_some();
    let limit = format!("; hard spheres may overlap by at most {MAX_START_OVERLAP} of it");
    check_start_overlaps(
        v,
        &centres,
        &radii,
        MAX_START_OVERLAP,
        |i, j| stuck(i) && stuck(j),
        &limit,
    )
}

fn wall(v: &V, k: usize, w: &WallSpec) -> Result<Wall, SceneError> {
    let f = |x: &str| format!("wall[{k}].{x}");
    let need_radius = |allow_zero: bool| -> Result<f64, SceneError> {
        match w.radius {
            Some(r) if allow_zero => v.size_or_zero(&f("radius"), r),
            Some(r) => v.positive(&f("radius"), r),
            None => Err(v.invalid(f("radius"), format!("required for a {}, got nothing", w.kind))),
        }
    };
    let length = w.length.map(|l| v.size_or_zero(&f("length"), l)).transpose()?;
    let no = |field: &str, given: bool| -> Result<(), SceneError> {
        if given {
            Err(v.invalid(f(field), format!("not used by a {}; remove it", w.kind)))
        } else {
            Ok(())
        }
    };
    let shape = match w.kind.as_str() {
        "plane" => {
            no("radius", w.radius.is_some())?;
            no("length", length.is_some())?;
            Shape::Plane
        }
        "disk" => {
            no("length", length.is_some())?;
            Shape::Disk {
                radius: need_radius(false)?,
            }
        }
        "ring" => {
            no("length", length.is_some())?;
            match need_radius(true)? {
                0.0 => Shape::Point,
                r => Shape::Ring { radius: r },
            }
        }
        "point" => {
            no("radius", w.radius.is_some())?;
            no("length", length.is_some())?;
            Shape::Point
        }
        "line" => {
            no("radius", w.radius.is_some())?;
            Shape::Line {
                length: length.filter(|&l| l > 0.0),
            }
        }
        "cylinder" => {
            // Degenerate cases (notes): L = 0 is a ring, R = 0 a line, both a point.
            match (need_radius(true)?, length) {
                (0.0, Some(0.0)) => Shape::Point,
                (0.0, l) => Shape::Line { length: l },
                (r, Some(0.0)) => Shape::Ring { radius: r },
                (r, l) => Shape::Cylinder { radius: r, length: l },
            }
        }
        other => {
            return Err(v.invalid(
                f("kind"),
                format!(
                    "must be one of \"plane\", \"disk\", \"cylinder\", \"ring\", \"point\", \"line\", got {other:?}"
                ),
            ));
        }
    };
    // A plane is placed by a point and its normal, the others by their centre and axis.
    let (at, facing) = if w.kind == "plane" {
        no("centre", w.centre.is_some())?;
        no("axis", w.axis.is_some())?;
        (("point", w.point), ("normal", w.normal))
    } else {
        no("point", w.point.is_some())?;
        no("normal", w.normal.is_some())?;
        (("centre", w.centre), ("axis", w.axis))
    };
    let axis = unit(v, &f(facing.0), facing.1.unwrap_or([0.0, 0.0, 1.0]))?;
    let mut wall = Wall::new(shape, vector(v, &f(at.0), at.1.unwrap_or_default())?, axis);
    let oscillation = w
        .oscillation
        .as_ref()
        .map(|o| oscillation(v, &format!("wall[{k}]"), o, Some(axis)))
        .transpose()?;
    if !w.spin.is_finite() {
        return Err(v.invalid(f("spin"), format!("must be finite, got {}", w.spin)));
    }
    wall.motion = WallMotion {
        velocity: vector(v, &f("velocity"), w.velocity)?,
        oscillation,
        spin: w.spin,
    };
    wall.eps_n = w
        .eps_n
        .map(|e| v.within(&WallSpec::EPS_N, &f("eps_n"), e))
        .transpose()?;
    wall.eps_t = w
        .eps_t
        .map(|e| v.within(&WallSpec::EPS_T, &f("eps_t"), e))
        .transpose()?;
    if w.sticky && w.absorbing {
        return Err(v.invalid(f("sticky"), "a wall cannot be both sticky and absorbing, got both true"));
    }
    wall.sticky = w.sticky;
    wall.absorbing = w.absorbing;
    Ok(wall)
}

pub use crate::io::particles::ParticlesFileError;

/// Reads a particles CSV (header with at least the [`PARTICLE_COLUMNS`], optionally [`STUCK_COLUMN`]); rows in that
/// column order.
pub fn read_particles_csv(path: &Path) -> Result<Vec<ParticleRow>, ParticlesFileError> {
    let records = crate::io::particles::read_particles(path, &PARTICLE_COLUMNS, &[STUCK_COLUMN])?;
    let mut rows = Vec::with_capacity(records.len());
    for r in records {
        let mut values = [0.0; 13];
        values.copy_from_slice(&r.values);
        let stuck_to = match r.optional[0].as_deref() {
            None | Some("") => None,
            Some(s) => match s.parse::<i64>() {
                Ok(w) if w < 0 => None,
                Ok(w) => Some(w as usize),
                Err(_) => {
                    return Err(ParticlesFileError::Cell {
                        line: r.line,
                        column: STUCK_COLUMN,
                        expected: "a wall index or -1",
                        value: s.to_string(),
                    });
                }
            },
        };
        rows.push(ParticleRow { values, stuck_to });
    }
    Ok(rows)
}
