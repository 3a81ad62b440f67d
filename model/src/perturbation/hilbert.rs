//! The analytic signal (eq. 20, Marple's FFT method), the perturbation shape `m_p` (eq. 21) and
//! the least-squares linear detrend (eq. 22), in `f64` on one complex buffer.
//!
//! [`analytic`] turns the real signal held in `data[k].re` into its analytic signal
//! `m_a = m + i·H{m}` exactly as MATLAB's `hilbert`: FFT, weights `h₀ = 1`, `h_l = 2` for
//! `0 < l < n/2`, `h_{n/2} = 1` when `n` is even, `h_l = 0` above, inverse FFT, divide by `n`.
//! [`fold_reversed_envelope`] forms `m_p[k] = imag(m_a[k]) + |m_a[n−1−k]|` into `data[k].re`, and
//! [`detrend`] subtracts the least-squares line from it.
//!
//! ```
//! use margemu_model::perturbation::fft::{Complex, FftPlan};
//! use margemu_model::perturbation::hilbert::analytic;
//! // The analytic signal of cos is e^{iωt}: its imaginary part is sin.
//! let n = 64;
//! let plan = FftPlan::new(n)?;
//! let mut scratch = [Complex::ZERO; 128];
//! plan.init(&mut scratch)?;
//! let w = 2.0 * core::f64::consts::PI * 4.0 / n as f64;
//! let mut data: [Complex; 64] = core::array::from_fn(|k| Complex::new(libm::cos(w * k as f64), 0.0));
//! analytic(&mut data, &plan, &mut scratch)?;
//! assert!((data[5].im - libm::sin(w * 5.0)).abs() < 1e-12);
//! # Ok::<(), margemu_model::Error>(())
//! ```

use super::fft::{Complex, FftPlan};
use crate::error::Error;

/// The analytic signal of the real part of `data`, in place (the imaginary input is ignored),
/// with an FFT plan of `data.len()` and the scratch its [`FftPlan::init`] filled.
pub fn analytic(data: &mut [Complex], fft: &FftPlan, scratch: &mut [Complex]) -> Result<(), Error> {
    let n = data.len();
    for z in data.iter_mut() {
        z.im = 0.0;
    }
    fft.forward(scratch, data)?;
    let half = n / 2;
    let inv_n = 1.0 / n as f64;
    for (l, z) in data.iter_mut().enumerate() {
        let h = if l == 0 || (n.is_multiple_of(2) && l == half) {
            1.0
        } else if l < n.div_ceil(2) {
            2.0
        } else {
            0.0
        };
        // The 1/n of the inverse transform is folded in here.
        let s = h * inv_n;
        *z = Complex::new(z.re * s, z.im * s);
    }
    fft.inverse(scratch, data)
}

/// `m_p[k] = imag(m_a[k]) + |m_a[n−1−k]|` (eq. 21), written to `data[k].re`; `data[k].im` is
/// set to 0.
pub fn fold_reversed_envelope(data: &mut [Complex]) {
    let n = data.len();
    for k in 0..n / 2 {
        let j = n - 1 - k;
        let (a, b) = (data[k], data[j]);
        data[k] = Complex::new(a.im + b.norm(), 0.0);
        data[j] = Complex::new(b.im + a.norm(), 0.0);
    }
    if n % 2 == 1 {
        let a = data[n / 2];
        data[n / 2] = Complex::new(a.im + a.norm(), 0.0);
    }
}

/// Subtracts from `data[k].re` its least-squares line `α + β·k` (eq. 22).
pub fn detrend(data: &mut [Complex]) {
    let n = data.len();
    if n < 2 {
        for z in data.iter_mut() {
            z.re = 0.0;
        }
        return;
    }
    let nf = n as f64;
    let mean_k = (nf - 1.0) * 0.5;
    // Σ (k − k̄)² = n(n² − 1)/12.
    let skk = nf * (nf * nf - 1.0) / 12.0;
    let (mut sum, mut sky) = (0.0, 0.0);
    for (k, z) in data.iter().enumerate() {
        sum += z.re;
        sky += (k as f64 - mean_k) * z.re;
    }
    let mean = sum / nf;
    let slope = sky / skk;
    for (k, z) in data.iter_mut().enumerate() {
        z.re -= mean + slope * (k as f64 - mean_k);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn detrend_removes_a_line_exactly() {
        let mut d: [Complex; 9] = core::array::from_fn(|k| Complex::new(3.0 - 0.5 * k as f64, 0.0));
        detrend(&mut d);
        assert!(d.iter().all(|z| z.re.abs() < 1e-14));
        // A parabola keeps its curvature, loses its mean and slope.
        let mut p: [Complex; 5] = core::array::from_fn(|k| Complex::new((k * k) as f64, 0.0));
        detrend(&mut p);
        let expect = [2.0, -1.0, -2.0, -1.0, 2.0];
        for (z, e) in p.iter().zip(expect) {
            assert!((z.re - e).abs() < 1e-12, "{z:?}");
        }
    }

    #[test]
    fn envelope_is_reversed() {
        let mut d = [
            Complex::new(3.0, 4.0),
            Complex::new(0.0, 1.0),
            Complex::new(1.0, 0.0),
        ];
        fold_reversed_envelope(&mut d);
        assert_eq!(d.map(|z| z.re), [4.0 + 1.0, 1.0 + 1.0, 0.0 + 5.0]);
    }

    #[test]
    fn matches_matlab_documentation_example() {
        // MATLAB: hilbert([1 2 3 4]) = [1+1i, 2-1i, 3-1i, 4+1i].
        let mut scratch = [Complex::ZERO; 8];
        let fft = FftPlan::new(4).unwrap();
        fft.init(&mut scratch).unwrap();
        let mut d: [Complex; 4] = core::array::from_fn(|k| Complex::new(k as f64 + 1.0, 0.0));
        analytic(&mut d, &fft, &mut scratch).unwrap();
        for (z, im) in d.iter().zip([1.0, -1.0, -1.0, 1.0]) {
            assert!((z.im - im).abs() < 1e-14, "{z:?}");
        }
    }

    #[test]
    fn odd_lengths_follow_matlab_weights() {
        // The real part is kept and the spectrum is one-sided.
        let n = 7;
        let mut scratch = [Complex::ZERO; 128];
        let fft = FftPlan::new(n).unwrap();
        fft.init(&mut scratch).unwrap();
        let x = [1.0, 2.0, 0.5, -1.0, 3.0, 0.0, 2.0];
        let mut d: [Complex; 7] = core::array::from_fn(|k| Complex::new(x[k], 0.0));
        analytic(&mut d, &fft, &mut scratch).unwrap();
        for k in 0..n {
            assert!((d[k].re - x[k]).abs() < 1e-12);
        }
        fft.forward(&mut scratch, &mut d).unwrap();
        for z in &d[4..] {
            assert!(z.norm() < 1e-12, "negative frequencies must vanish: {z:?}");
        }
    }
}
