//! Outcome of a tidal flyby run: mass lost, the largest remnant's spin and shape before and after, and a class after
//! Richardson, Bottke & Love 1998 (Icarus 134, 47–76; "RBL98").
//!
//! Largest remnant by peeling: drop every body with `½ |v − v_S|² − G (M_S − m)/|r − r_S| ≥ 0` (S the set without
//! the body) until none drops; mass lost = 1 − M_LR/M. Spin `ω = I⁻¹ L` about its centre of mass, period `2π/|ω|` (h);
//! shape the uniform ellipsoid of its inertia, `a² = 5 (I₂ + I₃ − I₁)/(2M)` (cyclic), as `b/a`, `c/a`; spin state per
//! [`crate::ellipsoid::spin_state`]. The tide's effect is the run's change minus its control run's (`DIR/control/`,
//! no planet), else the run's own (`tide.from_control = false`). Class (our thresholds after RBL98's S/B/M/N):
//! `disrupted` (≥ 50 % of the mass taken), `mass loss` (any fragment), `reshaped` (`b/a` or `c/a` moved by
//! ≥ [`RESHAPE_THRESHOLD`]), `spin changed` (`π|L|/E` moved by ≥ [`SPIN_CHANGE_THRESHOLD`]; a constant of free
//! tumbling, so a tumbler's phase does not enter), else `unaffected`.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::analysis::clumps::mass_mean;
use crate::ellipsoid::body::Body;
use crate::ellipsoid::equations::G_SI;
use crate::ellipsoid::quaternion::rotation_matrix;
use crate::ellipsoid::rigid_rotation::fit_rigid_rotation;
use crate::ellipsoid::spin_state::{SpinState, spin_state_of_fit};
use crate::impact::flyby::CONTROL_DIR;
use crate::impact::run::read_target;
use crate::impact::settle::SettleReport;
use crate::math::{Mat3, Vec3};

/// Change of `b/a` or `c/a` (absolute, run minus control) from which a pile that lost no mass counts as reshaped.
pub const RESHAPE_THRESHOLD: f64 = 0.02;
/// Change of the invariant period `π|L|/E` (run minus control, relative to its value before) from which a pile
/// that kept its mass and shape counts as `spin changed`.
pub const SPIN_CHANGE_THRESHOLD: f64 = 0.01;
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
    /// Rotation state of the remnant read as a rigid body.
    pub spin: SpinState,
}

/// One run's remnant before and after (the run with the planet, or its control).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunRemnants {
    /// Largest remnant at the first snapshot.
    pub before: Remnant,
    /// Largest remnant at the last snapshot.
    pub after: Remnant,
    /// Mass lost from the largest remnant, `1 − M_after/M_total` (fraction).
    pub mass_lost: f64,
    /// `P_after − P_before` (h), `P = 2π/|ω|`.
    pub delta_period_hours: f64,
}

/// The tide's effect: the run's changes minus the control's (module docs).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TideEffect {
    /// Whether a control run was subtracted (false: the run's own changes).
    pub from_control: bool,
    /// Mass fraction lost from the remnant.
    pub mass_lost: f64,
    /// Fragments lost from the remnant (the control's remnant's count minus the run's, at the end).
    pub fragments_lost: i64,
    /// Change of `2π/|ω|` (h).
    pub delta_period_hours: f64,
    /// Change of the invariant period `π|L|/E` (h).
    pub delta_invariant_period_hours: f64,
    /// Change of `b/a`.
    pub delta_b_over_a: f64,
    /// Change of `c/a`.
    pub delta_c_over_a: f64,
}

