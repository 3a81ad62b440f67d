//! Random vibration: a stationary Gaussian process with a PSD given by breakpoints.
//!
//! Synthesis by windowed overlap-add: blocks of `n` samples ([`RandomSource::fft_len`], a
//! 5-smooth length giving a resolution of at most a sixteenth of the lowest breakpoint) are
//! made by an inverse FFT of `H_k·(g₁ + i g₂)/√2` per bin (`g` standard normal, drawn only for
//! bins with `H_k ≠ 0`, bins `k` and `n − k` drawn independently) with
//! `|H_k|² = S(f_k)·rate/n`, so the real part is one axis and the imaginary part another, each
//! with the one-sided PSD `S`. Blocks overlap by half and are weighted by `sin(π(j + ½)/n)`,
//! whose squares add to 1: the variance is stationary and the PSD is `S` smoothed over about
//! two bins. A block pair serves x and y, another z. Before the first sample, two blocks are
//! made, so the process is stationary from `t = 0`. The PSD is zero below the first breakpoint,
//! above the last and above the internal Nyquist frequency.

use crate::error::Error;
use crate::perturbation::fft::{next_smooth, FftPlan};
use crate::perturbation::Complex;
use crate::rng::{self, StreamRng};
use crate::vec3::{mat_vec, Mat3, Mat3d, Vec3};

/// Most breakpoints of a PSD.
pub const MAX_PSD_POINTS: usize = 16;
/// Longest synthesis block.
pub const MAX_FFT_LEN: usize = 1 << 16;
/// Standard gravity, m/s² per g (the PSD's unit is g²/Hz).
const G0: f64 = 9.806_65;

/// A PSD breakpoint.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PsdPoint {
    /// Frequency, Hz (> 0, increasing).
    pub f_hz: f64,
    /// One-sided acceleration PSD, g²/Hz (> 0).
    pub g2_per_hz: f64,
}

/// A random vibration source: a PSD, per-axis gains and the axes it is given in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RandomSource {
    points: [PsdPoint; MAX_PSD_POINTS],
    count: usize,
    /// Amplitude factor per axis (1 = the PSD on that axis; 0 = none).
    pub gains: [f64; 3],
    /// Rotation from the source's axes into the sensor's (`None`: the same axes).
    pub axes: Option<Mat3d>,
}

impl RandomSource {
    /// The PSD through `points` (2..=[`MAX_PSD_POINTS`], frequencies increasing, values > 0), on
    /// every axis.
    pub fn new(points: &[PsdPoint]) -> Result<Self, Error> {
        if points.len() < 2 || points.len() > MAX_PSD_POINTS {
            return Err(Error::InvalidPsd);
        }
        let mut stored = [PsdPoint::default(); MAX_PSD_POINTS];
        for (dst, p) in stored.iter_mut().zip(points) {
            crate::error::positive(p.f_hz, "vibration.random.psd frequency")?;
            crate::error::positive(p.g2_per_hz, "vibration.random.psd value")?;
            *dst = *p;
        }
        if points.windows(2).any(|w| w[1].f_hz <= w[0].f_hz) {
            return Err(Error::InvalidPsd);
        }
        Ok(Self {
            points: stored,
            count: points.len(),
            gains: [1.0; 3],
            axes: None,
        })
    }

    /// The breakpoints.
    pub fn points(&self) -> &[PsdPoint] {
        self.points.get(..self.count).unwrap_or(&[])
    }

    /// The PSD at `f_hz`, g²/Hz: log-log interpolation, 0 outside the breakpoints.
    pub fn psd_at(&self, f_hz: f64) -> f64 {
        for w in self.points().windows(2) {
            let (a, b) = (w[0], w[1]);
            if f_hz >= a.f_hz && f_hz <= b.f_hz {
                let slope = libm::log(b.g2_per_hz / a.g2_per_hz) / libm::log(b.f_hz / a.f_hz);
                return a.g2_per_hz * libm::pow(f_hz / a.f_hz, slope);
            }
        }
        0.0
    }

    /// The highest frequency with content, Hz.
    pub fn max_frequency_hz(&self) -> f64 {
        self.points().last().map_or(0.0, |p| p.f_hz)
    }

    /// The synthesis block length at `rate_hz`.
    pub fn fft_len(&self, rate_hz: f64) -> Result<usize, Error> {
        let lowest = self.points().first().map_or(1.0, |p| p.f_hz);
        let wanted = libm::ceil(16.0 * rate_hz / lowest).max(64.0);
        if wanted.is_nan() || wanted > MAX_FFT_LEN as f64 {
            return Err(Error::PsdTooFine);
        }
        let n = next_smooth(wanted as usize).ok_or(Error::PsdTooFine)?;
        let n = n + n % 2;
        if n > MAX_FFT_LEN {
            return Err(Error::PsdTooFine);
        }
        Ok(n)
    }

    /// The complex values of buffer the synthesis needs at `rate_hz`: FFT scratch, the filter
    /// and window, and four blocks.
    pub fn buffer_len(&self, rate_hz: f64) -> Result<usize, Error> {
        let n = self.fft_len(rate_hz)?;
        Ok(FftPlan::new(n)?.scratch_len() + 5 * n)
    }
}

