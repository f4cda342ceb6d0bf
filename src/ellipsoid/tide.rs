//! Tide of a planet on a prescribed Kepler orbit, the `[physics.flyby]` term (the setting of Richardson, Bottke &
//! Love 1998, Icarus 134, 47–76). The frame's origin falls freely on `s(t)` ([`crate::gravity::kepler`]), the planet
//! at `R = −s`; each body, a point mass (as the mutual gravity, Roig03 Eq. 6), gets the exact (not linearised)
//! `a_i = −GM (r_i − R)/|r_i − R|³ − GM R/|R|³`.
//!
//! Energy: `H + E_tide` is conserved (up to `2∫F dt`), `E_tide = P·V₀ + Σ GM m_i (1/|R| − 1/|r_i − R|)` (`V₀ = ṡ`,
//! `P` the frame momentum): the restricted problem's inertial energy minus the origin's constant Kepler energy.
//! [`TideTerm::energy`] computes it for the residual, so the state and checkpoints keep their shape; both near-equal
//! differences are cancellation-free (`|R| − |d| = (2 r·R − r·r)/(|R| + |d|)`). Optional J2 (`j2`, `radius`, `pole`):
//! `a_i += g_J2(r_i − R)` ([`crate::gravity::zonal`]) with the origin still on the Kepler orbit (exact for a
//! prescribed frame acceleration; the centre of mass drifts by `~J2 (R/q)²` of the tide), and `E_tide` gains
//! `Σ m_i Φ_J2(r_i − R)`.

use scene_derive::SceneFields;
use serde::{Deserialize, Serialize};

use crate::gravity::kepler::{KeplerOrbit, orientation_matrix};
use crate::gravity::zonal::J2Field;
use crate::io::scene_file::{SceneError, Validator};
use crate::math::Vec3;

/// `physics.flyby`: a planet on a prescribed orbit about the frame's origin (the pile's centre of mass at t = 0).
///
/// ```toml
/// [physics.flyby]
/// mass = 5.9722e24            # kg (Earth)
/// radius = 6.371e6            # m, optional
/// q = 3.8e7                   # perigee distance (m)
/// v_inf = 5800.0              # m/s (hyperbolic); or eccentricity = 0.5
/// t_perigee = 1.2e5           # s
/// orientation_deg = [0, 0, 0] # [node, inclination, argument of perigee] (deg)
/// j2 = 1.0826e-3              # optional (needs radius); Earth's
/// pole = [0.0, 0.0, 1.0]      # optional: the planet's spin axis in the frame
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "physics.flyby")]
#[serde(deny_unknown_fields)]
pub struct FlybySpec {
    /// Planet mass (kg, ≥ 0). Required. `GM` uses the scene's `physics.gravity.G` (SI G without gravity). A mass of
    /// 0 is allowed: the planet then pulls on nothing and the frame moves in a straight line at `v_inf`.
    #[field(unit = "kg", default = "required", range = NonNegative)]
    #[field(meaning = "planet mass (0: no pull, the frame moves in a straight line at v_inf)")]
    pub mass: f64,
    /// planet radius: the perigee must lie outside it; the reference radius of j2
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "m", default = "none", range = Positive)]
    pub radius: Option<f64>,
    /// perigee distance between the planet's centre and the frame origin
    #[field(unit = "m", default = "required", range = Positive)]
    pub q: f64,
    /// Speed at infinity `v∞` (m/s, > 0) of a hyperbolic flyby, `e = 1 + q v∞²/GM`. Give exactly one of `v_inf`
    /// and `eccentricity`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "m/s", default = "(v_inf or eccentricity)", range = Positive)]
    #[field(meaning = "speed at infinity of a hyperbolic flyby; exactly one of v_inf, eccentricity")]
    pub v_inf: Option<f64>,
    /// Eccentricity `e` (≥ 0, ≠ 1; < 1 elliptic, > 1 hyperbolic), the explicit form. Give exactly one of `v_inf`
    /// and `eccentricity`; needs `mass > 0`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "-", default = "(v_inf or eccentricity)", range = Rule(">= 0, != 1; needs mass > 0"))]
    #[field(meaning = "orbit eccentricity (< 1 elliptic, > 1 hyperbolic); exactly one of v_inf, eccentricity")]
    pub eccentricity: Option<f64>,
    /// time of perigee passage
    #[field(unit = "s", default = "required", range = Rule("finite"))]
    pub t_perigee: f64,
    /// Orientation `[Ω, i, ω]` (degrees) of the frame origin's orbit about the planet: longitude of the node,
    /// inclination and argument of perigee, perifocal → frame `R_z(Ω) R_x(i) R_z(ω)`. Default `[0, 0, 0]`: the orbit
    /// in the x–y plane, anticlockwise about +z, the origin at `+q x̂` from the planet at perigee (the planet at
    /// `−q x̂` in the frame).
    #[serde(default, deserialize_with = "crate::io::scene_file::exact::array")]
    #[field(unit = "deg", default = "[0, 0, 0]", range = Rule("3 finite numbers"))]
    #[field(meaning = "[node, inclination, argument of perigee] of the orbit about the planet")]
    pub orientation_deg: [f64; 3],
    /// The planet's second zonal harmonic J2 (dimensionless, finite; Earth 1.0826e-3 with its equatorial radius
    /// 6378.137 km). Optional, default none (a point mass); needs `radius`, the reference radius of J2.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "-", default = "none", range = Rule("finite; needs radius"))]
    #[field(meaning = "the planet's second zonal harmonic (Earth 1.0826e-3)")]
    pub j2: Option<f64>,
    /// The planet's spin axis (frame coordinates, any non-zero length; normalised), used with `j2`. Default
    /// `[0, 0, 1]`.
    #[serde(
        default,
        deserialize_with = "crate::io::scene_file::exact::option",
        skip_serializing_if = "Option::is_none"
    )]
    #[field(unit = "-", default = "[0, 0, 1]", range = Rule("3 finite numbers, non-zero"))]
    #[field(meaning = "the planet's spin axis in the frame (normalised), used with j2")]
    pub pole: Option<[f64; 3]>,
}

