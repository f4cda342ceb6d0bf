//! The model atmosphere of Richardson11 §3.1: elastic spheres of three masses in a vertical cylinder on a plane under
//! uniform gravity should reach equipartition, each species' heights (bottom surface above the plane) exponential
//! with scale height `h_m = kT/(m g)` (ideal isothermal atmosphere in hydrostatic equilibrium).
//!
//! Temperature: each free particle carries `E_i = ½ m v² + ½ I ω² + m g (z − R)` (its energy above the ground state,
//! resting on the plane); three translational degrees of freedom hold `(3/2) kT` and the exponential height law
//! `⟨m g (z − R)⟩ = kT`, so `⟨E_i⟩ = (5/2) kT` and `kT = (2/5) E / N` with `E` the total energy above the ground state
//! (Richardson11 Eqs. 29–31). Spin stays zero with smooth spheres (ε_t = 1), so the ½ I ω² term is zero there; it is
//! kept so the budget stays complete. `E` is taken at t = 0 (it is conserved; the run's drift is reported).
//!
//! Statistics: the maximum-likelihood scale height of an exponential is the mean height (Richardson11 Eq. 28); the
//! Kolmogorov–Smirnov probability of each species' heights is computed against the exponential law with `statrs`
//! ([`ks_exponential`]), once with the measured mean height and once with the equipartition value. The paper's
//! caveat applies: with the scale fitted from the same data the formal KS probability is biased high.

use rubblepile::analysis::AnalysisError;
use rubblepile::math::{mean, mean_std};
use std::path::{Path, PathBuf};

use statrs::distribution::Exp;
use statrs::stats_tests::NaNPolicy;
use statrs::stats_tests::ks_test::{KSOneSampleAlternativeMethod, ks_onesample};

use rubblepile::granular::hard::scene::{ParticleRow, read_particles_csv};

/// The snapshot fractions of the run at which KS probabilities are averaged (Richardson11 §3.1).
pub const KS_FRACTIONS: [f64; 6] = [0.5, 0.6, 0.7, 0.8, 0.9, 1.0];

/// Heights of one species.
#[derive(Debug, Clone, PartialEq)]
pub struct SpeciesHeights {
    /// Particle mass (kg).
    pub mass: f64,
    /// Heights of the bottom surfaces above the plane (m).
    pub heights: Vec<f64>,
}

/// Splits free particles by mass (sorted, lightest first) and returns their heights `z − R − plane_z`.
/// Rows: a snapshot's rows ([`read_particles_csv`]); stuck particles are skipped.
pub fn species_heights(rows: &[ParticleRow], plane_z: f64) -> Vec<SpeciesHeights> {
    let mut out: Vec<SpeciesHeights> = Vec::new();
    for r in rows.iter().filter(|r| r.stuck_to.is_none()) {
        let (m, radius, z) = (r.values[2], r.values[3], r.values[6]);
        let h = z - radius - plane_z;
        match out.iter_mut().find(|s| s.mass == m) {
            Some(s) => s.heights.push(h),
            None => out.push(SpeciesHeights {
                mass: m,
                heights: vec![h],
            }),
        }
    }
    out.sort_by(|a, b| a.mass.total_cmp(&b.mass));
    out
}

/// Energy above the ground state (J): `Σ ½ m v² + ½ I ω² + m g (z − R − plane_z)` over the free particles, with
/// `I = (2/5) m R²` and `g` the magnitude of the downward field (m/s²).
pub fn energy_above_ground(rows: &[ParticleRow], g: f64, plane_z: f64) -> f64 {
    rows.iter()
        .filter(|r| r.stuck_to.is_none())
        .map(|r| {
            let v = &r.values;
            let (m, radius) = (v[2], v[3]);
            let v2 = v[7] * v[7] + v[8] * v[8] + v[9] * v[9];
            let w2 = v[10] * v[10] + v[11] * v[11] + v[12] * v[12];
            0.5 * m * v2 + 0.2 * m * radius * radius * w2 + m * g * (v[6] - radius - plane_z)
        })
        .sum()
}

/// `kT = (2/5) E / N` (J) from equipartition over N particles holding energy `E` above the ground state.
pub fn equipartition_kt(energy: f64, n: usize) -> f64 {
    0.4 * energy / n as f64
}

