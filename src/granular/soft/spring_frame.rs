//! Carrying spring histories along with the contact frame (Zhang17 §2.2.1–2.2.2: "transforming δ_T according to the
//! change in n̂"). Each step the tangential and rolling springs turn by the shortest-arc swing from the old normal to
//! the new, then about the new normal by the pair's mean spin about the mean normal times the step (twist); lengths
//! are kept and a rounding residue along the normal is projected out. A rigidly co-rotating pair's springs stay fixed
//! in its frame to second order (`tests/ssdem_spring_frame.rs`).
//!
//! No trigonometry (once per contact and step): the swing is Rodrigues' `R v = c v + a × v + a (a·v)/(1 + c)` with
//! `a = n_old × n_new`, `c = n_old · n_new` (exact, `|a|² = (1 − c)(1 + c)`); the twist's sine and cosine are Taylor
//! series to the 9th and 8th power (below 2⁻⁵ rad the first omitted term is under 10⁻¹⁸ of the angle). Nearly
//! antiparallel normals fall back to an explicit axis–angle rotation.

use crate::math::Vec3;
use nalgebra::{Rotation3, Unit};

/// Below this value of `1 + n_old · n_new` the swing is built as an explicit axis–angle rotation.
const NEAR_ANTIPARALLEL: f64 = 1e-6;
/// Values of `1 − n_old · n_new` below this take `1/(1 + cos)` and `1/|n_old + n_new|` from series.
const SMALL_TILT: f64 = 1e-6;
/// Twist angles (rad) below this take their sine and cosine from the Taylor series.
const SMALL_ANGLE: f64 = 1.0 / 32.0;

/// The rotation carrying the contact frame over one step: normal `n_old` to `n_new` plus the pair's mean spin
/// about the mean normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameRotation {
    /// `n_old × n_new`.
    axis: Vec3,
    /// `n_old · n_new`.
    cos: f64,
    /// `1 / (1 + n_old · n_new)`.
    inv_one_plus_cos: f64,
    /// The new normal (the twist axis).
    normal: Vec3,
    /// The twist angle (rad), its cosine and sine.
    twist: f64,
    twist_cos: f64,
    twist_sin: f64,
}

/// `(sin x, cos x)`, by Taylor series for small `|x|`.
#[inline(always)]
fn sin_cos(x: f64) -> (f64, f64) {
    if x.abs() < SMALL_ANGLE {
        let x2 = x * x;
        let s = x
            * (1.0
                - x2 * (1.0 / 6.0) * (1.0 - x2 * (1.0 / 20.0) * (1.0 - x2 * (1.0 / 42.0) * (1.0 - x2 * (1.0 / 72.0)))));
        let c = 1.0 - x2 * 0.5 * (1.0 - x2 * (1.0 / 12.0) * (1.0 - x2 * (1.0 / 30.0) * (1.0 - x2 * (1.0 / 56.0))));
        (s, c)
    } else {
        x.sin_cos()
    }
}

