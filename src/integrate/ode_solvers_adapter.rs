//! skeleton
use super::*;
/// Adapter.
pub struct OdeSolversAdapter;
impl OdeSolversAdapter {
    /// New.
    pub fn new(_m: Method, _tol: Tolerances, _h0: Option<f64>) -> Result<Self, IntegrateError> { todo!() }
}
impl Integrator for OdeSolversAdapter {
    fn advance(&mut self, _s: &dyn OdeSystem, _t: &mut f64, _y: &mut [f64], _tt: f64) -> Result<(), IntegrateError> { todo!() }
    fn stats(&self) -> Stats { todo!() }
    fn method(&self) -> Method { Method::Dop853 }
}
