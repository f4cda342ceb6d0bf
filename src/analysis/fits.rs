//! Curve fitting for the post-processing of impact runs (Roig03 §4.2–4.3).
//!
//! * [`levenberg_marquardt`]: a small, general Levenberg–Marquardt least-squares solver for `y = f(x; p)`,
//!   with an analytic Jacobian or central differences, optional per-point `σ`, and parameter standard errors
//!   from the covariance `(JᵀWJ)⁻¹` (scaled by the reduced χ² when no `σ` are given).
//! * [`fit_spin_histogram`] / [`compare_exponents`]: the spin-histogram model of Roig03 Eq. (44),
//!   `f(x) = a xⁿ exp(−x²/b²)`, with its Eq. (45) normalisation `∫₀^∞ f dx = ½ a bⁿ⁺¹ Γ((n+1)/2)`.
//! * [`fit_power_law`]: `y = c x^α` by least squares in log–log (ejection speed or spin vs size).
//! * [`fit_line`] / [`line_crossing`]: a straight line and where it crosses a level, with the propagated error
//!   (Q*_D: bound mass fraction vs Q, crossing 0.5).
//! * [`histogram`]: equal-width bins → (centres, counts).
//!
//! Nothing here panics on bad data: every entry point returns a [`FitError`] instead.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;
use statrs::function::gamma::gamma;

/// Why a fit could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    /// Fewer usable data points than the fit needs.
    #[error("too few points: {points} usable, at least {needed} needed")]
    TooFewPoints {
        /// Usable points given.
        points: usize,
        /// Points needed.
        needed: usize,
    },
    /// A NaN or infinite value in the data, the starting parameters or the model.
    #[error("non-finite value in {0}")]
    NonFinite(&'static str),
    /// The normal matrix `JᵀWJ` is singular: some parameters are not determined by the data.
    #[error("singular normal matrix: parameters not determined by the data")]
    Singular,
    /// Inconsistent or meaningless input (mismatched lengths, non-positive σ, empty range …).
    #[error("invalid input: {0}")]
    InvalidInput(String),
}

/// Stopping rules of [`levenberg_marquardt`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LmOptions {
    /// Most outer iterations (Jacobian evaluations).
    pub max_iterations: usize,
    /// Converged when every accepted step satisfies `|δp_i| ≤ xtol (|p_i| + xtol)`.
    pub xtol: f64,
    /// Converged when an accepted step lowers χ² by less than `ftol · χ²`.
    pub ftol: f64,
    /// Starting damping λ (Marquardt scaling: `JᵀWJ + λ diag(JᵀWJ)`).
    pub initial_lambda: f64,
}

impl Default for LmOptions {
    fn default() -> Self {
        Self {
            max_iterations: 500,
            xtol: 1e-10,
            ftol: 1e-15,
            initial_lambda: 1e-3,
        }
    }
}

/// The result of [`levenberg_marquardt`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LmFit {
    /// Best-fit parameters.
    pub parameters: Vec<f64>,
    /// Standard errors: `√diag(C)` with `C = (JᵀWJ)⁻¹`, times the reduced χ² when no σ were given.
    pub standard_errors: Vec<f64>,
    /// The covariance matrix `C` (row-major, `p × p`), scaled as the standard errors are.
    pub covariance: Vec<Vec<f64>>,
    /// Σ rᵢ² with `rᵢ = yᵢ − f(xᵢ; p)` (unweighted).
    pub rss: f64,
    /// χ² = Σ wᵢ rᵢ² with `wᵢ = 1/σᵢ²` (equal to `rss` without σ).
    pub chi2: f64,
    /// χ² / (N − p); NaN when N = p.
    pub reduced_chi2: f64,
    /// Degrees of freedom N − p.
    pub dof: usize,
    /// Outer iterations done.
    pub iterations: usize,
    /// Whether a stopping rule was met before `max_iterations`.
    pub converged: bool,
}

