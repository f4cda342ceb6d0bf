//! The data of Roig03 Fig. 2: energy partition (a) and momentum conservation (b) over a run, from `timeseries.csv`
//! (totals) and `tracks.csv` (the projectile's state at the same times).
//!
//! Kinetic energies are relative to the *target* barycentre (as Fig. 3's ejection velocities), moving at
//! `V_T = (P − m_p v_p)/M_T`: projectile `K_p = ½ m_p |v_p − V_T|² + ½ ωᵀ I ω`; fragments
//! `K_f = (K_trans − ½ m_p |v_p|²) − ½ M_T |V_T|² + (K_rot − ½ ωᵀ I ω)`, normalised by the first `K_p` (the summary's
//! projectile energy without tracks). Without the projectile's tracks panel (a) shows the system totals,
//! `K_trans − ½ |P|²/(M_T + m_p)` and `K_rot`, and says so. Momentum drift `|P(t) − P(0)| / S_P`,
//! `|L(t) − L(0)| / S_L` (L about the origin) with [`momentum_scales`]: `S_P = Σ m_i |v_i|`,
//! `S_L = Σ (m_i |r_i × v_i| + |I_i ω_i|)` at t = 0, the sizes of the sums whose round-off the drift measures.

use std::path::Path;

use crate::ellipsoid::body::Body;
use crate::engine::{MOMENTUM_COLUMNS, column_names};

/// What Fig. 2 needs beyond the two CSV files (from the run's analysis).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyInputs {
    /// Index (snapshot id) of the projectile.
    pub projectile: usize,
    /// Projectile mass (kg).
    pub projectile_mass: f64,
    /// Projectile principal moments of inertia (kg m², the run's inertia model).
    pub projectile_moments: [f64; 3],
    /// Target mass `M_T` (kg), projectile excluded.
    pub target_mass: f64,
    /// Projectile kinetic energy relative to the target at t = 0 from the analysis summary (J): the
    /// normaliser when `tracks.csv` is missing.
    pub summary_projectile_energy: f64,
    /// `S_P` of [`momentum_scales`] (kg m/s).
    pub momentum_scale: f64,
    /// `S_L` of [`momentum_scales`] (kg m²/s).
    pub angular_momentum_scale: f64,
}

/// The curves of Fig. 2, one value per `timeseries.csv` row.
#[derive(Debug, Clone, PartialEq)]
pub struct EnergySeries {
    /// Times (s).
    pub t: Vec<f64>,
    /// The energy every curve of panel (a) is divided by (J).
    pub reference_energy: f64,
    /// Projectile kinetic energy (translational + rotational) over the reference; NaN at times without a
    /// `tracks.csv` row; `None` without tracks.
    pub projectile_kinetic: Option<Vec<f64>>,
    /// Fragments' (target bodies') kinetic energy, translational + rotational, over the reference; all bodies'
    /// when the projectile could not be separated (see [`EnergySeries::tracks_note`]).
    pub fragments_kinetic: Vec<f64>,
    /// Fragments' (or all bodies') rotational kinetic energy over the reference.
    pub fragments_rotational: Vec<f64>,
    /// Why the projectile could not be separated (`None` when it was).
    pub tracks_note: Option<String>,
    /// `|P(t) − P(0)| / S_P`.
    pub momentum_drift: Vec<f64>,
    /// `|L(t) − L(0)| / S_L`.
    pub angular_momentum_drift: Vec<f64>,
}

/// `S_P = Σ m_i |v_i|` (kg m/s) and `S_L = Σ (m_i |r_i × v_i| + |I_i ω_i|)` (kg m²/s, about the origin) over
/// `bodies`, with `moments[i]` the principal moments of body `i` (its spin is in body axes).
pub fn momentum_scales(bodies: &[Body], moments: &[[f64; 3]]) -> (f64, f64) {
    let mut s_p = 0.0;
    let mut s_l = 0.0;
    for (b, m) in bodies.iter().zip(moments) {
        s_p += b.shape.mass * b.velocity.norm();
        let w = b.spin_body;
        let spin = (m[0] * w.x).hypot(m[1] * w.y).hypot(m[2] * w.z);
        s_l += b.shape.mass * b.position.cross(&b.velocity).norm() + spin;
    }
    (s_p, s_l)
}

