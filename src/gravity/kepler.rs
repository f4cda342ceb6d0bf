//! Two-body (Kepler) orbits given by perigee distance, eccentricity, time of perigee and orientation, with
//! Kepler's equation solved by Newton's method: elliptic `E − e sin E = M`, hyperbolic `e sinh H − H = M`
//! (Danby, *Fundamentals of Celestial Mechanics*, 2nd ed., §6.3–6.4 and §6.6; Murray & Dermott 1999 §2.4–2.6).
//!
//! Used by the ellipsoid engine's flyby tide (a layer above this one): the frame origin falls freely on such an
//! orbit about a planet. The orbit is the relative motion `s(t)` of the orbiting point with respect to the central mass.
//! Conventions: the perifocal frame has `x̂` towards perigee and `ẑ` along the orbital angular momentum; the
//! orientation is the classical `(Ω, i, ω)` (longitude of the node, inclination, argument of perigee), so that
//! the perifocal axes in the frame are the columns of `R_z(Ω) R_x(i) R_z(ω)`. Angles in radians internally.

use crate::math::{Mat3, Vec3};

/// Newton iterations at most; from the starting guesses below both equations converge quadratically in a handful.
const MAX_NEWTON: usize = 100;

/// A Kepler orbit about a central mass of gravitational parameter `gm` (m³ s⁻²).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeplerOrbit {
    /// Gravitational parameter `G M` of the central mass (m³ s⁻², > 0).
    pub gm: f64,
    /// Perigee (pericentre) distance `q` (m, > 0).
    pub q: f64,
    /// Eccentricity `e` (≥ 0, ≠ 1): < 1 elliptic, > 1 hyperbolic; infinite for a massless centre (`gm = 0`),
    /// whose "orbit" is the straight line at `v_inf` through perigee.
    pub e: f64,
    /// Speed at infinity (m/s) of a hyperbola or a straight line; 0 for an ellipse.
    pub v_inf: f64,
    /// Time of perigee passage (s).
    pub t_perigee: f64,
    /// Perifocal → frame rotation (columns: perigee direction, 90° ahead in the plane, orbit normal).
    pub rotation: Mat3,
}

/// The orbit could not be built from the given elements.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum KeplerError {
    /// An element is out of range (the message names it and the expected value).
    #[error("{0}")]
    Invalid(String),
}

/// `R_z(Ω) R_x(i) R_z(ω)`: perifocal → frame (angles in rad).
pub fn orientation_matrix(node: f64, inclination: f64, arg_perigee: f64) -> Mat3 {
    let rz = |a: f64| Mat3::new(a.cos(), -a.sin(), 0.0, a.sin(), a.cos(), 0.0, 0.0, 0.0, 1.0);
    let (ci, si) = (inclination.cos(), inclination.sin());
    let rx = Mat3::new(1.0, 0.0, 0.0, 0.0, ci, -si, 0.0, si, ci);
    rz(node) * rx * rz(arg_perigee)
}

impl KeplerOrbit {
    /// An orbit from its perigee distance `q` (m), eccentricity `e` and orientation (`GM` > 0); errors name the
    /// element.
    pub fn new(gm: f64, q: f64, e: f64, t_perigee: f64, rotation: Mat3) -> Result<Self, KeplerError> {
        if !(gm.is_finite() && gm > 0.0) {
            return Err(KeplerError::Invalid(format!("GM must be > 0 m^3 s^-2, got {gm}")));
        }
        if !(q.is_finite() && q > 0.0) {
            return Err(KeplerError::Invalid(format!("q must be > 0 m, got {q}")));
        }
        if !(e.is_finite() && e >= 0.0 && e != 1.0) {
            return Err(KeplerError::Invalid(format!(
                "eccentricity must be >= 0 and != 1 (parabolic orbits are not supported), got {e}"
            )));
        }
        if !t_perigee.is_finite() {
            return Err(KeplerError::Invalid(format!(
                "t_perigee must be finite, got {t_perigee}"
            )));
        }
        let v_inf = if e > 1.0 { (gm * (e - 1.0) / q).sqrt() } else { 0.0 };
        Ok(KeplerOrbit {
            gm,
            q,
            e,
            v_inf,
            t_perigee,
            rotation,
        })
    }

    /// A hyperbolic orbit from `q` (m) and the speed at infinity `v_inf` (m/s, > 0): `e = 1 + q v∞²/GM`; with
    /// `GM = 0` the straight line at `v_inf` through perigee (the motion with the centre's attraction off).
    pub fn hyperbolic(gm: f64, q: f64, v_inf: f64, t_perigee: f64, rotation: Mat3) -> Result<Self, KeplerError> {
        if !(v_inf.is_finite() && v_inf > 0.0) {
            return Err(KeplerError::Invalid(format!("v_inf must be > 0 m/s, got {v_inf}")));
        }
        if gm == 0.0 {
            // The e → ∞ limit: a massless centre does not bend the path.
            let mut line = KeplerOrbit::new(1.0, q, 2.0, t_perigee, rotation)?;
            (line.gm, line.e, line.v_inf) = (0.0, f64::INFINITY, v_inf);
            return Ok(line);
        }
        let mut orbit = KeplerOrbit::new(gm, q, 1.0 + q * v_inf * v_inf / gm, t_perigee, rotation)?;
        orbit.v_inf = v_inf;
        Ok(orbit)
    }

