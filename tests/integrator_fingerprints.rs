//! Fingerprints of every integrator: each method (bulirsch-stoer, dop853, bulirsch-stoer-implicit, dopri5, rk4, and
//! the `ode_solvers` crate's Dop853) run on the canonical problems of `integrate::problems` through a sequence of
//! output times, backwards, across a saved and restored checkpoint state, into its step budget, a past deadline, a
//! step underflow and a right-hand side that turns non-finite, written as exact floats (`{:e}` round-trips) with the
//! statistics, the rejections by cause, the system's step hooks and the saved states, and compared byte for byte
//! with `tests/data/integrator_fingerprints.txt`. A change that should not change any result (a refactoring of the
//! step loop) must leave this file as it is.
//!
//! To re-record after an intended change of the results: `RUBBLEPILE_BLESS_FINGERPRINTS=1 cargo test --release
//! --test integrator_fingerprints`, then review the diff before committing it.

use std::fmt::Write as _;
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};

use rubblepile::integrate::bulirsch_stoer::BulirschStoer;
use rubblepile::integrate::dop853::Dop853;
use rubblepile::integrate::linearly_implicit::LinearlyImplicit;
use rubblepile::integrate::ode_solvers_adapter::OdeSolversAdapter;
use rubblepile::integrate::problems::{
    Arenstorf, ExponentialDecay, HarmonicOscillator, Kepler, RigidBody, StiffDampedOscillator, TestProblem,
};
use rubblepile::integrate::{
    IntegrateError, Integrator, IntegratorState, Method, OdeSystem, StiffSolve, Tolerances, make_integrator,
};

const EXPECTED: &str = "tests/data/integrator_fingerprints.txt";

/// Exact text of a float (`{:e}` is the shortest string that reads back to the same bits).
fn f(x: f64) -> String {
    format!("{x:e}")
}

fn fs(v: &[f64]) -> String {
    v.iter().map(|&x| f(x)).collect::<Vec<_>>().join(" ")
}

/// A problem seen through the step hooks: counts `begin_step`, `end_steps`, `stiff_part` and evaluations, and
/// folds the `(t, y)` of every `begin_step` into a checksum; optionally turns non-finite after `nan_after`.
struct Watched<'a> {
    inner: &'a dyn OdeSystem,
    nan_after: Option<f64>,
    begins: AtomicU64,
    ends: AtomicU64,
    stiff: AtomicU64,
    rhs: AtomicU64,
    sum: AtomicU64,
}

impl<'a> Watched<'a> {
    fn new(inner: &'a dyn OdeSystem, nan_after: Option<f64>) -> Self {
        Watched {
            inner,
            nan_after,
            begins: AtomicU64::new(0),
            ends: AtomicU64::new(0),
            stiff: AtomicU64::new(0),
            rhs: AtomicU64::new(0),
            sum: AtomicU64::new(0),
        }
    }

    fn hooks(&self) -> String {
        format!(
            "hooks begin {} end {} stiff {} rhs {} sum {:016x}",
            self.begins.load(Relaxed),
            self.ends.load(Relaxed),
            self.stiff.load(Relaxed),
            self.rhs.load(Relaxed),
            self.sum.load(Relaxed)
        )
    }
}

impl OdeSystem for Watched<'_> {
    fn dim(&self) -> usize {
        self.inner.dim()
    }
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        self.rhs.fetch_add(1, Relaxed);
        self.inner.rhs(t, y, dydt);
        if self.nan_after.is_some_and(|t_bad| t > t_bad) {
            dydt[0] = f64::NAN;
        }
    }
    fn state_units(&self) -> Option<Vec<f64>> {
        self.inner.state_units()
    }
    fn begin_step(&self, t: f64, y: &[f64]) {
        self.begins.fetch_add(1, Relaxed);
        let mut s = self.sum.load(Relaxed);
        for v in std::iter::once(t).chain(y.iter().copied()) {
            s = s.rotate_left(7) ^ v.to_bits();
        }
        self.sum.store(s, Relaxed);
        self.inner.begin_step(t, y);
    }
    fn end_steps(&self) {
        self.ends.fetch_add(1, Relaxed);
        self.inner.end_steps();
    }
    fn stiff_part(&self, t: f64, y: &[f64]) -> Option<Box<dyn StiffSolve + '_>> {
        self.stiff.fetch_add(1, Relaxed);
        self.inner.stiff_part(t, y)
    }
}

