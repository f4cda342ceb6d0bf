//! Impact geometry beyond Roig03's ζ: where the trajectory is aimed (an impact parameter `b`, or the impact
//! angle θ to the local surface normal, at azimuth ψ around the approach direction `n`) and the projectile's
//! spin and attitude. The default is Roig03 §3's: aimed at the target's centre of mass, a seeded random attitude,
//! no spin.
//!
//! θ is measured on the target's *surface ellipsoid* ([`SurfaceEllipsoid`]): centred at its centre of mass,
//! with the axes and axis ratios of its second moments, scaled to enclose every fragment. It stands for the
//! macroscopic surface that θ means; the union of the fragments would give a normal that changes at the
//! fragments' scale, and a θ(b) that is neither monotonic nor unique. ψ means the same for every aim: the azimuth
//! of the trajectory's offset (and so of the aim point) about `n`. Aimed by θ, the aim point is the point of that
//! ellipsoid on the half-plane spanned by `n` and `e(ψ)`, on the side facing the projectile, whose outward normal
//! makes θ with `n`: a root in the polar angle φ from `n` (bisection between φ = 0 and the silhouette, where the
//! normal is ⊥ `n`); the offset `b` is its distance from the line through the centre of mass along `n`. For a
//! sphere of radius `R`, `φ = θ` and `b = R sin θ`. θ = 0 is the one point whose normal is `n`, at its own azimuth
//! (recorded as ψ), whatever ψ was given.

use crate::ellipsoid::body::Body;
use crate::ellipsoid::quaternion::rotation_matrix;
use crate::impact::error::ImpactError;
use crate::math::{Mat3, Vec3, Vec4};

/// Where the projectile's trajectory (a line along the approach direction `n`) is aimed.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Aim {
    /// At the target's centre of mass, `b = 0` (Roig03 §3; the default).
    #[default]
    Centre,
    /// At an impact parameter `b` (m, ≥ 0): the line's distance from the target's centre of mass.
    ParameterM(f64),
    /// At `b` given as a fraction (in [0, 1)) of the target's radius `R` ([`SurfaceEllipsoid::radius`]).
    ParameterFrac(f64),
    /// At the impact angle θ (degrees, in [0, 90)) between the trajectory and the outward normal of the target's
    /// surface ellipsoid at the aim point (0 = head-on, 90 = grazing).
    AngleDeg(f64),
}

/// The projectile's geometry (the default reproduces Roig03 §3's set-up).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ImpactGeometry {
    /// Where the trajectory is aimed.
    pub aim: Aim,
    /// Azimuth ψ (degrees, in [0, 360)) of the aim point around `n`: of the trajectory's offset, for every aim.
    /// ψ = 0 is along `x̂`, ψ = 90° along `n × x̂ = (0, cos ζ, −sin ζ)`.
    pub azimuth_deg: f64,
    /// Spin of the projectile (rad/s, world frame).
    pub spin_rad_s: Vec3,
    /// Attitude of the projectile: a quaternion `(α, β, γ, δ)`, scalar last, world → body as in the bodies files
    /// (normalised here); `None` = the seeded random attitude.
    pub attitude: Option<Vec4>,
}

/// The keys (fields of the impact's configuration and of the campaign's `[impact]`) that set the aim.
pub const AIM_KEYS: [&str; 3] = ["impact_parameter_m", "impact_parameter_frac", "impact_angle_deg"];

/// The key of [`AIM_KEYS`] that `aim` is given by.
pub fn aim_field(aim: &Aim) -> &'static str {
    match aim {
        Aim::Centre | Aim::ParameterM(_) => AIM_KEYS[0],
        Aim::ParameterFrac(_) => AIM_KEYS[1],
        Aim::AngleDeg(_) => AIM_KEYS[2],
    }
}

