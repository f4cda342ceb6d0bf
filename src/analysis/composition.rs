//! Composition of the outcome of a collision between two rubble piles (the paper has a single-ellipsoid projectile;
//! these are our definitions): bodies are `target` or `projectile` by index (`impact.json`); the clumps are the
//! caller's, those of [`crate::analysis::clumps`] (so the largest remnant here is the one of `analyze`'s
//! `largest remnant:` line). A clump is bound to the system by Roig03 Eq. 43 with the clump as one body:
//! `½ M_c |V_c − V_sys|² < Σ_{i∈c} Σ_{j∉c} G m_i m_j / r_ij`. The largest remnant is the heaviest clump, its spin
//! `ω = I⁻¹ L` with `I = Σ (Rᵢᵀ Iᵢ Rᵢ + mᵢ(|dᵢ|² 1 − dᵢ dᵢᵀ))`, `L = Σ (mᵢ dᵢ × uᵢ + Rᵢᵀ Iᵢ ω_bᵢ)` (barycentric),
//! period `2π/|ω|` (no §4.3 correction: parallel-axis terms dominate). Mixing of the other bound clumps: their
//! mass-weighted projectile fraction and how many hold bodies of both origins.

use crate::analysis::clumps::{clump_spin, mass_mean};
use crate::ellipsoid::body::Body;
use crate::math::Vec3;

/// Where a body came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Origin {
    /// A body of the target pile.
    Target,
    /// A body of the projectile (pile).
    Projectile,
}

/// One clump (connected set of bodies in contact).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Clump {
    /// Body indices, increasing.
    pub bodies: Vec<usize>,
    /// Total mass (kg).
    pub mass_kg: f64,
    /// Mass of its projectile bodies over its mass.
    pub projectile_fraction: f64,
    /// Whether it is bound (module docs).
    pub bound: bool,
}

/// The largest remnant (most massive clump): the same clump as [`crate::analysis::clumps::ClumpReport::largest`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LargestRemnant {
    /// Number of bodies.
    pub n_bodies: usize,
    /// Mass (kg).
    pub mass_kg: f64,
    /// Mass over the mass of the whole system (target + projectile).
    pub mass_fraction_of_system: f64,
    /// Mass over the target's mass.
    pub mass_over_target: f64,
    /// Mass fraction from the projectile.
    pub projectile_fraction: f64,
    /// Whether it is bound (module docs).
    pub bound: bool,
    /// Spin rate `|ω|` of the clump as a whole (rad/s).
    pub spin_rate: f64,
    /// Spin period `2π/|ω|` (h); `None` without spin.
    pub spin_period_h: Option<f64>,
}

/// Composition of a two-pile collision outcome (`analysis.json`'s `composition`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Composition {
    /// Target mass (kg).
    pub target_mass_kg: f64,
    /// Projectile mass (kg).
    pub projectile_mass_kg: f64,
    /// Number of clumps (single bodies included).
    pub n_clumps: usize,
    /// Number of bound clumps.
    pub n_bound_clumps: usize,
    /// Mass in bound clumps over the system mass.
    pub bound_mass_fraction: f64,
    /// Target mass in bound clumps over the target mass.
    pub bound_target_fraction: f64,
    /// Projectile mass in bound clumps over the projectile mass.
    pub bound_projectile_fraction: f64,
    /// The largest remnant.
    pub largest_remnant: LargestRemnant,
    /// Share of the projectile's mass that ends in the largest remnant.
    pub projectile_in_largest_remnant: f64,
    /// Number of bound clumps other than the largest remnant.
    pub n_other_bound: usize,
    /// Their total mass (kg).
    pub other_bound_mass_kg: f64,
    /// Their mass-weighted projectile fraction; `None` when there are none.
    pub other_bound_projectile_fraction: Option<f64>,
    /// How many of them hold bodies of both origins.
    pub other_bound_mixed: usize,
    /// Every clump, the most massive first.
    pub clumps: Vec<Clump>,
    /// Per body: its origin.
    pub origins: Vec<Origin>,
    /// Per body: the index of its clump in [`Composition::clumps`].
    pub clump_of: Vec<usize>,
}

impl Composition {
    /// One line for the terminal: bound fraction, largest remnant (mass, spin, projectile fraction), mixing.
    pub fn summary_line(&self) -> String {
        let lr = &self.largest_remnant;
        format!(
            "composition: {} ({} bound to the system, {:.3} of all bodies' mass); largest remnant {}, {:.4e} kg ({:.3} of \
             the system, {}), spin period {}, projectile fraction {:.3}; other bound clumps {} ({:.4e} kg, projectile \
             fraction {}, {} mixed)",
            crate::analysis::clumps::counted(self.n_clumps, "clump", "clumps"),
            self.n_bound_clumps,
            self.bound_mass_fraction,
            crate::analysis::clumps::counted(lr.n_bodies, "body", "bodies"),
            lr.mass_kg,
            lr.mass_fraction_of_system,
            if lr.bound {
                "bound to the system"
            } else {
                "not bound to the system"
            },
            lr.spin_period_h.map_or("none".into(), |p| format!("{p:.3} h")),
            lr.projectile_fraction,
            self.n_other_bound,
            self.other_bound_mass_kg,
            self.other_bound_projectile_fraction
                .map_or("n/a".into(), |f| format!("{f:.3}")),
            self.other_bound_mixed,
        )
    }
}

