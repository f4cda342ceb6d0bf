//! The rotating tumbler of Richardson11 §3.2: the dynamic angle of repose of the free surface vs the Froude number
//! `Fr = ω² R / g`, measured as in the paper by a straight-line fit to surface points on one side of the centre,
//! averaged over snapshots; centrifuging at Fr ≥ 1.
//!
//! Frame: the drum's axis is `+y` through the origin, gravity `−g ẑ`, spin `ω > 0` about `+y`, so the drum's bottom
//! moves towards `−x` and the material rises on the `x < 0` side (the paper's "left of centre" in its clockwise
//! view). Surface points: the free particles are binned in columns of width `2r` along x; each column's highest
//! particle that touches another free particle (centres within 2.5 r, so flying particles do not count) is a surface
//! point. The fit ([`rubblepile::analysis::fits::fit_line`]) uses the columns with `−0.8 R < x < 0`; the angle is
//! `atan(−slope)`.
//!
//! Centrifuging ([`centrifuging`]): the fraction of free particles moving with the drum's wall speed at their
//! position, their mean angular velocity over ω, and the fraction above the axis (0.5 for a uniform ring). The
//! threshold ([`centrifuging_threshold`]) is the Froude number at which a bed spread into an annulus against the
//! lining is held there at the top all the way to its inner surface: `ω² r_in ≥ g`, i.e. `Fr ≥ R / r_in`.

use std::path::{Path, PathBuf};

use super::atmosphere::{RunFiles, read_run_files};
use crate::studies::csv_rows::{read_rows, write_rows};
use rubblepile::analysis::AnalysisError;
use rubblepile::analysis::fits::fit_line;
use rubblepile::granular::hard::scene::{ParticleRow, read_particles_csv};
use rubblepile::math::Vec3;
use rubblepile::math::{mean, mean_std};

/// Surface points `(x, z)` of a pile of free particles (centres `(x, z)` projected along the axis, radius `r`):
/// per column of width `2r`, the highest particle with another within 2.5 r.
pub fn surface_points(centres: &[(f64, f64)], r: f64) -> Vec<(f64, f64)> {
    let w = 2.0 * r;
    let touching = |k: usize| {
        centres.iter().enumerate().any(|(j, c)| {
            j != k && {
                let (dx, dz) = (c.0 - centres[k].0, c.1 - centres[k].1);
                dx * dx + dz * dz < (2.5 * r) * (2.5 * r)
            }
        })
    };
    let mut tops: std::collections::BTreeMap<i64, (f64, f64)> = std::collections::BTreeMap::new();
    for (k, &(x, z)) in centres.iter().enumerate() {
        let col = (x / w).floor() as i64;
        if tops.get(&col).is_some_and(|t| t.1 >= z) || !touching(k) {
            continue;
        }
        tops.insert(col, (x, z));
    }
    tops.into_values().collect()
}

/// Dynamic angle of repose (degrees) from surface points with `x_lo < x < x_hi`, `atan(−slope)` of the
/// least-squares line, and its fit error (degrees): the slope's standard error `σ_s` carried through `atan`,
/// `σ_θ = σ_s / (1 + s²)`. `None` with fewer than 3 points.
pub fn repose_fit(surface: &[(f64, f64)], x_lo: f64, x_hi: f64) -> Option<(f64, f64)> {
    let (x, z): (Vec<f64>, Vec<f64>) = surface.iter().filter(|p| p.0 > x_lo && p.0 < x_hi).copied().unzip();
    if x.len() < 3 {
        return None;
    }
    fit_line(&x, &z).ok().map(|f| {
        let sigma = f.sigma_slope / (1.0 + f.slope * f.slope);
        ((-f.slope).atan().to_degrees(), sigma.to_degrees())
    })
}

/// Relative tolerance of [`co_rotates`]: a particle moves with the drum when its velocity differs from the drum's
/// rigid rotation at its position by less than this fraction of the local drum speed `ω ρ`.
pub const CO_ROTATION_TOLERANCE: f64 = 0.1;

/// A free particle as the drum analysis sees it: centre (m) and velocity (m/s) in the lab frame, drum axis `+y`
/// through the origin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrumParticle {
    /// Centre (m).
    pub position: Vec3,
    /// Velocity (m/s).
    pub velocity: Vec3,
}

/// Velocity (m/s) of a point at `position` turning rigidly with the drum at `omega` (rad/s) about `+y`.
fn drum_velocity(position: &Vec3, omega: f64) -> Vec3 {
    Vec3::new(0.0, omega, 0.0).cross(&Vec3::new(position.x, 0.0, position.z))
}