impl ImpactGeometry {
    /// The geometry given as options, each absent one the default: `aims` are the values of [`AIM_KEYS`] (at most
    /// one), ψ (degrees), the spin (3 numbers, rad/s) and the attitude (4). Errors name the key (the message names
    /// the two aim keys given together); the values are checked by [`Self::validate`].
    pub fn from_options(
        aims: [Option<f64>; 3],
        azimuth_deg: Option<f64>,
        spin_rad_s: Option<&[f64]>,
        attitude: Option<&[f64]>,
    ) -> Result<Self, ImpactError> {
        let invalid = ImpactError::invalid;
        let given: Vec<usize> = (0..3).filter(|&k| aims[k].is_some()).collect();
        if let [first, second, ..] = given[..] {
            let (first, second) = (AIM_KEYS[first], AIM_KEYS[second]);
            let message = format!("give at most one of {AIM_KEYS:?} (each sets the aim), got {first} and {second}");
            return Err(invalid(second, message));
        }
        let aim = match (given.first(), aims) {
            (Some(0), [Some(b), ..]) => Aim::ParameterM(b),
            (Some(1), [_, Some(f), _]) => Aim::ParameterFrac(f),
            (Some(2), [.., Some(t)]) => Aim::AngleDeg(t),
            _ => Aim::Centre,
        };
        let length = |field: &str, v: Option<&[f64]>, n: usize| match v {
            Some(v) if v.len() != n => Err(invalid(field, format!("expected {n} numbers, got {v:?}"))),
            _ => Ok(()),
        };
        length("projectile_spin_rad_s", spin_rad_s, 3)?;
        length("projectile_attitude", attitude, 4)?;
        Ok(ImpactGeometry {
            aim,
            azimuth_deg: azimuth_deg.unwrap_or(0.0),
            spin_rad_s: spin_rad_s.map_or(Vec3::zeros(), Vec3::from_column_slice),
            attitude: attitude.map(Vec4::from_column_slice),
        })
    }

    /// Checks every value is in range: `Err((field, message))`; `pile` says the projectile is a rubble pile
    /// (which keeps its own spin and attitude).
    pub fn validate(&self, pile: bool) -> Result<(), (&'static str, String)> {
        let field = aim_field(&self.aim);
        match self.aim {
            Aim::ParameterM(b) if !(b.is_finite() && b >= 0.0) => {
                return Err((field, format!("must be >= 0 m and finite, got {b}")));
            }
            Aim::ParameterFrac(f) if !(0.0..1.0).contains(&f) => {
                return Err((field, format!("expected [0, 1) of the target's radius, got {f}")));
            }
            Aim::AngleDeg(t) if !(0.0..90.0).contains(&t) => {
                return Err((
                    field,
                    format!("expected [0, 90) degrees from the surface normal, got {t}"),
                ));
            }
            _ => {}
        }
        let psi = self.azimuth_deg;
        if !(0.0..360.0).contains(&psi) {
            return Err(("aim_azimuth_deg", format!("expected [0, 360) degrees, got {psi}")));
        }
        if psi != 0.0 && self.aim == Aim::Centre {
            return Err((
                "aim_azimuth_deg",
                "needs impact_parameter_m, impact_parameter_frac or impact_angle_deg".into(),
            ));
        }
        let spin = self.spin_rad_s;
        if !spin.iter().all(|w| w.is_finite()) {
            return Err(("projectile_spin_rad_s", format!("must be finite rad/s, got {spin:?}")));
        }
        if pile && spin != Vec3::zeros() {
            return Err((
                "projectile_spin_rad_s",
                "not for a rubble-pile projectile (it keeps its own)".into(),
            ));
        }
        if let Some(q) = self.attitude {
            if !(q.iter().all(|c| c.is_finite()) && q.norm() > 0.0) {
                return Err((
                    "projectile_attitude",
                    format!(
                        "need a finite quaternion [x, y, z, w] of norm > 0, got {:?}",
                        q.as_slice()
                    ),
                ));
            }
            if pile {
                return Err(("projectile_attitude", "not for a rubble-pile projectile".into()));
            }
        }
        Ok(())
    }

    /// The unit vector `e(ψ)` ⊥ `n` (see [`Self::azimuth_deg`]).
    pub fn azimuth_direction(&self, n: &Vec3) -> Vec3 {
        let psi = self.azimuth_deg.to_radians();
        let x = Vec3::x();
        x * psi.cos() + n.cross(&x) * psi.sin()
    }

    /// Where this geometry aims at `target` (bodies in its centre-of-mass frame) coming along `n`.
    pub fn aiming(&self, target: &[Body], n: &Vec3) -> Aiming {
        let surface = SurfaceEllipsoid::of(target);
        let e = self.azimuth_direction(n);
        let offset = match self.aim {
            Aim::Centre => Vec3::zeros(),
            Aim::ParameterM(b) => e * b,
            Aim::ParameterFrac(f) => e * (f * surface.radius()),
            Aim::AngleDeg(t) => {
                // θ = 0: the one point whose normal is n, wherever ψ points (recorded at its own azimuth)
                let p = match t {
                    0.0 => surface.point_with_normal(n),
                    t => surface.point_at_angle(n, &e, t.to_radians()),
                };
                p - n * p.dot(n)
            }
        };
        let aim_point = surface.entry_point(&offset, n);
        Aiming {
            offset,
            aim_point,
            surface,
        }
    }
}

