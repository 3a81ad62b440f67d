//! Reading one value column against a strictly increasing time column of a CSV file (a header
//! row, then data rows). Every failure names the file, and the line where a row is at fault.
//!
//! Used by CSV joint references (time column `t`, seconds) and by the analysis of recorded
//! runs (time column `t_ns`, integer nanoseconds).

use crate::csv_table::Table;
use std::fmt::Display;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// A CSV column that could not be read.
#[derive(Debug, thiserror::Error, docsplay::Display)]
pub enum ColumnError {
    /// {path}: cannot read: {cause}
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O or CSV error (its text is part of the message, so it is not a `source`).
        cause: csv::Error,
    },
    /// {0}
    Input(crate::input_file::InputFileError),
    /// {path}: no column `{column}` in the header (columns: {found})
    MissingColumn {
        /// The file.
        path: PathBuf,
        /// The column asked for.
        column: String,
        /// The header's columns.
        found: String,
    },
    /// {path}:{line}: {reason}
    BadRow {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: u64,
        /// What is wrong.
        reason: String,
    },
    /// {path}: needs at least {needed} data rows, found {found}
    TooShort {
        /// The file.
        path: PathBuf,
        /// Rows needed.
        needed: usize,
        /// Rows found.
        found: usize,
    },
}

/// A time stamp type of a time column.
pub trait TimeStamp: FromStr + PartialOrd + Copy + Display {
    /// Whether a parsed value is usable (finite for floats).
    fn is_valid(&self) -> bool;
}

impl TimeStamp for f64 {
    fn is_valid(&self) -> bool {
        self.is_finite()
    }
}

impl TimeStamp for u64 {
    fn is_valid(&self) -> bool {
        true
    }
}

/// Reads `(time, value)` pairs: times strictly increasing, values finite, at least `min_rows`.
pub fn read<T: TimeStamp>(
    path: &Path,
    time: &str,
    column: &str,
    min_rows: usize,
) -> Result<(Vec<T>, Vec<f64>), ColumnError> {
    let rows = read_checked(path, time, column, min_rows, |_, _| Ok(()))?;
    Ok((rows.times, rows.values))
}

/// The rows [`read_checked`] returns.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Rows<T> {
    /// Times, strictly increasing.
    pub times: Vec<T>,
    /// Finite values.
    pub values: Vec<f64>,
    /// The 1-based line of each row in the file.
    pub lines: Vec<u64>,
}

/// [`read`], with `check(time, value)` refusing a row (its reason is located at the row's
/// line), and the rows' lines.
pub fn read_checked<T: TimeStamp>(
    path: &Path,
    time: &str,
    column: &str,
    min_rows: usize,
    mut check: impl FnMut(T, f64) -> Result<(), String>,
) -> Result<Rows<T>, ColumnError> {
    let table = Table::open(path)?;
    let [ti, vi] = table.columns([time, column])?;
    let (mut times, mut values, mut lines) = (Vec::<T>::new(), Vec::new(), Vec::new());
    table.for_each(|row| {
        let (t_text, v_text) = (row.text(ti), row.text(vi));
        let t: T = t_text
            .parse()
            .ok()
            .filter(T::is_valid)
            .ok_or_else(|| row.error(format!("`{time}` = {t_text:?} is not a valid time")))?;
        let v: f64 = v_text
            .parse()
            .map_err(|_| row.error(format!("`{column}` = {v_text:?} is not a number")))?;
        if !v.is_finite() {
            return Err(row.error(format!("`{column}` = {v_text} is not finite")));
        }
        if times.last().is_some_and(|&last| t <= last) {
            return Err(row.error(format!("{time} = {t} does not increase")));
        }
        check(t, v).map_err(|why| row.error(why))?;
        times.push(t);
        values.push(v);
        lines.push(row.line());
        Ok(())
    })?;
    if values.len() < min_rows {
        return Err(ColumnError::TooShort {
            path: path.to_path_buf(),
            needed: min_rows,
            found: values.len(),
        });
    }
    Ok(Rows {
        times,
        values,
        lines,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_rows_name_their_line() {
        let dir = std::env::temp_dir().join(format!("margemu-csv-column-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("bad.csv");
        let check = |text: &str, expected: &str| {
            std::fs::write(&path, text).unwrap();
            let err = read::<f64>(&path, "t", "z", 1).unwrap_err().to_string();
            assert!(err.ends_with(expected), "{err}");
        };
        check("t,z\n0,1\n0.5,oops\n", ":3: `z` = \"oops\" is not a number");
        check("t,z\n0,1\n0,2\n", ":3: t = 0 does not increase");
        check("t,z\n0,1\nnan,2\n", ":3: `t` = \"nan\" is not a valid time");
        check("t,z\n0,inf\n", ":2: `z` = inf is not finite");
        check("t,q\n0,1\n", "no column `z` in the header (columns: t, q)");
        check("t,z\n", "needs at least 1 data rows, found 0");
        let (t, v) = read::<u64>(&path, "t", "z", 0).unwrap();
        assert!(t.is_empty() && v.is_empty());
    }
}
