//! Our DOP853 (`src/integrate/dop853.rs`, whose unit tests check its tableau's order conditions): order 8 at a
//! fixed step, accuracy on problems with known solutions, agreement with the `ode_solvers` crate's Dop853 on the N30
//! impact, exact landing and continuation, bits independent of the thread count, exact checkpoint/resume, the step hooks, and failures
//! that leave the last good state.
//!
//! Run with `--nocapture` to see the measured errors and statistics.

use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

use rubblepile::impact::problems::WorkPrecisionProblem;
use rubblepile::integrate::dop853::{self, Dop853};
use rubblepile::integrate::ode_solvers_adapter::OdeSolversAdapter;
use rubblepile::integrate::problems::{Arenstorf, Kepler, TestProblem};
use rubblepile::integrate::{IntegrateError, Integrator, IntegratorState, Method, OdeSystem, Tolerances};

fn tol(rtol: f64, n: usize) -> Tolerances {
    Tolerances::uniform(rtol, rtol, n)
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

// ---------------------------------------------------------------------------------------------
// The method

/// Kepler e = 0.3 over one orbit at a fixed step `T/steps` (a tolerance too loose to reject, `h_max` = the step).
fn kepler_fixed_step_error(steps: u32) -> f64 {
    let k = Kepler::new(0.3);
    let t_end = k.period();
    let h = t_end / steps as f64;
    let mut d = Dop853::new(tol(1e6, 4), Some(h)).unwrap();
    d.set_h_max(h);
    let (mut t, mut y) = (0.0, k.initial_state());
    d.advance(&k, &mut t, &mut y, t_end).unwrap();
    let st = d.stats();
    assert_eq!(st.steps_rejected, 0);
    assert_eq!(st.steps_accepted, steps as u64, "{st:?}");
    // The derivative at the start, 11 stages per step, and FSAL's derivative after each step but the last.
    assert_eq!(st.rhs_evaluations, 1 + 11 * steps as u64 + (steps as u64 - 1), "{st:?}");
    max_abs_diff(&y, &k.exact(t_end).unwrap())
}

#[test]
fn order_eight_at_fixed_step() {
    // Measured: 2.3e-8, 1.5e-10, 6.9e-13 (observed orders 7.2 and 7.8, approaching 8 as h falls; at 192 steps
    // round-off takes over). A 7th-order tableau would stay at or below 7.
    let errors: Vec<f64> = [32, 64, 128].iter().map(|&s| kepler_fixed_step_error(s)).collect();
    let orders: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    eprintln!("fixed-step errors {errors:?}: observed orders {orders:?}");
    assert!(orders[0] > 7.0, "{orders:?} from {errors:?}");
    assert!((7.5..=8.5).contains(&orders[1]), "{orders:?} from {errors:?}");
    assert!(errors[2] < 2e-12, "{errors:?}");
}

#[test]
fn error_follows_rtol_on_kepler() {
    let k = Kepler::new(0.5).with_orbits(3.0);
    let t_end = k.t_end();
    let exact = k.exact(t_end).unwrap();
    let mut previous = f64::INFINITY;
    for &r in &[1e-6, 1e-8, 1e-10, 1e-12] {
        let mut d = Dop853::new(tol(r, 4), None).unwrap();
        let (mut t, mut y) = (0.0, k.initial_state());
        d.advance(&k, &mut t, &mut y, t_end).unwrap();
        let e = max_abs_diff(&y, &exact);
        eprintln!("kepler e = 0.5, 3 orbits, rtol {r:e}: error {e:.3e}, {:?}", d.stats());
        // Per-step control: the final error is a modest multiple of rtol and falls with it (by at least 10x per
        // 100x of rtol; DOP853's error is about proportional to rtol).
        assert!(e <= 1e4 * r, "rtol {r:e}: error {e:e}");
        assert!(e * 10.0 <= previous, "rtol {r:e}: error {e:e} after {previous:e}");
        previous = e;
    }
}

#[test]
fn arenstorf_and_kepler_at_rtol_1e_10() {
    let p = Arenstorf;
    let mut d = Dop853::new(tol(1e-10, 4), None).unwrap();
    let (mut t, mut y) = (0.0, p.initial_state());
    d.advance(&p, &mut t, &mut y, Arenstorf::PERIOD).unwrap();
    let e_arenstorf = max_abs_diff(&y, &p.exact(Arenstorf::PERIOD).unwrap());
    let st = d.stats();
    eprintln!("Arenstorf at 1e-10: return error {e_arenstorf:.3e}, {st:?}");
    let mut old = OdeSolversAdapter::new(Method::Dop853, tol(1e-10, 4), None).unwrap();
    let (mut t_old, mut y_old) = (0.0, p.initial_state());
    old.advance(&p, &mut t_old, &mut y_old, Arenstorf::PERIOD).unwrap();
    let e_old = max_abs_diff(&y_old, &p.exact(Arenstorf::PERIOD).unwrap());
    eprintln!(
        "ode_solvers' Dop853 at 1e-10: return error {e_old:.3e}, {:?}",
        old.stats()
    );
    // Measured 8.6e-7 (the crate's: the same, with the same 176 accepted and 61 rejected steps).
    assert!(e_arenstorf <= 2e-6, "{e_arenstorf:e}");
    assert!(e_arenstorf <= 2.0 * e_old, "{e_arenstorf:e} vs the crate's {e_old:e}");

    let k = Kepler::new(0.5).with_orbits(10.0);
    let exact = k.exact(k.t_end()).unwrap();
    let mut d = Dop853::new(tol(1e-10, 4), None).unwrap();
    let (mut t, mut y) = (0.0, k.initial_state());
    d.advance(&k, &mut t, &mut y, k.t_end()).unwrap();
    let e_kepler = max_abs_diff(&y, &exact);
    let energy = (k.energy(&y) + 0.5).abs() / 0.5;
    eprintln!(
        "Kepler e = 0.5, 10 orbits at 1e-10: error {e_kepler:.3e}, energy {energy:.3e}, {:?}",
        d.stats()
    );
    let mut old = OdeSolversAdapter::new(Method::Dop853, tol(1e-10, 4), None).unwrap();
    let (mut t_old, mut y_old) = (0.0, k.initial_state());
    old.advance(&k, &mut t_old, &mut y_old, k.t_end()).unwrap();
    let e_old = max_abs_diff(&y_old, &exact);
    eprintln!("ode_solvers' Dop853: error {e_old:.3e}, {:?}", old.stats());
    // Per-step control: the local errors of ten eccentric orbits add up and shear along the orbit (measured
    // 8.4e-7, the crate's about the same; the integrators tests allow 1e5 rtol), while the energy stays at 5e-9.
    assert!(e_kepler <= 1e-5, "{e_kepler:e}");
    assert!(e_kepler <= 2.0 * e_old, "{e_kepler:e} vs the crate's {e_old:e}");
    assert!(energy <= 2e-8, "{energy:e}");
}

/// The N30 impact (contact, gravity, dissipation; 435 components, scale-free tolerances) at rtol 1e-8 under ours
/// and the crate's Dop853: both end within their tolerance of a tight reference, and of each other.
#[test]
fn agrees_with_ode_solvers_dop853_on_the_n30_impact() {
    let problem = WorkPrecisionProblem::N30.setup();
    let system = &problem.system;
    let y0 = problem.initial_state();
    let run = |integ: &mut dyn Integrator| {
        let (mut t, mut y) = (0.0, y0.clone());
        integ.advance(system, &mut t, &mut y, problem.t_end).unwrap();
        assert_eq!(t, problem.t_end);
        y
    };
    let tolerances = |r: f64| Tolerances::scale_free(r, r, system);
    let reference = run(&mut Dop853::new(tolerances(1e-13), None).unwrap());
    let mut ours = Dop853::new(tolerances(1e-8), None).unwrap();
    let y_ours = run(&mut ours);
    let mut crate_dop = OdeSolversAdapter::new(Method::Dop853, tolerances(1e-8), None).unwrap();
    let y_crate = run(&mut crate_dop);
    let e_ours = problem.state_error(&y_ours, &reference);
    let e_crate = problem.state_error(&y_crate, &reference);
    let apart = problem.state_error(&y_ours, &y_crate);
    eprintln!(
        "N30 at rtol 1e-8: ours {e_ours:.3e} ({:?}), the crate's {e_crate:.3e} ({:?}), apart {apart:.3e}",
        ours.stats(),
        crate_dop.stats()
    );
    assert!(e_ours <= 1e-6, "ours: {e_ours:e}");
    assert!(e_crate <= 1e-6, "the crate's: {e_crate:e}");
    assert!(apart <= 1e-6, "ours and the crate's differ by {apart:e}");
    // The same method and control: the work is about the same.
    let (a, b) = (
        ours.stats().rhs_evaluations as f64,
        crate_dop.stats().rhs_evaluations as f64,
    );
    assert!(a <= 1.2 * b && b <= 1.2 * a, "RHS evaluations {a} vs {b}");
}

// ---------------------------------------------------------------------------------------------
// Landing and continuation

#[test]
fn lands_exactly_on_output_times_and_keeps_its_step() {
    let k = Kepler::new(0.3).with_orbits(3.0);
    let outputs = [
        0.1,
        0.1 + 1e-9,
        0.37,
        1.0 / 3.0 + 1.0,
        2.0,
        2.0 + f64::EPSILON * 4.0,
        5.123456789,
        7.0,
        k.t_end(),
    ];
    let mut many = Dop853::new(tol(1e-11, 4), None).unwrap();
    let (mut t, mut y) = (0.0, k.initial_state());
    for &to in &outputs {
        many.advance(&k, &mut t, &mut y, to).unwrap();
        assert_eq!(t.to_bits(), to.to_bits(), "landed on {t} instead of {to}");
    }
    let mut one = Dop853::new(tol(1e-11, 4), None).unwrap();
    let (mut t1, mut y1) = (0.0, k.initial_state());
    one.advance(&k, &mut t1, &mut y1, k.t_end()).unwrap();
    let d = max_abs_diff(&y, &y1);
    let (s_many, s_one) = (many.stats(), one.stats());
    eprintln!("successive vs one advance {d:.3e}; {s_many:?} vs {s_one:?}");
    assert!(d <= 1e-9, "successive advances differ by {d:e}");
    // The step control continues across calls: landing on eight more times costs about eight more steps and
    // their derivatives, not a restart of the control at each.
    assert!(
        s_many.steps_accepted <= s_one.steps_accepted + 2 * outputs.len() as u64,
        "{s_many:?} vs {s_one:?}"
    );
    // The tiny landings did not bring the proposal down.
    let h = many.proposed_step().unwrap();
    let h1 = one.proposed_step().unwrap();
    assert!(h > 0.1 * h1, "proposal {h} after the landings, {h1} after one call");
}

// ---------------------------------------------------------------------------------------------
// Parallel vector work

/// A ring of `n` anharmonic oscillators coupled to their neighbours (`2n` components, time-dependent forcing on
/// one: a slow sine and a sharp pulse), so that every component matters to the step control.
struct Ring {
    n: usize,
}

impl OdeSystem for Ring {
    fn dim(&self) -> usize {
        2 * self.n
    }
    fn rhs(&self, t: f64, y: &[f64], d: &mut [f64]) {
        let n = self.n;
        for i in 0..n {
            let (x, left, right) = (y[2 * i], y[2 * ((i + n - 1) % n)], y[2 * ((i + 1) % n)]);
            let w2 = 1.0 + (i % 7) as f64 * 0.3;
            d[2 * i] = y[2 * i + 1];
            d[2 * i + 1] = -w2 * x - x * x * x + 0.5 * (left - 2.0 * x + right);
        }
        // A pulse at t = 0.5 that the step control has to find (and rejects steps on).
        d[1] += (3.0 * t).sin() + 50.0 * (-((t - 0.5) / 0.02).powi(2)).exp();
    }
}

impl Ring {
    fn initial_state(&self) -> Vec<f64> {
        (0..2 * self.n)
            .map(|i| ((i as f64 * 0.618_033_988_7).fract() - 0.5) * if i % 2 == 0 { 1.0 } else { 0.3 })
            .collect()
    }
}

/// Runs the ring through three outputs on a pool of `threads` threads; `parallel_from` sets the path.
fn ring_run(
    ring: &Ring,
    threads: usize,
    parallel_from: usize,
) -> (Vec<f64>, rubblepile::integrate::Stats, IntegratorState) {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| {
        let mut d = Dop853::new(Tolerances::uniform(1e-7, 1e-9, ring.dim()), None).unwrap();
        d.set_parallel_from(parallel_from);
        let (mut t, mut y) = (0.0, ring.initial_state());
        for to in [0.3, 0.55, 1.0] {
            d.advance(ring, &mut t, &mut y, to).unwrap();
        }
        (y, d.stats(), d.save_state())
    })
}