/// Model `f(x; p)` of [`levenberg_marquardt`].
pub type Model<'a> = &'a dyn Fn(f64, &[f64]) -> f64;
/// Analytic Jacobian row of [`levenberg_marquardt`]: writes `∂f(x; p)/∂p_j` into the slice.
pub type Jacobian<'a> = &'a dyn Fn(f64, &[f64], &mut [f64]);

/// Levenberg–Marquardt least squares: minimises χ² = Σ wᵢ (yᵢ − f(xᵢ; p))² from `p0`.
///
/// `jacobian` gives `∂f/∂p` at one `x`; without it central differences with step
/// `h_j = ε^{1/3} (|p_j| + ε^{1/3})` are used. `sigma` (per-point standard deviations, all > 0) gives the
/// weights `wᵢ = 1/σᵢ²`; then the covariance is `(JᵀWJ)⁻¹`. Without σ, `wᵢ = 1` and the covariance is
/// `(JᵀJ)⁻¹ · χ²/(N − p)`. Steps solve `(JᵀWJ + λ diag JᵀWJ) δ = JᵀW r`; λ shrinks ×10 on success and
/// grows ×10 on failure; a step that makes the model non-finite counts as a failure. When λ exceeds 10¹⁶ no
/// downhill step exists at machine precision and the fit is reported as converged.
///
/// Errors: mismatched lengths, no parameters, N < p, non-finite data/σ/p0 (or model at p0), σ ≤ 0,
/// a non-finite Jacobian, and a singular `JᵀWJ` at the solution (not positive definite, or some
/// `(JᵀWJ)_jj ((JᵀWJ)⁻¹)_jj ≥ 10⁻³/ε`).
pub fn levenberg_marquardt(
    x: &[f64],
    y: &[f64],
    sigma: Option<&[f64]>,
    p0: &[f64],
    model: Model<'_>,
    jacobian: Option<Jacobian<'_>>,
    options: &LmOptions,
) -> Result<LmFit, FitError> {
    let (n_pts, n_par) = (x.len(), p0.len());
    if y.len() != n_pts {
        return Err(FitError::InvalidInput(format!(
            "x has {n_pts} values, y has {}",
            y.len()
        )));
    }
    if n_par == 0 {
        return Err(FitError::InvalidInput("no parameters".into()));
    }
    if n_pts < n_par {
        return Err(FitError::TooFewPoints {
            points: n_pts,
            needed: n_par,
        });
    }
    if !all_finite(x) || !all_finite(y) {
        return Err(FitError::NonFinite("data"));
    }
    if !all_finite(p0) {
        return Err(FitError::NonFinite("starting parameters"));
    }
    let weights: Vec<f64> = match sigma {
        Some(s) => {
            if s.len() != n_pts {
                return Err(FitError::InvalidInput(format!(
                    "sigma has {} values, expected {n_pts}",
                    s.len()
                )));
            }
            if !all_finite(s) {
                return Err(FitError::NonFinite("sigma"));
            }
            if s.iter().any(|&v| v <= 0.0) {
                return Err(FitError::InvalidInput("sigma must be > 0".into()));
            }
            s.iter().map(|v| 1.0 / (v * v)).collect()
        }
        None => vec![1.0; n_pts],
    };

    let residuals = |p: &[f64]| -> Vec<f64> { x.iter().zip(y).map(|(&xi, &yi)| yi - model(xi, p)).collect() };
    let chi2_of = |r: &[f64]| -> f64 { r.iter().zip(&weights).map(|(ri, wi)| wi * ri * ri).sum() };
    let jacobian_at = |p: &[f64]| -> Result<DMatrix<f64>, FitError> {
        let mut jac = DMatrix::zeros(n_pts, n_par);
        let mut row = vec![0.0; n_par];
        let mut q = p.to_vec();
        for (i, &xi) in x.iter().enumerate() {
            match jacobian {
                Some(jf) => jf(xi, p, &mut row),
                None => {
                    let e3 = f64::EPSILON.cbrt();
                    for j in 0..n_par {
                        let h = e3 * (p[j].abs() + e3);
                        q[j] = p[j] + h;
                        let fp = model(xi, &q);
                        q[j] = p[j] - h;
                        let fm = model(xi, &q);
                        q[j] = p[j];
                        row[j] = (fp - fm) / (2.0 * h);
                    }
                }
            }
            for j in 0..n_par {
                jac[(i, j)] = row[j];
            }
        }
        if jac.iter().all(|v| v.is_finite()) {
            Ok(jac)
        } else {
            Err(FitError::NonFinite("Jacobian"))
        }
    };

    let mut p = p0.to_vec();
    let mut r = residuals(&p);
    if !all_finite(&r) {
        return Err(FitError::NonFinite("model at the starting parameters"));
    }
    let mut chi2 = chi2_of(&r);
    let mut lambda = options.initial_lambda;
    let mut iterations = 0;
    let mut converged = chi2 == 0.0;
    while !converged && iterations < options.max_iterations {
        iterations += 1;
        let jac = jacobian_at(&p)?;
        let (a, g) = normal_equations(&jac, &weights, &r);
        loop {
            let mut damped = a.clone();
            for j in 0..n_par {
                let d = a[(j, j)].max(f64::MIN_POSITIVE);
                damped[(j, j)] += lambda * d;
            }
            let step = damped.cholesky().map(|c| c.solve(&g));
            if let Some(delta) = step.filter(|d| d.iter().all(|v| v.is_finite())) {
                let trial: Vec<f64> = p.iter().zip(delta.iter()).map(|(pi, di)| pi + di).collect();
                let r_trial = residuals(&trial);
                let chi2_trial = chi2_of(&r_trial);
                if chi2_trial.is_finite() && chi2_trial <= chi2 {
                    let small_step = delta
                        .iter()
                        .zip(&p)
                        .all(|(d, pi)| d.abs() <= options.xtol * (pi.abs() + options.xtol));
                    let small_gain = chi2 - chi2_trial <= options.ftol * chi2;
                    p = trial;
                    r = r_trial;
                    chi2 = chi2_trial;
                    lambda = (lambda / 10.0).max(1e-20);
                    converged = small_step || small_gain || chi2 == 0.0;
                    break;
                }
            }
            lambda *= 10.0;
            if lambda > 1e16 {
                converged = true;
                break;
            }
        }
    }

    let jac = jacobian_at(&p)?;
    let (a, _) = normal_equations(&jac, &weights, &r);
    let inverse = a.clone().cholesky().ok_or(FitError::Singular)?.inverse();
    // `A_jj (A⁻¹)_jj ≥ 1`, and it blows up as `A` becomes singular: treat ~1/ε as singular.
    let ill = (0..n_par)
        .any(|j| (a[(j, j)] * inverse[(j, j)]).is_nan() || a[(j, j)] * inverse[(j, j)] >= 1e-3 / f64::EPSILON);
    if ill || !inverse.iter().all(|v| v.is_finite()) {
        return Err(FitError::Singular);
    }
    let dof = n_pts - n_par;
    let reduced_chi2 = if dof > 0 { chi2 / dof as f64 } else { f64::NAN };
    let scale = if sigma.is_some() { 1.0 } else { reduced_chi2 };
    let covariance: Vec<Vec<f64>> = (0..n_par)
        .map(|i| (0..n_par).map(|j| inverse[(i, j)] * scale).collect())
        .collect();
    let standard_errors = (0..n_par).map(|j| covariance[j][j].sqrt()).collect();
    Ok(LmFit {
        parameters: p,
        standard_errors,
        covariance,
        rss: r.iter().map(|v| v * v).sum(),
        chi2,
        reduced_chi2,
        dof,
        iterations,
        converged,
    })
}

