//! Compensated (Kahan) summation of accepted step increments across steps and `advance` calls, shared by the
//! extrapolation methods (`bulirsch_stoer.rs`, `linearly_implicit.rs`): each step adds a small increment to a
//! large state, and the bits rounded away are carried into the next step instead of lost, so long runs at tight
//! tolerances do not drift by rounding alone.

/// What was rounded away from each component, and the state the last `advance` returned (to tell whether the
/// caller passes back that same state, whose carried bits still belong to it).
#[derive(Debug, Clone, Default)]
pub struct Compensation {
    /// Per component, what the compensated sum has not yet added to the state.
    pub carry: Vec<f64>,
    /// The state at the end of the last `advance`, if any.
    last_output: Option<Vec<f64>>,
}

impl Compensation {
    /// Before an `advance` from state `y`: a new state from the caller (or a new dimension) starts with nothing
    /// carried, since what was rounded away belonged to another state.
    pub fn begin(&mut self, y: &[f64]) {
        let n = y.len();
        if self.carry.len() != n || self.last_output.as_ref().is_some_and(|prev| prev.as_slice() != y) {
            self.carry.clear();
            self.carry.resize(n, 0.0);
        }
    }

    /// After an `advance`: remembers the state it returned.
    pub fn end(&mut self, y: &[f64]) {
        match &mut self.last_output {
            Some(prev) if prev.len() == y.len() => prev.copy_from_slice(y),
            slot => *slot = Some(y.to_vec()),
        }
    }

    /// `y += increment`, compensated.
    pub fn add(&mut self, y: &mut [f64], increment: &[f64]) {
        for ((yi, &d), c) in y.iter_mut().zip(increment).zip(self.carry.iter_mut()) {
            let inc = d + *c;
            let sum = *yi + inc;
            *c = inc - (sum - *yi);
            *yi = sum;
        }
    }

    /// Forgets the last output (after a restored checkpoint, whose state the caller sets).
    pub fn forget_output(&mut self) {
        self.last_output = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_increments_are_not_lost_to_rounding() {
        let mut c = Compensation::default();
        let mut y = vec![1.0];
        c.begin(&y);
        for _ in 0..1000 {
            c.add(&mut y, &[1e-17]);
        }
        // plain summation would leave 1.0: each 1e-17 is below half an ulp of 1
        assert!((y[0] - (1.0 + 1e-14)).abs() < 2e-16, "{}", y[0]);
        c.end(&y);
        // the same state passed back keeps its carry; another state drops it
        let carried = c.carry.clone();
        c.begin(&y);
        assert_eq!(c.carry, carried);
        c.begin(&[2.0]);
        assert_eq!(c.carry, vec![0.0]);
    }
}
