//! Random packings by Zhang17's recipe (§2.3.2) on the SSDEM engine ([`crate::granular::soft`]): a random cloud
//! collapses under self-gravity with very inelastic collisions, is shaken vertically and sinusoidally in a rigid
//! spherical container in 1 g, then settles under self-gravity alone; all stages frictionless (μ_S = μ_T = μ_R =
//! β = 0) so voids close without Brazil-nut segregation. The caller carves the result.
//!
//! Parameters and their defaults: [`Recipe`] / [`Recipe::default`] (reported with every aggregate). Each stage
//! picks `k_N` for the overlap fraction `f` it tolerates and a step of contact time / `steps_per_contact`: dynamic
//! load `k_N ≥ (4/3)π ρ r_max v²/f²`, static load `k_N ≥ 4 p r_max/f`. Stages: (1) sequential placement, largest
//! first, to `cloud_packing`; (2) collapse for `collapse_freefall_times` × `t_ff = √(3π/(32 G ρ_cloud))`, `k_N` for
//! escape-speed impacts; (3) shaking in a container filled to `container_fill`, `Γ = A ω²/g = shake_gamma`, then
//! calm periods, then one with the field off; (4) settle in half-free-fall chunks until the kinetic energy is below
//! `settle_kinetic_fraction` of |U| (at most `settle_max_chunks`). Self-gravity is direct below `direct_below`,
//! else an octree (`tree_theta`), every `gravity_interval` steps. Deterministic.

use crate::geometry::walls::soft::{Oscillation, SphereContainer, Wall};
use crate::granular::soft::contact::Material;
use crate::granular::soft::forces::{Gravity, SoftSystem};
use crate::granular::soft::leapfrog::step;
use crate::granular::soft::particle::Particle;
use crate::gravity::SelfGravity;
use crate::io::scene_file::SI_G;
use crate::math::Vec3;
use crate::random::{Generator, point_in_ball};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The recipe's parameters (see the module docs for what each stage does with them).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Recipe {
    /// Volume fraction of the initial random cloud.
    pub cloud_packing: f64,
    /// Restitution ε_n = ε_t of every stage (very inelastic).
    pub restitution: f64,
    /// Collapse duration in free-fall times of the cloud.
    pub collapse_freefall_times: f64,
    /// Largest overlap (fraction of the smaller radius) at escape-speed impacts during the collapse.
    pub collapse_overlap: f64,
    /// Packing fraction the grains would have if they filled the shaking container.
    pub container_fill: f64,
    /// The container also encloses at least this fraction of the collapsed grains; the rest are dropped.
    pub container_enclose: f64,
    /// Uniform field during shaking (m/s², along −z).
    pub shake_g: f64,
    /// Dimensionless shaking acceleration Γ = A ω² / g.
    pub shake_gamma: f64,
    /// Shaking amplitude A in mean grain radii.
    pub shake_amplitude: f64,
    /// Number of shaking periods.
    pub shake_periods: f64,
    /// Periods at rest in the field after shaking.
    pub calm_periods: f64,
    /// Largest overlap (fraction of the smaller radius) tolerated while shaking.
    pub shake_overlap: f64,
    /// Largest overlap (fraction of the smaller radius) in the settled pile.
    pub settle_overlap: f64,
    /// Settle criterion: kinetic energy / |gravitational energy|.
    pub settle_kinetic_fraction: f64,
    /// Most settle chunks (half a free-fall time each).
    pub settle_max_chunks: usize,
    /// Steps per contact duration of the lightest pair.
    pub steps_per_contact: f64,
    /// Self-gravity is direct summation below this many grains.
    pub direct_below: usize,
    /// Octree opening angle above it.
    pub tree_theta: f64,
    /// Self-gravity every this many steps in the collapse and settle stages (r-RESPA,
    /// [`crate::granular::soft::respa`]); at most `steps_per_contact / 5`, so that the gravity kicks pulse faster
    /// than any contact vibration ([`crate::granular::soft::advise::gravity_interval`]). Default 1 (every step;
    /// the committed targets were built so).
    #[serde(default = "one")]
    pub gravity_interval: u64,
}

