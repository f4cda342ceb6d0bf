//! Contact-barrier overrun detector (Roig03 §2, Eqs. 10–14). Roig03 calibrate κ (Eq. 13) so that the smallest
//! barrier is β times `K = ½ m_l v²` (Eq. 14, `β ~ 10`), to "avoid penetration between the bodies"; nothing in
//! the equations enforces it, so this module watches every touching pair and says when a collision went deeper.
//!
//! Per pair in contact (`x = κ Δᵀ G⁻¹ Δ < κλ_ij`, Eqs. 10, 12; `a = P_ij det(G)^{−1/2}` in J; `μ` the reduced
//! mass): overlap energy `E_c = a (e^{−x} − e^{−κλ})`, collision energy `E = ½ μ v_n² + E_c` (nearly constant in a
//! head-on contact), relative speed `v_eq = √(2E/μ)`, calibrated speed `v_c² = G M_ref e^{κλ}/(β κλ (R_i + R_j))`
//! (Eq. 14 on the pair, `M_ref` per [`KappaReading`]), barrier `B = a (1 − e^{−κλ})`. Verdicts (warnings):
//! **overrun** when `v_eq > `[`SPEED_MARGIN`]` · v_c` (1.25: room for mutual gravity and ellipsoidal shapes),
//! **broke through** when `E ≥ B`. β is `model.calibrate.beta`, or [`DEFAULT_BETA`] for a given κ.
//!
//! A warning, not a stop: only the colliding pair's outcome is unphysical. The driver checks every sampled state,
//! appends each overrun to `barrier_overruns.csv` (flushed), lists the pairs in `summary.json` (`barrier`) and
//! prints one stderr line per pair; contacts shorter than `output.every` are not seen.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::ellipsoid::body::Body;
use crate::ellipsoid::calibration::{KappaReading, lambda, pair_prefactor};
use crate::ellipsoid::clumps::shape_matrix;
use crate::ellipsoid::equations::{EllipsoidSystem, ModelConfig};
use crate::ellipsoid::scene::KappaSource;

/// β used when κ is given rather than calibrated (Roig03 after Eq. 13: "β ~ 10").
pub const DEFAULT_BETA: f64 = 10.0;

/// An overrun is reported when a pair's relative speed exceeds this multiple of its calibrated speed.
pub const SPEED_MARGIN: f64 = 1.25;

/// At most this many pairs are listed in `summary.json` (all are counted, and every sample is in the CSV).
pub const MAX_LISTED_PAIRS: usize = 20;

/// File (in the run directory) that receives every overrun sample as it is found.
pub const OVERRUN_FILE: &str = "barrier_overruns.csv";

/// Columns of [`OVERRUN_FILE`]: time (s), the pair's body ids, `overrun` or `broke-through`, relative
/// speed and calibrated speed (m/s), the exponent `x` and the touching exponent `κλ`, and the centre
/// distance in units of the touching distance (sphere-equivalent, `√(x/κλ)`).
pub const OVERRUN_COLUMNS: [&str; 9] = [
    "t",
    "i",
    "j",
    "level",
    "speed",
    "calibrated_speed",
    "exponent",
    "contact_exponent",
    "separation_ratio",
];

/// How the detector judges a pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BarrierSettings {
    /// β of Roig03 Eqs. 13–14 (dimensionless, > 0).
    pub beta: f64,
    /// Which `K` of Eq. 13 the calibrated speeds use: the calibration's, or the printed one for a given κ.
    pub reading: KappaReading,
    /// Where β came from: `"model.calibrate"` or `"default"` ([`DEFAULT_BETA`]).
    pub beta_source: &'static str,
    /// Overrun when the relative speed exceeds `speed_margin ×` the calibrated speed (≥ 1).
    pub speed_margin: f64,
}

impl BarrierSettings {
    /// β of the scene's calibration, or [`DEFAULT_BETA`] for a given κ; margin [`SPEED_MARGIN`].
    pub fn for_kappa_source(source: &KappaSource) -> Self {
        let (beta, reading, beta_source) = match *source {
            KappaSource::Calibrated { beta, reading, .. } => (beta, reading, "model.calibrate"),
            KappaSource::Given => (DEFAULT_BETA, KappaReading::Printed, "default"),
        };
        BarrierSettings {
            beta,
            reading,
            beta_source,
            speed_margin: SPEED_MARGIN,
        }
    }
}

