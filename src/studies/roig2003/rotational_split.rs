//! How much of the fragments' rotational energy an impact gave them, and how much they already had (Roig03 §4.1,
//! Fig. 2a: "between 10–20 %" remains in rotation). Eq. 5's `K_R = Σ ωᵢᵀ Iᵢ ωᵢ / 2` counts the targets' own
//! pre-impact spin (4 h or 12 h); two ways to take it out, both zero for a target that keeps turning rigidly:
//! in the frame of the initial spin, `K_R,add = Σ ½ (wᵢ − Ω₀)ᵀ Tᵢ (wᵢ − Ω₀)` (world-frame spin and inertia at the
//! analysis time, `Ω₀` the best-fit rigid rotation at t = 0, [`fit_rigid_rotation`]); per fragment, with each
//! fragment's own spin at t = 0 in place of `Ω₀`. `K_R − K_R,add` is the pre-existing part. The translational energy
//! compared with it is taken in the system's barycentric frame (as [`rubblepile::analysis::fragments`]) and, as a
//! variant, in the target fragments' barycentre (Fig. 3's frame), which removes the target's recoil.

use rubblepile::ellipsoid::body::Body;
use rubblepile::ellipsoid::quaternion::rotation_matrix;
use rubblepile::ellipsoid::rigid_rotation::fit_rigid_rotation;
use rubblepile::math::{Mat3, Vec3};

/// The energies of the target fragments (projectile excluded), all in J.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct RotationalSplit {
    /// `K_R` at the analysis time (Roig03 Eq. 5's rotational term over the target fragments).
    pub rotational: f64,
    /// `K_R` at `t = 0`: the targets' own spin energy before the impact.
    pub rotational_initial: f64,
    /// `K_R,add` in the frame of the target's initial rigid rotation `Ω₀` (module docs).
    pub added_spin_frame: f64,
    /// `K_R,add` against each fragment's own spin at `t = 0` (module docs).
    pub added_per_fragment: f64,
    /// Translational kinetic energy in the barycentric frame of all bodies (projectile included).
    pub translational_system: f64,
    /// Translational kinetic energy in the barycentric frame of the target fragments.
    pub translational_target: f64,
    /// `|Ω₀|`, the target's initial rigid spin rate (rad/s).
    pub initial_spin_rate: f64,
}

impl RotationalSplit {
    /// `K_R / (K_T + K_R)`, `K_T` in the system's frame (the share `rubblepile analyze` reports).
    pub fn share(&self) -> f64 {
        ratio(self.rotational, self.translational_system + self.rotational)
    }

    /// `K_R / (K_T + K_R)`, `K_T` in the target's barycentric frame.
    pub fn share_target_frame(&self) -> f64 {
        ratio(self.rotational, self.translational_target + self.rotational)
    }

    /// `K_R,add / (K_T + K_R)` in the frame of the initial spin, `K_T` in the system's frame: the share of the
    /// impact's own spin.
    pub fn added_share(&self) -> f64 {
        ratio(self.added_spin_frame, self.translational_system + self.rotational)
    }

    /// `1 − K_R,add / K_R` in the frame of the initial spin: the pre-existing fraction of `K_R`.
    pub fn pre_existing_fraction(&self) -> f64 {
        1.0 - ratio(self.added_spin_frame, self.rotational)
    }

    /// `1 − K_R,add / K_R` against each fragment's own initial spin.
    pub fn pre_existing_fraction_per_fragment(&self) -> f64 {
        1.0 - ratio(self.added_per_fragment, self.rotational)
    }
}

fn ratio(a: f64, b: f64) -> f64 {
    if b > 0.0 { a / b } else { 0.0 }
}

/// World-frame spin and inertia tensor of a body whose principal moments are `moments` (kg m²).
fn world_spin_and_tensor(body: &Body, moments: &Vec3) -> (Vec3, Mat3) {
    let rot = rotation_matrix(&body.quaternion);
    (
        rot.transpose() * body.spin_body,
        rot.transpose() * Mat3::from_diagonal(moments) * rot,
    )
}

fn mean_velocity<'a>(bodies: impl Iterator<Item = &'a Body>) -> Vec3 {
    let (mut p, mut m) = (Vec3::zeros(), 0.0);
    for b in bodies {
        p += b.velocity * b.shape.mass;
        m += b.shape.mass;
    }
    if m > 0.0 { p / m } else { Vec3::zeros() }
}

/// [`RotationalSplit`] of the bodies at the analysis time (`at`) against `t = 0` (`initial`; the same bodies in
/// the same order), the target being every body for which `is_target(index)` holds, the moments those of Eq. 4
/// with `kappa_inertia` (Roig03's κ for Gaussian bodies, 5/2 for uniform ones). `None` when the snapshots
/// differ in length or hold no target body.
pub fn rotational_split(
    initial: &[Body],
    at: &[Body],
    kappa_inertia: f64,
    is_target: impl Fn(usize) -> bool,
) -> Option<RotationalSplit> {
    if initial.len() != at.len() {
        return None;
    }
    let targets: Vec<usize> = (0..at.len()).filter(|i| is_target(*i)).collect();
    if targets.is_empty() {
        return None;
    }
    let moments: Vec<Vec3> = targets
        .iter()
        .map(|&i| at[i].shape.principal_moments(kappa_inertia))
        .collect();
    let initial_targets: Vec<Body> = targets.iter().map(|&i| initial[i].clone()).collect();
    let omega0 = fit_rigid_rotation(&initial_targets, &moments).omega;
    let v_system = mean_velocity(at.iter());
    let v_target = mean_velocity(targets.iter().map(|&i| &at[i]));
    let mut split = RotationalSplit {
        rotational: 0.0,
        rotational_initial: 0.0,
        added_spin_frame: 0.0,
        added_per_fragment: 0.0,
        translational_system: 0.0,
        translational_target: 0.0,
        initial_spin_rate: omega0.norm(),
    };
    for (&i, moment) in targets.iter().zip(&moments) {
        let (b0, b) = (&initial[i], &at[i]);
        let (w, tensor) = world_spin_and_tensor(b, moment);
        let (w0, _) = world_spin_and_tensor(b0, moment);
        let spin_energy = |d: Vec3| 0.5 * d.dot(&(tensor * d));
        split.rotational += 0.5 * b.spin_body.dot(&moment.component_mul(&b.spin_body));
        split.rotational_initial += 0.5 * b0.spin_body.dot(&moment.component_mul(&b0.spin_body));
        split.added_spin_frame += spin_energy(w - omega0);
        split.added_per_fragment += spin_energy(w - w0);
        split.translational_system += 0.5 * b.shape.mass * (b.velocity - v_system).norm_squared();
        split.translational_target += 0.5 * b.shape.mass * (b.velocity - v_target).norm_squared();
    }
    Some(split)
}
