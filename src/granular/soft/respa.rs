//! Multiple time stepping for self-gravity: the impulse method / r-RESPA (Tuckerman, Berne & Martyna 1992, J. Chem.
//! Phys. 97, 1990; Zhang17 §2.1 uses one leapfrog step for all forces, this splits them). Self-gravity changes on
//! `1/√(Gρ)`, contacts on the contact time, so gravity is evaluated once per block of `k` steps:
//! `v += a_slow k dt/2`, then `k` × (`v += F/m dt/2; x += v dt; F(x); v += F/m dt/2`), then `a_slow(x)`,
//! `v += a_slow k dt/2`.
//!
//! A symmetric composition of symplectic, time-reversible maps, so a block is both; momenta are conserved to rounding
//! when the slow forces are pairwise (direct summation); `k = 1` is plain leapfrog. The impulse method's resonance
//! (`k dt` near a multiple of half a fast period) is avoided by [`crate::granular::soft::advise::gravity_interval`].
//! Mid-block the velocities carry the opening kick and the gravitational energy is the block start's, so energies
//! are exact only at block ends (`SoftSystem::gravity_phase == 0`).

use crate::granular::soft::forces::SoftSystem;
use crate::granular::soft::ordered_sum::ordered_sum;
use crate::gravity::accelerations;
use crate::math::Vec3;
use crate::phase::{Kind, Phase};
use rayon::prelude::*;

static PHASE_SLOW_GATHER: Phase = Phase::new("soft.slow_gather", Kind::Parallel);
static PHASE_SLOW_ENERGY: Phase = Phase::new("soft.slow_energy", Kind::Parallel);

impl SoftSystem {
    /// Whether self-gravity is on and split off as the slow force (`gravity_interval > 1`).
    pub fn split_gravity(&self) -> bool {
        self.gravity_interval > 1 && self.gravity.self_gravity.is_some()
    }

    /// Evaluates self-gravity at the current positions into [`SoftSystem::slow_accelerations`] and
    /// [`SoftSystem::slow_energy`], and updates the gravitational energy of the last evaluation to match.
    pub fn update_slow_gravity(&mut self) {
        let n = self.particles.len();
        let (acc, pot) = match self.gravity.self_gravity {
            Some(mode) if n > 1 => {
                let (positions, masses): (Vec<Vec3>, Vec<f64>) =
                    PHASE_SLOW_GATHER.time(|| self.particles.par_iter().map(|p| (p.position, p.mass)).unzip());
                accelerations(mode, &positions, &masses, self.gravity.g)
            }
            _ => (vec![Vec3::zeros(); n], vec![0.0; n]),
        };
        // summed in fixed chunks: the same bits on any number of threads
        let ps = &self.particles;
        let energy = PHASE_SLOW_ENERGY.time(|| ordered_sum(n, |k| 0.5 * ps[k].mass * pot[k]));
        self.stats.gravitational_energy += energy - self.slow_energy;
        self.slow_energy = energy;
        self.slow_accelerations = acc;
    }
}

/// The opening slow kick of a block, before the fast step from time `t`: its `τ` (s) if the step opens a block
/// (the caller gives the kick, in the step's first pass), evaluating the slow force first if it is missing (a
/// system set up without [`SoftSystem::compute_forces`]).
pub(crate) fn open_block(sys: &mut SoftSystem, dt: f64) -> Option<f64> {
    if !sys.split_gravity() || sys.gravity_phase != 0 {
        return None;
    }
    if sys.slow_accelerations.len() != sys.particles.len() {
        sys.update_slow_gravity();
    }
    Some(0.5 * sys.gravity_interval as f64 * dt)
}

/// Counts the fast step just taken (its forces evaluated, its closing fast kick not yet given); at the block's
/// end evaluates the slow force (positions only: the fast kick does not change it) and returns the closing slow
/// kick's `τ` (s), which the caller gives after the fast kick.
pub(crate) fn close_block(sys: &mut SoftSystem, dt: f64) -> Option<f64> {
    if !sys.split_gravity() {
        return None;
    }
    sys.gravity_phase += 1;
    if sys.gravity_phase >= sys.gravity_interval {
        sys.update_slow_gravity();
        sys.gravity_phase = 0;
        return Some(0.5 * sys.gravity_interval as f64 * dt);
    }
    None
}
