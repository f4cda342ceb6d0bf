//! Jacobi elliptic functions and elliptic integrals of the first kind, for the analytic torque-free top.
//!
//! Sources: M. Abramowitz & I. A. Stegun, *Handbook of Mathematical Functions* (1964), §16.4 (the
//! arithmetic–geometric mean / descending Landen scale for `sn, cn, dn`) and §17.6 (`K(m)` from the AGM);
//! B. C. Carlson, "Numerical computation of real or complex elliptic integrals", *Numer. Algorithms* 10
//! (1995) 13–26 (the symmetric integral `R_F` and its duplication algorithm). Independent implementations
//! written from those descriptions.
//!
//! The parameter is `m = k²` (A&S convention), `0 ≤ m ≤ 1`.

use std::f64::consts::PI;

/// Complete elliptic integral of the first kind `K(m) = ∫₀^{π/2} dθ / √(1 − m sin²θ)`, by the AGM:
/// `K(m) = π / (2 AGM(1, √(1 − m)))` (A&S 17.6). `+∞` at `m = 1`; NaN outside `[0, 1]`.
///
/// ```
/// use rubblepile::integrate::elliptic::complete_k;
/// assert!((complete_k(0.0) - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
/// assert!((complete_k(0.5) - 1.854_074_677_301_372).abs() < 1e-14);
/// ```
pub fn complete_k(m: f64) -> f64 {
    if !(0.0..=1.0).contains(&m) {
        return f64::NAN;
    }
    if m == 1.0 {
        return f64::INFINITY;
    }
    let (mut a, mut b) = (1.0, (1.0 - m).sqrt());
    for _ in 0..64 {
        if (a - b).abs() <= 2.0 * f64::EPSILON * a {
            break;
        }
        let a_next = 0.5 * (a + b);
        b = (a * b).sqrt();
        a = a_next;
    }
    PI / (a + b)
}

/// Carlson's symmetric integral `R_F(x, y, z) = ½ ∫₀^∞ dt / √((t+x)(t+y)(t+z))` for `x, y, z ≥ 0`, at most
/// one of them zero (duplication to `max |1 − x/A| < 10⁻³`, then the fifth-order series; relative error
/// below 10⁻¹⁶ in theory).
pub fn carlson_rf(x: f64, y: f64, z: f64) -> f64 {
    let (mut x, mut y, mut z) = (x, y, z);
    for _ in 0..100 {
        let a = (x + y + z) / 3.0;
        let (dx, dy, dz) = (1.0 - x / a, 1.0 - y / a, 1.0 - z / a);
        if dx.abs().max(dy.abs()).max(dz.abs()) < 1e-3 {
            let e2 = dx * dy - dz * dz;
            let e3 = dx * dy * dz;
            return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) / a.sqrt();
        }
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lambda = sx * sy + sy * sz + sz * sx;
        x = 0.25 * (x + lambda);
        y = 0.25 * (y + lambda);
        z = 0.25 * (z + lambda);
    }
    f64::NAN
}

/// Incomplete elliptic integral of the first kind `F(φ | m) = ∫₀^φ dθ / √(1 − m sin²θ)` for any real
/// amplitude `φ` (rad) and `0 ≤ m < 1`: `F(φ + nπ) = F(φ) + 2nK(m)`, and on `|φ| ≤ π/2`
/// `F = sin φ · R_F(cos²φ, 1 − m sin²φ, 1)` (Carlson 1995). It inverts the amplitude: `am(F(φ|m) | m) = φ`.
pub fn incomplete_f(phi: f64, m: f64) -> f64 {
    let n = (phi / PI).round();
    let r = phi - n * PI;
    let (s, c) = r.sin_cos();
    let base = s * carlson_rf(c * c, 1.0 - m * s * s, 1.0);
    if n == 0.0 { base } else { base + 2.0 * n * complete_k(m) }
}

