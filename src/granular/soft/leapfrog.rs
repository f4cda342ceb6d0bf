//! Kick–drift–kick leapfrog with a fixed step (Zhang17 §2.1: "a second-order leapfrog method").
//!
//! `v += F/m dt/2, ω += τ/I dt/2` (kick), `x += v dt` (drift), forces at the new positions with the
//! half-step velocities and spins (the springs advance by the relative motion over the drift), kick again.
//! For central pair forces and the contact law's equal and opposite forces and torques, every kick and drift
//! conserves total linear and angular momentum up to rounding. With `gravity_interval = k > 1` self-gravity
//! is kicked separately once per block of `k` steps ([`crate::granular::soft::respa`]).
//!
//! Every kick and drift treats each sphere on its own, so they run in parallel with the same bits on any number of
//! threads. A step's passes are fused (the same operations per sphere, in the same order): the opening slow kick,
//! kick, drift, Verlet-list staleness check and (for a run) the copy of the state before the step in one pass; the
//! force evaluation; the closing kick and slow kick in one pass (fewer fork–joins and less memory traffic).

use crate::granular::soft::forces::SoftSystem;
use crate::granular::soft::particle::Particle;
use crate::granular::soft::respa::{close_block, open_block};

/// Advances `sys` from time `t` (s) by one step `dt` (s). The forces of `sys` must be those at `t`
/// (from [`SoftSystem::compute_forces`] or the previous step).
pub fn step(sys: &mut SoftSystem, t: f64, dt: f64) {
    step_keeping(sys, t, dt, None);
}

/// [`step`], also copying the state before the step into `before` (resized to the spheres), in the step's first
/// pass (a run keeps it for `last_good_state.csv`).
pub fn step_keeping(sys: &mut SoftSystem, t: f64, dt: f64, before: Option<&mut Vec<Particle>>) {
    let slow = open_block(sys, dt);
    sys.open_step(before, slow, 0.5 * dt, dt);
    sys.compute_forces(t + dt, dt);
    let slow = close_block(sys, dt);
    sys.close_step(slow, 0.5 * dt);
}
