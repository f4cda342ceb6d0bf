//! The explicit Runge–Kutta method DOP853 of Dormand & Prince (order 8, error estimator 8(5,3), step control of
//! Hairer's code DOP853): Hairer, Nørsett & Wanner, *Solving Ordinary Differential Equations I* (2nd ed., 1993),
//! §II.10, and §II.4 for the initial step `hinit`; the published coefficients, an independent implementation (the
//! `ode_solvers` crate's Dop853 stays reachable through [`super::ode_solvers_adapter`] for cross-checks).
//!
//! Twelve stages `k_i = f(t + c_i h, y + h Σ_{j<i} a_ij k_j)`, `y_new = y + h Σ b_i k_i` (FSAL). With
//! `E5 = Σ (e5_i/sc_i)²`, `E3 = Σ (e3_i/sc_i)²` in the scaled norm of [`Tolerances`],
//! `err = |h| E5 / sqrt(n (E5 + 0.01 E3))`; `h_new = h / clamp(err^{1/8} / 0.9, 1/6, 1/0.333)`, accepted when
//! `err ≤ 1`, no growth right after a rejection, β = 0. The loop (landing on output times, restart with the last
//! full step, failures, statistics) is [`Adaptive`]'s; this file supplies the step ([`Dop853Step`]).
//!
//! Invariants: [`OdeSystem::begin_step`] sees each state steps are attempted from (a rejected retry keeps its
//! choice), [`OdeSystem::end_steps`] each return. The vector work runs over fixed chunks of [`CHUNK`] components,
//! on rayon from [`DEFAULT_PARALLEL_FROM`], with the norms summed within and then over chunks in order: results
//! are bit-identical on any number of threads; a step allocates nothing. Only the proposed step, settings and
//! counters pass between calls ([`Dop853State`]), so a restored integrator continues bit for bit.

use super::adaptive_loop::{
    Adaptive, Carried, Cause, FirstStep, Outcome, StepMethod, Trial, hinit_h0, hinit_h1, validate_tolerances,
    wrong_state,
};
pub use super::adaptive_loop::{DEFAULT_MAX_NONFINITE_RETRIES, DEFAULT_MAX_STEPS};
pub use super::common::Dop853State;
#[cfg(doc)]
use super::common::Integrator;
use super::common::{IntegrateError, IntegratorState, Method, OdeSystem, Tolerances};
use super::compensated::Compensation;
use crate::phase::{Kind, Phase};
use rayon::prelude::*;

/// Components per chunk of every vector loop: the unit of parallel work and of the norms' partial sums (the
/// summation order, hence the bits, depend on it and on nothing else).
pub const CHUNK: usize = 2048;
/// Default dimension from which the vector loops run on rayon's pool ([`Dop853::set_parallel_from`]).
pub const DEFAULT_PARALLEL_FROM: usize = 16_384;

/// Safety factor of the step-size control.
const SAFE: f64 = 0.9;
/// Smallest step ratio `h_new / h` (DOP853's `fac1`).
const FAC1: f64 = 0.333;
/// Largest step ratio `h_new / h` (DOP853's `fac2`).
const FAC2: f64 = 6.0;
/// Exponent of the step-size control: 1/8 (β = 0).
const EXPO: f64 = 1.0 / 8.0;

/// The vector work on the parallel path.
static VECTOR: Phase = Phase::new("integrate.dop853.vector", Kind::Parallel);
/// The vector work on the serial path (small systems).
static VECTOR_SERIAL: Phase = Phase::new("integrate.dop853.vector_serial", Kind::Serial);

/// The published coefficients of DOP853 (Hairer's code), 1-based names as there.
#[allow(clippy::excessive_precision, clippy::unreadable_literal)]
mod tableau {
    pub const C2: f64 = 0.526001519587677318785587544488e-01;
    pub const C3: f64 = 0.789002279381515978178381316732e-01;
    pub const C4: f64 = 0.118350341907227396726757197510e+00;
    pub const C5: f64 = 0.281649658092772603273242802490e+00;
    pub const C6: f64 = 0.333333333333333333333333333333e+00;
    pub const C7: f64 = 0.25e+00;
    pub const C8: f64 = 0.307692307692307692307692307692e+00;
    pub const C9: f64 = 0.651282051282051282051282051282e+00;
    pub const C10: f64 = 0.6e+00;
    pub const C11: f64 = 0.857142857142857142857142857142e+00;

