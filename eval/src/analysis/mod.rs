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
pub use margemu_sim::csv_column::ColumnError as SeriesError;

impl Series {
    /// Reads column `column` of a CSV with a time column: `t_ns` (integer nanoseconds, as
    /// `margemu simulate` writes) or else `t_s` (seconds, as external recordings and estimates
    /// files have it), strictly increasing.
    pub fn from_csv(path: &Path, column: &str) -> Result<Self, SeriesError> {
        let has_ns = margemu_sim::csv_table::Table::open(path)?
            .optional("t_ns")
            .is_some();
        let (t_ns, values): (Vec<u64>, Vec<f64>) = if has_ns {
            margemu_sim::csv_column::read::<u64>(path, "t_ns", column, 16)?
        } else {
            let (t, values) = margemu_sim::csv_column::read::<f64>(path, "t_s", column, 16)?;
            (t.iter().map(|s| (s * 1e9).round() as u64).collect(), values)
        };
        let mut steps: Vec<u64> = t_ns.windows(2).map(|w| w[1] - w[0]).collect();
        steps.sort_unstable();
        let rate = 1e9 / steps[steps.len() / 2].max(1) as f64;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_time_column_is_t_ns_or_t_s() {
        let dir = std::env::temp_dir().join(format!("margemu-series-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (ns, s) = (dir.join("ns.csv"), dir.join("s.csv"));
        let rows = |scale: f64| -> String {
            (0..20)
                .map(|k| format!("{},{}\n", f64::from(k) * 0.005 * scale, k % 3))
                .collect()
        };
        std::fs::write(&ns, format!("t_ns,gx\n{}", rows(1e9))).unwrap();
        std::fs::write(&s, format!("t_s,gx\n{}", rows(1.0))).unwrap();
        for path in [&ns, &s] {
            let series = Series::from_csv(path, "gx").unwrap();
            assert_eq!(series.values.len(), 20);
            assert!((series.rate - 200.0).abs() < 1e-6, "{}", series.rate);
        }
        std::fs::write(&s, "time,gx\n0,1\n").unwrap();
        let e = Series::from_csv(&s, "gx").unwrap_err().to_string();
        assert!(e.contains("no column `t_s`"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
