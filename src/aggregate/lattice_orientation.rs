//! The orientation of a carved lattice relative to the body (Zhang17 §2.3.2 builds its HCP model "directly" and
//! does not say how the lattice was turned before the Didymos shape carved it).
//!
//! [`crate::geometry::lattice::hcp_centres`] stacks its close-packed layers along z, the body's spin axis. How the
//! layers meet the spin axis decides how many contacts survive the settling under self-gravity and rotation, and
//! with them the pile's strength, so the orientation is a build input recorded in the aggregate's report:
//!
//! - `perpendicular`: layers ⟂ the spin axis (the stacking axis c along z; the default);
//! - `parallel`: layers containing the spin axis (c along y: the lattice turned 90° about x);
//! - `tilt:DEG`: c tilted by DEG degrees from z towards −y (a turn about x; `tilt:54.7356` puts the spin axis on a
//!   body diagonal of the lattice's cubic cell);
//! - `random` or `random:SEED`: a rotation uniform over SO(3) drawn from SEED (default: the build's seed) by
//!   Shoemake's method ([`crate::random::random_quaternion`], the first draw of a generator of its own, so the
//!   random packing of RCPC's shell does not change with it).

use crate::math::{Mat3, Vec3};
use crate::random::{generator, random_quaternion};

/// How a lattice is turned before it is carved (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum LatticeOrientation {
    /// Close-packed layers perpendicular to the spin axis (identity); the default, for a build that names none.
    #[default]
    Perpendicular,
    /// Layers containing the spin axis: 90° about x.
    Parallel,
    /// The stacking axis tilted by this many degrees from the spin axis (a turn about x).
    Tilt {
        /// Tilt (degrees), 0 to 180.
        degrees: f64,
    },
    /// A uniformly random rotation drawn from a seed; `None`: the build's seed.
    Random {
        /// Seed of the draw.
        seed: Option<u64>,
    },
}

impl std::str::FromStr for LatticeOrientation {
    type Err = String;
    /// Parses `perpendicular`, `parallel`, `tilt:DEG` (0 ≤ DEG ≤ 180) or `random[:SEED]`.
    ///
    /// ```
    /// use rubblepile::aggregate::lattice_orientation::LatticeOrientation;
    /// assert_eq!("tilt:54.7".parse::<LatticeOrientation>(), Ok(LatticeOrientation::Tilt { degrees: 54.7 }));
    /// assert_eq!("random:3".parse::<LatticeOrientation>(), Ok(LatticeOrientation::Random { seed: Some(3) }));
    /// assert!("tilt:200".parse::<LatticeOrientation>().unwrap_err().contains("0 to 180"));
    /// ```
    fn from_str(s: &str) -> Result<Self, String> {
        let expected = "expected perpendicular, parallel, tilt:DEG (degrees, 0 to 180) or random[:SEED]";
        let (kind, arg) = s.split_once(':').unwrap_or((s, ""));
        match (kind, arg.is_empty()) {
            ("perpendicular", true) => Ok(LatticeOrientation::Perpendicular),
            ("parallel", true) => Ok(LatticeOrientation::Parallel),
            ("random", true) => Ok(LatticeOrientation::Random { seed: None }),
            ("random", false) => arg
                .trim()
                .parse::<u64>()
                .map(|seed| LatticeOrientation::Random { seed: Some(seed) })
                .map_err(|_| format!("--lattice-orientation: `{s}`: the seed must be a whole number; {expected}")),
            ("tilt", false) => match arg.trim().parse::<f64>() {
                Ok(d) if (0.0..=180.0).contains(&d) => Ok(LatticeOrientation::Tilt { degrees: d }),
                _ => Err(format!("--lattice-orientation: `{s}`: {expected}")),
            },
            _ => Err(format!("--lattice-orientation: `{s}`: {expected}")),
        }
    }
}

impl LatticeOrientation {
    /// The name written in reports: `perpendicular`, `parallel`, `tilt:DEG` or `random:SEED` with the seed
    /// actually used (`build_seed` where none was given).
    pub fn name(&self, build_seed: u64) -> String {
        match self {
            LatticeOrientation::Perpendicular => "perpendicular".into(),
            LatticeOrientation::Parallel => "parallel".into(),
            LatticeOrientation::Tilt { degrees } => format!("tilt:{degrees}"),
            LatticeOrientation::Random { seed } => format!("random:{}", seed.unwrap_or(build_seed)),
        }
    }

    /// The rotation taking lattice coordinates to body coordinates (`build_seed` seeds `random` without a seed).
    pub fn rotation(&self, build_seed: u64) -> Mat3 {
        let about_x = |deg: f64| {
            let (s, c) = deg.to_radians().sin_cos();
            Mat3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
        };
        match self {
            LatticeOrientation::Perpendicular => Mat3::identity(),
            LatticeOrientation::Parallel => about_x(90.0),
            LatticeOrientation::Tilt { degrees } => about_x(*degrees),
            LatticeOrientation::Random { seed } => {
                let q = random_quaternion(&mut generator(seed.unwrap_or(build_seed)));
                // scalar last (crate::random's convention)
                let unit = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[3], q[0], q[1], q[2]));
                *unit.to_rotation_matrix().matrix()
            }
        }
    }

    /// Angle (degrees, 0–90) between the lattice's stacking axis, turned into the body, and the spin axis z.
    pub fn stacking_axis_tilt_deg(&self, build_seed: u64) -> f64 {
        let c = self.rotation(build_seed) * Vec3::z();
        c.z.abs().min(1.0).acos().to_degrees()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Guards the rotations: orthonormal with determinant 1, the named tilts put the stacking axis where they
    /// say, and a random orientation is reproducible from its seed and differs between seeds.
    #[test]
    fn orientations_are_proper_rotations_with_the_named_tilts() {
        let all = [
            LatticeOrientation::Perpendicular,
            LatticeOrientation::Parallel,
            LatticeOrientation::Tilt { degrees: 54.7356 },
            LatticeOrientation::Random { seed: Some(1) },
            LatticeOrientation::Random { seed: None },
        ];
        for o in all {
            let r = o.rotation(9);
            assert!((r.transpose() * r - Mat3::identity()).norm() < 1e-12, "{o:?}");
            assert!((r.determinant() - 1.0).abs() < 1e-12, "{o:?}");
        }
        assert_eq!(LatticeOrientation::Perpendicular.stacking_axis_tilt_deg(0), 0.0);
        assert!((LatticeOrientation::Parallel.stacking_axis_tilt_deg(0) - 90.0).abs() < 1e-9);
        assert!((LatticeOrientation::Tilt { degrees: 54.7356 }.stacking_axis_tilt_deg(0) - 54.7356).abs() < 1e-9);
        let random = LatticeOrientation::Random { seed: None };
        assert_eq!(
            random.rotation(4),
            LatticeOrientation::Random { seed: Some(4) }.rotation(0)
        );
        assert!((random.rotation(4) - random.rotation(5)).norm() > 1e-3);
        assert_eq!(random.name(4), "random:4");
    }

    /// The stacking axis of random orientations is isotropic: |cos tilt| is uniform on [0, 1], mean 1/2.
    #[test]
    fn random_stacking_axes_are_isotropic() {
        let n = 4000;
        let mean = (0..n)
            .map(|s| {
                LatticeOrientation::Random { seed: Some(s) }
                    .stacking_axis_tilt_deg(0)
                    .to_radians()
                    .cos()
            })
            .sum::<f64>()
            / n as f64;
        // standard error of the mean of U(0,1): 1/sqrt(12 n) = 0.0046
        assert!((mean - 0.5).abs() < 0.02, "{mean}");
    }
}
