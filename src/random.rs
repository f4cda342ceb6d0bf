//! Seeded random numbers (PCG-64 from `rand_pcg`): every random choice of a scene, a target or a benchmark
//! comes from a seed stored with its inputs, so the same inputs give the same bytes.

use crate::math::{Vec3, Vec4};
use rand_core::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// The generator used throughout the crate.
pub type Generator = Pcg64;

/// A generator from a seed.
pub fn generator(seed: u64) -> Generator {
    Pcg64::seed_from_u64(seed)
}

/// Uniform in `[0, 1)` with 53 random bits.
pub fn uniform(rng: &mut Generator) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Uniform in `[−half_width, half_width)`.
pub fn symmetric(rng: &mut Generator, half_width: f64) -> f64 {
    (2.0 * uniform(rng) - 1.0) * half_width
}

/// A uniformly distributed unit quaternion `(α, β, γ, δ)`, scalar last (Shoemake's method).
pub fn random_quaternion(rng: &mut Generator) -> Vec4 {
    let (u1, u2, u3) = (uniform(rng), uniform(rng), uniform(rng));
    let tau = std::f64::consts::TAU;
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    Vec4::new(
        a * (tau * u2).sin(),
        a * (tau * u2).cos(),
        b * (tau * u3).sin(),
        b * (tau * u3).cos(),
    )
    .normalize()
}

/// A point uniformly distributed in the ball of radius `radius` about the origin (by rejection).
pub fn point_in_ball(rng: &mut Generator, radius: f64) -> Vec3 {
    loop {
        let p = Vec3::new(symmetric(rng, 1.0), symmetric(rng, 1.0), symmetric(rng, 1.0));
        if p.norm_squared() <= 1.0 {
            return p * radius;
        }
    }
}
