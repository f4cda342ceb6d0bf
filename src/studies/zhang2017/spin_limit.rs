//! The least friction angle with which a spinning self-gravitating ellipsoid can hold its shape, from its
//! volume-averaged stress (Holsapple 2001, Icarus 154, 432; 2004, Icarus 172, 272; the "global volume-averaging"
//! upper spin limit that Zhang17 §5.1.1 compares its T_c,3 with in Fig. 23).
//!
//! A homogeneous ellipsoid of semi-axes `a_x, a_y, a_z` and density ρ spinning at ω about z carries the body force
//! `ρ (ω² (x, y, 0) − 2πGρ (A_x x, A_y y, A_z z))`, with the gravitational shape coefficients
//! `A_i = a_x a_y a_z ∫₀^∞ du / ((a_i² + u) Δ(u))`, `Δ(u) = √((a_x² + u)(a_y² + u)(a_z² + u))`, `Σ A_i = 2`
//! (`2/3` each for a sphere). The virial theorem averages the stress over the volume to the principal values
//! `σ̄_i = ρ (ω² δ_i − 2πGρ A_i) a_i² / 5` (tension positive; `δ_i` = 1 for x, y and 0 for z). A cohesionless
//! Mohr–Coulomb material holds them when `sin φ ≥ (σ̄_max − σ̄_min) / −(σ̄_max + σ̄_min)` with every σ̄ compressive:
//! averaged over the whole body, no smaller friction angle can carry the spin. A sphere gives
//! `sin φ = q / (2 − q)`, `q = 3ω² / (4πGρ)`.

use rubblepile::io::scene_file::SI_G;

/// Carlson's symmetric integral of the second kind `R_D(x, y, z) = (3/2) ∫₀^∞ dt / ((t + z) √((t+x)(t+y)(t+z)))`
/// for `x, y ≥ 0` (not both 0) and `z > 0`, by the duplication theorem (B. C. Carlson, Numer. Algorithms 10
/// (1995) 13–26, Eq. 2.29 and its series), to about 1e-15 relative.
pub fn carlson_rd(x: f64, y: f64, z: f64) -> f64 {
    let (mut x, mut y, mut z) = (x, y, z);
    let (mut sum, mut weight) = (0.0, 1.0);
    for _ in 0..100 {
        let mean = (x + y + 3.0 * z) / 5.0;
        let spread = [(mean - x).abs(), (mean - y).abs(), (mean - z).abs()]
            .into_iter()
            .fold(0.0, f64::max)
            / mean;
        if spread < 1e-4 {
            // the series of Carlson's Eq. 2.29 in the normalised deviations, to fifth order
            let (dx, dy, dz) = ((mean - x) / mean, (mean - y) / mean, (mean - z) / mean);
            let e2 = dx * dy - 6.0 * dz * dz;
            let e3 = (3.0 * dx * dy - 8.0 * dz * dz) * dz;
            let e4 = 3.0 * (dx * dy - dz * dz) * dz * dz;
            let e5 = dx * dy * dz * dz * dz;
            let series =
                1.0 - 3.0 / 14.0 * e2 + e3 / 6.0 + 9.0 / 88.0 * e2 * e2 - 3.0 / 22.0 * e4 - 9.0 / 52.0 * e2 * e3
                    + 3.0 / 26.0 * e5;
            return 3.0 * sum + weight * series / (mean * mean.sqrt());
        }
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lambda = sx * sy + sx * sz + sy * sz;
        sum += weight / (sz * (z + lambda));
        weight *= 0.25;
        x = 0.25 * (x + lambda);
        y = 0.25 * (y + lambda);
        z = 0.25 * (z + lambda);
    }
    f64::NAN
}

/// The gravitational shape coefficients `A_x, A_y, A_z` of a homogeneous ellipsoid of semi-axes `axes` (any
/// length unit): `A_i = (2/3) a_x a_y a_z R_D(a_j², a_k², a_i²)` with j, k the other two axes.
pub fn gravity_coefficients(axes: [f64; 3]) -> [f64; 3] {
    let [a, b, c] = axes;
    let abc = a * b * c;
    let (a2, b2, c2) = (a * a, b * b, c * c);
    [
        2.0 / 3.0 * abc * carlson_rd(b2, c2, a2),
        2.0 / 3.0 * abc * carlson_rd(a2, c2, b2),
        2.0 / 3.0 * abc * carlson_rd(a2, b2, c2),
    ]
}

/// The volume-averaged principal stresses (Pa, tension positive) of a homogeneous ellipsoid of semi-axes `axes`
/// (m) and density `rho` (kg/m³) spinning about z with period `period_s` (s).
pub fn averaged_stress(axes: [f64; 3], rho: f64, period_s: f64) -> [f64; 3] {
    let omega2 = (std::f64::consts::TAU / period_s).powi(2);
    let coefficients = gravity_coefficients(axes);
    let spin = [omega2, omega2, 0.0];
    std::array::from_fn(|i| {
        rho * (spin[i] - std::f64::consts::TAU * SI_G * rho * coefficients[i]) * axes[i] * axes[i] / 5.0
    })
}

