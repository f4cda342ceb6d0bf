//! Post-impact fragment analysis of Roig03 §4: energy partition (§4.1), ejection velocities and escape (§4.2,
//! Eq. 43, footnote 6), spins with the `√(5/(2κ))` correction (§4.3) and tumbling (§4.4, Eq. 46), from the
//! snapshots at `t = 0` and `t_at` (the paper: 400 s). The projectile (or a contiguous range of bodies) is
//! excluded from every target quantity but counts in Eq. 43's binding energy and the system barycentre.
//!
//! Our readings where the paper is not explicit: parent size `R_eff = (3 V_T / 4π)^{1/3}` over the target
//! fragments' volume (voids not counted; footnote 6); `Δv_i = [v_i − V_T](t_at) − [v_i − V_T](0)` with `V_T` the
//! target's mean velocity; escape iff `½ m_i |v_i − V_sys|² ≥ Σ_{j≠i} G m_i m_j / r_ij` (Eq. 43, translational,
//! `binding_energy` ≥ 0); bound mass fraction over the target (not the largest remnant); `f_KE` = the target's total
//! kinetic energy at `t_at` / `½ m_p |v_p(0) − V_T(0)|²` (the final energy, not its increase). Spins
//! `ω_corr = ω √(5/(2κ_I))` with `κ_I` = [`InertiaModel::inertia_kappa`] (factor 1 for [`InertiaModel::Uniform`]).
//! Tumbling: `I_eff = |Iω|² / (ωᵀ I ω)`, `s = (I_eff − I₂)/(I₃ − I₂)` above `I₂`, `(I_eff − I₂)/(I₂ − I₁)` below,
//! clamped to `[−1, 1]` (+1 short-axis, −1 long-axis); SAM iff `I_eff > I₂`, LAM iff `I_eff < I₂`.

use std::path::Path;

use crate::ellipsoid::body::{Body, InertiaModel};
use crate::impact::run::{ImpactError, read_target};
use crate::math::{Vec3, median};

/// `|s|` below which the axis-rotation-mode measure counts as the intermediate-axis mode (round-off only).
pub const MODE_TOLERANCE: f64 = 1e-9;

/// Petit & Farinella (1993) coefficient in `v_esc² = 1.64 G M / R_eff` (Roig03 footnote 6).
pub const ESCAPE_COEFFICIENT: f64 = 1.64;

/// Axis rotation mode of a fragment (Roig03 §4.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum RotationMode {
    /// Short-axis mode: `I₂ < I_eff ≤ I₃`.
    Sam,
    /// Long-axis mode: `I₁ ≤ I_eff < I₂`.
    Lam,
    /// Rotation about the intermediate axis (`I_eff = I₂` within [`MODE_TOLERANCE`]), or a degenerate body.
    Intermediate,
    /// No spin: `I_eff` is undefined.
    None,
}

/// Model parameters the analysis needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FragmentParams {
    /// The model's κ (Roig03 Eq. 4/5).
    pub kappa: f64,
    /// Which moments of inertia the bodies had in the run.
    pub inertia: InertiaModel,
    /// Gravitational constant (SI).
    pub g: f64,
    /// Index of the projectile among the bodies (of its first body for a rubble-pile projectile).
    pub projectile: usize,
    /// Number of projectile bodies, `projectile..projectile + projectile_count` (1 for a single ellipsoid; the
    /// pile's N for a rubble-pile projectile, [`crate::impact::pile`]). 0 counts as 1.
    pub projectile_count: usize,
}

/// Why the analysis could not be done.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FragmentError {
    /// The two snapshots hold different numbers of bodies.
    #[error("snapshots differ in size: {initial} bodies at t = 0, {at} at the analysis time")]
    CountMismatch {
        /// Bodies at `t = 0`.
        initial: usize,
        /// Bodies at `t_at`.
        at: usize,
    },
    /// The projectile index is out of range, or it is the only body.
    #[error("projectile index {index} invalid for {count} bodies (need at least one target fragment)")]
    Projectile {
        /// The index given.
        index: usize,
        /// Number of bodies.
        count: usize,
    },
    /// κ or G is not finite and positive.
    #[error("need finite kappa > 0 and G > 0 (got kappa = {kappa}, G = {g})")]
    Parameters {
        /// κ given.
        kappa: f64,
        /// G given.
        g: f64,
    },
}

