//! κ and the contact amplitude `U0_ij` (Roig03 Eqs. 11–14).
//!
//! For two spheres of radii `R_i, R_j` the pair potential `U_C + U_G` has its minimum exactly at
//! `|r_i − r_j| = R_i + R_j` when `U0_ij` is Eq. 11; there `U_C/|U_G| = 1/(2κλ_ij)` with `λ_ij` of Eq. 12.
//! Ellipsoids use their equivalent radius `(ABC)^{1/3}` (the paper's rule).

use serde::{Deserialize, Serialize};

/// Why κ could not be calibrated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CalibrationError {
    /// Eq. 14 has no root with κ > 3/2 for the given β and v.
    #[error(
        "model.calibrate: no kappa > 3/2 solves Roig03 Eq. 14 for beta = {beta}, v = {v} m/s; need v^2 > {v2_min:e} m^2/s^2 (raise v or beta)"
    )]
    Unreachable {
        /// β given.
        beta: f64,
        /// v given (m/s).
        v: f64,
        /// Minimum v² (m²/s²) for κ > 3/2 at this β.
        v2_min: f64,
    },
    /// β, v, radii, mass or G not positive and finite.
    #[error("model.calibrate: {field} must be > 0 and finite, got {value}")]
    BadInput {
        /// Which input.
        field: &'static str,
        /// Its value.
        value: f64,
    },
}

/// `λ_ij = (R_i + R_j)² / (R_i² + R_j²)` (Roig03 Eq. 12), `1 < λ ≤ 2`.
pub fn lambda(r_i: f64, r_j: f64) -> f64 {
    (r_i + r_j).powi(2) / (r_i * r_i + r_j * r_j)
}

/// The pair prefactor `U0_ij m_i m_j (κ/π)^{3/2}` (J m³), with `U0_ij = G π^{3/2}/2 (R_i+R_j)² exp(κλ)/(κλ)^{5/2}`
/// (Roig03 Eq. 11, such that `U_C = U0 ∫ρ_iρ_j d³r` is an energy), so that
/// `U_C = prefactor · det(G)^{−1/2} · exp(−κ Δᵀ G⁻¹ Δ)` (the note's cheaper form of Eq. 10).
///
/// Evaluated without `powf` (it runs for every interacting pair at every RHS evaluation):
/// `U0 (κ/π)^{3/2} = ½ G (R_i+R_j)² e^{κλ} / (κ λ^{5/2})`.
pub fn pair_prefactor(g: f64, kappa: f64, r_i: f64, m_i: f64, r_j: f64, m_j: f64) -> f64 {
    let sum = r_i + r_j;
    let lam = sum * sum / (r_i * r_i + r_j * r_j);
    0.5 * g * sum * sum * (kappa * lam).exp() / (kappa * lam * lam * lam.sqrt()) * m_i * m_j
}

/// Which kinetic energy `K` the barrier of Roig03 Eq. 13 is measured against, for the pair of the smallest
/// (`k`, mass `m_k`) and the largest body (`l`, mass `m_l`).
///
/// With spheres of the equivalent radii, the left side of Eq. 13 (the pair's contact energy at full
/// overlap) is `G m_k m_l e^{κλ} / (2 (R_k + R_l) κλ)`. Setting it to `β · ½ M_K v²` gives
/// `e^{κλ}/(κλ) = β v² (R_k + R_l) / (G M_ref)` with `M_ref = m_k m_l / M_K`:
///
/// | reading | `K` | `M_ref` (Eq. 14's denominator over G) |
/// | --- | --- | --- |
/// | [`Printed`](Self::Printed) | `½ m_l v²` (Roig03's words after Eq. 13) | `m_k` (Eq. 14 as printed) |
/// | [`Impactor`](Self::Impactor) | `½ m_k v²` (the light body moving at `v`) | `m_l` |
/// | [`Reduced`](Self::Reduced) | `½ μ v²`, `μ = m_k m_l/(m_k + m_l)` (the pair's collision energy in its centre-of-mass frame) | `m_k + m_l` |
///
/// The printed reading protects against the heavy body's kinetic energy, which is `m_l/μ` times more than
/// a collision at relative speed `v` can bring into the contact; for the impact targets it gives κ = 13–17,
/// where Roig03 §4.3 states "κ ≃ 10 in all our examples". The other two give 9.6–11.4 (see
/// `analysis/roig2003/DISCUSSION.md`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum KappaReading {
    /// `K = ½ m_l v²`: Eq. 14 exactly as printed (the default).
    #[default]
    Printed,
    /// `K = ½ m_k v²`: the kinetic energy of the light, impacting body.
    Impactor,
    /// `K = ½ μ v²`: the relative kinetic energy of the pair (reduced mass μ).
    Reduced,
}

