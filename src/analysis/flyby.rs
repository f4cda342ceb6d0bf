//! Outcome of a tidal flyby run (issue 20): mass lost, the largest remnant's spin period and shape before and
//! after, and a class after Richardson, Bottke & Love 1998 (Icarus 134, 47–76; "RBL98").
//!
//! - **Largest remnant**: the bodies bound to one another, found by peeling: start from all bodies; drop every
//!   body whose energy relative to the rest of the set, `½ |v − v_S|² − G (M_S − m)/|r − r_S|` (S the set's centre
//!   of mass, the body's own mass removed from it), is ≥ 0; repeat until none is dropped. Mass lost = 1 − M_LR/M.
//! - **Spin**: `ω = I⁻¹ L` about the remnant's centre of mass (orbital terms of the fragments plus their own spins,
//!   with the run's inertia model), period `2π/|ω|` (h).
//! - **Shape**: the semi-axes `a ≥ b ≥ c` of the uniform ellipsoid with the remnant's inertia tensor (fragments as
//!   uniform solids of their own axes, κ = 5/2): with principal moments `I₁ ≤ I₂ ≤ I₃`,
//!   `a² = 5 (I₂ + I₃ − I₁)/(2M)` etc.; reported as `b/a`, `c/a`.
//! - **Class** (our thresholds, after RBL98's S / B / M / N classes, which are by the fraction of mass shed):
//!   `disrupted` (RBL98 "S", Shoemaker–Levy-9-like): the remnant keeps < 50 % of the mass; `mass loss` (RBL98 "B"
//!   for 10–50 % lost, "M" below 10 %): any fragment lost; `reshaped` (RBL98 "N" with a shape change): no mass lost
//!   but `b/a` or `c/a` changed by ≥ [`RESHAPE_THRESHOLD`]; `unaffected` otherwise (the spin change is reported in
//!   every class).

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::ellipsoid::body::Body;
use crate::ellipsoid::equations::G_SI;
use crate::ellipsoid::quaternion::rotation_matrix;
use crate::impact::flyby::{FlybyArgs, run_flyby};
use crate::impact::run::read_target;
use crate::math::{Mat3, Vec3};

/// Change of `b/a` or `c/a` (absolute) from which a pile that lost no mass counts as reshaped.
pub const RESHAPE_THRESHOLD: f64 = 0.02;
/// Fraction of the mass the remnant must lose for a `disrupted` class (RBL98 "S": < 50 % retained).
pub const DISRUPTED_LOST_FRACTION: f64 = 0.5;
/// RBL98's boundary between "B" (break-up) and "M" (mild) mass loss.
pub const RBL98_B_LOST_FRACTION: f64 = 0.1;

/// The largest remnant of one snapshot.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Remnant {
    /// Time of the snapshot (s).
    pub t: f64,
    /// Number of fragments in it.
    pub fragments: usize,
    /// Its mass (kg).
    pub mass: f64,
    /// Its mass over the total.
    pub mass_fraction: f64,
    /// Spin period `2π/|ω|` (h).
    pub period_hours: f64,
    /// `b/a` of the equivalent uniform ellipsoid.
    pub b_over_a: f64,
    /// `c/a`.
    pub c_over_a: f64,
    /// Semi-major axis `a` of the equivalent ellipsoid (m).
    pub a_m: f64,
}

/// `analysis/flyby.json`: before (first snapshot) and after (last snapshot).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FlybyOutcome {
    /// Largest remnant at the first snapshot.
    pub before: Remnant,
    /// Largest remnant at the last snapshot.
    pub after: Remnant,
    /// Mass lost from the largest remnant, `1 − M_after/M_total` (fraction).
    pub mass_lost: f64,
    /// `P_after − P_before` (h).
    pub delta_period_hours: f64,
    /// `disrupted`, `mass loss`, `reshaped` or `unaffected` (module docs).
    pub class: String,
    /// RBL98's letter: S, B, M or N.
    pub rbl98_class: String,
}

