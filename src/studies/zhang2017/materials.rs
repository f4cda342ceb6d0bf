//! Zhang17 §4.4, Table 7: the HCP and PP2 models with a weaker (β = 0.3, μ_s = 0.5) and a stronger (β = 0.6,
//! μ_s = 1.3) material than the nominal one (β = 0.5, μ_s = 1.0), each pile settled with its own material before
//! the spin-up (a lattice settled with μ_s = 1.0 and then spun with μ_s = 0.5 compacts during its holds).
//!
//! Layout read: `RUNS/<model>_beta<β>_mus<μ_s>/path2` and `…/critical` ([`variant_dir`]), the nominal material's
//! run being the Table 3 one, `RUNS/<model>`. Such directories are neither Table 3 rows nor bulk-density points
//! ([`super::rows::is_material_variant`]). Per material: T_c,1/T_c,2 of path 2, T_c,3 by both creep criteria and where the
//! pile stops failing ([`super::ordering::union_search`]), φ, and the single-density κ₃ and critical bulk density
//! at the Didymos period (Eq. 22, as Table 7 gives them) beside the paper's.

use std::fmt::Write as _;
use std::path::Path;

use rubblepile::analysis::spinup::fit_density;
use rubblepile::io::scene_file::SI_G;

use super::ordering::union_search;
use super::rows::{DIDYMOS_PERIOD_HOURS, ModelRow, bulk_density, is_material_variant, opt};

/// Zhang17 Table 7: model, β, μ_s, and the paper's ρ_B^{c,3} (kg/m³), κ₃ and φ (°) (full size, path 1); the
/// nominal material's column repeats Table 4.
pub const TABLE7: [(&str, f64, f64, f64, f64, f64); 6] = [
    ("hcp", 0.3, 0.5, 2430.0, 0.937, 42.0),
    ("hcp", 0.5, 1.0, 2383.0, 0.946, 43.0),
    ("hcp", 0.6, 1.3, 2369.0, 0.949, 43.0),
    ("pp2", 0.3, 0.5, 2952.0, 0.850, 35.0),
    ("pp2", 0.5, 1.0, 2662.0, 0.895, 38.0),
    ("pp2", 0.6, 1.3, 2612.0, 0.904, 39.0),
];

/// Zhang17 §2.3.3: the nominal shape parameter β and static friction μ_s.
pub const NOMINAL_MATERIAL: (f64, f64) = (0.5, 1.0);

/// The run directory of `model` with material (β, μ_s): the model itself for the nominal material, else
/// `<model>_beta<β>_mus<μ_s>`.
pub fn variant_dir(model: &str, beta: f64, mu_s: f64) -> String {
    if (beta, mu_s) == NOMINAL_MATERIAL {
        model.to_string()
    } else {
        format!("{model}_beta{beta:?}_mus{mu_s:?}")
    }
}

/// The particle file a run started from (`particles_file` of its `scene.toml`, file name only): which settled
/// lattice the material variant was spun up from.
fn target_of(run: &Path) -> Option<String> {
    let text = std::fs::read_to_string(run.join("scene.toml")).ok()?;
    let table: toml::Table = text.parse().ok()?;
    let file = table.get("scene")?.get("particles_file")?.as_str()?;
    Path::new(file).file_name().map(|n| n.to_string_lossy().into_owned())
}