#[test]
fn bits_do_not_depend_on_the_thread_count() {
    // 20 000 components: above the default threshold, so the vector work runs on the pool in 10 chunks.
    let ring = Ring { n: 10_000 };
    assert!(ring.dim() >= dop853::DEFAULT_PARALLEL_FROM);
    let (y1, s1, state1) = ring_run(&ring, 1, dop853::DEFAULT_PARALLEL_FROM);
    eprintln!("ring of 10 000: {s1:?}");
    assert!(s1.steps_accepted >= 10 && s1.steps_rejected >= 1, "{s1:?}");
    for threads in [2, 3, 4] {
        let (y, s, state) = ring_run(&ring, threads, dop853::DEFAULT_PARALLEL_FROM);
        assert_eq!(bits(&y), bits(&y1), "{threads} threads: final state");
        assert_eq!(s, s1, "{threads} threads: statistics");
        assert_eq!(state, state1, "{threads} threads: integrator state");
    }
    // The serial path sums in the same chunks: the same bits.
    let (y, s, _) = ring_run(&ring, 4, usize::MAX);
    assert_eq!(bits(&y), bits(&y1), "serial path");
    assert_eq!(s, s1, "serial path");
}

// ---------------------------------------------------------------------------------------------
// Checkpoints

#[test]
fn state_restores_bit_identically_mid_run() {
    // A state on the parallel path, saved after two of five outputs, round-tripped through JSON.
    let ring = Ring { n: 9_000 };
    let outputs = [0.2, 0.45, 0.7, 0.71, 1.2];
    let make = || {
        let mut d = Dop853::new(Tolerances::uniform(1e-7, 1e-9, ring.dim()), None).unwrap();
        d.set_max_steps(100_000);
        d
    };
    let mut whole = make();
    let (mut t, mut y) = (0.0, ring.initial_state());
    for &to in &outputs {
        whole.advance(&ring, &mut t, &mut y, to).unwrap();
    }
    let mut part = make();
    let (mut t2, mut y2) = (0.0, ring.initial_state());
    for &to in &outputs[..2] {
        part.advance(&ring, &mut t2, &mut y2, to).unwrap();
    }
    let json = serde_json::to_string(&part.save_state()).unwrap();
    drop(part);
    let state: IntegratorState = serde_json::from_str(&json).unwrap();
    assert_eq!(state.method(), Method::Dop853);
    let mut resumed = make();
    resumed.restore_state(&state).unwrap();
    assert_eq!(resumed.save_state(), state);
    for &to in &outputs[2..] {
        resumed.advance(&ring, &mut t2, &mut y2, to).unwrap();
    }
    assert_eq!(bits(&y2), bits(&y), "final state");
    assert_eq!(resumed.stats(), whole.stats());
    assert_eq!(resumed.save_state(), whole.save_state());
    assert!(
        whole.stats().steps_rejected > 0,
        "no rejection exercised: {:?}",
        whole.stats()
    );
}

