//! Projectiles and the impact geometry of Roig03 §3 and Table 2.
//!
//! A projectile is one ellipsoid with the fragments' density and axis ratios (1 : 0.7 : 0.5), a random
//! (seeded) attitude and no spin. It moves in the y–z plane toward the target's centre of mass, at angle ζ to
//! the target's spin axis z, and is placed so that its surface first touches a fragment at `contact_time`
//! (≈ 90 s); [`crate::impact::geometry`] aims it off the centre, spins and turns it. The whole system is then moved
//! to its centre-of-mass frame.
//! `Q = ½ m_p v² / M` is the specific impact energy (J/kg; ×10⁴ for erg/g).

use crate::ellipsoid::body::{Body, Ellipsoid};
use crate::ellipsoid::quaternion::rotation_matrix;
use crate::geometry::ellipsoid_overlap::are_apart;
use crate::impact::geometry::{Aim, GeometryRecord, ImpactGeometry};
use crate::impact::target::to_centre_of_mass_frame;
use crate::math::{Mat3, Vec3};
use crate::random::{generator, random_quaternion};
use std::f64::consts::PI;

/// 1 J/kg in erg/g.
pub const ERG_PER_G_PER_J_PER_KG: f64 = 1e4;

/// A projectile: equivalent radius, speed and density.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ProjectileSpec {
    /// Name ("P1", "P2", "P3", or "custom").
    pub id: String,
    /// Equivalent radius `(ABC)^{1/3}` (m).
    pub equivalent_radius: f64,
    /// Impact speed relative to the target (m/s).
    pub speed: f64,
    /// Density (kg m⁻³).
    pub density: f64,
    /// Axis ratios B/A and C/A.
    pub axis_ratios: [f64; 2],
}

impl ProjectileSpec {
    /// The Table 2 projectiles P1, P2, P3 (equivalent radii 14.14, 21.21, 28.28 km) at 5 km/s.
    pub fn preset(id: &str) -> Option<Self> {
        let r = match id.to_ascii_uppercase().as_str() {
            "P1" => 14.14e3,
            "P2" => 21.21e3,
            "P3" => 28.28e3,
            _ => return None,
        };
        Some(Self::custom(id.to_ascii_uppercase(), r, 5000.0))
    }

    /// A projectile of the fragments' density (3000 kg m⁻³) and shape.
    pub fn custom(id: String, equivalent_radius: f64, speed: f64) -> Self {
        ProjectileSpec {
            id,
            equivalent_radius,
            speed,
            density: 3000.0,
            axis_ratios: [0.7, 0.5],
        }
    }

    /// The ellipsoid (semi-axes from the equivalent radius and axis ratios).
    pub fn shape(&self) -> Ellipsoid {
        let a = self.equivalent_radius / (self.axis_ratios[0] * self.axis_ratios[1]).cbrt();
        Ellipsoid {
            axes: Vec3::new(a, a * self.axis_ratios[0], a * self.axis_ratios[1]),
            mass: self.density * 4.0 / 3.0 * PI * self.equivalent_radius.powi(3),
        }
    }
}

/// How an impact was set up (written as `impact.json`).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ImpactSetup {
    /// The projectile.
    pub projectile: ProjectileSpec,
    /// Impact angle ζ between the trajectory and the spin axis z (degrees).
    pub angle_deg: f64,
    /// Projectile mass (kg).
    pub projectile_mass_kg: f64,
    /// Target mass (kg).
    pub target_mass_kg: f64,
    /// `Q = ½ m_p v² / M` (J/kg).
    pub q_j_per_kg: f64,
    /// `Q` in erg/g.
    pub q_erg_per_g: f64,
    /// Time at which the projectile's surface first touches a fragment, ballistic estimate (s).
    pub impact_time_s: f64,
    /// Seed of the projectile's attitude.
    pub seed: u64,
    /// Index of the projectile among the bodies (the last one); for a rubble-pile projectile, its first body.
    pub projectile_index: usize,
    /// The rubble-pile projectile (file, N, mass, which bodies are whose), when there is one
    /// (`pile.rs`); absent for a single ellipsoid.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub projectile_pile: Option<PileRecord>,
    /// The impact geometry ([`crate::impact::geometry`]), when it is not the default (aimed at the centre of mass,
    /// seeded random attitude, no spin).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub geometry: Option<GeometryRecord>,
}

/// The target's bodies in their centre-of-mass frame, their total mass (kg) and the unit vector `n` from the
/// target's centre towards the incoming projectile, at `angle_deg` (ζ, degrees) from the z axis in the y–z plane.
pub fn target_and_direction(target: &[Body], angle_deg: f64) -> (Vec<Body>, f64, Vec3) {
    let mut bodies = target.to_vec();
    to_centre_of_mass_frame(&mut bodies);
    let target_mass: f64 = bodies.iter().map(|b| b.shape.mass).sum();
    let zeta = angle_deg.to_radians();
    (bodies, target_mass, Vec3::new(0.0, zeta.sin(), zeta.cos()))
}

