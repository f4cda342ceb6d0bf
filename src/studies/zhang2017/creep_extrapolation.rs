//! Where a pile's creep would stop: the spin period at which the weakening rates measured in holds at several
//! periods reach zero, from a straight line through them (Zhang17 §3.3.3's creep test read as a trend across the
//! holds rather than hold by hold).
//!
//! Judged with zero tolerance ([`rubblepile::analysis::creep`]), a long hold of a lattice well above its failure period
//! still loses contacts slowly: each rate lies many standard errors from zero, so no hold is called stable, yet the
//! rates fall steadily with the period. The zero of the fitted line is the period from which no hold would weaken.
//! Its standard error comes from the scatter of the rates about the line (first-order error propagation of
//! −a/b); the scatter, not the rates' own errors, measures how well a line describes them.

use rubblepile::analysis::critical::HoldVerdict;

/// The period at which a fitted weakening rate reaches zero.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZeroRate {
    /// Period of zero weakening (h).
    pub period_h: f64,
    /// Its standard error (h); 0 when the rates lie exactly on the line.
    pub se_h: f64,
    /// Slope of the weakening rate against the period (rate unit per hour; negative).
    pub slope_per_h: f64,
    /// Holds in the fit.
    pub holds: usize,
}

/// The zero of the least-squares line through `points` = (period h, weakening rate), positive rates weakening;
/// `None` with fewer than 3 points, a non-finite value, or rates that do not fall as the period grows.
pub fn zero_rate_period(points: &[(f64, f64)]) -> Option<ZeroRate> {
    let n = points.len();
    if n < 3 || points.iter().any(|(t, w)| !t.is_finite() || !w.is_finite()) {
        return None;
    }
    let nf = n as f64;
    let tm = points.iter().map(|p| p.0).sum::<f64>() / nf;
    let wm = points.iter().map(|p| p.1).sum::<f64>() / nf;
    let stt: f64 = points.iter().map(|p| (p.0 - tm).powi(2)).sum();
    let stw: f64 = points.iter().map(|p| (p.0 - tm) * (p.1 - wm)).sum();
    if stt == 0.0 {
        return None;
    }
    let b = stw / stt;
    if b >= 0.0 {
        return None;
    }
    let a = wm - b * tm;
    let ssr: f64 = points.iter().map(|p| (p.1 - a - b * p.0).powi(2)).sum();
    let s2 = ssr / (nf - 2.0);
    // covariance of (a, b): s² (XᵀX)⁻¹ for the design rows (1, T)
    let var_b = s2 / stt;
    let var_a = s2 * (1.0 / nf + tm * tm / stt);
    let cov_ab = -s2 * tm / stt;
    // T0 = −a/b: ∂T0/∂a = −1/b, ∂T0/∂b = a/b²
    let (ga, gb) = (-1.0 / b, a / (b * b));
    let var_t0 = ga * ga * var_a + gb * gb * var_b + 2.0 * ga * gb * cov_ab;
    Some(ZeroRate {
        period_h: -a / b,
        se_h: var_t0.max(0.0).sqrt(),
        slope_per_h: b,
        holds: n,
    })
}

/// The periods of zero weakening of the coordination number, η_B and θ_max (in that order) over the holds of a
/// search that were not released and have recorded rates; weakening is a falling coordination number or η_B and a
/// rising θ_max.
pub fn weakening_zeros(verdicts: &[HoldVerdict]) -> [Option<ZeroRate>; 3] {
    let held: Vec<_> = verdicts
        .iter()
        .filter(|v| !v.released)
        .filter_map(|v| v.rates.map(|r| (v.t_final_hours, r)))
        .collect();
    let zero = |weakening: &dyn Fn(&rubblepile::analysis::creep::HoldRates) -> f64| {
        let points: Vec<(f64, f64)> = held.iter().map(|(t, r)| (*t, weakening(r))).collect();
        zero_rate_period(&points)
    };
    [
        zero(&|r| -r.coordination.rate_per_ks),
        zero(&|r| -r.packing.rate_per_ks),
        zero(&|r| r.theta_max_deg.rate_per_ks),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rates exactly on a line give its zero and no error.
    #[test]
    fn rates_on_a_line_give_its_zero_exactly() {
        let points: Vec<(f64, f64)> = [2.5, 2.6, 2.7, 2.8].iter().map(|&t| (t, 0.3 * (2.9 - t))).collect();
        let z = zero_rate_period(&points).unwrap();
        assert!((z.period_h - 2.9).abs() < 1e-12 && z.se_h < 1e-9, "{z:?}");
        assert!((z.slope_per_h + 0.3).abs() < 1e-12);
        assert_eq!(z.holds, 4);
    }

    /// The 3k HCP (random:1) search's coordination-loss rates over 50 000 s holds at 2.50–2.70 h: the zero and its
    /// error as an independent least-squares fit (numpy.linalg.lstsq and the same error propagation) gives them.
    #[test]
    fn the_zero_and_its_error_match_an_independent_fit() {
        let rates = [
            (2.50, 0.0494),
            (2.55, 0.0438),
            (2.60, 0.0388),
            (2.65, 0.0331),
            (2.70, 0.0248),
        ];
        let z = zero_rate_period(&rates).unwrap();
        assert!((z.period_h - 2.917_028_380_634).abs() < 1e-9, "{z:?}");
        assert!((z.se_h - 0.019_010_333_867).abs() < 1e-9, "{z:?}");
        assert!((z.slope_per_h + 0.1198).abs() < 1e-9);
    }

    /// No zero from fewer than 3 holds, a non-finite rate, or rates that grow with the period.
    #[test]
    fn no_zero_without_a_falling_trend() {
        assert_eq!(zero_rate_period(&[(2.5, 0.04), (2.6, 0.03)]), None);
        assert_eq!(zero_rate_period(&[(2.5, 0.04), (2.6, f64::NAN), (2.7, 0.02)]), None);
        assert_eq!(zero_rate_period(&[(2.5, 0.01), (2.6, 0.02), (2.7, 0.03)]), None);
        assert_eq!(zero_rate_period(&[(2.5, 0.01), (2.5, 0.02), (2.5, 0.03)]), None);
    }
}