/// The resolved flyby term.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TideTerm {
    /// `G M` of the planet (m³ s⁻², ≥ 0).
    pub gm: f64,
    /// Planet radius (m), when given.
    pub radius: Option<f64>,
    /// The frame origin's orbit about the planet (`gm` as above; a straight line when it is 0).
    pub orbit: KeplerOrbit,
    /// The planet's J2 field, when given (`None`: a point mass).
    pub j2: Option<J2Field>,
}

impl TideTerm {
    /// The planet's position `R(t) = −s(t)` (m) in the frame at time `t` (s).
    pub fn planet_position(&self, t: f64) -> Vec3 {
        -self.orbit.state(t).0
    }

    /// Tidal acceleration (m/s²) at `r` (m) with the planet at `planet` (m):
    /// `−GM (r − R)/|r − R|³ − GM R/|R|³`, in the cancellation-free form
    /// `GM [R (|R|³ − |d|³)/(|d|³ |R|³) − r/|d|³]`, `d = r − R`; plus `g_J2(d)` with J2.
    pub fn acceleration(&self, r: &Vec3, planet: &Vec3) -> Vec3 {
        if self.gm == 0.0 {
            return Vec3::zeros();
        }
        let point = self.point_mass_acceleration(r, planet);
        match &self.j2 {
            Some(j2) => point + j2.acceleration(&(r - planet)),
            None => point,
        }
    }

    fn point_mass_acceleration(&self, r: &Vec3, planet: &Vec3) -> Vec3 {
        let big = planet.norm();
        let d = (r - planet).norm();
        // |R| − |d| = (|R|² − |d|²)/(|R| + |d|) = (2 r·R − r·r)/(|R| + |d|).
        let diff = (2.0 * r.dot(planet) - r.norm_squared()) / (big + d);
        let cube_diff = diff * (big * big + big * d + d * d);
        let (d3, big3) = (d * d * d, big * big * big);
        self.gm * (planet * (cube_diff / (d3 * big3)) - r / d3)
    }