/// Analysis of one body at the analysis time.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FragmentAnalysis {
    /// Index of the body in the snapshots.
    pub index: usize,
    /// Whether this body is the projectile (excluded from target quantities).
    pub is_projectile: bool,
    /// Mass (kg).
    pub mass: f64,
    /// Equivalent radius `(A B C)^{1/3}` (m).
    pub equivalent_radius: f64,
    /// Equivalent radius over the parent-body radius `R_eff` (module docs).
    pub size: f64,
    /// Ejection velocity `Δv` in the target's barycentric frame (m/s).
    pub ejection_velocity: [f64; 3],
    /// `|Δv|` (m/s).
    pub ejection_speed: f64,
    /// Translational kinetic energy in the system's barycentric frame at `t_at` (J).
    pub kinetic_energy: f64,
    /// Rotational kinetic energy `½ ωᵀ I ω` at `t_at` (J).
    pub rotational_energy: f64,
    /// Binding energy magnitude `|U_bind|` of Eq. 43 (J, ≥ 0).
    pub binding_energy: f64,
    /// Whether `kinetic_energy ≥ binding_energy` (Eq. 43).
    pub escaping: bool,
    /// Spin rate `|ω|` (rad/s).
    pub spin_rate: f64,
    /// Spin period `2π/|ω|` (h); `None` without spin.
    pub spin_period_h: Option<f64>,
    /// Spin rate times `√(5/(2κ_I))` (rad/s; §4.3).
    pub spin_rate_corrected: f64,
    /// Spin period divided by `√(5/(2κ_I))` (h); `None` without spin.
    pub spin_period_corrected_h: Option<f64>,
    /// Principal moments `(I_x, I_y, I_z)` of Eq. 4 with the inertia model's κ (kg m²).
    pub moments: [f64; 3],
    /// `I_eff` of Eq. 46 (kg m²); `None` without spin.
    pub effective_inertia: Option<f64>,
    /// Axis-rotation-mode measure in `[−1, 1]` (+1 pure SAM, −1 pure LAM, 0 intermediate); `None` without spin.
    pub rotation_mode_measure: Option<f64>,
    /// SAM / LAM classification.
    pub rotation_mode: RotationMode,
    /// Where the fragment sat in the target before the impact: the cosine of the angle between its position and
    /// the projectile's, both relative to the target barycentre at `t = 0` (+1 at the impact point, −1 at the
    /// antipode; §4.2). 0 for the projectile itself and for a fragment at the barycentre.
    pub impact_site_cosine: f64,
}

/// Where the fast fragments come from (Roig03 §4.2: "only small fragments are ejected at the impact point, while
/// the largest ones tend to be ejected at the antipodal point"). "Fast" = ejection speed at or above the run's
/// median; sides split by the sign of [`FragmentAnalysis::impact_site_cosine`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EjectionSites {
    /// Number of fast target fragments.
    pub fast_fragments: usize,
    /// Fast fragments from the impact hemisphere (cosine > 0).
    pub impact_side: usize,
    /// Fast fragments from the antipodal hemisphere (cosine ≤ 0).
    pub antipodal_side: usize,
    /// Median normalised size of the fast fragments from the impact hemisphere (`None` if there are none).
    pub impact_side_median_size: Option<f64>,
    /// Median normalised size of the fast fragments from the antipodal hemisphere (`None` if there are none).
    pub antipodal_side_median_size: Option<f64>,
    /// Pearson correlation of ln(size) with the impact-site cosine over the fast fragments: negative when the
    /// small ones come from the impact side and the large ones from the antipode (`None` for < 3 fragments or
    /// no spread).
    pub size_cosine_correlation: Option<f64>,
}

