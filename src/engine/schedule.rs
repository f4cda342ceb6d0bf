//! The sample schedule of a time-stepped run: the time-series grid `0, every, 2·every, …` merged with the snapshot
//! times, each landed on exactly.

/// The times at which the run samples its state: `0, every, 2·every, …` below `t_end`, then `t_end`,
/// merged with the snapshot times (an interior grid time within `1e-9·every` of a snapshot time is replaced by it;
/// 0 and `t_end` are always sampled).
#[derive(Debug, Clone)]
pub struct Schedule {
    every: f64,
    t_end: f64,
    n_grid: u64,
    next_grid: u64,
    end_done: bool,
    snapshots: Vec<f64>,
    next_snapshot: usize,
    tol: f64,
}

/// One sampling time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Time (s).
    pub t: f64,
    /// Index `k` of the snapshot to write (`snapshots/<k>.csv`), if this is a snapshot time.
    pub snapshot: Option<usize>,
}

impl Schedule {
    /// `every > 0`, `t_end > 0`, snapshot times sorted within `[0, t_end]` (as validated by the scene).
    pub fn new(t_end: f64, every: f64, snapshots: &[f64]) -> Self {
        let tol = 1e-9 * every;
        // Number of grid points i·every (i ≥ 0) strictly below t_end − tol.
        let limit = t_end - tol;
        let mut n = (limit / every).ceil().max(0.0) as u64;
        while n > 0 && (n - 1) as f64 * every >= limit {
            n -= 1;
        }
        while (n as f64) * every < limit {
            n += 1;
        }
        Schedule {
            every,
            t_end,
            n_grid: n,
            next_grid: 0,
            end_done: false,
            snapshots: snapshots.to_vec(),
            next_snapshot: 0,
            tol,
        }
    }

    fn peek_grid(&self) -> Option<f64> {
        if self.next_grid < self.n_grid {
            Some(self.next_grid as f64 * self.every)
        } else if !self.end_done {
            Some(self.t_end)
        } else {
            None
        }
    }

    fn pop_grid(&mut self) {
        if self.next_grid < self.n_grid {
            self.next_grid += 1;
        } else {
            self.end_done = true;
        }
    }
}

impl Iterator for Schedule {
    type Item = Sample;

    fn next(&mut self) -> Option<Sample> {
        let grid = self.peek_grid();
        // Interior grid times within tol of a snapshot time are replaced by it; 0 and t_end are always sampled
        // exactly.
        let merged = |g: f64, s: f64| g == s || (g != 0.0 && g != self.t_end && (g - s).abs() <= self.tol);
        let (take_grid, snapshot_t) = match (grid, self.snapshots.get(self.next_snapshot).copied()) {
            (None, None) => return None,
            (Some(g), Some(s)) if merged(g, s) => (true, Some(s)),
            (Some(g), s) if s.is_none_or(|s| g < s) => (true, None),
            (_, s) => (false, s),
        };
        if take_grid {
            self.pop_grid();
        }
        let Some(t) = snapshot_t else {
            return Some(Sample {
                t: grid?,
                snapshot: None,
            });
        };
        self.next_snapshot += 1;
        Some(Sample {
            t,
            snapshot: Some(self.next_snapshot - 1),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn times(s: Schedule) -> Vec<(f64, Option<usize>)> {
        s.map(|x| (x.t, x.snapshot)).collect()
    }

    #[test]
    fn schedule_merges_and_ends_at_t_end() {
        let s = times(Schedule::new(3.0, 1.0, &[0.0, 1.5, 3.0]));
        assert_eq!(
            s,
            vec![(0.0, Some(0)), (1.0, None), (1.5, Some(1)), (2.0, None), (3.0, Some(2))]
        );
        let s = times(Schedule::new(2.5, 1.0, &[]));
        assert_eq!(s, vec![(0.0, None), (1.0, None), (2.0, None), (2.5, None)]);
        // 0.1 steps: 3·0.1 ≠ 0.3 in floating point, but they merge.
        let s = times(Schedule::new(0.3, 0.1, &[0.3]));
        assert_eq!(s.len(), 4);
        assert_eq!(s[3], (0.3, Some(0)));
        let s = times(Schedule::new(1.0, 5.0, &[0.5]));
        assert_eq!(s, vec![(0.0, None), (0.5, Some(0)), (1.0, None)]);
        // Snapshot times next to 0 and t_end do not replace them.
        let s = times(Schedule::new(2.0, 1.0, &[1e-12, 2.0 - 1e-12]));
        assert_eq!(
            s,
            vec![
                (0.0, None),
                (1e-12, Some(0)),
                (1.0, None),
                (2.0 - 1e-12, Some(1)),
                (2.0, None)
            ]
        );
    }

    #[test]
    fn schedule_is_strictly_increasing() {
        for (t_end, every) in [(200.0, 1.0), (1.0, 0.1), (7.3, 0.7), (1e3, 0.001)] {
            let v: Vec<f64> = Schedule::new(t_end, every, &[0.0, t_end / 3.0, t_end])
                .map(|s| s.t)
                .collect();
            assert!(v.windows(2).all(|w| w[1] > w[0]), "{t_end} {every}");
            assert_eq!(*v.last().unwrap(), t_end);
            assert_eq!(v[0], 0.0);
        }
    }
}
