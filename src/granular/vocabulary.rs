//! The one vocabulary of the two granular scene files (`kind = "soft-spheres"`, Zhang17; `kind = "hard-spheres"`,
//! Richardson11): what both call by the same name, in SI units, and the pieces both parsers share — the wall
//! oscillation's schema ([`OscillationSpec`]), its check ([`oscillation`]) and its rows of the field reference.
//!
//! | concept                          | key                                                   | unit        |
//! |----------------------------------|-------------------------------------------------------|-------------|
//! | time step                        | `[stepping] dt`                                       | s           |
//! | contact material                 | `[material]` (`eps_n`, `eps_t`, soft: `k_n`, `mu_*`…) | SI per key  |
//! | uniform gravity                  | `[gravity] uniform = [gx, gy, gz]`                    | m/s²        |
//! | wall                             | `[[wall]]`, its shape `kind`                          | text        |
//! | a point of a plane               | `wall.point`                                          | m           |
//! | plane normal                     | `wall.normal`                                         | − (unit)    |
//! | centre (sphere, cylinder, disk…) | `wall.centre`                                         | m           |
//! | axis (cylinder, disk, ring, line)| `wall.axis`                                           | − (unit)    |
//! | radius, length                   | `wall.radius`, `wall.length` (absent = infinite)      | m           |
//! | translation                      | `wall.velocity` (hard)                                | m/s         |
//! | oscillation                      | `wall.oscillation = { amplitude, angular_frequency, phase, direction }` | m, rad/s, rad, − |
//! | spin about the axis              | `wall.spin`                                           | rad/s       |
//!
//! The oscillation displaces the wall by `A (sin(ω t + φ) − sin φ) d̂` (`geometry::walls::motion`), so it is
//! where its keys put it at t = 0 whatever the phase. Old names are still read (`granular::migrate`).

use serde::{Deserialize, Serialize};

use crate::geometry::walls::motion::Oscillation;
use crate::io::scene_file::{SceneError, Validator, exact};
use crate::math::Vec3;
use scene_derive::SceneFields;

/// The `scene.kind` of a soft-sphere scene (`granular::soft::scene`).
pub const SOFT_KIND: &str = "soft-spheres";

/// The `scene.kind` of a hard-sphere scene (`granular::hard::scene`).
pub const HARD_KIND: &str = "hard-spheres";

/// `wall.oscillation`: `A (sin(ω t + φ) − sin φ) d̂` added to the wall's position.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "wall.oscillation")]
#[serde(deny_unknown_fields)]
pub struct OscillationSpec {
    /// amplitude A
    #[field(unit = "m", default = "required", range = Rule("0 or >= 1e-300, finite"))]
    pub amplitude: f64,
    /// angular frequency omega = 2 pi f
    #[field(unit = "rad/s", default = "required", range = Rule("finite, A omega finite"))]
    pub angular_frequency: f64,
    /// phase phi
    #[serde(default)]
    #[field(unit = "rad", default = "0", range = Rule("finite"))]
    pub phase: f64,
    /// direction of the oscillation (normalised)
    #[serde(default, deserialize_with = "exact::option", skip_serializing_if = "Option::is_none")]
    #[field(unit = "-", default = "normal or axis, else required", range = Rule("3 finite numbers, non-zero"))]
    pub direction: Option<[f64; 3]>,
}

/// The oscillation of `wall` (`wall[k]`, for messages) checked: the amplitude a size or zero, `ω` and `φ` finite, the
/// wall speed `A ω` finite, the direction a non-zero vector (normalised) or, absent, `default_direction` (a wall
/// without an axis has none: the direction is then required).
pub(crate) fn oscillation(
    v: &Validator,
    wall: &str,
    spec: &OscillationSpec,
    default_direction: Option<Vec3>,
) -> Result<Oscillation, SceneError> {
    let f = |key: &str| format!("{wall}.oscillation.{key}");
    let amplitude = v.size_or_zero(&f("amplitude"), spec.amplitude)?;
    let omega = spec.angular_frequency;
    // The wall's speed A ω must be finite too: the contacts take it as the surface velocity.
    if !(omega.is_finite() && (amplitude * omega).is_finite()) {
        return Err(v.invalid(
            f("angular_frequency"),
            format!("must be finite (rad/s) with a finite wall speed amplitude x angular_frequency, got {omega:e} (amplitude {amplitude:e} m)"),
        ));
    }
    if !spec.phase.is_finite() {
        return Err(v.invalid(f("phase"), format!("must be finite (rad), got {}", spec.phase)));
    }
    let direction = match (spec.direction, default_direction) {
        (Some(d), _) => unit(v, &f("direction"), d)?,
        (None, Some(d)) => d,
        (None, None) => {
            return Err(v.invalid(
                f("direction"),
                "missing (required: this wall has no normal or axis to default to)",
            ));
        }
    };
    Ok(Oscillation {
        amplitude,
        omega,
        phase: spec.phase,
        direction,
    })
}

