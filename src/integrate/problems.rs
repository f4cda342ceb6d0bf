//! Canonical test problems with known solutions or invariants, shared by the integrator tests and benchmarks; each
//! a small struct implementing [`OdeSystem`] and [`TestProblem`] (initial state, natural end time, exact solution
//! where known): [`HarmonicOscillator`] (order of convergence), [`Kepler`] (Kepler's equation, energy, angular
//! momentum), [`Arenstorf`] (restricted three-body periodic orbit, hard step control), [`ExponentialDecay`] (mildly
//! stiff), [`StiffDampedOscillator`] (stiffness ratio ~4ζ², exact Jacobian), [`RigidBody`] (Euler's equations,
//! exact via [`torque_free_spin`]). The ellipsoid model's problems are in `impact::problems`.

use crate::integrate::OdeSystem;
use crate::integrate::elliptic::{incomplete_f, jacobi_sn_cn_dn};
use crate::integrate::linearly_implicit::{DenseStiff, StiffSolve};
use std::f64::consts::PI;

/// A test problem: an [`OdeSystem`] with an initial state, a natural end time and (optionally)
/// an exact solution.
pub trait TestProblem: OdeSystem {
    /// Short name for reports and benchmark tables.
    fn name(&self) -> &'static str;
    /// Initial time `t0`.
    fn t0(&self) -> f64 {
        0.0
    }
    /// Initial state `y(t0)`.
    fn initial_state(&self) -> Vec<f64>;
    /// The natural end time of the problem.
    fn t_end(&self) -> f64;
    /// The exact solution `y(t)`, where one is known in closed form.
    fn exact(&self, _t: f64) -> Option<Vec<f64>> {
        None
    }
}

/// Harmonic oscillator `x'' = −ω² x`, state `[x, v]`, started at `x = 1, v = 0`.
///
/// Exact solution `x = cos ωt`, `v = −ω sin ωt`; invariant `E = ½ v² + ½ ω² x²` (= ½ ω² initially).
/// The natural end time is ten periods.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HarmonicOscillator {
    /// Angular frequency ω (rad per unit time, > 0).
    pub omega: f64,
}

impl HarmonicOscillator {
    /// An oscillator of angular frequency `omega`.
    pub fn new(omega: f64) -> Self {
        HarmonicOscillator { omega }
    }
    /// The period `2π/ω`.
    pub fn period(&self) -> f64 {
        2.0 * PI / self.omega
    }
    /// Energy `½ v² + ½ ω² x²` of the state `y = [x, v]`.
    pub fn energy(&self, y: &[f64]) -> f64 {
        0.5 * y[1] * y[1] + 0.5 * self.omega * self.omega * y[0] * y[0]
    }
}

impl OdeSystem for HarmonicOscillator {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, y: &[f64], dydt: &mut [f64]) {
        dydt[0] = y[1];
        dydt[1] = -self.omega * self.omega * y[0];
    }
}

impl TestProblem for HarmonicOscillator {
    fn name(&self) -> &'static str {
        "harmonic-oscillator"
    }
    fn initial_state(&self) -> Vec<f64> {
        vec![1.0, 0.0]
    }
    fn t_end(&self) -> f64 {
        10.0 * self.period()
    }
    fn exact(&self, t: f64) -> Option<Vec<f64>> {
        let (s, c) = (self.omega * t).sin_cos();
        Some(vec![c, -self.omega * s])
    }
}

/// Planar Kepler two-body problem `r'' = −r/|r|³` (G M = 1) with eccentricity `e`, semi-major
/// axis 1 and period 2π, state `[x, y, vx, vy]`.
///
/// Starts at pericentre `(1 − e, 0)` with velocity `(0, √((1+e)/(1−e)))`. The exact solution
/// comes from Kepler's equation `E − e sin E = t` (mean motion 1), solved by Newton's method.
/// Invariants: energy `−½` and angular momentum `√(1 − e²)`. The natural end time is
/// [`Kepler::orbits`] periods.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kepler {
    /// Eccentricity, `0 ≤ e < 1`.
    pub e: f64,
    /// Number of orbits in [`TestProblem::t_end`].
    pub orbits: f64,
}

