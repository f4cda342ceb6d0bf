//! Rubble-pile targets as in Roig03 §3 and Table 1. (1) Sizes: equivalent radii from `N(>R) ∝ R^−2.5` on
//! `[R_smallest, R_largest]`, both extremes fixed, `N − 2` drawn (seeded) until the total mass is within
//! `mass_tolerance` (Table 1: 1.0e19 kg ± 0.5 %). (2) `B/A = 0.7`, `C/A = 0.5`, 3000 kg m⁻³, `A = R / 0.35^{1/3}`.
//! (3) Largest at the centre, the others (largest first) at random points and attitudes in a sphere, none touching
//! (Perram–Wertheim); no room grows the sphere 3 % and restarts. (4) Rigid rotation `Ω ẑ` (period `T`), then
//! relaxed with gravity, contact and dissipation until the kinetic energy relative to the best-fit rigid rotation is
//! below `rigidity` (1e-4) at two successive checks after three free-fall times; the contraction spins it up, so it
//! is reset to `Ω` and relaxed again until within 2 % of `T` (≤ 4 rounds). (5) κ from Eq. 14 with β = 10,
//! v = 5 km/s over the fragments (Table 2's projectiles lie within their sizes, so the same κ serves the impacts).

use crate::ellipsoid::body::{Body, Ellipsoid};
use crate::ellipsoid::calibration::calibrate_kappa_read;
use crate::ellipsoid::equations::{EllipsoidSystem, G_SI, ModelConfig, Physics};
use crate::ellipsoid::quaternion::rotation_matrix;
use crate::ellipsoid::rigid_rotation::{RigidFit, fit_rigid_rotation};
use crate::geometry::ellipsoid_overlap::are_apart;
use crate::impact::target_checkpoint::{BuildCheckpoint, RoundState};
use crate::impact::target_spec::is_default;
pub use crate::impact::target_spec::{TargetError, TargetSpec};
use crate::integrate::{Method, Tolerances, make_integrator};
use crate::math::{Mat3, Vec3};
use crate::random::{Generator, generator, point_in_ball, random_quaternion, uniform};
use std::f64::consts::PI;

/// `(ABC)^{1/3} / A` for the axis ratios 1 : 0.7 : 0.5.
fn equivalent_to_major(b_over_a: f64, c_over_a: f64) -> f64 {
    (b_over_a * c_over_a).cbrt()
}

/// The Table 1 quantities of a target, plus how it was made (written as `NAME.json`).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TargetReport {
    /// Number of fragments.
    pub fragments: usize,
    /// Total mass (kg).
    pub total_mass_kg: f64,
    /// Radius of the sphere with the fragments' total volume (m).
    pub effective_radius_m: f64,
    /// Mean of the three half-extents of the pile along x, y, z (m).
    pub apparent_radius_m: f64,
    /// Total mass / total fragment volume (kg m⁻³).
    pub effective_density_kg_m3: f64,
    /// Total mass / volume of the sphere of the apparent radius (kg m⁻³).
    pub apparent_density_kg_m3: f64,
    /// `1 − apparent density / effective density`.
    pub porosity: f64,
    /// Semi-major axis A of the largest fragment (m).
    pub largest_major_radius_m: f64,
    /// Equivalent radius of the largest fragment (m).
    pub largest_equivalent_radius_m: f64,
    /// Semi-major axis A of the smallest fragment (m).
    pub smallest_major_radius_m: f64,
    /// Equivalent radius of the smallest fragment (m).
    pub smallest_equivalent_radius_m: f64,
    /// Spin period of the best-fit rigid rotation at the end (hours).
    pub spin_period_hours: f64,
    /// Angle between the final spin axis and z (degrees).
    pub spin_axis_tilt_deg: f64,
    /// `K_rel / K` at the end.
    pub non_rigid_fraction: f64,
    /// Simulated relaxation time, all rounds (s).
    pub relaxation_time_s: f64,
    /// Relaxation rounds (each ends rigid; later rounds reset the spin to the requested period).
    pub relaxation_rounds: usize,
    /// Spin period of the first round's rigid rotation (hours): the requested period, or longer when that
    /// spin would unbind the placement sphere's equator (see [`first_round_spin`]). Absent (0) in reports
    /// written before it was recorded.
    #[serde(default)]
    pub first_round_period_hours: f64,
    /// κ (Roig03 Eq. 14).
    pub kappa: f64,
    /// Largest relative energy residual `|H − H0 − 2∫F| / scale` of the relaxation runs.
    pub relaxation_energy_error: f64,
    /// Radius of the placement sphere (m).
    pub placement_radius_m: f64,
    /// Size draws tried before the mass matched.
    pub size_draws: usize,
    /// Fragments removed as detached from the pile ([`TargetSpec::drop_detached`]); absent (0) otherwise.
    #[serde(default, skip_serializing_if = "is_default")]
    pub detached_fragments: usize,
    /// Their mass (kg), not counted in `total_mass_kg`.
    #[serde(default, skip_serializing_if = "is_default")]
    pub detached_mass_kg: f64,
    /// The inputs.
    pub spec: TargetSpec,
}

