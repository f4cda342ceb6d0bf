//! The event queue of a drift (Richardson11 §2.1: "process the globally earliest event").
//!
//! A binary heap ordered by time, earliest first, with deterministic tie-breaking (then by particle index, then
//! walls before particles, then the partner's index), so equal times are processed in the same order on every run.
//! Events are invalidated lazily: each stores the collision counters (generations) of its participants at
//! prediction time and is skipped when popped if either has changed since.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// The other side of an event.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Partner {
    /// A wall (its index).
    Wall(usize),
    /// Another particle (its index).
    Particle(usize),
}

/// A predicted collision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Event {
    /// Absolute time (s).
    pub t: f64,
    /// The particle.
    pub i: usize,
    /// What it hits.
    pub partner: Partner,
    /// Generation of `i` when predicted.
    pub gen_i: u64,
    /// Generation of the partner particle when predicted (0 for walls).
    pub gen_j: u64,
}

impl Eq for Event {}

impl Ord for Event {
    /// Reversed (the heap is a max-heap): the earliest event is the greatest.
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .t
            .total_cmp(&self.t)
            .then_with(|| other.i.cmp(&self.i))
            .then_with(|| other.partner.cmp(&self.partner))
    }
}

impl PartialOrd for Event {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Earliest-first queue of [`Event`]s (the heap's greatest is the earliest by their reversed order).
pub type EventQueue = BinaryHeap<Event>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn earliest_first_with_deterministic_ties() {
        let mut q = EventQueue::new();
        let e = |t, i, partner| Event {
            t,
            i,
            partner,
            gen_i: 0,
            gen_j: 0,
        };
        q.push(e(2.0, 0, Partner::Wall(0)));
        q.push(e(1.0, 3, Partner::Particle(4)));
        q.push(e(1.0, 3, Partner::Wall(1)));
        q.push(e(1.0, 1, Partner::Particle(2)));
        let order: Vec<_> = std::iter::from_fn(|| q.pop()).map(|e| (e.t, e.i, e.partner)).collect();
        assert_eq!(
            order,
            vec![
                (1.0, 1, Partner::Particle(2)),
                (1.0, 3, Partner::Wall(1)),
                (1.0, 3, Partner::Particle(4)),
                (2.0, 0, Partner::Wall(0))
            ]
        );
    }
}
