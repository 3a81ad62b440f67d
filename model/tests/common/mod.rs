//! Shared helpers of the integration tests: Allan deviation and power spectra.
#![allow(dead_code)]

use rustfft::num_complex::Complex64;
use rustfft::FftPlanner;

/// Overlapping Allan deviation of `x` (samples at `rate_hz`) at cluster time `tau_s`.
pub fn allan_deviation(x: &[f64], rate_hz: f64, tau_s: f64) -> f64 {
    let m = (tau_s * rate_hz).round() as usize;
    assert!(m >= 1 && 2 * m < x.len(), "tau {tau_s} s out of range");
    let mut theta = Vec::with_capacity(x.len() + 1);
    let mut acc = 0.0;
    theta.push(0.0);
    for &v in x {
        acc += v / rate_hz;
        theta.push(acc);
    }
    let tau = m as f64 / rate_hz;
    let count = theta.len() - 2 * m;
    let sum: f64 = (0..count)
        .map(|k| {
            let d = theta[k + 2 * m] - 2.0 * theta[k + m] + theta[k];
            d * d
        })
        .sum();
    (sum / (2.0 * tau * tau * count as f64)).sqrt()
}

/// Standard deviation.
pub fn std_dev(x: &[f64]) -> f64 {
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    (x.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0)).sqrt()
}

/// One-sided power spectrum |X(f)|² of `x` (optionally Hann-tapered), bins 0..=n/2, and the bin
/// width in Hz.
pub fn power_spectrum(x: &[f64], rate_hz: f64, hann: bool) -> (Vec<f64>, f64) {
    let n = x.len();
    let mut buf: Vec<Complex64> = x
        .iter()
        .enumerate()
        .map(|(k, &v)| {
            let w = if hann {
                0.5 - 0.5 * (2.0 * std::f64::consts::PI * k as f64 / n as f64).cos()
            } else {
                1.0
            };
            Complex64::new(v * w, 0.0)
        })
        .collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut buf);
    (
        buf[..=n / 2].iter().map(|z| z.norm_sqr()).collect(),
        rate_hz / n as f64,
    )
}

/// Mean of `p` over the bins whose frequency lies in `[lo, hi]` Hz.
pub fn band_mean(p: &[f64], df: f64, lo: f64, hi: f64) -> f64 {
    let bins: Vec<f64> = p
        .iter()
        .enumerate()
        .filter(|(i, _)| (*i as f64 * df) >= lo && (*i as f64 * df) <= hi)
        .map(|(_, &v)| v)
        .collect();
    bins.iter().sum::<f64>() / bins.len() as f64
}
