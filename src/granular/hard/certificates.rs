//! Pair certificates kept across steps: for each listed pair of free particles, a time before which the pair cannot
//! touch, so that a drift start re-predicts only the pairs whose certificate has come due (Richardson11 §2.1 re-predicts
//! every pair at every drift start because the kicks change every velocity).
//!
//! Why a certificate survives the kicks: uniform gravity adds the same `g h/2` to the velocity of every free
//! particle, so the relative velocity `v_i − v_j` of two free particles, and with it their relative trajectory, is
//! not changed by a kick; only a collision of either particle (or its re-listing, or sticking to a wall) changes it.
//! The relative trajectory is then one straight line across any number of kick–drift–kick steps, and a time computed
//! from it at one moment stays valid at later drift starts (the event-calendar idea of event-driven molecular dynamics:
//! Lubachevsky 1991, J. Comput. Phys. 94, 255; Rapaport, *The Art of Molecular Dynamics Simulation*, ch. 14).
//!
//! The stepper still computes every event it queues exactly as before, from the positions and velocities at the drift
//! start: a certificate only decides which pairs need that prediction. So that it never skips a pair that the
//! prediction would have queued, the certificate is the time at which the pair first comes within `s + m` (contact
//! distance `s` plus a margin `m` that covers, many times over, the rounding by which the positions and velocities
//! the stepper will use at a later drift start differ from the straight relative line), and it expires after
//! [`HORIZON_STEPS`] steps however far apart the pair stays, which bounds that rounding. The runs' bits are therefore
//! those of re-predicting every pair at every drift start (`tests/hsdem_certificates.rs`).

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use crate::math::Vec3;

/// A certificate expires after this many steps (so the rounding it must cover stays bounded).
pub const HORIZON_STEPS: f64 = 64.0;

/// Relative margin on the contact distance (m = `MARGIN_RELATIVE · s` plus [`margin`]'s position terms). The
/// rounding it covers is of order 1e-16 per step relative to the positions: 1e-6 leaves a factor ~1e8.
pub const MARGIN_RELATIVE: f64 = 1e-6;

/// The margin (m) on the contact distance `s` of a pair whose particles sit at distances up to `x` from the origin
/// and move at speeds up to `v` under gravity `g`, for a certificate lasting `horizon` seconds: covers the rounding
/// of the positions (relative to `x`, growing with the travel) and of the contact distance.
pub fn margin(s: f64, x: f64, v: f64, g: f64, horizon: f64) -> f64 {
    MARGIN_RELATIVE * s + 1e-10 * (x + v * horizon + g * horizon * horizon)
}

/// The earliest time at which two particles whose separation is `r` at time `t` and changes at the constant rate `v`
/// can come within `s + m` of each other, capped at `t + horizon`: the certificate of the pair. `t` itself when they
/// are already that close (such a pair is re-predicted at every drift start, as the reference scheme does).
pub fn safe_until(t: f64, r: &Vec3, v: &Vec3, reach: f64, horizon: f64) -> f64 {
    let cap = t + horizon;
    let c = r.norm_squared() - reach * reach;
    if c <= 0.0 {
        return t;
    }
    let b = r.dot(v);
    if b >= 0.0 {
        // Separating: the distance only grows along a straight line.
        return cap;
    }
    let disc = b * b - v.norm_squared() * c;
    if disc < 0.0 {
        return cap;
    }
    // The smaller root, in the form that does not cancel (as the stepper's predictions).
    (t + c / (-b + disc.sqrt())).min(cap)
}

/// A certificate in the calendar: the pair `(i, j)`, `i < j`, needs a fresh prediction at the first drift start
/// whose drift reaches `t`; valid while both particles' certificate generations are those stored.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Due {
    /// When the certificate runs out (s).
    pub t: f64,
    /// The smaller particle index.
    pub i: usize,
    /// The larger particle index.
    pub j: usize,
    /// Certificate generation of `i` when certified.
    pub gen_i: u64,
    /// Certificate generation of `j` when certified.
    pub gen_j: u64,
}

impl Eq for Due {}

impl Ord for Due {
    /// Reversed (the heap is a max-heap): the earliest is the greatest; ties by the pair, so the order is total.
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .t
            .total_cmp(&self.t)
            .then_with(|| other.i.cmp(&self.i))
            .then_with(|| other.j.cmp(&self.j))
            .then_with(|| other.gen_i.cmp(&self.gen_i))
            .then_with(|| other.gen_j.cmp(&self.gen_j))
    }
}

impl PartialOrd for Due {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Certificates, earliest expiry first (stale ones are dropped lazily, when they come due).
#[derive(Debug, Clone, Default)]
pub struct Calendar {
    heap: BinaryHeap<Due>,
}

impl Calendar {
    /// Files a certificate.
    pub fn push(&mut self, d: Due) {
        self.heap.push(d);
    }

    /// Removes and returns every certificate that runs out at or before `t1`, in the calendar's order.
    pub fn take_due(&mut self, t1: f64, out: &mut Vec<Due>) {
        out.clear();
        while self.heap.peek().is_some_and(|d| d.t <= t1) {
            out.extend(self.heap.pop());
        }
    }

    /// Keeps only the certificates for which `keep` holds.
    pub fn retain(&mut self, keep: impl FnMut(&Due) -> bool) {
        self.heap.retain(keep);
    }

    /// Drops every certificate.
    pub fn clear(&mut self) {
        self.heap.clear();
    }

    /// Certificates filed (valid or stale).
    pub fn len(&self) -> usize {
        self.heap.len()
    }

    /// Whether no certificate is filed.
    pub fn is_empty(&self) -> bool {
        self.heap.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The certificate is the time of reaching the inflated contact distance, capped, and `t` when already there.
    #[test]
    fn certificate_times() {
        let r = Vec3::new(3.0, 0.0, 0.0);
        let v = Vec3::new(-1.0, 0.0, 0.0);
        assert!((safe_until(10.0, &r, &v, 1.0, 100.0) - 12.0).abs() < 1e-15);
        assert_eq!(safe_until(10.0, &r, &v, 1.0, 1.5), 11.5);
        assert_eq!(safe_until(10.0, &r, &(-v), 1.0, 100.0), 110.0, "separating");
        assert_eq!(
            safe_until(10.0, &r, &Vec3::new(0.0, 1.0, 0.0), 1.0, 7.0),
            17.0,
            "passing by"
        );
        assert_eq!(safe_until(10.0, &r, &v, 3.5, 100.0), 10.0, "already within reach");
    }

    #[test]
    fn calendar_takes_the_due_in_order() {
        let mut c = Calendar::default();
        for (t, i) in [(3.0, 0), (1.0, 5), (2.0, 1), (1.0, 2)] {
            c.push(Due {
                t,
                i,
                j: 9,
                gen_i: 0,
                gen_j: 0,
            });
        }
        let mut out = Vec::new();
        c.take_due(2.0, &mut out);
        let got: Vec<(f64, usize)> = out.iter().map(|d| (d.t, d.i)).collect();
        assert_eq!(got, vec![(1.0, 2), (1.0, 5), (2.0, 1)]);
        assert_eq!(c.len(), 1);
    }
}
