//! Spectral and stability analysis of one recorded column: how a user checks a scene's noise.
//!
//! - [`allan`]: overlapping Allan deviation at log-spaced τ from one sample period to N/10;
//! - [`psd`]: one-sided power spectral density by Welch's method (Hann window, 50 % overlap),
//!   with `rustfft`;
//! - [`plot`]: both drawn to PNG or SVG with `plotters`.
//!
//! Noise density convention (shared with the `model` crate): white noise of density `N`
//! (unit/√Hz) is sampled at `fs` with standard deviation `σ = N·√fs`, so its one-sided PSD is
//! `2N²` and its Allan deviation at τ = 1 s is `N`. [`white_density_from_psd`] inverts that.

pub mod allan;
pub mod plot;
pub mod psd;

use std::path::{Path, PathBuf};

/// A column of a CSV file, with its sample rate estimated from `t_ns`.
#[derive(Clone, Debug)]
pub struct Series {
    /// Column name.
    pub name: String,
    /// Values.
    pub values: Vec<f64>,
    /// Sample rate (Hz), from the median `t_ns` step.
    pub rate: f64,
}

/// A column that could not be read.
#[derive(Debug, thiserror::Error, docsplay::Display)]
pub enum SeriesError {
    /// {path}: cannot read: {source}
    Read {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: csv::Error,
    },
    /// {path}: no column `{column}` (columns: {found})
    MissingColumn {
        /// The file.
        path: PathBuf,
        /// The column asked for.
        column: String,
        /// The columns present.
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
    /// {path}: needs at least {needed} rows, found {found}
    TooShort {
        /// The file.
        path: PathBuf,
        /// Rows needed.
        needed: usize,
        /// Rows found.
        found: usize,
    },
}

impl Series {
    /// Reads column `column` of a CSV with a `t_ns` column (as written by `margemu simulate`).
    pub fn from_csv(path: &Path, column: &str) -> Result<Self, SeriesError> {
        let read = |source| SeriesError::Read {
            path: path.to_path_buf(),
            source,
        };
        let mut reader = csv::Reader::from_path(path).map_err(read)?;
        let header = reader.headers().map_err(read)?.clone();
        let find = |name: &str| {
            header
                .iter()
                .position(|h| h == name)
                .ok_or_else(|| SeriesError::MissingColumn {
                    path: path.to_path_buf(),
                    column: name.to_owned(),
                    found: header.iter().collect::<Vec<_>>().join(", "),
                })
        };
        let (ti, vi) = (find("t_ns")?, find(column)?);
        let (mut t, mut values) = (Vec::<u64>::new(), Vec::new());
        for record in reader.records() {
            let record = record.map_err(read)?;
            let line = record.position().map_or(0, |p| p.line());
            let bad = |reason: String| SeriesError::BadRow {
                path: path.to_path_buf(),
                line,
                reason,
            };
            let t_text = record.get(ti).unwrap_or("");
            let tv: u64 = t_text
                .parse()
                .map_err(|_| bad(format!("`t_ns` = {t_text:?} is not an integer")))?;
            let text = record.get(vi).unwrap_or("");
            let v: f64 = text
                .parse()
                .map_err(|_| bad(format!("`{column}` = {text:?} is not a number")))?;
            if !v.is_finite() {
                return Err(bad(format!("`{column}` = {text} is not finite")));
            }
            if t.last().is_some_and(|&last| tv <= last) {
                return Err(bad(format!("t_ns = {tv} does not increase")));
            }
            t.push(tv);
            values.push(v);
        }
        if values.len() < 16 {
            return Err(SeriesError::TooShort {
                path: path.to_path_buf(),
                needed: 16,
                found: values.len(),
            });
        }
        let mut steps: Vec<u64> = t.windows(2).map(|w| w[1] - w[0]).collect();
        steps.sort_unstable();
        let rate = 1e9 / steps[steps.len() / 2] as f64;
        Ok(Self {
            name: column.to_owned(),
            values,
            rate,
        })
    }
}

/// The white-noise density `N` whose one-sided PSD is `psd_level` (`PSD = 2N²`).
pub fn white_density_from_psd(psd_level: f64) -> f64 {
    (psd_level / 2.0).sqrt()
}