/// Relative enlargement of the semi-axes in the contact test of [`drop_detached`].
pub const DETACHED_MARGIN: f64 = 0.1;

/// Removes from `bodies` every fragment outside their most massive clump (bodies in contact, semi-axes enlarged
/// by [`DETACHED_MARGIN`]; [`crate::ellipsoid::clumps`]) and the same entries from `kept` (each body's index in
/// the placement). The collapse of a large placement sphere throws a few small fragments onto wide orbits; the
/// next round's rigid rotation would give those far out more than the local escape speed, and their growing
/// distance would keep `K_rel/K` rising forever (`analysis/n2000/REPORT.md`). Returns how many were removed.
pub fn drop_detached(bodies: &mut Vec<Body>, kept: &mut Vec<usize>) -> usize {
    let clumps =
        crate::ellipsoid::clumps::find_clumps(bodies, crate::ellipsoid::clumps::Linking::ScaledAxes(DETACHED_MARGIN));
    let mass = |c: &Vec<usize>| c.iter().map(|&i| bodies[i].shape.mass).sum::<f64>();
    let Some(main) = clumps.iter().max_by(|a, b| mass(a).total_cmp(&mass(b))) else {
        return 0;
    };
    let removed = bodies.len() - main.len();
    *bodies = main.iter().map(|&i| bodies[i].clone()).collect();
    *kept = main.iter().map(|&i| kept[i]).collect();
    removed
}

/// Equivalent radii, largest first: extremes fixed, the rest drawn from the truncated power law, redrawn
/// until the total mass is within tolerance. Returns the radii and the number of draws.
pub fn draw_sizes(spec: &TargetSpec, rng: &mut Generator) -> Result<(Vec<f64>, usize), TargetError> {
    let n = spec.fragments;
    let (a, b) = (spec.r_largest.powf(-spec.slope), spec.r_smallest.powf(-spec.slope));
    let mass_of = |r: &[f64]| r.iter().map(|r| spec.density * 4.0 / 3.0 * PI * r.powi(3)).sum::<f64>();
    for draw in 1..=100_000 {
        let mut radii = vec![spec.r_largest, spec.r_smallest];
        radii.extend((0..n - 2).map(|_| (a + uniform(rng) * (b - a)).powf(-1.0 / spec.slope)));
        if (mass_of(&radii) / spec.total_mass - 1.0).abs() <= spec.mass_tolerance {
            radii.sort_by(|x, y| y.total_cmp(x));
            return Ok((radii, draw));
        }
    }
    Err(TargetError::Invalid(format!(
        "no size draw reaches total mass {:e} kg within {} (check --fragments, radii and mass)",
        spec.total_mass, spec.mass_tolerance
    )))
}