/// Distance (m) from the drum's axis.
fn axial_distance(position: &Vec3) -> f64 {
    position.x.hypot(position.z)
}

/// Whether `p` moves with the drum: `|v − ω ŷ × ρ| < CO_ROTATION_TOLERANCE · |ω| ρ` (never on the axis or with
/// `ω = 0`).
pub fn co_rotates(p: &DrumParticle, omega: f64) -> bool {
    let slip = (p.velocity - drum_velocity(&p.position, omega)).norm();
    slip < CO_ROTATION_TOLERANCE * omega.abs() * axial_distance(&p.position)
}

/// Centrifuging measures of one snapshot of the free particles (equal masses), or their mean over snapshots.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Centrifuging {
    /// Fraction of the particles that [`co_rotates`]: 1 for a bed turning rigidly with the drum, 0 for one at rest.
    pub co_rotating: f64,
    /// Mean angular velocity about the axis over ω, `Σ (z vx − x vz) / (ω Σ ρ²)`: the particles' angular momentum
    /// about the axis over that of rigid co-rotation at their positions (1 rigid, 0 at rest, < 0 turning backwards).
    pub spin_ratio: f64,
    /// Fraction of the particles above the axis (z > 0): 0 for a half-full drum's bed below the axis, 0.5 for a
    /// uniform ring.
    pub above_axis: f64,
}

/// [`Centrifuging`] of `particles` in a drum turning at `omega` (rad/s); NaN fields when there are no particles,
/// a NaN spin ratio when `omega = 0`.
pub fn centrifuging(particles: &[DrumParticle], omega: f64) -> Centrifuging {
    let n = particles.len() as f64;
    let count = |f: &dyn Fn(&DrumParticle) -> bool| particles.iter().filter(|p| f(p)).count() as f64 / n;
    let spin: f64 = particles
        .iter()
        .map(|p| p.position.z * p.velocity.x - p.position.x * p.velocity.z)
        .sum();
    let rigid: f64 = particles
        .iter()
        .map(|p| omega * axial_distance(&p.position).powi(2))
        .sum();
    Centrifuging {
        co_rotating: count(&|p| co_rotates(p, omega)),
        spin_ratio: spin / rigid,
        above_axis: count(&|p| p.position.z > 0.0),
    }
}

/// Field-by-field mean of several [`Centrifuging`] values (NaN fields for none).
pub fn mean_centrifuging(values: &[Centrifuging]) -> Centrifuging {
    let of = |f: fn(&Centrifuging) -> f64| mean(&values.iter().map(f).collect::<Vec<_>>());
    Centrifuging {
        co_rotating: of(|c| c.co_rotating),
        spin_ratio: of(|c| c.spin_ratio),
        above_axis: of(|c| c.above_axis),
    }
}

/// Fraction of a disc of radius `a` lying below the horizontal chord at height `h` from its centre (`h` clamped to
/// `[−a, a]`).
pub fn disc_fraction_below(h: f64, a: f64) -> f64 {
    let h = h.clamp(-a, a);
    (a * a * (-h / a).acos() + h * (a * a - h * h).sqrt()) / (std::f64::consts::PI * a * a)
}

/// The Froude number `R / r_in` above which a bed filling the fraction `fill` of the disc inside the lining
/// (radius `R − 2r`, the lining particles' inner surface), spread into an annulus against the lining, is held
/// against gravity at the top down to its inner radius `r_in = (R − 2r) √(1 − fill)` (`ω² r_in ≥ g`).
/// `drum_radius` R and `particle_radius` r in m.
pub fn centrifuging_threshold(fill: f64, drum_radius: f64, particle_radius: f64) -> f64 {
    drum_radius / ((drum_radius - 2.0 * particle_radius) * (1.0 - fill).sqrt())
}

/// The fill of a bed at rest (its first snapshot): the fraction of the disc inside the lining (radius
/// `drum_radius − 2r`) below the top of its highest particle.
pub fn initial_fill(particles: &[DrumParticle], drum_radius: f64, particle_radius: f64) -> f64 {
    let top = particles.iter().map(|p| p.position.z).fold(f64::NEG_INFINITY, f64::max) + particle_radius;
    disc_fraction_below(top, drum_radius - 2.0 * particle_radius)
}

