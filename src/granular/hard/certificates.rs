//! Pair certificates kept across steps: for each listed pair of free particles a time before which it cannot touch,
//! so a drift start re-predicts only pairs whose certificate came due (Richardson11 §2.1 re-predicts every pair). A
//! uniform kick adds the same `g h/2` to every free particle, so the relative trajectory stays one straight line
//! until a collision, re-listing or sticking of either (the event calendar of event-driven MD: Lubachevsky 1991,
//! J. Comput. Phys. 94, 255; Rapaport, *The Art of Molecular Dynamics Simulation*, ch. 14).
//!
//! A certificate only decides which pairs are predicted; events are still computed from the drift-start state. It is
//! the time the pair first comes within `s + m` (contact distance plus a margin covering, many times over, the
//! rounding between that straight line and later drift-start states) and expires after [`HORIZON_STEPS`] steps, so
//! no pair is skipped and the bits equal re-predicting every pair every step (`tests/hsdem_certificates.rs`).

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

/// Buckets in the calendar's ring: certificates last at most [`HORIZON_STEPS`] steps of one bucket width each.
const BUCKETS: usize = 2 * HORIZON_STEPS as usize + 4;

/// Certificates filed by expiry in a ring of buckets one step wide (a calendar queue, Brown 1988, Commun. ACM 31,
/// 1220: filing and taking are O(1), where a heap cost a sift through thousands of entries). Stale certificates are
/// dropped lazily, when their bucket comes due.
#[derive(Debug, Clone)]
pub struct Calendar {
    /// Bucket width (s): the step length when the calendar was last cleared.
    width: f64,
    /// Absolute index (time / width) of the earliest bucket that may hold certificates; nothing is filed before it.
    base: i64,
    buckets: Vec<Vec<Due>>,
    len: usize,
}

impl Default for Calendar {
    fn default() -> Self {
        Calendar {
            width: 1.0,
            base: 0,
            buckets: vec![Vec::new(); BUCKETS],
            len: 0,
        }
    }
}

impl Calendar {
    /// The absolute bucket index of time `t`, never before the earliest bucket.
    fn index(&self, t: f64) -> i64 {
        super::anchors::floor_i64(t / self.width).max(self.base)
    }

    /// Files a certificate (one due beyond the ring goes in its last bucket and is filed again when that comes
    /// due).
    pub fn push(&mut self, d: Due) {
        let idx = self.index(d.t).min(self.base + BUCKETS as i64 - 1);
        self.buckets[idx.rem_euclid(BUCKETS as i64) as usize].push(d);
        self.len += 1;
    }

    /// Moves into `out` every certificate that runs out at or before `t1` (in no particular order, the same on every
    /// run); the others stay filed.
    pub fn take_due(&mut self, t1: f64, out: &mut Vec<Due>) {
        out.clear();
        let last = self.index(t1);
        let span = (last - self.base + 1).min(BUCKETS as i64);
        let mut later = Vec::new();
        for idx in self.base..self.base + span {
            let bucket = &mut self.buckets[idx.rem_euclid(BUCKETS as i64) as usize];
            for d in bucket.drain(..) {
                if d.t <= t1 { out.push(d) } else { later.push(d) }
            }
        }
        // The last bucket reached may hold certificates beyond t1: it stays the earliest.
        self.base = last;
        self.len -= out.len() + later.len();
        for d in later {
            self.push(d);
        }
    }

    /// Keeps only the certificates for which `keep` holds.
    pub fn retain(&mut self, mut keep: impl FnMut(&Due) -> bool) {
        self.len = 0;
        for b in &mut self.buckets {
            b.retain(&mut keep);
            self.len += b.len();
        }
    }

    /// Drops every certificate; buckets are `width` seconds wide (> 0) from time `t` on.
    pub fn clear(&mut self, t: f64, width: f64) {
        self.buckets.iter_mut().for_each(Vec::clear);
        self.len = 0;
        self.width = if width > 0.0 && width.is_finite() { width } else { 1.0 };
        self.base = i64::MIN;
        self.base = self.index(t);
    }

    /// Certificates filed (valid or stale).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether no certificate is filed.
    pub fn is_empty(&self) -> bool {
        self.len == 0
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
    fn calendar_takes_the_due() {
        let mut c = Calendar::default();
        c.clear(0.0, 1.0);
        let due = |t, i| Due {
            t,
            i,
            j: 9,
            gen_i: 0,
            gen_j: 0,
        };
        for (t, i) in [(3.0, 0), (1.0, 5), (2.5, 1), (1.0, 2), (-1.0, 3), (1e6, 4)] {
            c.push(due(t, i));
        }
        let mut out = Vec::new();
        c.take_due(2.0, &mut out);
        let mut got: Vec<usize> = out.iter().map(|d| d.i).collect();
        got.sort();
        assert_eq!(got, vec![2, 3, 5], "the due ones, including one filed late");
        assert_eq!(c.len(), 3);
        c.take_due(2.7, &mut out);
        assert_eq!(
            out.iter().map(|d| d.i).collect::<Vec<_>>(),
            vec![1],
            "same bucket, later time"
        );
        c.take_due(500.0, &mut out);
        assert_eq!(out.iter().map(|d| d.i).collect::<Vec<_>>(), vec![0]);
        c.take_due(2e6, &mut out);
        assert_eq!(
            out.iter().map(|d| d.i).collect::<Vec<_>>(),
            vec![4],
            "beyond the ring: refiled until due"
        );
        assert!(c.is_empty());
    }
}
