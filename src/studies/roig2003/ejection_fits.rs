//! Roig03 §4.2 and Fig. 4: the ejection speed–size power law `Δv ∝ size^α` fitted to subsets of the target
//! fragments with standard errors, and where the ejected fragments started. The paper does not say which fragments
//! enter its fit, and a rotating pile always has a floor of slow, unperturbed fragments (`Δv` is relative to the
//! target barycentre between `t = 0` and `t_at`), so three fits: all target fragments (as `analyze`), those above a
//! `Δv` floor (m/s), and the escaping ones (Eq. 43). Each is [`fit_power_law`] (least squares in logs, `σ_α` from
//! the residual variance). §4.2's spatial claim (small fragments ejected at the impact point, the largest at the
//! antipode) is measured by [`ejected_sites`]: the correlation of `ln size` with the impact-site cosine and the
//! median sizes from each hemisphere.

use rubblepile::analysis::fits::{FitError, PowerLawFit, fit_power_law};
use rubblepile::analysis::fragments::{EjectionSites, FragmentAnalysis, pearson};
use rubblepile::math::median;

/// The three Fig. 4 fits of one run.
#[derive(Debug, Clone, PartialEq)]
pub struct EjectionFits {
    /// The floor used for [`EjectionFits::above_floor`] (m/s).
    pub floor: f64,
    /// All target fragments.
    pub all: Result<PowerLawFit, FitError>,
    /// Target fragments with `Δv > floor`.
    pub above_floor: Result<PowerLawFit, FitError>,
    /// Escaping target fragments (Eq. 43).
    pub escaping: Result<PowerLawFit, FitError>,
}

/// `Δv = c size^α` fitted to the pairs whose `keep` is true (same length as `sizes` and `speeds`).
pub fn fit_selected(sizes: &[f64], speeds: &[f64], keep: &[bool]) -> Result<PowerLawFit, FitError> {
    if sizes.len() != speeds.len() || sizes.len() != keep.len() {
        return Err(FitError::InvalidInput(format!(
            "sizes, speeds and selection differ in length ({}, {}, {})",
            sizes.len(),
            speeds.len(),
            keep.len()
        )));
    }
    let (x, y): (Vec<f64>, Vec<f64>) = sizes
        .iter()
        .zip(speeds)
        .zip(keep)
        .filter(|(_, k)| **k)
        .map(|((s, v), _)| (*s, *v))
        .unzip();
    fit_power_law(&x, &y)
}

/// `Δv = c size^α` fitted to the pairs with `speed > floor` (m/s).
pub fn fit_above_floor(sizes: &[f64], speeds: &[f64], floor: f64) -> Result<PowerLawFit, FitError> {
    if !floor.is_finite() {
        return Err(FitError::InvalidInput(format!(
            "floor: expected a finite speed (m/s), got {floor}"
        )));
    }
    let keep: Vec<bool> = speeds.iter().map(|v| *v > floor).collect();
    fit_selected(sizes, speeds, &keep)
}

/// The three fits ([`EjectionFits`]) of the target fragments of one run (the projectile is skipped), the
/// floor in m/s.
pub fn ejection_fits(fragments: &[FragmentAnalysis], floor: f64) -> EjectionFits {
    let targets: Vec<&FragmentAnalysis> = fragments.iter().filter(|f| !f.is_projectile).collect();
    let sizes: Vec<f64> = targets.iter().map(|f| f.size).collect();
    let speeds: Vec<f64> = targets.iter().map(|f| f.ejection_speed).collect();
    let escaping: Vec<bool> = targets.iter().map(|f| f.escaping).collect();
    EjectionFits {
        floor,
        all: fit_power_law(&sizes, &speeds),
        above_floor: fit_above_floor(&sizes, &speeds, floor),
        escaping: fit_selected(&sizes, &speeds, &escaping),
    }
}

/// §4.2's "small fragments from the impact point, large ones from the antipode", measured on the target
/// fragments thrown above `floor` (m/s) instead of the faster half of [`rubblepile::analysis::fragments::ejection_sites`]:
/// the same fields, `fast_fragments` counting those above the floor.
pub fn ejected_sites(fragments: &[FragmentAnalysis], floor: f64) -> EjectionSites {
    let ejected: Vec<&FragmentAnalysis> = fragments
        .iter()
        .filter(|f| !f.is_projectile && f.ejection_speed > floor)
        .collect();
    let sizes_where = |impact: bool| -> Vec<f64> {
        ejected
            .iter()
            .filter(|f| (f.impact_site_cosine > 0.0) == impact)
            .map(|f| f.size)
            .collect()
    };
    let (near, far) = (sizes_where(true), sizes_where(false));
    let med = |v: &[f64]| (!v.is_empty()).then(|| median(v));
    let x: Vec<f64> = ejected.iter().map(|f| f.size.ln()).collect();
    let y: Vec<f64> = ejected.iter().map(|f| f.impact_site_cosine).collect();
    EjectionSites {
        fast_fragments: ejected.len(),
        impact_side: near.len(),
        antipodal_side: far.len(),
        impact_side_median_size: med(&near),
        antipodal_side_median_size: med(&far),
        size_cosine_correlation: pearson(&x, &y),
    }
}