impl Kepler {
    /// An orbit of eccentricity `e`, integrated over one period by default.
    pub fn new(e: f64) -> Self {
        assert!((0.0..1.0).contains(&e), "Kepler eccentricity must be in [0, 1)");
        Kepler { e, orbits: 1.0 }
    }
    /// The same orbit, with [`TestProblem::t_end`] spanning `orbits` periods.
    pub fn with_orbits(mut self, orbits: f64) -> Self {
        self.orbits = orbits;
        self
    }
    /// The orbital period `2π`.
    pub fn period(&self) -> f64 {
        2.0 * PI
    }
    /// Eccentric anomaly `E` solving Kepler's equation `E − e sin E = M`.
    pub fn eccentric_anomaly(&self, mean_anomaly: f64) -> f64 {
        // Reduce to [-π, π]; the position depends only on E mod 2π.
        let turns = (mean_anomaly / (2.0 * PI)).round();
        let m = mean_anomaly - turns * 2.0 * PI;
        let e = self.e;
        let mut big_e = if e > 0.8 { m.signum() * PI } else { m };
        if m == 0.0 {
            big_e = 0.0;
        }
        for _ in 0..100 {
            let f = big_e - e * big_e.sin() - m;
            let df = 1.0 - e * big_e.cos();
            let d = f / df;
            big_e -= d;
            if d.abs() <= 1e-16 * (1.0 + big_e.abs()) {
                break;
            }
        }
        big_e + turns * 2.0 * PI
    }
    /// Total energy `½ |v|² − 1/|r|` (exactly `−½` for this orbit).
    pub fn energy(&self, y: &[f64]) -> f64 {
        let r = (y[0] * y[0] + y[1] * y[1]).sqrt();
        0.5 * (y[2] * y[2] + y[3] * y[3]) - 1.0 / r
    }
    /// Angular momentum `x vy − y vx` (exactly `√(1 − e²)`).
    pub fn angular_momentum(&self, y: &[f64]) -> f64 {
        y[0] * y[3] - y[1] * y[2]
    }
}

impl OdeSystem for Kepler {
    fn dim(&self) -> usize {
        4
    }
    fn rhs(&self, _t: f64, y: &[f64], dydt: &mut [f64]) {
        let r2 = y[0] * y[0] + y[1] * y[1];
        let r3 = r2 * r2.sqrt();
        dydt[0] = y[2];
        dydt[1] = y[3];
        dydt[2] = -y[0] / r3;
        dydt[3] = -y[1] / r3;
    }
}

impl TestProblem for Kepler {
    fn name(&self) -> &'static str {
        "kepler"
    }
    fn initial_state(&self) -> Vec<f64> {
        let e = self.e;
        vec![1.0 - e, 0.0, 0.0, ((1.0 + e) / (1.0 - e)).sqrt()]
    }
    fn t_end(&self) -> f64 {
        self.orbits * self.period()
    }
    fn exact(&self, t: f64) -> Option<Vec<f64>> {
        let e = self.e;
        let big_e = self.eccentric_anomaly(t);
        let (s, c) = big_e.sin_cos();
        let b = (1.0 - e * e).sqrt();
        let denom = 1.0 - e * c; // r / a
        Some(vec![c - e, b * s, -s / denom, b * c / denom])
    }
}

/// The Arenstorf orbit: a periodic solution of the planar restricted three-body problem
/// (Earth–Moon mass ratio), the classic step-size-control test of Hairer, Nørsett & Wanner
/// (*Solving ODEs I*, §II.0). State `[x, y, vx, vy]` in the rotating frame.
///
/// The orbit returns to its initial state after [`Arenstorf::PERIOD`]; it passes very close to
/// the Moon, so a fixed-step method needs tens of thousands of steps.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Arenstorf;

impl Arenstorf {
    /// Reduced mass μ of the Moon.
    pub const MU: f64 = 0.012277471;
    /// Period of the orbit.
    #[allow(clippy::excessive_precision)]
    pub const PERIOD: f64 = 17.065_216_560_157_962_558_891_720_624_9;
    /// Initial y-velocity.
    #[allow(clippy::excessive_precision)]
    pub const VY0: f64 = -2.001_585_106_379_082_522_405_378_622_24;
}