/// World shape matrix `Σ = Rᵀ diag(A², B², C²) R`.
fn shape_matrix(b: &Body) -> Mat3 {
    let r = rotation_matrix(&b.quaternion);
    r.transpose() * Mat3::from_diagonal(&b.shape.axes.component_mul(&b.shape.axes)) * r
}

/// Places fragments of the given equivalent radii (largest first; the largest at the origin) in the smallest
/// sphere, growing by 3 %, where random placement succeeds. Returns the bodies (at rest) and the sphere radius.
pub fn place_fragments(spec: &TargetSpec, radii: &[f64], rng: &mut Generator) -> (Vec<Body>, f64) {
    let k = equivalent_to_major(spec.axis_ratios[0], spec.axis_ratios[1]);
    let shapes: Vec<Ellipsoid> = radii
        .iter()
        .map(|r| {
            let a = r / k;
            Ellipsoid {
                axes: Vec3::new(a, a * spec.axis_ratios[0], a * spec.axis_ratios[1]),
                mass: spec.density * 4.0 / 3.0 * PI * r.powi(3),
            }
        })
        .collect();
    let volume: f64 = shapes.iter().map(|s| s.volume()).sum();
    // Start at a packing fraction of 0.4 of the sphere (random loose packing of ellipsoids is ~0.5–0.6).
    let mut radius = (volume / 0.4 * 3.0 / (4.0 * PI)).cbrt().max(shapes[0].axes.x);
    'attempt: loop {
        let mut bodies: Vec<Body> = Vec::with_capacity(shapes.len());
        let mut sigmas: Vec<Mat3> = Vec::with_capacity(shapes.len());
        for (i, shape) in shapes.iter().enumerate() {
            let mut placed = false;
            for _ in 0..4000 {
                let position = if i == 0 {
                    Vec3::zeros()
                } else {
                    point_in_ball(rng, radius - shape.axes.x)
                };
                let body = Body {
                    shape: *shape,
                    position,
                    velocity: Vec3::zeros(),
                    quaternion: random_quaternion(rng),
                    spin_body: Vec3::zeros(),
                };
                let sigma = shape_matrix(&body);
                let free = bodies.iter().zip(&sigmas).all(|(other, s)| {
                    let d = position - other.position;
                    let dist = d.norm();
                    if dist > shape.axes.x + other.shape.axes.x {
                        true
                    } else if dist < shape.axes.z + other.shape.axes.z {
                        false
                    } else {
                        are_apart(&d, &sigma, s)
                    }
                });
                if free {
                    bodies.push(body);
                    sigmas.push(sigma);
                    placed = true;
                    break;
                }
            }
            if !placed {
                radius *= 1.03;
                continue 'attempt;
            }
        }
        return (bodies, radius);
    }
}

/// Centre-of-mass position (m) and velocity (m/s) of `bodies`.
pub fn centre_of_mass(bodies: &[Body]) -> (Vec3, Vec3) {
    let mass: f64 = bodies.iter().map(|b| b.shape.mass).sum();
    let r = bodies.iter().map(|b| b.position * b.shape.mass).sum::<Vec3>() / mass;
    let v = bodies.iter().map(|b| b.velocity * b.shape.mass).sum::<Vec3>() / mass;
    (r, v)
}

/// Puts every body into the rigid rotation `ω` about the centre of mass (world frame, rad/s), with the
/// centre of mass at rest at the origin.
pub fn set_rigid_rotation(bodies: &mut [Body], omega: &Vec3) {
    let (com, _) = centre_of_mass(bodies);
    for b in bodies.iter_mut() {
        b.position -= com;
        b.velocity = omega.cross(&b.position);
        b.spin_body = rotation_matrix(&b.quaternion) * omega;
    }
}

/// Shifts positions and velocities to the centre-of-mass frame.
pub fn to_centre_of_mass_frame(bodies: &mut [Body]) {
    let (com, vcm) = centre_of_mass(bodies);
    for b in bodies.iter_mut() {
        b.position -= com;
        b.velocity -= vcm;
    }
}

/// Progress of a relaxation, called after every check: (round, simulated time s, K_rel/K, period h).
pub type RelaxProgress<'a> = dyn FnMut(usize, f64, f64, f64) + 'a;

