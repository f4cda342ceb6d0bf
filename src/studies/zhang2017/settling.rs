//! Whether T_c,1 or T_c,2 was read from the body's settling rather than from its response to the spin.
//!
//! The limits are the first forced sample after t_start at which b/a, c/a (> 0.01) or η_B (> 0.001) departs from
//! its value at t_start (Zhang17 §3.1, §3.2). Its §2.3.4 lets the body "settle down at a slow spin state T_start" before the spin-up
//! and names 1/√(Gρ_B) (≈ 2650 s for Didymos) the time over which the pile keeps quasi-equilibrium; its path from
//! 5 h to 3 h is chosen "sufficiently far from the critical value to ensure the body always remains stable". A
//! departure within one dynamical time of t_start therefore comes from the settling still going on (our path-2
//! scenes start forcing at 700 s, less than one dynamical time after the start), not from the spin: the report
//! flags it instead of quoting the period silently.

/// A limit whose first departure came within the settling.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SettlingWarning {
    /// "T_c1" or "T_c2".
    pub limit: &'static str,
    /// Time of the departing sample after t_start (s).
    pub after_start_s: f64,
    /// The body's dynamical time 1/√(Gρ_B) (s).
    pub dynamical_time_s: f64,
}

impl SettlingWarning {
    /// One line for the report and the command line.
    pub fn describe(&self, model: &str) -> String {
        format!(
            "{model}: {} is read {:.0} s after t_start, within one dynamical time 1/√(Gρ_B) = {:.0} s: the body is \
             still settling, the value is not the spin's limit",
            self.limit, self.after_start_s, self.dynamical_time_s
        )
    }
}

/// The warnings for T_c,1 and T_c,2 whose departing samples, at `departures` (index into `times`, the forced
/// samples' times in s, `times[0]` being t_start's sample), come less than `dynamical_time_s` after `times[0]`.
pub fn settling_warnings(times: &[f64], departures: [Option<usize>; 2], dynamical_time_s: f64) -> Vec<SettlingWarning> {
    let Some(&t0) = times.first() else {
        return Vec::new();
    };
    ["T_c1", "T_c2"]
        .into_iter()
        .zip(departures)
        .filter_map(|(limit, k)| {
            let after_start_s = times.get(k?)? - t0;
            (after_start_s < dynamical_time_s).then_some(SettlingWarning {
                limit,
                after_start_s,
                dynamical_time_s,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Departures at 200 s and 3000 s after t_start against a dynamical time of 2667 s: the first is flagged.
    #[test]
    fn only_a_departure_within_one_dynamical_time_is_flagged() {
        let times: Vec<f64> = (0..30).map(|k| 700.0 + 200.0 * k as f64).collect();
        let w = settling_warnings(&times, [Some(1), Some(15)], 2667.0);
        assert_eq!(w.len(), 1);
        assert_eq!((w[0].limit, w[0].after_start_s), ("T_c1", 200.0));
        assert!(settling_warnings(&times, [None, Some(15)], 2667.0).is_empty());
        assert!(settling_warnings(&[], [Some(0), None], 2667.0).is_empty());
    }
}
