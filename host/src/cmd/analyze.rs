//! `margemu analyze noise FILE --column C`: Allan deviation and PSD of one recorded column.

use anyhow::Result;
use margemu::analysis::{allan, plot, psd, white_density_from_psd, Series};
use std::path::PathBuf;

#[derive(clap::Subcommand)]
pub enum Cmd {
    /// Overlapping Allan deviation (τ from 1/rate to N/10) and Welch PSD of one column.
    Noise {
        /// A CSV with a time column, `t_ns` (truth.csv, marg.csv, …) or `t_s` (an external
        /// recording, an estimates file).
        file: PathBuf,
        /// The column to analyse.
        #[arg(long)]
        column: String,
        /// Welch segment length (samples).
        #[arg(long, default_value_t = 4096)]
        segment: usize,
        /// Also draw both curves to this file (.png or .svg).
        #[arg(long)]
        plot: Option<PathBuf>,
    },
}

impl Cmd {
    pub fn run(self) -> Result<()> {
        let Cmd::Noise {
            file,
            column,
            segment,
            plot: plot_path,
        } = self;
        let series = Series::from_csv(&file, &column)?;
        let n = series.values.len();
        let mean = series.values.iter().sum::<f64>() / n as f64;
        let var = series
            .values
            .iter()
            .map(|v| (v - mean) * (v - mean))
            .sum::<f64>()
            / (n - 1) as f64;
        println!(
            "{}: column `{column}`, {n} samples at {} Hz",
            file.display(),
            series.rate
        );
        println!("mean {mean:.6e}, standard deviation {:.6e}", var.sqrt());
        println!(
            "white-noise density from the standard deviation (σ/√fs): {:.6e} /√Hz",
            var.sqrt() / series.rate.sqrt()
        );
        let points = allan::overlapping(&series.values, series.rate);
        println!("\n{:>12} {:>14} {:>10}", "tau (s)", "adev", "terms");
        for p in &points {
            println!("{:>12.6} {:>14.6e} {:>10}", p.tau, p.adev, p.terms);
        }
        if let Some(one) = allan::at(&points, 1.0) {
            println!("Allan deviation at τ = 1 s: {one:.6e} (the white-noise density)");
        }
        let spectrum = psd::welch(&series.values, series.rate, segment);
        let nyquist = series.rate / 2.0;
        println!(
            "\nWelch PSD: {} segments of {segment} samples, {:.4} Hz resolution",
            spectrum.segments,
            series.rate / segment as f64
        );
        let edges = [0.0, 0.01, 0.1, 0.25, 0.5, 0.75, 1.0];
        println!(
            "{:>22} {:>14} {:>16}",
            "band (Hz)", "mean PSD", "density (/√Hz)"
        );
        for w in edges.windows(2) {
            let (lo, hi) = (w[0] * nyquist, w[1] * nyquist);
            if let Some(level) = spectrum.mean_in(lo.max(series.rate / segment as f64), hi) {
                println!(
                    "{:>10.3} – {:<9.3} {level:>14.6e} {:>16.6e}",
                    lo,
                    hi,
                    white_density_from_psd(level)
                );
            }
        }
        if let Some(path) = plot_path {
            plot::noise(&path, &column, &points, &spectrum)?;
            println!("\nwrote {}", path.display());
        }
        Ok(())
    }
}