    /// Tidal energy `E_tide = P·V₀ + Σ GM m_i (1/|R| − 1/|r_i − R|)` (+ `Σ m_i Φ_J2(r_i − R)` with J2) (J) of
    /// bodies at `positions` (m) with
    /// `masses` (kg) and total momentum `momentum` (kg m/s), at time `t` (s): `H + E_tide` is conserved (see the
    /// module docs).
    pub fn energy(&self, t: f64, positions: &[Vec3], masses: &[f64], momentum: &Vec3) -> f64 {
        let (s, v0) = self.orbit.state(t);
        let planet = -s;
        let big = planet.norm();
        let mut potential = 0.0;
        if self.gm != 0.0 {
            for (r, m) in positions.iter().zip(masses) {
                let d = (r - planet).norm();
                // 1/|R| − 1/|d| = (|d| − |R|)/(|R| |d|), |d| − |R| = (r·r − 2 r·R)/(|R| + |d|).
                let diff = (r.norm_squared() - 2.0 * r.dot(&planet)) / (big + d);
                potential += m * diff / (big * d);
            }
        }
        let zonal: f64 = match &self.j2 {
            Some(j2) if self.gm != 0.0 => positions
                .iter()
                .zip(masses)
                .map(|(r, m)| m * j2.potential(&(r - planet)))
                .sum(),
            _ => 0.0,
        };
        momentum.dot(&v0) + self.gm * potential + zonal
    }
}

/// Validates `physics.flyby` (errors name the field) and resolves it with the scene's `G` (m³ kg⁻¹ s⁻²).
pub(crate) fn resolve_flyby(v: &Validator, spec: &FlybySpec, g: f64) -> Result<TideTerm, SceneError> {
    let mass = v.field(&FlybySpec::MASS, spec.mass)?;
    let gm = g * mass;
    let q = v.field(&FlybySpec::Q, spec.q)?;
    let radius = spec.radius.map(|r| v.field(&FlybySpec::RADIUS, r)).transpose()?;
    if let Some(r) = radius
        && q <= r
    {
        return Err(v.invalid(
            "physics.flyby.q",
            format!("must exceed the planet's radius {r} m (the orbit would hit the planet), got {q}"),
        ));
    }
    if !spec.t_perigee.is_finite() {
        return Err(v.invalid(
            "physics.flyby.t_perigee",
            format!("must be finite (s), got {}", spec.t_perigee),
        ));
    }
    v.finite_vec("physics.flyby.orientation_deg", &spec.orientation_deg)?;
    let [node, inc, peri] = spec.orientation_deg.map(f64::to_radians);
    let rotation = orientation_matrix(node, inc, peri);
    let orbit = match (spec.v_inf, spec.eccentricity) {
        (Some(vi), None) => {
            let vi = v.field(&FlybySpec::V_INF, vi)?;
            KeplerOrbit::hyperbolic(gm, q, vi, spec.t_perigee, rotation)
                .map_err(|e| v.invalid("physics.flyby", e.to_string()))?
        }
        (None, Some(e)) => {
            if !(e.is_finite() && e >= 0.0 && e != 1.0) {
                return Err(v.invalid(
                    "physics.flyby.eccentricity",
                    format!("must be >= 0 and != 1 (parabolic orbits are not supported), got {e}"),
                ));
            }
            if gm <= 0.0 {
                return Err(v.invalid(
                    "physics.flyby.mass",
                    format!("must be > 0 kg with `eccentricity` (a massless planet has no orbit), got {mass}"),
                ));
            }
            KeplerOrbit::new(gm, q, e, spec.t_perigee, rotation)
                .map_err(|e| v.invalid("physics.flyby", e.to_string()))?
        }
        (vi, _) => return Err(v.exactly_one("physics.flyby", "v_inf", "eccentricity", vi.is_some())),
    };
    let j2 = match spec.j2 {
        None => None,
        Some(j2) => {
            if !j2.is_finite() {
                return Err(v.invalid("physics.flyby.j2", format!("must be finite, got {j2}")));
            }
            let Some(r) = radius else {
                return Err(v.invalid(
                    "physics.flyby.radius",
                    format!("is needed with j2 = {j2} (the reference radius of J2, m)"),
                ));
            };
            let pole = Vec3::from(spec.pole.unwrap_or([0.0, 0.0, 1.0]));
            if !(pole.iter().all(|x| x.is_finite()) && pole.norm() > 0.0) {
                return Err(v.invalid(
                    "physics.flyby.pole",
                    format!(
                        "must be a finite non-zero vector (the planet's spin axis), got {:?}",
                        spec.pole
                    ),
                ));
            }
            // J2 = 0 is a point mass: no term, so the run is bit-identical to one without `j2`.
            (j2 != 0.0).then(|| J2Field::new(gm, j2, r, pole))
        }
    };
    if spec.pole.is_some() && spec.j2.is_none() {
        return Err(v.invalid(
            "physics.flyby.pole",
            "is the planet's spin axis for `j2`; give `j2` too, or leave `pole` out".to_string(),
        ));
    }
    Ok(TideTerm { gm, radius, orbit, j2 })
}