#[test]
fn foreign_and_old_states_are_refused() {
    let mut d = Dop853::new(tol(1e-9, 4), None).unwrap();
    // A checkpoint written when "dop853" ran the ode_solvers crate.
    let old = OdeSolversAdapter::new(Method::Dop853, tol(1e-9, 4), None)
        .unwrap()
        .save_state();
    assert_eq!(old.method(), Method::Dop853);
    let err = d.restore_state(&old).unwrap_err().to_string();
    assert!(err.contains("ode_solvers") && err.contains("re-run"), "{err}");
    let dopri = OdeSolversAdapter::new(Method::Dopri5, tol(1e-9, 4), None)
        .unwrap()
        .save_state();
    assert!(d.restore_state(&dopri).is_err());
    let other_dim = Dop853::new(tol(1e-9, 3), None).unwrap().save_state();
    assert!(d.restore_state(&other_dim).is_err());
    let mut bs = rubblepile::integrate::bulirsch_stoer::BulirschStoer::new(tol(1e-9, 4), None).unwrap();
    assert!(bs.restore_state(&d.save_state()).is_err());
}

// ---------------------------------------------------------------------------------------------
// Step hooks

/// Kepler, recording the step hooks: the time of the state the current step started from (`None` outside an
/// advance), and counts.
struct Hooked {
    inner: Kepler,
    step_start: Mutex<Option<f64>>,
    begins: AtomicU64,
    ends: AtomicU64,
    outside: AtomicU64,
}

