//! The stability cases (Roig03 §2: contact Eqs. 10–14, attitudes Eqs. 19–37, dissipation Eqs. 40–41),
//! built in code as scene TOML so that each run directory's `scene.toml` reruns it with `rubblepile run`. One file
//! per regime (a)–(h); this file holds what they share and the sets.
//!
//! All bodies have density 3000 kg/m³ unless said otherwise; SI units throughout. Criteria (stated in each
//! row's note) are chosen from the physics of the case, not from the measured values: strict energy bounds
//! are 10–100 × the tolerance `rtol = 1e-10` for conservative runs; dissipative runs are held to the energy
//! bookkeeping `H − H0 − 2∫F dt` at 1e-6 of the initial energy scale.

use std::f64::consts::{PI, TAU};
use std::fmt::Write as _;

use super::case::{Case, CaseRun, Judgement, judge};
use rubblepile::ellipsoid::barrier::SPEED_MARGIN;
use rubblepile::ellipsoid::body::{Body, Ellipsoid};
use rubblepile::ellipsoid::calibration::lambda;
use rubblepile::ellipsoid::cloud::{CloudParams, random_cloud};
use rubblepile::ellipsoid::equations::G_SI;
use rubblepile::ellipsoid::quaternion::rotation_matrix;
use rubblepile::math::{Vec3, Vec4};

mod cloud_collapse;
mod head_on;
mod kappa_sweep;
mod mass_ratio;
mod needles_plates;
mod resting;
mod stiff_dissipation;
mod theta_zero;

pub use cloud_collapse::*;
pub use head_on::*;
pub use kappa_sweep::*;
pub use mass_ratio::*;
pub use needles_plates::*;
pub use resting::*;
pub use stiff_dissipation::*;
pub use theta_zero::*;

/// Density of every case body (kg/m³).
pub const DENSITY: f64 = 3000.0;

/// Tolerance (`rtol = atol`) of every case.
pub const RTOL: f64 = 1e-10;

/// Strict energy bound of a conservative run (relative residual): 100 × [`RTOL`].
pub const ENERGY_STRICT: f64 = 1e-8;

/// Energy bound of a dissipative run's bookkeeping `H − H0 − 2∫F` (relative to the initial energy scale).
pub const ENERGY_DISSIPATIVE: f64 = 1e-6;

/// Loose energy bound: above it a case fails.
pub const ENERGY_LOOSE: f64 = 1e-4;

/// Hard bound on `max ||q| − 1|` (1000 × below the run driver's stop at 1e-3).
pub const QUATERNION_HARD: f64 = 1e-6;

/// The drift of `|q|` a run may show: about [`RTOL`] per accepted step (the quaternions are never
/// renormalised, so each step's error within the tolerance adds up), at least `100 × RTOL`.
pub fn quaternion_budget(steps: u64) -> f64 {
    RTOL * (steps.max(100) as f64)
}

/// A body of density [`DENSITY`] with semi-axes `axes` (m).
pub fn rock(axes: [f64; 3], position: [f64; 3], velocity: [f64; 3], quaternion: Vec4, spin_body: [f64; 3]) -> Body {
    let axes = Vec3::from(axes);
    let mass = DENSITY * 4.0 / 3.0 * PI * axes.x * axes.y * axes.z;
    Body {
        shape: Ellipsoid { axes, mass },
        position: Vec3::from(position),
        velocity: Vec3::from(velocity),
        quaternion,
        spin_body: Vec3::from(spin_body),
    }
}

/// The unit quaternion of a rotation by `angle` (rad) about `axis`, in the scene convention
/// (`(α, β, γ, δ)`, scalar last; for the z axis, `R(q)` of Roig03 Eq. 21 turns body x to world `(cos, sin, 0)`).
pub fn axis_angle(axis: [f64; 3], angle: f64) -> Vec4 {
    let a = Vec3::from(axis).normalize() * (0.5 * angle).sin();
    Vec4::new(a.x, a.y, a.z, (0.5 * angle).cos())
}

/// How κ is set.
#[derive(Debug, Clone, Copy)]
pub enum Kappa {
    /// `model.kappa`.
    Given(f64),
    /// `model.calibrate = { beta, v }` (v in m/s).
    Calibrated {
        /// β of Eq. 14.
        beta: f64,
        /// v of Eq. 14 (m/s).
        v: f64,
    },
}

/// Everything of a scene but its bodies.
#[derive(Debug, Clone)]
pub struct SceneSpec {
    /// End time (s).
    pub t_end: f64,
    /// κ.
    pub kappa: Kappa,
    /// Monopole gravity (SI G).
    pub gravity: bool,
    /// Contact potential.
    pub contact: bool,
    /// Dissipation F0 (s m⁻²), if on.
    pub f0: Option<f64>,
    /// Time-series cadence (s).
    pub every: f64,
    /// Snapshot times (s); `None` = one at every time-series row.
    pub snapshots: Option<Vec<f64>>,
    /// Absolute tolerance (SI units of each component; [`RTOL`] unless a case needs otherwise).
    pub atol: f64,
}