    pub const B1: f64 = 5.42937341165687622380535766363e-2;
    pub const B6: f64 = 4.45031289275240888144113950566e0;
    pub const B7: f64 = 1.89151789931450038304281599044e0;
    pub const B8: f64 = -5.8012039600105847814672114227e0;
    pub const B9: f64 = 3.1116436695781989440891606237e-1;
    pub const B10: f64 = -1.52160949662516078556178806805e-1;
    pub const B11: f64 = 2.01365400804030348374776537501e-1;
    pub const B12: f64 = 4.47106157277725905176885569043e-2;

    pub const BHH1: f64 = 0.244094488188976377952755905512e+00;
    pub const BHH2: f64 = 0.733846688281611857341361741547e+00;
    pub const BHH3: f64 = 0.220588235294117647058823529412e-01;

    pub const ER1: f64 = 0.1312004499419488073250102996e-01;
    pub const ER6: f64 = -0.1225156446376204440720569753e+01;
    pub const ER7: f64 = -0.4957589496572501915214079952e+00;
    pub const ER8: f64 = 0.1664377182454986536961530415e+01;
    pub const ER9: f64 = -0.3503288487499736816886487290e+00;
    pub const ER10: f64 = 0.3341791187130174790297318841e+00;
    pub const ER11: f64 = 0.8192320648511571246570742613e-01;
    pub const ER12: f64 = -0.2235530786388629525884427845e-01;

    pub const A21: f64 = 5.26001519587677318785587544488e-2;
    pub const A31: f64 = 1.97250569845378994544595329183e-2;
    pub const A32: f64 = 5.91751709536136983633785987549e-2;
    pub const A41: f64 = 2.95875854768068491816892993775e-2;
    pub const A43: f64 = 8.87627564304205475450678981324e-2;
    pub const A51: f64 = 2.41365134159266685502369798665e-1;
    pub const A53: f64 = -8.84549479328286085344864962717e-1;
    pub const A54: f64 = 9.24834003261792003115737966543e-1;
    pub const A61: f64 = 3.7037037037037037037037037037e-2;
    pub const A64: f64 = 1.70828608729473871279604482173e-1;
    pub const A65: f64 = 1.25467687566822425016691814123e-1;
    pub const A71: f64 = 3.7109375e-2;
    pub const A74: f64 = 1.70252211019544039314978060272e-1;
    pub const A75: f64 = 6.02165389804559606850219397283e-2;
    pub const A76: f64 = -1.7578125e-2;
    pub const A81: f64 = 3.70920001185047927108779319836e-2;
    pub const A84: f64 = 1.70383925712239993810214054705e-1;
    pub const A85: f64 = 1.07262030446373284651809199168e-1;
    pub const A86: f64 = -1.53194377486244017527936158236e-2;
    pub const A87: f64 = 8.27378916381402288758473766002e-3;
    pub const A91: f64 = 6.24110958716075717114429577812e-1;
    pub const A94: f64 = -3.36089262944694129406857109825e0;
    pub const A95: f64 = -8.68219346841726006818189891453e-1;
    pub const A96: f64 = 2.75920996994467083049415600797e1;
    pub const A97: f64 = 2.01540675504778934086186788979e1;
    pub const A98: f64 = -4.34898841810699588477366255144e1;
    pub const A101: f64 = 4.77662536438264365890433908527e-1;
    pub const A104: f64 = -2.48811461997166764192642586468e0;
    pub const A105: f64 = -5.90290826836842996371446475743e-1;
    pub const A106: f64 = 2.12300514481811942347288949897e1;
    pub const A107: f64 = 1.52792336328824235832596922938e1;
    pub const A108: f64 = -3.32882109689848629194453265587e1;
    pub const A109: f64 = -2.03312017085086261358222928593e-2;
    pub const A111: f64 = -9.3714243008598732571704021658e-1;
    pub const A114: f64 = 5.18637242884406370830023853209e0;
    pub const A115: f64 = 1.09143734899672957818500254654e0;
    pub const A116: f64 = -8.14978701074692612513997267357e0;
    pub const A117: f64 = -1.85200656599969598641566180701e1;
    pub const A118: f64 = 2.27394870993505042818970056734e1;
    pub const A119: f64 = 2.49360555267965238987089396762e0;
    pub const A1110: f64 = -3.0467644718982195003823669022e0;
    pub const A121: f64 = 2.27331014751653820792359768449e0;
    pub const A124: f64 = -1.05344954667372501984066689879e1;
    pub const A125: f64 = -2.00087205822486249909675718444e0;
    pub const A126: f64 = -1.79589318631187989172765950534e1;
    pub const A127: f64 = 2.79488845294199600508499808837e1;
    pub const A128: f64 = -2.85899827713502369474065508674e0;
    pub const A129: f64 = -8.87285693353062954433549289258e0;
    pub const A1210: f64 = 1.23605671757943030647266201528e1;
    pub const A1211: f64 = 6.43392746015763530355970484046e-1;
}

