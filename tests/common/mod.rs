//! Helpers shared by the integration tests: a seeded random source and random bodies.
#![allow(dead_code)]

use rand_core::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use rubblepile::math::{Vec3, Vec4};

/// Seeded uniform random numbers for reproducible tests.
pub struct Random(Pcg64);

impl Random {
    pub fn new(seed: u64) -> Self {
        Random(Pcg64::seed_from_u64(seed))
    }
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }
    pub fn vec3(&mut self, scale: f64) -> Vec3 {
        Vec3::new(self.range(-scale, scale), self.range(-scale, scale), self.range(-scale, scale))
    }
    /// A random unit quaternion (scalar last).
    pub fn unit_quaternion(&mut self) -> Vec4 {
        loop {
            let q = Vec4::new(self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0));
            let n = q.norm();
            if n > 0.2 && n < 1.0 {
                return q / n;
            }
        }
    }
    /// Semi-axes A ≥ B ≥ C with A in [a_lo, a_hi].
    pub fn axes(&mut self, a_lo: f64, a_hi: f64) -> Vec3 {
        let a = self.range(a_lo, a_hi);
        let b = a * self.range(0.4, 1.0);
        let c = b * self.range(0.4, 1.0);
        Vec3::new(a, b, c)
    }
}

/// Relative error of `approx` against `exact`, by vector norm, with a floor on the scale.
pub fn rel_err(approx: &[f64], exact: &[f64], floor: f64) -> f64 {
    let diff: f64 = approx.iter().zip(exact).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
    let scale: f64 = exact.iter().map(|b| b * b).sum::<f64>().sqrt().max(floor);
    diff / scale
}