/// Scale height `kT / (m g)` (m).
pub fn scale_height(kt: f64, mass: f64, g: f64) -> f64 {
    kt / (mass * g)
}

/// Kolmogorov–Smirnov test of `heights` against the exponential law `1 − exp(−z/h)`: the statistic D and the
/// two-sided probability (asymptotic Kolmogorov distribution, `statrs`). Errors: fewer than 2 heights, a scale
/// height that is not positive and finite.
pub fn ks_exponential(heights: &[f64], h: f64) -> Result<(f64, f64), AnalysisError> {
    if !(h.is_finite() && h > 0.0) {
        return Err(format!("scale height must be positive and finite, got {h}").into());
    }
    let law = Exp::new(1.0 / h).map_err(|e| format!("exponential law of scale {h}: {e}"))?;
    ks_onesample(
        heights.to_vec(),
        &law,
        KSOneSampleAlternativeMethod::TwoSidedAsymptotic,
        NaNPolicy::Error,
    )
    .map_err(|e| AnalysisError::Input(format!("KS test on {} heights: {e:?}", heights.len())))
}

/// One snapshot of a run reduced to per-species numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct SnapshotStats {
    /// Time (s).
    pub t: f64,
    /// Mean height per species (m), lightest first.
    pub mean_heights: Vec<f64>,
}

/// KS probabilities at one snapshot, per species.
#[derive(Debug, Clone, PartialEq)]
pub struct KsAt {
    /// Fraction of the run.
    pub fraction: f64,
    /// Snapshot time (s).
    pub t: f64,
    /// Probability against the exponential with the measured mean height, per species.
    pub p_measured: Vec<f64>,
    /// Probability against the exponential with the equipartition scale height, per species.
    pub p_expected: Vec<f64>,
}

/// The analysis of one atmosphere run directory.
#[derive(Debug, Clone)]
pub struct AtmosphereRun {
    /// The run directory.
    pub dir: PathBuf,
    /// Cylinder radius (m), from the run's `scene.toml`.
    pub cylinder_radius: f64,
    /// Species masses (kg), lightest first.
    pub masses: Vec<f64>,
    /// Particles per species.
    pub counts: Vec<usize>,
    /// Energy above the ground state at t = 0 (J).
    pub energy0: f64,
    /// Relative change of that energy at the last snapshot.
    pub energy_drift: f64,
    /// `kT = (2/5) E0 / N` (J).
    pub kt: f64,
    /// Equipartition scale heights per species (m).
    pub expected: Vec<f64>,
    /// Per snapshot, in time order.
    pub snapshots: Vec<SnapshotStats>,
    /// Mean over the snapshots from 50 % to 100 % of the run of the mean heights, per species, and their
    /// standard deviation.
    pub late_mean_heights: Vec<(f64, f64)>,
    /// KS probabilities at [`KS_FRACTIONS`] of the run.
    pub ks: Vec<KsAt>,
    /// Heights per species at the last snapshot (for the KS-curve figure).
    pub final_heights: Vec<Vec<f64>>,
    /// `(t, (E − E0)/scale)` from `timeseries.csv` (the run's total-energy record).
    pub energy_series: Vec<(f64, f64)>,
    /// From `summary.json`: events per wall-clock second, collisions, wall seconds, max overlap, neighbour builds.
    pub events_per_second: f64,
    /// Collisions applied.
    pub collisions: u64,
    /// Wall-clock seconds of the run.
    pub wall_seconds: f64,
    /// Largest overlap at a collision (fraction of the radius).
    pub max_overlap: f64,
    /// Steps taken.
    pub steps: u64,
}

fn json_f64(v: &serde_json::Value, key: &str) -> f64 {
    v[key].as_f64().unwrap_or(f64::NAN)
}

/// What the analyses read from a finished hard-sphere run directory: its `scene.toml` copy (as TOML: the particles
/// file is not in the run directory), the downward gravity magnitude, `summary.json` and the snapshot files in index
/// order.
#[derive(Debug, Clone)]
pub struct RunFiles {
    /// The scene copy.
    pub scene: toml::Value,
    /// `−g_z` (m/s²), > 0.
    pub g: f64,
    /// `summary.json`.
    pub summary: serde_json::Value,
    /// `snapshots/<k>.csv`, by k.
    pub snapshots: Vec<PathBuf>,
}

