//! The rotating tumbler of Richardson11 §3.2: the dynamic angle of repose of the free surface vs the Froude number
//! `Fr = ω² R / g`, measured as in the paper by a straight-line fit to surface points on one side of the centre,
//! averaged over snapshots; centrifuging at Fr ≥ 1.
//!
//! Frame: the drum's axis is `+y` through the origin, gravity `−g ẑ`, spin `ω > 0` about `+y`, so the drum's bottom
//! moves towards `−x` and the material rises on the `x < 0` side (the paper's "left of centre" in its clockwise
//! view). Surface points: the free particles are binned in columns of width `2r` along x; each column's highest
//! particle that touches another free particle (centres within 2.5 r, so flying particles do not count) is a surface
//! point. The fit ([`crate::analysis::fits::fit_line`]) uses the columns with `−0.8 R < x < 0`; the angle is
//! `atan(−slope)`.

use std::path::{Path, PathBuf};

use crate::analysis::atmosphere::{RunFiles, mean_std, read_run_files};
use crate::analysis::fits::fit_line;
use crate::granular::hard::scene::read_particles_csv;

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

/// Dynamic angle of repose (degrees) from surface points with `x_lo < x < x_hi`: `atan(−slope)` of the
/// least-squares line. `None` with fewer than 3 points.
pub fn repose_angle(surface: &[(f64, f64)], x_lo: f64, x_hi: f64) -> Option<f64> {
    let (x, z): (Vec<f64>, Vec<f64>) = surface.iter().filter(|p| p.0 > x_lo && p.0 < x_hi).copied().unzip();
    if x.len() < 3 {
        return None;
    }
    fit_line(&x, &z).ok().map(|f| (-f.slope).atan().to_degrees())
}

/// The analysis of one tumbler run.
#[derive(Debug, Clone)]
pub struct TumblerRun {
    /// Run directory.
    pub dir: PathBuf,
    /// Froude number `ω² R / g`.
    pub froude: f64,
    /// Drum spin (rad/s).
    pub omega: f64,
    /// Drum radius (m).
    pub radius: f64,
    /// Particle radius (m) of the free particles.
    pub particle_radius: f64,
    /// Free and stuck particles.
    pub free: usize,
    /// Stuck (lining) particles.
    pub stuck: usize,
    /// `(t, angle in degrees)` per late snapshot (t ≥ half the run) with a fit.
    pub angles: Vec<(f64, f64)>,
    /// Mean and standard deviation of the angles (degrees).
    pub angle: (f64, f64),
    /// Mean fraction of free particles above the axis (z > 0) in the late snapshots: ≈ 0 for a tumbling half-full
    /// drum, large when the material centrifuges.
    pub above_axis: f64,
    /// From `summary.json`: status, time reached, events per second, wall seconds, collisions.
    pub status: String,
    /// Time reached (s).
    pub t_reached: f64,
    /// Events per wall-clock second.
    pub events_per_second: f64,
    /// Wall-clock seconds.
    pub wall_seconds: f64,
    /// Collisions applied.
    pub collisions: u64,
}

/// Reads a tumbler run: `scene.toml` (wall 0 the drum: its radius and spin; gravity), `summary.json`, snapshots.
pub fn analyse_tumbler_run(dir: &Path) -> Result<TumblerRun, String> {
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
    let t_reached = summary["t_reached"].as_f64().unwrap_or(f64::NAN);
    let mut angles = Vec::new();
    let mut above = Vec::new();
    let (mut free, mut stuck, mut r) = (0, 0, f64::NAN);
    for path in &files {
        let rows = read_particles_csv(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let t = rows.first().map_or(f64::NAN, |r| r.values[0]);
        let centres: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.stuck_to.is_none())
            .map(|r| (r.values[4], r.values[6]))
            .collect();
        free = centres.len();
        stuck = rows.len() - free;
        r = rows
            .iter()
            .find(|r| r.stuck_to.is_none())
            .map_or(f64::NAN, |r| r.values[3]);
        if t < 0.5 * t_reached || centres.is_empty() {
            continue;
        }
        above.push(centres.iter().filter(|c| c.1 > 0.0).count() as f64 / centres.len() as f64);
        if let Some(a) = repose_angle(&surface_points(&centres, r), -0.8 * radius, 0.0) {
            angles.push((t, a));
        }
    }
    let a: Vec<f64> = angles.iter().map(|p| p.1).collect();
    Ok(TumblerRun {
        dir: dir.to_path_buf(),
        froude: omega * omega * radius / g,
        omega,
        radius,
        particle_radius: r,
        free,
        stuck,
        angle: mean_std(&a),
        angles,
        above_axis: mean_std(&above).0,
        status: summary["status"].as_str().unwrap_or("?").to_string(),
        t_reached,
        events_per_second: summary["events_per_second"].as_f64().unwrap_or(f64::NAN),
        wall_seconds: summary["wall_seconds"].as_f64().unwrap_or(f64::NAN),
        collisions: summary["collisions"].as_u64().unwrap_or(0),
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
        let a = repose_angle(&surface_points(&c, r), -24.0, 0.0).unwrap();
        assert!((a - 30.0).abs() < 3.0, "angle {a}");
        // A flat pile gives 0.
        let flat: Vec<(f64, f64)> = (-20..20)
            .flat_map(|i| [(2.0 * i as f64, 0.0), (2.0 * i as f64, -2.0)])
            .collect();
        let a0 = repose_angle(&surface_points(&flat, r), -24.0, 0.0).unwrap();
        assert!(a0.abs() < 1e-9, "flat angle {a0}");
        assert!(repose_angle(&[(0.0, 0.0)], -1.0, 1.0).is_none());
    }
}
