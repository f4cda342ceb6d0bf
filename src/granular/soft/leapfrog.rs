//! Kick–drift–kick leapfrog with a fixed step (Zhang17 §2.1: "a second-order leapfrog method").
//!
//! `v += F/m dt/2, ω += τ/I dt/2` (kick), `x += v dt` (drift), forces at the new positions with the
//! half-step velocities and spins (the springs advance by the relative motion over the drift), kick again.
//! For central pair forces and the contact law's equal and opposite forces and torques, every kick and drift
//! conserves total linear and angular momentum up to rounding. With `gravity_interval = k > 1` self-gravity
//! is kicked separately once per block of `k` steps ([`crate::granular::soft::respa`]).

//!
//! Every kick and drift is a loop over the spheres, each sphere on its own: they run in parallel (tasks of
//! `SUM_CHUNK` spheres) with the same bits on any number of threads.

use crate::granular::soft::forces::{SUM_CHUNK, SoftSystem};
use crate::granular::soft::respa::{close_block, open_block};
use crate::phase::{Kind, Phase};
use rayon::prelude::*;

static PHASE_KICK: Phase = Phase::new("soft.kick", Kind::Parallel);
static PHASE_DRIFT: Phase = Phase::new("soft.drift", Kind::Parallel);

fn kick(sys: &mut SoftSystem, half_dt: f64) {
    PHASE_KICK.time(|| {
        sys.particles
            .par_iter_mut()
            .zip(&sys.forces)
            .zip(&sys.torques)
            .with_min_len(SUM_CHUNK)
            .for_each(|((p, f), tau)| {
                p.velocity += f * (half_dt / p.mass);
                p.spin += tau * (half_dt / p.inertia());
            })
    })
}

/// Advances `sys` from time `t` (s) by one step `dt` (s). The forces of `sys` must be those at `t`
/// (from [`SoftSystem::compute_forces`] or the previous step).
pub fn step(sys: &mut SoftSystem, t: f64, dt: f64) {
    open_block(sys, dt);
    kick(sys, 0.5 * dt);
    PHASE_DRIFT.time(|| {
        sys.particles
            .par_iter_mut()
            .with_min_len(SUM_CHUNK)
            .for_each(|p| p.position += p.velocity * dt)
    });
    sys.compute_forces(t + dt, dt);
    kick(sys, 0.5 * dt);
    close_block(sys, dt);
}