/// The summary of a run that has no `summary.json` (stopped before its end), from its `timeseries.csv`:
/// `status = "interrupted"`, `t_reached` and `wall_seconds` of the last row, `collisions` the sum of the per-row
/// counts, `events_per_second` their ratio, `energy_error` the largest |energy_residual| of the rows (when the
/// column is there). `None` without a time series or with no data row.
pub fn interrupted_summary(dir: &Path) -> Option<serde_json::Value> {
    let text = std::fs::read_to_string(dir.join("timeseries.csv")).ok()?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next()?.split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name);
    let (it, ic, iw) = (col("t")?, col("collisions")?, col("wall_seconds")?);
    let ie = col("energy_residual");
    let (mut t, mut collisions, mut wall, mut residual) = (None, 0.0, f64::NAN, None::<f64>);
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let v: Vec<f64> = line.split(',').map(|x| x.trim().parse().unwrap_or(f64::NAN)).collect();
        t = Some(*v.get(it)?);
        collisions += v.get(ic).copied().unwrap_or(0.0);
        wall = v.get(iw).copied().unwrap_or(f64::NAN);
        if let Some(e) = ie.and_then(|k| v.get(k)).filter(|e| e.is_finite()) {
            residual = Some(residual.map_or(e.abs(), |r| r.max(e.abs())));
        }
    }
    let mut summary = serde_json::json!({
        "status": "interrupted",
        "t_reached": t?,
        "wall_seconds": wall,
        "collisions": collisions as u64,
        "events_per_second": collisions / wall,
    });
    if let Some(e) = residual {
        summary["energy_error"] = serde_json::json!(e);
    }
    Some(summary)
}

/// Reads [`RunFiles`]; errors (one line, naming the file) when a file is missing or gravity does not point down. A
/// run without `summary.json` but with a time series is read as interrupted ([`interrupted_summary`]).
pub fn read_run_files(dir: &Path) -> Result<RunFiles, AnalysisError> {
    let sp = dir.join("scene.toml");
    let text = std::fs::read_to_string(&sp).map_err(|e| format!("{}: {e}", sp.display()))?;
    // A scene copy of an older run may use the old names: read it as its migrated text.
    let text = rubblepile::granular::migrate::migrate(&text).text;
    let scene: toml::Value = toml::from_str(&text).map_err(|e| format!("{}: {e}", sp.display()))?;
    let g = scene
        .get("gravity")
        .and_then(|x| x.get("uniform"))
        .and_then(|x| x.as_array())
        .and_then(|a| a.get(2))
        .and_then(|x| x.as_float())
        .map(|gz| -gz)
        .filter(|g| *g > 0.0)
        .ok_or_else(|| format!("{}: gravity.uniform must point down (gz < 0)", sp.display()))?;
    let jp = dir.join("summary.json");
    let summary = match std::fs::read_to_string(&jp) {
        Ok(text) => serde_json::from_str(&text).map_err(|e| format!("{}: {e}", jp.display()))?,
        // A run stopped before its end (killed, or still going) has no summary yet: take its time series instead.
        Err(e) => interrupted_summary(dir).ok_or_else(|| format!("{}: {e}", jp.display()))?,
    };
    let snap_dir = dir.join("snapshots");
    let mut files: Vec<(usize, PathBuf)> = std::fs::read_dir(&snap_dir)
        .map_err(|e| format!("{}: {e}", snap_dir.display()))?
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let p = e.path();
            let k = p.file_stem()?.to_str()?.parse::<usize>().ok()?;
            (p.extension()? == "csv").then_some((k, p))
        })
        .collect();
    files.sort();
    Ok(RunFiles {
        scene,
        g,
        summary,
        snapshots: files.into_iter().map(|f| f.1).collect(),
    })
}

