//! Rubble-pile projectiles: a whole pile of ellipsoids (a target file of `rubblepile target build`)
//! thrown at the target instead of Roig03 §3's single ellipsoid.
//!
//! The projectile pile keeps its own internal state (relative positions, velocities, spins: a relaxed pile
//! spinning rigidly); it is moved to its own centre-of-mass frame, optionally turned by a seeded random
//! attitude (the same draw, [`random_quaternion`] of the run's seed, as the single ellipsoid's), then
//! translated rigidly along the impact direction `n = (0, sin ζ, cos ζ)` and given the velocity `−v n`, so that
//! the closest surfaces of the two piles first touch at `contact_time` (the ellipsoids' overlap test of
//! [`crate::impact::projectile::contact_walk`], as for a single projectile). The whole system is then moved to its
//! centre-of-mass frame. Bodies `0..N_t` are the target's, `N_t..N_t + N_p` the projectile's.
//! `Q = ½ M_p v² / M_t` uses the pile's total mass `M_p`.

use std::path::{Path, PathBuf};

use crate::ellipsoid::body::Body;
use crate::ellipsoid::quaternion::{from_unit_quaternion, to_unit_quaternion};
use crate::impact::error::{ImpactError, read_target};
use crate::impact::geometry::{Aim, ImpactGeometry};
pub use crate::impact::projectile::PileRecord;
use crate::impact::projectile::{
    ERG_PER_G_PER_J_PER_KG, ImpactSetup, ProjectileSpec, contact_walk, target_and_direction,
};
use crate::impact::target::to_centre_of_mass_frame;
use crate::random::{generator, random_quaternion};

/// A rubble-pile projectile: the bodies of a pile file (any frame, any N and spin).
#[derive(Debug, Clone, PartialEq)]
pub struct ProjectilePile {
    /// The bodies file it was read from (recorded in `impact.json`).
    pub file: PathBuf,
    /// Its bodies as read.
    pub bodies: Vec<Body>,
    /// Whether the pile is turned by a random attitude drawn from the run's seed (default true); false keeps
    /// the file's orientation.
    pub random_attitude: bool,
}

/// Turns an error reading a pile file into [`ImpactError::Invalid`] naming `field` (the file and the reason in
/// the message).
pub fn as_field(field: &str) -> impl Fn(ImpactError) -> ImpactError + '_ {
    move |e| ImpactError::invalid(field, e.to_string())
}

impl ProjectilePile {
    /// Reads a pile from a bodies file (the checks of [`read_target`]: at least one body, finite values,
    /// mass > 0, `A >= B >= C > 0`).
    pub fn read(file: &Path, random_attitude: bool) -> Result<Self, ImpactError> {
        Ok(ProjectilePile {
            file: file.to_path_buf(),
            bodies: read_target(file)?,
            random_attitude,
        })
    }

    /// Its name in run titles and as the projectile id: `pile-` and the file stem.
    pub fn id(&self) -> String {
        let stem = self.file.file_stem().map(|s| s.to_string_lossy().into_owned());
        format!("pile-{}", stem.unwrap_or_default())
    }

    /// Total mass (kg).
    pub fn mass(&self) -> f64 {
        self.bodies.iter().map(|b| b.shape.mass).sum()
    }

    /// The single-ellipsoid projectile of the same mass and solid volume (density = mass / Σ volumes; the
    /// fragments' 1 : 0.7 : 0.5 shape) at `speed` (m/s), named `id`: what the campaign and the run title show,
    /// and the same-mass ellipsoid to compare with.
    pub fn equivalent_spec(&self, id: String, speed: f64) -> ProjectileSpec {
        let volume: f64 = self.bodies.iter().map(|b| b.shape.volume()).sum();
        let mut spec = ProjectileSpec::custom(id, (3.0 * volume / (4.0 * std::f64::consts::PI)).cbrt(), speed);
        spec.density = self.mass() / volume;
        spec
    }

    /// The pile's bodies in its own centre-of-mass frame, turned by the seeded random attitude when
    /// [`ProjectilePile::random_attitude`] (positions, velocities and attitudes rotated together: a rigid turn
    /// of the whole pile, so its internal state and body-frame spins are unchanged).
    pub fn oriented_bodies(&self, seed: u64) -> Vec<Body> {
        let mut bodies = self.bodies.clone();
        to_centre_of_mass_frame(&mut bodies);
        if self.random_attitude {
            // The run's seed, as for the single ellipsoid's attitude.
            let turn = to_unit_quaternion(&random_quaternion(&mut generator(seed)));
            let q = turn.to_rotation_matrix();
            for b in &mut bodies {
                b.position = q * b.position;
                b.velocity = q * b.velocity;
                // `to_unit_quaternion` is body → world: turning the world by `turn` composes on the left.
                b.quaternion = from_unit_quaternion(&(turn * to_unit_quaternion(&b.quaternion)));
            }
        }
        bodies
    }
}

/// Adds the projectile pile to `target` (any frame) and returns the whole system in its centre-of-mass frame
/// with the setup: the pile's bodies (`projectile.speed` is the impact speed, the rest of `projectile`
/// is recorded as given) follow the target's, placed so that the closest surfaces first touch at
/// `contact_time` (s), moving at `−speed n` relative to the target, aimed by `geometry` (its aim only: a pile keeps
/// its own spin and attitude); and whether the pile meets the target, as for
/// [`crate::impact::projectile::set_up_aimed_impact`].
pub fn set_up_aimed_pile_impact(
    target: &[Body],
    pile: &ProjectilePile,
    projectile: &ProjectileSpec,
    geometry: &ImpactGeometry,
    angle_deg: f64,
    contact_time: f64,
    seed: u64,
) -> (Vec<Body>, ImpactSetup, bool) {
    let (mut bodies, target_mass, n) = target_and_direction(target, angle_deg);
    let n_t = bodies.len();
    let mut incoming = pile.oriented_bodies(seed);
    let aiming = geometry.aiming(&bodies, &n);
    if geometry.aim != Aim::Centre {
        incoming.iter_mut().for_each(|b| b.position += aiming.offset);
    }
    let (touch, touched) = contact_walk(&bodies, &incoming, &n);
    let start = touch + projectile.speed * contact_time;
    bodies.extend(incoming.into_iter().map(|mut b| {
        b.position += n * start;
        b.velocity -= n * projectile.speed;
        b
    }));
    to_centre_of_mass_frame(&mut bodies);
    let mass = pile.mass();
    let q = 0.5 * mass * projectile.speed.powi(2) / target_mass;
    let record = PileRecord {
        file: pile.file.display().to_string(),
        n: pile.bodies.len(),
        mass_kg: mass,
        random_attitude: pile.random_attitude,
        target_bodies: [0, n_t],
        projectile_bodies: [n_t, bodies.len()],
    };
    let setup = ImpactSetup {
        projectile: projectile.clone(),
        angle_deg,
        projectile_mass_kg: mass,
        target_mass_kg: target_mass,
        q_j_per_kg: q,
        q_erg_per_g: q * ERG_PER_G_PER_J_PER_KG,
        impact_time_s: contact_time,
        seed,
        projectile_index: n_t,
        projectile_pile: Some(record),
        geometry: (*geometry != ImpactGeometry::default()).then(|| aiming.record(geometry, &n)),
    };
    let hits = geometry.aim == Aim::Centre || (touched && aiming.aim_point.is_some());
    (bodies, setup, hits)
}