use tableau::*;

/// One stage's sum: the node `c_i` and the nonzero `a_ij` with their stage indices `j` (0-based).
struct StageRow {
    c: f64,
    a: &'static [(usize, f64)],
}

/// Stages 2–12 (index 0 is stage 2). Stages 2 and 3 do not use `k_4 … k_8`, stages 4 on do not use `k_2, k_3`.
const STAGES: [StageRow; 11] = [
    StageRow { c: C2, a: &[(0, A21)] },
    StageRow {
        c: C3,
        a: &[(0, A31), (1, A32)],
    },
    StageRow {
        c: C4,
        a: &[(0, A41), (2, A43)],
    },
    StageRow {
        c: C5,
        a: &[(0, A51), (2, A53), (3, A54)],
    },
    StageRow {
        c: C6,
        a: &[(0, A61), (3, A64), (4, A65)],
    },
    StageRow {
        c: C7,
        a: &[(0, A71), (3, A74), (4, A75), (5, A76)],
    },
    StageRow {
        c: C8,
        a: &[(0, A81), (3, A84), (4, A85), (5, A86), (6, A87)],
    },
    StageRow {
        c: C9,
        a: &[(0, A91), (3, A94), (4, A95), (5, A96), (6, A97), (7, A98)],
    },
    StageRow {
        c: C10,
        a: &[
            (0, A101),
            (3, A104),
            (4, A105),
            (5, A106),
            (6, A107),
            (7, A108),
            (8, A109),
        ],
    },
    StageRow {
        c: C11,
        a: &[
            (0, A111),
            (3, A114),
            (4, A115),
            (5, A116),
            (6, A117),
            (7, A118),
            (8, A119),
            (9, A1110),
        ],
    },
    StageRow {
        c: 1.0,
        a: &[
            (0, A121),
            (3, A124),
            (4, A125),
            (5, A126),
            (6, A127),
            (7, A128),
            (8, A129),
            (9, A1210),
            (10, A1211),
        ],
    },
];

/// The weights `b_i` of the 8th-order solution (0-based stage indices).
const WEIGHTS: [(usize, f64); 8] = [
    (0, B1),
    (5, B6),
    (6, B7),
    (7, B8),
    (8, B9),
    (9, B10),
    (10, B11),
    (11, B12),
];

/// The 5th-order error estimator `b_i − b̂_i` (0-based stage indices: the same stages as [`WEIGHTS`], in the
/// same order).
const ERROR5: [(usize, f64); 8] = [
    (0, ER1),
    (5, ER6),
    (6, ER7),
    (7, ER8),
    (8, ER9),
    (9, ER10),
    (10, ER11),
    (11, ER12),
];

// The final pass reads each of these stages once for both sums.
const _: () = {
    let mut t = 0;
    while t < WEIGHTS.len() {
        assert!(WEIGHTS[t].0 == ERROR5[t].0);
        t += 1;
    }
};

/// Runs `f(lo, chunk)` on every [`CHUNK`] of `out` (`lo`: the chunk's first index), on rayon's pool if `parallel`.
fn each_chunk(parallel: bool, out: &mut [f64], f: impl Fn(usize, &mut [f64]) + Sync + Send) {
    if parallel {
        out.par_chunks_mut(CHUNK).enumerate().for_each(|(c, o)| f(c * CHUNK, o));
    } else {
        for (c, o) in out.chunks_mut(CHUNK).enumerate() {
            f(c * CHUNK, o);
        }
    }
}