/// Reads a finished atmosphere run (`scene.toml`, `summary.json`, `timeseries.csv`, `snapshots/*.csv`): the plane is
/// `z = 0`, gravity `−g ẑ` and the cylinder radius are read from the scene copy.
pub fn analyse_atmosphere_run(dir: &Path) -> Result<AtmosphereRun, AnalysisError> {
    let RunFiles {
        scene: value,
        g,
        summary,
        snapshots: files,
    } = read_run_files(dir)?;
    let cylinder_radius = value
        .get("wall")
        .and_then(|w| w.as_array())
        .and_then(|ws| {
            ws.iter()
                .find(|w| w.get("kind").and_then(|t| t.as_str()) == Some("cylinder"))
        })
        .and_then(|w| w.get("radius"))
        .and_then(|r| r.as_float())
        .unwrap_or(f64::NAN);
    if files.len() < 2 {
        return Err(format!("{}: fewer than 2 snapshots", dir.join("snapshots").display()).into());
    }
    let mut snapshots = Vec::new();
    let mut all_heights = Vec::new();
    let mut energy0 = f64::NAN;
    let mut energy_last = f64::NAN;
    let mut masses = Vec::new();
    let mut counts = Vec::new();
    for (k, path) in files.iter().enumerate() {
        let rows = read_particles_csv(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let t = rows.first().map(|r| r.values[0]).unwrap_or(f64::NAN);
        let species = species_heights(&rows, 0.0);
        let e = energy_above_ground(&rows, g, 0.0);
        if k == 0 {
            energy0 = e;
            masses = species.iter().map(|s| s.mass).collect();
            counts = species.iter().map(|s| s.heights.len()).collect();
        }
        energy_last = e;
        if species.iter().map(|s| s.mass).collect::<Vec<_>>() != masses {
            return Err(format!("{}: not the species of the first snapshot", path.display()).into());
        }
        snapshots.push(SnapshotStats {
            t,
            mean_heights: species.iter().map(|s| mean(&s.heights)).collect(),
        });
        all_heights.push(species.into_iter().map(|s| s.heights).collect::<Vec<_>>());
    }
    let n: usize = counts.iter().sum();
    let kt = equipartition_kt(energy0, n);
    let expected: Vec<f64> = masses.iter().map(|&m| scale_height(kt, m, g)).collect();
    let t_last = snapshots.last().map_or(f64::NAN, |s| s.t);
    let late: Vec<usize> = (0..snapshots.len())
        .filter(|&k| snapshots[k].t >= 0.5 * t_last)
        .collect();
    let late_mean_heights = (0..masses.len())
        .map(|s| mean_std(&late.iter().map(|&k| snapshots[k].mean_heights[s]).collect::<Vec<_>>()))
        .collect();
    let mut ks = Vec::new();
    for f in KS_FRACTIONS {
        let k = (0..snapshots.len())
            .min_by(|&a, &b| {
                (snapshots[a].t - f * t_last)
                    .abs()
                    .total_cmp(&(snapshots[b].t - f * t_last).abs())
            })
            .unwrap_or(0);
        let mut p_measured = Vec::new();
        let mut p_expected = Vec::new();
        for (s, h) in all_heights[k].iter().enumerate() {
            p_measured.push(ks_exponential(h, mean(h))?.1);
            p_expected.push(ks_exponential(h, expected[s])?.1);
        }
        ks.push(KsAt {
            fraction: f,
            t: snapshots[k].t,
            p_measured,
            p_expected,
        });
    }
    Ok(AtmosphereRun {
        dir: dir.to_path_buf(),
        cylinder_radius,
        masses,
        counts,
        energy0,
        energy_drift: (energy_last - energy0) / energy0,
        kt,
        expected,
        snapshots,
        late_mean_heights,
        ks,
        final_heights: all_heights.pop().unwrap_or_default(),
        energy_series: read_energy_series(&dir.join("timeseries.csv"))?,
        events_per_second: json_f64(&summary, "events_per_second"),
        collisions: summary["collisions"].as_u64().unwrap_or(0),
        wall_seconds: json_f64(&summary, "wall_seconds"),
        max_overlap: json_f64(&summary, "max_overlap"),
        steps: summary["steps"].as_u64().unwrap_or(0),
    })
}

/// `(t, energy_change)` columns of a hard-sphere `timeseries.csv`.
pub fn read_energy_series(path: &Path) -> Result<Vec<(f64, f64)>, AnalysisError> {
    let mut rdr = ::csv::Reader::from_path(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let headers = rdr.headers().map_err(|e| format!("{}: {e}", path.display()))?.clone();
    let col = |name: &str| {
        headers
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| format!("{}: no column `{name}`", path.display()))
    };
    let (it, ie) = (col("t")?, col("energy_change")?);
    let mut out = Vec::new();
    for rec in rdr.records() {
        let rec = rec.map_err(|e| format!("{}: {e}", path.display()))?;
        let num = |i: usize| rec.get(i).and_then(|s| s.parse::<f64>().ok()).unwrap_or(f64::NAN);
        out.push((num(it), num(ie)));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rubblepile::random::{generator, uniform};

    /// Exponential samples of scale `h` by inversion from a seeded PCG stream.
    fn exponential_samples(n: usize, h: f64, seed: u64) -> Vec<f64> {
        let mut rng = generator(seed);
        (0..n).map(|_| -h * (1.0 - uniform(&mut rng)).ln()).collect()
    }

    #[test]
    fn ks_accepts_the_right_scale_height_and_rejects_a_wrong_one() {
        let h = 0.626;
        let z = exponential_samples(330, h, 7);
        let (_, p_right) = ks_exponential(&z, h).unwrap();
        let (_, p_fitted) = ks_exponential(&z, mean(&z)).unwrap();
        let (_, p_wrong) = ks_exponential(&z, 2.0 * h).unwrap();
        assert!(p_right > 0.05, "p at the true scale height {p_right}");
        assert!(p_fitted > 0.05, "p at the fitted scale height {p_fitted}");
        assert!(p_wrong < 1e-6, "p at twice the scale height {p_wrong}");
        // The maximum-likelihood scale height (the mean) is within 3 standard errors h/√n of the truth.
        assert!((mean(&z) - h).abs() < 3.0 * h / (z.len() as f64).sqrt());
        assert!(ks_exponential(&z, 0.0).is_err());
    }

    #[test]
    fn ks_probability_is_uniform_under_the_null() {
        // Under the null the two-sided probability is ~uniform: about 10 % of 200 samples fall below 0.1.
        let low = (0..200)
            .filter(|&s| ks_exponential(&exponential_samples(200, 1.0, 100 + s), 1.0).unwrap().1 < 0.1)
            .count();
        assert!((8..=36).contains(&low), "{low} of 200 probabilities below 0.1");
    }

    #[test]
    fn equipartition_gives_the_papers_scale_heights() {
        // Richardson11 §3.1: expected 1.88, 0.626, 0.188 for masses 1, 3, 10 with g = 1, i.e. kT = 1.88.
        let kt = equipartition_kt(2.5 * 1.88 * 991.0, 991);
        for (m, h) in [(1.0, 1.88), (3.0, 0.626), (10.0, 0.188)] {
            // The paper quotes three significant figures.
            assert!(
                (scale_height(kt, m, 1.0) - h).abs() < 1e-3,
                "m = {m}: {}",
                scale_height(kt, m, 1.0)
            );
        }
    }

    #[test]
    fn energy_and_species_of_rows() {
        let row = |m: f64, z: f64, vz: f64, wx: f64, stuck: Option<usize>| ParticleRow {
            values: [0.0, 0.0, m, 0.5, 0.0, 0.0, z, 0.0, 0.0, vz, wx, 0.0, 0.0],
            stuck_to: stuck,
        };
        let rows = [
            row(2.0, 1.5, 3.0, 0.0, None),
            row(1.0, 0.5, 0.0, 2.0, None),
            row(5.0, 9.0, 9.0, 0.0, Some(0)),
        ];
        // 2 g (1.5 − 0.5) + ½ 2 · 9 + (1/5) 1 · 0.25 · 4 with g = 2.
        let e = energy_above_ground(&rows, 2.0, 0.0);
        assert!((e - (4.0 + 9.0 + 0.2)).abs() < 1e-12, "{e}");
        let s = species_heights(&rows, 0.0);
        assert_eq!(s.len(), 2);
        assert_eq!((s[0].mass, s[0].heights.clone()), (1.0, vec![0.0]));
        assert_eq!((s[1].mass, s[1].heights.clone()), (2.0, vec![1.0]));
        let (m, sd) = mean_std(&[1.0, 2.0, 3.0]);
        assert_eq!((m, sd), (2.0, 1.0));
    }
}