/// Adds the projectile to `target` (bodies of the target, any frame) and returns the whole system in its
/// centre-of-mass frame, with the setup; `contact_time` (s) is when the surfaces first touch. The projectile's
/// `geometry` (aim, spin, attitude; [`ImpactGeometry::default`] for Roig03's) displaces its trajectory by the aim's
/// offset (⊥ `n`), its velocity stays `−v n`. The flag says whether the projectile meets the target (its
/// trajectory enters the surface ellipsoid and its surface touches a fragment before its centre passes the
/// target's); always true when aimed at the centre.
pub fn set_up_aimed_impact(
    target: &[Body],
    projectile: &ProjectileSpec,
    geometry: &ImpactGeometry,
    angle_deg: f64,
    contact_time: f64,
    seed: u64,
) -> (Vec<Body>, ImpactSetup, bool) {
    let (mut bodies, target_mass, n) = target_and_direction(target, angle_deg);
    let shape = projectile.shape();
    let quaternion = match geometry.attitude {
        Some(q) => q.normalize(),
        None => random_quaternion(&mut generator(seed)),
    };
    // Zero stays the exact zero of the default set-up (no rounded −0).
    let spin_body = if geometry.spin_rad_s == Vec3::zeros() {
        Vec3::zeros()
    } else {
        rotation_matrix(&quaternion) * geometry.spin_rad_s
    };
    let aiming = geometry.aiming(&bodies, &n);
    let incoming = [Body {
        shape,
        position: aiming.offset,
        velocity: Vec3::zeros(),
        quaternion,
        spin_body,
    }];
    let (hi, touched) = contact_walk(&bodies, &incoming, &n);
    let start = hi + projectile.speed * contact_time;
    let mut position = n * start;
    if geometry.aim != Aim::Centre {
        position += aiming.offset;
    }
    bodies.push(Body {
        position,
        velocity: -n * projectile.speed,
        ..incoming[0].clone()
    });
    to_centre_of_mass_frame(&mut bodies);
    let q = 0.5 * shape.mass * projectile.speed.powi(2) / target_mass;
    let setup = ImpactSetup {
        projectile: projectile.clone(),
        angle_deg,
        projectile_mass_kg: shape.mass,
        target_mass_kg: target_mass,
        q_j_per_kg: q,
        q_erg_per_g: q * ERG_PER_G_PER_J_PER_KG,
        impact_time_s: contact_time,
        seed,
        projectile_index: bodies.len() - 1,
        projectile_pile: None,
        geometry: (*geometry != ImpactGeometry::default()).then(|| aiming.record(geometry, &n)),
    };
    let hits = geometry.aim == Aim::Centre || (touched && aiming.aim_point.is_some());
    (bodies, setup, hits)
}

/// Distance `s` (m) along the unit vector `n` at which `projectile` (bodies in its own frame, moved rigidly by
/// `s n`) first touches `target` (centre-of-mass frame) when coming in from afar: the largest `s` at which some
/// pair of ellipsoids overlaps, to bisection precision (60 halvings of a step of 2 % of the smallest semi-axis
/// of the projectile). The walk starts beyond every bounding sphere and moves in by that step. Also whether the
/// bodies touch at all before the projectile's frame passes the target's centre (`s > 0`).
pub fn contact_walk(target: &[Body], projectile: &[Body], n: &Vec3) -> (f64, bool) {
    let sigma = |b: &Body| {
        let r = rotation_matrix(&b.quaternion);
        r.transpose() * Mat3::from_diagonal(&b.shape.axes.component_mul(&b.shape.axes)) * r
    };
    let sigmas_t: Vec<Mat3> = target.iter().map(sigma).collect();
    let sigmas_p: Vec<Mat3> = projectile.iter().map(sigma).collect();
    let touching = |s: f64| {
        let shift = n * s;
        projectile.iter().zip(&sigmas_p).any(|(p, sig_p)| {
            let centre = shift + p.position;
            target.iter().zip(&sigmas_t).any(|(b, sig)| {
                let d = centre - b.position;
                d.norm() < p.shape.axes.x + b.shape.axes.x && !are_apart(&d, sig_p, sig)
            })
        })
    };
    let reach = |bodies: &[Body]| {
        bodies
            .iter()
            .map(|b| b.position.norm() + b.shape.axes.x)
            .fold(0.0, f64::max)
    };
    let outer = reach(target) + reach(projectile);
    let step = 0.02 * projectile.iter().map(|b| b.shape.axes.z).fold(f64::INFINITY, f64::min);
    let mut s = outer;
    while s > 0.0 && !touching(s) {
        s -= step;
    }
    let (mut lo, mut hi) = (s, s + step); // touching at lo, apart at hi
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if touching(mid) { lo = mid } else { hi = mid }
    }
    (hi, s > 0.0)
}

/// Where the bodies of an impact with a rubble-pile projectile come from (in `impact.json` as
/// `"projectile_pile"`).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PileRecord {
    /// The projectile pile's bodies file.
    pub file: String,
    /// Number of bodies of the projectile pile `N_p`.
    pub n: usize,
    /// Total mass of the projectile pile (kg).
    pub mass_kg: f64,
    /// Whether it was turned by the seeded random attitude.
    pub random_attitude: bool,
    /// Body indices of the target: `[0, N_t)` (start, end).
    pub target_bodies: [usize; 2],
    /// Body indices of the projectile pile: `[N_t, N_t + N_p)` (start, end).
    pub projectile_bodies: [usize; 2],
}