/// A resolved aim ([`ImpactGeometry::aiming`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Aiming {
    /// The trajectory line's offset from the target's centre of mass (m, ⊥ `n`): `b = |offset|`.
    pub offset: Vec3,
    /// Where that line enters the target's surface ellipsoid (m, from the centre of mass); `None`: it misses.
    pub aim_point: Option<Vec3>,
    /// The target's surface ellipsoid.
    pub surface: SurfaceEllipsoid,
}

impl Aiming {
    /// The record of this aim in `impact.json` (`geometry`).
    pub fn record(&self, geometry: &ImpactGeometry, n: &Vec3) -> GeometryRecord {
        let theta = self
            .aim_point
            .map(|p| self.surface.normal(&p).dot(n).clamp(-1.0, 1.0).acos().to_degrees());
        GeometryRecord {
            impact_parameter_m: self.offset.norm(),
            target_radius_m: self.surface.radius(),
            aim_azimuth_deg: match geometry.aim {
                // the head-on point's own azimuth (ψ = 0 along x̂, 90° along n × x̂), 0 on the axis
                Aim::AngleDeg(0.0) if self.offset.norm() > 0.0 => {
                    let x = Vec3::x();
                    let psi = self.offset.dot(&n.cross(&x)).atan2(self.offset.dot(&x)).to_degrees();
                    psi.rem_euclid(360.0)
                }
                _ => geometry.azimuth_deg,
            },
            impact_angle_deg: theta,
            aim_point_m: self.aim_point.map(|p| p.into()),
            projectile_spin_rad_s: geometry.spin_rad_s.into(),
            projectile_attitude: geometry.attitude.map(|q| q.normalize().into()),
        }
    }
}

/// The geometry of an impact as `impact.json` records it (`"geometry"`, only when not the default).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GeometryRecord {
    /// Impact parameter `b` (m).
    pub impact_parameter_m: f64,
    /// The target's radius `R` ([`SurfaceEllipsoid::radius`], m).
    pub target_radius_m: f64,
    /// Azimuth ψ (degrees).
    pub aim_azimuth_deg: f64,
    /// Impact angle θ to the surface ellipsoid's normal at the aim point (degrees).
    pub impact_angle_deg: Option<f64>,
    /// The aim point (m, from the target's centre of mass, in the target's centre-of-mass frame).
    pub aim_point_m: Option<[f64; 3]>,
    /// Spin of the projectile (rad/s, world frame).
    pub projectile_spin_rad_s: [f64; 3],
    /// Attitude quaternion given (scalar last, normalised); absent = the seeded random one.
    pub projectile_attitude: Option<[f64; 4]>,
}

/// The target's surface ellipsoid `xᵀ Q x = 1` about its centre of mass (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceEllipsoid {
    /// Semi-axes (m).
    pub axes: Vec3,
    /// Principal directions (columns, world frame).
    pub frame: Mat3,
}

impl SurfaceEllipsoid {
    /// The ellipsoid of `bodies` (centre-of-mass frame): the uniform ellipsoid of their second moments
    /// `Σ m (c cᵀ + Rᵀ diag(A², B², C²) R / 5)` (whatever the inertia model), scaled by the smallest factor for
    /// which each fragment `c + Rᵀ diag(A, B, C) u` (|u| ≤ 1) provably lies inside: `|Q^½ c| + ‖Q^½ Rᵀ diag(A, B, C)‖₂`
    /// (exact for one fragment at the centre).
    pub fn of(bodies: &[Body]) -> Self {
        let mass: f64 = bodies.iter().map(|b| b.shape.mass).sum();
        let shape = |b: &Body| rotation_matrix(&b.quaternion).transpose() * Mat3::from_diagonal(&b.shape.axes);
        let second: Mat3 = bodies
            .iter()
            .map(|b| {
                let l = shape(b);
                (b.position * b.position.transpose() + l * l.transpose() / 5.0) * b.shape.mass
            })
            .sum();
        let eigen = (second / mass).symmetric_eigen();
        let axes = eigen.eigenvalues.map(|l| (5.0 * l.max(0.0)).sqrt());
        let root_q = eigen.eigenvectors * Mat3::from_diagonal(&axes.map(|a| 1.0 / a)) * eigen.eigenvectors.transpose();
        let scale = bodies
            .iter()
            .map(|b| {
                let m = root_q * shape(b);
                let stretch = (m.transpose() * m).symmetric_eigenvalues().max().max(0.0).sqrt();
                (root_q * b.position).norm() + stretch
            })
            .fold(0.0, f64::max);
        SurfaceEllipsoid {
            axes: axes * scale,
            frame: eigen.eigenvectors,
        }
    }

