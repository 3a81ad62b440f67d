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

use std::path::Path;

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
pub use crate::csv_column::ColumnError as SeriesError;

impl Series {
    /// Reads column `column` of a CSV with a `t_ns` column (as written by `margemu simulate`).
    pub fn from_csv(path: &Path, column: &str) -> Result<Self, SeriesError> {
        let (t, values) = crate::csv_column::read::<u64>(path, "t_ns", column, 16)?;
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