/// The least friction angle (degrees) with which a cohesionless body of this shape, density (kg/m³) and spin
/// period (s) is in equilibrium on volume average; `None` when a principal stress is tensile (no friction angle
/// holds it without cohesion).
pub fn least_friction_angle(axes: [f64; 3], rho: f64, period_s: f64) -> Option<f64> {
    let s = averaged_stress(axes, rho, period_s);
    let (max, min) = (
        s.iter().cloned().fold(f64::MIN, f64::max),
        s.iter().cloned().fold(f64::MAX, f64::min),
    );
    if max >= 0.0 {
        return None;
    }
    Some(((max - min) / -(max + min)).asin().to_degrees())
}

/// The spin at which the least friction angle reaches `phi_deg` (the continuum upper spin limit of Zhang17 Fig. 23)
/// as κ of Zhang17 Eq. 22, `Ω / √(4πGρ/3)`, for a body of the shape of `axes` (any scale; κ depends on neither the
/// size nor the density). A sphere gives `κ² = 2 sin φ / (1 + sin φ)`.
pub fn critical_kappa(axes: [f64; 3], phi_deg: f64) -> f64 {
    // at ρ = 1000 kg/m³; the angle grows with the spin until the stress turns tensile
    let rho = 1000.0;
    let unit = (4.0 * std::f64::consts::PI * SI_G * rho / 3.0).sqrt();
    let angle = |kappa: f64| least_friction_angle(axes, rho, std::f64::consts::TAU / (kappa * unit)).unwrap_or(90.0);
    let (mut lo, mut hi) = (0.0f64, 2.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid > 0.0 && angle(mid) < phi_deg {
            lo = mid
        } else {
            hi = mid
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Guards the shape coefficients: 2/3 each for a sphere, their sum 2 for any ellipsoid, the flattened axis
    /// pulled hardest; and the sphere's least friction angle in closed form.
    #[test]
    fn shape_coefficients_and_the_sphere_in_closed_form() {
        for a in gravity_coefficients([5.0; 3]) {
            assert!((a - 2.0 / 3.0).abs() < 1e-13, "{a}");
        }
        let c = gravity_coefficients([416.0, 419.0, 393.0]);
        assert!((c.iter().sum::<f64>() - 2.0).abs() < 1e-13, "{c:?}");
        assert!(c[2] > c[0] && c[0] > c[1], "{c:?}");
        // a prolate spheroid's end coefficient in closed form: e² = 1 − b²/a²,
        // A_a = (1 − e²)/e³ (ln((1 + e)/(1 − e)) − 2e)
        let (a, b) = (2.0f64, 1.0f64);
        let e = (1.0 - b * b / (a * a)).sqrt();
        let exact = (1.0 - e * e) / e.powi(3) * (((1.0 + e) / (1.0 - e)).ln() - 2.0 * e);
        assert!((gravity_coefficients([a, b, b])[0] - exact).abs() < 1e-12);
        for hours in [2.3, 2.6, 3.0, 5.0] {
            let rho = 2192.5;
            let q =
                3.0 * (std::f64::consts::TAU / (hours * 3600.0)).powi(2) / (4.0 * std::f64::consts::PI * SI_G * rho);
            let phi = least_friction_angle([390.0; 3], rho, hours * 3600.0).unwrap();
            assert!((phi - (q / (2.0 - q)).asin().to_degrees()).abs() < 1e-9, "{hours} h");
        }
        // spun past the point where the equator's averaged stress turns tensile: no cohesionless equilibrium
        assert_eq!(least_friction_angle([390.0; 3], 2100.0, 2.0 * 3600.0), None);
    }

    /// Guards the examples the docs quote: Carlson (1995) §3's check values of R_D, Zhang17's sphere at its HCP and
    /// RCP T_c3, and κ of a sphere in closed form.
    #[test]
    fn carlson_values_and_the_sphere_limits() {
        assert!((carlson_rd(0.0, 2.0, 1.0) - 1.797_210_352_103_4).abs() < 1e-12);
        assert!((carlson_rd(2.0, 3.0, 4.0) - 0.165_105_272_942_61).abs() < 1e-12);
        let sphere = [390.0; 3];
        assert!((least_friction_angle(sphere, 2100.0, 2.40 * 3600.0).unwrap() - 55.0).abs() < 0.1);
        assert!((least_friction_angle(sphere, 2100.0, 2.83 * 3600.0).unwrap() - 28.6).abs() < 0.1);
        let phi = 30f64.to_radians();
        assert!((critical_kappa([1.0; 3], 30.0) - (2.0 * phi.sin() / (1.0 + phi.sin())).sqrt()).abs() < 1e-9);
    }
}