/// `(JᵀWJ, JᵀW r)`.
fn normal_equations(jac: &DMatrix<f64>, weights: &[f64], r: &[f64]) -> (DMatrix<f64>, DVector<f64>) {
    let mut wj = jac.clone();
    for (i, &w) in weights.iter().enumerate() {
        wj.row_mut(i).scale_mut(w);
    }
    (wj.transpose() * jac, wj.transpose() * DVector::from_column_slice(r))
}

fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// The data checks of the line fits: as many `x` as `y`, all finite.
fn paired_finite(x: &[f64], y: &[f64]) -> Result<(), FitError> {
    if x.len() != y.len() {
        return Err(FitError::InvalidInput(format!(
            "x has {} values, y has {}",
            x.len(),
            y.len()
        )));
    }
    if !all_finite(x) || !all_finite(y) {
        return Err(FitError::NonFinite("data"));
    }
    Ok(())
}

/// A fit of Roig03 Eq. (44), `f(x) = a xⁿ exp(−x²/b²)`, to a histogram.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpinFit {
    /// Amplitude `a` (counts per unit of `x`^n, as the histogram was given).
    pub a: f64,
    /// Width `b` (> 0; same unit as the bin centres).
    pub b: f64,
    /// Exponent `n` (fixed or fitted).
    pub n: f64,
    /// Standard error of `a`.
    pub sigma_a: f64,
    /// Standard error of `b`.
    pub sigma_b: f64,
    /// Standard error of `n` (0 when `n` was fixed).
    pub sigma_n: f64,
    /// Whether `n` was a free parameter.
    pub n_free: bool,
    /// Residual sum of squares Σ (countᵢ − f(xᵢ))².
    pub rss: f64,
    /// `rss / (N − p)`.
    pub reduced_chi2: f64,
    /// Eq. (45): `∫₀^∞ f(x) dx = ½ a bⁿ⁺¹ Γ((n+1)/2)` (≈ total count × bin width for a good fit).
    pub integral: f64,
    /// The amplitude that makes the integral 1 (Eq. 45): `a₁ = 2 / (bⁿ⁺¹ Γ((n+1)/2))`.
    pub normalised_a: f64,
    /// Number of bins fitted.
    pub points: usize,
    /// Levenberg–Marquardt iterations.
    pub iterations: usize,
    /// Whether the solver converged.
    pub converged: bool,
}