/// How badly a pair went through its barrier.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum OverrunLevel {
    /// Relative speed above the margin times the calibrated speed.
    Overrun,
    /// Collision energy at least the barrier height: the bodies pass through each other.
    BrokeThrough,
}

impl OverrunLevel {
    /// `"overrun"` or `"broke-through"` (the CSV's `level` column).
    pub fn as_str(self) -> &'static str {
        match self {
            OverrunLevel::Overrun => "overrun",
            OverrunLevel::BrokeThrough => "broke-through",
        }
    }
}

/// The contact state of one touching pair (`x < κλ`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairContact {
    /// Body ids (indices), `i < j`.
    pub i: usize,
    /// Second body id.
    pub j: usize,
    /// `x = κ Δᵀ G⁻¹ Δ` (dimensionless).
    pub exponent: f64,
    /// `κλ_ij` (dimensionless): the exponent at which equivalent spheres touch.
    pub contact_exponent: f64,
    /// Contact energy stored beyond touching, `a (e^{−x} − e^{−κλ})` (J).
    pub stored_energy: f64,
    /// Collision energy `½ μ v_n² + stored` (J).
    pub collision_energy: f64,
    /// Barrier height `a (1 − e^{−κλ})` (J).
    pub barrier: f64,
    /// Relative (head-on equivalent) speed `√(2E/μ)` (m/s).
    pub speed: f64,
    /// The pair's calibrated speed from Roig03 Eq. 14 (m/s; may be +∞ for very stiff pairs).
    pub calibrated_speed: f64,
}

impl PairContact {
    /// Centre distance in units of the touching distance for equivalent spheres, `√(x/κλ)` (< 1 in contact).
    pub fn separation_ratio(&self) -> f64 {
        (self.exponent / self.contact_exponent).max(0.0).sqrt()
    }

    /// The verdict for this contact, if it is an overrun.
    pub fn level(&self, settings: &BarrierSettings) -> Option<OverrunLevel> {
        if self.collision_energy >= self.barrier {
            Some(OverrunLevel::BrokeThrough)
        } else if self.speed > settings.speed_margin * self.calibrated_speed {
            Some(OverrunLevel::Overrun)
        } else {
            None
        }
    }
}

/// One overrun sample: a pair found over its barrier at time `t`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Overrun {
    /// Time (s).
    pub t: f64,
    /// The pair's contact state.
    pub contact: PairContact,
    /// Its verdict.
    pub level: OverrunLevel,
}

/// The pair's calibrated speed (m/s): Roig03 Eq. 14 solved for `v` with the pair's own equivalent radii
/// `r_i, r_j` (m), `κλ_ij` and the reading's reference mass `m_ref` (kg, [`KappaReading::reference_mass`]):
/// `v² = G m_ref e^{κλ}/(β κλ (R_i + R_j))`.
pub fn calibrated_speed(g: f64, kappa: f64, beta: f64, r_i: f64, r_j: f64, m_ref: f64) -> f64 {
    let x = kappa * lambda(r_i, r_j);
    // exp(x)/x in log form: finite up to x ≈ 1400.
    (g * m_ref / (beta * (r_i + r_j))).sqrt() * (0.5 * (x - x.ln())).exp()
}

/// Radius (m) beyond which no partner can be in contact: `x < κλ ≤ 2κ` needs `|Δ|² < 2 λ_max(G)`, and
/// `λ_max(Σ) ≤ A² (|q|² + ||q|² − 1|)²`, so `|Δ| < √2 (ρ_i + ρ_j)` with `ρ = A (|q|² + ||q|² − 1|)`.
fn reach(b: &Body) -> f64 {
    let q2 = b.quaternion.norm_squared();
    std::f64::consts::SQRT_2 * b.shape.axes.x * (q2 + (q2 - 1.0).abs()) * (1.0 + 1e-9)
}