/// The section "Table 7": one row per entry of [`TABLE7`] whose model has a Table 3 run under `runs`; a material
/// not run says so.
pub fn write_materials_section(md: &mut String, runs: &Path, rows: &[ModelRow]) {
    let models: Vec<&str> = TABLE7
        .iter()
        .map(|t| t.0)
        .filter(|m| rows.iter().any(|r| r.model == *m))
        .collect();
    if !rows.iter().any(|r| is_material_variant(&r.model)) {
        return;
    }
    let _ = writeln!(md, "\n## Material (Zhang17 §4.4, Table 7)\n");
    let _ = writeln!(
        md,
        "The model spun up along path 2 with the weaker and the stronger material of §4.4, each from a pile settled \
         with that material (runs `<model>_beta<β>_mus<μ_s>`, scenes `analysis/zhang2017/<model>_beta<β>_mus<μ_s>_path2.toml`); \
         the nominal row is Table 3's. T_c3 by the paper's creep criterion with tolerances (`paper-tolerance`) and by ours, and where the pile stops \
         failing (the shortest period held above every released hold; holds of 16 000 s). φ is the θ_max of that \
         hold, and κ₃ and ρ_B^{{c,3}} (the bulk density whose T_c3 is the Didymos period, {DIDYMOS_PERIOD_HOURS} h) \
         follow from its period by Eq. 22 at the one density run: where it stops failing is defined for every \
         material, while a creep criterion that rejects a relaxing slow hold moves its T_c3 to the slowest holds. The \
         paper fits κ₃ over several densities.\n"
    );
    let _ = writeln!(
        md,
        "| model | β, μ_s | spun up from | T_c1 / T_c2 (h) | T_c3 (h): paper-tolerance / ours | stops failing (h) | φ (°) there | κ₃, ρ_B^{{c,3}} (kg/m³) there | paper: κ₃, ρ_B^{{c,3}}, φ |"
    );
    let _ = writeln!(md, "| --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    for &(model, beta, mu_s, rho_c, kappa, phi) in TABLE7.iter().filter(|t| models.contains(&t.0)) {
        let dir = variant_dir(model, beta, mu_s);
        let paper = format!("{kappa:.3}, {rho_c:.0}, {phi:.0}°");
        let Some(row) = rows.iter().find(|r| r.model == dir) else {
            let _ = writeln!(
                md,
                "| {} | {beta:.1}, {mu_s:.1} | not run | | | | | | {paper} |",
                model.to_uppercase()
            );
            continue;
        };
        let search = union_search(&runs.join(&dir).join("critical"));
        let [paper_c, ours_c] = row.t_c3_by_criterion.unwrap_or([(row.t_c3, row.phi), (None, None)]);
        let stops = search.as_ref().map_or("–".to_string(), |s| {
            let t = opt(s.after_release_hours, 2);
            if s.bracketed { t } else { format!("≤ {t}") }
        });
        // Eq. 22 through where the pile stops failing: the one measure defined for every material (the creep
        // criteria reject some slow holds whose θ_max relaxes, and then every faster hold by the trailing rule)
        let at_stop = search.as_ref().filter(|s| s.bracketed);
        let fit = at_stop
            .and_then(|s| s.after_release_hours)
            .and_then(|t| fit_density(&[(bulk_density(row), t)], SI_G, DIDYMOS_PERIOD_HOURS));
        let _ = writeln!(
            md,
            "| {} | {beta:.1}, {mu_s:.1} | `{}` | {} / {} | {} / {} | {stops} | {} | {} | {paper} |",
            model.to_uppercase(),
            target_of(&runs.join(&dir).join("path2")).unwrap_or_else(|| "?".into()),
            opt(row.limits.t_c1_hours, 3),
            opt(row.limits.t_c2_hours, 3),
            opt(paper_c.0, 2),
            opt(ours_c.0, 2),
            opt(at_stop.and_then(|s| s.after_release_theta_deg), 1),
            fit.map_or("–".into(), |f| format!("{:.3}, {:.0}", f.kappa, f.critical_density)),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The nominal material runs in the model's own directory, the others in `<model>_beta<β>_mus<μ_s>`.
    #[test]
    fn the_nominal_material_runs_in_the_model_directory() {
        assert_eq!(variant_dir("hcp", 0.3, 0.5), "hcp_beta0.3_mus0.5");
        assert_eq!(variant_dir("hcp", 0.5, 1.0), "hcp");
    }
}