impl SpinFit {
    /// `f(x) = a xⁿ exp(−x²/b²)` with the fitted parameters.
    pub fn evaluate(&self, x: f64) -> f64 {
        spin_model(x, self.a, self.b, self.n)
    }

    /// The normalised curve of Eq. (45): `a₁ xⁿ exp(−x²/b²)`, with `∫₀^∞ = 1`.
    pub fn density(&self, x: f64) -> f64 {
        spin_model(x, self.normalised_a, self.b, self.n)
    }
}

/// Eq. (45): `∫₀^∞ a xⁿ exp(−x²/b²) dx = ½ a bⁿ⁺¹ Γ((n+1)/2)` (finite for `n > −1`, `b > 0`).
pub fn spin_integral(a: f64, b: f64, n: f64) -> f64 {
    0.5 * a * b.abs().powf(n + 1.0) * gamma(0.5 * (n + 1.0))
}

fn spin_model(x: f64, a: f64, b: f64, n: f64) -> f64 {
    if x == 0.0 && n > 0.0 {
        return 0.0;
    }
    a * x.powf(n) * (-(x * x) / (b * b)).exp()
}

/// Fits Roig03 Eq. (44), `f(x) = a xⁿ exp(−x²/b²)`, to a histogram by Levenberg–Marquardt (unweighted, as the
/// paper does: the residual sum of squares is what is compared between exponents).
///
/// `n = Some(n)` fixes the exponent and fits `a`, `b`; `None` fits `a`, `b`, `n`. Starting values: `b` from the
/// histogram mean `x̄` using `x̄ = b Γ((n+2)/2)/Γ((n+1)/2)` (with `n = 1` when free), `a` as the linear
/// least-squares amplitude at that `b`; the free fit starts from the converged fixed `n = 1` fit. Centres must
/// be ≥ 0, counts ≥ 0 and not all zero; a fixed `n` must be > −1.
pub fn fit_spin_histogram(centres: &[f64], counts: &[f64], n: Option<f64>) -> Result<SpinFit, FitError> {
    if centres.len() != counts.len() {
        return Err(FitError::InvalidInput(format!(
            "{} centres, {} counts",
            centres.len(),
            counts.len()
        )));
    }
    if !all_finite(centres) || !all_finite(counts) || n.is_some_and(|v| !v.is_finite()) {
        return Err(FitError::NonFinite("histogram"));
    }
    let needed = if n.is_some() { 2 } else { 3 };
    if centres.len() < needed {
        return Err(FitError::TooFewPoints {
            points: centres.len(),
            needed,
        });
    }
    if centres.iter().any(|&c| c < 0.0) || counts.iter().any(|&c| c < 0.0) {
        return Err(FitError::InvalidInput("centres and counts must be ≥ 0".into()));
    }
    if n.is_some_and(|v| v <= -1.0) {
        return Err(FitError::InvalidInput("exponent n must be > −1".into()));
    }
    let total: f64 = counts.iter().sum();
    if total <= 0.0 {
        return Err(FitError::InvalidInput("empty histogram".into()));
    }
    let mean = centres.iter().zip(counts).map(|(x, c)| x * c).sum::<f64>() / total;
    if mean <= 0.0 {
        return Err(FitError::InvalidInput("histogram mean must be > 0".into()));
    }
    // parameters (a, b) with n fixed, (a, b, n) with n free
    let p0 = match n {
        Some(n0) => {
            let b0 = mean * gamma(0.5 * (n0 + 1.0)) / gamma(0.5 * (n0 + 2.0));
            let (mut num, mut den) = (0.0, 0.0);
            for (&x, &c) in centres.iter().zip(counts) {
                let g = spin_model(x, 1.0, b0, n0);
                num += c * g;
                den += g * g;
            }
            vec![if den > 0.0 { num / den } else { total }, b0]
        }
        None => {
            let fixed = fit_spin_histogram(centres, counts, Some(1.0))?;
            vec![fixed.a, fixed.b, 1.0]
        }
    };
    let n_of = |p: &[f64]| n.unwrap_or_else(|| p[2]);
    let model = |x: f64, p: &[f64]| spin_model(x, p[0], p[1], n_of(p));
    let jac = |x: f64, p: &[f64], d: &mut [f64]| {
        let g = spin_model(x, 1.0, p[1], n_of(p));
        d[0] = g;
        d[1] = p[0] * g * 2.0 * x * x / (p[1] * p[1] * p[1]);
        if n.is_none() {
            d[2] = if x > 0.0 { p[0] * g * x.ln() } else { 0.0 };
        }
    };
    let lm = levenberg_marquardt(centres, counts, None, &p0, &model, Some(&jac), &LmOptions::default())?;
    let p = &lm.parameters;
    let (a, b) = (p[0], p[1].abs());
    let (n_fit, sigma_n) = match n {
        Some(v) => (v, 0.0),
        None => (p[2], lm.standard_errors[2]),
    };
    let integral = spin_integral(a, b, n_fit);
    Ok(SpinFit {
        a,
        b,
        n: n_fit,
        sigma_a: lm.standard_errors[0],
        sigma_b: lm.standard_errors[1],
        sigma_n,
        n_free: n.is_none(),
        rss: lm.rss,
        reduced_chi2: lm.reduced_chi2,
        integral,
        normalised_a: spin_integral(1.0, b, n_fit).recip(),
        points: centres.len(),
        iterations: lm.iterations,
        converged: lm.converged,
    })
}