/// The contact state of pair `(i, j)`, or `None` when it is not in contact (`x ≥ κλ`) or degenerate.
pub fn pair_contact(
    model: &ModelConfig,
    settings: &BarrierSettings,
    bodies: &[Body],
    i: usize,
    j: usize,
) -> Option<PairContact> {
    let (bi, bj) = (&bodies[i], &bodies[j]);
    let kappa = model.kappa;
    let (ri, rj) = (bi.shape.equivalent_radius(), bj.shape.equivalent_radius());
    let (mi, mj) = (bi.shape.mass, bj.shape.mass);
    let contact_exponent = kappa * lambda(ri, rj);
    // Σ = Rᵀ diag(A², B², C²) R of each body, as the contact potential uses it.
    let g = shape_matrix(bi, 1.0) + shape_matrix(bj, 1.0);
    let g_inv = g.try_inverse()?;
    let delta = bi.position - bj.position;
    let exponent = kappa * delta.dot(&(g_inv * delta));
    // (written so that a NaN exponent is out of contact too)
    if exponent.is_nan() || exponent >= contact_exponent {
        return None;
    }
    let amplitude = pair_prefactor(model.contact_g, kappa, ri, mi, rj, mj) / g.determinant().sqrt();
    let touch = (-contact_exponent).exp();
    let stored_energy = (amplitude * ((-exponent).exp() - touch)).max(0.0);
    let mu = mi * mj / (mi + mj);
    let dv = bi.velocity - bj.velocity;
    let dist = delta.norm();
    let v_n = if dist > 0.0 { dv.dot(&delta) / dist } else { dv.norm() };
    let collision_energy = 0.5 * mu * v_n * v_n + stored_energy;
    let contact = PairContact {
        i,
        j,
        exponent,
        contact_exponent,
        stored_energy,
        collision_energy,
        barrier: amplitude * (1.0 - touch),
        speed: (2.0 * collision_energy / mu).sqrt(),
        calibrated_speed: calibrated_speed(
            model.contact_g,
            kappa,
            settings.beta,
            ri,
            rj,
            settings.reading.reference_mass(mi.min(mj), mi.max(mj)),
        ),
    };
    contact.speed.is_finite().then_some(contact)
}

/// From this many bodies on, [`contacts`] sweeps in parallel.
const PARALLEL_SWEEP_FROM: usize = 256;

/// Every pair in contact (`x < κλ`), sorted by `(i, j)`: sort-and-sweep along x with a bound on each body's
/// reach, then the exact test.
pub fn contacts(model: &ModelConfig, settings: &BarrierSettings, bodies: &[Body]) -> Vec<PairContact> {
    let reaches: Vec<f64> = bodies.iter().map(reach).collect();
    let max_reach = reaches.iter().copied().fold(0.0, f64::max);
    let mut order: Vec<usize> = (0..bodies.len())
        .filter(|&k| bodies[k].position.x.is_finite())
        .collect();
    order.sort_by(|&a, &b| bodies[a].position.x.total_cmp(&bodies[b].position.x));
    // The sweep from each body is independent of the others': in parallel for many bodies (it runs at every
    // output sample), the pairs then sorted, so the result is the same on any number of threads.
    let sweep = |(n, &a): (usize, &usize)| {
        let mut found = Vec::new();
        let xa = bodies[a].position.x;
        for &b in &order[n + 1..] {
            if bodies[b].position.x - xa > reaches[a] + max_reach {
                break;
            }
            let d2 = (bodies[a].position - bodies[b].position).norm_squared();
            if d2 >= (reaches[a] + reaches[b]).powi(2) {
                continue;
            }
            let (i, j) = (a.min(b), a.max(b));
            if let Some(c) = pair_contact(model, settings, bodies, i, j) {
                found.push(c);
            }
        }
        found
    };
    let mut out: Vec<PairContact> = if order.len() >= PARALLEL_SWEEP_FROM {
        order.par_iter().enumerate().flat_map_iter(sweep).collect()
    } else {
        order.iter().enumerate().flat_map(sweep).collect()
    };
    out.sort_by_key(|c| (c.i, c.j));
    out
}

