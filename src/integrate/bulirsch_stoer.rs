//! skeleton
use super::*;
/// Adaptive Bulirsch–Stoer.
pub struct BulirschStoer;
impl BulirschStoer {
    /// New.
    pub fn new(_tol: Tolerances, _h0: Option<f64>) -> Result<Self, IntegrateError> { todo!() }
}
impl Integrator for BulirschStoer {
    fn advance(&mut self, _s: &dyn OdeSystem, _t: &mut f64, _y: &mut [f64], _tt: f64) -> Result<(), IntegrateError> { todo!() }
    fn stats(&self) -> Stats { todo!() }
    fn method(&self) -> Method { Method::BulirschStoer }
}