impl OdeSystem for Hooked {
    fn dim(&self) -> usize {
        4
    }
    fn rhs(&self, t: f64, y: &[f64], d: &mut [f64]) {
        match *self.step_start.lock().unwrap() {
            Some(t0) => assert!(t >= t0, "evaluation at {t} before its step's start {t0}"),
            None => {
                self.outside.fetch_add(1, Ordering::Relaxed);
            }
        }
        self.inner.rhs(t, y, d)
    }
    fn begin_step(&self, t: f64, _y: &[f64]) {
        self.begins.fetch_add(1, Ordering::Relaxed);
        *self.step_start.lock().unwrap() = Some(t);
    }
    fn end_steps(&self) {
        self.ends.fetch_add(1, Ordering::Relaxed);
        *self.step_start.lock().unwrap() = None;
    }
}

#[test]
fn begin_step_at_every_step_and_end_steps_at_every_return() {
    let sys = Hooked {
        inner: Kepler::new(0.5),
        step_start: Mutex::new(None),
        begins: AtomicU64::new(0),
        ends: AtomicU64::new(0),
        outside: AtomicU64::new(0),
    };
    let mut d = Dop853::new(tol(1e-9, 4), None).unwrap();
    let (mut t, mut y) = (0.0, sys.inner.initial_state());
    let outputs = [1.0, 2.5, 6.0];
    for &to in &outputs {
        d.advance(&sys, &mut t, &mut y, to).unwrap();
        assert!(sys.step_start.lock().unwrap().is_none(), "lists dropped after the call");
    }
    let st = d.stats();
    eprintln!("{st:?}");
    assert!(st.steps_rejected > 0, "{st:?}");
    assert_eq!(sys.outside.load(Ordering::Relaxed), 0, "every evaluation within a step");
    // Once per state steps start from: each call's start and each accepted state but the call's last.
    assert_eq!(sys.begins.load(Ordering::Relaxed), st.steps_accepted);
    assert_eq!(sys.ends.load(Ordering::Relaxed), outputs.len() as u64);
}