/// What the run remembers about one pair that overran.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PairOverrun {
    /// Body id (index), `i < j`.
    pub i: usize,
    /// Second body id.
    pub j: usize,
    /// First sampled time it was found over its barrier (s).
    pub first_t: f64,
    /// Its relative speed then (m/s).
    pub first_speed: f64,
    /// Time of its largest relative speed (s).
    pub worst_t: f64,
    /// Largest relative speed found (m/s).
    pub worst_speed: f64,
    /// The pair's calibrated speed (m/s).
    pub calibrated_speed: f64,
    /// Smallest centre distance in units of the touching distance, `√(x/κλ)`, seen in overrun samples.
    pub min_separation_ratio: f64,
    /// Whether it ever broke through (collision energy ≥ barrier height).
    pub broke_through: bool,
    /// Number of overrun samples.
    pub samples: u64,
}

impl PairOverrun {
    /// One line for a scientist: `bodies 3 and 7 overran the contact barrier at t = … s (…)`.
    pub fn message(&self) -> String {
        let what = if self.broke_through {
            "broke through the contact barrier (they pass through each other)"
        } else {
            "overran the contact barrier"
        };
        format!(
            "bodies {} and {} {what} at t = {} s (relative speed {:.4} m/s > calibrated {:.4} m/s; worst {:.4} m/s at t = {} s, centres down to {:.3} of the touching distance)",
            self.i,
            self.j,
            self.first_t,
            self.first_speed,
            self.calibrated_speed,
            self.worst_speed,
            self.worst_t,
            self.min_separation_ratio
        )
    }
}

/// The `barrier` entry of `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BarrierReport {
    /// β used for the calibrated speeds.
    pub beta: f64,
    /// Which `K` of Roig03 Eq. 13 the calibrated speeds use (summaries written before the option: printed).
    #[serde(default)]
    pub reading: KappaReading,
    /// `"model.calibrate"` or `"default"`.
    pub beta_source: String,
    /// Overrun when relative speed > `speed_margin ×` calibrated speed.
    pub speed_margin: f64,
    /// Number of distinct pairs found over their barrier.
    pub overrun_pairs: usize,
    /// Number of those that broke through.
    pub broke_through_pairs: usize,
    /// Total overrun samples (rows of `barrier_overruns.csv`).
    pub samples: u64,
    /// The first [`MAX_LISTED_PAIRS`] pairs, by first time.
    pub pairs: Vec<PairOverrun>,
}

impl BarrierReport {
    /// One warning line per listed pair, plus one for the pairs not listed.
    pub fn warnings(&self) -> Vec<String> {
        let mut w: Vec<String> = self.pairs.iter().map(PairOverrun::message).collect();
        if self.overrun_pairs > self.pairs.len() {
            w.push(format!(
                "{} more pairs overran the contact barrier (see {OVERRUN_FILE})",
                self.overrun_pairs - self.pairs.len()
            ));
        }
        w
    }
}

/// Watches every sampled state of a run for barrier overruns and logs them to [`OVERRUN_FILE`].
#[derive(Debug)]
pub struct BarrierMonitor {
    settings: BarrierSettings,
    enabled: bool,
    pairs: BTreeMap<(usize, usize), PairOverrun>,
    samples: u64,
    path: Option<PathBuf>,
    file: Option<std::fs::File>,
}

fn overrun_row(o: &Overrun) -> String {
    let c = &o.contact;
    format!(
        "{:e},{},{},{},{:e},{:e},{:e},{:e},{:e}\n",
        o.t,
        c.i,
        c.j,
        o.level.as_str(),
        c.speed,
        c.calibrated_speed,
        c.exponent,
        c.contact_exponent,
        c.separation_ratio()
    )
}

impl BarrierMonitor {
    /// A monitor with these settings; `enabled` is false when the contact term is off (then it does nothing).
    /// With `log`, overrun samples are appended to that file (created at the first overrun).
    pub fn new(settings: BarrierSettings, enabled: bool, log: Option<&Path>) -> Self {
        BarrierMonitor {
            settings,
            enabled,
            pairs: BTreeMap::new(),
            samples: 0,
            path: log.map(Path::to_path_buf),
            file: None,
        }
    }

