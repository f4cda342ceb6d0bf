//! An aggregate on disk: the particle file (`t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz`, the soft-sphere scene's
//! `particles_file`) with its JSON report beside it (`NAME.json`), and the bulk-density variant of Zhang17 §4.2
//! made from such a pair.

use std::path::{Path, PathBuf};

use crate::aggregate::report::AggregateReport;
use crate::aggregate::{AggregateError, density, input};
use crate::granular::soft::particle::Particle;
use crate::granular::soft::run::write_particles_csv;
use crate::math::Vec3;

/// The JSON report beside a particle file: `NAME.csv` → `NAME.json`.
pub fn report_path(csv: &Path) -> PathBuf {
    csv.with_extension("json")
}

/// Refuses an output path that is not `FILE.csv`, or whose CSV or JSON exists unless `force`.
pub fn check_outputs(out: &Path, force: bool) -> Result<(), AggregateError> {
    if out.extension().and_then(|e| e.to_str()) != Some("csv") {
        return Err(input(
            "--out",
            format!("expected a FILE.csv path, got {}", out.display()),
        ));
    }
    for p in [out.to_path_buf(), report_path(out)] {
        if p.exists() && !force {
            return Err(input(
                "--out",
                format!("{} exists; pass --force to overwrite it", p.display()),
            ));
        }
    }
    Ok(())
}

/// Writes the particle file at `out` (t = 0) and its report beside it, creating the folder.
pub fn write_aggregate(out: &Path, particles: &[Particle], report: &AggregateReport) -> Result<(), AggregateError> {
    let failed = |p: &Path, e: std::io::Error| AggregateError::Failed(format!("{}: {e}", p.display()));
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| failed(dir, e))?;
    }
    write_particles_csv(out, 0.0, particles).map_err(|e| failed(out, e))?;
    let json = serde_json::to_string_pretty(report).expect("report serialises") + "\n";
    let path = report_path(out);
    std::fs::write(&path, json).map_err(|e| failed(&path, e))
}

/// Reads a particle file written by `aggregate build` through the shared particle reader
/// ([`crate::io::particles::read_particles`]); errors name the file, line and column.
pub fn read_aggregate_csv(path: &Path) -> Result<Vec<Particle>, AggregateError> {
    const COLUMNS: [&str; 11] = ["mass", "radius", "x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz"];
    let rows = crate::io::particles::read_particles(path, &COLUMNS, &[])
        .map_err(|e| input("--input", format!("{}: {e}", path.display())))?;
    Ok(rows
        .iter()
        .map(|r| {
            let v = &r.values;
            Particle {
                mass: v[0],
                radius: v[1],
                position: Vec3::new(v[2], v[3], v[4]),
                velocity: Vec3::new(v[5], v[6], v[7]),
                spin: Vec3::new(v[8], v[9], v[10]),
            }
        })
        .collect())
}

/// The bulk-density variant of the aggregate at `input_csv`: same positions, radii and velocities, masses scaled
/// so that the bulk density becomes `bulk_density` (kg/m³). The body's shape volume comes from the aggregate's
/// report, `report_json` or by default the `NAME.json` beside the CSV (a settled snapshot of an aggregate has
/// none: name the report of the aggregate it was settled from). Returns the particles, the updated report and
/// the mass factor.
pub fn density_variant(
    input_csv: &Path,
    report_json: Option<&Path>,
    bulk_density: f64,
) -> Result<(Vec<Particle>, AggregateReport, f64), AggregateError> {
    if !(bulk_density.is_finite() && bulk_density > 0.0) {
        return Err(input(
            "--bulk-density-kg-m3",
            format!("a positive density in kg/m³, got {bulk_density}"),
        ));
    }
    let json_in = report_json.map_or_else(|| report_path(input_csv), Path::to_path_buf);
    let field = if report_json.is_some() { "--report" } else { "--input" };
    let bad = |e: String| input(field, format!("{}: {e}", json_in.display()));
    let text = std::fs::read_to_string(&json_in).map_err(|e| bad(e.to_string()))?;
    let old: AggregateReport = serde_json::from_str(&text).map_err(|e| bad(e.to_string()))?;
    let mut particles = read_aggregate_csv(input_csv)?;
    let factor = density::rescale_bulk_density(&mut particles, old.shape_volume_m3, bulk_density);
    // the geometry is unchanged: only what the masses set is recomputed
    let total: f64 = particles.iter().map(|p| p.mass).sum();
    let report = AggregateReport {
        grain_density_kg_m3: old.grain_density_kg_m3 * factor,
        core_grain_density_kg_m3: old.core_grain_density_kg_m3.map(|x| x * factor),
        total_mass_kg: total,
        bulk_density_kg_m3: total / old.shape_volume_m3,
        notes: format!(
            "{}; bulk-density variant of {} (masses × {factor}){}",
            old.notes,
            input_csv.display(),
            report_json.map_or(String::new(), |r| format!("; shape volume from {}", r.display()))
        ),
        ..old
    };
    Ok((particles, report, factor))
}