    /// Semi-major axis `a = q/(1 − e)` (m; negative for a hyperbola).
    pub fn semi_major_axis(&self) -> f64 {
        self.q / (1.0 - self.e)
    }

    /// Mean motion `n = sqrt(GM/|a|³)` (rad/s).
    pub fn mean_motion(&self) -> f64 {
        let a = self.semi_major_axis().abs();
        (self.gm / (a * a * a)).sqrt()
    }

    /// Position (m) and velocity (m/s) at time `t` (s) of the orbiting point relative to the central mass.
    pub fn state(&self, t: f64) -> (Vec3, Vec3) {
        if self.gm == 0.0 {
            let v = self.v_inf;
            return (
                self.rotation * Vec3::new(self.q, v * (t - self.t_perigee), 0.0),
                self.rotation * Vec3::new(0.0, v, 0.0),
            );
        }
        let (e, n) = (self.e, self.mean_motion());
        let m = n * (t - self.t_perigee);
        let (x, y, vx, vy) = if e < 1.0 {
            let a = self.semi_major_axis();
            let big_e = solve_elliptic(e, m);
            let (s, c) = big_e.sin_cos();
            let b = a * (1.0 - e * e).sqrt();
            let e_dot = n / (1.0 - e * c);
            (a * (c - e), b * s, -a * s * e_dot, b * c * e_dot)
        } else {
            let a = -self.semi_major_axis();
            let h = solve_hyperbolic(e, m);
            let (s, c) = (h.sinh(), h.cosh());
            let b = a * (e * e - 1.0).sqrt();
            let h_dot = n / (e * c - 1.0);
            // At H = 0 the point is at perigee: x = a (e − 1) = q.
            (a * (e - c), b * s, -a * s * h_dot, b * c * h_dot)
        };
        (
            self.rotation * Vec3::new(x, y, 0.0),
            self.rotation * Vec3::new(vx, vy, 0.0),
        )
    }

    /// The time (s) after perigee at which the distance reaches `r` (m, ≥ q) on the outgoing branch, or `None`
    /// when an ellipse never gets that far (r above apogee).
    pub fn time_from_perigee_at_distance(&self, r: f64) -> Option<f64> {
        let e = self.e;
        if r.is_nan() || r < self.q {
            return None;
        }
        if self.gm == 0.0 {
            return Some((r * r - self.q * self.q).sqrt() / self.v_inf);
        }
        let n = self.mean_motion();
        if e < 1.0 {
            let a = self.semi_major_axis();
            // r = a (1 − e cos E).
            let c = (1.0 - r / a) / e.max(f64::MIN_POSITIVE);
            if c < -1.0 {
                return None;
            }
            let big_e = c.clamp(-1.0, 1.0).acos();
            Some((big_e - e * big_e.sin()) / n)
        } else {
            let a = -self.semi_major_axis();
            // r = a (e cosh H − 1).
            let h = ((r / a + 1.0) / e).max(1.0).acosh();
            Some((e * h.sinh() - h) / n)
        }
    }
}

/// Solves `E − e sin E = M` (e in [0, 1)) by Newton's method; `M` any real (rad).
pub fn solve_elliptic(e: f64, mean_anomaly: f64) -> f64 {
    let two_pi = 2.0 * std::f64::consts::PI;
    // Work on M in (−π, π] and add the whole turns back: E − M is 2π-periodic.
    let turns = (mean_anomaly / two_pi).round();
    let m = mean_anomaly - turns * two_pi;
    let mut x = if e < 0.8 {
        m + e * m.sin()
    } else {
        std::f64::consts::PI.copysign(m)
    };
    for _ in 0..MAX_NEWTON {
        let dx = (x - e * x.sin() - m) / (1.0 - e * x.cos());
        x -= dx;
        if dx.abs() <= 4.0 * f64::EPSILON * x.abs().max(1.0) {
            break;
        }
    }
    x + turns * two_pi
}

/// Solves `e sinh H − H = M` (e > 1) by Newton's method; `M` any real.
pub fn solve_hyperbolic(e: f64, mean_anomaly: f64) -> f64 {
    let m = mean_anomaly.abs();
    // Start at or above the root, where Newton on the convex (for H ≥ 0) f(H) = e sinh H − H − M decreases
    // monotonically to it: f(H) ≥ (e − 1) sinh H − M, so f ≥ 0 at asinh(M/(e − 1)); the usual guess
    // ln(2M/e + 1.8) is closer for large M and is used when it is also above the root.
    let f = |h: f64| e * h.sinh() - h - m;
    let mut x = (m / (e - 1.0)).asinh();
    let guess = (2.0 * m / e + 1.8).ln();
    if guess < x && f(guess) >= 0.0 {
        x = guess;
    }
    for _ in 0..MAX_NEWTON {
        let dx = f(x) / (e * x.cosh() - 1.0);
        x -= dx;
        if dx.abs() <= 4.0 * f64::EPSILON * x.abs().max(1.0) {
            break;
        }
    }
    x.copysign(mean_anomaly)
}
