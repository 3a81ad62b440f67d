//! Setpoints from a CSV file: a header row, a time column `t` in seconds (strictly increasing)
//! and a named value column. Between rows the value is interpolated linearly (bench setpoints)
//! or by a natural cubic spline (kinematic mode, which needs continuous acceleration). Before
//! the first row the first value holds, after the last row the last value holds.
//!
//! The file must be a regular file within [`crate::input_file::MAX_INPUT_BYTES`]; times must
//! lie in [`SOURCE_TIME`] and values in [`JOINT_VALUE`] (plausible ranges, refused at their
//! line).

use super::Derivatives;
use crate::scene::ranges::{JOINT_VALUE, SOURCE_TIME};
use std::path::Path;

/// A CSV reference file that could not be used.
pub use crate::csv_column::ColumnError as TableError;

/// A time series `(t, y)` with optional spline second derivatives.
#[derive(Clone, Debug)]
pub struct Table {
    t: Vec<f64>,
    y: Vec<f64>,
    /// Spline second derivatives at the knots (empty for linear use).
    m: Vec<f64>,
    /// The file and each row's line, for tables read from a file.
    origin: Option<(std::path::PathBuf, Vec<u64>)>,
}

impl Table {
    /// Loads column `column` against column `t` from `path`.
    pub fn load(path: &Path, column: &str) -> Result<Self, TableError> {
        crate::input_file::check(path).map_err(TableError::Input)?;
        let rows = crate::csv_column::read_checked::<f64>(path, "t", column, 1, |t, v| {
            if !SOURCE_TIME.contains(t) {
                return Err(format!("`t` = {}", SOURCE_TIME.refusal(t)));
            }
            if !JOINT_VALUE.contains(v) {
                return Err(format!("`{column}` = {}", JOINT_VALUE.refusal(v)));
            }
            Ok(())
        })?;
        Ok(Self {
            t: rows.times,
            y: rows.values,
            m: Vec::new(),
            origin: Some((path.to_path_buf(), rows.lines)),
        })
    }

    /// `file:line` of the rows in force at time `x` (s): the row before and the row after, or
    /// the first or last row outside the table; `None` for a table not read from a file.
    pub fn rows_at(&self, x: f64) -> Option<String> {
        let (path, lines) = self.origin.as_ref()?;
        let rows = match self.interval(x) {
            Some(i) => format!("lines {}–{}", lines[i], lines[i + 1]),
            None if x < self.t[0] => format!("line {}", lines[0]),
            None => format!("line {}", lines[lines.len() - 1]),
        };
        Some(format!("{} {rows}", path.display()))
    }

    /// A table from samples (times strictly increasing, at least one).
    pub fn from_samples(t: Vec<f64>, y: Vec<f64>) -> Self {
        Self {
            t,
            y,
            m: Vec::new(),
            origin: None,
        }
    }

    /// Index `i` with `t[i] ≤ x < t[i+1]`, or `None` outside the table.
    fn interval(&self, x: f64) -> Option<usize> {
        if x < self.t[0] || x >= self.t[self.t.len() - 1] {
            return None;
        }
        Some(self.t.partition_point(|&ti| ti <= x) - 1)
    }

    fn clamp_value(&self, x: f64) -> f64 {
        if x < self.t[0] {
            self.y[0]
        } else {
            self.y[self.y.len() - 1]
        }
    }

    /// Linear interpolation.
    pub fn linear(&self, x: f64) -> f64 {
        match self.interval(x) {
            None => self.clamp_value(x),
            Some(i) => {
                let w = (x - self.t[i]) / (self.t[i + 1] - self.t[i]);
                self.y[i] + w * (self.y[i + 1] - self.y[i])
            }
        }
    }

    /// Slope of the linear interpolation (0 outside the table).
    pub fn slope(&self, x: f64) -> f64 {
        self.interval(x).map_or(0.0, |i| {
            (self.y[i + 1] - self.y[i]) / (self.t[i + 1] - self.t[i])
        })
    }

    /// Computes the natural cubic spline through the rows.
    pub fn into_spline(mut self) -> Self {
        let n = self.t.len();
        let mut m = vec![0.0; n];
        if n > 2 {
            // Tridiagonal system for the interior second derivatives (Thomas algorithm).
            let (mut c, mut d) = (vec![0.0; n], vec![0.0; n]);
            for i in 1..n - 1 {
                let (h0, h1) = (self.t[i] - self.t[i - 1], self.t[i + 1] - self.t[i]);
                let rhs =
                    6.0 * ((self.y[i + 1] - self.y[i]) / h1 - (self.y[i] - self.y[i - 1]) / h0);
                let diag = 2.0 * (h0 + h1) - h0 * c[i - 1];
                c[i] = h1 / diag;
                d[i] = (rhs - h0 * d[i - 1]) / diag;
            }
            for i in (1..n - 1).rev() {
                m[i] = d[i] - c[i] * m[i + 1];
            }
        }
        self.m = m;
        self
    }

    /// Spline value, slope and curvature (constant value outside the table).
    pub fn spline(&self, x: f64) -> Derivatives {
        let Some(i) = self.interval(x) else {
            return [self.clamp_value(x), 0.0, 0.0];
        };
        let h = self.t[i + 1] - self.t[i];
        let (a, b) = ((self.t[i + 1] - x) / h, (x - self.t[i]) / h);
        let (m0, m1, y0, y1) = (self.m[i], self.m[i + 1], self.y[i], self.y[i + 1]);
        let value = a * y0 + b * y1 + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0;
        let slope = (y1 - y0) / h + ((1.0 - 3.0 * a * a) * m0 + (3.0 * b * b - 1.0) * m1) * h / 6.0;
        [value, slope, a * m0 + b * m1]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn linear_interpolation_and_clamping() {
        let t = Table::from_samples(vec![0.0, 1.0, 3.0], vec![0.0, 2.0, 0.0]);
        assert_eq!(t.linear(-1.0), 0.0);
        assert_eq!(t.linear(0.5), 1.0);
        assert_eq!(t.linear(2.0), 1.0);
        assert_eq!(t.linear(9.0), 0.0);
        assert_eq!(t.slope(2.0), -1.0);
    }

    #[test]
    fn a_spline_reproduces_a_smooth_signal() {
        let ts: Vec<f64> = (0..=200).map(|k| k as f64 * 0.01).collect();
        let ys = ts.iter().map(|t| (3.0 * t).sin()).collect();
        let s = Table::from_samples(ts, ys).into_spline();
        let [v, d, dd] = s.spline(1.005);
        assert_relative_eq!(v, (3.015f64).sin(), epsilon = 1e-8);
        assert_relative_eq!(d, 3.0 * (3.015f64).cos(), epsilon = 1e-5);
        assert_relative_eq!(dd, -9.0 * (3.015f64).sin(), epsilon = 1e-3);
    }
}