    /// `R = (A B C)^{1/3}` (m): the radius of the sphere of the same volume (a sphere's radius).
    pub fn radius(&self) -> f64 {
        self.axes.product().cbrt()
    }

    /// `Q` with the semi-axes raised to `power` (−2: the ellipsoid's `Q`; 2: its `Q⁻¹`).
    fn q(&self, power: i32) -> Mat3 {
        self.frame * Mat3::from_diagonal(&self.axes.map(|a| a.powi(power))) * self.frame.transpose()
    }

    /// The outward unit normal at the surface point `p` (m).
    pub fn normal(&self, p: &Vec3) -> Vec3 {
        (self.q(-2) * p).normalize()
    }

    /// The surface point whose outward normal is the unit vector `normal`: `Q⁻¹ N / √(Nᵀ Q⁻¹ N)`.
    pub fn point_with_normal(&self, normal: &Vec3) -> Vec3 {
        let inverse = self.q(2);
        inverse * normal / normal.dot(&(inverse * normal)).sqrt()
    }

    /// The point `p(φ) = d/√(dᵀ Q d)`, `d = cos φ n + sin φ e`, of the ellipsoid on the half-plane of the unit
    /// vectors `n` and `e ⊥ n` (`φ ∈ [0, φ_s]` from `n` to the silhouette, where the normal is ⊥ `n`) whose outward
    /// normal makes the angle `theta` (rad, in [0, π/2)) with `n` (module docs). The first sign change of the
    /// angle's excess over a scan of 64 steps is bisected to the last bit of φ; when no point of the arc makes
    /// `theta` (an angle below the smallest there, which is above 0 unless `n` is a principal direction or the
    /// azimuth holds the point whose normal is `n`), the point of the smallest angle the scan found.
    pub fn point_at_angle(&self, n: &Vec3, e: &Vec3, theta: f64) -> Vec3 {
        let q = self.q(-2);
        let point = |phi: f64| {
            let d = n * phi.cos() + e * phi.sin();
            d / d.dot(&(q * d)).sqrt()
        };
        let excess = |phi: f64| (q * point(phi)).normalize().dot(n).clamp(-1.0, 1.0).acos() - theta;
        // The silhouette of the plane's ellipse u² M₀₀ + 2uv M₀₁ + v² M₁₁ = 1 (p = u n + v e): largest v.
        let silhouette = n.dot(&(q * n)).atan2(-n.dot(&(q * e)));
        const STEPS: usize = 64;
        let phis: Vec<f64> = (0..=STEPS).map(|k| silhouette * k as f64 / STEPS as f64).collect();
        let values: Vec<f64> = phis.iter().map(|&phi| excess(phi)).collect();
        if values[0] == 0.0 {
            return point(0.0);
        }
        let Some(k) = (1..=STEPS).find(|&k| values[k - 1] < 0.0 && values[k] >= 0.0) else {
            let lowest = (0..=STEPS)
                .min_by(|&a, &b| values[a].total_cmp(&values[b]))
                .unwrap_or(0);
            return point(phis[lowest]);
        };
        let (mut lo, mut hi) = (phis[k - 1], phis[k]);
        loop {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if excess(mid) < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        // the end whose angle is nearer θ
        if excess(lo).abs() <= excess(hi).abs() {
            point(lo)
        } else {
            point(hi)
        }
    }

    /// Where the line `offset + s n` coming from `s = +∞` enters the ellipsoid, or `None` if it misses (or only
    /// grazes) it.
    pub fn entry_point(&self, offset: &Vec3, n: &Vec3) -> Option<Vec3> {
        let q = self.q(-2);
        let (a, b, c) = (n.dot(&(q * n)), offset.dot(&(q * n)), offset.dot(&(q * offset)) - 1.0);
        let discriminant = b * b - a * c;
        (discriminant > 0.0).then(|| offset + n * ((-b + discriminant.sqrt()) / a))
    }
}
