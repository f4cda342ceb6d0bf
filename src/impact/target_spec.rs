//! What a rubble-pile target build is asked for ([`TargetSpec`], with Roig03 Table 1's targets) and why it can fail
//! ([`TargetError`]): below both the build (`target.rs`) and its checkpoints (`target_checkpoint.rs`), which both
//! use them, so that neither imports the other for them (Roig et al. 2003, §3 and Table 1).

use crate::ellipsoid::calibration::{CalibrationError, KappaReading};
use crate::integrate::IntegrateError;

/// What to build. Lengths in m, masses in kg, times in s unless the name says otherwise.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TargetSpec {
    /// Number of fragments N (≥ 2).
    pub fragments: usize,
    /// Spin period of the pile (hours; converted at the edge).
    pub period_hours: f64,
    /// Seed of every random choice.
    pub seed: u64,
    /// Equivalent radius of the largest fragment (m).
    pub r_largest: f64,
    /// Equivalent radius of the smallest fragment (m).
    pub r_smallest: f64,
    /// Total mass aimed at (kg).
    pub total_mass: f64,
    /// Relative tolerance on the total mass (dimensionless).
    pub mass_tolerance: f64,
    /// Fragment density (kg m⁻³).
    pub density: f64,
    /// Axis ratios B/A and C/A.
    pub axis_ratios: [f64; 2],
    /// Exponent of the cumulative size distribution `N(>R) ∝ R^−slope`.
    pub slope: f64,
    /// β and v (m/s) of Roig03 Eq. 14 for κ.
    pub calibrate: [f64; 2],
    /// Dissipation coefficient F0 used while relaxing (s m⁻²).
    pub f0: f64,
    /// Relative tolerance of the relaxation run (Bulirsch–Stoer).
    pub rtol: f64,
    /// Rigidity criterion: `K_rel / K` below this ends a relaxation round.
    pub rigidity: f64,
    /// Largest simulated relaxation time per round (s) before giving up.
    pub max_relax_time: f64,
    /// Whether fragments outside the pile's main clump are removed at the end of every round (before the spin is
    /// reset; see `drop_detached` in `target.rs`). Off for the committed targets, whose bits it would change; absent from
    /// their files.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub drop_detached: bool,
    /// Which kinetic energy Roig03 Eq. 13's barrier is β times when κ is calibrated over the target's smallest
    /// and largest fragments ([`KappaReading`]). Printed (the default) for the committed targets, absent from
    /// their files; `reduced` relaxes the pile at the κ of the impacts (`analysis/roig2003/campaign.toml`).
    #[serde(default, skip_serializing_if = "is_default")]
    pub kappa_reading: KappaReading,
}

/// Whether `x` is its type's default (a field `serde` leaves out of the files).
pub(crate) fn is_default<T: Default + PartialEq>(x: &T) -> bool {
    *x == T::default()
}

impl TargetSpec {
    /// The Table 1 target with `fragments`, or any count with both size limits given (km; `r_largest_km`,
    /// `r_smallest_km`: the other Table 1 defaults of the 30-fragment target kept); an error names the option.
    pub fn table1_or_sizes(
        fragments: usize,
        period_hours: f64,
        seed: u64,
        r_largest_km: Option<f64>,
        r_smallest_km: Option<f64>,
    ) -> Result<Self, String> {
        match (
            TargetSpec::table1(fragments, period_hours, seed),
            r_largest_km,
            r_smallest_km,
        ) {
            (_, Some(large), Some(small)) => {
                let mut s = TargetSpec::table1(30, period_hours, seed).expect("Table 1 has N = 30");
                s.fragments = fragments;
                s.r_largest = large * 1e3;
                s.r_smallest = small * 1e3;
                Ok(s)
            }
            (Some(s), None, None) => Ok(s),
            _ => Err(format!(
                "--fragments {fragments}: Table 1 has only 30, 100 and 200; give both --r-largest-km and --r-smallest-km"
            )),
        }
    }

    /// The Roig03 Table 1 target with `fragments` ∈ {30, 100, 200} (64→16, 60→10, 59→7 km), or `None`.
    pub fn table1(fragments: usize, period_hours: f64, seed: u64) -> Option<Self> {
        let (r_largest, r_smallest) = match fragments {
            30 => (64e3, 16e3),
            100 => (60e3, 10e3),
            200 => (59e3, 7e3),
            _ => return None,
        };
        Some(TargetSpec {
            fragments,
            period_hours,
            seed,
            r_largest,
            r_smallest,
            total_mass: 1.0e19,
            mass_tolerance: 0.005,
            density: 3000.0,
            axis_ratios: [0.7, 0.5],
            slope: 2.5,
            calibrate: [10.0, 5000.0],
            f0: 1e-4,
            rtol: 1e-8,
            rigidity: 1e-4,
            max_relax_time: 2e5,
            drop_detached: false,
            kappa_reading: KappaReading::Printed,
        })
    }
}

/// Why a target could not be built.
#[derive(Debug, thiserror::Error)]
pub enum TargetError {
    /// An input out of range (one line naming it).
    #[error("{0}")]
    Invalid(String),
    /// κ could not be calibrated.
    #[error(transparent)]
    Calibration(#[from] CalibrationError),
    /// The relaxation run failed.
    #[error("relaxation failed: {0}")]
    Integration(#[from] IntegrateError),
    /// The pile did not become rigid in time.
    #[error("the pile did not become rigid within {time:.0} s of relaxation (K_rel/K = {fraction:e})")]
    NotRigid {
        /// Simulated time spent (s).
        time: f64,
        /// Last `K_rel / K`.
        fraction: f64,
    },
}