/// Runs `f(lo, out_chunk)` on every [`CHUNK`] of `out`, storing what it returns per chunk in `partials`, and
/// returns the element-wise sums of `partials` added in chunk order.
fn each_chunk_sums(
    parallel: bool,
    out: &mut [f64],
    partials: &mut [[f64; 3]],
    f: impl Fn(usize, &mut [f64]) -> [f64; 3] + Sync + Send,
) -> [f64; 3] {
    let partials = &mut partials[..out.len().div_ceil(CHUNK)];
    if parallel {
        out.par_chunks_mut(CHUNK)
            .zip(partials.par_iter_mut())
            .enumerate()
            .for_each(|(c, (o, p))| *p = f(c * CHUNK, o));
    } else {
        for (c, (o, p)) in out.chunks_mut(CHUNK).zip(partials.iter_mut()).enumerate() {
            *p = f(c * CHUNK, o);
        }
    }
    in_chunk_order(partials)
}

/// Runs `f(lo, hi)` on the index range of every [`CHUNK`] of `0..n`, storing what it returns per chunk in
/// `partials`, and returns the element-wise sums of `partials` added in chunk order.
fn chunk_sums(
    parallel: bool,
    n: usize,
    partials: &mut [[f64; 3]],
    f: impl Fn(usize, usize) -> [f64; 3] + Sync + Send,
) -> [f64; 3] {
    let partials = &mut partials[..n.div_ceil(CHUNK)];
    let range = |c: usize| (c * CHUNK, ((c + 1) * CHUNK).min(n));
    if parallel {
        partials.par_iter_mut().enumerate().for_each(|(c, p)| {
            let (lo, hi) = range(c);
            *p = f(lo, hi);
        });
    } else {
        for (c, p) in partials.iter_mut().enumerate() {
            let (lo, hi) = range(c);
            *p = f(lo, hi);
        }
    }
    in_chunk_order(partials)
}

/// The element-wise sums of per-chunk partial sums, added in chunk order (the order that makes the bits independent
/// of the thread count).
fn in_chunk_order(partials: &[[f64; 3]]) -> [f64; 3] {
    let mut total = [0.0; 3];
    for p in partials {
        for (t, v) in total.iter_mut().zip(p) {
            *t += v;
        }
    }
    total
}

/// One chunk of a stage's argument: `out = y + h Σ_j a_j k_j` over `lo..lo + out.len()`, with the `M` terms
/// `(j, a_j)` summed left to right (each element's arithmetic is fixed, whichever thread does it).
fn stage_chunk<const M: usize>(out: &mut [f64], y: &[f64], h: f64, k: &[Vec<f64>], lo: usize, terms: &[(usize, f64)]) {
    let hi = lo + out.len();
    let ks: [&[f64]; M] = std::array::from_fn(|t| &k[terms[t].0][lo..hi]);
    let w: [f64; M] = std::array::from_fn(|t| terms[t].1);
    let y = &y[lo..hi];
    for (i, (z, &yi)) in out.iter_mut().zip(y).enumerate() {
        let mut s = w[0] * ks[0][i];
        for t in 1..M {
            s += w[t] * ks[t][i];
        }
        *z = yi + h * s;
    }
}

/// [`stage_chunk`] for a row of [`STAGES`] (1 to 10 terms).
fn stage_row_chunk(out: &mut [f64], y: &[f64], h: f64, k: &[Vec<f64>], lo: usize, terms: &[(usize, f64)]) {
    match terms.len() {
        1 => stage_chunk::<1>(out, y, h, k, lo, terms),
        2 => stage_chunk::<2>(out, y, h, k, lo, terms),
        3 => stage_chunk::<3>(out, y, h, k, lo, terms),
        4 => stage_chunk::<4>(out, y, h, k, lo, terms),
        5 => stage_chunk::<5>(out, y, h, k, lo, terms),
        6 => stage_chunk::<6>(out, y, h, k, lo, terms),
        7 => stage_chunk::<7>(out, y, h, k, lo, terms),
        8 => stage_chunk::<8>(out, y, h, k, lo, terms),
        9 => stage_chunk::<9>(out, y, h, k, lo, terms),
        m => unreachable!("DOP853 has no stage with {m} terms"),
    }
}

/// The DOP853 integrator (see the [module documentation](self)): the step loop [`Adaptive`] around [`Dop853Step`].
///
/// ```
/// use rubblepile::integrate::{Integrator, Tolerances, dop853::Dop853};
/// use rubblepile::integrate::problems::{HarmonicOscillator, TestProblem};
///
/// let osc = HarmonicOscillator::new(1.0);
/// let mut dop = Dop853::new(Tolerances::uniform(1e-10, 1e-10, 2), None).unwrap();
/// let (mut t, mut y) = (0.0, osc.initial_state());
/// for &t_out in &[0.5, 1.0, 2.5, 2.0 * std::f64::consts::PI] {
///     dop.advance(&osc, &mut t, &mut y, t_out).unwrap();
///     assert_eq!(t, t_out); // lands exactly on every output time
/// }
/// assert!((y[0] - 1.0).abs() < 1e-8 && y[1].abs() < 1e-8);
/// ```
pub type Dop853 = Adaptive<Dop853Step>;