fn one() -> u64 {
    1
}

impl Default for Recipe {
    fn default() -> Self {
        Recipe {
            cloud_packing: 0.3,
            restitution: 0.1,
            collapse_freefall_times: 1.5,
            collapse_overlap: 0.1,
            container_fill: 0.56,
            container_enclose: 0.97,
            shake_g: 9.81,
            shake_gamma: 1.5,
            shake_amplitude: 0.2,
            shake_periods: 10.0,
            calm_periods: 5.0,
            shake_overlap: 0.1,
            settle_overlap: 0.01,
            settle_kinetic_fraction: 1e-4,
            settle_max_chunks: 10,
            steps_per_contact: 20.0,
            direct_below: 1500,
            tree_theta: 0.8,
            gravity_interval: 1,
        }
    }
}

/// What one stage did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StageLog {
    /// Stage name.
    pub stage: String,
    /// Normal spring constant (N/m).
    pub k_n: f64,
    /// Step (s).
    pub dt: f64,
    /// Steps taken.
    pub steps: u64,
    /// Simulated duration (s).
    pub duration: f64,
    /// Largest overlap seen, as a fraction of the smaller radius.
    pub max_overlap_fraction: f64,
    /// Kinetic energy at the end (J).
    pub final_kinetic_energy: f64,
    /// Stage-specific numbers (container radius, amplitude, frequency …).
    pub notes: String,
}

/// A grain set to insert before the settle stage (the HCP core of RCPC): centres (m, about the heap's centre of
/// mass) and radii (m). Heap grains overlapping them or with centres inside `clear_radius` are removed.
#[derive(Debug, Clone, PartialEq)]
pub struct Insert {
    /// Centres (m).
    pub centres: Vec<Vec3>,
    /// Radii (m).
    pub radii: Vec<f64>,
    /// Heap grains with centres closer than this to the centre are removed (m).
    pub clear_radius: f64,
}

/// The settled heap: centres about its centre of mass (m) and radii (m).
#[derive(Debug, Clone, PartialEq)]
pub struct Heap {
    /// Centres (m).
    pub centres: Vec<Vec3>,
    /// Radii (m).
    pub radii: Vec<f64>,
    /// The stages.
    pub stages: Vec<StageLog>,
}

fn frictionless(k_n: f64, eps: f64) -> Material {
    Material {
        k_n,
        eps_n: eps,
        eps_t: eps,
        mu_s: 0.0,
        mu_t: 0.0,
        mu_r: 0.0,
        beta: 0.0,
    }
}

fn ball_volume(r: f64) -> f64 {
    4.0 / 3.0 * PI * r.powi(3)
}

struct Loads {
    rho: f64,
    r_min: f64,
    r_max: f64,
}

impl Loads {
    /// `k_N` for impacts at `v` (m/s) and static pressure `p` (Pa) at overlap fraction `f`.
    fn k_n(&self, v: f64, p: f64, f: f64) -> f64 {
        (4.0 / 3.0 * PI * self.rho * self.r_max * v * v / (f * f)).max(4.0 * p * self.r_max / f)
    }

    /// The step for `k_n`: the lightest pair's contact time over `steps_per_contact`.
    fn dt(&self, k_n: f64, steps_per_contact: f64) -> f64 {
        let mu = 0.5 * self.rho * ball_volume(self.r_min);
        PI * (mu / k_n).sqrt() / steps_per_contact
    }
}

/// Random sequential placement in a ball of radius `cloud_radius` (m), largest grains first; returns centres
/// in the order of `radii`. Fails if a grain finds no room in 10⁵ tries.
fn random_cloud(radii: &[f64], cloud_radius: f64, rng: &mut Generator) -> Option<Vec<Vec3>> {
    let mut order: Vec<usize> = (0..radii.len()).collect();
    order.sort_by(|&i, &j| radii[j].total_cmp(&radii[i]).then(i.cmp(&j)));
    let mut placed: Vec<(Vec3, f64)> = Vec::with_capacity(radii.len());
    let mut centres = vec![Vec3::zeros(); radii.len()];
    for i in order {
        let r = radii[i];
        let mut tries = 0;
        let p = loop {
            let p = point_in_ball(rng, cloud_radius - r);
            if placed.iter().all(|(q, s)| (p - q).norm_squared() > (r + s) * (r + s)) {
                break p;
            }
            tries += 1;
            if tries > 100_000 {
                return None;
            }
        };
        placed.push((p, r));
        centres[i] = p;
    }
    Some(centres)
}