/// Fits of Eq. (44) for several fixed exponents plus the free-`n` fit (Roig03 §4.3 compares n = ½ with the
/// Maxwellian n = 2).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExponentComparison {
    /// One fit per requested exponent, in the order given.
    pub fixed: Vec<SpinFit>,
    /// The fit with `n` free, or `None` when it failed.
    pub free: Option<SpinFit>,
    /// The requested exponent whose fit has the smallest residual sum of squares.
    pub best_n: f64,
}

/// Fits Eq. (44) with each exponent in `exponents` (fixed) and with `n` free; `best_n` is the fixed exponent
/// with the smallest residual sum of squares. Fails when `exponents` is empty or any fixed fit fails; a failed
/// free fit is reported as `free: None`.
pub fn compare_exponents(centres: &[f64], counts: &[f64], exponents: &[f64]) -> Result<ExponentComparison, FitError> {
    if exponents.is_empty() {
        return Err(FitError::InvalidInput("no exponents to compare".into()));
    }
    let fixed = exponents
        .iter()
        .map(|&n| fit_spin_histogram(centres, counts, Some(n)))
        .collect::<Result<Vec<_>, _>>()?;
    let best_n = fixed
        .iter()
        .min_by(|p, q| p.rss.total_cmp(&q.rss))
        .map(|f| f.n)
        .unwrap_or(f64::NAN);
    let free = fit_spin_histogram(centres, counts, None).ok();
    Ok(ExponentComparison { fixed, free, best_n })
}

