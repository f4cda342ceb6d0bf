//! The soft-sphere contact law: normal spring–dashpot and tangential stick–slip spring–dashpot–slider
//! (Zhang17 Eqs. 1–2), twisting (Eqs. 3–5) and rolling (Eqs. 6–10) spring–dashpot–sliders with the
//! shape parameter β of Jiang et al. 2015 (Eqs. 11–12).
//!
//! Conventions: `n̂` points from particle `i` to its partner `j` (a particle or a wall), `x > 0` is the
//! overlap, `l_i`, `l_j` the lever arms from the centres to the contact point, `u` the velocity of `j`'s
//! surface relative to `i`'s at the contact point, `u_n = (u·n̂) n̂`, `u_t = u − u_n`. Forces and torques are
//! those on `i`; `j` gets the opposite force and the torque of Newton's third law about its own centre.
//!
//! Deviations, all documented here: on slip the spring is shortened to the cap and carries the whole capped
//! force/torque (no dashpot, Eq. 2/4/9 second branch); while sticking, the total (spring + dashpot) is also
//! limited to the cap, so the tangential force and the twisting/rolling torques never exceed their Coulomb
//! limits. The normal force is not clipped at zero, so a head-on collision returns exactly the ε_n of the
//! damping formula ([`damping`]).

use crate::granular::soft::spring_frame::FrameRotation;
use crate::math::Vec3;
use serde::{Deserialize, Serialize};

/// The material constants of the contact law (one set for the whole scene).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// Normal spring constant `k_N` (N/m, > 0). `k_S = 2/7 k_N` (Zhang17 §2.3.3).
    pub k_n: f64,
    /// Normal coefficient of restitution ε_n (in (0, 1]); sets `C_N` by [`damping`].
    pub eps_n: f64,
    /// Tangential coefficient of restitution ε_t (in (0, 1]); sets `C_S` by [`damping`] with `k_S`.
    pub eps_t: f64,
    /// Sliding friction coefficient μ_S (≥ 0): `|F_S| ≤ μ_S |F_N|`.
    pub mu_s: f64,
    /// Twisting friction coefficient μ_T (≥ 0): `M_T,max = μ_T β R μ_S |F_N|` (Eq. 12).
    pub mu_t: f64,
    /// Rolling friction coefficient μ_R (≥ 0): `M_R,max = μ_R β R |F_N|` (Eq. 12).
    pub mu_r: f64,
    /// Shape parameter β (≥ 0) of Eqs. 11–12; 0 turns twisting and rolling resistance off.
    pub beta: f64,
}

impl Material {
    /// Zhang17's nominal set (§2.3.3) with the given `k_N`: μ_S = 1.0, β = 0.5, μ_T = 1.3, μ_R = 1.05,
    /// ε_n = ε_t = 0.55.
    pub fn nominal(k_n: f64) -> Self {
        Material {
            k_n,
            eps_n: 0.55,
            eps_t: 0.55,
            mu_s: 1.0,
            mu_t: 1.3,
            mu_r: 1.05,
            beta: 0.5,
        }
    }

    /// Tangential spring constant `k_S = 2/7 k_N` (N/m).
    pub fn k_s(&self) -> f64 {
        2.0 / 7.0 * self.k_n
    }
}

/// Dashpot coefficient (kg/s) giving restitution `eps` for a linear spring `k` (N/m) and reduced mass `mu`
/// (kg): `C = −2 ln ε √(k μ / (π² + ln² ε))` (Schwartz et al. 2012, as in our notes).
///
/// ```
/// use rubblepile::granular::soft::contact::damping;
/// assert_eq!(damping(1.0, 1.0, 1.0), 0.0);
/// assert!(damping(0.5, 100.0, 2.0) > 0.0);
/// ```
pub fn damping(eps: f64, k: f64, mu: f64) -> f64 {
    let l = eps.ln();
    -2.0 * l * (k * mu / (std::f64::consts::PI.powi(2) + l * l)).sqrt()
}

/// Spring histories of one contact (Eqs. 2, 5, 10), carried with the contact frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Springs {
    /// The contact normal when the springs were last updated (unit).
    pub normal: Vec3,
    /// Sliding displacement δ_S (m), in the tangent plane.
    pub shear: Vec3,
    /// Twisting angle δ_T (rad) about the normal.
    pub twist: f64,
    /// Rolling angular displacement δ_R (rad), in the tangent plane.
    pub roll: Vec3,
}

impl Springs {
    /// Fresh springs for a contact that has just begun with normal `normal`.
    pub fn new(normal: Vec3) -> Self {
        Springs {
            normal,
            ..Default::default()
        }
    }
}