fn stats_line(integ: &dyn Integrator) -> String {
    let s = integ.stats();
    format!(
        "stats acc {} rej {} rhs {} hmin {}",
        s.steps_accepted,
        s.steps_rejected,
        s.rhs_evaluations,
        f(s.smallest_step)
    )
}

fn result_line(r: &Result<(), IntegrateError>, t: f64, y: &[f64]) -> String {
    let r = match r {
        Ok(()) => "ok".to_string(),
        Err(e) => format!("err {e}"),
    };
    format!("{r} | t {} | y {}", f(t), fs(y))
}

/// Advances through `outputs`, writing a line per output time; stops at the first error.
fn through(out: &mut String, integ: &mut dyn Integrator, sys: &Watched, t: &mut f64, y: &mut [f64], outputs: &[f64]) {
    for &t_out in outputs {
        let r = integ.advance(sys, t, y, t_out);
        writeln!(
            out,
            "  -> {} {} | {}",
            f(t_out),
            result_line(&r, *t, y),
            stats_line(integ)
        )
        .unwrap();
        if r.is_err() {
            break;
        }
    }
}

fn state_json(integ: &dyn Integrator) -> String {
    serde_json::to_string(&integ.save_state()).unwrap()
}

/// The problems, each with its tolerances and the rk4 step.
fn problems() -> Vec<(Box<dyn TestProblemBox>, f64, f64)> {
    vec![
        (Box::new(HarmonicOscillator::new(1.0)), 1e-10, 0.05),
        (Box::new(Kepler::new(0.5)), 1e-9, 0.01),
        (Box::new(Arenstorf), 1e-8, 1e-3),
        (Box::new(ExponentialDecay::new(50.0)), 1e-8, 0.01),
        (Box::new(StiffDampedOscillator::default()), 1e-6, 1e-3),
        (
            Box::new(RigidBody {
                inertia: [1.0, 2.0, 3.0],
                omega0: [0.3, -0.2, 0.9],
            }),
            1e-10,
            0.02,
        ),
    ]
}

trait TestProblemBox: TestProblem + Send {}
impl<T: TestProblem + Send> TestProblemBox for T {}

/// Every method as built by the run driver, and the crate's Dop853.
fn methods() -> Vec<(&'static str, Method)> {
    vec![
        ("bulirsch-stoer", Method::BulirschStoer),
        ("dop853", Method::Dop853),
        ("bulirsch-stoer-implicit", Method::BulirschStoerImplicit),
        ("dopri5", Method::Dopri5),
        ("rk4", Method::Rk4),
        ("crate-dop853", Method::Dop853),
    ]
}

fn build(name: &str, method: Method, tol: &Tolerances, rk4_step: f64) -> Box<dyn Integrator + Send> {
    let step = (method == Method::Rk4).then_some(rk4_step);
    if name == "crate-dop853" {
        return Box::new(OdeSolversAdapter::new(Method::Dop853, tol.clone(), None).unwrap());
    }
    make_integrator(method, tol.clone(), step).unwrap()
}