/// A straight line `y = slope · x + intercept` by ordinary least squares.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LineFit {
    /// Slope.
    pub slope: f64,
    /// Intercept.
    pub intercept: f64,
    /// Standard error of the slope (from the residual variance, N − 2 dof; NaN when N = 2).
    pub sigma_slope: f64,
    /// Standard error of the intercept (NaN when N = 2).
    pub sigma_intercept: f64,
    /// Covariance of slope and intercept (NaN when N = 2).
    pub covariance: f64,
    /// Coefficient of determination r² (1 when all y are equal and fitted exactly).
    pub r_squared: f64,
    /// Residual sum of squares.
    pub rss: f64,
    /// Number of points.
    pub points: usize,
}

/// Ordinary least-squares line through `(x, y)`: needs ≥ 2 points with distinct x, all finite.
/// Standard errors use `s² = rss/(N − 2)`: `σ_slope² = s²/Sxx`, `σ_intercept² = s² (1/N + x̄²/Sxx)`,
/// `cov = −x̄ s²/Sxx`.
pub fn fit_line(x: &[f64], y: &[f64]) -> Result<LineFit, FitError> {
    paired_finite(x, y)?;
    let n = x.len();
    if n < 2 {
        return Err(FitError::TooFewPoints { points: n, needed: 2 });
    }
    let nf = n as f64;
    let (xm, ym) = (x.iter().sum::<f64>() / nf, y.iter().sum::<f64>() / nf);
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for (&xi, &yi) in x.iter().zip(y) {
        sxx += (xi - xm) * (xi - xm);
        sxy += (xi - xm) * (yi - ym);
        syy += (yi - ym) * (yi - ym);
    }
    if sxx <= 0.0 {
        return Err(FitError::Singular);
    }
    let slope = sxy / sxx;
    let intercept = ym - slope * xm;
    let rss: f64 = x
        .iter()
        .zip(y)
        .map(|(&xi, &yi)| (yi - slope * xi - intercept).powi(2))
        .sum();
    let s2 = if n > 2 { rss / (nf - 2.0) } else { f64::NAN };
    Ok(LineFit {
        slope,
        intercept,
        sigma_slope: (s2 / sxx).sqrt(),
        sigma_intercept: (s2 * (1.0 / nf + xm * xm / sxx)).sqrt(),
        covariance: -xm * s2 / sxx,
        r_squared: if syy > 0.0 { 1.0 - rss / syy } else { 1.0 },
        rss,
        points: n,
    })
}

/// Where a fitted line reaches a level.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LineCrossing {
    /// `x₀ = (y₀ − intercept)/slope`.
    pub x: f64,
    /// Propagated standard error of `x₀` (first order, with the slope–intercept covariance).
    pub sigma_x: f64,
}

