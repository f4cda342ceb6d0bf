//! Grain radii with a differential power law `dN/dr ∝ r^q` on `[r_min, r_max]` (Zhang17 §2.3.2 and Table 2:
//! q = −3 over 4–32 m for PP1 and 4–16 m for PP2), sampled by inverting the cumulative distribution.
//!
//! For q ≠ −1: `F(r) = (r^{q+1} − r_min^{q+1}) / (r_max^{q+1} − r_min^{q+1})`, so `r = (r_min^{q+1} + u (r_max^{q+1}
//! − r_min^{q+1}))^{1/(q+1)}` for `u` uniform in [0, 1). The distribution implements statrs' `ContinuousCDF`, so
//! samples can be checked with its Kolmogorov–Smirnov test.

use crate::random::{Generator, uniform};
use statrs::distribution::ContinuousCDF;
use statrs::statistics::{Max, Min};

/// `dN/dr ∝ r^exponent` on `[r_min, r_max]` (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PowerLawRadii {
    /// Smallest radius (m, > 0).
    pub r_min: f64,
    /// Largest radius (m, > r_min).
    pub r_max: f64,
    /// Differential exponent q (≠ −1); Zhang17 uses −3.
    pub exponent: f64,
}

impl PowerLawRadii {
    /// Zhang17's `r⁻³` law on `[r_min, r_max]` (m); `None` unless `0 < r_min < r_max` and both finite.
    pub fn inverse_cube(r_min: f64, r_max: f64) -> Option<Self> {
        (r_min > 0.0 && r_max > r_min && r_max.is_finite()).then_some(PowerLawRadii {
            r_min,
            r_max,
            exponent: -3.0,
        })
    }

    fn k(&self) -> f64 {
        self.exponent + 1.0
    }

    /// Draws one radius (m).
    pub fn sample(&self, rng: &mut Generator) -> f64 {
        self.inverse_cdf(uniform(rng))
    }

    /// The mean of `r^p` over the distribution (m^p), e.g. `p = 3` for the mean grain volume over (4/3)π.
    pub fn moment(&self, p: f64) -> f64 {
        let k = self.k();
        let norm = (self.r_max.powf(k) - self.r_min.powf(k)) / k;
        let e = k + p;
        let integral = if e.abs() < 1e-12 {
            (self.r_max / self.r_min).ln()
        } else {
            (self.r_max.powf(e) - self.r_min.powf(e)) / e
        };
        integral / norm
    }

    /// The same law with both bounds multiplied by `s`.
    pub fn scaled(&self, s: f64) -> Self {
        PowerLawRadii {
            r_min: self.r_min * s,
            r_max: self.r_max * s,
            ..*self
        }
    }
}

impl Min<f64> for PowerLawRadii {
    fn min(&self) -> f64 {
        self.r_min
    }
}

impl Max<f64> for PowerLawRadii {
    fn max(&self) -> f64 {
        self.r_max
    }
}

impl ContinuousCDF<f64, f64> for PowerLawRadii {
    fn cdf(&self, r: f64) -> f64 {
        let k = self.k();
        let r = r.clamp(self.r_min, self.r_max);
        (r.powf(k) - self.r_min.powf(k)) / (self.r_max.powf(k) - self.r_min.powf(k))
    }

    fn inverse_cdf(&self, u: f64) -> f64 {
        let k = self.k();
        let lo = self.r_min.powf(k);
        (lo + u * (self.r_max.powf(k) - lo))
            .powf(1.0 / k)
            .clamp(self.r_min, self.r_max)
    }
}