impl Dop853 {
    /// A new integrator with per-component `tolerances` (of the dimension of the systems later passed to
    /// [`Integrator::advance`]) and an optional initial step `step` (|step| for the very first step; `None`: Hairer's
    /// `hinit` from `f(t0, y0)` and one more evaluation). Errors with [`IntegrateError::Config`] for tolerances
    /// [`validate_tolerances`] refuses or a `step` not non-zero and finite.
    pub fn new(tolerances: Tolerances, step: Option<f64>) -> Result<Self, IntegrateError> {
        validate_tolerances(&tolerances)?;
        let method = Dop853Step {
            tol: tolerances,
            parallel_from: DEFAULT_PARALLEL_FROM,
            ..Dop853Step::default()
        };
        Adaptive::with_method(method, step)
    }

    /// Sets the dimension from which the vector loops run on rayon's current pool (default
    /// [`DEFAULT_PARALLEL_FROM`]); below it they run on the calling thread. No bit of the results depends on it.
    pub fn set_parallel_from(&mut self, n: usize) {
        self.method.parallel_from = n;
    }
}

/// One DOP853 step and its work arrays.
#[derive(Debug, Clone, Default)]
pub struct Dop853Step {
    tol: Tolerances,
    parallel_from: usize,
    evals: u64,

    // Work arrays (allocated once per dimension).
    n: usize,
    /// The stages `k_1 … k_12` (0-based); `k[0]` is the derivative at the step's start.
    k: Vec<Vec<f64>>,
    /// The last accepted state.
    y: Vec<f64>,
    /// The trial new state of a step.
    y_new: Vec<f64>,
    /// A stage's argument `y + h Σ a_ij k_j`, and scratch of the error pass.
    y_stage: Vec<f64>,
    /// Per-chunk partial sums of the norms.
    partials: Vec<[f64; 3]>,
}

impl Dop853Step {
    fn parallel(&self) -> bool {
        self.n >= self.parallel_from
    }

    /// Times `f` as the vector phase of the path in use.
    fn timed<R>(parallel: bool, f: impl FnOnce() -> R) -> R {
        if parallel {
            VECTOR.time(f)
        } else {
            VECTOR_SERIAL.time(f)
        }
    }

    /// `k[stage] = f(t, arg)`, counting the evaluation.
    fn eval(&mut self, system: &dyn OdeSystem, t: f64, stage: usize, arg: Arg) {
        self.evals += 1;
        let src = match arg {
            Arg::State => &self.y,
            Arg::Stage => &self.y_stage,
        };
        system.rhs(t, src, &mut self.k[stage]);
    }

    /// Whether stage `stage` holds only finite values (chunked, parallel on the parallel path).
    fn finite(&mut self, stage: usize) -> bool {
        let parallel = self.parallel();
        let k = &self.k[stage];
        let [bad, _, _] = Self::timed(parallel, || {
            chunk_sums(parallel, self.n, &mut self.partials, |lo, hi| {
                [k[lo..hi].iter().filter(|v| !v.is_finite()).count() as f64, 0.0, 0.0]
            })
        });
        bad == 0.0
    }

    /// Copies `from` into `to` chunk by chunk (parallel on the parallel path).
    fn copy(parallel: bool, from: &[f64], to: &mut [f64]) {
        Self::timed(parallel, || {
            each_chunk(parallel, to, |lo, o| o.copy_from_slice(&from[lo..lo + o.len()]))
        });
    }