/// [`EjectionSites`] of the target fragments in `fragments` (the projectile is skipped).
pub fn ejection_sites(fragments: &[FragmentAnalysis]) -> EjectionSites {
    let targets: Vec<&FragmentAnalysis> = fragments.iter().filter(|f| !f.is_projectile).collect();
    let speeds: Vec<f64> = targets.iter().map(|f| f.ejection_speed).collect();
    let threshold = median(&speeds);
    let fast: Vec<&&FragmentAnalysis> = targets.iter().filter(|f| f.ejection_speed >= threshold).collect();
    let sizes_where = |impact: bool| -> Vec<f64> {
        fast.iter()
            .filter(|f| (f.impact_site_cosine > 0.0) == impact)
            .map(|f| f.size)
            .collect()
    };
    let (near, far) = (sizes_where(true), sizes_where(false));
    let med = |v: &[f64]| (!v.is_empty()).then(|| median(v));
    let x: Vec<f64> = fast.iter().map(|f| f.size.ln()).collect();
    let y: Vec<f64> = fast.iter().map(|f| f.impact_site_cosine).collect();
    EjectionSites {
        fast_fragments: fast.len(),
        impact_side: near.len(),
        antipodal_side: far.len(),
        impact_side_median_size: med(&near),
        antipodal_side_median_size: med(&far),
        size_cosine_correlation: pearson(&x, &y),
    }
}

/// Pearson correlation coefficient of `x` and `y` (`None` for fewer than 3 pairs or zero variance).
pub fn pearson(x: &[f64], y: &[f64]) -> Option<f64> {
    let n = x.len().min(y.len());
    if n < 3 {
        return None;
    }
    let (mx, my) = (
        x[..n].iter().sum::<f64>() / n as f64,
        y[..n].iter().sum::<f64>() / n as f64,
    );
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x[..n].iter().zip(&y[..n]) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx) * (a - mx);
        syy += (b - my) * (b - my);
    }
    (sxx > 0.0 && syy > 0.0).then(|| sxy / (sxx * syy).sqrt())
}

/// Per-run aggregates.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FragmentSummary {
    /// Number of target fragments (projectile excluded).
    pub n_fragments: usize,
    /// Target mass `M` (kg).
    pub target_mass: f64,
    /// Parent-body radius `R_eff` (m): sphere of the target's total volume.
    pub target_radius: f64,
    /// `v_esc = √(1.64 G M / R_eff)` (m/s; footnote 6).
    pub escape_velocity: f64,
    /// Projectile speed relative to the target barycentre at `t = 0` (m/s).
    pub projectile_speed: f64,
    /// Projectile kinetic energy relative to the target at `t = 0`, `½ m_p v_p²` (J).
    pub projectile_kinetic_energy: f64,
    /// Specific impact energy `Q = ½ m_p v_p² / M` (J/kg).
    pub specific_energy: f64,
    /// Kinetic energy of the target fragments at `t = 0` (translational + rotational, system frame) (J).
    pub fragment_kinetic_initial: f64,
    /// Translational kinetic energy of the target fragments at `t_at` (system frame) (J).
    pub fragment_kinetic_translational: f64,
    /// Rotational kinetic energy of the target fragments at `t_at` (J).
    pub fragment_kinetic_rotational: f64,
    /// `f_KE`: fragment kinetic energy at `t_at` over the projectile kinetic energy (§4.1).
    pub f_ke: f64,
    /// Rotational share of the fragment kinetic energy at `t_at` (0 when it is zero).
    pub rotational_share: f64,
    /// Mass fraction of the target in non-escaping fragments (Fig. 5).
    pub bound_mass_fraction: f64,
    /// Mass of the largest target fragment over the target mass.
    pub largest_fragment_fraction: f64,
    /// Number of escaping target fragments.
    pub n_escaping: usize,
    /// Median ejection speed of the target fragments (m/s).
    pub ejection_speed_median: f64,
    /// Mean ejection speed of the target fragments (m/s).
    pub ejection_speed_mean: f64,
    /// Median ejection speed over the projectile speed.
    pub ejection_speed_median_relative: f64,
    /// Mean ejection speed over the projectile speed.
    pub ejection_speed_mean_relative: f64,
    /// The spin correction factor `√(5/(2κ_I))` used (§4.3).
    pub spin_correction: f64,
    /// Where the fast fragments come from (§4.2).
    pub ejection_sites: EjectionSites,
}