// ---------------------------------------------------------------------------------------------
// Failures

/// `y_i' = 1` for `t ≤ 1`; component `bad` turns NaN after `t = 1`.
struct NanAfterOne {
    n: usize,
    bad: usize,
}

impl OdeSystem for NanAfterOne {
    fn dim(&self) -> usize {
        self.n
    }
    fn rhs(&self, t: f64, _y: &[f64], d: &mut [f64]) {
        d.fill(1.0);
        if t > 1.0 {
            d[self.bad] = f64::NAN;
        }
    }
}

#[test]
fn non_finite_stage_leaves_the_last_good_state() {
    // One component on the serial path, and one component among 20 000 on the parallel path.
    for sys in [NanAfterOne { n: 1, bad: 0 }, NanAfterOne { n: 20_000, bad: 12_345 }] {
        let mut d = Dop853::new(tol(1e-10, sys.n), None).unwrap();
        let (mut t, mut y) = (0.0, vec![0.0; sys.n]);
        let r = d.advance(&sys, &mut t, &mut y, 2.0);
        eprintln!("n = {}: {r:?} at t = {t}, {:?}", sys.n, d.stats());
        match r {
            Err(IntegrateError::NonFinite { t: te }) => assert_eq!(te, t),
            other => panic!("expected NonFinite, got {other:?}"),
        }
        assert!(t <= 1.0 && t > 0.5, "t = {t}");
        assert!(
            y.iter().all(|&v| (v - t).abs() <= 1e-12),
            "state is not the one at t = {t}"
        );
    }
}