    /// The stages and the new state of the step `h` from `(t, self.y)` with `k[0] = f(t, y)`, ending at `t_end`.
    /// Returns the outcome of the error test and the error estimate.
    fn stages(&mut self, system: &dyn OdeSystem, t: f64, h: f64, t_end: f64) -> (Attempt, f64) {
        let parallel = self.parallel();
        for (s, row) in STAGES.iter().enumerate() {
            let (y, k) = (&self.y, &self.k);
            Self::timed(parallel, || {
                each_chunk(parallel, &mut self.y_stage, |lo, o| {
                    stage_row_chunk(o, y, h, k, lo, row.a)
                })
            });
            let ts = if row.c == 1.0 { t_end } else { t + row.c * h };
            self.eval(system, ts, s + 1, Arg::Stage);
        }
        // The new state, both error estimators and their norms in one pass per chunk (WEIGHTS and ERROR5 use the
        // same stages: k_1, k_6 … k_12).
        let (y, k, tol) = (&self.y, &self.k, &self.tol);
        let [e5, e3, bad] = Self::timed(parallel, || {
            each_chunk_sums(parallel, &mut self.y_new, &mut self.partials, |lo, yn| {
                let hi = lo + yn.len();
                let ks: [&[f64]; 8] = std::array::from_fn(|t| &k[WEIGHTS[t].0][lo..hi]);
                let (y, atol, rtol) = (&y[lo..hi], &tol.atol[lo..hi], &tol.rtol[lo..hi]);
                let (mut s5, mut s3, mut bad) = (0.0, 0.0, 0.0);
                for (i, v) in yn.iter_mut().enumerate() {
                    let mut b = WEIGHTS[0].1 * ks[0][i];
                    let mut e5 = ERROR5[0].1 * ks[0][i];
                    for t in 1..8 {
                        b += WEIGHTS[t].1 * ks[t][i];
                        e5 += ERROR5[t].1 * ks[t][i];
                    }
                    let e3 = b - BHH1 * ks[0][i] - BHH2 * ks[4][i] - BHH3 * ks[7][i];
                    let yi = y[i];
                    *v = yi + h * b;
                    if !v.is_finite() {
                        bad += 1.0;
                    }
                    let sc = (atol[i] + rtol[i] * yi.abs().max(v.abs())).max(f64::MIN_POSITIVE);
                    s5 += (e5 / sc).powi(2);
                    s3 += (e3 / sc).powi(2);
                }
                [s5, s3, bad]
            })
        });
        let mut deno = e5 + 0.01 * e3;
        if deno <= 0.0 {
            deno = 1.0;
        }
        let err = h.abs() * e5 * (1.0 / (self.n as f64 * deno)).sqrt();
        if bad > 0.0 || err.is_nan() {
            (Attempt::NonFinite, err)
        } else if err <= 1.0 {
            (Attempt::Accepted, err)
        } else {
            (Attempt::Rejected, err)
        }
    }
}

/// The outcome of the error test of one step.
enum Attempt {
    /// Accepted; the new state is in `y_new`.
    Accepted,
    /// Rejected by the error test.
    Rejected,
    /// A stage or the new state was not finite.
    NonFinite,
}

/// Which vector a stage is evaluated at.
#[derive(Clone, Copy)]
enum Arg {
    /// The last accepted state `y`.
    State,
    /// A stage's argument.
    Stage,
}

impl StepMethod for Dop853Step {
    type Frozen<'s> = ();
    const METHOD: Method = Method::Dop853;

    fn prepare(&mut self, n: usize) {
        if self.n == n && self.y.len() == n {
            return;
        }
        self.n = n;
        self.k = vec![vec![0.0; n]; 12];
        self.y = vec![0.0; n];
        self.y_new = vec![0.0; n];
        self.y_stage = vec![0.0; n];
        self.partials = vec![[0.0; 3]; n.div_ceil(CHUNK)];
    }

    /// The step works on its own copy of the state (`y`, swapped with `y_new` on acceptance).
    fn enter(&mut self, y: &[f64], _comp: &mut Compensation) {
        Self::copy(self.parallel(), y, &mut self.y);
    }

    /// The system sees the step's own copy of the state; `f(t, y)` into `k[0]`.
    fn start(&mut self, system: &dyn OdeSystem, t: f64, _y: &[f64]) -> Option<()> {
        system.begin_step(t, &self.y);
        // FSAL after an accepted step: the derivative at the new state is the next step's first stage.
        self.eval(system, t, 0, Arg::State);
        self.finite(0).then_some(())
    }