/// `analysis/flyby.json`: before (first snapshot) and after (last snapshot), of the run and of its control.
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
    /// The control run's remnants (`DIR/control/`), when there is one.
    pub control: Option<RunRemnants>,
    /// The tide's effect: run minus control.
    pub tide: TideEffect,
    /// How the pile was settled before the run (from `flyby.json`), when it was.
    pub settling: Option<SettleReport>,
    /// `disrupted`, `mass loss`, `reshaped`, `spin changed` or `unaffected`, from [`FlybyOutcome::tide`] (module
    /// docs).
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
        let r = mass_mean(bodies, &set, m, |b| b.position);
        let v = mass_mean(bodies, &set, m, |b| b.velocity);
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
    let r = mass_mean(bodies, &ids, m, |b| b.position);
    let members: Vec<Body> = ids.iter().map(|&i| bodies[i].clone()).collect();
    let moments: Vec<Vec3> = members.iter().map(|b| b.shape.principal_moments(kappa_i)).collect();
    let fit = fit_rigid_rotation(&members, &moments);
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
        period_hours: fit.period() / 3600.0,
        b_over_a: (b2 / a2).sqrt(),
        c_over_a: (c2.max(0.0) / a2).sqrt(),
        a_m: a2.sqrt(),
        spin: spin_state_of_fit(&fit),
    }
}

/// The tide's effect from the run's remnants and, when there is one, the control's (module docs).
pub fn tide_effect(run: &RunRemnants, control: Option<&RunRemnants>) -> TideEffect {
    let change = |r: &RunRemnants| {
        (
            r.mass_lost,
            r.after.fragments as i64,
            r.delta_period_hours,
            r.after.spin.invariant_period_hours - r.before.spin.invariant_period_hours,
            r.after.b_over_a - r.before.b_over_a,
            r.after.c_over_a - r.before.c_over_a,
        )
    };
    let (lost, n, dp, dpi, db, dc) = change(run);
    match control {
        Some(c) => {
            let (lost_c, n_c, dp_c, dpi_c, db_c, dc_c) = change(c);
            TideEffect {
                from_control: true,
                mass_lost: lost - lost_c,
                fragments_lost: n_c - n,
                delta_period_hours: dp - dp_c,
                delta_invariant_period_hours: dpi - dpi_c,
                delta_b_over_a: db - db_c,
                delta_c_over_a: dc - dc_c,
            }
        }
        None => TideEffect {
            from_control: false,
            mass_lost: lost,
            fragments_lost: run.before.fragments as i64 - n,
            delta_period_hours: dp,
            delta_invariant_period_hours: dpi,
            delta_b_over_a: db,
            delta_c_over_a: dc,
        },
    }
}