impl SceneSpec {
    /// The spec of most cases: gravity and contact, dissipation `f0` (s m⁻²) if any, κ calibrated with β = 10 and
    /// `v_cal` (m/s, Eq. 14), the tolerance [`RTOL`]; `rows` time-series rows and `snapshots` + 1 snapshots
    /// evenly over `t_end` (s).
    pub fn calibrated(t_end: f64, v_cal: f64, f0: Option<f64>, rows: u32, snapshots: usize) -> SceneSpec {
        SceneSpec {
            t_end,
            kappa: Kappa::Calibrated { beta: 10.0, v: v_cal },
            gravity: true,
            contact: true,
            f0,
            every: t_end / f64::from(rows),
            snapshots: Some(grid(t_end, snapshots)),
            atol: RTOL,
        }
    }
}

/// Snapshot times `0, t_end/n, …, t_end`.
pub fn grid(t_end: f64, n: usize) -> Vec<f64> {
    (0..=n).map(|k| t_end * k as f64 / n as f64).collect()
}

fn fmt(x: f64) -> String {
    format!("{x:?}")
}

fn fmt_list(v: &[f64]) -> String {
    format!("[{}]", v.iter().map(|&x| fmt(x)).collect::<Vec<_>>().join(", "))
}

/// The scene TOML of `spec` and `bodies` (exact: floats written in round-trip form).
pub fn scene_toml(title: &str, spec: &SceneSpec, bodies: &[Body]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Stability case {title} (rubblepile bench stability)\n");
    let _ = writeln!(s, "[scene]\nkind = \"ellipsoids\"\nt_end = {}\n", fmt(spec.t_end));
    let model = match spec.kappa {
        Kappa::Given(k) => format!("kappa = {}", fmt(k)),
        Kappa::Calibrated { beta, v } => format!("calibrate = {{ beta = {}, v = {} }}", fmt(beta), fmt(v)),
    };
    let _ = writeln!(s, "[model]\n{model}\ninertia = \"gaussian\"\n");
    let _ = writeln!(s, "[physics]");
    if spec.gravity {
        let _ = writeln!(s, "gravity = {{}}");
    }
    if spec.contact {
        let _ = writeln!(s, "contact = {{}}");
    }
    if let Some(f0) = spec.f0 {
        let _ = writeln!(s, "dissipation = {{ F0 = {} }}", fmt(f0));
    }
    let _ = writeln!(
        s,
        "\n[integrator]\nmethod = \"bulirsch-stoer\"\nrtol = {}\natol = {}\n",
        fmt(RTOL),
        fmt(spec.atol)
    );
    let times = spec.snapshots.clone().unwrap_or_else(|| {
        let n = (spec.t_end / spec.every).round().max(1.0) as usize;
        grid(spec.t_end, n)
    });
    let _ = writeln!(s, "[output]\ntimes = {}\nevery = {}", fmt_list(&times), fmt(spec.every));
    for b in bodies {
        let _ = writeln!(
            s,
            "\n[[body]]\naxes = {}\nmass = {}\nposition = {}\nvelocity = {}\nquaternion = {}\nspin_body = {}",
            fmt_list(b.shape.axes.as_slice()),
            fmt(b.shape.mass),
            fmt_list(b.position.as_slice()),
            fmt_list(b.velocity.as_slice()),
            fmt_list(b.quaternion.as_slice()),
            fmt_list(b.spin_body.as_slice())
        );
    }
    s
}

/// Roig03 Eq. 14 solved for `v` (m/s) given κ: `v² = e^{κλ}/(κλ) · G m_k/(β (R_k + R_l))`.
pub fn speed_for_kappa(kappa: f64, beta: f64, small: &Body, large: &Body) -> f64 {
    let (rk, rl) = (small.shape.equivalent_radius(), large.shape.equivalent_radius());
    let x = kappa * lambda(rk, rl);
    (G_SI * small.shape.mass / (beta * (rk + rl))).sqrt() * (0.5 * (x - x.ln())).exp()
}

/// `a` and `b` moving along x, towards each other when `a` lies at smaller x, at relative speed `v` (m/s) with
/// zero total momentum.
fn approaching(a: Body, b: Body, v: f64) -> [Body; 2] {
    let m = a.shape.mass + b.shape.mass;
    let (va, vb) = (v * b.shape.mass / m, -v * a.shape.mass / m);
    [
        Body {
            velocity: Vec3::new(va, 0.0, 0.0),
            ..a
        },
        Body {
            velocity: Vec3::new(vb, 0.0, 0.0),
            ..b
        },
    ]
}