/// `y' = y²`, `y(0) = 1`: blows up at t = 1.
struct BlowUp;
impl OdeSystem for BlowUp {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, _t: f64, y: &[f64], d: &mut [f64]) {
        d[0] = y[0] * y[0];
    }
}

#[test]
fn blow_up_underflows_at_the_last_good_state() {
    let mut d = Dop853::new(tol(1e-12, 1), None).unwrap();
    let (mut t, mut y) = (0.0, vec![1.0]);
    let r = d.advance(&BlowUp, &mut t, &mut y, 2.0);
    eprintln!("{r:?} at t = {t}, y = {y:?}, {:?}", d.stats());
    match r {
        Err(IntegrateError::StepUnderflow { t: te, h }) => {
            assert_eq!(te, t);
            assert!(h.abs() < 10.0 * f64::EPSILON * t.abs(), "h = {h:e}");
        }
        Err(IntegrateError::NonFinite { t: te }) => assert_eq!(te, t),
        other => panic!("expected StepUnderflow, got {other:?}"),
    }
    assert!(t > 0.999 && t < 1.0 + 1e-9, "t = {t}");
    // The state is the accepted one at t: 1/(1 − t) to the integration's accuracy.
    assert!(y[0].is_finite() && y[0] > 1e8, "y = {}", y[0]);
    assert!((1.0 / y[0] - (1.0 - t)).abs() < 1e-9, "y = {} at t = {t}", y[0]);
}

#[test]
fn too_many_steps_keeps_the_last_accepted_state() {
    let mut d = Dop853::new(tol(1e-10, 4), None).unwrap();
    d.set_max_steps(5);
    let (mut t, mut y) = (0.0, Arenstorf.initial_state());
    match d.advance(&Arenstorf, &mut t, &mut y, Arenstorf::PERIOD) {
        Err(IntegrateError::TooManySteps { t: te, max_steps: 5 }) => assert_eq!(te, t),
        other => panic!("expected TooManySteps, got {other:?}"),
    }
    assert!(t > 0.0 && t < 1.0);
    // Continuing from there reaches the same state as one uninterrupted call would, to the tolerance.
    d.set_max_steps(100_000);
    d.advance(&Arenstorf, &mut t, &mut y, Arenstorf::PERIOD).unwrap();
    assert!(max_abs_diff(&y, &Arenstorf.initial_state()) < 1e-5);
}