/// Classifies the tide's effect `tide` on a pile whose invariant period before was `period_before_hours` (module
/// docs): the class and RBL98's letter.
pub fn classify(tide: &TideEffect, period_before_hours: f64) -> (String, String) {
    let lost = tide.mass_lost;
    let letter = if lost >= DISRUPTED_LOST_FRACTION {
        "S"
    } else if lost >= RBL98_B_LOST_FRACTION {
        "B"
    } else if tide.fragments_lost > 0 {
        "M"
    } else {
        "N"
    };
    let class = if lost >= DISRUPTED_LOST_FRACTION {
        "disrupted"
    } else if tide.fragments_lost > 0 {
        "mass loss"
    } else if tide.delta_b_over_a.abs() >= RESHAPE_THRESHOLD || tide.delta_c_over_a.abs() >= RESHAPE_THRESHOLD {
        "reshaped"
    } else if (tide.delta_invariant_period_hours / period_before_hours).abs() >= SPIN_CHANGE_THRESHOLD {
        "spin changed"
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

/// The largest remnant at the first and last snapshots of the run in `dir`.
pub fn run_remnants(dir: &Path) -> Result<RunRemnants, FlybyAnalysisError> {
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
    Ok(RunRemnants {
        mass_lost: 1.0 - after.mass_fraction,
        delta_period_hours: after.period_hours - before.period_hours,
        before,
        after,
    })
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
    // Read field by field: a control's flyby.json holds `"eccentricity": null` (infinite without a planet).
    let setup: serde_json::Value = std::fs::read_to_string(dir.join("flyby.json"))
        .ok()
        .and_then(|text| serde_json::from_str(&text).ok())
        .unwrap_or_default();
    let settling: Option<SettleReport> = serde_json::from_value(setup["settling"].clone()).ok();
    let run = run_remnants(dir)?;
    let control = if setup["control"].as_bool() == Some(true) && dir.join(CONTROL_DIR).join("snapshots").is_dir() {
        Some(run_remnants(&dir.join(CONTROL_DIR))?)
    } else {
        None
    };
    let tide = tide_effect(&run, control.as_ref());
    let (class, rbl98_class) = classify(&tide, run.before.spin.invariant_period_hours);
    let outcome = FlybyOutcome {
        mass_lost: run.mass_lost,
        delta_period_hours: run.delta_period_hours,
        before: run.before,
        after: run.after,
        control,
        tide,
        settling,
        class,
        rbl98_class,
    };
    let out = dir.join("analysis");
    let path = out.join("flyby.json");
    crate::io::safe_write::ensure_dir(&out)
        .and_then(|_| {
            let text = serde_json::to_string_pretty(&outcome).unwrap_or_default() + "\n";
            crate::io::safe_write::write_atomic(&path, text)
        })
        .map_err(|e| FlybyAnalysisError::File {
            path: path.clone(),
            message: crate::io::safe_write::reason(&e),
        })?;
    Ok(outcome)
}

/// One line on the settling: its time, `K_rel/K`, the period, and a warning when the cap was reached.
pub fn settling_line(s: &SettleReport) -> String {
    let head = if s.capped {
        format!(
            "warning: settling stopped at its cap of {:.2} h before K_rel/K fell below {:e}",
            s.max_time / 3600.0,
            crate::impact::settle::SETTLE_NON_RIGID_FRACTION
        )
    } else {
        format!("settled in {:.2} h", s.time / 3600.0)
    };
    format!(
        "{head}: K_rel/K {:.1e} -> {:.1e}, P {:.3} h -> {:.3} h{}",
        s.non_rigid_fraction_start,
        s.non_rigid_fraction,
        s.period_hours[0],
        s.period_hours[1],
        if s.set_to_principal {
            ", then set into principal-axis rotation about the largest moment"
        } else {
            ""
        }
    )
}

impl FlybyOutcome {
    /// One line for the terminal: class, the tide's effect, and the run's period and axis ratios before and after.
    pub fn one_line(&self) -> String {
        let t = &self.tide;
        format!(
            "flyby: {} (RBL98 {}), tide ({}): mass lost {:.4} of the target's, d(period) {:+.3} h (d(pi|L|/E) {:+.3} h), d(b/a) {:+.4}, d(c/a) {:+.4}; run: P {:.3} h -> {:.3} h, b/a {:.3} -> {:.3}, c/a {:.3} -> {:.3}",
            self.class,
            self.rbl98_class,
            if t.from_control {
                "run - control"
            } else {
                "run alone, no control"
            },
            t.mass_lost,
            t.delta_period_hours,
            t.delta_invariant_period_hours,
            t.delta_b_over_a,
            t.delta_c_over_a,
            self.before.period_hours,
            self.after.period_hours,
            self.before.b_over_a,
            self.after.b_over_a,
            self.before.c_over_a,
            self.after.c_over_a
        )
    }

    /// The lines for the terminal: the spin state before and after, then [`FlybyOutcome::one_line`].
    pub fn lines(&self) -> Vec<String> {
        vec![
            format!("before: {}", self.before.spin.describe()),
            format!("after: {}", self.after.spin.describe()),
            self.one_line(),
        ]
    }
}

/// Whether `dir` holds a flyby run: its `scene.toml` loads and has a `[physics.flyby]` section.
pub fn is_flyby_run(dir: &Path) -> bool {
    crate::ellipsoid::scene::load_scene(&dir.join("scene.toml")).is_ok_and(|s| s.tide.is_some())
}