/// The head-on pair of cases (a) and (f): the largest body (1000 × 700 × 500 m, at x = −1000 m) and the smallest
/// (600 × 450 × 300 m, at x = 1400 m), tip to tip along x with their surfaces 800 m apart, meeting at `v` (m/s).
fn tip_to_tip(v: f64) -> [Body; 2] {
    let large = rock(
        [1000.0, 700.0, 500.0],
        [-1000.0, 0.0, 0.0],
        [0.0; 3],
        Vec4::w(),
        [0.0; 3],
    );
    let small = rock([600.0, 450.0, 300.0], [1400.0, 0.0, 0.0], [0.0; 3], Vec4::w(), [0.0; 3]);
    approaching(large, small, v)
}

/// A case of the scene `spec` with `bodies`, judged by `check`; a check that cannot read the run's outputs
/// (`Err`) fails the case, saying why.
fn case(
    id: &str,
    description: String,
    spec: &SceneSpec,
    bodies: &[Body],
    check: impl Fn(&CaseRun) -> Result<Judgement, String> + Send + Sync + 'static,
) -> Case {
    Case {
        id: id.into(),
        description,
        scene_toml: scene_toml(id, spec, bodies),
        check: Box::new(move |run| {
            check(run).unwrap_or_else(|e| judge(&[(true, false, format!("outputs readable: {e}"))]))
        }),
    }
}

// -------------------------------------------------------------------------------------------------
// Shared measurements.
// -------------------------------------------------------------------------------------------------

/// `(check passed?, text)` for completion.
fn completed_check(run: &CaseRun) -> (bool, bool, String) {
    match &run.failure {
        None => (true, true, format!("completed to t = {} s", run.summary.final_time)),
        Some(cause) => (true, false, format!("completed (stopped: {cause})")),
    }
}

/// The energy residual against the loose bound (hard) and, soft, against [`ENERGY_DISSIPATIVE`] for the
/// bookkeeping `H − H0 − 2∫F` of a `dissipative` run, else against [`ENERGY_STRICT`].
fn energy_check(run: &CaseRun, dissipative: bool) -> [(bool, bool, String); 2] {
    let (strict, label) = if dissipative {
        (ENERGY_DISSIPATIVE, "H - H0 - 2intF")
    } else {
        (ENERGY_STRICT, "energy")
    };
    let e = run.summary.energy_error;
    [
        (
            false,
            e <= strict,
            format!("{label} residual {e:.2e} <= {strict:e} (pass bound)"),
        ),
        (true, e <= ENERGY_LOOSE, format!("<= {ENERGY_LOOSE:e} (fail bound)")),
    ]
}

/// The checks every case starts with: [`completed_check`] and [`energy_check`].
fn run_checks(run: &CaseRun, dissipative: bool) -> Vec<(bool, bool, String)> {
    let mut checks = vec![completed_check(run)];
    checks.extend(energy_check(run, dissipative));
    checks
}

/// No stall: at most 1e6 step attempts (hard).
fn no_stall_check(run: &CaseRun) -> (bool, bool, String) {
    let attempts = run.summary.steps_accepted + run.summary.steps_rejected;
    (
        true,
        attempts <= 1_000_000,
        format!("no stall: {attempts} step attempts <= 1e6"),
    )
}

fn quaternion_check(run: &CaseRun) -> (bool, bool, String) {
    let q = run.summary.quaternion_norm_error;
    let budget = quaternion_budget(run.summary.steps_accepted);
    if q > QUATERNION_HARD {
        (
            true,
            false,
            format!("max||q|-1| {q:.1e} <= {QUATERNION_HARD:e} (fail bound)"),
        )
    } else {
        (
            false,
            q <= budget,
            format!("max||q|-1| {q:.1e} <= rtol x steps = {budget:.1e}"),
        )
    }
}

fn no_overrun_check(run: &CaseRun) -> (bool, bool, String) {
    let n = run.overrun_pairs();
    (false, n == 0, format!("barrier overruns {n} (expected 0)"))
}

fn final_bodies(run: &CaseRun) -> Result<Vec<Body>, String> {
    run.snapshots()?
        .pop()
        .map(|(_, b)| b)
        .ok_or_else(|| "no snapshot".to_string())
}

/// The rows of a run's `timeseries.csv` as numbers (columns of [`rubblepile::ellipsoid::output::TIMESERIES_COLUMNS`]).
fn timeseries(run: &CaseRun) -> Result<Vec<Vec<f64>>, String> {
    let path = run.dir.join("timeseries.csv");
    rubblepile::io::table::read_table(&path, rubblepile::io::table::Cells::Strict)
        .map(|t| t.rows)
        .map_err(|e| e.to_string())
}