impl KappaReading {
    /// Every reading, in the order of the table above.
    pub const ALL: [KappaReading; 3] = [KappaReading::Printed, KappaReading::Impactor, KappaReading::Reduced];

    /// The mass `M_ref` (kg) that divides `G` in Eq. 14 for a pair of masses `m_small ≤ m_large` (kg).
    pub fn reference_mass(self, m_small: f64, m_large: f64) -> f64 {
        match self {
            KappaReading::Printed => m_small,
            KappaReading::Impactor => m_large,
            KappaReading::Reduced => m_small + m_large,
        }
    }

    /// `"printed"`, `"impactor"` or `"reduced"` (the scene and command-line spelling).
    pub fn as_str(self) -> &'static str {
        match self {
            KappaReading::Printed => "printed",
            KappaReading::Impactor => "impactor",
            KappaReading::Reduced => "reduced",
        }
    }
}

impl std::fmt::Display for KappaReading {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::str::FromStr for KappaReading {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        KappaReading::ALL
            .into_iter()
            .find(|r| r.as_str() == s)
            .ok_or_else(|| format!("expected one of printed, impactor, reduced; got {s:?}"))
    }
}

/// κ from Roig03 Eq. 14 for the smallest (`r_small`, `m_small`) and the largest body (`r_large`,
/// `m_large`) under a [`KappaReading`]: [`calibrate_kappa`] with that reading's `M_ref`.
pub fn calibrate_kappa_read(
    reading: KappaReading,
    beta: f64,
    v: f64,
    (r_small, m_small): (f64, f64),
    (r_large, m_large): (f64, f64),
    g: f64,
) -> Result<f64, CalibrationError> {
    calibrate_kappa(beta, v, r_small, reading.reference_mass(m_small, m_large), r_large, g)
}

/// Solves Roig03 Eq. 14 for κ: `exp(κλ)/(κλ) = β v² (R_k + R_l)/(G m_ref)`, where `k` is the smallest
/// (equivalent radius `r_small`) and `l` the largest body (`r_large`), and `m_ref` is the mass in the
/// denominator: the smallest body's mass `m_k` as printed, otherwise [`KappaReading::reference_mass`].
/// Newton on `x = κλ` on the branch `x > 1`; refuses when the root has κ ≤ 3/2.
///
/// ```
/// use rubblepile::ellipsoid::calibration::{calibrate_kappa, lambda};
/// let (g, r, m) = (6.674e-11, 1000.0, 1.2566e13);
/// let kappa = calibrate_kappa(10.0, 5.0, r, m, r, g).unwrap();
/// let x = kappa * lambda(r, r);
/// let rhs = 10.0 * 25.0 * 2.0 * r / (g * m);
/// assert!(((x.exp() / x) / rhs - 1.0).abs() < 1e-12);
/// ```
pub fn calibrate_kappa(
    beta: f64,
    v: f64,
    r_small: f64,
    m_ref: f64,
    r_large: f64,
    g: f64,
) -> Result<f64, CalibrationError> {
    for (field, value) in [
        ("beta", beta),
        ("v", v),
        ("smallest body's radius", r_small),
        ("reference mass", m_ref),
        ("largest body's radius", r_large),
        ("G", g),
    ] {
        if !(value > 0.0 && value.is_finite()) {
            return Err(CalibrationError::BadInput { field, value });
        }
    }
    let lam = lambda(r_small, r_large);
    let rhs = beta * v * v * (r_small + r_large) / (g * m_ref);
    // κ > 3/2  ⇔  x > 1.5 λ; exp(x)/x is increasing for x > 1.
    let x_min = 1.5 * lam;
    let unreachable = || CalibrationError::Unreachable {
        beta,
        v,
        v2_min: x_min.exp() / x_min * g * m_ref / (beta * (r_small + r_large)),
    };
    // (written so that a NaN right side is refused too)
    if rhs.is_nan() || rhs <= x_min.exp() / x_min {
        return Err(unreachable());
    }
    // f(x) = x − ln x − ln(rhs) is convex and increasing for x > 1: Newton from the right converges monotonically.
    let ln_rhs = rhs.ln();
    let mut x = (ln_rhs + ln_rhs.ln().max(0.0) + 1.0).max(x_min + 1.0);
    for _ in 0..200 {
        let f = x - x.ln() - ln_rhs;
        let step = f / (1.0 - 1.0 / x);
        x -= step;
        if step.abs() <= 1e-15 * x {
            break;
        }
    }
    let kappa = x / lam;
    if kappa > 1.5 && kappa.is_finite() {
        Ok(kappa)
    } else {
        Err(unreachable())
    }
}

