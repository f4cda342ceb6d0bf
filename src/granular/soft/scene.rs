//! The `kind = "soft-spheres"` scene file (Zhang17 §2; parameters of §2.3.3), run by `rubblepile run`: `[scene]`,
//! `[stepping]`, `[material]`, `[gravity]`, `[output]`, `[[wall]]` (plane, sphere, cylinder) and `[[particle]]`.
//! Every field's unit, default, range and meaning is written once, on the structs below, and listed by `rubblepile
//! check --explain soft-spheres`; `targets/examples/soft_spheres.toml` and `soft_drum.toml` are complete scenes.
//! The names are the hard-sphere scene's wherever the concept is the same ([`crate::granular::vocabulary`]); old
//! names are read with a warning ([`crate::granular::migrate`]). Errors are one line naming the file, the dotted
//! field and what was expected ([`SceneError`]); warnings flag an old name, a step more than ten times the advised
//! one and a `k_N` far below the advised one.

use std::path::{Path, PathBuf};

use scene_derive::SceneFields;
use serde::{Deserialize, Serialize};

use crate::geometry::walls::soft::{Cylinder, Plane, SphereContainer, Wall};
use crate::granular::soft::advise::{Advice, AdviceInput, DEFAULT_MAX_OVERLAP, advise};
use crate::granular::soft::contact::Material;
use crate::granular::soft::forces::Gravity;
use crate::granular::soft::particle::Particle;
use crate::granular::vocabulary::{
    OscillationSpec, check_inertia, check_start_overlaps, check_uniform_gravity, hundredths, oscillation, unit, vector,
};
use crate::gravity::SelfGravity;
use crate::io::scene_file::{
    MAX_BODIES, MIN_MEANINGFUL, MIN_STEP_FRACTION, SI_G, SceneError, WORK_WARNING_STEPS, exact,
};

use crate::math::Vec3;

/// The scene kind this module reads.
pub const KIND: &str = crate::granular::vocabulary::SOFT_KIND;

/// A whole soft-sphere scene file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, SceneFields)]
#[serde(deny_unknown_fields)]
pub struct SoftSceneFile {
    /// what is simulated and for how long (required)
    #[field(table)]
    pub scene: SoftSceneSection,
    /// the fixed leapfrog step (required)
    #[field(table)]
    pub stepping: SoftSteppingSection,
    /// the contact law's material, Zhang17 Eqs. 1-12 (required for k_n; the rest default to Zhang17's nominal set)
    #[field(table)]
    pub material: MaterialSection,
    /// uniform field and self-gravity (optional; absent = no gravity)
    #[serde(default)]
    #[field(table)]
    pub gravity: GravitySection,
    /// time-series cadence and snapshot times (required)
    #[field(table)]
    pub output: SoftOutputSection,
    /// one wall each: a plane (point, normal), the inside of a sphere (centre, radius) or a cylinder (centre, axis,
    /// radius, length)
    #[serde(default, rename = "wall", skip_serializing_if = "Vec::is_empty")]
    #[field(table)]
    pub walls: Vec<WallSpec>,
    /// one sphere each (or scene.particles_file)
    #[serde(default, rename = "particle", skip_serializing_if = "Vec::is_empty")]
    #[field(table)]
    pub particles: Vec<ParticleSpec>,
    /// spin-up forcing along a period path T(t) and its diagnostics (optional; Zhang17 §2.3.4)
    #[serde(default)]
    #[field(table)]
    pub spinup: Option<crate::granular::soft::spinup::SpinupSection>,
    /// the run's budget: most steps and wall-clock seconds (optional)
    #[serde(default, skip_serializing_if = "crate::io::run_budget::RunSection::is_empty")]
    #[field(table)]
    pub run: crate::io::run_budget::RunSection,
}

/// `[scene]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "scene")]
#[serde(deny_unknown_fields)]
pub struct SoftSceneSection {
    /// which engine reads the scene
    #[field(unit = "text", default = "required", range = Rule("\"soft-spheres\""))]
    pub kind: String,
    /// end time; the run takes round(t_end/dt) steps
    #[field(unit = "s", default = "required", range = Positive)]
    pub t_end: f64,
    /// recorded in the summary; the engine draws no random numbers
    #[serde(default)]
    #[field(unit = "count", default = "0", range = Rule("integer >= 0"))]
    pub seed: u64,
    /// CSV of the initial particles, relative to the scene's directory (`t`, `id` optional; a snapshot works).
    #[serde(default)]
    #[field(unit = "path", default = "none", range = Rule("readable CSV, <= 1e7 rows"))]
    #[field(meaning = "initial particles (t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz) instead of [[particle]]")]
    pub particles_file: Option<String>,
}