/// Grains at rest with these centres (m), radii (m) and grain density `rho` (kg/m³).
pub(crate) fn particles(centres: &[Vec3], radii: &[f64], rho: f64) -> Vec<Particle> {
    centres
        .iter()
        .zip(radii)
        .map(|(&position, &radius)| Particle {
            mass: rho * ball_volume(radius),
            radius,
            position,
            velocity: Vec3::zeros(),
            spin: Vec3::zeros(),
        })
        .collect()
}

fn at_rest(ps: &mut [Particle]) {
    for p in ps.iter_mut() {
        (p.velocity, p.spin) = (Vec3::zeros(), Vec3::zeros());
    }
}

fn recentre(ps: &mut [Particle]) {
    let m: f64 = ps.iter().map(|p| p.mass).sum();
    let c: Vec3 = ps.iter().map(|p| p.position * p.mass).sum::<Vec3>() / m;
    let v: Vec3 = ps.iter().map(|p| p.velocity * p.mass).sum::<Vec3>() / m;
    for p in ps.iter_mut() {
        p.position -= c;
        p.velocity -= v;
    }
}

/// Where a build stands: the stage's name, the steps done and the steps the stage will take (for progress
/// displays; the settle stage reports each chunk as its own run of steps).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BuildProgress<'a> {
    /// Stage name (collapse, shake, calm, unload, settle).
    pub stage: &'a str,
    /// Steps done in this stage (or settle chunk).
    pub step: u64,
    /// Steps of this stage (or settle chunk).
    pub steps: u64,
}

/// Steps between two progress reports.
const PROGRESS_EVERY: u64 = 500;