impl OdeSystem for Arenstorf {
    fn dim(&self) -> usize {
        4
    }
    fn rhs(&self, _t: f64, y: &[f64], dydt: &mut [f64]) {
        let mu = Arenstorf::MU;
        let mu1 = 1.0 - mu;
        let d1 = (y[0] + mu).powi(2) + y[1] * y[1];
        let d1 = d1 * d1.sqrt();
        let d2 = (y[0] - mu1).powi(2) + y[1] * y[1];
        let d2 = d2 * d2.sqrt();
        dydt[0] = y[2];
        dydt[1] = y[3];
        dydt[2] = y[0] + 2.0 * y[3] - mu1 * (y[0] + mu) / d1 - mu * (y[0] - mu1) / d2;
        dydt[3] = y[1] - 2.0 * y[2] - mu1 * y[1] / d1 - mu * y[1] / d2;
    }
}

impl TestProblem for Arenstorf {
    fn name(&self) -> &'static str {
        "arenstorf"
    }
    fn initial_state(&self) -> Vec<f64> {
        vec![0.994, 0.0, 0.0, Arenstorf::VY0]
    }
    fn t_end(&self) -> f64 {
        Arenstorf::PERIOD
    }
    /// Known only at multiples of the period, where it equals the initial state.
    fn exact(&self, t: f64) -> Option<Vec<f64>> {
        if t == 0.0 || t == Arenstorf::PERIOD {
            Some(self.initial_state())
        } else {
            None
        }
    }
}

/// Exponential decay `y' = −λ y`, `y(0) = 1`, exact `y = e^{−λt}`; mildly stiff for large λ
/// (explicit methods are limited by stability to `h ≲ c/λ` once the transient has decayed).
/// The natural end time is 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExponentialDecay {
    /// Decay rate λ (> 0).
    pub lambda: f64,
}

impl ExponentialDecay {
    /// Decay at rate `lambda`.
    pub fn new(lambda: f64) -> Self {
        ExponentialDecay { lambda }
    }
}

impl OdeSystem for ExponentialDecay {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, _t: f64, y: &[f64], dydt: &mut [f64]) {
        dydt[0] = -self.lambda * y[0];
    }
}

impl TestProblem for ExponentialDecay {
    fn name(&self) -> &'static str {
        "exponential-decay"
    }
    fn initial_state(&self) -> Vec<f64> {
        vec![1.0]
    }
    fn t_end(&self) -> f64 {
        1.0
    }
    fn exact(&self, t: f64) -> Option<Vec<f64>> {
        Some(vec![(-self.lambda * t).exp()])
    }
}

/// The overdamped oscillator `x'' + 2 ζ ω x' + ω² x = 0` (ζ > 1), state `[x, v]`, started at `x = 1, v = 0`: the
/// contact of two bodies under strong linear damping, reduced to one coordinate.
///
/// Its modes decay at `λ_fast = −ω (ζ + s)` and `λ_slow = −ω/(ζ + s)` (`s = √(ζ² − 1)`, the second written so that
/// it does not cancel): a stiffness ratio of about `4 ζ²`. Exact solution
/// `x = A e^{λ_slow t} + B e^{λ_fast t}` with `A = λ_fast/(λ_fast − λ_slow)`, `B = 1 − A`. It supplies its exact
/// (constant) Jacobian `[[0, 1], [−ω², −2ζω]]` as its stiff part. The natural end time is `1/|λ_slow|`, one
/// e-folding of the slow mode; an explicit method needs about `|λ_fast|/|λ_slow| ≈ 4 ζ²` steps to get there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StiffDampedOscillator {
    /// Undamped angular frequency ω (rad per unit time, > 0).
    pub omega: f64,
    /// Damping ratio ζ (> 1: overdamped).
    pub zeta: f64,
}

impl Default for StiffDampedOscillator {
    /// ω = 1, ζ = 1000 (stiffness ratio 4e6).
    fn default() -> Self {
        StiffDampedOscillator {
            omega: 1.0,
            zeta: 1000.0,
        }
    }
}

impl StiffDampedOscillator {
    /// The decay rates `(λ_slow, λ_fast)` (both negative).
    pub fn rates(&self) -> (f64, f64) {
        let s = (self.zeta * self.zeta - 1.0).sqrt();
        (-self.omega / (self.zeta + s), -self.omega * (self.zeta + s))
    }
}