/// Jacobi elliptic functions `(sn, cn, dn)(u | m)` for real `u` and `0 ≤ m ≤ 1`.
///
/// `u` is first reduced modulo the period `4K(m)` of `sn` and `cn` (`dn` has period `2K`); then the
/// descending Landen (AGM) scale of A&S 16.4: `a₀ = 1, b₀ = √(1−m), c₀ = √m`, `a_n = (a + b)/2`,
/// `b_n = √(a b)`, `c_n = (a − b)/2` until `c_N ≈ 0`; `φ_N = 2^N a_N u`,
/// `φ_{n−1} = ½ (φ_n + asin(c_n sin φ_n / a_n))`; `sn = sin φ₀`, `cn = cos φ₀`, `dn = √(1 − m sn²)`.
/// Limits: `m = 0` gives `(sin, cos, 1)`, `m = 1` gives `(tanh, sech, sech)`.
///
/// ```
/// use rubblepile::integrate::elliptic::{complete_k, jacobi_sn_cn_dn};
/// let (m, u) = (0.7, 0.9);
/// let (sn, cn, dn) = jacobi_sn_cn_dn(u, m);
/// assert!((sn * sn + cn * cn - 1.0).abs() < 1e-15);
/// assert!((dn * dn + m * sn * sn - 1.0).abs() < 1e-15);
/// let (s, c, _) = jacobi_sn_cn_dn(complete_k(m), m);
/// assert!((s - 1.0).abs() < 1e-15 && c.abs() < 1e-14);
/// ```
pub fn jacobi_sn_cn_dn(u: f64, m: f64) -> (f64, f64, f64) {
    if !(0.0..=1.0).contains(&m) || !u.is_finite() {
        return (f64::NAN, f64::NAN, f64::NAN);
    }
    if m == 0.0 {
        let (s, c) = u.sin_cos();
        return (s, c, 1.0);
    }
    if m == 1.0 {
        let sech = 1.0 / u.cosh();
        return (u.tanh(), sech, sech);
    }
    let period = 4.0 * complete_k(m);
    let u = u - period * (u / period).round();
    const LEVELS: usize = 32;
    let mut a = [0.0; LEVELS];
    let mut c = [0.0; LEVELS];
    a[0] = 1.0;
    c[0] = m.sqrt();
    let mut b = (1.0 - m).sqrt();
    let mut n = 0;
    while n + 1 < LEVELS && c[n].abs() > f64::EPSILON * a[n] {
        let (an, bn) = (a[n], b);
        a[n + 1] = 0.5 * (an + bn);
        c[n + 1] = 0.5 * (an - bn);
        b = (an * bn).sqrt();
        n += 1;
    }
    let mut phi = 2f64.powi(n as i32) * a[n] * u;
    for k in (1..=n).rev() {
        phi = 0.5 * (phi + (c[k] / a[k] * phi.sin()).asin());
    }
    let (sn, cn) = phi.sin_cos();
    (sn, cn, (1.0 - m * sn * sn).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_and_identities() {
        for &u in &[-7.3, -0.4, 0.0, 0.3, 1.1, 2.9, 25.0] {
            let (s, c, d) = jacobi_sn_cn_dn(u, 0.0);
            assert!((s - f64::sin(u)).abs() < 1e-15 && (c - f64::cos(u)).abs() < 1e-15 && d == 1.0);
            let (s, c, d) = jacobi_sn_cn_dn(u, 1.0);
            assert!((s - u.tanh()).abs() < 1e-15 && (c - 1.0 / u.cosh()).abs() < 1e-15 && c == d);
            for &m in &[1e-12, 0.1, 0.5, 0.9, 0.999] {
                let (s, c, d) = jacobi_sn_cn_dn(u, m);
                assert!((s * s + c * c - 1.0).abs() < 1e-14, "u {u} m {m}");
                assert!((d * d + m * s * s - 1.0).abs() < 1e-14, "u {u} m {m}");
                // d sn/du = cn dn (central difference).
                let h = 1e-5;
                let ds = (jacobi_sn_cn_dn(u + h, m).0 - jacobi_sn_cn_dn(u - h, m).0) / (2.0 * h);
                assert!((ds - c * d).abs() < 1e-9, "u {u} m {m}: {ds} vs {}", c * d);
                // Near m = 0 the functions approach sin and cos.
                if m < 1e-6 {
                    assert!((s - u.sin()).abs() < 1e-10);
                }
            }
        }
    }

    #[test]
    fn known_values() {
        // A&S Table 17.1: K(0.5) = 1.85407 46773 01371 92; K(0.9) = 2.57809 21133 48173 1.
        assert!((complete_k(0.5) - 1.854_074_677_301_372).abs() < 1e-14);
        assert!((complete_k(0.9) - 2.578_092_113_348_173).abs() < 1e-14);
        // F(π/2 | m) = K(m); F(φ + π) = F(φ) + 2K.
        for &m in &[0.0, 0.3, 0.8] {
            assert!((incomplete_f(PI / 2.0, m) - complete_k(m)).abs() < 1e-14);
            assert!((incomplete_f(0.4 + PI, m) - incomplete_f(0.4, m) - 2.0 * complete_k(m)).abs() < 1e-13);
        }
        // am(F(φ)) = φ.
        for &phi in &[-2.5, -0.3, 0.0, 0.7, 1.5, 3.0, 9.0] {
            for &m in &[0.2, 0.6, 0.95] {
                let (s, c, _) = jacobi_sn_cn_dn(incomplete_f(phi, m), m);
                let back = s.atan2(c);
                let diff = (back - phi).rem_euclid(2.0 * PI);
                assert!(diff.min(2.0 * PI - diff) < 1e-13, "phi {phi} m {m}: {back}");
            }
        }
        // sn(K/2 | m) = 1/√(1 + √(1−m)) (A&S 16.5.2).
        let m: f64 = 0.64;
        let s = jacobi_sn_cn_dn(0.5 * complete_k(m), m).0;
        assert!((s - 1.0 / (1.0 + (1.0 - m).sqrt()).sqrt()).abs() < 1e-15);
    }
}
