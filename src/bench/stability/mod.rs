//! `rubblepile bench stability`'s result files: `stability.csv` and `stability.md`, one row per case of the
//! stability suite: its cases ([`cases`]), how a case is judged ([`case`]) and how one is run ([`suite`]).

pub mod case;
pub mod cases;
pub mod suite;
#[cfg(test)]
mod suite_tests;

use std::io::Write;
use std::path::{Path, PathBuf};

use suite::{StabilityError, StabilityRow};

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

/// The measured columns of a row, `steps` to `min_step`, as text: the wall time with `wall_digits` decimals, the
/// energy and quaternion errors and the smallest step in scientific notation with `exp_digits`.
fn measured(r: &StabilityRow, wall_digits: usize, exp_digits: usize) -> [String; 7] {
    let exp = |x: f64| format!("{x:.exp_digits$e}");
    [
        r.steps.to_string(),
        r.rejections.to_string(),
        r.rhs_evaluations.to_string(),
        format!("{:.wall_digits$}", r.wall_seconds),
        exp(r.energy_error),
        exp(r.max_quat_norm_error),
        exp(r.min_step),
    ]
}

/// Writes `stability.csv` (columns [`CSV_COLUMNS`]).
pub fn write_csv(path: &Path, rows: &[StabilityRow]) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(f, "{}", CSV_COLUMNS.join(","))?;
    for r in rows {
        writeln!(
            f,
            "{},{},{},{},{}",
            csv_field(&r.case),
            csv_field(&r.description),
            measured(r, 3, 3).join(","),
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
            "| {} | {} | {} |",
            r.case,
            measured(r, 2, 1).join(" | "),
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
    fn csv_and_markdown_rows_write_the_measurements_at_their_precisions() {
        let row = StabilityRow {
            case: "a1".into(),
            description: "d".into(),
            steps: 12,
            rejections: 3,
            rhs_evaluations: 456,
            wall_seconds: 1.23456,
            energy_error: 2.5e-12,
            max_quat_norm_error: 7.25e-15,
            min_step: f64::NAN,
            verdict: suite::Verdict::Warn,
            note: "n".into(),
        };
        let dir = std::env::temp_dir().join(format!("rubblepile-bench-stability-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let [csv, md] = result_paths(&dir);
        write_csv(&csv, std::slice::from_ref(&row)).unwrap();
        write_markdown(&md, std::slice::from_ref(&row), "t").unwrap();
        let csv = std::fs::read_to_string(csv).unwrap();
        let md = std::fs::read_to_string(md).unwrap();
        let _ = std::fs::remove_dir_all(&dir);
        assert_eq!(
            csv.lines().nth(1),
            Some("a1,d,12,3,456,1.235,2.500e-12,7.250e-15,NaN,warn,n")
        );
        assert!(
            md.contains("\n| a1 | 12 | 3 | 456 | 1.23 | 2.5e-12 | 7.3e-15 | NaN | warn |\n"),
            "{md}"
        );
    }

    #[test]
    fn csv_fields_are_quoted() {
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("say \"x\""), "\"say \"\"x\"\"\"");
        assert_eq!(csv_field("plain"), "plain");
    }
}
