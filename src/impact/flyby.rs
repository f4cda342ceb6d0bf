//! A tidal flyby of a rubble pile past a planet (the experiment of Richardson, Bottke & Love 1998, Icarus
//! 134, 47–76) as a library call: the `[physics.flyby]` term ([`crate::ellipsoid::tide`]) on a target pile.
//!
//! [`prepare_flyby`] reads a target bodies file (e.g. from `rubblepile target build`), optionally rescales it to a
//! given radius (lengths × s, masses × s³, velocities × s: at the same density the dynamics is similar, with the
//! same κ, when F0 scales as s⁻²) and sets a rigid spin, moves it to its centre-of-mass frame, and writes into the
//! run directory `initial_bodies.csv`, `flyby.json` ([`FlybySetup`]) and `scene.toml` (gravity, contact,
//! dissipation, the flyby; Bulirsch–Stoer). The run starts with the planet at `start_q · q` on the way in and ends
//! at the same distance on the way out. The same run again: `rubblepile run DIR/scene.toml --out OTHER`.
//!
//! **A fair flyby**: a pile that was rescaled or re-spun is first settled without tide
//! ([`crate::impact::settle`]; the pile as prepared is kept as `prepared_bodies.csv`, the settled one is
//! `initial_bodies.csv`, the run's "before"), optionally put into principal-axis rotation about its largest moment
//! (`--settle-to-principal`), and a control run of the same pile over the same time without the planet (mass 0)
//! goes into `DIR/control/` unless `--no-control`: the tide's effect is the run minus the control
//! (reported by the flyby analysis one layer up).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::driver::{RunOptions, prepare_output_dir};
use crate::ellipsoid::body::Body;
use crate::ellipsoid::equations::G_SI;
use crate::ellipsoid::output::write_snapshot;
use crate::ellipsoid::quaternion::rotation_matrix;
use crate::ellipsoid::scene::{LoadedScene, parse_scene};
use crate::gravity::kepler::{KeplerOrbit, orientation_matrix};
use crate::impact::run::{ImpactError, read_target};
use crate::impact::settle::{SETTLE_MAX_FREE_FALLS, SettleReport, free_fall_time, set_principal_axis_rotation, settle};
use crate::io::run_lock::DirLock;
use crate::math::Vec3;

/// Earth's mass (kg; IAU 2015 nominal GM 3.986004e14 m³ s⁻² over G = 6.674e-11).
pub const EARTH_MASS_KG: f64 = 5.9722e24;
/// Earth's mean radius (m; IUGG).
pub const EARTH_RADIUS_M: f64 = 6.371e6;
/// Default start (and end) distance in units of q: at 10 q the tidal acceleration is 1e-3 of its perigee value
/// and the tidal impulse still to come (∝ d⁻² for a straight-line passage) ~1 % of the whole; 20 q would take it
/// to 0.25 % at about twice the run time (the outer legs dominate the duration).
pub const DEFAULT_START_Q: f64 = 10.0;

/// Smallest `e − 1 = q v∞² / GM` of a flyby's orbit: below it the hyperbola is a parabola to rounding.
pub const MIN_HYPERBOLIC_EXCESS: f64 = 1e-9;
/// Dissipation F0 of a pile of radius [`F0_REFERENCE_RADIUS_M`] (s m⁻², Roig03's "F0 ≈ 1" in km and s, the impact
/// default); other radii get `F0 (R_ref/R)²`, which keeps the damping of the similar pile the same.
pub const F0_REFERENCE: f64 = 1e-6;
/// Radius (m) at which [`F0_REFERENCE`] applies (Roig03's 100 km piles).
pub const F0_REFERENCE_RADIUS_M: f64 = 1e5;