    /// Continues a monitor after a checkpoint at `t_max` (s): the rows of the log with `t ≤ t_max` are
    /// kept (the file is rewritten without later rows, which a killed process may have written) and
    /// replayed, so the final report equals an uninterrupted run's.
    pub fn resume(settings: BarrierSettings, enabled: bool, log: &Path, t_max: f64) -> std::io::Result<Self> {
        let mut m = BarrierMonitor::new(settings, enabled, Some(log));
        let text = match std::fs::read_to_string(log) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(m),
            Err(e) => return Err(e),
        };
        let mut kept = String::new();
        let mut reader = csv::ReaderBuilder::new().flexible(true).from_reader(text.as_bytes());
        for (n, record) in reader.records().enumerate() {
            let malformed = |what: String| std::io::Error::other(format!("{} line {}: {what}", log.display(), n + 2));
            let record = record.map_err(|e| malformed(e.to_string()))?;
            let o = parse_row(&record).ok_or_else(|| malformed(format!("malformed row {:?}", record.as_slice())))?;
            if o.t <= t_max {
                m.record(&o);
                kept.push_str(&record.iter().collect::<Vec<_>>().join(","));
                kept.push('\n');
            }
        }
        if m.samples > 0 {
            let mut f = crate::io::safe_write::create_fresh(log)?;
            writeln!(f, "{}", OVERRUN_COLUMNS.join(","))?;
            f.write_all(kept.as_bytes())?;
            f.sync_all()?;
            m.file = Some(f);
        } else {
            std::fs::remove_file(log)?;
        }
        Ok(m)
    }

    /// Adds one overrun sample to the per-pair record (no file output).
    pub fn record(&mut self, o: &Overrun) {
        let c = &o.contact;
        let ratio = c.separation_ratio();
        let broke = o.level == OverrunLevel::BrokeThrough;
        self.samples += 1;
        self.pairs
            .entry((c.i, c.j))
            .and_modify(|p| {
                if c.speed > p.worst_speed {
                    p.worst_speed = c.speed;
                    p.worst_t = o.t;
                }
                p.min_separation_ratio = p.min_separation_ratio.min(ratio);
                p.broke_through |= broke;
                p.samples += 1;
            })
            .or_insert(PairOverrun {
                i: c.i,
                j: c.j,
                first_t: o.t,
                first_speed: c.speed,
                worst_t: o.t,
                worst_speed: c.speed,
                calibrated_speed: c.calibrated_speed,
                min_separation_ratio: ratio,
                broke_through: broke,
                samples: 1,
            });
    }

    /// The overruns among `bodies` at time `t` (s) under `model`, without recording them.
    pub fn check(&self, t: f64, model: &ModelConfig, bodies: &[Body]) -> Vec<Overrun> {
        if !self.enabled {
            return Vec::new();
        }
        contacts(model, &self.settings, bodies)
            .into_iter()
            .filter_map(|contact| contact.level(&self.settings).map(|level| Overrun { t, contact, level }))
            .collect()
    }

    /// Checks the sampled state `y` of `system` at `t`, records and logs its overruns, and returns them.
    pub fn observe(&mut self, t: f64, system: &EllipsoidSystem, y: &[f64]) -> std::io::Result<Vec<Overrun>> {
        if !self.enabled {
            return Ok(Vec::new());
        }
        let found = self.check(t, system.model(), &system.bodies_at(t, y));
        for o in &found {
            self.record(o);
        }
        if !found.is_empty()
            && let Some(path) = &self.path
        {
            if self.file.is_none() {
                let mut f = crate::io::safe_write::create_fresh(path)?;
                writeln!(f, "{}", OVERRUN_COLUMNS.join(","))?;
                self.file = Some(f);
            }
            if let Some(f) = &mut self.file {
                let rows: String = found.iter().map(overrun_row).collect();
                f.write_all(rows.as_bytes())?;
                f.flush()?;
            }
        }
        Ok(found)
    }

    /// For a failed run's status: the earliest break-through (or, failing that, the earliest overrun), which
    /// likely explains the failure, as `after bodies i and j broke through the contact barrier at t = … s (…)`.
    pub fn failure_hint(&self) -> Option<String> {
        let earliest = |broke: bool| {
            self.pairs
                .values()
                .filter(|p| p.broke_through || !broke)
                .min_by(|a, b| a.first_t.total_cmp(&b.first_t))
        };
        let (p, why) = match earliest(true) {
            Some(p) => (p, "their centres met, where point-mass gravity is singular"),
            None => (earliest(false)?, "deeper overlap than the calibration provides for"),
        };
        let what = if p.broke_through { "broke through" } else { "overran" };
        Some(format!(
            "after bodies {} and {} {what} the contact barrier at t = {} s (relative speed {:.4} m/s, calibrated {:.4} m/s; {why})",
            p.i, p.j, p.first_t, p.worst_speed, p.calibrated_speed
        ))
    }

    /// The report for `summary.json`; `None` when the monitor is disabled (no contact term).
    pub fn report(&self) -> Option<BarrierReport> {
        if !self.enabled {
            return None;
        }
        let mut pairs: Vec<PairOverrun> = self.pairs.values().copied().collect();
        pairs.sort_by(|a, b| a.first_t.total_cmp(&b.first_t).then((a.i, a.j).cmp(&(b.i, b.j))));
        let broke_through_pairs = pairs.iter().filter(|p| p.broke_through).count();
        let overrun_pairs = pairs.len();
        pairs.truncate(MAX_LISTED_PAIRS);
        Some(BarrierReport {
            beta: self.settings.beta,
            reading: self.settings.reading,
            beta_source: self.settings.beta_source.to_string(),
            speed_margin: self.settings.speed_margin,
            overrun_pairs,
            broke_through_pairs,
            samples: self.samples,
            pairs,
        })
    }
}