/// Column positions of `names` in a CSV header.
fn columns(path: &Path, headers: &csv::StringRecord, names: &[&str]) -> Result<Vec<usize>, String> {
    names
        .iter()
        .map(|n| {
            headers
                .iter()
                .position(|h| h.trim() == *n)
                .ok_or_else(|| format!("{}: no `{n}` column", path.display()))
        })
        .collect()
}

/// The rows of a CSV file as numbers in the order of `names`.
fn read_columns(path: &Path, names: &[&str]) -> Result<Vec<Vec<f64>>, String> {
    let mut rdr = csv::Reader::from_path(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let headers = rdr.headers().map_err(|e| format!("{}: {e}", path.display()))?.clone();
    let cols = columns(path, &headers, names)?;
    let mut rows = Vec::new();
    for (k, rec) in rdr.records().enumerate() {
        let rec = rec.map_err(|e| format!("{}: {e}", path.display()))?;
        let row = cols
            .iter()
            .zip(names)
            .map(|(&c, n)| {
                rec.get(c)
                    .and_then(|s| s.trim().parse::<f64>().ok())
                    .ok_or_else(|| format!("{}: row {}: `{n}` is not a number", path.display(), k + 1))
            })
            .collect::<Result<Vec<f64>, String>>()?;
        rows.push(row);
    }
    Ok(rows)
}

/// The columns of the ellipsoid engine's time series read here: t, the two kinetic energies, P and L.
const TIMESERIES: [&str; 9] = column_names(&[&["t", "kinetic_translational", "kinetic_rotational"], &MOMENTUM_COLUMNS]);
const TRACKS: [&str; 9] = ["t", "id", "mass", "vx", "vy", "vz", "wx", "wy", "wz"];

/// One projectile row of `tracks.csv`: time, velocity, kinetic translational and rotational energy.
struct Track {
    t: f64,
    velocity: [f64; 3],
    translational: f64,
    rotational: f64,
}

/// The projectile's rows of `tracks.csv`, sorted by time; `Err` says why there are none.
fn read_tracks(path: &Path, inputs: &EnergyInputs) -> Result<Vec<Track>, String> {
    if !path.is_file() {
        return Err("no tracks.csv".into());
    }
    let rows = read_columns(path, &TRACKS)?;
    let i = inputs.projectile_moments;
    let mut tracks: Vec<Track> = rows
        .iter()
        .filter(|r| r[1] == inputs.projectile as f64)
        .map(|r| {
            let (m, v, w) = (r[2], [r[3], r[4], r[5]], [r[6], r[7], r[8]]);
            Track {
                t: r[0],
                velocity: v,
                translational: 0.5 * m * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]),
                rotational: 0.5 * (i[0] * w[0] * w[0] + i[1] * w[1] * w[1] + i[2] * w[2] * w[2]),
            }
        })
        .collect();
    if tracks.is_empty() {
        return Err(format!("tracks.csv has no rows for body {}", inputs.projectile));
    }
    tracks.sort_by(|a, b| a.t.total_cmp(&b.t));
    Ok(tracks)
}