/// The running synthesis.
pub(super) struct Random<B> {
    plan: FftPlan,
    n: usize,
    buffers: B,
    /// Which of the two block pairs is current (0 or 1).
    current: usize,
    /// Position in the current block, 0..n/2.
    pos: usize,
    rng: StreamRng,
    gains: [f32; 3],
    axes: Option<Mat3>,
}

impl<B: AsMut<[Complex]> + AsRef<[Complex]>> Random<B> {
    pub(super) fn new(
        source: &RandomSource,
        rate_hz: f64,
        seed: u64,
        mut buffers: B,
    ) -> Result<Self, Error> {
        let n = source.fft_len(rate_hz)?;
        let plan = FftPlan::new(n)?;
        let scratch_len = plan.scratch_len();
        let buf = buffers.as_mut();
        if buf.len() < scratch_len + 5 * n {
            return Err(Error::BufferTooSmall {
                needed: scratch_len + 5 * n,
                got: buf.len(),
            });
        }
        let (scratch, rest) = buf.split_at_mut(scratch_len);
        plan.init(scratch)?;
        let scale = G0 * G0 * rate_hz / n as f64;
        for (k, hw) in rest.iter_mut().take(n).enumerate() {
            let bin = if k <= n / 2 { k } else { n - k };
            let f = bin as f64 * rate_hz / n as f64;
            let window = libm::sin(core::f64::consts::PI * (k as f64 + 0.5) / n as f64);
            *hw = Complex::new(libm::sqrt(source.psd_at(f) * scale), window);
        }
        let gains = crate::sensor::vec_f32_checked(source.gains, "vibration.random.gains")?;
        let axes = match source.axes {
            Some(m) => Some([
                crate::sensor::vec_f32_checked(m[0], "vibration.random.axes")?,
                crate::sensor::vec_f32_checked(m[1], "vibration.random.axes")?,
                crate::sensor::vec_f32_checked(m[2], "vibration.random.axes")?,
            ]),
            None => None,
        };
        let mut random = Self {
            plan,
            n,
            buffers,
            current: 0,
            pos: 0,
            rng: rng::stream(seed, "vibration/random"),
            gains,
            axes,
        };
        // Pair 1 becomes the "previous" blocks of the first hop, pair 0 the current ones.
        random.fill(1)?;
        random.fill(0)?;
        Ok(random)
    }

    /// Makes block pair `pair` (x/y block and z block) anew.
    fn fill(&mut self, pair: usize) -> Result<(), Error> {
        let n = self.n;
        let scratch_len = self.plan.scratch_len();
        let buf = self.buffers.as_mut();
        let (scratch, rest) = buf.split_at_mut(scratch_len);
        let (hw, blocks) = rest.split_at_mut(n);
        for b in 0..2 {
            let start = (2 * pair + b) * n;
            let block = blocks
                .get_mut(start..start + n)
                .ok_or(Error::BufferTooSmall {
                    needed: start + n,
                    got: 0,
                })?;
            for (z, h) in block.iter_mut().zip(hw.iter()) {
                *z = if h.re == 0.0 {
                    Complex::ZERO
                } else {
                    let g1 = f64::from(rng::standard_normal(&mut self.rng));
                    let g2 = f64::from(rng::standard_normal(&mut self.rng));
                    let a = h.re * core::f64::consts::FRAC_1_SQRT_2;
                    Complex::new(a * g1, a * g2)
                };
            }
            self.plan.inverse(scratch, block)?;
        }
        Ok(())
    }

    /// The next sample, m/s², sensor axes.
    #[inline]
    pub(super) fn next(&mut self) -> Vec3 {
        let n = self.n;
        let half = n / 2;
        let offset = self.plan.scratch_len();
        let buf = self.buffers.as_ref();
        let at = |i: usize| buf.get(offset + i).copied().unwrap_or(Complex::ZERO);
        let (cur, prev) = (self.current, 1 - self.current);
        let j = self.pos;
        let (w_cur, w_prev) = (at(j).im, at(j + half).im);
        let block = |pair: usize, b: usize, i: usize| at(n + (2 * pair + b) * n + i);
        let xy = block(cur, 0, j);
        let xy_prev = block(prev, 0, j + half);
        let z = block(cur, 1, j);
        let z_prev = block(prev, 1, j + half);
        let v = [
            (w_cur * xy.re + w_prev * xy_prev.re) as f32 * self.gains[0],
            (w_cur * xy.im + w_prev * xy_prev.im) as f32 * self.gains[1],
            (w_cur * z.re + w_prev * z_prev.re) as f32 * self.gains[2],
        ];
        self.pos += 1;
        if self.pos == half {
            self.pos = 0;
            self.current = prev;
            // The old previous pair becomes the new current one; a failure cannot happen with
            // the buffers checked at construction, and would repeat the old blocks.
            let _ = self.fill(prev);
        }
        match &self.axes {
            Some(m) => mat_vec(m, v),
            None => v,
        }
    }
}