/// The free particles of a snapshot's rows.
fn drum_particles(rows: &[ParticleRow]) -> Vec<DrumParticle> {
    rows.iter()
        .filter(|r| r.stuck_to.is_none())
        .map(|r| DrumParticle {
            position: Vec3::new(r.values[4], r.values[5], r.values[6]),
            velocity: Vec3::new(r.values[7], r.values[8], r.values[9]),
        })
        .collect()
}

/// The analysis of one tumbler run: its [`TumblerFacts`] (read through it: `run.froude`, `run.fill`, …) and the
/// measures of its snapshots.
#[derive(Debug, Clone)]
pub struct TumblerRun {
    /// Run directory (the tests compare runs read from two places with it).
    #[cfg_attr(not(test), allow(dead_code))]
    pub dir: PathBuf,
    /// The run-level facts.
    pub facts: TumblerFacts,
    /// `(t, angle in degrees)` per late snapshot (t ≥ half the run) with a fit.
    pub angles: Vec<(f64, f64)>,
    /// Mean and standard deviation of the angles (degrees).
    pub angle: (f64, f64),
    /// The fit error ([`repose_fit`], degrees) of each angle in `angles`, in the same order.
    pub angle_fit_errors: Vec<f64>,
    /// `(t, angle, fit error)` in degrees for every snapshot with a fit, the first half of the run included (how
    /// the surface got there: a bed still tilting with the drum, or settled).
    pub angle_history: Vec<(f64, f64, f64)>,
    /// [`centrifuging_threshold`] for the fill.
    pub threshold: f64,
    /// `(t, measures)` per snapshot (the report reads the means below; the tests read these).
    #[cfg_attr(not(test), allow(dead_code))]
    pub centrifuging: Vec<(f64, Centrifuging)>,
    /// Mean measures over the snapshots of the second half of the run (t ≥ half the time reached).
    pub late: Centrifuging,
    /// The same over its two halves, 50–75 % and 75–100 % of the run: equal when the measures have settled.
    pub late_halves: [Centrifuging; 2],
}

impl std::ops::Deref for TumblerRun {
    type Target = TumblerFacts;

    fn deref(&self) -> &TumblerFacts {
        &self.facts
    }
}

/// One snapshot of a tumbler run, reduced to what the reports read: a row of a compact copy's
/// [`COMPACT_SNAPSHOTS`] file.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TumblerSnapshot {
    /// Time (s).
    pub t: f64,
    /// Surface angle ([`repose_fit`], degrees); NaN when the snapshot has no fit.
    pub angle_deg: f64,
    /// Its fit error (degrees); NaN when the snapshot has no fit.
    pub fit_error_deg: f64,
    /// [`Centrifuging::co_rotating`].
    pub co_rotating: f64,
    /// [`Centrifuging::spin_ratio`].
    pub spin_ratio: f64,
    /// [`Centrifuging::above_axis`].
    pub above_axis: f64,
}

/// The run-level facts of a tumbler run: the one row of a compact copy's [`COMPACT_FACTS`] file.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TumblerFacts {
    /// Froude number `ω² R / g` with the wall radius.
    pub froude: f64,
    /// Drum spin (rad/s).
    pub omega: f64,
    /// Drum wall radius (m).
    pub radius: f64,
    /// Free particles' radius (m).
    pub particle_radius: f64,
    /// Free particles (last snapshot).
    pub free: usize,
    /// Stuck (lining) particles (last snapshot).
    pub stuck: usize,
    /// Normal restitution from `[material]` (NaN when absent).
    pub eps_n: f64,
    /// Tangential restitution from `[material]` (NaN when absent).
    pub eps_t: f64,
    /// [`initial_fill`] of the first snapshot.
    pub fill: f64,
    /// Run status (`completed`, `interrupted`, …).
    pub status: String,
    /// Time reached (s).
    pub t_reached: f64,
    /// Events per wall-clock second.
    pub events_per_second: f64,
    /// Wall-clock seconds.
    pub wall_seconds: f64,
    /// Collisions applied.
    pub collisions: u64,
    /// The scene's step `stepping.dt` (s; NaN when absent).
    pub dt: f64,
    /// The run's energy residual (`energy_error` of the summary, or the largest |energy_residual| of a stopped
    /// run's time series; NaN when neither is there): the integration error once restitution and the walls' work
    /// are booked.
    pub energy_error: f64,
}

impl TumblerFacts {
    /// The lining's inner radius over the particle radius, `(R − 2r) / r` (R the wall radius).
    pub fn radius_ratio(&self) -> f64 {
        (self.radius - 2.0 * self.particle_radius) / self.particle_radius
    }