/// The geometry and motion of one contact at the current step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kinematics {
    /// Unit normal from `i` towards `j`.
    pub normal: Vec3,
    /// Overlap `x` (m, > 0).
    pub overlap: f64,
    /// Lever arm of `i` (m).
    pub lever_i: f64,
    /// Lever arm of `j` (m); `f64::INFINITY` for a wall.
    pub lever_j: f64,
    /// Velocity of `j`'s surface relative to `i`'s at the contact point (m/s).
    pub relative_velocity: Vec3,
    /// Spin of `i` (rad/s).
    pub spin_i: Vec3,
    /// Spin of `j` (rad/s); zero for a wall.
    pub spin_j: Vec3,
    /// Effective radius `R = r_i r_j/(r_i + r_j)` (m); `r_i` for a wall.
    pub r_eff: f64,
    /// Reduced mass (kg); `m_i` for a wall.
    pub mass_eff: f64,
}

/// What one contact does at one step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Output {
    /// Force on `i` (N).
    pub force_i: Vec3,
    /// Torque on `i` about its centre (N m).
    pub torque_i: Vec3,
    /// Torque on `j` about its centre (N m) (ignored for walls).
    pub torque_j: Vec3,
    /// `|F_N|` (N).
    pub normal_force: f64,
    /// `|M_R|` (N m).
    pub rolling_torque: f64,
    /// `|M_T|` (N m).
    pub twisting_torque: f64,
    /// Energy stored in the four springs after the step (J).
    pub stored_energy: f64,
    /// Energy taken out by the dashpots and sliders during the step (J).
    pub dissipated: f64,
}

/// The material constants in the form the force loop uses, computed once per force evaluation: the contact
/// law for a pair only needs its reduced mass and effective radius on top of these.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Law {
    /// `k_N` (N/m).
    pub k_n: f64,
    /// `k_S = 2/7 k_N` (N/m).
    pub k_s: f64,
    /// `C_N / √μ` (kg^½/s): [`damping`] for ε_n and `k_N` at a reduced mass of 1 kg.
    pub c_n_unit: f64,
    /// `C_S / √μ` (kg^½/s): [`damping`] for ε_t and `k_S` at a reduced mass of 1 kg.
    pub c_s_unit: f64,
    /// β (dimensionless).
    pub beta: f64,
    /// μ_S (dimensionless).
    pub mu_s: f64,
    /// `M_T,max / (R |F_N|) = μ_T β μ_S` (dimensionless, Eq. 12).
    pub twist_cap: f64,
    /// `M_R,max / (R |F_N|) = μ_R β` (dimensionless, Eq. 12).
    pub roll_cap: f64,
}

impl Law {
    /// The constants of material `m`.
    pub fn new(m: &Material) -> Self {
        let k_s = m.k_s();
        Law {
            k_n: m.k_n,
            k_s,
            c_n_unit: damping(m.eps_n, m.k_n, 1.0),
            c_s_unit: damping(m.eps_t, k_s, 1.0),
            beta: m.beta,
            mu_s: m.mu_s,
            twist_cap: m.mu_t * m.beta * m.mu_s,
            roll_cap: m.mu_r * m.beta,
        }
    }
}

/// Adds `rate · dt` to a vector spring and applies a spring–dashpot–slider with cap `cap` (≥ 0):
/// returns (generalised force, energy lost by slip, dashpot power).
#[inline(always)]
fn slider_vec(spring: &mut Vec3, rate: &Vec3, dt: f64, k: f64, c: f64, cap: f64) -> (Vec3, f64, f64) {
    if k <= 0.0 {
        *spring = Vec3::zeros();
        return (Vec3::zeros(), 0.0, 0.0);
    }
    let before = *spring;
    let stretch = rate * dt;
    *spring += stretch;
    let trial = *spring * k;
    let size2 = trial.norm_squared();
    if size2 >= cap * cap {
        let size = size2.sqrt();
        let capped = if size > 0.0 {
            trial * (cap / size)
        } else {
            Vec3::zeros()
        };
        *spring = capped / k;
        // The slider takes the spring's energy before this step's stretch plus the work of the capped force
        // over the stretch, minus what the shortened spring keeps.
        let work = capped.dot(&stretch);
        let lost = 0.5 * k * before.norm_squared() + work - 0.5 * k * spring.norm_squared();
        (capped, lost, 0.0)
    } else {
        let mut total = trial + rate * c;
        let t2 = total.norm_squared();
        if t2 > cap * cap {
            total *= cap / t2.sqrt();
        }
        (total, 0.0, c * rate.norm_squared())
    }
}

/// The scalar version of [`slider_vec`] (twisting).
#[inline(always)]
fn slider_scalar(spring: &mut f64, rate: f64, dt: f64, k: f64, c: f64, cap: f64) -> (f64, f64, f64) {
    if k <= 0.0 {
        *spring = 0.0;
        return (0.0, 0.0, 0.0);
    }
    let before = *spring;
    let stretch = rate * dt;
    *spring += stretch;
    let trial = *spring * k;
    if trial.abs() >= cap {
        let capped = if trial == 0.0 { 0.0 } else { cap.copysign(trial) };
        *spring = capped / k;
        let lost = 0.5 * k * before * before + capped * stretch - 0.5 * k * *spring * *spring;
        (capped, lost, 0.0)
    } else {
        let total = trial + rate * c;
        let total = if total.abs() > cap { cap.copysign(total) } else { total };
        (total, 0.0, c * rate * rate)
    }
}

