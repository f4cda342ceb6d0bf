//! Whether two ellipsoids overlap: the Perram–Wertheim contact function
//! (Perram & Wertheim 1985, J. Comput. Phys. 58, 409).
//!
//! For ellipsoids with world shape matrices `Σ = Rᵀ diag(A², B², C²) R` (the same `Σ` as the contact
//! potential) and centre offset `Δ`, `F(λ) = λ(1−λ) Δᵀ [(1−λ) Σ_i + λ Σ_j]⁻¹ Δ` is concave on `[0, 1]`;
//! its maximum is < 1 when the ellipsoids overlap, = 1 when they touch and > 1 when they are apart.

use crate::math::{Mat3, Vec3};

/// `max_λ F(λ)` by golden-section search (60 iterations: λ to ~1e-12).
pub fn contact_function(delta: &Vec3, sigma_i: &Mat3, sigma_j: &Mat3) -> f64 {
    let f = |l: f64| {
        let m = (1.0 - l) * sigma_i + l * sigma_j;
        match m.try_inverse() {
            Some(inv) => l * (1.0 - l) * delta.dot(&(inv * delta)),
            None => 0.0,
        }
    };
    let phi = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (0.0, 1.0);
    let (mut x1, mut x2) = (b - phi * (b - a), a + phi * (b - a));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..60 {
        if f1 < f2 {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + phi * (b - a);
            f2 = f(x2);
        } else {
            b = x2;
            x2 = x1;
            f2 = f1;
            x1 = b - phi * (b - a);
            f1 = f(x1);
        }
    }
    f1.max(f2)
}

/// Whether the ellipsoids are strictly apart (`max F > 1`).
///
/// ```
/// use rubblepile::geometry::ellipsoid_overlap::are_apart;
/// use rubblepile::math::{Mat3, Vec3};
/// let unit = Mat3::identity(); // unit spheres
/// assert!(are_apart(&Vec3::new(2.1, 0.0, 0.0), &unit, &unit));
/// assert!(!are_apart(&Vec3::new(1.9, 0.0, 0.0), &unit, &unit));
/// ```
pub fn are_apart(delta: &Vec3, sigma_i: &Mat3, sigma_j: &Mat3) -> bool {
    contact_function(delta, sigma_i, sigma_j) > 1.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two spheres: `max F = d²/(R_i + R_j)²`, so the test is exact at the touching distance.
    #[test]
    fn spheres_touch_at_sum_of_radii() {
        let (ri, rj) = (2.0, 0.5);
        let (si, sj) = (Mat3::identity() * ri * ri, Mat3::identity() * rj * rj);
        for d in [1.0, 2.4, 2.5, 2.6, 7.0] {
            let f = contact_function(&Vec3::new(0.0, d, 0.0), &si, &sj);
            assert!((f - (d / (ri + rj)).powi(2)).abs() < 1e-10, "d = {d}: F = {f}");
        }
    }

    /// Axis-aligned ellipsoids along x touch at `A_i + A_j`; along y at `B_i + B_j`.
    #[test]
    fn aligned_ellipsoids_touch_at_sum_of_semi_axes() {
        let si = Mat3::from_diagonal(&Vec3::new(9.0, 4.0, 1.0));
        let sj = Mat3::from_diagonal(&Vec3::new(4.0, 1.0, 0.25));
        assert!(!are_apart(&Vec3::new(4.99, 0.0, 0.0), &si, &sj));
        assert!(are_apart(&Vec3::new(5.01, 0.0, 0.0), &si, &sj));
        assert!(!are_apart(&Vec3::new(0.0, 2.99, 0.0), &si, &sj));
        assert!(are_apart(&Vec3::new(0.0, 3.01, 0.0), &si, &sj));
    }
}