/// Per-body analyses and the run's aggregates.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FragmentReport {
    /// One entry per body, in snapshot order (the projectile included, flagged).
    pub fragments: Vec<FragmentAnalysis>,
    /// Aggregates over the target fragments.
    pub summary: FragmentSummary,
}

/// Reads a snapshot (or any bodies) CSV into bodies: [`read_target`], i.e. [`crate::ellipsoid::output::read_bodies_csv`]
/// with values checked and quaternions normalised.
pub fn read_snapshot_bodies(path: &Path) -> Result<Vec<Body>, ImpactError> {
    read_target(path)
}

/// The §4.3 spin correction factor `√(5/(2κ_I))`, `κ_I = inertia.inertia_kappa(kappa)`: multiply spin rates
/// by it (divide periods). 1 for [`InertiaModel::Uniform`] and for κ = 5/2.
pub fn spin_correction(inertia: InertiaModel, kappa: f64) -> f64 {
    (5.0 / (2.0 * inertia.inertia_kappa(kappa))).sqrt()
}

/// `v_esc = √(1.64 G M / R_eff)` (Roig03 footnote 6, after Petit & Farinella 1993).
pub fn escape_velocity(g: f64, mass: f64, radius: f64) -> f64 {
    (ESCAPE_COEFFICIENT * g * mass / radius).sqrt()
}

/// `I_eff = |I ω|² / (ωᵀ I ω)` (Eq. 46, `= |L_s|²/(2K_R)`) for principal `moments` and body-frame `omega`;
/// `None` when `ωᵀ I ω = 0` (no spin).
pub fn effective_inertia(moments: &Vec3, omega: &Vec3) -> Option<f64> {
    let l = moments.component_mul(omega);
    let two_k = omega.dot(&l);
    (two_k > 0.0).then(|| l.norm_squared() / two_k)
}

/// The axis-rotation-mode measure (module docs): with `I₁ ≤ I₂ ≤ I₃` the sorted `moments`,
/// `(I_eff − I₂)/(I₃ − I₂)` for `I_eff ≥ I₂`, `(I_eff − I₂)/(I₂ − I₁)` below, clamped to `[−1, 1]`
/// (0 when the relevant gap vanishes).
pub fn rotation_mode_measure(moments: &Vec3, i_eff: f64) -> f64 {
    let mut m = [moments.x, moments.y, moments.z];
    m.sort_by(f64::total_cmp);
    let [i1, i2, i3] = m;
    let d = i_eff - i2;
    let gap = if d >= 0.0 { i3 - i2 } else { i2 - i1 };
    if gap > 0.0 { (d / gap).clamp(-1.0, 1.0) } else { 0.0 }
}

/// Classifies a measure from [`rotation_mode_measure`] (`None`: no spin).
pub fn rotation_mode(measure: Option<f64>) -> RotationMode {
    match measure {
        None => RotationMode::None,
        Some(s) if s > MODE_TOLERANCE => RotationMode::Sam,
        Some(s) if s < -MODE_TOLERANCE => RotationMode::Lam,
        Some(_) => RotationMode::Intermediate,
    }
}

/// Binding energy magnitudes `|U_i^bind| = Σ_{j≠i} G m_i m_j / |r_i − r_j|` (Eq. 43) for every body.
pub fn binding_energies(g: f64, bodies: &[Body]) -> Vec<f64> {
    let mut u = vec![0.0; bodies.len()];
    for i in 0..bodies.len() {
        for j in i + 1..bodies.len() {
            let e = g * bodies[i].shape.mass * bodies[j].shape.mass / (bodies[i].position - bodies[j].position).norm();
            u[i] += e;
            u[j] += e;
        }
    }
    u
}

/// Mass-weighted mean of `f(body)` over the bodies for which `include(index)` holds.
fn mass_mean(bodies: &[Body], include: impl Fn(usize) -> bool, f: impl Fn(&Body) -> Vec3) -> Vec3 {
    let (mut sum, mut m) = (Vec3::zeros(), 0.0);
    for (_, b) in bodies.iter().enumerate().filter(|(i, _)| include(*i)) {
        sum += f(b) * b.shape.mass;
        m += b.shape.mass;
    }
    sum / m
}