/// The fixed settings of the relaxation rounds.
struct Relaxation<'a> {
    spec: &'a TargetSpec,
    model: ModelConfig,
    physics: Physics,
    /// Simulated time between rigidity checks (s).
    check_every: f64,
}

/// One relaxation round: evolves until rigid (two successive checks) after at least `t_min`, from the round's
/// start or from `resume`. After every check `save` is given the round's state (for a checkpoint).
/// Returns the bodies, the simulated time and the largest energy residual.
fn relax_round(
    bodies: &[Body],
    relaxation: &Relaxation<'_>,
    t_min: f64,
    round: usize,
    resume: Option<RoundState>,
    progress: &mut RelaxProgress<'_>,
    save: &mut dyn FnMut(RoundState),
) -> Result<(Vec<Body>, f64, f64), TargetError> {
    let (spec, check_every) = (relaxation.spec, relaxation.check_every);
    let system = EllipsoidSystem::new(bodies, relaxation.model, relaxation.physics);
    let mut y = system.initial_state();
    let mut integrator = make_integrator(
        Method::BulirschStoer,
        Tolerances::scale_free(spec.rtol, spec.rtol, &system),
        None,
    )?;
    let d0 = system.diagnostics(&y);
    let mut t = 0.0;
    let mut rigid_checks = 0;
    let mut energy_error: f64 = 0.0;
    if let Some(r) = resume {
        if r.y.len() != y.len() {
            return Err(TargetError::Invalid(format!(
                "checkpoint: state of {} values, expected {}",
                r.y.len(),
                y.len()
            )));
        }
        integrator.restore_state(&r.integrator)?;
        (t, y, rigid_checks, energy_error) = (r.t, r.y, r.rigid_checks, r.energy_error);
    }
    loop {
        let target = t + check_every;
        integrator.advance(&system, &mut t, &mut y, target)?;
        let d = system.diagnostics(&y);
        energy_error = energy_error.max((d.energy() - d0.energy() - d.dissipated).abs() / d0.energy_scale);
        let now = system.bodies_at(t, &y);
        let fit = fit_rigid_rotation(&now, system.principal_moments());
        progress(round, t, fit.non_rigid_fraction(), fit.period() / 3600.0);
        if t >= t_min && fit.non_rigid_fraction() < spec.rigidity {
            rigid_checks += 1;
            if rigid_checks >= 2 {
                return Ok((now, t, energy_error));
            }
        } else {
            rigid_checks = 0;
        }
        if t >= spec.max_relax_time {
            return Err(TargetError::NotRigid {
                time: t,
                fraction: fit.non_rigid_fraction(),
            });
        }
        save(RoundState {
            t,
            y: y.clone(),
            integrator: integrator.save_state(),
            rigid_checks,
            energy_error,
        });
    }
}

/// The rigid rotation the first relaxation round starts from: `ω` itself, unless `ω` would unbind the equator
/// of the placement sphere (`ω² R_p³ > G M`: there the centrifugal acceleration exceeds the pile's gravity, and
/// the outer fragments fly off during the collapse instead of settling). Then the first round spins at the
/// rate where the centrifugal acceleration on that equator is half of gravity, `√(G M / (2 R_p³))`, and the
/// later rounds reset the spin to `ω` as usual: loose placements of many small fragments need it (the N = 2000
/// pile, `analysis/n2000/REPORT.md`); Table 1's targets keep `ω`.
pub fn first_round_spin(omega: &Vec3, total_mass: f64, placement_radius: f64) -> Vec3 {
    let gm = G_SI * total_mass;
    let r3 = placement_radius.powi(3);
    if omega.norm_squared() * r3 > gm {
        omega.normalize() * (0.5 * gm / r3).sqrt()
    } else {
        *omega
    }
}

