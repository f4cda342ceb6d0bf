//! The rotation state of a rigid body (or a pile read as one): principal-axis rotation or tumbling, and a tumbler's
//! two periods of free rotation. Sources: Landau & Lifshitz, *Mechanics* (3rd ed., 1976) §37, Eqs. 37.10–37.11;
//! Kaasalainen 2001 (A&A 376, 302); Pravec et al. 2005 (Icarus 173, 108) for the modes and `P_ψ`, `P_φ` (Apophis:
//! Pravec et al. 2014, Icarus 233, 48).
//!
//! With `I₁ ≤ I₂ ≤ I₃`, `L`, `E = ½ L·I⁻¹L` ([`crate::ellipsoid::rigid_rotation`]), `D = L²/2E ∈ [I₁, I₃]`: SAM when
//! `D > I₂`, LAM when `D < I₂`. With `(a, b, c) = (I₁, I₂, I₃)` (SAM) or `(I₃, I₂, I₁)` (LAM),
//! `λ² = (c − b)(L² − 2E a)/(a b c)`, `k² = (b − a)(2E c − L²)/((c − b)(L² − 2E a))`,
//! `ω_a² = (2Ec − L²)/(a(c − a)) cn²(λt)`, `ω_b² = (2Ec − L²)/(b(c − b)) sn²(λt)`,
//! `ω_c² = (L² − 2Ea)/(c(c − a)) dn²(λt)`; `P_ψ = 4K(k²)/λ`; the axis precesses at
//! `φ̇ = L (a ω_a² + b ω_b²)/(a² ω_a² + b² ω_b²)`, `P_φ = 2π/⟨φ̇⟩` (trapezoidal mean over `P_ψ`, geometrically
//! convergent); a symmetric top (`I₁ = I₂`) has `φ̇ = L/I₁` exactly.

use serde::Serialize;

use crate::ellipsoid::rigid_rotation::RigidFit;
use crate::integrate::elliptic::{complete_k, jacobi_sn_cn_dn};
use crate::math::{Mat3, Vec3};

/// Angle between `L` and `ω` (degrees) below which the rotation counts as principal-axis: the period `2π/|ω|`
/// of such a rotation varies over its cycle by well under 0.1 %.
pub const PRINCIPAL_AXIS_ANGLE_DEG: f64 = 0.2;

/// Points of the trapezoidal rule over one period `P_ψ` for `⟨φ̇⟩` and the range of `|ω|`.
const PERIOD_SAMPLES: usize = 1024;

/// The two periods of torque-free rotation of a tumbling rigid body (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FreeRotation {
    /// `P_ψ`: period of the body-frame motion of `ω` (rotation about the mode's axis for SAM, its libration for
    /// LAM) (s).
    pub rotation_period: f64,
    /// `P_φ`: mean precession period of the mode's axis about `L` (s).
    pub precession_period: f64,
    /// Smallest and largest `2π/|ω|` over one cycle (s): the range a single snapshot's period falls in.
    pub spin_period_range: [f64; 2],
}

/// Periods of free rotation for principal moments `moments` (any order, kg m²), `|L|` `l` (kg m² s⁻¹) and rotational
/// energy `e` (J). `None` when there is no tumbling to describe: `D = L²/2E` outside `(I₁, I₃)` or on the separatrix
/// `D = I₂` (an infinite period), or a degenerate input.
pub fn free_rotation(moments: [f64; 3], l: f64, e: f64) -> Option<FreeRotation> {
    let mut m = moments;
    m.sort_by(f64::total_cmp);
    let d = l * l / (2.0 * e);
    if !(d.is_finite() && m[0] > 0.0 && d > m[0] && d < m[2] && d != m[1]) {
        return None;
    }
    let (a, b, c) = if d > m[1] {
        (m[0], m[1], m[2])
    } else {
        (m[2], m[1], m[0])
    };
    let l2 = l * l;
    let lambda2 = (c - b) * (l2 - 2.0 * e * a) / (a * b * c);
    let k2 = (b - a) * (2.0 * e * c - l2) / ((c - b) * (l2 - 2.0 * e * a));
    if !(lambda2 > 0.0 && (0.0..1.0).contains(&k2)) {
        return None;
    }
    let (wa2, wb2, wc2) = (
        (2.0 * e * c - l2) / (a * (c - a)),
        (2.0 * e * c - l2) / (b * (c - b)),
        (l2 - 2.0 * e * a) / (c * (c - a)),
    );
    let quarter = complete_k(k2);
    let lambda = lambda2.sqrt();
    let mut rate_sum = 0.0;
    let (mut w_min, mut w_max) = (f64::INFINITY, 0.0_f64);
    for j in 0..PERIOD_SAMPLES {
        let u = 4.0 * quarter * j as f64 / PERIOD_SAMPLES as f64;
        let (sn, cn, dn) = jacobi_sn_cn_dn(u, k2);
        let (xa, xb) = (wa2 * cn * cn, wb2 * sn * sn);
        rate_sum += l * (a * xa + b * xb) / (a * a * xa + b * b * xb);
        let w = (xa + xb + wc2 * dn * dn).sqrt();
        w_min = w_min.min(w);
        w_max = w_max.max(w);
    }
    let mean_rate = rate_sum / PERIOD_SAMPLES as f64;
    let two_pi = 2.0 * std::f64::consts::PI;
    let out = FreeRotation {
        rotation_period: 4.0 * quarter / lambda,
        precession_period: two_pi / mean_rate,
        spin_period_range: [two_pi / w_max, two_pi / w_min],
    };
    (out.rotation_period.is_finite() && out.precession_period.is_finite()).then_some(out)
}