fn fingerprints() -> String {
    let mut out = String::new();
    for (problem, tolerance, rk4_step) in problems() {
        let p: &dyn TestProblemBox = problem.as_ref();
        let (t0, t_end) = (p.t0(), p.t_end());
        let n = p.dim();
        let tol = Tolerances::scale_free(tolerance, tolerance, p);
        let outputs: Vec<f64> = (1..=7).map(|i| t0 + (t_end - t0) * i as f64 / 7.0).collect();
        for (name, method) in methods() {
            // Many steps for explicit methods on the stiff problem: the budget bounds the test's time.
            let budget = 30_000;
            for span in [false, true] {
                if span && !matches!(method, Method::BulirschStoer | Method::BulirschStoerImplicit) {
                    continue;
                }
                writeln!(out, "{} {name} span {span} n {n}", p.name()).unwrap();
                let sys = Watched::new(p, None);
                let mut integ = build(name, method, &tol, rk4_step);
                integ.set_max_steps(budget);
                if span {
                    integ.set_span(t_end - t0);
                }
                let (mut t, mut y) = (t0, p.initial_state());
                // The first three output times, then a checkpoint state; the original and a restored copy both go
                // on to the end.
                through(&mut out, integ.as_mut(), &sys, &mut t, &mut y, &outputs[..3]);
                let json = state_json(integ.as_ref());
                writeln!(out, "  state {json}").unwrap();
                let (t_saved, y_saved) = (t, y.clone());
                through(&mut out, integ.as_mut(), &sys, &mut t, &mut y, &outputs[3..]);
                writeln!(out, "  {}", sys.hooks()).unwrap();
                writeln!(out, "  end state {}", state_json(integ.as_ref())).unwrap();
                if t == t_end && method != Method::Rk4 {
                    // Backwards to the start (the adaptive methods).
                    let r = integ.advance(&sys, &mut t, &mut y, t0);
                    writeln!(
                        out,
                        "  back {} | {}",
                        result_line(&r, t, &y),
                        stats_line(integ.as_ref())
                    )
                    .unwrap();
                }
                let mut restored = build(name, method, &tol, rk4_step);
                let state: IntegratorState = serde_json::from_str(&json).unwrap();
                restored.restore_state(&state).unwrap();
                let sys2 = Watched::new(p, None);
                let (mut t2, mut y2) = (t_saved, y_saved);
                through(&mut out, restored.as_mut(), &sys2, &mut t2, &mut y2, &outputs[3..]);
                writeln!(out, "  restored {}", sys2.hooks()).unwrap();
            }
            // A small step budget, a past deadline and a right-hand side that turns NaN after 40 % of the span.
            let sys = Watched::new(p, None);
            let mut integ = build(name, method, &tol, rk4_step);
            integ.set_max_steps(5);
            let (mut t, mut y) = (t0, p.initial_state());
            let r = integ.advance(&sys, &mut t, &mut y, t_end);
            writeln!(
                out,
                "  budget {} | {} | {}",
                result_line(&r, t, &y),
                stats_line(integ.as_ref()),
                sys.hooks()
            )
            .unwrap();
            let mut integ = build(name, method, &tol, rk4_step);
            integ.set_deadline(Some(std::time::Instant::now()));
            let (mut t, mut y) = (t0, p.initial_state());
            let r = integ.advance(&sys, &mut t, &mut y, t_end);
            writeln!(
                out,
                "  deadline {} | {}",
                result_line(&r, t, &y),
                stats_line(integ.as_ref())
            )
            .unwrap();
            let bad = Watched::new(p, Some(t0 + 0.4 * (t_end - t0)));
            let mut integ = build(name, method, &tol, rk4_step);
            integ.set_max_steps(budget);
            let (mut t, mut y) = (t0, p.initial_state());
            through(&mut out, integ.as_mut(), &bad, &mut t, &mut y, &outputs);
            writeln!(out, "  nan {} | state {}", bad.hooks(), state_json(integ.as_ref())).unwrap();
        }
        // The settings only the concrete types have.
        let sys = Watched::new(p, None);
        let mut bs = BulirschStoer::new(tol.clone(), Some((t_end - t0) * 1e-3)).unwrap();
        bs.set_max_columns(5).unwrap();
        bs.set_h_max((t_end - t0) / 20.0);
        bs.set_max_nonfinite_retries(3);
        let (mut t, mut y) = (t0, p.initial_state());
        writeln!(out, "{} bs km 5 h_max", p.name()).unwrap();
        through(&mut out, &mut bs, &sys, &mut t, &mut y, &outputs);
        writeln!(
            out,
            "  rejections {:?} columns {} h {:?}",
            bs.rejections(),
            bs.columns(),
            bs.proposed_step()
        )
        .unwrap();
        let mut bs = BulirschStoer::new(tol.clone(), None).unwrap();
        bs.set_h_min((t_end - t0) * 0.3);
        let (mut t, mut y) = (t0, p.initial_state());
        let r = bs.advance(&sys, &mut t, &mut y, t_end);
        writeln!(out, "  bs h_min {} | {}", result_line(&r, t, &y), stats_line(&bs)).unwrap();
        let mut d = Dop853::new(tol.clone(), Some((t_end - t0) * 1e-3)).unwrap();
        d.set_h_max((t_end - t0) / 20.0);
        d.set_max_steps(30_000);
        let (mut t, mut y) = (t0, p.initial_state());
        writeln!(out, "{} dop853 h_max", p.name()).unwrap();
        through(&mut out, &mut d, &sys, &mut t, &mut y, &outputs);
        let mut d = Dop853::new(tol.clone(), None).unwrap();
        d.set_h_min((t_end - t0) * 0.3);
        let (mut t, mut y) = (t0, p.initial_state());
        let r = d.advance(&sys, &mut t, &mut y, t_end);
        writeln!(out, "  dop853 h_min {} | {}", result_line(&r, t, &y), stats_line(&d)).unwrap();
        let mut li = LinearlyImplicit::new(tol.clone()).unwrap();
        li.set_max_steps(30_000);
        let (mut t, mut y) = (t0, p.initial_state());
        writeln!(out, "{} implicit", p.name()).unwrap();
        through(&mut out, &mut li, &sys, &mut t, &mut y, &outputs);
        writeln!(
            out,
            "  rejections {:?} solves {} columns {}",
            li.rejections(),
            li.solves(),
            li.columns()
        )
        .unwrap();
        let mut a = OdeSolversAdapter::new(Method::Dopri5, tol.clone(), None).unwrap();
        a.set_chunk_steps(Some(7));
        a.set_max_steps(30_000);
        let (mut t, mut y) = (t0, p.initial_state());
        writeln!(out, "{} dopri5 chunks of 7", p.name()).unwrap();
        through(&mut out, &mut a, &sys, &mut t, &mut y, &outputs);
        let mut a = OdeSolversAdapter::new(Method::Rk4, tol.clone(), Some(rk4_step)).unwrap();
        a.set_chunk_steps(Some(7));
        let (mut t, mut y) = (t0, p.initial_state());
        writeln!(out, "{} rk4 chunks of 7", p.name()).unwrap();
        through(&mut out, &mut a, &sys, &mut t, &mut y, &outputs);
    }
    out
}

#[test]
fn every_integrator_gives_the_recorded_bits() {
    let got = fingerprints();
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(EXPECTED);
    if std::env::var_os("RUBBLEPILE_BLESS_FINGERPRINTS").is_some() {
        std::fs::write(&path, &got).unwrap();
        return;
    }
    let expected = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    if got != expected {
        let first = got
            .lines()
            .zip(expected.lines())
            .enumerate()
            .find(|(_, (a, b))| a != b)
            .map(|(i, (a, b))| format!("line {}:\n  got      {a}\n  expected {b}", i + 1))
            .unwrap_or_else(|| format!("{} lines, expected {}", got.lines().count(), expected.lines().count()));
        panic!("integrator fingerprints differ from {EXPECTED}: {first}");
    }
}
