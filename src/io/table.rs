//! Numeric CSV tables (a header line of column names, then rows of numbers) read with the `csv` crate: the time
//! series, snapshots and logs that the analysis and the benchmarks read back. Errors name the file, the line and the
//! column.

use std::fs::File;
use std::path::{Path, PathBuf};

/// Why a table could not be read.
#[derive(Debug, thiserror::Error)]
pub enum TableError {
    /// The file could not be opened or read.
    #[error("{}: {source}", .path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The OS or CSV error.
        source: csv::Error,
    },
    /// A cell is not a number.
    #[error("{} line {line}: column {column}: expected a number, got {value:?}", .path.display())]
    Number {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: u64,
        /// The column's name.
        column: String,
        /// The cell.
        value: String,
    },
    /// The header is not the one expected.
    #[error("{}: unexpected header (expected {expected})", .path.display())]
    Header {
        /// The file.
        path: PathBuf,
        /// What was expected.
        expected: String,
    },
}

/// A CSV file of numbers under a header of column names.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// The column names.
    pub columns: Vec<String>,
    /// The rows, one number per column (rows of a file still being written may be shorter).
    pub rows: Vec<Vec<f64>>,
}

impl Table {
    /// The index of column `name`.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == name)
    }

    /// The values of column `name` (NaN where a row is too short).
    pub fn values(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.column(name)?;
        Some(
            self.rows
                .iter()
                .map(|r| r.get(k).copied().unwrap_or(f64::NAN))
                .collect(),
        )
    }
}

/// How cells that are not numbers are treated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cells {
    /// Every cell must be a number; rows must be complete.
    Strict,
    /// Cells that are not numbers read as NaN, and short rows (a file still being written) are kept as they are.
    Lenient,
}

/// Reads the numeric CSV file at `path`.
pub fn read_table(path: &Path, cells: Cells) -> Result<Table, TableError> {
    let read_err = |source: csv::Error| TableError::Read {
        path: path.to_path_buf(),
        source,
    };
    let file = crate::io::scene_file::open_bounded(path).map_err(|e| read_err(e.into()))?;
    let mut reader = csv::ReaderBuilder::new()
        .flexible(cells == Cells::Lenient)
        .trim(csv::Trim::All)
        .from_reader(file);
    let columns: Vec<String> = reader.headers().map_err(read_err)?.iter().map(str::to_string).collect();
    let mut rows = Vec::new();
    for record in reader.records() {
        let record = record.map_err(read_err)?;
        let line = record.position().map_or(0, |p| p.line());
        let mut row = Vec::with_capacity(record.len());
        for (k, cell) in record.iter().enumerate() {
            match (cell.parse::<f64>(), cells) {
                (Ok(x), _) => row.push(x),
                (Err(_), Cells::Lenient) => row.push(f64::NAN),
                (Err(_), Cells::Strict) => {
                    return Err(TableError::Number {
                        path: path.to_path_buf(),
                        line,
                        column: columns.get(k).cloned().unwrap_or_else(|| format!("#{}", k + 1)),
                        value: cell.to_string(),
                    });
                }
            }
        }
        rows.push(row);
    }
    Ok(Table { columns, rows })
}

/// The column names of the CSV file at `path` (its first line).
pub fn read_header(path: &Path) -> Result<Vec<String>, TableError> {
    let read_err = |source: csv::Error| TableError::Read {
        path: path.to_path_buf(),
        source,
    };
    let file = crate::io::scene_file::open_bounded(path).map_err(|e| read_err(e.into()))?;
    let mut reader = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(file);
    Ok(reader.headers().map_err(read_err)?.iter().map(str::to_string).collect())
}

/// A CSV reader on `path` (`csv::Reader::from_path`, cells as written) and the position in its header of each of
/// `names`. The error is one line without the path (the caller names the file): the CSV error, or
/// ``no `name` column``.
pub fn open_columns<const N: usize>(path: &Path, names: [&str; N]) -> Result<(csv::Reader<File>, [usize; N]), String> {
    let mut reader = csv::Reader::from_path(path).map_err(|e| e.to_string())?;
    let headers = reader.headers().map_err(|e| e.to_string())?;
    let mut at = [0; N];
    for (k, name) in at.iter_mut().zip(names) {
        *k = headers
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| format!("no `{name}` column"))?;
    }
    Ok((reader, at))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(name: &str, text: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("rubblepile-table-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    #[test]
    fn strict_tables_name_the_bad_cell_and_lenient_ones_keep_going() {
        let p = file("a.csv", "t,x,y\n0,1e0,2\n1,x,3\n2,4");
        let e = read_table(&p, Cells::Strict).unwrap_err().to_string();
        assert!(
            e.contains("line 3") && e.contains("column x") && e.contains("\"x\""),
            "{e}"
        );
        let t = read_table(&p, Cells::Lenient).unwrap();
        assert_eq!(t.rows.len(), 3);
        assert!(t.rows[1][1].is_nan());
        assert_eq!(t.rows[2], vec![2.0, 4.0], "a row still being written is kept short");
        assert!(t.values("y").unwrap()[2].is_nan());
        assert_eq!(read_header(&p).unwrap(), vec!["t", "x", "y"]);
        let exact = file("b.csv", "v\n0.1\n6.674e-11\n");
        let t = read_table(&exact, Cells::Strict).unwrap();
        assert_eq!(t.rows[1][0].to_bits(), 6.674e-11f64.to_bits());
    }
}