    /// Normal and tangential coefficients of restitution from the scene's `[material]` (NaN when absent).
    pub fn restitution(&self) -> (f64, f64) {
        (self.eps_n, self.eps_t)
    }
}

/// File of a compact copy holding [`TumblerFacts`] (one row).
pub const COMPACT_FACTS: &str = "tumbler_run.csv";
/// File of a compact copy holding one [`TumblerSnapshot`] per snapshot.
pub const COMPACT_SNAPSHOTS: &str = "tumbler_snapshots.csv";

/// The facts and per-snapshot measures of the tumbler run in `dir`: a run directory (`scene.toml` — wall 0 the
/// drum: its radius and spin; gravity —, `summary.json` or the time series, snapshots) or a compact copy written by
/// [`write_tumbler_compact`] (its two CSV files, a few kB instead of the snapshots' tens of MB).
pub fn read_tumbler_parts(dir: &Path) -> Result<(TumblerFacts, Vec<TumblerSnapshot>), AnalysisError> {
    if !dir.join("scene.toml").exists() && dir.join(COMPACT_SNAPSHOTS).exists() {
        let facts: Vec<TumblerFacts> = read_rows(&dir.join(COMPACT_FACTS))?;
        let facts = facts
            .into_iter()
            .next()
            .ok_or_else(|| AnalysisError::Input(format!("{}: no data row", dir.join(COMPACT_FACTS).display())))?;
        return Ok((facts, read_rows(&dir.join(COMPACT_SNAPSHOTS))?));
    }
    let RunFiles {
        scene: v,
        g,
        summary,
        snapshots: files,
    } = read_run_files(dir)?;
    let sp = dir.join("scene.toml");
    let drum = v
        .get("wall")
        .and_then(|w| w.as_array())
        .and_then(|w| w.first())
        .ok_or_else(|| format!("{}: no wall 0 (the drum)", sp.display()))?;
    let num = |t: &toml::Value, k: &str| t.get(k).and_then(|x| x.as_float());
    let radius = num(drum, "radius").ok_or_else(|| format!("{}: wall[0].radius missing", sp.display()))?;
    let omega = num(drum, "spin").unwrap_or(0.0);
    let material = |k: &str| v.get("material").and_then(|m| num(m, k)).unwrap_or(f64::NAN);
    let mut snapshots = Vec::new();
    let (mut free, mut stuck, mut r, mut first) = (0, 0, f64::NAN, None);
    for path in &files {
        let rows = read_particles_csv(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let t = rows.first().map_or(f64::NAN, |r| r.values[0]);
        let centres: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.stuck_to.is_none())
            .map(|r| (r.values[4], r.values[6]))
            .collect();
        let particles = drum_particles(&rows);
        let c = centrifuging(&particles, omega);
        first.get_or_insert(particles);
        free = centres.len();
        stuck = rows.len() - free;
        r = rows
            .iter()
            .find(|r| r.stuck_to.is_none())
            .map_or(f64::NAN, |r| r.values[3]);
        let fit = if centres.is_empty() {
            None
        } else {
            repose_fit(&surface_points(&centres, r), -0.8 * radius, 0.0)
        };
        let (angle_deg, fit_error_deg) = fit.unwrap_or((f64::NAN, f64::NAN));
        snapshots.push(TumblerSnapshot {
            t,
            angle_deg,
            fit_error_deg,
            co_rotating: c.co_rotating,
            spin_ratio: c.spin_ratio,
            above_axis: c.above_axis,
        });
    }
    let facts = TumblerFacts {
        froude: omega * omega * radius / g,
        omega,
        radius,
        particle_radius: r,
        free,
        stuck,
        eps_n: material("eps_n"),
        eps_t: material("eps_t"),
        fill: initial_fill(first.as_deref().unwrap_or_default(), radius, r),
        status: summary["status"].as_str().unwrap_or("?").to_string(),
        t_reached: summary["t_reached"].as_f64().unwrap_or(f64::NAN),
        events_per_second: summary["events_per_second"].as_f64().unwrap_or(f64::NAN),
        wall_seconds: summary["wall_seconds"].as_f64().unwrap_or(f64::NAN),
        collisions: summary["collisions"].as_u64().unwrap_or(0),
        dt: v.get("stepping").and_then(|s| num(s, "dt")).unwrap_or(f64::NAN),
        energy_error: summary["energy_error"].as_f64().unwrap_or(f64::NAN),
    };
    Ok((facts, snapshots))
}

