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

/// The skew-symmetric cross-product matrix `[v]×`, so that `[v]× x = v × x`.
pub fn skew(v: &Vec3) -> Mat3 {
    Mat3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}