/// Table 1 quantities of a pile.
fn describe(bodies: &[Body], fit: &RigidFit) -> (f64, f64, f64) {
    let volume: f64 = bodies.iter().map(|b| b.shape.volume()).sum();
    let effective_radius = (volume * 3.0 / (4.0 * PI)).cbrt();
    let mut half_extent = Vec3::zeros();
    for axis in 0..3 {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for b in bodies {
            // half-width of an ellipsoid along unit vector u is sqrt(uᵀ Σ u)
            let w = shape_matrix(b)[(axis, axis)].sqrt();
            lo = lo.min(b.position[axis] - fit.centre_of_mass[axis] - w);
            hi = hi.max(b.position[axis] - fit.centre_of_mass[axis] + w);
        }
        half_extent[axis] = 0.5 * (hi - lo);
    }
    (volume, effective_radius, half_extent.mean())
}

/// Builds, places, spins and relaxes a target. `progress` is called after every relaxation check.
pub fn build_target(
    spec: &TargetSpec,
    progress: &mut RelaxProgress<'_>,
) -> Result<(Vec<Body>, TargetReport), TargetError> {
    build_target_resumable(spec, None, progress, &mut |_| {})
}

/// [`build_target`] that continues from `resume` (a checkpoint of the same `spec`) when given, and hands a
/// [`BuildCheckpoint`] to `checkpoint` after every relaxation check that does not end the build. A resumed
/// build gives the same bits as one that was never stopped.
pub fn build_target_resumable(
    spec: &TargetSpec,
    resume: Option<BuildCheckpoint>,
    progress: &mut RelaxProgress<'_>,
    checkpoint: &mut dyn FnMut(&BuildCheckpoint),
) -> Result<(Vec<Body>, TargetReport), TargetError> {
    validate(spec)?;
    if let Some(c) = &resume {
        c.check(spec)?;
    }
    let mut rng = generator(spec.seed);
    let (radii, size_draws) = draw_sizes(spec, &mut rng)?;
    let (mut bodies, placement_radius) = place_fragments(spec, &radii, &mut rng);
    let small = bodies.last().unwrap().shape;
    let large = bodies[0].shape;
    let kappa = calibrate_kappa_read(
        spec.kappa_reading,
        spec.calibrate[0],
        spec.calibrate[1],
        (small.equivalent_radius(), small.mass),
        (large.equivalent_radius(), large.mass),
        G_SI,
    )?;
    let model = ModelConfig::gaussian_si(kappa);
    let physics = Physics::impact(spec.f0);
    let omega = Vec3::new(0.0, 0.0, 2.0 * PI / (spec.period_hours * 3600.0));
    let total_mass: f64 = bodies.iter().map(|b| b.shape.mass).sum();
    // free-fall time of the placement sphere's mean density
    let density = total_mass / (4.0 / 3.0 * PI * placement_radius.powi(3));
    let t_ff = (3.0 * PI / (32.0 * G_SI * density)).sqrt();
    let (mut time, mut energy_error, mut rounds) = (0.0, 0.0_f64, 0);
    let omega_first = first_round_spin(&omega, total_mass, placement_radius);
    set_rigid_rotation(&mut bodies, &omega_first);
    let mut resume_round = None;
    // each body's index in the placement (fewer than N once detached fragments are dropped)
    let mut kept: Vec<usize> = (0..bodies.len()).collect();
    let placed_masses: Vec<f64> = bodies.iter().map(|b| b.shape.mass).collect();
    if let Some(c) = resume {
        kept = c.kept.clone().unwrap_or(kept);
        bodies = c.round_start_bodies(&bodies);
        (rounds, time, energy_error) = (c.round - 1, c.time_before, c.energy_error_before);
        resume_round = Some(c.state);
    }
    loop {
        rounds += 1;
        let t_min = if rounds == 1 { 3.0 * t_ff } else { t_ff };
        let relaxation = Relaxation {
            spec,
            model,
            physics,
            check_every: 0.25 * t_ff,
        };
        let mut save = |state: RoundState| {
            checkpoint(&BuildCheckpoint::new(
                spec,
                rounds,
                &bodies,
                &kept,
                time,
                energy_error,
                state,
            ));
        };
        let (relaxed, t, e) = relax_round(
            &bodies,
            &relaxation,
            t_min,
            rounds,
            resume_round.take(),
            progress,
            &mut save,
        )?;
        time += t;
        energy_error = energy_error.max(e);
        bodies = relaxed;
        to_centre_of_mass_frame(&mut bodies);
        if spec.drop_detached && drop_detached(&mut bodies, &mut kept) > 0 {
            to_centre_of_mass_frame(&mut bodies);
        }
        let moments: Vec<Vec3> = bodies.iter().map(|b| b.shape.principal_moments(kappa)).collect();
        let fit = fit_rigid_rotation(&bodies, &moments);
        let period_ratio = fit.period() / (spec.period_hours * 3600.0);
        if (period_ratio - 1.0).abs() <= 0.02 || rounds >= 4 {
            break;
        }
        set_rigid_rotation(&mut bodies, &omega);
    }
    let moments: Vec<Vec3> = bodies.iter().map(|b| b.shape.principal_moments(kappa)).collect();
    let fit = fit_rigid_rotation(&bodies, &moments);
    let (volume, effective_radius, apparent_radius) = describe(&bodies, &fit);
    let detached_fragments = placed_masses.len() - kept.len();
    let (total_mass, detached_mass_kg) = if detached_fragments == 0 {
        (total_mass, 0.0)
    } else {
        let kept_mass: f64 = bodies.iter().map(|b| b.shape.mass).sum();
        (kept_mass, placed_masses.iter().sum::<f64>() - kept_mass)
    };
    let apparent_density = total_mass / (4.0 / 3.0 * PI * apparent_radius.powi(3));
    let effective_density = total_mass / volume;
    let report = TargetReport {
        fragments: bodies.len(),
        total_mass_kg: total_mass,
        effective_radius_m: effective_radius,
        apparent_radius_m: apparent_radius,
        effective_density_kg_m3: effective_density,
        apparent_density_kg_m3: apparent_density,
        porosity: 1.0 - apparent_density / effective_density,
        largest_major_radius_m: large.axes.x,
        largest_equivalent_radius_m: large.equivalent_radius(),
        smallest_major_radius_m: small.axes.x,
        smallest_equivalent_radius_m: small.equivalent_radius(),
        spin_period_hours: fit.period() / 3600.0,
        spin_axis_tilt_deg: fit.omega.angle(&Vec3::z()).to_degrees(),
        non_rigid_fraction: fit.non_rigid_fraction(),
        relaxation_time_s: time,
        relaxation_rounds: rounds,
        first_round_period_hours: 2.0 * PI / omega_first.norm() / 3600.0,
        kappa,
        relaxation_energy_error: energy_error,
        placement_radius_m: placement_radius,
        size_draws,
        detached_fragments,
        detached_mass_kg,
        spec: spec.clone(),
    };
    Ok((bodies, report))
}

fn validate(spec: &TargetSpec) -> Result<(), TargetError> {
    let bad = |field: &str, need: &str, got: String| Err(TargetError::Invalid(format!("{field}: {need}, got {got}")));
    if spec.fragments < 2 {
        return bad("fragments", "need at least 2", spec.fragments.to_string());
    }
    if !(spec.period_hours.is_finite() && spec.period_hours > 0.0) {
        return bad("period-h", "must be > 0 and finite", spec.period_hours.to_string());
    }
    if !(spec.r_smallest > 0.0 && spec.r_smallest <= spec.r_largest && spec.r_largest.is_finite()) {
        return bad(
            "radii",
            "need 0 < smallest <= largest equivalent radius (m)",
            format!("{} and {}", spec.r_smallest, spec.r_largest),
        );
    }
    for (field, v) in [
        ("total-mass-kg", spec.total_mass),
        ("density", spec.density),
        ("f0", spec.f0),
        ("rtol", spec.rtol),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return bad(field, "must be > 0 and finite", v.to_string());
        }
    }
    Ok(())
}