impl OdeSystem for StiffDampedOscillator {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, y: &[f64], dydt: &mut [f64]) {
        dydt[0] = y[1];
        dydt[1] = -self.omega * self.omega * y[0] - 2.0 * self.zeta * self.omega * y[1];
    }
    fn stiff_part(&self, _t: f64, _y: &[f64]) -> Option<Box<dyn StiffSolve + '_>> {
        let jacobian = vec![0.0, 1.0, -self.omega * self.omega, -2.0 * self.zeta * self.omega];
        Some(Box::new(DenseStiff::new(2, jacobian)))
    }
}

impl TestProblem for StiffDampedOscillator {
    fn name(&self) -> &'static str {
        "stiff-damped-oscillator"
    }
    fn initial_state(&self) -> Vec<f64> {
        vec![1.0, 0.0]
    }
    fn t_end(&self) -> f64 {
        -1.0 / self.rates().0
    }
    fn exact(&self, t: f64) -> Option<Vec<f64>> {
        let (slow, fast) = self.rates();
        let a = fast / (fast - slow);
        let b = 1.0 - a;
        let (es, ef) = ((slow * t).exp(), (fast * t).exp());
        Some(vec![a * es + b * ef, a * slow * es + b * fast * ef])
    }
}

/// Free rigid body, Euler's equations in the body frame `I ω̇ = (I ω) × ω` with principal
/// moments `I = diag(I₁, I₂, I₃)`; state `ω = [ω₁, ω₂, ω₃]`.
///
/// Invariants: kinetic energy `½ Σ Iᵢ ωᵢ²` and the norm of the angular momentum `|I ω|`.
/// The default body (Hairer, Lubich & Wanner, *Geometric Numerical Integration*, §I.5) has
/// `I = (2, 1, 2/3)` and angular momentum `(cos 1.1, 0, sin 1.1)`; natural end time 20.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidBody {
    /// Principal moments of inertia (> 0).
    pub inertia: [f64; 3],
    /// Initial angular velocity in the body frame.
    pub omega0: [f64; 3],
}

impl Default for RigidBody {
    fn default() -> Self {
        let inertia = [2.0, 1.0, 2.0 / 3.0];
        let m0 = [1.1f64.cos(), 0.0, 1.1f64.sin()];
        RigidBody {
            inertia,
            omega0: [m0[0] / inertia[0], m0[1] / inertia[1], m0[2] / inertia[2]],
        }
    }
}

impl RigidBody {
    /// Kinetic energy `½ Σ Iᵢ ωᵢ²`.
    pub fn energy(&self, w: &[f64]) -> f64 {
        0.5 * (0..3).map(|i| self.inertia[i] * w[i] * w[i]).sum::<f64>()
    }
    /// Norm of the angular momentum `|I ω|`.
    pub fn angular_momentum_norm(&self, w: &[f64]) -> f64 {
        (0..3).map(|i| (self.inertia[i] * w[i]).powi(2)).sum::<f64>().sqrt()
    }
}

impl OdeSystem for RigidBody {
    fn dim(&self) -> usize {
        3
    }
    fn rhs(&self, _t: f64, w: &[f64], dydt: &mut [f64]) {
        let [i1, i2, i3] = self.inertia;
        dydt[0] = (i2 - i3) * w[1] * w[2] / i1;
        dydt[1] = (i3 - i1) * w[2] * w[0] / i2;
        dydt[2] = (i1 - i2) * w[0] * w[1] / i3;
    }
}

impl TestProblem for RigidBody {
    fn name(&self) -> &'static str {
        "rigid-body"
    }
    fn initial_state(&self) -> Vec<f64> {
        self.omega0.to_vec()
    }
    fn t_end(&self) -> f64 {
        20.0
    }
    /// The torque-free solution ([`torque_free_spin`]); `None` for a symmetric body.
    fn exact(&self, t: f64) -> Option<Vec<f64>> {
        torque_free_spin(self.inertia, self.omega0, t).map(|w| w.to_vec())
    }
}