/// The rotation state of a pile read as a rigid body (module docs). Angles in degrees, moments in kg m².
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpinState {
    /// `principal-axis`, `short-axis mode` (SAM) or `long-axis mode` (LAM).
    pub mode: String,
    /// Angle between `L` and `ω = I⁻¹L` (degrees).
    pub angle_l_omega_deg: f64,
    /// Angle between `ω` and the axis of largest moment (degrees, 0–90).
    pub angle_omega_largest_axis_deg: f64,
    /// Angle between `L` and the axis of largest moment (degrees, 0–90).
    pub angle_l_largest_axis_deg: f64,
    /// Principal moments `I₁ ≤ I₂ ≤ I₃` (kg m²).
    pub moments: [f64; 3],
    /// `D = L²/2E` (kg m²), between `I₁` and `I₃`.
    pub l2_over_2e: f64,
    /// `|L|` (kg m² s⁻¹).
    pub angular_momentum: f64,
    /// Rotational energy `E = ½ L·I⁻¹L` of the rigid rotation (J).
    pub energy: f64,
    /// `2π/|ω|` now (h).
    pub spin_period_hours: f64,
    /// `π|L|/E = 2π D/|L|` (h): `2π/|ω|` for principal-axis rotation, and a constant of free tumbling.
    pub invariant_period_hours: f64,
    /// For a tumbler, `P_ψ` (h): [`FreeRotation::rotation_period`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rotation_period_hours: Option<f64>,
    /// For a tumbler, `P_φ` (h): [`FreeRotation::precession_period`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub precession_period_hours: Option<f64>,
    /// For a tumbler, the range of `2π/|ω|` over its cycle (h).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spin_period_range_hours: Option<[f64; 2]>,
}

/// Principal moments (ascending) and their axes (columns, same order) of the symmetric tensor `inertia`.
pub fn principal_axes(inertia: &Mat3) -> ([f64; 3], Mat3) {
    let eig = inertia.symmetric_eigen();
    let mut order = [0, 1, 2];
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    let moments = order.map(|i| eig.eigenvalues[i]);
    let axes = Mat3::from_columns(&order.map(|i| eig.eigenvectors.column(i).into_owned()));
    (moments, axes)
}

/// Angle between two vectors (degrees), or between two lines when `as_lines` (0–90); by `atan2`, accurate near 0.
fn angle_deg(u: &Vec3, v: &Vec3, as_lines: bool) -> f64 {
    let c = u.dot(v);
    let c = if as_lines { c.abs() } else { c };
    u.cross(v).norm().atan2(c).to_degrees()
}

/// The rotation state of inertia tensor `inertia` (kg m²) with angular momentum `l` (kg m² s⁻¹).
pub fn spin_state(inertia: &Mat3, l: &Vec3) -> SpinState {
    let (moments, axes) = principal_axes(inertia);
    let omega = inertia.try_inverse().map_or(Vec3::zeros(), |inv| inv * l);
    let energy = 0.5 * l.dot(&omega);
    let ln = l.norm();
    let d = ln * ln / (2.0 * energy);
    let largest = axes.column(2).into_owned();
    let angle_l_omega_deg = angle_deg(l, &omega, false);
    let hours = |s: f64| s / 3600.0;
    let tumbling = (angle_l_omega_deg >= PRINCIPAL_AXIS_ANGLE_DEG)
        .then(|| free_rotation(moments, ln, energy))
        .flatten();
    let mode = if angle_l_omega_deg < PRINCIPAL_AXIS_ANGLE_DEG {
        "principal-axis"
    } else if d > moments[1] {
        "short-axis mode"
    } else {
        "long-axis mode"
    };
    SpinState {
        mode: mode.into(),
        angle_l_omega_deg,
        angle_omega_largest_axis_deg: angle_deg(&omega, &largest, true),
        angle_l_largest_axis_deg: angle_deg(l, &largest, true),
        moments,
        l2_over_2e: d,
        angular_momentum: ln,
        energy,
        spin_period_hours: hours(2.0 * std::f64::consts::PI / omega.norm()),
        invariant_period_hours: hours(std::f64::consts::PI * ln / energy),
        rotation_period_hours: tumbling.map(|f| hours(f.rotation_period)),
        precession_period_hours: tumbling.map(|f| hours(f.precession_period)),
        spin_period_range_hours: tumbling.map(|f| f.spin_period_range.map(hours)),
    }
}

/// The rotation state of a rigid fit ([`crate::ellipsoid::rigid_rotation::fit_rigid_rotation`]).
pub fn spin_state_of_fit(fit: &RigidFit) -> SpinState {
    spin_state(&fit.inertia, &fit.angular_momentum)
}

impl SpinState {
    /// One phrase: the mode, the L–ω angle, `D` against the moments and, for a tumbler, its periods.
    pub fn describe(&self) -> String {
        let [i1, i2, i3] = self.moments;
        let mut s = format!(
            "{}, L-w {:.2} deg, w {:.1} deg from the largest-moment axis, L^2/2E = {:.4} I2 (I1 {:.4} I2, I3 {:.4} I2)",
            self.mode,
            self.angle_l_omega_deg,
            self.angle_omega_largest_axis_deg,
            self.l2_over_2e / i2,
            i1 / i2,
            i3 / i2
        );
        if let (Some(p_psi), Some(p_phi), Some([lo, hi])) = (
            self.rotation_period_hours,
            self.precession_period_hours,
            self.spin_period_range_hours,
        ) {
            s += &format!(", P_psi {p_psi:.2} h, P_phi {p_phi:.2} h, 2pi/|w| cycles over {lo:.2}-{hi:.2} h");
        }
        s
    }
}