/// `[stepping]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "stepping")]
#[serde(deny_unknown_fields)]
pub struct SoftSteppingSection {
    /// Fixed leapfrog step (s); more than 1e9 steps are run with a warning.
    #[field(unit = "s", default = "required", range = Rule("<= 2 sqrt(m_min/2 / k_n) and t_end, >= t_end x 1e-12"))]
    #[field(meaning = "fixed leapfrog step (see `rubblepile ssdem advise`)")]
    pub dt: f64,
}

/// `[material]`: the contact law's material (defaults: Zhang17's nominal set, §2.3.3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "material")]
#[serde(deny_unknown_fields)]
pub struct MaterialSection {
    /// normal spring constant (k_S = 2/7 k_N); see `rubblepile ssdem advise`
    #[field(unit = "N/m", default = "required", range = Positive)]
    pub k_n: f64,
    /// normal coefficient of restitution
    #[serde(default = "hundredths::<55>")]
    #[field(unit = "-", default = "0.55", range = open_closed(0.0, 1.0))]
    pub eps_n: f64,
    /// tangential coefficient of restitution
    #[serde(default = "hundredths::<55>")]
    #[field(unit = "-", default = "0.55", range = open_closed(0.0, 1.0))]
    pub eps_t: f64,
    /// sliding friction coefficient
    #[serde(default = "hundredths::<100>")]
    #[field(unit = "-", default = "1.0", range = NonNegative)]
    pub mu_s: f64,
    /// twisting friction coefficient
    #[serde(default = "hundredths::<130>")]
    #[field(unit = "-", default = "1.3", range = NonNegative)]
    pub mu_t: f64,
    /// rolling friction coefficient
    #[serde(default = "hundredths::<105>")]
    #[field(unit = "-", default = "1.05", range = NonNegative)]
    pub mu_r: f64,
    /// shape parameter (0 = no twisting or rolling resistance)
    #[serde(default = "hundredths::<50>")]
    #[field(unit = "-", default = "0.5", range = NonNegative)]
    pub beta: f64,
    /// largest initial overlap accepted, as a fraction of the smaller radius
    #[serde(default = "hundredths::<5>")]
    #[field(unit = "-", default = "0.05", range = NonNegative)]
    pub max_start_overlap: f64,
}

/// `[gravity]`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, SceneFields)]
#[scene(table = "gravity")]
#[serde(deny_unknown_fields)]
pub struct GravitySection {
    /// uniform acceleration
    #[serde(default, deserialize_with = "exact::option")]
    #[field(unit = "m/s^2", default = "none", range = Rule("3 finite numbers"))]
    pub uniform: Option<[f64; 3]>,
    /// self-gravity by octree (quadrupole) or exact pair sum; absent = none
    #[serde(default, rename = "self")]
    #[field(unit = "text", default = "none", range = Rule("\"tree\" | \"direct\""))]
    pub self_gravity: Option<String>,
    /// tree opening angle; only with self = "tree"
    #[serde(default)]
    #[field(unit = "-", default = "0.5", range = open_closed(0.0, 1.0))]
    pub theta: Option<f64>,
    /// Steps `k` between self-gravity evaluations: kicks of `k dt/2` at both ends of each block of `k` steps
    /// (r-RESPA, [`crate::granular::soft::respa`]).
    #[serde(default)]
    #[field(unit = "steps", default = "1", range = Rule("integer >= 1; > 1 needs self"))]
    #[field(meaning = "steps between self-gravity evaluations (r-RESPA kicks)")]
    pub interval_steps: Option<i64>,
    /// gravitational constant of the self-gravity
    #[serde(default, rename = "G")]
    #[field(unit = "m^3 kg^-1 s^-2", default = "6.674e-11", range = Positive)]
    pub g: Option<f64>,
}

/// `[output]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "output")]
#[serde(deny_unknown_fields)]
pub struct SoftOutputSection {
    /// Time-series cadence (s), rounded to a whole number of steps.
    #[field(unit = "s", default = "required", range = Rule(">= t_end / 1e8"))]
    #[field(meaning = "time-series cadence, rounded to whole steps (at least one)")]
    pub every: f64,
    /// Snapshot times (s), each taken at the nearest step.
    #[serde(default)]
    #[field(unit = "s", default = "[0, t_end]", range = Rule("increasing, in [0, t_end], >= 1 step apart, <= 1e5"))]
    #[field(meaning = "snapshot times, each at the nearest step; not with snapshot_every")]
    pub times: Option<Vec<f64>>,
    /// Snapshot cadence (s), instead of `times`; each snapshot at the nearest step.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "s", default = "none", range = Rule(">= 1 step, <= 1e5 snapshots"))]
    #[field(meaning = "snapshot cadence instead of times: 0, every, 2 every, ... and t_end")]
    pub snapshot_every: Option<f64>,
    /// Also write every snapshot as VTK for ParaView, as `--format vtk` does.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    #[field(unit = "bool", default = "false", range = Rule("true | false"))]
    #[field(meaning = "also write every snapshot as VTK (vtk/*.vtp, vtk/run.pvd)")]
    pub vtk: bool,
}