/// The exact body-frame angular velocity `ω(t)` (rad/s) of a torque-free asymmetric rigid body with
/// principal moments `inertia` (kg m², any order, pairwise different) that has `ω(0) = omega0`, i.e. the
/// solution of Euler's equations `I ω̇ = (I ω) × ω` (Landau & Lifshitz, *Mechanics*, §37).
///
/// With the moments sorted `I₁ < I₂ < I₃` (an odd relabelling of the axes also flips the sign of `ω`,
/// which keeps Euler's equations), `2E = Σ Iᵢωᵢ²` and `M² = Σ (Iᵢωᵢ)²`:
/// * `M² ≥ 2E I₂` (rotation about the axis of `I₃`): `ω₁ = A₁ cn τ`, `ω₂ = s A₂ sn τ`, `ω₃ = s A₃ dn τ`
///   with `A₁² = (2EI₃ − M²)/(I₁(I₃−I₁))`, `A₂² = (2EI₃ − M²)/(I₂(I₃−I₂))`, `A₃² = (M² − 2EI₁)/(I₃(I₃−I₁))`,
///   `τ = t √((I₃−I₂)(M²−2EI₁)/(I₁I₂I₃)) + τ₀`, `m = (I₂−I₁)(2EI₃−M²)/((I₃−I₂)(M²−2EI₁))`, `s = sign ω₃(0)`;
/// * `M² < 2E I₂` (about the axis of `I₁`): the same with the roles of axes 1 and 3 exchanged
///   (`ω₁ = s A₁ dn τ`, `ω₂ = s A₂ sn τ`, `ω₃ = A₃ cn τ`, `s = sign ω₁(0)`).
///
/// The phase `τ₀ = F(φ₀ | m)` comes from the amplitude `φ₀ = atan2(sn τ₀, cn τ₀)` of the initial state.
/// Returns `None` when two moments agree to 1e-12 (a symmetric top) or an input is not finite.
///
/// ```
/// use rubblepile::integrate::problems::torque_free_spin;
/// let (i, w0) = ([1.0, 2.0, 3.0], [0.3, -0.2, 0.9]);
/// let w = torque_free_spin(i, w0, 10.0).unwrap();
/// let e = |w: &[f64; 3]| (0..3).map(|k| i[k] * w[k] * w[k]).sum::<f64>();
/// assert!((e(&w) - e(&w0)).abs() < 1e-14);
/// ```
pub fn torque_free_spin(inertia: [f64; 3], omega0: [f64; 3], t: f64) -> Option<[f64; 3]> {
    if !(inertia.iter().chain(&omega0).all(|v| v.is_finite()) && t.is_finite()) {
        return None;
    }
    let mut perm = [0usize, 1, 2];
    perm.sort_by(|&a, &b| inertia[a].total_cmp(&inertia[b]));
    // Sign of the permutation: even (cyclic) keeps the handedness, odd flips it.
    let inversions = (0..3)
        .flat_map(|a| ((a + 1)..3).map(move |b| (a, b)))
        .filter(|&(a, b)| perm[a] > perm[b])
        .count();
    let flip = if inversions % 2 == 1 { -1.0 } else { 1.0 };
    let (i1, i2, i3) = (inertia[perm[0]], inertia[perm[1]], inertia[perm[2]]);
    if i1.is_nan() || i1 <= 0.0 || i2 - i1 <= 1e-12 * i3 || i3 - i2 <= 1e-12 * i3 {
        return None;
    }
    let w = [flip * omega0[perm[0]], flip * omega0[perm[1]], flip * omega0[perm[2]]];
    let e2 = i1 * w[0] * w[0] + i2 * w[1] * w[1] + i3 * w[2] * w[2];
    if e2 == 0.0 {
        return Some([0.0; 3]);
    }
    let m2 = (i1 * w[0]).powi(2) + (i2 * w[1]).powi(2) + (i3 * w[2]).powi(2);
    let d1 = (m2 - e2 * i1).max(0.0);
    let d3 = (e2 * i3 - m2).max(0.0);
    let sign = |x: f64| if x < 0.0 { -1.0 } else { 1.0 };
    let sorted = if m2 >= e2 * i2 {
        let a1 = (d3 / (i1 * (i3 - i1))).sqrt();
        let a2 = (d3 / (i2 * (i3 - i2))).sqrt();
        let a3 = (d1 / (i3 * (i3 - i1))).sqrt();
        let rate = ((i3 - i2) * d1 / (i1 * i2 * i3)).sqrt();
        let m = ((i2 - i1) * d3 / ((i3 - i2) * d1)).clamp(0.0, 1.0);
        let s = sign(w[2]);
        let phi0 = (s * w[1] / a2).atan2(w[0] / a1);
        let phi0 = if phi0.is_nan() { 0.0 } else { phi0 };
        let (sn, cn, dn) = jacobi_sn_cn_dn(rate * t + incomplete_f(phi0, m), m);
        [a1 * cn, s * a2 * sn, s * a3 * dn]
    } else {
        let a1 = (d3 / (i1 * (i3 - i1))).sqrt();
        let a2 = (d1 / (i2 * (i2 - i1))).sqrt();
        let a3 = (d1 / (i3 * (i3 - i1))).sqrt();
        let rate = ((i2 - i1) * d3 / (i1 * i2 * i3)).sqrt();
        let m = ((i3 - i2) * d1 / ((i2 - i1) * d3)).clamp(0.0, 1.0);
        let s = sign(w[0]);
        let phi0 = (s * w[1] / a2).atan2(w[2] / a3);
        let phi0 = if phi0.is_nan() { 0.0 } else { phi0 };
        let (sn, cn, dn) = jacobi_sn_cn_dn(rate * t + incomplete_f(phi0, m), m);
        [s * a1 * dn, s * a2 * sn, a3 * cn]
    };
    let mut out = [0.0; 3];
    for k in 0..3 {
        out[perm[k]] = flip * sorted[k];
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The torque-free solution satisfies Euler's equations (central differences), keeps E and |L|, and
    /// starts at ω(0), for both cases (M² above and below 2EI₂) and for every ordering of the moments.
    #[test]
    fn torque_free_spin_solves_euler() {
        let orders = [
            [1.0, 2.0, 3.0],
            [2.0, 3.0, 1.0],
            [3.0, 2.0, 1.0],
            [2.0, 1.0, 2.0 / 3.0],
            [1.0, 3.0, 2.0],
        ];
        let spins = [[0.3, -0.2, 0.9], [-1.2, 0.4, 0.2], [0.5, 0.0, -0.6], [0.0, 1.0, 0.1]];
        for inertia in orders {
            for w0 in spins {
                let body = RigidBody { inertia, omega0: w0 };
                let w_init = torque_free_spin(inertia, w0, 0.0).unwrap();
                for k in 0..3 {
                    assert!((w_init[k] - w0[k]).abs() < 1e-13, "{inertia:?} {w0:?}: {w_init:?}");
                }
                for &t in &[0.7, 5.3, 40.0] {
                    let w = torque_free_spin(inertia, w0, t).unwrap();
                    assert!((body.energy(&w) - body.energy(&w0)).abs() < 1e-13);
                    assert!((body.angular_momentum_norm(&w) - body.angular_momentum_norm(&w0)).abs() < 1e-13);
                    let h = 1e-5;
                    let (wp, wm) = (
                        torque_free_spin(inertia, w0, t + h).unwrap(),
                        torque_free_spin(inertia, w0, t - h).unwrap(),
                    );
                    let mut f = [0.0; 3];
                    body.rhs(t, &w, &mut f);
                    for k in 0..3 {
                        let d = (wp[k] - wm[k]) / (2.0 * h);
                        assert!((d - f[k]).abs() < 1e-8, "{inertia:?} {w0:?} t {t}: {d} vs {}", f[k]);
                    }
                }
            }
        }
        assert!(torque_free_spin([1.0, 1.0, 2.0], [0.1, 0.2, 0.3], 1.0).is_none());
    }

    #[test]
    fn kepler_exact_is_consistent() {
        let k = Kepler::new(0.5);
        let y0 = k.exact(0.0).unwrap();
        let init = k.initial_state();
        for i in 0..4 {
            assert!((y0[i] - init[i]).abs() < 1e-15);
        }
        for &t in &[0.3, 1.7, 3.2, 10.0, -2.0] {
            let y = k.exact(t).unwrap();
            assert!((k.energy(&y) + 0.5).abs() < 1e-14);
            assert!((k.angular_momentum(&y) - (0.75f64).sqrt()).abs() < 1e-14);
        }
        let y = k.exact(2.0 * PI).unwrap();
        for i in 0..4 {
            assert!((y[i] - init[i]).abs() < 1e-13);
        }
    }
}