/// Evaluates the contact law of material `m` for one step of length `dt` (s), updating `springs` (first
/// carried into the current contact frame, then advanced by the relative motion over the step). The force
/// loop calls [`evaluate_law`] with constants computed once.
pub fn evaluate(m: &Material, kin: &Kinematics, springs: &mut Springs, dt: f64) -> Output {
    evaluate_law(&Law::new(m), kin, springs, dt)
}

/// [`evaluate`] with the material's constants `law` already computed.
#[inline(always)]
pub fn evaluate_law(law: &Law, kin: &Kinematics, springs: &mut Springs, dt: f64) -> Output {
    evaluate_inner::<true, true>(law, kin, springs, dt)
}

/// [`evaluate_law`] for the force loop: without `SIZES`, `Output::rolling_torque` and
/// `Output::twisting_torque` are left at zero (they only go into contact records); without `STORED`,
/// `Output::stored_energy` is (it is read only at output samples; the dissipation is always summed, because the
/// energy balance integrates it over every step).
#[inline(always)]
pub(crate) fn evaluate_inner<const SIZES: bool, const STORED: bool>(
    law: &Law,
    kin: &Kinematics,
    springs: &mut Springs,
    dt: f64,
) -> Output {
    let n = kin.normal;
    // Carry the springs into the current frame (spring_frame.rs).
    let mean_spin = (kin.spin_i + kin.spin_j) * 0.5;
    let rot = FrameRotation::new(&springs.normal, &n, &mean_spin, dt);
    springs.shear = rot.carry(&springs.shear);
    springs.roll = rot.carry(&springs.roll);
    springs.normal = n;

    let u = kin.relative_velocity;
    let u_along = u.dot(&n);
    let u_n = n * u_along;
    let u_t = u - u_n;
    let k_s = law.k_s;
    let root_mass = kin.mass_eff.sqrt();
    let c_n = law.c_n_unit * root_mass;
    let c_s = law.c_s_unit * root_mass;
    let br = law.beta * kin.r_eff;
    let br2 = br * br;
    let (k_t, c_t) = (2.0 * k_s * br2, 2.0 * c_s * br2);
    let (k_r, c_r) = (law.k_n * br2, c_n * br2);

    // Normal (Eq. 1), along n̂: |F_N| is the size of its one component.
    let f_n_along = -law.k_n * kin.overlap + c_n * u_along;
    let f_n = n * f_n_along;
    let f_n_size = f_n_along.abs();
    let mut dissipated = c_n * u_along * u_along * dt;

    // Tangential stick–slip (Eq. 2).
    let (f_s, slip, power) = slider_vec(&mut springs.shear, &u_t, dt, k_s, c_s, law.mu_s * f_n_size);
    dissipated += slip + power * dt;

    // Twisting (Eqs. 3–5).
    let spin_rel = kin.spin_j - kin.spin_i;
    let w_t = spin_rel.dot(&n);
    let cap_t = law.twist_cap * kin.r_eff * f_n_size;
    let (m_t, slip, power) = slider_scalar(&mut springs.twist, w_t, dt, k_t, c_t, cap_t);
    dissipated += slip + power * dt;

    // Rolling (Eqs. 6–10): ω_R = (ω_j − ω_i)_⊥ + ½ (l_j − l_i)/(l_i l_j) n̂ × u_t.
    let arm = if kin.lever_j == kin.lever_i {
        // equal spheres (a division saved)
        0.0
    } else if kin.lever_j.is_finite() {
        0.5 * (kin.lever_j - kin.lever_i) / (kin.lever_i * kin.lever_j)
    } else {
        0.5 / kin.lever_i
    };
    let w_r = spin_rel - n * w_t + n.cross(&u_t) * arm;
    let cap_r = law.roll_cap * kin.r_eff * f_n_size;
    let (m_r, slip, power) = slider_vec(&mut springs.roll, &w_r, dt, k_r, c_r, cap_r);
    dissipated += slip + power * dt;

    let lever_j = if kin.lever_j.is_finite() { kin.lever_j } else { 0.0 };
    let shear_torque = n.cross(&f_s);
    let stored = if STORED {
        0.5 * law.k_n * kin.overlap * kin.overlap
            + 0.5 * k_s * springs.shear.norm_squared()
            + 0.5 * k_t * springs.twist * springs.twist
            + 0.5 * k_r * springs.roll.norm_squared()
    } else {
        0.0
    };
    Output {
        force_i: f_n + f_s,
        torque_i: shear_torque * kin.lever_i + n * m_t + m_r,
        torque_j: shear_torque * lever_j - n * m_t - m_r,
        normal_force: f_n_size,
        rolling_torque: if SIZES { m_r.norm() } else { 0.0 },
        twisting_torque: if SIZES { m_t.abs() } else { 0.0 },
        stored_energy: stored,
        dissipated,
    }
}
