//! Prescribed wall motion (Richardson11 §2.2: walls may translate, oscillate and, for cylinders, spin; derivations in
//! the docs of `geometry::walls`, "Particle–wall").
//!
//! The wall's reference point is `o(t) = origin + V t + A (sin(ω t + φ) − sin φ) d̂`, so `origin` is where the wall
//! is at t = 0 whatever the phase. Within one step `[t0, t1]` the wall moves on the straight secant from `o(t0)` to
//! `o(t1)` with the constant velocity `(o(t1) − o(t0))/(t1 − t0)` ("the wall's velocity is held constant within a
//! step"): the relative motion of a particle and a wall is then a straight line, every time of impact is exact, and
//! the wall is exactly where its law puts it at the step ends. The spin Ω (rad/s, right-handed about the wall axis)
//! moves no surface of these axisymmetric primitives; it only adds `Ω â × ρ` to the surface velocity.
//!
//! The [`Oscillation`] law is the one of both granular engines: the soft-sphere walls (`walls::soft`) take its
//! displacement and its exact velocity at the current time.

use crate::math::Vec3;

/// Sinusoidal oscillation `A (sin(ω t + φ) − sin φ) d̂`: zero at t = 0 whatever the phase.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Oscillation {
    /// Amplitude A (m), ≥ 0.
    pub amplitude: f64,
    /// Angular frequency ω (rad/s).
    pub omega: f64,
    /// Phase φ (rad).
    pub phase: f64,
    /// Unit direction d̂.
    pub direction: Vec3,
}

impl Oscillation {
    /// Displacement `A (sin(ω t + φ) − sin φ) d̂` (m) at time `t` (s).
    pub fn displacement(&self, t: f64) -> Vec3 {
        self.direction * (self.amplitude * ((self.omega * t + self.phase).sin() - self.phase.sin()))
    }

    /// Velocity `A ω cos(ω t + φ) d̂` (m/s) at time `t` (s): the time derivative of [`Oscillation::displacement`].
    pub fn velocity(&self, t: f64) -> Vec3 {
        self.direction * (self.amplitude * (self.omega * (self.omega * t + self.phase).cos()))
    }
}

/// How a wall moves.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WallMotion {
    /// Constant translation velocity V (m/s).
    pub velocity: Vec3,
    /// Optional oscillation.
    pub oscillation: Option<Oscillation>,
    /// Spin Ω about the wall axis (rad/s).
    pub spin: f64,
}

impl WallMotion {
    /// Displacement `o(t) − origin` (m).
    pub fn displacement(&self, t: f64) -> Vec3 {
        let mut d = self.velocity * t;
        if let Some(o) = &self.oscillation {
            d += o.displacement(t);
        }
        d
    }

    /// The secant velocity over `[t0, t1]` (m/s), used for the whole step.
    pub fn step_velocity(&self, t0: f64, t1: f64) -> Vec3 {
        if t1 > t0 {
            (self.displacement(t1) - self.displacement(t0)) / (t1 - t0)
        } else {
            self.velocity
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The soft-sphere walls' former law, `A sin(2π f t)` with velocity `2π f A cos(2π f t)` for an amplitude vector
    /// `A` along an axis, is this law to the bit with `ω = 2π f` (the product as the old law formed it),
    /// `amplitude = |A|`, `direction` the signed axis and `φ = 0`: scenes migrated to the one oscillation run as
    /// before.
    #[test]
    fn old_soft_oscillation_is_the_same_law_to_the_bit() {
        for (a, axis) in [([0.0, 0.0, 0.01], 2), ([-0.3, 0.0, 0.0], 0), ([0.0, 7e-4, 0.0], 1)] {
            for f in [5.0, 0.3, 17.125, 1e-3] {
                let w = std::f64::consts::TAU * f;
                let mut direction = Vec3::zeros();
                direction[axis] = f64::signum(a[axis]);
                let new = Oscillation {
                    amplitude: f64::abs(a[axis]),
                    omega: w,
                    phase: 0.0,
                    direction,
                };
                for t in [0.0, 1e-4, 0.37, 12.5, 1234.567] {
                    let old_offset = Vec3::from(a) * (std::f64::consts::TAU * f * t).sin();
                    let old_velocity = Vec3::from(a) * (w * (w * t).cos());
                    for k in 0..3 {
                        assert_eq!(
                            new.displacement(t)[k].to_bits(),
                            old_offset[k].to_bits(),
                            "A {a:?} f {f} t {t}"
                        );
                        assert_eq!(
                            new.velocity(t)[k].to_bits(),
                            old_velocity[k].to_bits(),
                            "A {a:?} f {f} t {t}"
                        );
                    }
                }
            }
        }
    }
}