impl FrameRotation {
    /// The rotation carrying the contact frame from normal `n_old` to `n_new` (unit vectors), with the pair's
    /// mean spin `mean_spin` (rad/s) acting for `dt` (s) about the mean normal.
    ///
    /// ```
    /// use rubblepile::granular::soft::spring_frame::FrameRotation;
    /// use rubblepile::math::Vec3;
    /// let r = FrameRotation::new(&Vec3::x(), &Vec3::y(), &Vec3::zeros(), 0.0);
    /// assert!((r.apply(&Vec3::x()) - Vec3::y()).norm() < 1e-15);
    /// assert!((r.apply(&Vec3::z()) - Vec3::z()).norm() < 1e-15);
    /// ```
    #[inline(always)]
    pub fn new(n_old: &Vec3, n_new: &Vec3, mean_spin: &Vec3, dt: f64) -> Self {
        let axis = n_old.cross(n_new);
        let cos = n_old.dot(n_new);
        let mean = n_old + n_new;
        // 1/(1 + cos) and 1/|n_old + n_new| = 1/√(2 (1 + cos)); for the tiny tilts of one step, with
        // e = 1 − cos, from their series ½ (1 + e/2 + e²/4) and ½ (1 + e/4 + 3e²/32) (the first omitted
        // terms are below 10⁻¹⁸ for e < 10⁻⁶), else directly.
        let e = 1.0 - cos;
        let (inv_one_plus_cos, inv_mean_size) = if e.abs() < SMALL_TILT {
            (
                0.5 * (1.0 + e * (0.5 + 0.25 * e)),
                0.5 * (1.0 + e * (0.25 + (3.0 / 32.0) * e)),
            )
        } else if 1.0 + cos > NEAR_ANTIPARALLEL {
            let inv = 1.0 / (1.0 + cos);
            (inv, (0.5 * inv).sqrt())
        } else {
            // Nearly antiparallel: 1 + cos has lost its digits, measure the sum itself.
            let size = mean.norm();
            (1.0 / (1.0 + cos), if size > 0.0 { 1.0 / size } else { 0.0 })
        };
        let twist = if inv_mean_size > 0.0 {
            mean_spin.dot(&mean) * dt * inv_mean_size
        } else {
            mean_spin.dot(n_new) * dt
        };
        let (twist_sin, twist_cos) = sin_cos(twist);
        FrameRotation {
            axis,
            cos,
            inv_one_plus_cos,
            normal: *n_new,
            twist,
            twist_cos,
            twist_sin,
        }
    }

    /// Whether the normals are too close to antiparallel for Rodrigues' formula in `a` and `c`.
    #[inline(always)]
    fn near_antiparallel(&self) -> bool {
        1.0 + self.cos <= NEAR_ANTIPARALLEL
    }

    /// The rotation as an explicit composition of axis–angle rotations (nearly antiparallel normals).
    #[cold]
    fn general(&self) -> Rotation3<f64> {
        let sin = self.axis.norm();
        let swing = if sin > 1e-300 {
            Rotation3::from_axis_angle(&Unit::new_unchecked(self.axis / sin), sin.atan2(self.cos))
        } else {
            // Antiparallel normals: half a turn about any axis perpendicular to them.
            let n = &self.normal;
            let other = if n.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() };
            Rotation3::from_axis_angle(&Unit::new_normalize(n.cross(&other)), std::f64::consts::PI)
        };
        Rotation3::from_axis_angle(&Unit::new_unchecked(self.normal), self.twist) * swing
    }

    /// The swing part: Rodrigues' formula with `a = n_old × n_new`, `c = n_old · n_new`.
    #[inline(always)]
    fn swing(&self, v: &Vec3) -> Vec3 {
        let a = &self.axis;
        v * self.cos + a.cross(v) + a * (a.dot(v) * self.inv_one_plus_cos)
    }

    /// The rotated vector.
    #[inline(always)]
    pub fn apply(&self, v: &Vec3) -> Vec3 {
        if self.near_antiparallel() {
            return self.general() * v;
        }
        let w = self.swing(v);
        let n = &self.normal;
        w * self.twist_cos + n.cross(&w) * self.twist_sin + n * (n.dot(&w) * (1.0 - self.twist_cos))
    }

    /// Rotates a tangential spring and removes any component along the new normal. (The twist moves no
    /// component along its axis, so the projection is applied to the swung spring before the twist.)
    #[inline(always)]
    pub fn carry(&self, spring: &Vec3) -> Vec3 {
        let n = &self.normal;
        if self.near_antiparallel() {
            let s = self.general() * spring;
            return s - n * s.dot(n);
        }
        let w = self.swing(spring);
        let w = w - n * n.dot(&w);
        w * self.twist_cos + n.cross(&w) * self.twist_sin
    }
}
