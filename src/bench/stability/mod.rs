//! `rubblepile bench stability`'s result files: `stability.csv` and `stability.md`, one row per case of the
//! stability suite ([`rubblepile::driver::stability`], which holds the cases, runs them and judges them).

use std::io::Write;
use std::path::{Path, PathBuf};

use rubblepile::driver::stability::{StabilityError, StabilityRow};

/// Columns of `stability.csv`.
pub const CSV_COLUMNS: [&str; 11] = [
    "case",
    "description",
    "steps",
    "rejections",
    "rhs_evaluations",
    "wall_seconds",
    "energy_error",
    "max_quat_norm_error",
    "min_step",
    "verdict",
    "note",
];

/// The result files of the suite in `out`.
pub fn result_paths(out: &Path) -> [PathBuf; 2] {
    [out.join("stability.csv"), out.join("stability.md")]
}

/// Refuses an `out` that already holds results unless `force`; creates it.
pub fn prepare_out(out: &Path, force: bool) -> Result<(), StabilityError> {
    if !force && (result_paths(out).iter().any(|p| p.exists()) || out.join("runs").exists()) {
        return Err(StabilityError::OutputExists(out.to_path_buf()));
    }
    std::fs::create_dir_all(out.join("runs")).map_err(|source| StabilityError::Io {
        path: out.join("runs"),
        source,
    })
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Writes `stability.csv` (columns [`CSV_COLUMNS`]).
pub fn write_csv(path: &Path, rows: &[StabilityRow]) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(f, "{}", CSV_COLUMNS.join(","))?;
    for r in rows {
        writeln!(
            f,
            "{},{},{},{},{},{:.3},{:.3e},{:.3e},{:.3e},{},{}",
            csv_field(&r.case),
            csv_field(&r.description),
            r.steps,
            r.rejections,
            r.rhs_evaluations,
            r.wall_seconds,
            r.energy_error,
            r.max_quat_norm_error,
            r.min_step,
            r.verdict.as_str(),
            csv_field(&r.note)
        )?;
    }
    f.flush()
}

/// Writes `stability.md`: one table row per case, notes below.
pub fn write_markdown(path: &Path, rows: &[StabilityRow], title: &str) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(f, "# {title}\n")?;
    writeln!(
        f,
        "| case | steps | rejected | RHS | wall (s) | energy error | max \\|\\|q\\|-1\\| | min step (s) | verdict |"
    )?;
    writeln!(f, "|---|---:|---:|---:|---:|---:|---:|---:|---|")?;
    for r in rows {
        writeln!(
            f,
            "| {} | {} | {} | {} | {:.2} | {:.1e} | {:.1e} | {:.1e} | {} |",
            r.case,
            r.steps,
            r.rejections,
            r.rhs_evaluations,
            r.wall_seconds,
            r.energy_error,
            r.max_quat_norm_error,
            r.min_step,
            r.verdict.as_str()
        )?;
    }
    writeln!(f, "\n## Cases and criteria\n")?;
    for r in rows {
        writeln!(
            f,
            "- **{}** ({}): {}. {}",
            r.case,
            r.verdict.as_str(),
            r.description,
            r.note
        )?;
    }
    f.flush()
}
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_fields_are_quoted() {
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("say \"x\""), "\"say \"\"x\"\"\"");
        assert_eq!(csv_field("plain"), "plain");
    }
}