/// A flyby experiment (`rubblepile flyby`): a rubble pile (a target file) past a planet on a hyperbolic orbit.
/// Field names are those of the command line's flags (`q_m` is `--q-m`), so errors name what the user typed.
#[derive(Debug, Clone, PartialEq)]
pub struct FlybyConfig {
    /// Target bodies file (snapshot columns, e.g. from `rubblepile target build`).
    pub target: PathBuf,
    /// Rescale the pile to this apparent radius (m; max over fragments of |r − r_cm| + A); a rescaled pile is
    /// settled before the run [default: as built].
    pub radius_m: Option<f64>,
    /// Set the pile into rigid rotation about its z axis with this period (hours); a re-spun pile is settled before
    /// the run [default: the target's spins].
    pub period_hours: Option<f64>,
    /// Planet mass (kg; 0 for a control run without tide, the frame then moves straight at v∞) [default: Earth].
    pub planet_mass: f64,
    /// Planet radius (m) [default: Earth's mean radius].
    pub planet_radius_m: f64,
    /// The planet's J2 (dimensionless; Earth 1.0826e-3), with `--planet-radius-m` as its reference radius
    /// [default: none, a point mass].
    pub planet_j2: Option<f64>,
    /// The planet's spin axis X,Y,Z in the run's frame (the flyby orbit lies in the x–y plane), used with
    /// `--planet-j2` [default: 0,0,1].
    pub planet_pole: Option<Vec<f64>>,
    /// Perigee distance from the planet's centre (m).
    pub q_m: f64,
    /// Speed at infinity (km/s).
    pub v_inf_km_s: f64,
    /// Orbit orientation Ω,i,ω (degrees; see `physics.flyby.orientation_deg`) [default: 0,0,0, prograde in x–y].
    pub orientation_deg: Option<Vec<f64>>,
    /// Start and end with the planet this many q away.
    pub start_q: f64,
    /// κ of the pile [default: "kappa" of the target's NAME.json, as built].
    pub kappa: Option<f64>,
    /// Dissipation F0 (s m⁻²) [default: 1e-6 (100 km/R)², R the pile's apparent radius].
    pub f0: Option<f64>,
    /// Relative (and absolute) tolerance of Bulirsch–Stoer over the run (and over the settling).
    pub rtol: f64,
    /// Number of snapshots, evenly spaced from start to end (2 to 100000).
    pub snapshots: usize,
    /// Output directory.
    pub out: PathBuf,
    /// Overwrite an earlier run in DIR.
    pub force: bool,
    /// Write the run directory (scene, bodies) but do not run it (the pile is still settled when it would be).
    pub no_run: bool,
    /// Skip the control run without the planet (by default it runs into DIR/control over the same time).
    pub no_control: bool,
    /// After settling, put the pile into rigid rotation about its axis of largest moment with the same |L|
    /// (settles an as-built pile too).
    pub settle_to_principal: bool,
    /// Cap on the settling time (hours) [default: 100 free-fall times √(3π/(32 G ρ)) of the pile].
    pub settle_max_hours: Option<f64>,
}

/// What `flyby.json` records about a flyby run (SI units).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FlybySetup {
    /// The target file.
    pub target: String,
    /// Planet GM (m³ s⁻²).
    pub gm: f64,
    /// Planet radius (m).
    pub planet_radius: f64,
    /// Perigee distance (m).
    pub q: f64,
    /// Speed at infinity (m/s).
    pub v_inf: f64,
    /// Eccentricity.
    pub eccentricity: f64,
    /// Speed at perigee (m/s).
    pub v_perigee: f64,
    /// Time of perigee (s) = half the run.
    pub t_perigee: f64,
    /// End time (s).
    pub t_end: f64,
    /// Start/end distance (m).
    pub start_distance: f64,
    /// Scale factor applied to the target's lengths.
    pub scale: f64,
    /// Apparent radius of the pile (m).
    pub radius: f64,
    /// Total mass (kg).
    pub mass: f64,
    /// Rigid spin period set (h), if any.
    pub period_hours: Option<f64>,
    /// κ.
    pub kappa: f64,
    /// F0 (s m⁻²).
    pub f0: f64,
    /// The planet's J2 (none: a point mass).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub j2: Option<f64>,
    /// The planet's spin axis in the frame (with `j2`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pole: Option<[f64; 3]>,
    /// Whether a control run without the planet goes into `control/` (absent in older runs: none).
    #[serde(default)]
    pub control: bool,
    /// How the pile was settled before the run (absent: it was not).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settling: Option<SettleReport>,
}