/// The `x` where `fit` crosses `y0` (e.g. Q*_D: bound fraction vs Q crossing 0.5), with
/// `σ_x² = (σ_c² + x₀² σ_m² + 2 x₀ cov(m, c)) / m²` for slope `m` and intercept `c`.
/// Errors on a zero (or non-finite) slope or a non-finite `y0`.
pub fn line_crossing(fit: &LineFit, y0: f64) -> Result<LineCrossing, FitError> {
    if !y0.is_finite() || !fit.slope.is_finite() || !fit.intercept.is_finite() {
        return Err(FitError::NonFinite("line or level"));
    }
    if fit.slope == 0.0 {
        return Err(FitError::Singular);
    }
    let x0 = (y0 - fit.intercept) / fit.slope;
    let var = (fit.sigma_intercept.powi(2) + x0 * x0 * fit.sigma_slope.powi(2) + 2.0 * x0 * fit.covariance)
        / (fit.slope * fit.slope);
    Ok(LineCrossing {
        x: x0,
        sigma_x: var.max(0.0).sqrt(),
    })
}

/// A power law `y = c x^α`, fitted as a line in `(ln x, ln y)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PowerLawFit {
    /// Exponent α.
    pub alpha: f64,
    /// Prefactor `c`.
    pub c: f64,
    /// Standard error of α.
    pub sigma_alpha: f64,
    /// Standard error of `c` (first order: `c · σ(ln c)`).
    pub sigma_c: f64,
    /// r² of the log–log line.
    pub r_squared: f64,
    /// Points used (x > 0 and y > 0).
    pub points: usize,
    /// Points skipped because x ≤ 0 or y ≤ 0.
    pub skipped: usize,
}

/// Fits `y = c x^α` by least squares on `ln y = ln c + α ln x`. Pairs with `x ≤ 0` or `y ≤ 0` are skipped
/// (counted in `skipped`); NaN/∞ anywhere is an error, as are fewer than 3 usable points.
pub fn fit_power_law(x: &[f64], y: &[f64]) -> Result<PowerLawFit, FitError> {
    paired_finite(x, y)?;
    let (lx, ly): (Vec<f64>, Vec<f64>) = x
        .iter()
        .zip(y)
        .filter(|(xi, yi)| **xi > 0.0 && **yi > 0.0)
        .map(|(xi, yi)| (xi.ln(), yi.ln()))
        .unzip();
    if lx.len() < 3 {
        return Err(FitError::TooFewPoints {
            points: lx.len(),
            needed: 3,
        });
    }
    let line = fit_line(&lx, &ly)?;
    let c = line.intercept.exp();
    Ok(PowerLawFit {
        alpha: line.slope,
        c,
        sigma_alpha: line.sigma_slope,
        sigma_c: c * line.sigma_intercept,
        r_squared: line.r_squared,
        points: lx.len(),
        skipped: x.len() - lx.len(),
    })
}

/// Equal-width histogram of `values` with `bins` bins over `range` (`None`: `[min, max]` of the values).
/// Returns `(centres, counts)`; values outside the range are ignored, the upper edge belongs to the last bin.
/// Errors: `bins = 0`, no values (with `range = None`), NaN/∞ values, or an empty/non-finite range.
pub fn histogram(values: &[f64], bins: usize, range: Option<(f64, f64)>) -> Result<(Vec<f64>, Vec<f64>), FitError> {
    if bins == 0 {
        return Err(FitError::InvalidInput("zero bins".into()));
    }
    if !all_finite(values) {
        return Err(FitError::NonFinite("values"));
    }
    let (lo, hi) = match range {
        Some(r) => r,
        None => {
            if values.is_empty() {
                return Err(FitError::TooFewPoints { points: 0, needed: 1 });
            }
            values
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)))
        }
    };
    if !lo.is_finite() || !hi.is_finite() || hi <= lo {
        return Err(FitError::InvalidInput(format!("bad histogram range [{lo}, {hi}]")));
    }
    let width = (hi - lo) / bins as f64;
    let centres = (0..bins).map(|i| lo + (i as f64 + 0.5) * width).collect();
    let mut counts = vec![0.0; bins];
    for &v in values {
        if v < lo || v > hi {
            continue;
        }
        let i = (((v - lo) / width) as usize).min(bins - 1);
        counts[i] += 1.0;
    }
    Ok((centres, counts))
}