/// `[[wall]]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "wall")]
#[serde(deny_unknown_fields)]
pub struct WallSpec {
    /// a half-space, the inside of a sphere, or a cylinder (touched from inside or outside)
    #[field(unit = "text", default = "required", range = Rule("\"plane\" | \"sphere\" | \"cylinder\""))]
    pub kind: String,
    /// a point of the plane
    #[serde(default, deserialize_with = "exact::option", skip_serializing_if = "Option::is_none")]
    #[field(unit = "m", default = "required by \"plane\"", range = Rule("3 finite numbers"))]
    pub point: Option<[f64; 3]>,
    /// plane normal towards the particles (normalised)
    #[serde(default, deserialize_with = "exact::option", skip_serializing_if = "Option::is_none")]
    #[field(unit = "-", default = "required by \"plane\"", range = Rule("3 finite numbers, non-zero"))]
    pub normal: Option<[f64; 3]>,
    /// centre of a sphere wall, middle of a cylinder's axis
    #[serde(default, deserialize_with = "exact::option", skip_serializing_if = "Option::is_none")]
    #[field(unit = "m", default = "required by \"sphere\", \"cylinder\"", range = Rule("3 finite numbers"))]
    pub centre: Option<[f64; 3]>,
    /// cylinder axis (normalised)
    #[serde(default, deserialize_with = "exact::option", skip_serializing_if = "Option::is_none")]
    #[field(unit = "-", default = "required by \"cylinder\"", range = Rule("3 finite numbers, non-zero"))]
    pub axis: Option<[f64; 3]>,
    /// inner radius of a sphere wall, radius of a cylinder
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "m", default = "required by \"sphere\", \"cylinder\"", range = Positive)]
    pub radius: Option<f64>,
    /// length of a cylinder along its axis, centred on its centre
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "m", default = "infinite", range = Positive)]
    pub length: Option<f64>,
    /// sinusoidal translation A (sin(omega t + phi) - sin phi) along direction (optional)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(table)]
    pub oscillation: Option<OscillationSpec>,
    /// spin about the axis (right-handed): moves the surface tangentially
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "rad/s", default = "0", range = Rule("finite; \"cylinder\" only"))]
    pub spin: Option<f64>,
}

/// `[[particle]]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "particle")]
#[serde(deny_unknown_fields)]
pub struct ParticleSpec {
    /// sphere radius
    #[field(unit = "m", default = "required", range = Positive)]
    pub radius: f64,
    /// mass; exactly one of mass, density
    #[serde(default)]
    #[field(unit = "kg", default = "(mass or density)", range = Positive)]
    pub mass: Option<f64>,
    /// grain density: mass = 4/3 pi r^3 density
    #[serde(default)]
    #[field(unit = "kg/m^3", default = "(mass or density)", range = Positive)]
    pub density: Option<f64>,
    /// centre
    #[serde(deserialize_with = "exact::array")]
    #[field(unit = "m", default = "required", range = Rule("3 finite numbers; overlaps <= contact.max_start_overlap"))]
    pub position: [f64; 3],
    /// velocity
    #[serde(default, deserialize_with = "exact::array")]
    #[field(unit = "m/s", default = "[0, 0, 0]", range = Rule("3 finite numbers"))]
    pub velocity: [f64; 3],
    /// spin
    #[serde(default, deserialize_with = "exact::array")]
    #[field(unit = "rad/s", default = "[0, 0, 0]", range = Rule("3 finite numbers"))]
    pub spin: [f64; 3],
}