    /// Hairer's initial step guess `hinit` (§II.4) with the error's scaled RMS norms and the exponent 1/8, from
    /// `f(t, y)` in `k[0]` and one more evaluation (into `k[1]`).
    fn initial_step(&mut self, system: &dyn OdeSystem, _y: &[f64], first: &FirstStep) -> f64 {
        let &FirstStep { t, dir, span, h_max } = first;
        let n = self.n as f64;
        let parallel = self.parallel();
        let (y, k, tol) = (&self.y, &self.k, &self.tol);
        let scale = |i: usize| (tol.atol[i] + tol.rtol[i] * y[i].abs()).max(f64::MIN_POSITIVE);
        let [dy, df, _] = Self::timed(parallel, || {
            chunk_sums(parallel, self.n, &mut self.partials, |lo, hi| {
                let (mut dy, mut df) = (0.0, 0.0);
                for i in lo..hi {
                    let sc = scale(i);
                    dy += (y[i] / sc).powi(2);
                    df += (k[0][i] / sc).powi(2);
                }
                [dy, df, 0.0]
            })
        });
        let (d0, d1) = ((dy / n).sqrt(), (df / n).sqrt());
        let h0 = hinit_h0(d0, d1).min(span).min(h_max);
        if h0.is_nan() || h0 <= 0.0 {
            return 1e-6f64.min(span).min(h_max);
        }
        // Explicit Euler step into y_stage, its derivative into k[1].
        let (y, k) = (&self.y, &self.k);
        Self::timed(parallel, || {
            each_chunk(parallel, &mut self.y_stage, |lo, o| {
                for ((z, &yi), &fi) in o.iter_mut().zip(&y[lo..]).zip(&k[0][lo..]) {
                    *z = yi + dir * h0 * fi;
                }
            })
        });
        self.eval(system, t + dir * h0, 1, Arg::Stage);
        let (y, k, tol) = (&self.y, &self.k, &self.tol);
        let scale = |i: usize| (tol.atol[i] + tol.rtol[i] * y[i].abs()).max(f64::MIN_POSITIVE);
        let [d2, _, _] = Self::timed(parallel, || {
            chunk_sums(parallel, self.n, &mut self.partials, |lo, hi| {
                let mut d2 = 0.0;
                for (i, (&f1, &f0)) in (lo..hi).zip(k[1][lo..hi].iter().zip(&k[0][lo..hi])) {
                    d2 += ((f1 - f0) / scale(i)).powi(2);
                }
                [d2, 0.0, 0.0]
            })
        });
        hinit_h1(h0, d1, (d2 / n).sqrt() / h0, EXPO, span, h_max)
    }

    /// DOP853's step-size control: `h_new = h / clamp(err^{1/8} / 0.9, 1/6, 1/0.333)`, not growing right after a
    /// rejection.
    fn attempt(&mut self, system: &dyn OdeSystem, _frozen: &mut (), _y: &[f64], trial: &Trial) -> Outcome {
        let (outcome, err) = self.stages(system, trial.t, trial.h, trial.t_end);
        let h_abs = trial.h.abs();
        match outcome {
            Attempt::Accepted => {
                let fac = (err.powf(EXPO) / SAFE).clamp(1.0 / FAC2, 1.0 / FAC1);
                let h_next = (h_abs / fac).min(trial.h_max);
                Outcome::Accepted {
                    h_next: if trial.after_rejection {
                        h_next.min(h_abs)
                    } else {
                        h_next
                    },
                }
            }
            // err > 1: the step shrinks, by at most 1/FAC1.
            Attempt::Rejected => Outcome::Rejected {
                h_next: h_abs / (err.powf(EXPO) / SAFE).min(1.0 / FAC1),
            },
            Attempt::NonFinite => Outcome::Halve(Cause::NonFinite),
        }
    }

    fn commit(&mut self, _y: &mut [f64], _comp: &mut Compensation) {
        std::mem::swap(&mut self.y, &mut self.y_new);
    }

    /// `self.y` is the last accepted state, whatever the result.
    fn leave(&mut self, y: &mut [f64], _comp: &mut Compensation) {
        Self::copy(self.parallel(), &self.y, y);
    }

    fn evaluations(&self) -> u64 {
        self.evals
    }

    fn set_evaluations(&mut self, n: u64) {
        self.evals = n;
    }

    fn tolerances(&self) -> &Tolerances {
        &self.tol
    }

    fn save(&self, carried: Carried) -> IntegratorState {
        IntegratorState::Dop853(Dop853State {
            dim: carried.dim,
            initial_step: carried.initial_step,
            limits: carried.limits,
            h: carried.h,
            stats: carried.stats,
        })
    }