/// The field `field`'s vector `x`: three finite numbers.
pub(crate) fn vector(v: &Validator, field: &str, x: [f64; 3]) -> Result<Vec3, SceneError> {
    if x.iter().all(|c| c.is_finite()) {
        Ok(Vec3::from(x))
    } else {
        Err(v.invalid(field, format!("must be finite, got {x:?}")))
    }
}

/// The field `field`'s vector `x` normalised: three finite numbers, not all zero (a wall's normal, axis or
/// direction).
pub(crate) fn unit(v: &Validator, field: &str, x: [f64; 3]) -> Result<Vec3, SceneError> {
    let y = vector(v, field, x)?;
    if y.norm() > 0.0 {
        Ok(y.normalize())
    } else {
        Err(v.invalid(field, format!("must be a non-zero vector, got {x:?}")))
    }
}

/// `N / 100` as the serde default of a scene field: correctly rounded, so the same `f64` as the literal.
pub(crate) fn hundredths<const N: u32>() -> f64 {
    f64::from(N) / 100.0
}

/// Refuses a sphere whose moment of inertia `2/5 m r²` is not a normal number (the collisions divide by it): a
/// radius (`radius_fault`, its powers underflow) or a mass so small that it underflows. `f` names a key of the sphere.
pub(crate) fn check_inertia(
    v: &Validator,
    f: &dyn Fn(&str) -> String,
    mass: f64,
    radius: f64,
    radius_fault: bool,
) -> Result<(), SceneError> {
    let inertia = 0.4 * mass * radius * radius;
    if !(inertia.is_finite() && inertia >= f64::MIN_POSITIVE) {
        return Err(v.invalid(
            f(if radius_fault { "radius" } else { "mass" }),
            format!(
                "gives a moment of inertia 2/5 m r^2 = {inertia:e} kg m^2, not a finite normal number (mass {mass:e} \
                 kg, radius {radius:e} m)"
            ),
        ));
    }
    Ok(())
}

/// Refuses a uniform field of size `g` (m/s²) that gives a sphere `(mass, position)` a non-finite potential energy
/// `m |g| |x|` or kick `|g| dt` at t = 0, naming the largest factor.
pub(crate) fn check_uniform_gravity(
    v: &Validator,
    g: f64,
    spheres: impl Iterator<Item = (f64, Vec3)>,
    dt: f64,
) -> Result<(), SceneError> {
    for (k, (m, position)) in spheres.enumerate() {
        let x = position.norm();
        if !(m * g * x).is_finite() || !(g * dt).is_finite() {
            let field = match crate::io::scene_file::largest_factor(&[("m", m), ("g", g), ("x", x)]) {
                "m" => format!("particle[{k}].mass"),
                "x" => format!("particle[{k}].position"),
                _ => "gravity.uniform".to_string(),
            };
            return Err(v.invalid(
                field,
                format!(
                    "gives particle[{k}] a non-finite potential energy m |g| |x| or velocity kick |g| dt at t = 0 \
                     (m = {m:e} kg, |g| = {g:e} m/s^2, |x| = {x:e} m, dt = {dt:e} s)"
                ),
            ));
        }
    }
    Ok(())
}

/// Refuses a start where two spheres (`skip` excepted) overlap by more than `max` of the smaller radius; `limit`
/// ends the message with the rule broken.
pub(crate) fn check_start_overlaps(
    v: &Validator,
    centres: &[Vec3],
    radii: &[f64],
    max: f64,
    skip: impl Fn(usize, usize) -> bool,
    limit: &str,
) -> Result<(), SceneError> {
    for (i, j) in crate::geometry::neighbours::sphere_pairs(centres, radii) {
        if skip(i, j) {
            continue;
        }
        let overlap = radii[i] + radii[j] - (centres[j] - centres[i]).norm();
        let fraction = overlap / radii[i].min(radii[j]);
        if fraction > max {
            return Err(v.invalid(
                format!("particle[{i}].position"),
                format!(
                    "overlaps particle[{j}] by {overlap} m = {fraction:.4} of the smaller radius at the start{limit}"
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn hundredths_are_the_literals() {
        use super::hundredths;
        let got = [
            hundredths::<1>(),
            hundredths::<5>(),
            hundredths::<10>(),
            hundredths::<50>(),
            hundredths::<55>(),
        ];
        assert_eq!(got, [0.01, 0.05, 0.1, 0.5, 0.55]);
        assert_eq!(
            [hundredths::<100>(), hundredths::<105>(), hundredths::<130>()],
            [1.0, 1.05, 1.3]
        );
    }
}
