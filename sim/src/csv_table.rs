//! Reading several columns of a CSV file row by row, with every failure located: the file, and
//! for a bad value the line and the column (errors are [`ColumnError`]s, as for single columns).

use crate::csv_column::ColumnError;
use crate::input_file::{open_stream, LineBounded};
use std::fs::File;
use std::path::{Path, PathBuf};

/// An open CSV file and its header.
pub struct Table {
    path: PathBuf,
    reader: csv::Reader<LineBounded<File>>,
    header: csv::StringRecord,
    record: csv::StringRecord,
}

impl Table {
    /// Opens `path` and reads its header row.
    pub fn open(path: &Path) -> Result<Self, ColumnError> {
        let read_err = |cause| ColumnError::Read {
            path: path.to_path_buf(),
            cause,
        };
        let file = open_stream(path).map_err(ColumnError::Input)?;
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_reader(file);
        let header = reader.headers().map_err(read_err)?.clone();
        Ok(Self {
            path: path.to_path_buf(),
            reader,
            header,
            record: csv::StringRecord::new(),
        })
    }

    /// The index of column `name`, or `None`.
    pub fn optional(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|h| h == name)
    }

    /// The index of the first column whose name starts with `prefix`, or `None`.
    pub fn first_with_prefix(&self, prefix: &str) -> Option<usize> {
        self.header.iter().position(|h| h.starts_with(prefix))
    }

    /// The index of column `name`, or an error listing the columns there are.
    pub fn column(&self, name: &str) -> Result<usize, ColumnError> {
        self.optional(name)
            .ok_or_else(|| ColumnError::MissingColumn {
                path: self.path.clone(),
                column: name.to_owned(),
                found: self.header.iter().collect::<Vec<_>>().join(", "),
            })
    }

    /// The indices of `names`, all required.
    pub fn columns<const N: usize>(&self, names: [&str; N]) -> Result<[usize; N], ColumnError> {
        let mut out = [0; N];
        for (o, name) in out.iter_mut().zip(names) {
            *o = self.column(name)?;
        }
        Ok(out)
    }

    /// The next data row, or `None` at the end of the file: a cursor for readers that stream
    /// (one row in memory at a time).
    pub fn next_row(&mut self) -> Result<Option<Row<'_>>, ColumnError> {
        let more =
            self.reader
                .read_record(&mut self.record)
                .map_err(|cause| ColumnError::Read {
                    path: self.path.clone(),
                    cause,
                })?;
        if !more {
            return Ok(None);
        }
        let line = self.record.position().map_or(0, |p| p.line());
        Ok(Some(Row {
            path: &self.path,
            header: &self.header,
            record: &self.record,
            line,
        }))
    }

    /// Calls `f` on every data row, in order; stops at the first error. Returns the row count.
    pub fn for_each(
        mut self,
        mut f: impl FnMut(&Row<'_>) -> Result<(), ColumnError>,
    ) -> Result<usize, ColumnError> {
        let mut rows = 0;
        while let Some(row) = self.next_row()? {
            f(&row)?;
            rows += 1;
        }
        Ok(rows)
    }
}

/// One data row.
pub struct Row<'a> {
    path: &'a Path,
    header: &'a csv::StringRecord,
    record: &'a csv::StringRecord,
    line: u64,
}

impl Row<'_> {
    /// An error at this row's line.
    pub fn error(&self, reason: String) -> ColumnError {
        ColumnError::BadRow {
            path: self.path.to_path_buf(),
            line: self.line,
            reason,
        }
    }

    /// The line of the row in the file (1-based).
    pub fn line(&self) -> u64 {
        self.line
    }

    /// The raw text of column `i` (empty when the row is short).
    pub fn text(&self, i: usize) -> &str {
        self.record.get(i).unwrap_or("")
    }

    /// The name of column `i`.
    pub fn name(&self, i: usize) -> &str {
        self.header.get(i).unwrap_or("?")
    }

    /// Column `i` as a finite number.
    pub fn f64(&self, i: usize) -> Result<f64, ColumnError> {
        self.opt_f64(i)?
            .ok_or_else(|| self.error(format!("`{}` is empty", self.name(i))))
    }

    /// Column `i` as a number, `NaN` and infinities included (for values a reader checks itself).
    pub fn any_f64(&self, i: usize) -> Result<f64, ColumnError> {
        let text = self.text(i);
        text.parse::<f64>()
            .map_err(|_| self.error(format!("`{}` = {text:?} is not a number", self.name(i))))
    }

    /// Column `i` as a finite number, or `None` when empty.
    pub fn opt_f64(&self, i: usize) -> Result<Option<f64>, ColumnError> {
        let text = self.text(i);
        if text.is_empty() {
            return Ok(None);
        }
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(Some(v)),
            Ok(_) => Err(self.error(format!("`{}` = {text} is not finite", self.name(i)))),
            Err(_) => Err(self.error(format!("`{}` = {text:?} is not a number", self.name(i)))),
        }
    }

    /// Column `i` as an integer.
    pub fn int<T: std::str::FromStr>(&self, i: usize) -> Result<T, ColumnError> {
        let text = self.text(i);
        text.parse()
            .map_err(|_| self.error(format!("`{}` = {text:?} is not an integer", self.name(i))))
    }

    /// Columns `i` as numbers.
    pub fn f64s<const N: usize>(&self, i: [usize; N]) -> Result<[f64; N], ColumnError> {
        let mut out = [0.0; N];
        for (o, i) in out.iter_mut().zip(i) {
            *o = self.f64(i)?;
        }
        Ok(out)
    }

    /// An error unless `t` is after `previous` (`strictly`) or not before it.
    pub fn check_order<T: PartialOrd + std::fmt::Display>(
        &self,
        column: usize,
        previous: Option<T>,
        t: T,
        strictly: bool,
    ) -> Result<(), ColumnError> {
        match previous {
            Some(p) if t < p || (strictly && t == p) => Err(self.error(format!(
                "`{}` = {t} does not increase (previous row: {p})",
                self.name(column)
            ))),
            _ => Ok(()),
        }
    }
}
