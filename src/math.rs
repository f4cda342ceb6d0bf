//! Fixed-size linear-algebra aliases used throughout the crate (in the style of parry's `math` module).
//!
//! Everything is `f64` and SI: metres, kilograms, seconds, radians.

/// A 3-vector (position m, velocity m/s, spin rad/s, force N …).
pub type Vec3 = nalgebra::Vector3<f64>;
/// A 4-vector; used for quaternions stored as `(α, β, γ, δ)` = vector part first, scalar last (Roig03 Eq. 19).
pub type Vec4 = nalgebra::Vector4<f64>;
/// A 3×3 matrix (rotation, inertia tensor, covariance …).
pub type Mat3 = nalgebra::Matrix3<f64>;
/// A 4×4 matrix (the quaternion mass matrix `M`, `W(q)` of Roig03 Eq. 24 …).
pub type Mat4 = nalgebra::Matrix4<f64>;

/// Median of `values` (the mean of the two middle values for an even count); NaN for an empty slice.
///
/// ```
/// assert_eq!(rubblepile::math::median(&[3.0, 1.0, 2.0]), 2.0);
/// assert_eq!(rubblepile::math::median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
/// assert!(rubblepile::math::median(&[]).is_nan());
/// ```
pub fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Arithmetic mean (NaN for no values).
pub fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len() as f64
}

/// Mean and sample standard deviation (0 for one value).
pub fn mean_std(values: &[f64]) -> (f64, f64) {
    let m = mean(values);
    if values.len() < 2 {
        return (m, 0.0);
    }
    let var = values.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (values.len() - 1) as f64;
    (m, var.sqrt())
}

/// The bytes a vector's buffer holds: its capacity times the element size (heap memory the elements own
/// themselves is not counted).
pub fn vec_bytes<T>(v: &Vec<T>) -> usize {
    v.capacity() * std::mem::size_of::<T>()
}