/// A validated soft-sphere scene.
#[derive(Debug, Clone, PartialEq)]
pub struct SoftScene {
    /// Name in messages.
    pub name: String,
    /// The scene text (copied into the run directory).
    pub source: String,
    /// Where `particles_file` is resolved.
    pub base_dir: Option<PathBuf>,
    /// End time (s).
    pub t_end: f64,
    /// Seed.
    pub seed: u64,
    /// Step (s).
    pub dt: f64,
    /// Steps of the run, `round(t_end/dt)`.
    pub n_steps: u64,
    /// Steps between time-series rows.
    pub every_steps: u64,
    /// Steps of the snapshots, strictly increasing.
    pub snapshot_steps: Vec<u64>,
    /// `[output] vtk`: also write VTK snapshots.
    pub vtk: bool,
    /// Material.
    pub material: Material,
    /// Gravity.
    pub gravity: Gravity,
    /// Steps between self-gravity evaluations (`[gravity] interval_steps`, ≥ 1).
    pub gravity_interval: u64,
    /// Walls.
    pub walls: Vec<Wall>,
    /// Initial particles.
    pub particles: Vec<Particle>,
    /// `k_N` and step advised for this scene (1 % overlap).
    pub advice: Advice,
    /// Warnings (one line each).
    pub warnings: Vec<String>,
    /// Spin-up forcing and diagnostics (`[spinup]`), if any.
    pub spinup: Option<crate::granular::soft::spinup::SpinupSettings>,
}

/// The `scene.kind` of a TOML text, if it has one (used to dispatch `rubblepile run`).
pub fn scene_kind(text: &str) -> Option<String> {
    let value: toml::Table = toml::from_str(text).ok()?;
    value.get("scene")?.get("kind")?.as_str().map(str::to_string)
}

fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Reads and validates a soft-sphere scene file.
pub fn load_soft_scene(path: &Path) -> Result<SoftScene, SceneError> {
    let s = crate::io::scene_file::read_scene_text(path)?;
    parse_soft_scene(&s.text, &s.name, Some(&s.base_dir))
}

/// Parses and validates soft-sphere scene text (`name` for messages; `base_dir` resolves `particles_file`).
pub fn parse_soft_scene(text: &str, name: &str, base_dir: Option<&Path>) -> Result<SoftScene, SceneError> {
    let syntax = |message: String| SceneError::Syntax {
        file: name.to_string(),
        message: one_line(&message),
    };
    // Old names are read as the new ones, each with a warning.
    let migration = crate::granular::migrate::migrate(text);
    let de = toml::Deserializer::parse(&migration.text).map_err(|e| syntax(e.message().to_string()))?;
    let file: SoftSceneFile = serde_path_to_error::deserialize(de).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        syntax(format!("{path}: {}", inner.message()))
    })?;
    let v = V { file: name };
    let mut scene = v.resolve_soft(text, file, base_dir)?;
    scene.warnings.splice(0..0, migration.warnings(name));
    Ok(scene)
}

use crate::io::scene_file::Validator as V;