/// `(t, wall_seconds)` of every time-series row of a run.
fn wall_profile(run: &CaseRun) -> Result<Vec<(f64, f64)>, String> {
    Ok(timeseries(run)?.iter().map(|r| (r[0], r[r.len() - 1])).collect())
}

/// "Settled into rigid motion": the energy dissipated over the last 10% of the run is below 1e-3 of all
/// that was dissipated (the dissipation function vanishes for a common rigid motion, Roig03 App. A).
fn settled_check(run: &CaseRun) -> (bool, bool, String) {
    let rows = match timeseries(run) {
        Ok(r) if r.len() > 1 => r,
        _ => return (false, false, "settled: timeseries.csv unreadable".into()),
    };
    let t_end = rows[rows.len() - 1][0];
    let d = |r: &Vec<f64>| r[5];
    let total = d(&rows[rows.len() - 1]) - d(&rows[0]);
    let tail_start = rows.iter().find(|r| r[0] >= 0.9 * t_end).unwrap_or(&rows[0]);
    let tail = d(&rows[rows.len() - 1]) - d(tail_start);
    let frac = if total != 0.0 { tail / total } else { 0.0 };
    (
        false,
        frac.abs() < 1e-3,
        format!("settled into rigid motion: last 10% of the run dissipated {frac:.1e} of the total (< 1e-3)"),
    )
}

/// Relative speed (m/s) and the sphere-equivalent separation `√(x/κλ)` of bodies `i`, `j`.
fn pair_state(bodies: &[Body], i: usize, j: usize) -> (f64, f64) {
    let (bi, bj) = (&bodies[i], &bodies[j]);
    let sigma = |b: &Body| {
        let r = rotation_matrix(&b.quaternion);
        r.transpose() * rubblepile::math::Mat3::from_diagonal(&b.shape.axes.component_mul(&b.shape.axes)) * r
    };
    let g = sigma(bi) + sigma(bj);
    let d = bi.position - bj.position;
    let x = g.try_inverse().map_or(f64::NAN, |gi| d.dot(&(gi * d)));
    let lam = lambda(bi.shape.equivalent_radius(), bj.shape.equivalent_radius());
    ((bi.velocity - bj.velocity).norm(), (x / lam).sqrt())
}

// -------------------------------------------------------------------------------------------------
// The sets.
// -------------------------------------------------------------------------------------------------

/// κ values of the sweep (f): the full bench and the quick set.
pub fn sweep_kappas(quick: bool) -> Vec<f64> {
    if quick {
        vec![1.6, 5.0, 50.0]
    } else {
        vec![1.6, 2.5, 5.0, 10.0, 20.0, 50.0]
    }
}

/// Every case of the suite: the full bench (`quick = false`: N = 2000 cloud, six κ values, the κ = 1.6 impact
/// with gravity and the crawl of a resting contact at the default atol) or the quick set the tests run.
pub fn all_cases(quick: bool) -> Vec<Case> {
    let mut v = vec![
        head_on("a1-headon-1x", 1.0),
        head_on("a2-headon-3x", 3.0),
        head_on("a3-headon-15x", 15.0),
        flat_pair("b1-needles", false),
        flat_pair("b2-plates", true),
        tiny_orbit("c1-orbit-ratio-1e-6"),
        tiny_resting("c2-resting-ratio-1e-6"),
        theta_zero("d0-generic-attitude", 1.0, 0.0),
        theta_zero("d1-theta0-exact", 0.0, 0.0),
        theta_zero("d2-theta0-near", 1e-9, 1e-4),
        sticking("e1-f0-100-stick"),
        sticking_in_contact("e2-f0-100-in-contact"),
    ];
    for k in sweep_kappas(quick) {
        v.push(kappa_sweep(&format!("f-kappa-{k}"), k, false));
    }
    if !quick {
        v.push(kappa_sweep("f-kappa-1.6-gravity", 1.6, true));
    }
    v.push(cloud_collapse("g1-cloud-n64-naive-v", 64, CLOUD_T_END, true));
    v.push(cloud_collapse("g2-cloud-n64", 64, CLOUD_T_END, false));
    if !quick {
        v.push(cloud_collapse("g3-cloud-n2000", 2000, CLOUD_T_END_N2000, false));
    }
    v.push(resting("h1-rest-1e6s-damped", true, RESTING_ATOL, 1e6));
    v.push(resting("h2-rest-1e6s-free", false, RESTING_ATOL, 1e6));
    if !quick {
        v.push(resting("h0-rest-default-atol", true, RTOL, 7.5e4));
    }
    v
}
