//! The body a Zhang17 spin-up run spins, read from the run itself rather than assumed (the paper's Didymos
//! primary is D = 780 m, ρ_B = 2100 kg/m³, Zhang17 Table 1; a user's body need not be): its volume-equivalent
//! diameter and bulk density.
//!
//! Two sources, best first: the aggregate's record `NAME.json` beside the scene's `particles_file` (written by
//! `rubblepile aggregate`: `shape_equivalent_diameter_m`, `bulk_density_kg_m3`), used when its `total_mass_kg`
//! is the run's mass; else the grains over the packing, `V = Σ (4/3)π r³ / η_B` with η_B at t_start, the
//! estimate by which [`rubblepile::analysis::spinup::paper_bulk_density`] derives the paper's own bodies (it takes
//! the interior's packing for the whole body's filling: for our settled HCP, D 783 m and ρ_B 2072 kg/m³ against
//! the carved 780 m and 2100 kg/m³).

use std::path::Path;

/// Where a [`Body`]'s size and density were read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BodySource {
    /// The aggregate's `NAME.json` (exact: the carved shape's volume).
    Aggregate,
    /// Grain volume over η_B at t_start (an estimate).
    GrainsOverPacking,
}

/// A run's body: volume-equivalent diameter (m) and bulk density (kg/m³).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Body {
    /// Diameter of the sphere of the body's volume (m).
    pub diameter_m: f64,
    /// Mass over volume (kg/m³).
    pub bulk_density: f64,
    /// See [`BodySource`].
    pub source: BodySource,
}

impl Body {
    /// "D = 780 m, ρ_B = 2100 kg/m³", with "≈" for an estimate.
    pub fn describe(&self) -> String {
        let is = if self.source == BodySource::Aggregate {
            "="
        } else {
            "≈"
        };
        format!(
            "D {is} {:.0} m, ρ_B {is} {:.0} kg/m³",
            self.diameter_m, self.bulk_density
        )
    }
}

/// The aggregate record beside the run's `particles_file` (its `.json`), if it describes a body of `mass_kg`
/// (relative 1e-6: a record of another mass is not this body's).
fn from_aggregate(run: &Path, mass_kg: f64) -> Option<Body> {
    let scene: toml::Table = std::fs::read_to_string(run.join("scene.toml")).ok()?.parse().ok()?;
    let particles = Path::new(scene.get("scene")?.get("particles_file")?.as_str()?);
    let particles = if particles.is_absolute() {
        particles.to_path_buf()
    } else {
        run.join(particles)
    };
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(particles.with_extension("json")).ok()?).ok()?;
    let recorded_mass = record["total_mass_kg"].as_f64()?;
    if ((recorded_mass - mass_kg) / mass_kg).abs() > 1e-6 {
        return None;
    }
    Some(Body {
        diameter_m: record["shape_equivalent_diameter_m"].as_f64()?,
        bulk_density: record["bulk_density_kg_m3"].as_f64()?,
        source: BodySource::Aggregate,
    })
}

/// The body of the run directory `run`: total mass `mass_kg`, grain volume `grain_volume_m3` (Σ (4/3)π r³, if
/// known) and η_B at t_start `packing`; `None` when neither source gives a finite positive size.
pub fn body_of(run: &Path, mass_kg: f64, grain_volume_m3: Option<f64>, packing: f64) -> Option<Body> {
    if !(mass_kg.is_finite() && mass_kg > 0.0) {
        return None;
    }
    if let Some(b) = from_aggregate(run, mass_kg) {
        return Some(b);
    }
    let volume = grain_volume_m3? / packing;
    (volume.is_finite() && volume > 0.0).then(|| Body {
        diameter_m: (6.0 * volume / std::f64::consts::PI).cbrt(),
        bulk_density: mass_kg / volume,
        source: BodySource::GrainsOverPacking,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 1000 grains of 10 m radius at η_B = 0.5 fill the volume of 2000 grains, a sphere of radius 10·2000^(1/3) m;
    /// the aggregate record is used for its own mass only.
    #[test]
    fn grains_over_packing_and_a_record_of_another_mass() {
        let dir = std::env::temp_dir().join(format!("rp_body_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("scene.toml"), "[scene]\nparticles_file = \"agg.csv\"\n").unwrap();
        std::fs::write(
            dir.join("agg.json"),
            r#"{"total_mass_kg": 2.0, "shape_equivalent_diameter_m": 500.0, "bulk_density_kg_m3": 1900.0}"#,
        )
        .unwrap();
        let grains = 1000.0 * 4.0 / 3.0 * std::f64::consts::PI * 1e3;
        let b = body_of(&dir, 1e12, Some(grains), 0.5).unwrap();
        assert_eq!(b.source, BodySource::GrainsOverPacking);
        assert!((b.diameter_m - 2.0 * 10.0 * 2000f64.cbrt()).abs() < 1e-9, "{b:?}");
        let b = body_of(&dir, 2.0, Some(grains), 0.5).unwrap();
        assert_eq!(
            (b.diameter_m, b.bulk_density, b.source),
            (500.0, 1900.0, BodySource::Aggregate)
        );
        assert_eq!(b.describe(), "D = 500 m, ρ_B = 1900 kg/m³");
        assert!(body_of(&dir, f64::NAN, Some(grains), 0.5).is_none());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
