//! One-sided power spectral density by Welch's method: Hann-windowed segments with 50 %
//! overlap, each transformed with `rustfft`, averaged, and scaled to unit²/Hz so that the
//! integral over `[0, fs/2]` is the signal's variance.

use rustfft::{num_complex::Complex, FftPlanner};

/// A PSD estimate.
#[derive(Clone, Debug)]
pub struct Psd {
    /// Bin frequencies (Hz), from 0 to fs/2.
    pub frequency: Vec<f64>,
    /// One-sided density (unit²/Hz).
    pub density: Vec<f64>,
    /// Segments averaged.
    pub segments: usize,
}

/// Welch PSD of `y` sampled at `rate` Hz with segments of `len` samples (a power of two is
/// fastest; clamped to the signal length). The mean of each segment is removed.
pub fn welch(y: &[f64], rate: f64, len: usize) -> Psd {
    let len = len.clamp(8, y.len().max(8));
    let window: Vec<f64> = (0..len)
        .map(|i| 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / len as f64).cos())
        .collect();
    let power: f64 = window.iter().map(|w| w * w).sum();
    let fft = FftPlanner::new().plan_fft_forward(len);
    let bins = len / 2 + 1;
    let mut acc = vec![0.0; bins];
    let mut buf = vec![Complex::new(0.0, 0.0); len];
    let mut segments = 0;
    let mut start = 0;
    while start + len <= y.len() {
        let seg = &y[start..start + len];
        let mean = seg.iter().sum::<f64>() / len as f64;
        for (b, (&v, &w)) in buf.iter_mut().zip(seg.iter().zip(&window)) {
            *b = Complex::new((v - mean) * w, 0.0);
        }
        fft.process(&mut buf);
        for (a, b) in acc.iter_mut().zip(&buf) {
            *a += b.norm_sqr();
        }
        segments += 1;
        start += len / 2;
    }
    let scale = 1.0 / (rate * power * segments.max(1) as f64);
    let density = acc
        .iter()
        .enumerate()
        .map(|(i, a)| {
            let one_sided = if i == 0 || (len.is_multiple_of(2) && i == bins - 1) {
                1.0
            } else {
                2.0
            };
            a * scale * one_sided
        })
        .collect();
    let frequency = (0..bins).map(|i| i as f64 * rate / len as f64).collect();
    Psd {
        frequency,
        density,
        segments,
    }
}

impl Psd {
    /// Densities of the bins in `[lo, hi]` Hz.
    fn band(&self, lo: f64, hi: f64) -> Vec<f64> {
        let bins = self.frequency.iter().zip(&self.density);
        bins.filter(|(f, _)| (lo..=hi).contains(*f))
            .map(|(_, d)| *d)
            .collect()
    }

    /// Mean density over `[lo, hi]` Hz.
    pub fn mean_in(&self, lo: f64, hi: f64) -> Option<f64> {
        let band = self.band(lo, hi);
        (!band.is_empty()).then(|| band.iter().sum::<f64>() / band.len() as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sine_puts_its_variance_in_one_bin() {
        let rate = 1000.0;
        let y: Vec<f64> = (0..1 << 16)
            .map(|k| 2.0 * (2.0 * std::f64::consts::PI * 125.0 * k as f64 / rate).sin())
            .collect();
        let psd = welch(&y, rate, 1024);
        let df = rate / 1024.0;
        let variance: f64 = psd.density.iter().sum::<f64>() * df;
        assert!((variance - 2.0).abs() < 0.01, "variance {variance}");
        let peak = psd.density.iter().cloned().fold(0.0, f64::max);
        let at_peak = psd.frequency[psd.density.iter().position(|&d| d == peak).unwrap()];
        assert_eq!(at_peak, 125.0);
    }
}