/// Runs `steps` leapfrog steps of `dt` from t = 0; returns the largest overlap fraction seen. Stages with
/// self-gravity every `k` steps pass whole blocks ([`whole_blocks`]), so that each ends with its closing kick.
fn run(sys: &mut SoftSystem, dt: f64, steps: u64, stage: &str, progress: &mut dyn FnMut(BuildProgress<'_>)) -> f64 {
    debug_assert!(steps.is_multiple_of(sys.gravity_interval.max(1)));
    sys.compute_forces(0.0, 0.0);
    let mut worst = sys.stats.max_overlap_fraction;
    for k in 0..steps {
        if k % PROGRESS_EVERY == 0 {
            progress(BuildProgress { stage, step: k, steps });
        }
        step(sys, k as f64 * dt, dt);
        worst = worst.max(sys.stats.max_overlap_fraction);
    }
    progress(BuildProgress {
        stage,
        step: steps,
        steps,
    });
    worst
}

/// `steps` rounded up to a whole number of self-gravity blocks of `k` steps.
fn whole_blocks(steps: u64, k: u64) -> u64 {
    steps.div_ceil(k.max(1)) * k.max(1)
}

/// Runs one stage of `steps` steps of `dt` ([`run`]) and logs it.
fn stage(
    sys: &mut SoftSystem,
    dt: f64,
    steps: u64,
    name: &str,
    notes: String,
    progress: &mut dyn FnMut(BuildProgress<'_>),
) -> StageLog {
    let worst = run(sys, dt, steps, name, progress);
    log(name, sys, dt, steps, worst, notes)
}

fn log(stage: &str, sys: &SoftSystem, dt: f64, steps: u64, worst: f64, notes: String) -> StageLog {
    StageLog {
        stage: stage.into(),
        k_n: sys.material.k_n,
        dt,
        steps,
        duration: steps as f64 * dt,
        max_overlap_fraction: worst,
        final_kinetic_energy: sys.kinetic_energy(),
        notes,
    }
}

/// Builds a settled self-gravitating heap of grains with these `radii` (m) and grain density `rho` (kg/m³) by
/// the [`Recipe`], seeded by `rng`; `insert` (if any) replaces the heap's centre before the settle stage.
/// `progress` hears where the build stands every few hundred steps. `None` if the random cloud could not be
/// placed.
pub fn random_heap(
    radii: &[f64],
    rho: f64,
    recipe: &Recipe,
    rng: &mut Generator,
    insert: Option<&Insert>,
    progress: &mut dyn FnMut(BuildProgress<'_>),
) -> Option<Heap> {
    let n = radii.len();
    let v_grains: f64 = radii.iter().map(|&r| ball_volume(r)).sum();
    let r_max = radii.iter().cloned().fold(0.0, f64::max);
    let r_mean = radii.iter().sum::<f64>() / n as f64;
    let loads = Loads {
        rho,
        r_min: radii.iter().cloned().fold(f64::INFINITY, f64::min),
        r_max,
    };
    let gravity_mode = |n: usize| {
        if n < recipe.direct_below {
            SelfGravity::Direct
        } else {
            SelfGravity::Tree {
                theta: recipe.tree_theta,
            }
        }
    };
    let mut stages = Vec::new();

    // 1–2. cloud and collapse
    let cloud_radius = (v_grains / recipe.cloud_packing / ball_volume(1.0)).cbrt();
    let centres = random_cloud(radii, cloud_radius, rng)?;
    let packed_radius = (v_grains / 0.6 / ball_volume(1.0)).cbrt();
    let rho_packed = 0.6 * rho;
    let v_esc = packed_radius * (8.0 * PI * SI_G * rho_packed / 3.0).sqrt();
    let p_c = 2.0 * PI / 3.0 * SI_G * rho_packed * rho_packed * packed_radius * packed_radius;
    let k_collapse = loads.k_n(v_esc, p_c, recipe.collapse_overlap);
    let dt = loads.dt(k_collapse, recipe.steps_per_contact);
    let t_ff = (3.0 * PI / (32.0 * SI_G * recipe.cloud_packing * rho)).sqrt();
    let steps = (recipe.collapse_freefall_times * t_ff / dt).ceil() as u64;
    let self_gravity = Gravity {
        uniform: Vec3::zeros(),
        self_gravity: Some(gravity_mode(n)),
        g: SI_G,
    };
    let mut sys = SoftSystem::new(
        particles(&centres, radii, rho),
        Vec::new(),
        frictionless(k_collapse, recipe.restitution),
        self_gravity,
    );
    sys.gravity_interval = recipe.gravity_interval.max(1);
    let steps = whole_blocks(steps, sys.gravity_interval);
    let notes = format!("cloud radius {cloud_radius:.4e} m, t_ff {t_ff:.4e} s");
    stages.push(stage(&mut sys, dt, steps, "collapse", notes, progress));

    // 3. shaking in a spherical container under a uniform field
    let mut ps = sys.particles;
    recentre(&mut ps);
    let mut reach: Vec<f64> = ps.iter().map(|p| p.position.norm() + p.radius).collect();
    reach.sort_by(f64::total_cmp);
    let enclosing = reach[((recipe.container_enclose * n as f64).ceil() as usize).clamp(1, n) - 1];
    let container = (v_grains / recipe.container_fill / ball_volume(1.0))
        .cbrt()
        .max(enclosing);
    let before = ps.len();
    ps.retain(|p| p.position.norm() + p.radius <= container);
    let dropped = before - ps.len();
    at_rest(&mut ps);
    let amplitude = recipe.shake_amplitude * r_mean;
    let omega = (recipe.shake_gamma * recipe.shake_g / amplitude).sqrt();
    let period = std::f64::consts::TAU / omega;
    let p_field = rho * recipe.container_fill * recipe.shake_g * 2.0 * container;
    // grains thrown into the empty cap above the heap (a tenth of the container's radius) land at up to
    // `Aω + √(2 g 0.1 R_c)`
    let v_shake = amplitude * omega + (0.2 * recipe.shake_g * container).sqrt();
    let k_shake = loads.k_n(v_shake, p_field, recipe.shake_overlap);
    let dt = loads.dt(k_shake, recipe.steps_per_contact);
    let field = Gravity {
        uniform: Vec3::new(0.0, 0.0, -recipe.shake_g),
        self_gravity: None,
        g: SI_G,
    };
    let wall = |osc: Option<Oscillation>| {
        Wall::Sphere(SphereContainer {
            centre: Vec3::zeros(),
            radius: container,
            oscillation: osc,
        })
    };
    // ω = 2π (1/period), the factors in the order the shaking has always been computed in (its bits unchanged).
    let osc = Oscillation {
        amplitude,
        omega: std::f64::consts::TAU * (1.0 / period),
        phase: 0.0,
        direction: Vec3::z(),
    };
    let material = frictionless(k_shake, recipe.restitution);
    let notes = format!(
        "container radius {container:.4e} m ({dropped} collapse outliers dropped), amplitude {amplitude:.4e} m, frequency {:.4e} Hz, g {} m/s²",
        1.0 / period,
        recipe.shake_g
    );
    let mut sys = SoftSystem::new(ps, vec![wall(Some(osc))], material, field);
    let steps = (recipe.shake_periods * period / dt).ceil() as u64;
    stages.push(stage(&mut sys, dt, steps, "shake", notes, progress));
    let mut sys = SoftSystem::new(sys.particles, vec![wall(None)], material, field);
    let steps = (recipe.calm_periods * period / dt).ceil() as u64;
    let notes = "field on, container at rest".into();
    stages.push(stage(&mut sys, dt, steps, "calm", notes, progress));
    let no_field = Gravity {
        uniform: Vec3::zeros(),
        ..field
    };
    let mut sys = SoftSystem::new(sys.particles, vec![wall(None)], material, no_field);
    let steps = (period / dt).ceil() as u64;
    let notes = "field off, container at rest".into();
    stages.push(stage(&mut sys, dt, steps, "unload", notes, progress));

    // optional insert (the HCP core of RCPC)
    let mut ps = sys.particles;
    recentre(&mut ps);
    if let Some(ins) = insert {
        let keep = |p: &Particle| {
            p.position.norm() >= ins.clear_radius
                && ins
                    .centres
                    .iter()
                    .zip(&ins.radii)
                    .all(|(c, r)| (p.position - c).norm() >= p.radius + r)
        };
        ps.retain(keep);
        ps.extend(particles(&ins.centres, &ins.radii, rho));
    }

    // 4. settle under self-gravity alone, from rest
    let n = ps.len();
    at_rest(&mut ps);
    let k_settle = 10.0 * loads.k_n(0.0, p_c, recipe.settle_overlap);
    let dt = loads.dt(k_settle, recipe.steps_per_contact);
    let t_ff_pile = (3.0 * PI / (32.0 * SI_G * rho_packed)).sqrt();
    let chunk = (0.5 * t_ff_pile / dt).ceil() as u64;
    let gravity = Gravity {
        self_gravity: Some(gravity_mode(n)),
        ..self_gravity
    };
    let mut sys = SoftSystem::new(ps, Vec::new(), frictionless(k_settle, recipe.restitution), gravity);
    sys.gravity_interval = recipe.gravity_interval.max(1);
    let chunk = whole_blocks(chunk, sys.gravity_interval);
    let (mut steps, mut worst, mut last_worst) = (0, 0.0f64, 0.0);
    for _ in 0..recipe.settle_max_chunks {
        last_worst = run(&mut sys, dt, chunk, "settle", progress);
        worst = worst.max(last_worst);
        steps += chunk;
        if sys.kinetic_energy() < recipe.settle_kinetic_fraction * sys.stats.gravitational_energy.abs() {
            break;
        }
    }
    let notes = format!(
        "until kinetic/|gravitational| < {:e}: {:.3e}; last chunk's largest overlap {last_worst:.3e}",
        recipe.settle_kinetic_fraction,
        sys.kinetic_energy() / sys.stats.gravitational_energy.abs()
    );
    stages.push(log("settle", &sys, dt, steps, worst, notes));
    let mut ps = sys.particles;
    recentre(&mut ps);
    Some(Heap {
        centres: ps.iter().map(|p| p.position).collect(),
        radii: ps.iter().map(|p| p.radius).collect(),
        stages,
    })
}
