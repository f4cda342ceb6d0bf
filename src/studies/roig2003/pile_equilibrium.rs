//! Is a relaxed rubble pile in equilibrium under another contact potential? The drift of a pile run alone,
//! measured against the rigid rotation it started with.
//!
//! The Roig03 targets (`targets/N*_T*.csv`) were relaxed with κ from Eq. 14 as printed (16.94 for N200), while the
//! impacts run at the reduced reading's κ (11.44; `analysis/roig2003/DISCUSSION.md`). A softer κ moves the
//! minimum of the pair potential (Roig03 Fig. 1) and so the pile's equilibrium: left alone it would settle,
//! and that settling would be kinetic energy the impact did not give. Two measures, both zero for a pile that
//! keeps turning rigidly:
//! * `K_rel / K` at time `t`: the kinetic energy relative to the best-fit rigid rotation
//!   ([`fit_rigid_rotation`], the target builder's rigidity criterion), and `K_rel` itself (J);
//! * the displacement of every body from where the initial rigid rotation carries it: each offset from the
//!   centre of mass at `t = 0`, turned by `Ω₀ t` about the axis of `Ω₀`, against its offset at `t` (rms and
//!   largest, m).

use rubblepile::ellipsoid::body::Body;
use rubblepile::ellipsoid::rigid_rotation::fit_rigid_rotation;
use rubblepile::math::Vec3;

/// The drift of a pile between `t = 0` and `t`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PileDrift {
    /// Time since `t = 0` (s).
    pub time: f64,
    /// `K_rel / K` at `t` (dimensionless).
    pub non_rigid_fraction: f64,
    /// `K_rel` at `t` (J).
    pub kinetic_relative: f64,
    /// Kinetic energy at `t` in the centre-of-mass frame (J).
    pub kinetic: f64,
    /// Root-mean-square displacement of the bodies from the initial rigid rotation (m).
    pub rms_displacement: f64,
    /// Largest displacement of a body from the initial rigid rotation (m).
    pub max_displacement: f64,
}

fn centre_of_mass(bodies: &[Body]) -> Vec3 {
    let mass: f64 = bodies.iter().map(|b| b.shape.mass).sum();
    bodies.iter().map(|b| b.position * b.shape.mass).sum::<Vec3>() / mass
}

/// [`PileDrift`] of `at` (the state at `time`, s) against `initial` (the same bodies at `t = 0`, same order),
/// the moments those of Eq. 4 with `kappa_inertia`. `None` when the snapshots differ in length or are empty.
pub fn pile_drift(initial: &[Body], at: &[Body], time: f64, kappa_inertia: f64) -> Option<PileDrift> {
    if initial.len() != at.len() || initial.is_empty() {
        return None;
    }
    let moments: Vec<Vec3> = at.iter().map(|b| b.shape.principal_moments(kappa_inertia)).collect();
    let omega0 = fit_rigid_rotation(initial, &moments).omega;
    let now = fit_rigid_rotation(at, &moments);
    let turn = nalgebra::Rotation3::new(omega0 * time);
    let (c0, c) = (centre_of_mass(initial), centre_of_mass(at));
    let distances: Vec<f64> = initial
        .iter()
        .zip(at)
        .map(|(b0, b)| ((b.position - c) - turn * (b0.position - c0)).norm())
        .collect();
    let n = distances.len() as f64;
    Some(PileDrift {
        time,
        non_rigid_fraction: now.non_rigid_fraction(),
        kinetic_relative: now.kinetic_relative,
        kinetic: now.kinetic,
        rms_displacement: (distances.iter().map(|d| d * d).sum::<f64>() / n).sqrt(),
        max_displacement: distances.iter().copied().fold(0.0, f64::max),
    })
}