/// The frame origin's hyperbolic orbit about a planet of `gm` (m³ s⁻²) with perigee `q` (m) and speed at infinity
/// `v_inf` (m/s), and the time (s) from `start_q · q` on the way in to perigee: half the run's duration.
pub fn flyby_orbit(gm: f64, q: f64, v_inf: f64, start_q: f64) -> Result<(KeplerOrbit, f64), ImpactError> {
    let rot = orientation_matrix(0.0, 0.0, 0.0);
    let orbit = KeplerOrbit::hyperbolic(gm, q, v_inf, 0.0, rot).map_err(|e| invalid("q_m", e.to_string()))?;
    let t_perigee = orbit
        .time_from_perigee_at_distance(start_q * q)
        .ok_or_else(|| invalid("start_q", "the orbit never reaches that distance".into()))?;
    Ok((orbit, t_perigee))
}

/// Subfolder of a flyby run directory that holds its control run (the same pile and time, no planet).
pub const CONTROL_DIR: &str = "control";

/// `n ≥ 2` output times evenly spaced over `[0, t_end]` (s), the last exactly `t_end` and none above it
/// ([`crate::io::output_times::evenly_spaced`]; `t_end·k/(n − 1)` can round one ulp above `t_end`, which the scene
/// check refuses).
pub fn output_times(t_end: f64, n: usize) -> Vec<f64> {
    crate::io::output_times::evenly_spaced(t_end, n)
}

fn invalid(field: &str, message: String) -> ImpactError {
    ImpactError::Invalid {
        field: field.into(),
        message,
    }
}

/// Apparent radius (m) of a pile; it lives with the settling that reads it.
pub use crate::impact::settle::apparent_radius;

/// Centre-of-mass position (m) and velocity (m/s).
fn centre_of_mass(bodies: &[Body]) -> (Vec3, Vec3) {
    let m: f64 = bodies.iter().map(|b| b.shape.mass).sum();
    let r = bodies.iter().map(|b| b.position * b.shape.mass).sum::<Vec3>() / m;
    let v = bodies.iter().map(|b| b.velocity * b.shape.mass).sum::<Vec3>() / m;
    (r, v)
}

/// The pile of `args`: rescaled, spun and in its centre-of-mass frame; returns the bodies and the scale factor.
pub fn prepare_pile(target: &[Body], radius_m: Option<f64>, period_hours: Option<f64>) -> (Vec<Body>, f64) {
    let (cm, vcm) = centre_of_mass(target);
    let scale = radius_m.map_or(1.0, |r| r / apparent_radius(target));
    let bodies = target
        .iter()
        .map(|b| {
            let mut b = b.clone();
            b.position = (b.position - cm) * scale;
            b.velocity = (b.velocity - vcm) * scale;
            b.shape.axes *= scale;
            b.shape.mass *= scale * scale * scale;
            if let Some(p) = period_hours {
                let w = Vec3::new(0.0, 0.0, 2.0 * std::f64::consts::PI / (p * 3600.0));
                b.velocity = w.cross(&b.position);
                b.spin_body = rotation_matrix(&b.quaternion.normalize()) * w;
            }
            b
        })
        .collect::<Vec<_>>();
    // Rigid rotation about the centre of mass leaves it at rest; without it the shift above already did.
    (bodies, scale)
}

/// κ stored by `target build` in the target's `NAME.json`.
fn target_kappa(target: &Path) -> Option<f64> {
    let text = std::fs::read_to_string(target.with_extension("json")).ok()?;
    serde_json::from_str::<serde_json::Value>(&text).ok()?["kappa"].as_f64()
}