/// The composition of `bodies` (one snapshot) whose projectile bodies are `projectile` (a range of indices), over
/// the clumps `clumps` (lists of body indices, each ascending, covering every body once: those of
/// [`crate::analysis::clumps::ClumpReport`], so both name the same largest remnant); `moments` gives each body's
/// principal moments (kg m²), `g` the gravitational constant (SI). `None` when the range is empty, out of bounds or
/// covers every body, or when `clumps` is empty.
pub fn composition(
    bodies: &[Body],
    projectile: std::ops::Range<usize>,
    clumps: &[Vec<usize>],
    g: f64,
    moments: impl Fn(&Body) -> Vec3,
) -> Option<Composition> {
    let n = bodies.len();
    if projectile.is_empty() || projectile.end > n || projectile.len() == n || clumps.is_empty() {
        return None;
    }
    let origins: Vec<Origin> = (0..n)
        .map(|i| {
            if projectile.contains(&i) {
                Origin::Projectile
            } else {
                Origin::Target
            }
        })
        .collect();
    let mass_of = |ids: &mut dyn Iterator<Item = usize>, origin: Option<Origin>| -> f64 {
        ids.filter(|&i| origin.is_none_or(|o| origins[i] == o))
            .map(|i| bodies[i].shape.mass)
            .sum::<f64>()
            + 0.0 // -0 → 0 when empty
    };
    let total = mass_of(&mut (0..n), None);
    let target_mass = mass_of(&mut (0..n), Some(Origin::Target));
    let projectile_mass = mass_of(&mut (0..n), Some(Origin::Projectile));
    let v_sys = bodies.iter().map(|b| b.velocity * b.shape.mass).sum::<Vec3>() / total;

    let mut clumps: Vec<Clump> = clumps
        .iter()
        .cloned()
        .map(|ids| {
            let mass = mass_of(&mut ids.iter().copied(), None);
            let from_projectile = mass_of(&mut ids.iter().copied(), Some(Origin::Projectile));
            let v = mass_mean(bodies, &ids, mass, |b| b.velocity);
            let kinetic = 0.5 * mass * (v - v_sys).norm_squared();
            let mut binding = 0.0;
            for &i in &ids {
                for (j, other) in bodies.iter().enumerate() {
                    if ids.binary_search(&j).is_err() {
                        binding +=
                            g * bodies[i].shape.mass * other.shape.mass / (bodies[i].position - other.position).norm();
                    }
                }
            }
            Clump {
                bound: kinetic < binding,
                projectile_fraction: from_projectile / mass,
                mass_kg: mass,
                bodies: ids,
            }
        })
        .collect();
    // Most massive first; ties by first body, for determinism.
    clumps.sort_by(|a, b| b.mass_kg.total_cmp(&a.mass_kg).then(a.bodies[0].cmp(&b.bodies[0])));
    let mut clump_of = vec![0; n];
    for (k, c) in clumps.iter().enumerate() {
        for &i in &c.bodies {
            clump_of[i] = k;
        }
    }
    let bound: Vec<&Clump> = clumps.iter().filter(|c| c.bound).collect();
    let bound_of = |origin: Origin| -> f64 {
        bound
            .iter()
            .flat_map(|c| c.bodies.iter())
            .filter(|&&i| origins[i] == origin)
            .map(|&i| bodies[i].shape.mass)
            .sum::<f64>()
            + 0.0 // -0 → 0 when empty
    };
    let largest = &clumps[0];
    let spin = clump_spin(bodies, &largest.bodies, &moments).norm();
    // Clumps are sorted by mass: every bound clump after the first.
    let others: Vec<&Clump> = clumps.iter().skip(1).filter(|c| c.bound).collect();
    let other_mass: f64 = others.iter().map(|c| c.mass_kg).sum::<f64>() + 0.0; // -0 → 0 when empty
    let other_projectile: f64 = others.iter().map(|c| c.mass_kg * c.projectile_fraction).sum();
    Some(Composition {
        target_mass_kg: target_mass,
        projectile_mass_kg: projectile_mass,
        n_clumps: clumps.len(),
        n_bound_clumps: bound.len(),
        bound_mass_fraction: (bound_of(Origin::Target) + bound_of(Origin::Projectile)) / total,
        bound_target_fraction: bound_of(Origin::Target) / target_mass,
        bound_projectile_fraction: bound_of(Origin::Projectile) / projectile_mass,
        largest_remnant: LargestRemnant {
            n_bodies: largest.bodies.len(),
            mass_kg: largest.mass_kg,
            mass_fraction_of_system: largest.mass_kg / total,
            mass_over_target: largest.mass_kg / target_mass,
            projectile_fraction: largest.projectile_fraction,
            bound: largest.bound,
            spin_rate: spin,
            spin_period_h: (spin > 0.0).then(|| 2.0 * std::f64::consts::PI / spin / 3600.0),
        },
        projectile_in_largest_remnant: largest.mass_kg * largest.projectile_fraction / projectile_mass,
        n_other_bound: others.len(),
        other_bound_mass_kg: other_mass,
        other_bound_projectile_fraction: (other_mass > 0.0).then(|| other_projectile / other_mass),
        other_bound_mixed: others
            .iter()
            .filter(|c| c.projectile_fraction > 0.0 && c.projectile_fraction < 1.0)
            .count(),
        clumps,
        origins,
        clump_of,
    })
}