#[cfg(test)]
impl KappaReading {
    /// The mass `M_K` (kg) of `K = ½ M_K v²` for a pair of masses `m_small ≤ m_large` (kg).
    pub(crate) fn kinetic_mass(self, m_small: f64, m_large: f64) -> f64 {
        match self {
            KappaReading::Printed => m_large,
            KappaReading::Impactor => m_small,
            KappaReading::Reduced => m_small * m_large / (m_small + m_large),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const G: f64 = 6.674e-11;

    /// The contact energy of two spheres at full overlap, `U_C(Δ = 0)` of the note's form of Eq. 10.
    fn full_overlap_energy(kappa: f64, (r_k, m_k): (f64, f64), (r_l, m_l): (f64, f64)) -> f64 {
        let det_g = (r_k * r_k + r_l * r_l).powi(3);
        pair_prefactor(G, kappa, r_k, m_k, r_l, m_l) / det_g.sqrt()
    }

    /// Each reading's κ satisfies Eq. 13 with its own `K`: the barrier is β·½ M_K v², and the three
    /// readings' barriers stand in the ratio of their kinetic masses.
    #[test]
    fn each_reading_balances_eq13_with_its_kinetic_energy() {
        let (small, large) = ((900.0, 1.5e13), (4200.0, 9.0e14));
        let (beta, v) = (10.0, 5000.0);
        for reading in KappaReading::ALL {
            let kappa = calibrate_kappa_read(reading, beta, v, small, large, G).unwrap();
            let barrier = full_overlap_energy(kappa, small, large);
            let k = 0.5 * reading.kinetic_mass(small.1, large.1) * v * v;
            assert!(
                (barrier / (beta * k) - 1.0).abs() < 1e-10,
                "{reading}: barrier {barrier:e}, βK {:e}",
                beta * k
            );
        }
    }

    /// The printed reading protects against the heaviest body's energy, so it needs the stiffest κ; the
    /// reduced reading the softest (μ < m_k < m_l).
    #[test]
    fn readings_order_kappa_printed_impactor_reduced() {
        let (small, large) = ((900.0, 1.5e13), (4200.0, 9.0e14));
        let k = |r| calibrate_kappa_read(r, 10.0, 5000.0, small, large, G).unwrap();
        let (p, i, r) = (
            k(KappaReading::Printed),
            k(KappaReading::Impactor),
            k(KappaReading::Reduced),
        );
        assert!(p > i && i > r, "printed {p}, impactor {i}, reduced {r}");
        // the printed reading is `calibrate_kappa` with the small mass, unchanged
        assert_eq!(p, calibrate_kappa(10.0, 5000.0, small.0, small.1, large.0, G).unwrap());
    }

    #[test]
    fn reading_names_round_trip_and_bad_names_are_refused() {
        for r in KappaReading::ALL {
            assert_eq!(r.as_str().parse::<KappaReading>(), Ok(r));
        }
        let err = "mu".parse::<KappaReading>().unwrap_err();
        assert!(err.contains("printed, impactor, reduced"), "{err}");
    }
}