/// Why a run cannot be analysed.
#[derive(Debug, thiserror::Error)]
pub enum FlybyAnalysisError {
    /// Another rubblepile process writes the run's `analysis/`
    /// ([`crate::analysis::run_analysis::lock_analysis`]).
    #[error(transparent)]
    Locked(#[from] crate::io::run_lock::LockError),
    /// A file is missing or unreadable.
    #[error("{}: {message}", .path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
}

/// The indices of the largest set of mutually bound bodies (module docs), with `g` (m³ kg⁻¹ s⁻²).
pub fn largest_remnant(g: f64, bodies: &[Body]) -> Vec<usize> {
    let mut set: Vec<usize> = (0..bodies.len()).collect();
    loop {
        let m: f64 = set.iter().map(|&i| bodies[i].shape.mass).sum();
        let r = set
            .iter()
            .map(|&i| bodies[i].position * bodies[i].shape.mass)
            .sum::<Vec3>()
            / m;
        let v = set
            .iter()
            .map(|&i| bodies[i].velocity * bodies[i].shape.mass)
            .sum::<Vec3>()
            / m;
        let kept: Vec<usize> = set
            .iter()
            .copied()
            .filter(|&i| {
                let b = &bodies[i];
                let rest = m - b.shape.mass;
                if rest <= 0.0 {
                    return true;
                }
                // Centre of mass of the rest of the set: the body's own mass removed.
                let rc = (r * m - b.position * b.shape.mass) / rest;
                let vc = (v * m - b.velocity * b.shape.mass) / rest;
                0.5 * (b.velocity - vc).norm_squared() - g * rest / (b.position - rc).norm() < 0.0
            })
            .collect();
        if kept.len() == set.len() || kept.is_empty() {
            return set;
        }
        set = kept;
    }
}

/// Inertia tensor (kg m²) about `centre` of `bodies[ids]`, each body's own tensor from its principal moments for
/// `kappa_i` (5/2: uniform solid).
fn inertia_tensor(bodies: &[Body], ids: &[usize], centre: &Vec3, kappa_i: f64) -> Mat3 {
    let mut t = Mat3::zeros();
    for &i in ids {
        let b = &bodies[i];
        let d = b.position - centre;
        t += b.shape.mass * (Mat3::identity() * d.norm_squared() - d * d.transpose());
        // R maps world to body: the body tensor in the world is Rᵀ diag(I) R.
        let rot = rotation_matrix(&b.quaternion.normalize());
        t += rot.transpose() * Mat3::from_diagonal(&b.shape.principal_moments(kappa_i)) * rot;
    }
    t
}

/// The largest remnant of `bodies` at time `t`, with the spin computed for the run's inertia (`kappa_i` of the model).
pub fn remnant(t: f64, g: f64, bodies: &[Body], kappa_i: f64) -> Remnant {
    let ids = largest_remnant(g, bodies);
    let total: f64 = bodies.iter().map(|b| b.shape.mass).sum();
    let m: f64 = ids.iter().map(|&i| bodies[i].shape.mass).sum();
    let r = ids
        .iter()
        .map(|&i| bodies[i].position * bodies[i].shape.mass)
        .sum::<Vec3>()
        / m;
    let v = ids
        .iter()
        .map(|&i| bodies[i].velocity * bodies[i].shape.mass)
        .sum::<Vec3>()
        / m;
    let mut l = Vec3::zeros();
    for &i in &ids {
        let b = &bodies[i];
        let rot = rotation_matrix(&b.quaternion.normalize());
        l += b.shape.mass * (b.position - r).cross(&(b.velocity - v));
        l += rot.transpose() * b.shape.principal_moments(kappa_i).component_mul(&b.spin_body);
    }
    let omega = inertia_tensor(bodies, &ids, &r, kappa_i)
        .try_inverse()
        .map_or(Vec3::zeros(), |inv| inv * l);
    let shape = inertia_tensor(bodies, &ids, &r, 2.5);
    let mut moments: Vec<f64> = shape.symmetric_eigen().eigenvalues.iter().copied().collect();
    moments.sort_by(f64::total_cmp);
    let k = 5.0 / (2.0 * m);
    let a2 = k * (moments[1] + moments[2] - moments[0]);
    let b2 = k * (moments[0] + moments[2] - moments[1]);
    let c2 = k * (moments[0] + moments[1] - moments[2]);
    Remnant {
        t,
        fragments: ids.len(),
        mass: m,
        mass_fraction: m / total,
        period_hours: 2.0 * std::f64::consts::PI / omega.norm() / 3600.0,
        b_over_a: (b2 / a2).sqrt(),
        c_over_a: (c2.max(0.0) / a2).sqrt(),
        a_m: a2.sqrt(),
    }
}

/// Classifies a flyby from the two remnants (module docs).
pub fn classify(before: &Remnant, after: &Remnant) -> (String, String) {
    let lost = 1.0 - after.mass_fraction;
    let letter = if lost >= DISRUPTED_LOST_FRACTION {
        "S"
    } else if lost >= RBL98_B_LOST_FRACTION {
        "B"
    } else if after.fragments < before.fragments {
        "M"
    } else {
        "N"
    };
    let class = if lost >= DISRUPTED_LOST_FRACTION {
        "disrupted"
    } else if after.fragments < before.fragments {
        "mass loss"
    } else if (after.b_over_a - before.b_over_a).abs() >= RESHAPE_THRESHOLD
        || (after.c_over_a - before.c_over_a).abs() >= RESHAPE_THRESHOLD
    {
        "reshaped"
    } else {
        "unaffected"
    };
    (class.into(), letter.into())
}

/// Snapshot files of the run in `dir` (`snapshots/<k>.csv`), in order of `k`.
fn snapshot_files(dir: &Path) -> Result<Vec<PathBuf>, FlybyAnalysisError> {
    let snaps = dir.join("snapshots");
    let entries = std::fs::read_dir(&snaps).map_err(|e| FlybyAnalysisError::File {
        path: snaps.clone(),
        message: e.to_string(),
    })?;
    let mut files: Vec<(u64, PathBuf)> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter_map(|p| {
            let k = p.file_stem()?.to_str()?.parse::<u64>().ok()?;
            (p.extension()? == "csv").then_some((k, p))
        })
        .collect();
    files.sort();
    if files.len() < 2 {
        return Err(FlybyAnalysisError::File {
            path: snaps,
            message: "need at least two snapshots (before and after)".into(),
        });
    }
    Ok(files.into_iter().map(|(_, p)| p).collect())
}

/// Analyses the flyby run in `dir` (first vs last snapshot) and writes `dir/analysis/flyby.json`, holding the lock
/// of `dir/analysis/` (refused at once, [`FlybyAnalysisError::Locked`], while another process writes it).
pub fn analyze_flyby(dir: &Path) -> Result<FlybyOutcome, FlybyAnalysisError> {
    let _lock = match crate::analysis::run_analysis::lock_analysis(dir, "scene.toml") {
        Ok(lock) => lock,
        Err(crate::analysis::run_analysis::AnalysisError::Locked(e)) => return Err(e.into()),
        Err(e) => {
            return Err(FlybyAnalysisError::File {
                path: dir.join("analysis"),
                message: e.to_string(),
            });
        }
    };
    let files = snapshot_files(dir)?;
    let scene = crate::ellipsoid::scene::load_scene(&dir.join("scene.toml")).ok();
    let (g, kappa_i) = scene.as_ref().map_or((G_SI, 2.5), |s| {
        (
            s.physics.gravity.map_or(G_SI, |g| g.g),
            s.model.inertia.inertia_kappa(s.model.kappa),
        )
    });
    let read = |p: &PathBuf| -> Result<(f64, Vec<Body>), FlybyAnalysisError> {
        let bodies = read_target(p).map_err(|e| FlybyAnalysisError::File {
            path: p.clone(),
            message: e.to_string(),
        })?;
        let t = crate::io::particles::read_particles(p, &["t"], &[])
            .ok()
            .and_then(|rows| rows.first().map(|r| r.values[0]))
            .unwrap_or(0.0);
        Ok((t, bodies))
    };
    let (t0, first) = read(&files[0])?;
    let (t1, last) = read(&files[files.len() - 1])?;
    let before = remnant(t0, g, &first, kappa_i);
    let after = remnant(t1, g, &last, kappa_i);
    let (class, rbl98_class) = classify(&before, &after);
    let outcome = FlybyOutcome {
        mass_lost: 1.0 - after.mass_fraction,
        delta_period_hours: after.period_hours - before.period_hours,
        before,
        after,
        class,
        rbl98_class,
    };
    let out = dir.join("analysis");
    let path = out.join("flyby.json");
    std::fs::create_dir_all(&out)
        .and_then(|_| std::fs::write(&path, serde_json::to_string_pretty(&outcome).unwrap_or_default() + "\n"))
        .map_err(|e| FlybyAnalysisError::File {
            path: path.clone(),
            message: e.to_string(),
        })?;
    Ok(outcome)
}

/// `rubblepile flyby`: prepares and runs the flyby of `args` ([`run_flyby`]), then analyses it ([`analyze_flyby`]);
/// returns the lines to print, or the message and exit code (2 bad input, 1 failed run, 3 stopped on request).
pub fn flyby_command(args: &FlybyArgs) -> Result<Vec<String>, (String, u8)> {
    let summary = run_flyby(args, &crate::driver::RunOptions::default()).map_err(|e| (e.to_string(), e.exit_code()))?;
    let Some(summary) = summary else {
        return Ok(vec![format!("wrote {}", args.out.join("scene.toml").display())]);
    };
    let o = analyze_flyby(&args.out).map_err(|e| {
        let code = if matches!(e, FlybyAnalysisError::Locked(_)) {
            2
        } else {
            1
        };
        (e.to_string(), code)
    })?;
    Ok(vec![summary.one_line(), o.one_line()])
}

impl FlybyOutcome {
    /// One line for the terminal: class, mass lost, period and axis ratios before and after.
    pub fn one_line(&self) -> String {
        format!(
            "flyby: {} (RBL98 {}): mass lost {:.4}, P {:.3} h -> {:.3} h, b/a {:.3} -> {:.3}, c/a {:.3} -> {:.3}",
            self.class,
            self.rbl98_class,
            self.mass_lost,
            self.before.period_hours,
            self.after.period_hours,
            self.before.b_over_a,
            self.after.b_over_a,
            self.before.c_over_a,
            self.after.c_over_a
        )
    }
}

/// Whether `dir` holds a flyby run: its `scene.toml` loads and has a `[physics.flyby]` section.
pub fn is_flyby_run(dir: &Path) -> bool {
    crate::ellipsoid::scene::load_scene(&dir.join("scene.toml")).is_ok_and(|s| s.tide.is_some())
}