impl V<'_> {
    fn particle(&self, label: &str, s: &ParticleSpec) -> Result<Particle, SceneError> {
        let radius = self.within(&ParticleSpec::RADIUS, &format!("{label}.radius"), s.radius)?;
        // r² and r³ enter the moment of inertia and the mass from the density: they must stay normal numbers.
        let r3 = radius * radius * radius;
        let radius_fault = !(r3.is_finite() && radius * radius >= f64::MIN_POSITIVE && r3 >= f64::MIN_POSITIVE);
        let mass = match (s.mass, s.density) {
            (Some(m), None) => self.within(&ParticleSpec::MASS, &format!("{label}.mass"), m)?,
            (None, Some(rho)) => {
                let m = self.within(&ParticleSpec::DENSITY, &format!("{label}.density"), rho)? * 4.0 / 3.0
                    * std::f64::consts::PI
                    * r3;
                if !(m.is_finite() && m >= MIN_MEANINGFUL) {
                    let field = if radius_fault { "radius" } else { "density" };
                    return Err(self.invalid(
                        format!("{label}.{field}"),
                        format!(
                            "gives a mass 4/3 pi r^3 density = {m:e} kg (radius {radius:e} m, density {rho:e} kg/m^3), \
                             need finite and >= {MIN_MEANINGFUL:e}"
                        ),
                    ));
                }
                m
            }
            _ => return Err(self.invalid(label, "give exactly one of `mass` (kg) and `density` (kg/m^3)")),
        };
        check_inertia(self, &|key| format!("{label}.{key}"), mass, radius, radius_fault)?;
        Ok(Particle {
            mass,
            radius,
            position: vector(self, &format!("{label}.position"), s.position)?,
            velocity: vector(self, &format!("{label}.velocity"), s.velocity)?,
            spin: vector(self, &format!("{label}.spin"), s.spin)?,
        })
    }

    /// The gravity terms at t = 0: with self-gravity, `G m_max² / r_min²` (the largest pair force between touching
    /// spheres) and `G M² / r_min` must be finite; with a uniform field `g`, every `m |g| |x|` and `|g| dt`.
    fn gravity_finite(&self, gravity: &Gravity, particles: &[Particle], dt: f64) -> Result<(), SceneError> {
        if gravity.self_gravity.is_some() {
            let m_max = particles.iter().map(|p| p.mass).fold(0.0, f64::max);
            let m_total: f64 = particles.iter().map(|p| p.mass).sum();
            let r_min = particles.iter().map(|p| p.radius).fold(f64::INFINITY, f64::min);
            let force = gravity.g * m_max * m_max / (r_min * r_min);
            let energy = gravity.g * m_total * m_total / r_min;
            if !(force.is_finite() && energy.is_finite()) {
                return Err(self.invalid(
                    "gravity.G",
                    format!(
                        "gives a non-finite self-gravity at t = 0 (G m_max^2 / r_min^2 = {force:e} N, G M^2 / r_min = \
                         {energy:e} J), got {:e}",
                        gravity.g
                    ),
                ));
            }
        }
        let g = gravity.uniform.norm();
        if g > 0.0 {
            check_uniform_gravity(self, g, particles.iter().map(|p| (p.mass, p.position)), dt)?;
        }
        Ok(())
    }

    fn read_particles_file(&self, rel: &str, base_dir: Option<&Path>) -> Result<Vec<Particle>, SceneError> {
        let path = base_dir.map(|b| b.join(rel)).unwrap_or_else(|| PathBuf::from(rel));
        let field = "scene.particles_file";
        let names = ["mass", "radius", "x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz"];
        let records = crate::io::particles::read_particles(&path, &names, &[]).map_err(|e| match e {
            crate::io::particles::ParticlesFileError::Cell {
                line, column, value, ..
            } => self.invalid(
                format!("particle[{}] ({rel} line {line}).{column}", line - 2),
                format!("expected a number, got {value:?}"),
            ),
            crate::io::particles::ParticlesFileError::MissingColumn { column, .. } => self.invalid(
                field,
                format!(
                    "{}: missing column `{column}` (need t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz)",
                    path.display()
                ),
            ),
            crate::io::particles::ParticlesFileError::Read(m) => {
                self.invalid(field, format!("{}: {m}", path.display()))
            }
        })?;
        let mut out = Vec::new();
        for (row, r) in records.iter().enumerate() {
            let label = format!("particle[{row}] ({rel} line {})", r.line);
            let v = &r.values;
            let spec = ParticleSpec {
                radius: v[1],
                mass: Some(v[0]),
                density: None,
                position: [v[2], v[3], v[4]],
                velocity: [v[5], v[6], v[7]],
                spin: [v[8], v[9], v[10]],
            };
            out.push(self.particle(&label, &spec)?);
        }
        Ok(out)
    }

    fn wall(&self, k: usize, w: &WallSpec) -> Result<Wall, SceneError> {
        let label = format!("wall[{k}]");
        let field = |name: &str| format!("{label}.{name}");
        // The keys each kind requires and those it may take besides; any other placement key is refused.
        let (required, optional): (&[&str], &[&str]) = match w.kind.as_str() {
            "plane" => (&["point", "normal"], &[]),
            "sphere" => (&["centre", "radius"], &[]),
            "cylinder" => (&["centre", "axis", "radius"], &["length", "spin"]),
            other => {
                return Err(self.invalid(
                    field("kind"),
                    format!("must be \"plane\", \"sphere\" or \"cylinder\", got {other:?}"),
                ));
            }
        };
        let given = [
            ("point", w.point.is_some()),
            ("normal", w.normal.is_some()),
            ("centre", w.centre.is_some()),
            ("axis", w.axis.is_some()),
            ("radius", w.radius.is_some()),
            ("length", w.length.is_some()),
            ("spin", w.spin.is_some()),
        ];
        for name in required {
            if !given.iter().any(|(n, present)| n == name && *present) {
                return Err(self.invalid(field(name), format!("missing (required for a {} wall)", w.kind)));
            }
        }
        for (name, present) in given {
            if present && !required.contains(&name) && !optional.contains(&name) {
                return Err(self.invalid(field(name), format!("not used by a {} wall", w.kind)));
            }
        }
        let shaking = |direction: Option<Vec3>| {
            w.oscillation
                .as_ref()
                .map(|o| oscillation(self, &label, o, direction))
                .transpose()
        };
        match w.kind.as_str() {
            "plane" => {
                let point = vector(self, &field("point"), w.point.unwrap_or_default())?;
                let normal = unit(self, &field("normal"), w.normal.unwrap_or_default())?;
                Ok(Wall::Plane(Plane {
                    point,
                    normal,
                    oscillation: shaking(Some(normal))?,
                }))
            }
            "sphere" => Ok(Wall::Sphere(SphereContainer {
                centre: vector(self, &field("centre"), w.centre.unwrap_or_default())?,
                radius: self.within(&WallSpec::RADIUS, &field("radius"), w.radius.unwrap_or_default())?,
                oscillation: shaking(None)?,
            })),
            _ => {
                let axis = unit(self, &field("axis"), w.axis.unwrap_or_default())?;
                let spin = w.spin.unwrap_or(0.0);
                if !spin.is_finite() {
                    return Err(self.invalid(field("spin"), format!("must be finite (rad/s), got {spin}")));
                }
                Ok(Wall::Cylinder(Cylinder {
                    centre: vector(self, &field("centre"), w.centre.unwrap_or_default())?,
                    axis,
                    radius: self.within(&WallSpec::RADIUS, &field("radius"), w.radius.unwrap_or_default())?,
                    length: w
                        .length
                        .map(|l| self.within(&WallSpec::LENGTH, &field("length"), l))
                        .transpose()?,
                    oscillation: shaking(Some(axis))?,
                    spin,
                }))
            }
        }
    }

    fn resolve_soft(&self, text: &str, file: SoftSceneFile, base_dir: Option<&Path>) -> Result<SoftScene, SceneError> {
        if file.scene.kind != KIND {
            return Err(self.invalid("scene.kind", format!("must be \"{KIND}\", got {:?}", file.scene.kind)));
        }
        let t_end = self.field(&SoftSceneSection::T_END, file.scene.t_end)?;
        crate::io::run_budget::validate(self, &file.run)?;
        let dt = self.step("stepping.dt", file.stepping.dt, t_end)?;
        let steps = (t_end / dt).round();
        if !(1.0..=1e12).contains(&steps) {
            return Err(self.invalid(
                "stepping.dt",
                format!("t_end/dt must be in [1, 1e12], got {}", t_end / dt),
            ));
        }
        let n_steps = steps as u64;

        let c = &file.material;
        let material = Material {
            k_n: self.field(&MaterialSection::K_N, c.k_n)?,
            eps_n: self.field(&MaterialSection::EPS_N, c.eps_n)?,
            eps_t: self.field(&MaterialSection::EPS_T, c.eps_t)?,
            mu_s: self.field(&MaterialSection::MU_S, c.mu_s)?,
            mu_t: self.field(&MaterialSection::MU_T, c.mu_t)?,
            mu_r: self.field(&MaterialSection::MU_R, c.mu_r)?,
            beta: self.field(&MaterialSection::BETA, c.beta)?,
        };
        let max_start = self.field(&MaterialSection::MAX_START_OVERLAP, c.max_start_overlap)?;

        let gs = &file.gravity;
        let g =
            gs.g.map(|g| self.field(&GravitySection::G, g))
                .transpose()?
                .unwrap_or(SI_G);
        let self_gravity = match gs.self_gravity.as_deref() {
            None => {
                if gs.theta.is_some() {
                    return Err(self.invalid("gravity.theta", "only used with self = \"tree\""));
                }
                None
            }
            Some("direct") => {
                if gs.theta.is_some() {
                    return Err(self.invalid("gravity.theta", "only used with self = \"tree\", got self = \"direct\""));
                }
                Some(SelfGravity::Direct)
            }
            Some("tree") => {
                let theta = self.field(&GravitySection::THETA, gs.theta.unwrap_or(0.5))?;
                Some(SelfGravity::Tree { theta })
            }
            Some(other) => {
                return Err(self.invalid("gravity.self", format!("must be \"tree\" or \"direct\", got {other:?}")));
            }
        };
        let gravity_interval = match gs.interval_steps {
            None => 1,
            Some(k) if k < 1 => {
                return Err(self.invalid(
                    "gravity.interval_steps",
                    format!("must be an integer >= 1 (steps), got {k}"),
                ));
            }
            Some(k) if k > 1 && self_gravity.is_none() => {
                return Err(self.invalid(
                    "gravity.interval_steps",
                    format!("only used with self = \"tree\" or \"direct\", got {k} without self-gravity"),
                ));
            }
            Some(k) => k as u64,
        };
        let uniform = gs.uniform.map(|u| vector(self, "gravity.uniform", u)).transpose()?;
        let uniform = uniform.unwrap_or_else(Vec3::zeros);
        let gravity = Gravity {
            uniform,
            self_gravity,
            g,
        };

        let every = self.cadence("output.every", file.output.every, t_end)?;
        let every_steps = ((every / dt).round() as u64).max(1);
        let times = self.output_times(file.output.times.as_deref(), file.output.snapshot_every, t_end)?;
        let mut snapshot_steps: Vec<u64> = Vec::new();
        for (k, &t) in times.iter().enumerate() {
            // Distinct times may still round to one step.
            let s = ((t / dt).round() as u64).min(n_steps);
            if snapshot_steps.last().is_some_and(|&p| s <= p) {
                return Err(match file.output.snapshot_every {
                    Some(every) => self.invalid(
                        "output.snapshot_every",
                        format!("must be at least one step (dt = {dt} s) between snapshots, got {every}"),
                    ),
                    None => self.invalid(
                        format!("output.times[{k}]"),
                        format!("must be increasing and at least one step (dt = {dt} s) after the previous, got {t}"),
                    ),
                });
            }
            snapshot_steps.push(s);
        }

        let walls = file
            .walls
            .iter()
            .enumerate()
            .map(|(k, w)| self.wall(k, w))
            .collect::<Result<Vec<_>, _>>()?;
        let particles = match (&file.scene.particles_file, file.particles.is_empty()) {
            (Some(_), false) => {
                return Err(self.invalid(
                    "scene.particles_file",
                    "give either particles_file or [[particle]] tables, not both",
                ));
            }
            (Some(f), true) => self.read_particles_file(f, base_dir)?,
            (None, _) => file
                .particles
                .iter()
                .enumerate()
                .map(|(k, s)| self.particle(&format!("particle[{k}]"), s))
                .collect::<Result<Vec<_>, _>>()?,
        };
        if particles.is_empty() {
            return Err(self.invalid(
                "particle",
                "need at least one [[particle]] table or scene.particles_file",
            ));
        }
        self.count("particle", particles.len(), MAX_BODIES, "particles (MAX_BODIES)")?;
        self.gravity_finite(&gravity, &particles, dt)?;

        // Initial overlaps.
        let centres: Vec<Vec3> = particles.iter().map(|p| p.position).collect();
        let radii: Vec<f64> = particles.iter().map(|p| p.radius).collect();
        let limit = format!(", more than material.max_start_overlap = {max_start}");
        check_start_overlaps(self, &centres, &radii, max_start, |_, _| false, &limit)?;
        for (k, w) in walls.iter().enumerate() {
            for (i, p) in particles.iter().enumerate() {
                if let Some(touch) = w.touch(&p.position, p.radius, 0.0)
                    && touch.overlap / p.radius > max_start
                {
                    return Err(self.invalid(
                        format!("particle[{i}].position"),
                        format!(
                            "overlaps wall[{k}] by {} m = {:.4} of its radius at the start, more than material.max_start_overlap = {max_start}",
                            touch.overlap,
                            touch.overlap / p.radius
                        ),
                    ));
                }
            }
        }

        // [spinup] (crate::granular::soft::spinup)
        let spinup = file.spinup.as_ref().map(|s| self.spinup(s)).transpose()?;
        let advice = scene_advice(&particles, &gravity, material.k_n);
        let mut warnings = Vec::new();
        let m_min = particles.iter().map(|p| p.mass).fold(f64::INFINITY, f64::min);
        let limit = crate::granular::soft::advise::stability_limit(material.k_n, m_min);
        if limit.is_nan() || limit < t_end * MIN_STEP_FRACTION {
            let lightest = particles.iter().position(|p| p.mass == m_min).unwrap_or(0);
            // No step can be both stable and at least t_end × 1e-12: the stiffness (or a tiny mass) is the cause.
            return Err(self.invalid(
                "material.k_n",
                format!(
                    "gives a leapfrog stability limit 2 sqrt(m_min/2 / k_n) = {limit:.3e} s (m_min = {m_min:.3e} kg, \
                     particle[{lightest}]), below t_end x {MIN_STEP_FRACTION:e}: more than 1e12 steps, got {:e} N/m",
                    material.k_n
                ),
            ));
        }
        if dt > limit {
            return Err(self.invalid(
                "stepping.dt",
                format!(
                    "must be <= the leapfrog stability limit 2 sqrt(m_min/2 / k_n) = {limit:e} s for material.k_n = {:e} N/m, got {dt:e} (advised: {:e} s)",
                    material.k_n,
                    limit / (2.0 / std::f64::consts::PI * crate::granular::soft::advise::STEPS_PER_CONTACT)
                ),
            ));
        }
        let advised_dt = std::f64::consts::PI * (0.5 * m_min / material.k_n).sqrt()
            / crate::granular::soft::advise::STEPS_PER_CONTACT;
        if dt > 10.0 * advised_dt {
            warnings.push(format!(
                "{}: stepping.dt = {dt:e} s is more than 10 x the advised {advised_dt:e} s for material.k_n (contacts resolved by fewer than 5 steps)",
                self.file
            ));
        }
        if n_steps as f64 > WORK_WARNING_STEPS {
            warnings.push(format!(
                "{}: stepping.dt = {dt:e} s means {n_steps} steps to t_end = {t_end} s (more than \
                 {WORK_WARNING_STEPS:e}); the run may not end in useful time",
                self.file
            ));
        }
        if material.k_n < 0.1 * advice.k_n {
            // Run summaries record this line, and the recorded ones are compared byte for byte: it keeps the
            // words it was first written with ("contact" the contact law of `[material]`).
            warnings.push(format!(
                "{}: contact.k_n = {:e} N/m is below a tenth of the advised {:e} N/m: overlaps may exceed 1 % of the smallest radius",
                self.file, material.k_n, advice.k_n
            ));
        }
        if gravity_interval > 1 && !n_steps.is_multiple_of(gravity_interval) {
            warnings.push(format!(
                "{}: the run's {n_steps} steps are not a whole number of gravity.interval_steps = {gravity_interval}: the last block ends unclosed (its velocities lack the closing self-gravity kick)",
                self.file
            ));
        }
        if let Some(t_dyn) = advice.dynamical_time {
            let contact_time = advised_dt * crate::granular::soft::advise::STEPS_PER_CONTACT;
            let k = crate::granular::soft::advise::gravity_interval(t_dyn, dt, contact_time);
            if gravity_interval > 2 * k {
                warnings.push(format!(
                    "{}: gravity.interval_steps = {gravity_interval} is more than twice the {k} advised for this dt and material.k_n (rubblepile ssdem advise)",
                    self.file
                ));
            }
        }
        crate::io::scene_file::check_finite_motion(
            particles
                .iter()
                .map(|p| (p.mass, p.radius, p.position, p.velocity, p.spin)),
        )
        .map_err(|(field, message)| self.invalid(field, message))?;
        Ok(SoftScene {
            name: self.file.to_string(),
            source: text.to_string(),
            base_dir: base_dir.map(Path::to_path_buf),
            t_end,
            seed: file.scene.seed,
            dt,
            n_steps,
            every_steps,
            snapshot_steps,
            vtk: file.output.vtk,
            material,
            gravity,
            gravity_interval,
            walls,
            particles,
            advice,
            warnings,
            spinup,
        })
    }
}

