//! Serde rows to and from CSV files, the form of the compact copies that let a report regenerate from committed
//! files (the Roig03 referee tables, the Richardson11 tumbler runs). Errors name the file.

use std::path::Path;

use rubblepile::analysis::AnalysisError;

/// Every row of the CSV file at `path` as a `T` (header row first, columns by name).
pub fn read_rows<T: serde::de::DeserializeOwned>(path: &Path) -> Result<Vec<T>, AnalysisError> {
    let err = |e: String| AnalysisError::Input(format!("{}: {e}", path.display()));
    let mut r = csv::Reader::from_path(path).map_err(|e| err(e.to_string()))?;
    r.deserialize().map(|row| row.map_err(|e| err(e.to_string()))).collect()
}

/// Writes `rows` to `path` with a header row (f64 in the shortest form that reads back to the same bits; NaN
/// as `NaN`).
pub fn write_rows<T: serde::Serialize>(path: &Path, rows: &[T]) -> Result<(), AnalysisError> {
    let err = |e: String| AnalysisError::Output(format!("{}: {e}", path.display()));
    let mut w = csv::Writer::from_path(path).map_err(|e| err(e.to_string()))?;
    for row in rows {
        w.serialize(row).map_err(|e| err(e.to_string()))?;
    }
    w.flush().map_err(|e| err(e.to_string()))
}