/// Parses one row of [`OVERRUN_FILE`] back into an [`Overrun`] (only the columns the report needs are
/// restored; the energies are not logged and come back as 0, the level as written).
fn parse_row(f: &csv::StringRecord) -> Option<Overrun> {
    if f.len() != OVERRUN_COLUMNS.len() {
        return None;
    }
    let num = |k: usize| f[k].parse::<f64>().ok();
    let level = match &f[3] {
        "overrun" => OverrunLevel::Overrun,
        "broke-through" => OverrunLevel::BrokeThrough,
        _ => return None,
    };
    Some(Overrun {
        t: num(0)?,
        contact: PairContact {
            i: f[1].parse().ok()?,
            j: f[2].parse().ok()?,
            exponent: num(6)?,
            contact_exponent: num(7)?,
            stored_energy: 0.0,
            collision_energy: 0.0,
            barrier: 0.0,
            speed: num(4)?,
            calibrated_speed: num(5)?,
        },
        level,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ellipsoid::body::{Ellipsoid, InertiaModel};
    use crate::ellipsoid::calibration::calibrate_kappa_read;
    use crate::ellipsoid::equations::{ContactTerm, G_SI, GravityTerm, Physics};
    use crate::math::{Vec3, Vec4};

    fn sphere(r: f64, x: f64, vx: f64) -> Body {
        let shape = Ellipsoid {
            axes: Vec3::repeat(r),
            mass: 0.0,
        };
        Body {
            shape: Ellipsoid {
                axes: shape.axes,
                mass: 3000.0 * shape.volume(),
            },
            position: Vec3::new(x, 0.0, 0.0),
            velocity: Vec3::new(vx, 0.0, 0.0),
            quaternion: Vec4::w(),
            spin_body: Vec3::zeros(),
        }
    }

    fn model(kappa: f64) -> ModelConfig {
        ModelConfig {
            kappa,
            inertia: InertiaModel::Gaussian,
            contact_g: G_SI,
        }
    }

    /// The detector's settings for a given κ (β = 10, printed reading).
    fn printed() -> BarrierSettings {
        BarrierSettings::for_kappa_source(&KappaSource::Given)
    }

    /// The smallest–largest pair of a calibrated scene gets exactly the calibration's v, under every reading.
    #[test]
    fn calibrated_speed_inverts_eq14() {
        let (a, b) = (sphere(400.0, 0.0, 0.0), sphere(900.0, 1300.0, 0.0));
        let (r_a, r_b) = (a.shape.equivalent_radius(), b.shape.equivalent_radius());
        let (m_a, m_b) = (a.shape.mass, b.shape.mass);
        for reading in KappaReading::ALL {
            for v in [0.7, 2.0, 5.0, 40.0] {
                let kappa = calibrate_kappa_read(reading, 10.0, v, (r_a, m_a), (r_b, m_b), G_SI).unwrap();
                let vc = calibrated_speed(G_SI, kappa, 10.0, r_a, r_b, reading.reference_mass(m_a, m_b));
                assert!((vc / v - 1.0).abs() < 1e-9, "{reading}, v = {v}: calibrated speed {vc}");
            }
        }
    }

    /// Two spheres: stored energy and exponent follow the closed forms, and the summed potential of the
    /// contacts equals the model's `U_C` (same formula as the equations of motion).
    #[test]
    fn contact_matches_model_potential() {
        let (r1, r2) = (500.0, 800.0);
        let d = 0.8 * (r1 + r2);
        let bodies = [sphere(r1, 0.0, 1.0), sphere(r2, d, -0.5)];
        let kappa = 6.0;
        let m = model(kappa);
        let c = pair_contact(&m, &printed(), &bodies, 0, 1).unwrap();
        let x = kappa * d * d / (r1 * r1 + r2 * r2);
        assert!((c.exponent / x - 1.0).abs() < 1e-12);
        assert!((c.separation_ratio() - 0.8).abs() < 1e-12);
        let physics = Physics {
            gravity: Some(GravityTerm::new(G_SI)),
            contact: Some(ContactTerm::default()),
            dissipation: None,
        };
        let sys = EllipsoidSystem::new(&bodies, m, physics);
        let u_c = sys.diagnostics(&sys.initial_state()).potential_contact;
        let amplitude = c.barrier / (1.0 - (-c.contact_exponent).exp());
        let raw = amplitude * (-c.exponent).exp();
        assert!((raw / u_c - 1.0).abs() < 1e-12, "{raw} vs {u_c}");
        // collision energy = ½ μ v_n² + stored; v_n = 1.5 m/s
        let mu = bodies[0].shape.mass * bodies[1].shape.mass / (bodies[0].shape.mass + bodies[1].shape.mass);
        assert!((c.collision_energy - (0.5 * mu * 2.25 + c.stored_energy)).abs() < 1e-9 * c.collision_energy);
        // out of contact: nothing
        let apart = [sphere(r1, 0.0, 0.0), sphere(r2, 1.01 * (r1 + r2), 0.0)];
        assert!(pair_contact(&m, &printed(), &apart, 0, 1).is_none());
    }

    /// The verdicts: below the margin nothing, above it an overrun, with more than the barrier a break-through.
    /// The break-through speed pins each reading's `K`: the barrier is β·½ M_K v_c² against the pair's
    /// collision energy ½ μ v², so it breaks through above √(β M_K/μ) v_c.
    #[test]
    fn levels_follow_speed_and_barrier() {
        let (r, kappa) = (600.0, 5.0);
        let m = model(kappa);
        for reading in KappaReading::ALL {
            let settings = BarrierSettings { reading, ..printed() };
            let probe = |v: f64| {
                let bodies = [sphere(r, 0.0, v / 2.0), sphere(r, 1.99 * r, -v / 2.0)];
                pair_contact(&m, &settings, &bodies, 0, 1).unwrap()
            };
            let vc = probe(0.0).calibrated_speed;
            assert_eq!(probe(vc).level(&settings), None);
            assert_eq!(probe(1.2 * vc).level(&settings), None);
            assert_eq!(probe(1.3 * vc).level(&settings), Some(OverrunLevel::Overrun));
            // equal spheres of mass m: μ = m/2, M_K = m (printed, impactor) or m/2 (reduced)
            let mass = sphere(r, 0.0, 0.0).shape.mass;
            let through = (settings.beta * reading.kinetic_mass(mass, mass) / (0.5 * mass)).sqrt();
            assert_eq!(
                probe(0.98 * through * vc).level(&settings),
                Some(OverrunLevel::Overrun),
                "{reading}"
            );
            assert_eq!(
                probe(1.02 * through * vc).level(&settings),
                Some(OverrunLevel::BrokeThrough),
                "{reading}"
            );
        }
    }

    /// The sweep finds exactly the touching pairs, whatever their order along x, including rotated ellipsoids.
    #[test]
    fn sweep_finds_all_touching_pairs() {
        let mut bodies = Vec::new();
        let q = Vec4::new(0.3, -0.2, 0.5, 0.7).normalize();
        for k in 0..40 {
            let x = ((k * 7919) % 40) as f64 * 900.0;
            let y = ((k * 104729) % 3) as f64 * 1500.0;
            let mut b = sphere(500.0, x, 0.0);
            b.shape.axes = Vec3::new(800.0, 500.0, 300.0);
            b.position.y = y;
            b.quaternion = if k % 2 == 0 { q } else { Vec4::w() };
            bodies.push(b);
        }
        let m = model(4.0);
        let found: Vec<(usize, usize)> = contacts(&m, &printed(), &bodies).iter().map(|c| (c.i, c.j)).collect();
        let mut brute = Vec::new();
        for i in 0..bodies.len() {
            for j in i + 1..bodies.len() {
                if pair_contact(&m, &printed(), &bodies, i, j).is_some() {
                    brute.push((i, j));
                }
            }
        }
        assert!(!brute.is_empty());
        assert_eq!(found, brute);
    }

    /// The log is written as overruns are found, and a resumed monitor rebuilds the same report from it.
    #[test]
    fn log_resume_restores_report() {
        let dir = std::env::temp_dir().join(format!("rubblepile-barrier-unit-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let log = dir.join(OVERRUN_FILE);
        let _ = std::fs::remove_file(&log);
        let settings = BarrierSettings::for_kappa_source(&KappaSource::Given);
        let m = model(5.0);
        let physics = Physics {
            gravity: None,
            contact: Some(ContactTerm::default()),
            dissipation: None,
        };
        let mut mon = BarrierMonitor::new(settings, true, Some(&log));
        let bodies = [sphere(600.0, 0.0, 0.0), sphere(600.0, 1.9 * 600.0, 0.0)];
        let vc = pair_contact(&m, &settings, &bodies, 0, 1).unwrap().calibrated_speed;
        let mut states = Vec::new();
        for (k, v) in [0.5, 2.0, 3.0, 2.5].iter().enumerate() {
            let moving = [sphere(600.0, 0.0, v * vc), sphere(600.0, 1.9 * 600.0, 0.0)];
            let sys = EllipsoidSystem::new(&moving, m, physics);
            let y = sys.initial_state();
            let found = mon.observe(k as f64 * 10.0, &sys, &y).unwrap();
            assert_eq!(found.len(), usize::from(*v > SPEED_MARGIN), "v = {v} v_c");
            states.push(mon.report().unwrap());
        }
        let full = mon.report().unwrap();
        assert_eq!(full.overrun_pairs, 1);
        assert_eq!(full.samples, 3);
        assert_eq!((full.pairs[0].first_t, full.pairs[0].worst_t), (10.0, 20.0));
        assert!(full.warnings()[0].starts_with("bodies 0 and 1 overran the contact barrier at t = 10 s"));
        drop(mon);
        // resume after the sample at t = 20 s: the t = 30 s row is dropped from the file, the report matches
        let resumed = BarrierMonitor::resume(settings, true, &log, 20.0).unwrap();
        assert_eq!(resumed.report().unwrap(), states[2]);
        let rows = std::fs::read_to_string(&log).unwrap().lines().count();
        assert_eq!(rows, 3, "header + two rows");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