/// The advice ([`advise`]) for a set of particles: the largest particle speed, the fall speed `√(2|g|H)` over
/// the particles' extent `H` in a uniform field, and with self-gravity the body's escape speed, spin speed
/// (largest |ω|) and central pressure, the body being the ball about the centre of mass holding every particle.
pub fn scene_advice(particles: &[Particle], gravity: &Gravity, _k_n: f64) -> Advice {
    let r_min = particles.iter().map(|p| p.radius).fold(f64::INFINITY, f64::min);
    let m_min = particles.iter().map(|p| p.mass).fold(f64::INFINITY, f64::min);
    let m_max = particles.iter().map(|p| p.mass).fold(0.0, f64::max);
    let mut speed = particles.iter().map(|p| p.velocity.norm()).fold(0.0, f64::max);
    let g_size = gravity.uniform.norm();
    if g_size > 0.0 {
        let ghat = gravity.uniform / g_size;
        let heights: Vec<f64> = particles.iter().map(|p| p.position.dot(&ghat)).collect();
        let h = heights.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
            - heights.iter().cloned().fold(f64::INFINITY, f64::min);
        speed = speed.max((2.0 * g_size * h.max(r_min)).sqrt());
    }
    let mut body = None;
    let mut spin_period = None;
    if gravity.self_gravity.is_some() && particles.len() > 1 {
        let mass: f64 = particles.iter().map(|p| p.mass).sum();
        let com: Vec3 = particles.iter().map(|p| p.position * p.mass).sum::<Vec3>() / mass;
        let radius = particles
            .iter()
            .map(|p| (p.position - com).norm() + p.radius)
            .fold(0.0, f64::max);
        let density = mass / (4.0 / 3.0 * std::f64::consts::PI * radius.powi(3));
        body = Some((radius, density));
        let w = particles.iter().map(|p| p.spin.norm()).fold(0.0, f64::max);
        if w > 0.0 {
            spin_period = Some(std::f64::consts::TAU / w);
        }
    }
    advise(&AdviceInput {
        r_min,
        m_min,
        m_max,
        speed,
        body,
        spin_period,
        max_overlap: DEFAULT_MAX_OVERLAP,
        g: gravity.g,
    })
}
