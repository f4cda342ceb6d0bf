//! Initial packings for tests and benchmarks (Zhang17 §2.3.2 builds its HCP aggregate on a lattice; we use
//! the equally dense face-centred cubic lattice, which is simpler to generate).

use crate::granular::soft::particle::Particle;
use crate::math::Vec3;

/// The `n` sites of a face-centred cubic lattice closest to the origin, for spheres of radius `radius` (m)
/// whose centres are `2 radius (1 + gap)` apart (nearest neighbours), as particles of grain density
/// `density` (kg/m³) at rest. Ties in distance keep the generation order, so the result is deterministic.
///
/// ```
/// use rubblepile::granular::soft::packing::fcc_ball;
/// let p = fcc_ball(13, 1.0, 1000.0, 0.0);
/// assert_eq!(p.len(), 13);
/// assert!((p[1].position.norm() - 2.0).abs() < 1e-12);
/// ```
pub fn fcc_ball(n: usize, radius: f64, density: f64, gap: f64) -> Vec<Particle> {
    let spacing = 2.0 * radius * (1.0 + gap);
    let a = spacing * std::f64::consts::SQRT_2;
    let cells = ((n as f64 / 4.0).cbrt() / 2.0).ceil() as i64 + 2;
    let basis = [
        Vec3::zeros(),
        Vec3::new(0.5, 0.5, 0.0),
        Vec3::new(0.5, 0.0, 0.5),
        Vec3::new(0.0, 0.5, 0.5),
    ];
    let mut sites = Vec::new();
    for i in -cells..=cells {
        for j in -cells..=cells {
            for k in -cells..=cells {
                for b in &basis {
                    sites.push((Vec3::new(i as f64, j as f64, k as f64) + b) * a);
                }
            }
        }
    }
    sites.sort_by(|p, q| p.norm_squared().total_cmp(&q.norm_squared()));
    let mass = 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3) * density;
    sites
        .into_iter()
        .take(n)
        .map(|position| Particle {
            mass,
            radius,
            position,
            velocity: Vec3::zeros(),
            spin: Vec3::zeros(),
        })
        .collect()
}