/// The track row at time `t` (to 1e-9 relative), if any.
fn track_at(tracks: &[Track], t: f64) -> Option<&Track> {
    let tol = 1e-9 * t.abs().max(1.0);
    let k = tracks.partition_point(|r| r.t < t - tol);
    tracks.get(k).filter(|r| (r.t - t).abs() <= tol)
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// Reads `run_dir/timeseries.csv` (required) and `run_dir/tracks.csv` (optional; see the module docs) into the
/// curves of Fig. 2.
pub fn read_energy_series(
    run_dir: &Path,
    inputs: &EnergyInputs,
) -> Result<EnergySeries, crate::analysis::AnalysisError> {
    let ts_path = run_dir.join("timeseries.csv");
    if !ts_path.is_file() {
        return Err(format!("{}: not found", ts_path.display()).into());
    }
    let rows = read_columns(&ts_path, &TIMESERIES)?;
    if rows.is_empty() {
        return Err(format!("{}: no rows", ts_path.display()).into());
    }
    let tracks = read_tracks(&run_dir.join("tracks.csv"), inputs);
    let (m_p, m_t) = (inputs.projectile_mass, inputs.target_mass);
    let t: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    let p = |r: &[f64]| [r[3], r[4], r[5]];
    let l = |r: &[f64]| [r[6], r[7], r[8]];
    let (p0, l0) = (p(&rows[0]), l(&rows[0]));
    let drift = |a: [f64; 3], b: [f64; 3], scale: f64| norm([a[0] - b[0], a[1] - b[1], a[2] - b[2]]) / scale;
    let momentum_drift = rows.iter().map(|r| drift(p(r), p0, inputs.momentum_scale)).collect();
    let angular_momentum_drift = rows
        .iter()
        .map(|r| drift(l(r), l0, inputs.angular_momentum_scale))
        .collect();

    // Per row: (projectile K_p, fragments K_f, fragments K_rot) in J, in the target's frame; None where the
    // projectile has no track row at that time.
    let separated = |tracks: &[Track]| -> Vec<Option<(f64, f64, f64)>> {
        rows.iter()
            .map(|r| {
                let tr = track_at(tracks, r[0])?;
                let pt = p(r);
                let v = tr.velocity;
                let p_target = [pt[0] - m_p * v[0], pt[1] - m_p * v[1], pt[2] - m_p * v[2]];
                let v_t = p_target.map(|x| x / m_t);
                let rel = [v[0] - v_t[0], v[1] - v_t[1], v[2] - v_t[2]];
                let k_p = 0.5 * m_p * norm(rel).powi(2) + tr.rotational;
                let k_f_rot = r[2] - tr.rotational;
                let k_f_trans = r[1] - tr.translational - 0.5 * m_t * norm(v_t).powi(2);
                Some((k_p, k_f_trans + k_f_rot, k_f_rot))
            })
            .collect()
    };
    match tracks {
        Ok(tracks) => {
            let values = separated(&tracks);
            let reference = values[0].map_or(inputs.summary_projectile_energy, |v| v.0);
            let pick = |f: fn(&(f64, f64, f64)) -> f64| -> Vec<f64> {
                values
                    .iter()
                    .map(|v| v.as_ref().map_or(f64::NAN, f) / reference)
                    .collect()
            };
            Ok(EnergySeries {
                t,
                reference_energy: reference,
                projectile_kinetic: Some(pick(|v| v.0)),
                fragments_kinetic: pick(|v| v.1),
                fragments_rotational: pick(|v| v.2),
                tracks_note: None,
                momentum_drift,
                angular_momentum_drift,
            })
        }
        Err(why) => {
            let reference = inputs.summary_projectile_energy;
            let m = m_t + m_p;
            Ok(EnergySeries {
                t,
                reference_energy: reference,
                projectile_kinetic: None,
                fragments_kinetic: rows
                    .iter()
                    .map(|r| (r[1] - 0.5 * norm(p(r)).powi(2) / m + r[2]) / reference)
                    .collect(),
                fragments_rotational: rows.iter().map(|r| r[2] / reference).collect(),
                tracks_note: Some(why),
                momentum_drift,
                angular_momentum_drift,
            })
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The inputs of the run [`write_synthetic_run`] writes.
    pub(crate) fn inputs() -> EnergyInputs {
        EnergyInputs {
            projectile: 1,
            projectile_mass: 2.0,
            projectile_moments: [1.0, 1.0, 4.0],
            target_mass: 6.0,
            summary_projectile_energy: 9.0,
            momentum_scale: 10.0,
            angular_momentum_scale: 100.0,
        }
    }

    pub(crate) fn write_synthetic_run(dir: &Path, with_tracks: bool) {
        std::fs::create_dir_all(dir).unwrap();
        // Two rows. t = 0: projectile (m = 2) at v = (3, 0, 0) spinning at ω = (0, 0, 1) about its I = 4 axis,
        // target (M = 6) at rest spinning with K_rot = 5. t = 10: everything moves at 0.75 m/s along x (momentum
        // 6 conserved), projectile ω = (0, 0, 0.5), total K_rot = 3.
        std::fs::write(
            dir.join("timeseries.csv"),
            "t,kinetic_translational,kinetic_rotational,potential_contact,potential_gravity,dissipated,\
             energy_residual,px,py,pz,lx,ly,lz,wall_seconds\n\
             0e0,9e0,7e0,0,0,0,0,6e0,0,0,0,0,5e1,0\n\
             1e1,2.25e0,3e0,0,0,0,0,6e0,1e-12,0,0,0,5e1,0.5\n",
        )
        .unwrap();
        if with_tracks {
            std::fs::write(
                dir.join("tracks.csv"),
                "t,id,mass,a,b,c,x,y,z,vx,vy,vz,qa,qb,qc,qd,wx,wy,wz\n\
                 0e0,1,2e0,1,1,1,-50,0,0,3e0,0,0,0,0,0,1,0,0,1e0\n\
                 1e1,1,2e0,1,1,1,-20,0,0,7.5e-1,0,0,0,0,0,1,0,0,5e-1\n",
            )
            .unwrap();
        }
    }

    /// Hand computation (module-doc formulas): t = 0: V_T = (6 − 2·3)/6 = 0, K_p = ½·2·9 + ½·4·1 = 11 (the
    /// reference), K_f = (9 − 9 − 0) + (7 − 2) = 5. t = 10: V_T = (6 − 1.5)/6 = 0.75, K_p = 0 + ½·4·0.25 = 0.5,
    /// K_f,rot = 3 − 0.5 = 2.5, K_f,trans = 2.25 − 0.5625 − ½·6·0.5625 = 0.
    #[test]
    fn projectile_energy_from_tracks_matches_hand_computation() {
        let dir = std::env::temp_dir().join(format!("rubblepile-fig2-{}", std::process::id()));
        write_synthetic_run(&dir, true);
        let s = read_energy_series(&dir, &inputs()).unwrap();
        assert_eq!(s.t, vec![0.0, 10.0]);
        assert!((s.reference_energy - 11.0).abs() < 1e-12, "{}", s.reference_energy);
        let p = s.projectile_kinetic.as_ref().unwrap();
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert!(close(p[0], 1.0) && close(p[1], 0.5 / 11.0), "{p:?}");
        assert!(close(s.fragments_kinetic[0], 5.0 / 11.0), "{:?}", s.fragments_kinetic);
        assert!(close(s.fragments_kinetic[1], 2.5 / 11.0), "{:?}", s.fragments_kinetic);
        assert!(close(s.fragments_rotational[1], 2.5 / 11.0));
        assert!(close(s.momentum_drift[1], 1e-13) && s.momentum_drift[0] == 0.0);
        assert!(s.tracks_note.is_none());

        // without tracks.csv: totals of all bodies in the system frame (M = 8, |P| = 6), summary normaliser
        std::fs::remove_file(dir.join("tracks.csv")).unwrap();
        let s = read_energy_series(&dir, &inputs()).unwrap();
        assert!(s.projectile_kinetic.is_none() && s.tracks_note.as_deref() == Some("no tracks.csv"));
        assert!(close(s.fragments_kinetic[0], (9.0 - 36.0 / 16.0 + 7.0) / 9.0));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn missing_timeseries_is_an_error_not_a_panic() {
        let dir = std::env::temp_dir().join(format!("rubblepile-fig2-missing-{}", std::process::id()));
        let err = read_energy_series(&dir, &inputs()).unwrap_err();
        assert!(err.to_string().contains("timeseries.csv"), "{err}");
    }
}