/// Writes the compact copy of the tumbler run `run_dir` (a run directory or a compact copy) into `out`
/// ([`COMPACT_FACTS`] and [`COMPACT_SNAPSHOTS`]): everything [`analyse_tumbler_run`] reads, so that a report
/// regenerates from committed files. Refuses to write into a run directory.
pub fn write_tumbler_compact(run_dir: &Path, out: &Path) -> Result<(), AnalysisError> {
    if out.join("scene.toml").exists() {
        return Err(AnalysisError::Output(format!(
            "{}: is a run directory; a compact copy goes to a directory of its own",
            out.display()
        )));
    }
    let (facts, snapshots) = read_tumbler_parts(run_dir)?;
    std::fs::create_dir_all(out).map_err(|e| AnalysisError::Output(format!("{}: {e}", out.display())))?;
    write_rows(&out.join(COMPACT_FACTS), std::slice::from_ref(&facts))?;
    write_rows(&out.join(COMPACT_SNAPSHOTS), &snapshots)
}

/// Reads and analyses the tumbler run in `dir` (a run directory or a compact copy, [`read_tumbler_parts`]).
pub fn analyse_tumbler_run(dir: &Path) -> Result<TumblerRun, AnalysisError> {
    let (facts, snapshots) = read_tumbler_parts(dir)?;
    let t_reached = facts.t_reached;
    let mut angles = Vec::new();
    let mut fit_errors = Vec::new();
    let mut history = Vec::new();
    let mut measures = Vec::new();
    for s in &snapshots {
        measures.push((
            s.t,
            Centrifuging {
                co_rotating: s.co_rotating,
                spin_ratio: s.spin_ratio,
                above_axis: s.above_axis,
            },
        ));
        if s.angle_deg.is_nan() {
            continue;
        }
        history.push((s.t, s.angle_deg, s.fit_error_deg));
        if s.t >= 0.5 * t_reached {
            angles.push((s.t, s.angle_deg));
            fit_errors.push(s.fit_error_deg);
        }
    }
    let a: Vec<f64> = angles.iter().map(|p| p.1).collect();
    let between = |lo: f64, hi: f64| {
        let m: Vec<Centrifuging> = measures
            .iter()
            .filter(|(t, _)| {
                // Half-open windows (the last one closed) with a rounding margin: snapshot times are printed.
                let f = t / t_reached;
                f >= lo - 1e-9 && (f < hi - 1e-9 || hi >= 1.0)
            })
            .map(|p| p.1)
            .collect();
        mean_centrifuging(&m)
    };
    Ok(TumblerRun {
        dir: dir.to_path_buf(),
        angle: mean_std(&a),
        angles,
        angle_fit_errors: fit_errors,
        angle_history: history,
        threshold: centrifuging_threshold(facts.fill, facts.radius, facts.particle_radius),
        late: between(0.5, 1.0),
        late_halves: [between(0.5, 0.75), between(0.75, 1.0)],
        centrifuging: measures,
        facts,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tilted_packed_pile_gives_its_angle() {
        // A pile of touching discs (spacing 2r) filling z < −tan(30°) x inside a circle of radius 30 r: the fit to
        // its surface on x < 0 recovers 30° to within the column discretisation.
        let r = 1.0;
        let slope = -(30f64.to_radians().tan());
        let mut c = Vec::new();
        for i in -30..=30 {
            for k in -30..=30 {
                let (x, z) = (
                    2.0 * r * i as f64,
                    2.0 * r * k as f64 * 0.866 + if k % 2 == 0 { 0.0 } else { r },
                );
                if x * x + z * z < 900.0 && z < slope * x {
                    c.push((x, z));
                }
            }
        }
        // A flying particle above the pile is ignored.
        c.push((-10.0, 25.0));
        let a = repose_fit(&surface_points(&c, r), -24.0, 0.0).unwrap().0;
        assert!((a - 30.0).abs() < 3.0, "angle {a}");
        // A flat pile gives 0.
        let flat: Vec<(f64, f64)> = (-20..20)
            .flat_map(|i| [(2.0 * i as f64, 0.0), (2.0 * i as f64, -2.0)])
            .collect();
        let a0 = repose_fit(&surface_points(&flat, r), -24.0, 0.0).unwrap().0;
        assert!(a0.abs() < 1e-9, "flat angle {a0}");
        assert!(repose_fit(&[(0.0, 0.0)], -1.0, 1.0).is_none());
    }
}
