//! κ and U0 (Roig03 Eqs. 11–14). Skeleton.

/// Why κ could not be calibrated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CalibrationError {
    /// Eq. 14 has no root with κ > 3/2 for the given β and v.
    #[error("model.calibrate: no kappa > 3/2 solves Roig03 Eq. 14 for beta = {beta}, v = {v} m/s; need v^2 > {v2_min:e} m^2/s^2 (raise v or beta)")]
    Unreachable {
        /// β given.
        beta: f64,
        /// v given (m/s).
        v: f64,
        /// Minimum v² (m²/s²) for κ > 3/2 at this β.
        v2_min: f64,
    },
}

/// Solves Roig03 Eq. 14 for κ: `exp(κλ)/(κλ) = β v² (R_k + R_l)/(G m_k)`, where `k` is the smallest
/// (equivalent radius `r_small`, mass `m_small`) and `l` the largest body (`r_large`).
pub fn calibrate_kappa(
    _beta: f64,
    _v: f64,
    _r_small: f64,
    _m_small: f64,
    _r_large: f64,
    _g: f64,
) -> Result<f64, CalibrationError> {
    todo!()
}
