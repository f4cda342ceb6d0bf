//! Random clouds of ellipsoids (for benchmarks and stress tests), seeded and reproducible.

use crate::ellipsoid::body::{Body, Ellipsoid};
use crate::ellipsoid::quaternion::rotation_matrix;
use crate::engine::{ParticleView, SnapshotView};
use crate::math::{Mat3, Vec3};
use crate::random::{generator, random_quaternion, symmetric, uniform};

/// Parameters of [`random_cloud`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CloudParams {
    /// Bulk density (kg/m³).
    pub density: f64,
    /// Smallest equivalent radius (m).
    pub r_min: f64,
    /// Largest equivalent radius (m).
    pub r_max: f64,
    /// Lattice spacing as a multiple of the mean equivalent radius.
    pub spacing_factor: f64,
    /// Position jitter as a fraction of the spacing (each component uniform in ±jitter/2).
    pub jitter: f64,
    /// Speed scale (m/s): each velocity component uniform in ±speed.
    pub speed: f64,
    /// Spin scale (rad/s): each body-frame spin component uniform in ±spin.
    pub spin: f64,
    /// Smallest axis ratio B/A and C/B.
    pub min_axis_ratio: f64,
}

impl Default for CloudParams {
    /// Density 3000 kg/m³, equivalent radii 1–5 km, spacing 1.9 × mean radius (each body overlaps a
    /// few neighbours), jitter 0.2 spacing, speeds ±0.5 m/s, spins ±1e-3 rad/s, axis ratios ≥ 0.6.
    fn default() -> Self {
        CloudParams {
            density: 3000.0,
            r_min: 1000.0,
            r_max: 5000.0,
            spacing_factor: 1.9,
            jitter: 0.2,
            speed: 0.5,
            spin: 1e-3,
            min_axis_ratio: 0.6,
        }
    }
}

/// `n` ellipsoids on a jittered cubic lattice centred on the origin, with random shapes (equivalent
/// radius uniform in `[r_min, r_max]`, `A ≥ B ≥ C`), attitudes, spins and velocities.
pub fn random_cloud(n: usize, seed: u64, p: &CloudParams) -> Vec<Body> {
    let mut rng = generator(seed);
    let side = (n as f64).cbrt().ceil().max(1.0) as usize;
    let spacing = p.spacing_factor * 0.5 * (p.r_min + p.r_max);
    let offset = 0.5 * (side as f64 - 1.0) * spacing;
    let mut bodies = Vec::with_capacity(n);
    for k in 0..n {
        let (ix, iy, iz) = (k % side, (k / side) % side, k / (side * side));
        let lattice = Vec3::new(ix as f64, iy as f64, iz as f64) * spacing - Vec3::repeat(offset);
        // Components drawn in order x, y, z.
        let jitter = Vec3::from_fn(|_, _| symmetric(&mut rng, 0.5 * p.jitter * spacing));
        let r = p.r_min + (p.r_max - p.r_min) * uniform(&mut rng);
        let ba = p.min_axis_ratio + (1.0 - p.min_axis_ratio) * uniform(&mut rng);
        let cb = p.min_axis_ratio + (1.0 - p.min_axis_ratio) * uniform(&mut rng);
        // A · (ba A) · (cb ba A) = r³.
        let a = r / (ba * ba * cb).cbrt();
        let axes = Vec3::new(a, ba * a, cb * ba * a);
        let shape = Ellipsoid { axes, mass: 0.0 };
        let mass = p.density * shape.volume();
        bodies.push(Body {
            shape: Ellipsoid { axes, mass },
            position: lattice + jitter,
            velocity: Vec3::from_fn(|_, _| symmetric(&mut rng, p.speed)),
            quaternion: random_quaternion(&mut rng),
            spin_body: Vec3::from_fn(|_, _| symmetric(&mut rng, p.spin)),
        });
    }
    bodies
}

/// One random snapshot of `n` ellipsoids of [`random_cloud`] (seed 1, default [`CloudParams`]), or spheres of the
/// same volumes when `spheres`: a scene-sized input for the renderer and the snapshot writers.
pub fn cloud_view(n: usize, spheres: bool) -> SnapshotView {
    let bodies = random_cloud(n, 1, &CloudParams::default());
    let particles = bodies
        .iter()
        .enumerate()
        .map(|(id, b)| {
            let r = b.shape.axes.product().cbrt();
            ParticleView {
                id,
                mass: b.shape.mass,
                position: b.position,
                velocity: b.velocity,
                spin_world: b.spin_body,
                axes: if spheres { Vec3::repeat(r) } else { b.shape.axes },
                rotation: if spheres {
                    Mat3::identity()
                } else {
                    rotation_matrix(&b.quaternion).transpose()
                },
            }
        })
        .collect();
    SnapshotView {
        spheres,
        particles,
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cloud_is_reproducible_and_valid() {
        let p = CloudParams::default();
        let a = random_cloud(30, 7, &p);
        let b = random_cloud(30, 7, &p);
        assert_eq!(a, b);
        for body in &a {
            let ax = body.shape.axes;
            assert!(ax.x >= ax.y && ax.y >= ax.z && ax.z > 0.0);
            let r = body.shape.equivalent_radius();
            assert!(r >= 0.999 * p.r_min && r <= 1.001 * p.r_max, "{r}");
            assert!((body.quaternion.norm() - 1.0).abs() < 1e-14);
            assert!(body.shape.mass > 0.0);
        }
    }
}
