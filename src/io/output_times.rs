//! Snapshot times computed from a cadence or a count, shared by the three engines' `[output] snapshot_every` and
//! the commands that write scenes (`impact --snapshot-every-s`, the flyby's evenly spaced snapshots). Each time is
//! `k × step` computed from its index (not by adding steps, which drifts), and the last is `t_end` itself: a product
//! that rounds one ulp above `t_end` would be refused by the scene check (computed as
//! `t_end·k/(N−1)`, the last of `flyby --snapshots N` did so for 147 of N = 2…1201).

/// Relative distance (of the cadence) below which a cadence time next to `t_end` is taken as `t_end` itself, so a
/// cadence that divides `t_end` up to rounding does not add a snapshot a hair before the last.
pub const CADENCE_END_TOLERANCE: f64 = 1e-9;

/// How many snapshot times [`cadence_times`] gives for `t_end` and `every` (s), as a float so that a huge count is
/// checked against a limit before anything is allocated: `0, every, …` below `t_end`, then `t_end`.
pub fn cadence_count(t_end: f64, every: f64) -> f64 {
    let below = ((t_end - CADENCE_END_TOLERANCE * every) / every).ceil().max(1.0);
    below + 1.0
}

/// The snapshot times `0, every, 2·every, …` of a run of length `t_end` (s), each `k × every`, ending with `t_end`
/// exactly: the cadence times strictly below `t_end − 1e-9·every` ([`CADENCE_END_TOLERANCE`]), then `t_end`. With
/// `every ≥ t_end` this is `[0, t_end]`. Both arguments must be finite and `> 0` (the scene checks them first).
pub fn cadence_times(t_end: f64, every: f64) -> Vec<f64> {
    let limit = t_end - CADENCE_END_TOLERANCE * every;
    let mut times: Vec<f64> = (0u64..)
        .map(|k| k as f64 * every)
        .take_while(|&t| t < limit || t == 0.0)
        .collect();
    times.push(t_end);
    times
}

/// `n` snapshot times evenly spaced over `[0, t_end]` (s): `t_end × k/(n−1)` for `k = 0 … n−1`, the last exactly
/// `t_end` and none above it. `n = 1` gives `[0]`, `n = 0` none.
pub fn evenly_spaced(t_end: f64, n: usize) -> Vec<f64> {
    match n {
        0 => Vec::new(),
        1 => vec![0.0],
        _ => (0..n)
            .map(|k| {
                if k + 1 == n {
                    t_end
                } else {
                    (t_end * k as f64 / (n - 1) as f64).min(t_end)
                }
            })
            .collect(),
    }
}

/// The snapshot times of a cadence `every` (s) for a run of `t_end` (s), [`cadence_times`], after checking both:
/// the error names `every_field` or `t_end_field` (e.g. `--snapshot-every-s`, `--t-end-s`) and the expected value.
pub fn checked_cadence_times(t_end: f64, every: f64, every_field: &str, t_end_field: &str) -> Result<Vec<f64>, String> {
    use crate::io::limits::{MAX_SNAPSHOTS, MIN_MEANINGFUL};
    if !(every.is_finite() && every >= MIN_MEANINGFUL) {
        return Err(format!("{every_field}: must be > 0 s and finite, got {every}"));
    }
    if !(t_end.is_finite() && t_end > 0.0) {
        return Err(format!("{t_end_field}: must be > 0 s and finite, got {t_end}"));
    }
    let n = cadence_count(t_end, every);
    if n > MAX_SNAPSHOTS as f64 {
        return Err(format!(
            "{every_field}: too small for {t_end_field} {t_end}: would write {n:e} snapshots (at most {MAX_SNAPSHOTS}), \
             got {every}"
        ));
    }
    Ok(cadence_times(t_end, every))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cadence_that_divides_t_end_ends_on_it_once() {
        let t = cadence_times(600.0, 10.0);
        assert_eq!(t.len(), 61);
        assert_eq!(t, (0..=60).map(|k| 10.0 * k as f64).collect::<Vec<_>>());
        assert_eq!(cadence_count(600.0, 10.0), 61.0);
    }

    #[test]
    fn a_cadence_that_does_not_divide_t_end_adds_t_end() {
        assert_eq!(cadence_times(25.0, 10.0), vec![0.0, 10.0, 20.0, 25.0]);
        assert_eq!(cadence_count(25.0, 10.0), 4.0);
        assert_eq!(cadence_times(5.0, 10.0), vec![0.0, 5.0]);
        assert_eq!(cadence_count(5.0, 10.0), 2.0);
    }

    #[test]
    fn times_never_pass_t_end_and_are_strictly_increasing() {
        // 0.1 × 3 = 0.30000000000000004 > 0.3: the last time must be t_end itself.
        for (t_end, every) in [(0.3, 0.1), (1.0, 0.1), (0.7, 0.1), (1e4, 3.0), (1e-3, 1e-4)] {
            let t = cadence_times(t_end, every);
            assert_eq!(*t.last().unwrap(), t_end, "{t_end} / {every}");
            assert!(t.windows(2).all(|w| w[0] < w[1]), "{t:?}");
            assert_eq!(t.len() as f64, cadence_count(t_end, every), "{t_end} / {every}");
        }
    }

    #[test]
    fn evenly_spaced_times_end_exactly_on_t_end_for_every_count() {
        // The flyby's case: t_end·k/(N−1) rounded one ulp above t_end for some N.
        let t_end = 2.0 * 6.0 * 6.371e6 / 12e3 + 0.1;
        for n in 2..=1201 {
            let t = evenly_spaced(t_end, n);
            assert_eq!(t.len(), n);
            assert_eq!(t[n - 1], t_end);
            assert!(t.iter().all(|&x| x <= t_end));
            assert!(t.windows(2).all(|w| w[0] < w[1]));
        }
        assert_eq!(evenly_spaced(5.0, 1), vec![0.0]);
        assert!(evenly_spaced(5.0, 0).is_empty());
    }
}
