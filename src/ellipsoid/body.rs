//! A rigid triaxial ellipsoid: shape, mass, principal moments (Roig03 §2, Eq. 4) and its state.

use crate::math::{Vec3, Vec4};

/// Which principal moments of inertia a body gets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum InertiaModel {
    /// Roig03 Eq. 4 with the model's κ: `I = m/(2κ) diag(B²+C², C²+A², A²+B²)` (the paper's choice).
    /// For κ ≠ 5/2 this biases spins (Roig03 §4.3).
    #[default]
    Gaussian,
    /// The moments of a uniform-density ellipsoid, i.e. Eq. 4 with κ = 5/2, whatever the model's κ.
    Uniform,
}

impl InertiaModel {
    /// The κ that enters Eq. 4 for this model, given the model's κ.
    pub fn inertia_kappa(self, model_kappa: f64) -> f64 {
        match self {
            InertiaModel::Gaussian => model_kappa,
            InertiaModel::Uniform => 2.5,
        }
    }
}

/// Shape and mass of one fragment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ellipsoid {
    /// Semi-axes `(A, B, C)` with `A ≥ B ≥ C > 0` (m), along the body x, y, z axes.
    pub axes: Vec3,
    /// Mass (kg), > 0.
    pub mass: f64,
}

impl Ellipsoid {
    /// Volume `4/3 π A B C` (m³).
    pub fn volume(&self) -> f64 {
        4.0 / 3.0 * std::f64::consts::PI * self.axes.x * self.axes.y * self.axes.z
    }

    /// Equivalent radius `(A B C)^{1/3}` (m), used by Roig03 Eqs. 11–14 for ellipsoids.
    pub fn equivalent_radius(&self) -> f64 {
        (self.axes.x * self.axes.y * self.axes.z).cbrt()
    }

    /// Whether all three semi-axes are equal (then the contact potential ignores attitude).
    pub fn is_sphere(&self) -> bool {
        self.axes.x == self.axes.y && self.axes.y == self.axes.z
    }

    /// Principal moments (kg m²) from Roig03 Eq. 4 with the given κ:
    /// `m/(2κ) (B²+C², C²+A², A²+B²)`.
    ///
    /// ```
    /// use rubblepile::ellipsoid::body::Ellipsoid;
    /// use rubblepile::math::Vec3;
    /// let e = Ellipsoid { axes: Vec3::new(1.0, 1.0, 1.0), mass: 5.0 };
    /// // a uniform sphere: 2/5 m R² (κ = 5/2)
    /// assert!((e.principal_moments(2.5).x - 2.0).abs() < 1e-15);
    /// ```
    pub fn principal_moments(&self, kappa: f64) -> Vec3 {
        let (a2, b2, c2) = (self.axes.x.powi(2), self.axes.y.powi(2), self.axes.z.powi(2));
        self.mass / (2.0 * kappa) * Vec3::new(b2 + c2, c2 + a2, a2 + b2)
    }
}

/// One body: shape and initial dynamical state.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// Shape and mass.
    pub shape: Ellipsoid,
    /// Centre-of-mass position (m), world frame.
    pub position: Vec3,
    /// Centre-of-mass velocity (m/s), world frame.
    pub velocity: Vec3,
    /// Attitude quaternion `(α, β, γ, δ)`, scalar last, unit norm; `R(q)` (Roig03 Eq. 21) maps world to body.
    pub quaternion: Vec4,
    /// Spin about the principal (body) axes (rad/s).
    pub spin_body: Vec3,
}