fn mean_velocity(bodies: &[Body], include: impl Fn(usize) -> bool) -> Vec3 {
    mass_mean(bodies, include, |b| b.velocity)
}

/// Ejection velocities `Δv_i = [v_i(t_at) − V_T(t_at)] − [v_i(0) − V_T(0)]` of all bodies, `V_T` the barycentre
/// velocity of the target bodies, those for which `is_target(index)` holds. Panics if the snapshots differ in
/// length; NaN without a target body.
pub fn ejection_velocities(initial: &[Body], at: &[Body], is_target: impl Fn(usize) -> bool + Copy) -> Vec<Vec3> {
    assert_eq!(initial.len(), at.len(), "snapshots differ in size");
    let v0 = mean_velocity(initial, is_target);
    let v1 = mean_velocity(at, is_target);
    initial
        .iter()
        .zip(at)
        .map(|(b0, b1)| (b1.velocity - v1) - (b0.velocity - v0))
        .collect()
}

/// Analyses the bodies at `t_at` (`at`) against those at `t = 0` (`initial`): see the module docs for every
/// definition.
pub fn analyse_fragments(
    initial: &[Body],
    at: &[Body],
    params: &FragmentParams,
) -> Result<FragmentReport, FragmentError> {
    if initial.len() != at.len() {
        return Err(FragmentError::CountMismatch {
            initial: initial.len(),
            at: at.len(),
        });
    }
    let n = at.len();
    let p = params.projectile;
    let pc = params.projectile_count.max(1);
    if p + pc > n || n < pc + 1 {
        return Err(FragmentError::Projectile { index: p, count: n });
    }
    if !(params.kappa.is_finite() && params.kappa > 0.0 && params.g.is_finite() && params.g > 0.0) {
        return Err(FragmentError::Parameters {
            kappa: params.kappa,
            g: params.g,
        });
    }
    let kappa_i = params.inertia.inertia_kappa(params.kappa);
    let correction = spin_correction(params.inertia, params.kappa);
    let is_projectile = |i: usize| (p..p + pc).contains(&i);
    let is_target = |i: usize| !is_projectile(i);

    let target_sum = |f: fn(&Body) -> f64| -> f64 {
        let targets = at.iter().enumerate().filter(|(i, _)| is_target(*i));
        targets.map(|(_, b)| f(b)).sum()
    };
    let (target_mass, target_volume) = (target_sum(|b| b.shape.mass), target_sum(|b| b.shape.volume()));
    let target_radius = (3.0 * target_volume / (4.0 * std::f64::consts::PI)).cbrt();

    let v_sys0 = mean_velocity(initial, |_| true);
    let v_sys = mean_velocity(at, |_| true);
    let v_target0 = mean_velocity(initial, is_target);
    let dv = ejection_velocities(initial, at, is_target);
    let binding = binding_energies(params.g, at);
    let centre0 = mass_mean(initial, is_target, |b| b.position);
    // A single projectile's own position and velocity (bit for bit as before); a pile's barycentre.
    let (projectile_position0, projectile_velocity0, projectile_mass) = if pc == 1 {
        (initial[p].position, initial[p].velocity, initial[p].shape.mass)
    } else {
        let mass = initial[p..p + pc].iter().map(|b| b.shape.mass).sum();
        (
            mass_mean(initial, is_projectile, |b| b.position),
            mean_velocity(initial, is_projectile),
            mass,
        )
    };
    let impact_direction = (projectile_position0 - centre0)
        .try_normalize(0.0)
        .unwrap_or_else(Vec3::zeros);

    let fragments: Vec<FragmentAnalysis> = at
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let moments = b.shape.principal_moments(kappa_i);
            let omega = b.spin_body;
            let spin_rate = omega.norm();
            let period = |rate: f64| (rate > 0.0).then(|| 2.0 * std::f64::consts::PI / rate / 3600.0);
            let kinetic_energy = 0.5 * b.shape.mass * (b.velocity - v_sys).norm_squared();
            let i_eff = effective_inertia(&moments, &omega);
            let measure = i_eff.map(|ie| rotation_mode_measure(&moments, ie));
            FragmentAnalysis {
                index: i,
                is_projectile: is_projectile(i),
                mass: b.shape.mass,
                equivalent_radius: b.shape.equivalent_radius(),
                size: b.shape.equivalent_radius() / target_radius,
                ejection_velocity: dv[i].into(),
                ejection_speed: dv[i].norm(),
                kinetic_energy,
                rotational_energy: 0.5 * omega.dot(&moments.component_mul(&omega)),
                binding_energy: binding[i],
                escaping: kinetic_energy >= binding[i],
                spin_rate,
                spin_period_h: period(spin_rate),
                spin_rate_corrected: spin_rate * correction,
                spin_period_corrected_h: period(spin_rate * correction),
                moments: moments.into(),
                effective_inertia: i_eff,
                rotation_mode_measure: measure,
                rotation_mode: rotation_mode(measure),
                impact_site_cosine: if is_projectile(i) {
                    0.0
                } else {
                    (initial[i].position - centre0)
                        .try_normalize(0.0)
                        .map_or(0.0, |r| r.dot(&impact_direction))
                },
            }
        })
        .collect();

    let targets: Vec<&FragmentAnalysis> = fragments.iter().filter(|f| !f.is_projectile).collect();
    let fragment_kinetic_initial: f64 = initial
        .iter()
        .enumerate()
        .filter(|(i, _)| is_target(*i))
        .map(|(_, b)| {
            let moments = b.shape.principal_moments(kappa_i);
            0.5 * b.shape.mass * (b.velocity - v_sys0).norm_squared()
                + 0.5 * b.spin_body.dot(&moments.component_mul(&b.spin_body))
        })
        .sum();
    let fragment_kinetic_translational: f64 = targets.iter().map(|f| f.kinetic_energy).sum();
    let fragment_kinetic_rotational: f64 = targets.iter().map(|f| f.rotational_energy).sum();
    let fragment_kinetic = fragment_kinetic_translational + fragment_kinetic_rotational;
    let projectile_speed = (projectile_velocity0 - v_target0).norm();
    let projectile_kinetic_energy = 0.5 * projectile_mass * projectile_speed.powi(2);
    // + 0.0: an empty sum is −0.0, which prints as "-0.000" when every fragment escapes
    let bound_mass: f64 = targets.iter().filter(|f| !f.escaping).map(|f| f.mass).sum::<f64>() + 0.0;
    let largest = targets.iter().map(|f| f.mass).fold(0.0, f64::max);
    let speeds: Vec<f64> = targets.iter().map(|f| f.ejection_speed).collect();
    let ejection_speed_median = median(&speeds);
    let ejection_speed_mean = speeds.iter().sum::<f64>() / speeds.len() as f64;

    let summary = FragmentSummary {
        n_fragments: targets.len(),
        target_mass,
        target_radius,
        escape_velocity: escape_velocity(params.g, target_mass, target_radius),
        projectile_speed,
        projectile_kinetic_energy,
        specific_energy: projectile_kinetic_energy / target_mass,
        fragment_kinetic_initial,
        fragment_kinetic_translational,
        fragment_kinetic_rotational,
        f_ke: fragment_kinetic / projectile_kinetic_energy,
        rotational_share: if fragment_kinetic > 0.0 {
            fragment_kinetic_rotational / fragment_kinetic
        } else {
            0.0
        },
        bound_mass_fraction: bound_mass / target_mass,
        largest_fragment_fraction: largest / target_mass,
        n_escaping: targets.iter().filter(|f| f.escaping).count(),
        ejection_speed_median,
        ejection_speed_mean,
        ejection_speed_median_relative: ejection_speed_median / projectile_speed,
        ejection_speed_mean_relative: ejection_speed_mean / projectile_speed,
        spin_correction: correction,
        ejection_sites: ejection_sites(&fragments),
    };
    Ok(FragmentReport { fragments, summary })
}