/// Validates `args`, writes the run directory (refused when not empty unless `force`, or when another process writes
/// it) and returns the scene, with the directory's lock ([`crate::io::run_lock`]: keep it until the run has ended).
pub fn prepare_flyby(args: &FlybyConfig) -> Result<(LoadedScene, FlybySetup, DirLock), ImpactError> {
    let positive = |x: f64| x.is_finite() && x > 0.0;
    for (field, x) in [
        ("planet_radius_m", args.planet_radius_m),
        ("q_m", args.q_m),
        ("v_inf_km_s", args.v_inf_km_s),
        ("rtol", args.rtol),
        ("radius_m", args.radius_m.unwrap_or(1.0)),
        ("period_hours", args.period_hours.unwrap_or(1.0)),
        ("kappa", args.kappa.unwrap_or(2.0)),
        ("f0", args.f0.unwrap_or(1.0)),
        ("settle_max_hours", args.settle_max_hours.unwrap_or(1.0)),
    ] {
        if !positive(x) {
            return Err(invalid(field, format!("must be > 0 and finite, got {x}")));
        }
    }
    if !(args.planet_mass.is_finite() && args.planet_mass >= 0.0) {
        return Err(invalid(
            "planet_mass",
            format!(
                "must be >= 0 kg (0: a control run without tide), got {}",
                args.planet_mass
            ),
        ));
    }
    if !(args.start_q.is_finite() && args.start_q > 1.0) {
        return Err(invalid(
            "start_q",
            format!("must be > 1 (in units of q), got {}", args.start_q),
        ));
    }
    if args.q_m <= args.planet_radius_m {
        return Err(invalid(
            "q_m",
            format!(
                "must exceed the planet radius {} m, got {}",
                args.planet_radius_m, args.q_m
            ),
        ));
    }
    let max_snapshots = crate::io::scene_file::MAX_SNAPSHOTS;
    if !(2..=max_snapshots).contains(&args.snapshots) {
        return Err(invalid(
            "snapshots",
            format!("need 2 to {max_snapshots} (MAX_SNAPSHOTS), got {}", args.snapshots),
        ));
    }
    let orientation = args.orientation_deg.clone().unwrap_or(vec![0.0; 3]);
    for (field, values) in [
        ("orientation_deg", Some(&orientation)),
        ("planet_pole", args.planet_pole.as_ref()),
    ] {
        if let Some(v) = values
            && v.len() != 3
        {
            return Err(invalid(
                field,
                format!("needs three comma-separated numbers, got {v:?}"),
            ));
        }
    }
    if let Some(j2) = args.planet_j2
        && !j2.is_finite()
    {
        return Err(invalid("planet_j2", format!("must be finite, got {j2}")));
    }
    let pole = match (&args.planet_pole, args.planet_j2) {
        (Some(_), None) => {
            return Err(invalid(
                "planet_pole",
                "is the planet's spin axis for --planet-j2; give --planet-j2 too".to_string(),
            ));
        }
        (Some(p), Some(_)) => {
            let p = [p[0], p[1], p[2]];
            if !(p.iter().all(|x| x.is_finite()) && p.iter().any(|x| *x != 0.0)) {
                return Err(invalid(
                    "planet_pole",
                    format!("must be a finite non-zero vector, got {p:?}"),
                ));
            }
            Some(p)
        }
        (None, Some(_)) => Some([0.0, 0.0, 1.0]),
        (None, None) => None,
    };
    let target = read_target(&args.target)?;
    let kappa = match args.kappa.or_else(|| target_kappa(&args.target)) {
        Some(k) if k > 1.5 => k,
        Some(k) => return Err(invalid("kappa", format!("must be > 1.5, got {k}"))),
        None => {
            return Err(invalid(
                "kappa",
                format!(
                    "no --kappa and no \"kappa\" in {}",
                    args.target.with_extension("json").display()
                ),
            ));
        }
    };
    let (bodies, scale) = prepare_pile(&target, args.radius_m, args.period_hours);
    let radius = apparent_radius(&bodies);
    let f0 = args
        .f0
        .unwrap_or(F0_REFERENCE * (F0_REFERENCE_RADIUS_M / radius).powi(2));
    let gm = G_SI * args.planet_mass;
    let v_inf = args.v_inf_km_s * 1e3;
    // e − 1 = q v∞²/GM: below MIN_HYPERBOLIC_EXCESS the orbit is parabolic to rounding (and the time to perigee
    // unbounded), which is the speed's fault, not the perigee's.
    let excess = args.q_m * v_inf * v_inf / gm;
    if gm > 0.0 && (excess.is_nan() || excess < MIN_HYPERBOLIC_EXCESS) {
        return Err(invalid(
            "v_inf_km_s",
            format!(
                "must be at least {:.3e} km/s for q_m = {} m and this planet (slower, the orbit is parabolic to \
                 rounding: e - 1 < {MIN_HYPERBOLIC_EXCESS:e}), got {}",
                (MIN_HYPERBOLIC_EXCESS * gm / args.q_m).sqrt() / 1e3,
                args.q_m,
                crate::io::scene_file::fmt_num(args.v_inf_km_s)
            ),
        ));
    }
    // Settling a spun pile is bounded like a run (crate::io::run_budget): its spin alone asks for
    // STEPS_PER_TIME_SCALE steps a turn, refused before anything is written when that exceeds the ceiling.
    let settle_max_time = args.settle_max_hours.map_or_else(
        || SETTLE_MAX_FREE_FALLS * free_fall_time(bodies.iter().map(|b| b.shape.mass).sum(), radius),
        |h| h * 3600.0,
    );
    if let Some(p) = args.period_hours {
        let steps = crate::ellipsoid::scene::STEPS_PER_TIME_SCALE * settle_max_time / (p * 3600.0);
        if steps.is_nan() || steps > crate::io::run_budget::DEFAULT_MAX_STEPS as f64 {
            return Err(invalid(
                "period_hours",
                format!(
                    "a spin period of {} h asks for about {steps:.1e} steps to settle the pile over {settle_max_time:.3e} \
                     s, more than the step ceiling {:e}; give a longer --period-hours (or a shorter \
                     --settle-max-hours)",
                    crate::io::scene_file::fmt_num(p),
                    crate::io::run_budget::DEFAULT_MAX_STEPS as f64
                ),
            ));
        }
    }
    let (orbit, t_perigee) = flyby_orbit(gm, args.q_m, v_inf, args.start_q)?;
    let start_distance = args.start_q * args.q_m;
    let t_end = 2.0 * t_perigee;
    let times: Vec<String> = output_times(t_end, args.snapshots)
        .iter()
        .map(|t| format!("{t:?}"))
        .collect();
    let setup = FlybySetup {
        target: args.target.display().to_string(),
        gm,
        planet_radius: args.planet_radius_m,
        q: args.q_m,
        v_inf,
        eccentricity: orbit.e,
        v_perigee: (v_inf * v_inf + 2.0 * gm / args.q_m).sqrt(),
        t_perigee,
        t_end,
        start_distance,
        scale,
        radius,
        mass: bodies.iter().map(|b| b.shape.mass).sum(),
        period_hours: args.period_hours,
        kappa,
        f0,
        j2: args.planet_j2,
        pole,
        control: !args.no_control,
        settling: None,
    };
    let title = format!(
        "Flyby of {} (R = {radius:.1} m) at q = {:.4e} m ({:.2} planet radii), v_inf = {} km/s",
        args.target.display(),
        args.q_m,
        args.q_m / args.planet_radius_m,
        args.v_inf_km_s
    );
    let scene_text = |planet_mass: f64, title: &str| {
        format!(
            "# {title}\n# Generated by `rubblepile flyby`; the same run: `rubblepile run scene.toml --out OTHER_DIR`.\n\
         [scene]\nkind = \"ellipsoids\"\nt_end = {t_end:?}\nbodies_file = \"initial_bodies.csv\"\n\n\
         [model]\nkappa = {kappa:?}\n\n\
         [physics]\ngravity = {{}}\ncontact = {{}}\ndissipation = {{ F0 = {f0:?} }}\n\n\
         [physics.flyby]\nmass = {mass:?}\nradius = {pr:?}\nq = {q:?}\nv_inf = {v_inf:?}\nt_perigee = {t_perigee:?}\n\
         orientation_deg = [{o0:?}, {o1:?}, {o2:?}]\n{zonal}\n\
         [integrator]\nmethod = \"bulirsch-stoer\"\nrtol = {rtol:?}\natol = {rtol:?}\n\n\
         [output]\ntimes = [{times}]\nevery = {every:?}\n",
            mass = planet_mass,
            pr = args.planet_radius_m,
            q = args.q_m,
            o0 = orientation[0],
            o1 = orientation[1],
            o2 = orientation[2],
            rtol = args.rtol,
            times = times.join(", "),
            every = t_end / 400.0,
            zonal = match (args.planet_j2, pole) {
                (Some(j2), Some([x, y, z])) => format!("j2 = {j2:?}\npole = [{x:?}, {y:?}, {z:?}]\n"),
                _ => String::new(),
            },
        )
    };
    let scene_toml = scene_text(args.planet_mass, &title);
    let out = &args.out;
    let lock = prepare_output_dir(out, args.force)?;
    let io = |p: &Path| {
        let path = p.to_path_buf();
        move |source| ImpactError::Io { path, source }
    };
    let bodies_path = out.join("initial_bodies.csv");
    write_snapshot(&bodies_path, 0.0, &bodies).map_err(io(&bodies_path))?;
    let scene_path = out.join("scene.toml");
    crate::io::safe_write::write_atomic(&scene_path, &scene_toml).map_err(io(&scene_path))?;
    let mut scene = parse_scene(&scene_toml, &scene_path.display().to_string(), Some(out))?;
    let mut setup = setup;
    if args.radius_m.is_some() || args.period_hours.is_some() || args.settle_to_principal {
        let prepared_path = out.join("prepared_bodies.csv");
        write_snapshot(&prepared_path, 0.0, &bodies).map_err(io(&prepared_path))?;
        let max_time = settle_max_time;
        let (mut settled, mut report) = settle(&scene.bodies, scene.model, scene.physics, args.rtol, max_time)
            .map_err(|e| ImpactError::Run(crate::driver::RunError::Setup(format!("settling the pile: {e}"))))?;
        if args.settle_to_principal {
            let moments: Vec<Vec3> = settled
                .iter()
                .map(|b| b.shape.principal_moments(scene.model.inertia.inertia_kappa(kappa)))
                .collect();
            set_principal_axis_rotation(&mut settled, &moments);
            report.set_to_principal = true;
        }
        write_snapshot(&bodies_path, 0.0, &settled).map_err(io(&bodies_path))?;
        scene = parse_scene(&scene_toml, &scene_path.display().to_string(), Some(out))?;
        setup.settling = Some(report);
    }
    let json_path = out.join("flyby.json");
    let json = serde_json::to_string_pretty(&setup).unwrap_or_default() + "\n";
    crate::io::safe_write::write_atomic(&json_path, json).map_err(io(&json_path))?;
    if !args.no_control {
        let dir = out.join(CONTROL_DIR);
        crate::io::safe_write::ensure_dir(&dir).map_err(io(&dir))?;
        let control_bodies = dir.join("initial_bodies.csv");
        crate::io::safe_write::copy_atomic(&bodies_path, &control_bodies).map_err(io(&control_bodies))?;
        let control_toml = scene_text(
            0.0,
            "Control of the flyby in the directory above: the same pile and duration, no planet (mass 0)",
        );
        let control_path = dir.join("scene.toml");
        crate::io::safe_write::write_atomic(&control_path, &control_toml).map_err(io(&control_path))?;
    }
    Ok((scene, setup, lock))
}