    fn restore(&mut self, state: &IntegratorState, carried: &mut Carried) -> Result<(), IntegrateError> {
        let s = match state {
            IntegratorState::Dop853(s) => s,
            IntegratorState::OdeSolvers(s) if s.method == Method::Dop853 => {
                return Err(IntegrateError::Config(
                    "the state was saved by the `ode_solvers` crate's Dop853, which rubblepile no longer runs for \
                     method \"dop853\" (its own DOP853 has another step-size history): re-run from the start"
                        .into(),
                ));
            }
            other => return Err(wrong_state(other, Method::Dop853)),
        };
        carried.dim = s.dim;
        carried.limits = s.limits;
        carried.initial_step = s.initial_step;
        carried.h = s.h;
        carried.stats = s.stats;
        carried.check(Method::Dop853, self.tol.rtol.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The published DOP853 tableau as full arrays, for tests of its order conditions: `(c, a, b, bhat5, bhat3)`
    /// with `c` and `b` of length 12, `a` 12 × 12 (strictly lower triangular), `bhat5 = b − e5` (the 5th-order
    /// embedded weights) and `bhat3` the 3rd-order weights on stages 1, 9 and 12.
    #[allow(clippy::type_complexity)]
    fn tableau() -> ([f64; 12], [[f64; 12]; 12], [f64; 12], [f64; 12], [f64; 12]) {
        let mut c = [0.0; 12];
        let mut a = [[0.0; 12]; 12];
        for (s, row) in STAGES.iter().enumerate() {
            c[s + 1] = row.c;
            for &(j, v) in row.a {
                a[s + 1][j] = v;
            }
        }
        let mut b = [0.0; 12];
        let mut b5 = [0.0; 12];
        for &(j, v) in &WEIGHTS {
            b[j] = v;
            b5[j] = v;
        }
        for &(j, v) in &ERROR5 {
            b5[j] -= v;
        }
        let mut b3 = [0.0; 12];
        b3[0] = BHH1;
        b3[8] = BHH2;
        b3[11] = BHH3;
        (c, a, b, b5, b3)
    }

    #[test]
    fn tableau_satisfies_its_order_conditions() {
        let (c, a, b, b5, b3) = tableau();
        let close =
            |x: f64, y: f64, what: &str| assert!((x - y).abs() <= 1e-14 * (1.0 + y.abs()), "{what}: {x} vs {y}");
        // Row sums: each stage's time is its node.
        for i in 0..12 {
            close(a[i].iter().sum::<f64>(), c[i], &format!("row {i}"));
            assert!(a[i][i..].iter().all(|&v| v == 0.0), "row {i} is explicit");
        }
        assert_eq!(c[11], 1.0, "the 12th stage is at t + h");
        // Quadrature conditions Σ b_i c_i^(q−1) = 1/q: order 8 for b, 5 for the 5th-order weights, 3 for the 3rd.
        let quad = |w: &[f64; 12], q: i32| (0..12).map(|i| w[i] * c[i].powi(q - 1)).sum::<f64>();
        for q in 1..=8 {
            close(quad(&b, q), 1.0 / q as f64, &format!("b, c^{}", q - 1));
        }
        for q in 1..=5 {
            close(quad(&b5, q), 1.0 / q as f64, &format!("b5, c^{}", q - 1));
        }
        for q in 1..=3 {
            close(quad(&b3, q), 1.0 / q as f64, &format!("b3, c^{}", q - 1));
        }
        // Σ b_i a_ij c_j^(q−1) = 1/(q (q+1)) (the trees [τ^q]): order 8 needs q ≤ 7.
        let ac = |q: i32| -> Vec<f64> {
            (0..12)
                .map(|i| (0..12).map(|j| a[i][j] * c[j].powi(q - 1)).sum())
                .collect()
        };
        for q in 1..=7 {
            let v = ac(q);
            close(
                (0..12).map(|i| b[i] * v[i]).sum(),
                1.0 / (q * (q + 1)) as f64,
                &format!("b a c^{}", q - 1),
            );
        }
        // The simplifying assumption behind DOP853's stages 4 on: Σ_j a_ij c_j = c_i²/2.
        let v = ac(2);
        for i in 3..12 {
            close(v[i], c[i] * c[i] / 2.0, &format!("stage {i}: a c = c²/2"));
        }
        // An order-8 tree with a branch: Σ_i b_i c_i⁵ Σ_j a_ij c_j = 1/16.
        close(
            (0..12).map(|i| b[i] * c[i].powi(5) * v[i]).sum(),
            1.0 / 16.0,
            "b c^5 a c",
        );
    }
}