/// The control run's scene of the flyby directory `dir` (written by [`prepare_flyby`]).
pub fn control_scene(dir: &Path) -> Result<LoadedScene, ImpactError> {
    Ok(crate::ellipsoid::scene::load_scene(
        &dir.join(CONTROL_DIR).join("scene.toml"),
    )?)
}

/// The summaries of a flyby run and of its control (when run).
#[derive(Debug, Clone)]
pub struct FlybyRuns {
    /// The run with the planet.
    pub run: crate::driver::RunSummary,
    /// The control run without it, in `DIR/control/`.
    pub control: Option<crate::driver::RunSummary>,
    /// What `flyby.json` records.
    pub setup: FlybySetup,
}

/// Prepares and (unless `no_run`) runs the flyby of `args`, then its control (unless `no_control`).
pub fn run_flyby(args: &FlybyConfig, options: &RunOptions) -> Result<Option<FlybyRuns>, ImpactError> {
    let (scene, setup, _lock) = prepare_flyby(args)?;
    if args.no_run {
        return Ok(None);
    }
    let options = RunOptions {
        force: true,
        ..*options
    };
    let run = crate::driver::run_scene(&scene, &args.out, &options)?;
    let control = if setup.control {
        let control = control_scene(&args.out)?;
        Some(crate::driver::run_scene(
            &control,
            &args.out.join(CONTROL_DIR),
            &options,
        )?)
    } else {
        None
    };
    Ok(Some(FlybyRuns { run, control, setup }))
}
