//! A no_std, no-alloc complex FFT of any length, in `f64`, on caller-supplied memory.
//!
//! Lengths whose prime factors are 2, 3 and 5 run a mixed-radix (4, 2, 3, 5) Stockham
//! autosort FFT; any other length runs Bluestein's chirp-z algorithm on top of it, with the
//! smallest 5-smooth inner length `m ≥ 2n − 1`. A plan ([`FftPlan`], small and `Copy`) fills its
//! tables once ([`FftPlan::init`]) in scratch the caller owns ([`FftPlan::scratch_len`] complex
//! values), and then transforms any number of length-`n` buffers with that scratch; [`Fft`] bundles
//! a plan with a borrowed scratch for one-off use. The transforms are unnormalised (as `rustfft`):
//! `inverse(forward(x)) = n·x`.
//!
//! Determinism: twiddles come from `libm::sin`/`cos` of `2π·k/n` with `k` reduced exactly in
//! integers, and every butterfly spells its operations out, so x86-64 and a Cortex-M (soft `f64`)
//! produce the same bits. Accuracy is that of a textbook FFT, ~10⁻¹⁵ relative.
//!
//! ```
//! use margemu_model::perturbation::fft::{Complex, Fft};
//! let n = 6;
//! let mut scratch = [Complex::ZERO; 12];
//! assert_eq!(Fft::scratch_len(n)?, 12);
//! let mut fft = Fft::new(n, &mut scratch)?;
//! let mut x = [Complex::new(1.0, 0.0); 6];
//! fft.forward(&mut x)?;
//! assert!((x[0].re - 6.0).abs() < 1e-12 && x[1].norm() < 1e-12);
//! fft.inverse(&mut x)?;
//! assert!((x[3].re - 6.0).abs() < 1e-12);
//! # Ok::<(), margemu_model::Error>(())
//! ```

use crate::error::Error;
use core::f64::consts::PI;

/// A complex number in double precision.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Complex {
    /// Real part.
    pub re: f64,
    /// Imaginary part.
    pub im: f64,
}

impl Complex {
    /// Zero.
    pub const ZERO: Self = Self { re: 0.0, im: 0.0 };

    /// `re + i·im`.
    pub const fn new(re: f64, im: f64) -> Self {
        Self { re, im }
    }

    /// `|z|`.
    pub fn norm(self) -> f64 {
        libm::sqrt(self.re * self.re + self.im * self.im)
    }

    /// `e^{−2πi·k/n}` with `k` reduced modulo `n` exactly.
    fn root(k: usize, n: usize) -> Self {
        let angle = -2.0 * PI * ((k % n) as f64) / (n as f64);
        Self::new(libm::cos(angle), libm::sin(angle))
    }
}

#[inline(always)]
fn add(a: Complex, b: Complex) -> Complex {
    Complex::new(a.re + b.re, a.im + b.im)
}

#[inline(always)]
fn sub(a: Complex, b: Complex) -> Complex {
    Complex::new(a.re - b.re, a.im - b.im)
}

#[inline(always)]
fn mul(a: Complex, b: Complex) -> Complex {
    Complex::new(a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re)
}

#[inline(always)]
fn scale(a: Complex, s: f64) -> Complex {
    Complex::new(a.re * s, a.im * s)
}

/// `−i·a`.
#[inline(always)]
fn times_minus_i(a: Complex) -> Complex {
    Complex::new(a.im, -a.re)
}

#[inline(always)]
fn conj(a: Complex) -> Complex {
    Complex::new(a.re, -a.im)
}

/// Whether `n`'s prime factors are all 2, 3 or 5 (1 included).
pub fn is_smooth(mut n: usize) -> bool {
    if n == 0 {
        return false;
    }
    for p in [2, 3, 5] {
        while n.is_multiple_of(p) {
            n /= p;
        }
    }
    n == 1
}

/// The smallest 5-smooth number ≥ `n`, or `None` on overflow.
pub fn next_smooth(n: usize) -> Option<usize> {
    let mut best: Option<usize> = None;
    let mut p5 = 1usize;
    loop {
        let mut p35 = p5;
        loop {
            let mut x = p35;
            while x < n {
                x = x.checked_mul(2)?;
            }
            best = Some(best.map_or(x, |b| b.min(x)));
            if p35 >= n {
                break;
            }
            p35 = p35.checked_mul(3)?;
        }
        if p5 >= n {
            break;
        }
        p5 = p5.checked_mul(5)?;
    }
    best
}

/// The radices of a 5-smooth length, 4s first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Radices {
    n: usize,
    factors: [u8; 64],
    count: usize,
}

impl Radices {
    /// The factorisation of `n` (5-smooth, ≥ 1).
    fn new(n: usize) -> Self {
        let mut factors = [0u8; 64];
        let (mut count, mut m) = (0, n);
        for p in [4usize, 2, 3, 5] {
            while m % p == 0 && count < 64 {
                factors[count] = p as u8;
                count += 1;
                m /= p;
            }
        }
        Self { n, factors, count }
    }

    /// Fills `tw[k] = e^{−2πi·k/n}`, `k < n`.
    fn init(&self, tw: &mut [Complex]) {
        for (k, t) in tw.iter_mut().take(self.n).enumerate() {
            *t = Complex::root(k, self.n);
        }
    }

    /// The forward transform of `data[..n]` in place, with the twiddles `tw[..n]` and the work
    /// buffer `work[..n]`.
    fn forward(&self, tw: &[Complex], work: &mut [Complex], data: &mut [Complex]) {
        let n = self.n;
        let (tw, work, data) = (&tw[..n], &mut work[..n], &mut data[..n]);
        let (mut len, mut stride) = (n, 1usize);
        let mut in_data = true;
        for &r in &self.factors[..self.count] {
            let r = usize::from(r);
            let (src, dst): (&[Complex], &mut [Complex]) = if in_data {
                (&*data, &mut *work)
            } else {
                (&*work, &mut *data)
            };
            stage(src, dst, tw, r, len / r, stride);
            len /= r;
            stride *= r;
            in_data = !in_data;
        }
        if !in_data {
            data.copy_from_slice(work);
        }
    }
}

/// One Stockham stage of radix `r`: for `p < m`, `q < s`,
/// `dst[q + s(rp + k)] = w_{rm}^{pk} · Σ_j src[q + s(p + jm)]·w_r^{jk}`.
fn stage(src: &[Complex], dst: &mut [Complex], tw: &[Complex], r: usize, m: usize, s: usize) {
    const S3: f64 = 0.866_025_403_784_438_6; // sin(2π/3)
    const C51: f64 = 0.309_016_994_374_947_45; // cos(2π/5)
    const C52: f64 = -0.809_016_994_374_947_5; // cos(4π/5)
    const S51: f64 = 0.951_056_516_295_153_5; // sin(2π/5)
    const S52: f64 = 0.587_785_252_292_473_1; // sin(4π/5)
    let sm = s * m;
    for p in 0..m {
        // w_{rm}^{pk} = w_n^{pks}, and p·k·s < n.
        let w = |k: usize| tw[p * k * s];
        let (i0, o0) = (s * p, s * r * p);
        let src = &src[i0..];
        let dst = &mut dst[o0..o0 + r * s];
        match r {
            2 => {
                let w1 = w(1);
                for q in 0..s {
                    let (a0, a1) = (src[q], src[q + sm]);
                    dst[q] = add(a0, a1);
                    dst[q + s] = mul(sub(a0, a1), w1);
                }
            }
            3 => {
                let (w1, w2) = (w(1), w(2));
                for q in 0..s {
                    let (a0, a1, a2) = (src[q], src[q + sm], src[q + 2 * sm]);
                    let t1 = add(a1, a2);
                    let t2 = sub(a0, scale(t1, 0.5));
                    let t3 = times_minus_i(scale(sub(a1, a2), S3));
                    dst[q] = add(a0, t1);
                    dst[q + s] = mul(add(t2, t3), w1);
                    dst[q + 2 * s] = mul(sub(t2, t3), w2);
                }
            }
            4 => {
                let (w1, w2, w3) = (w(1), w(2), w(3));
                for q in 0..s {
                    let (a0, a1) = (src[q], src[q + sm]);
                    let (a2, a3) = (src[q + 2 * sm], src[q + 3 * sm]);
                    let (t0, t1) = (add(a0, a2), sub(a0, a2));
                    let (t2, t3) = (add(a1, a3), times_minus_i(sub(a1, a3)));
                    dst[q] = add(t0, t2);
                    dst[q + s] = mul(add(t1, t3), w1);
                    dst[q + 2 * s] = mul(sub(t0, t2), w2);
                    dst[q + 3 * s] = mul(sub(t1, t3), w3);
                }
            }
            _ => {
                let (w1, w2, w3, w4) = (w(1), w(2), w(3), w(4));
                for q in 0..s {
                    let a0 = src[q];
                    let (a1, a2) = (src[q + sm], src[q + 2 * sm]);
                    let (a3, a4) = (src[q + 3 * sm], src[q + 4 * sm]);
                    let (b1, b2) = (add(a1, a4), add(a2, a3));
                    let (d1, d2) = (sub(a1, a4), sub(a2, a3));
                    let c1 = add(a0, add(scale(b1, C51), scale(b2, C52)));
                    let c2 = add(a0, add(scale(b1, C52), scale(b2, C51)));
                    let s1 = times_minus_i(add(scale(d1, S51), scale(d2, S52)));
                    let s2 = times_minus_i(sub(scale(d1, S52), scale(d2, S51)));
                    dst[q] = add(a0, add(b1, b2));
                    dst[q + s] = mul(add(c1, s1), w1);
                    dst[q + 2 * s] = mul(add(c2, s2), w2);
                    dst[q + 3 * s] = mul(sub(c2, s2), w3);
                    dst[q + 4 * s] = mul(sub(c1, s1), w4);
                }
            }
        }
    }
}

/// How a length is transformed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Algo {
    /// 5-smooth: scratch = twiddles (n) | work (n).
    Direct(Radices),
    /// Other lengths: scratch = inner twiddles (m) | inner work (m) | chirp (n) | kernel (m) |
    /// buffer (m).
    Bluestein(Radices),
}

/// The plan of an FFT of one length: small and `Copy`; its tables live in caller scratch that
/// [`FftPlan::init`] fills once and every transform then reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FftPlan {
    n: usize,
    algo: Algo,
    scratch_len: usize,
}

impl FftPlan {
    /// Plans a transform of length `n`.
    pub fn new(n: usize) -> Result<Self, Error> {
        if n == 0 || is_smooth(n) {
            let scratch_len = n.checked_mul(2).ok_or(Error::FftTooLong)?;
            return Ok(Self {
                n,
                algo: Algo::Direct(Radices::new(n.max(1))),
                scratch_len,
            });
        }
        let m = bluestein_len(n)?;
        let scratch_len = m
            .checked_mul(4)
            .and_then(|x| x.checked_add(n))
            .ok_or(Error::FftTooLong)?;
        Ok(Self {
            n,
            algo: Algo::Bluestein(Radices::new(m)),
            scratch_len,
        })
    }

    /// The transform length.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Whether the length is zero.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The [`Complex`] values of scratch: `2n` for 5-smooth `n`, else `4m + n` with `m` the
    /// smallest 5-smooth number ≥ `2n − 1`.
    pub fn scratch_len(&self) -> usize {
        self.scratch_len
    }

    fn check(&self, scratch: &[Complex]) -> Result<(), Error> {
        match scratch.len() < self.scratch_len {
            true => Err(Error::BufferTooSmall {
                needed: self.scratch_len,
                got: scratch.len(),
            }),
            false => Ok(()),
        }
    }

    /// Fills the tables in `scratch` (at least [`Self::scratch_len`] values).
    pub fn init(&self, scratch: &mut [Complex]) -> Result<(), Error> {
        self.check(scratch)?;
        let n = self.n;
        match self.algo {
            Algo::Direct(radix) => radix.init(scratch),
            Algo::Bluestein(inner) => {
                let m = inner.n;
                let (tw, rest) = scratch.split_at_mut(m);
                let (work, rest) = rest.split_at_mut(m);
                let (chirp, rest) = rest.split_at_mut(n);
                let kernel = &mut rest[..m];
                inner.init(tw);
                let two_n = 2 * n as u128;
                for (j, c) in chirp.iter_mut().enumerate() {
                    // j² mod 2n, exactly: e^{−iπ j²/n} = e^{−2πi (j² mod 2n) / 2n}.
                    let k = ((j as u128 * j as u128) % two_n) as usize;
                    *c = Complex::root(k, 2 * n);
                }
                kernel.fill(Complex::ZERO);
                kernel[0] = conj(chirp[0]);
                for j in 1..n {
                    kernel[j] = conj(chirp[j]);
                    kernel[m - j] = conj(chirp[j]);
                }
                inner.forward(tw, work, kernel);
            }
        }
        Ok(())
    }

    /// `X_k = Σ_j x_j e^{−2πi jk/n}` in place, with the tables [`Self::init`] filled in
    /// `scratch`; `data` must hold exactly `n` values.
    pub fn forward(&self, scratch: &mut [Complex], data: &mut [Complex]) -> Result<(), Error> {
        self.check(scratch)?;
        if data.len() != self.n {
            return Err(Error::BufferTooSmall {
                needed: self.n,
                got: data.len(),
            });
        }
        let n = self.n;
        match self.algo {
            Algo::Direct(radix) => {
                if n > 0 {
                    let (tw, work) = scratch.split_at_mut(n);
                    radix.forward(tw, work, data);
                }
            }
            Algo::Bluestein(inner) => {
                let m = inner.n;
                let (tw, rest) = scratch.split_at_mut(m);
                let (work, rest) = rest.split_at_mut(m);
                let (chirp, rest) = rest.split_at_mut(n);
                let (kernel, rest) = rest.split_at_mut(m);
                let buf = &mut rest[..m];
                buf.fill(Complex::ZERO);
                for j in 0..n {
                    buf[j] = mul(data[j], chirp[j]);
                }
                inner.forward(tw, work, buf);
                for k in 0..m {
                    buf[k] = conj(mul(buf[k], kernel[k]));
                }
                inner.forward(tw, work, buf); // conj(FFT(conj(y))) = m·IFFT(y)
                let inv_m = 1.0 / m as f64;
                for k in 0..n {
                    data[k] = scale(mul(conj(buf[k]), chirp[k]), inv_m);
                }
            }
        }
        Ok(())
    }

    /// `x_j = Σ_k X_k e^{+2πi jk/n}` in place (unnormalised), as [`Self::forward`].
    pub fn inverse(&self, scratch: &mut [Complex], data: &mut [Complex]) -> Result<(), Error> {
        for z in data.iter_mut() {
            *z = conj(*z);
        }
        let result = self.forward(scratch, data);
        for z in data.iter_mut() {
            *z = conj(*z);
        }
        result
    }
}

/// A plan together with its filled scratch: the convenient form for one-off use.
pub struct Fft<'a> {
    plan: FftPlan,
    scratch: &'a mut [Complex],
}

impl<'a> Fft<'a> {
    /// The [`Complex`] values of scratch a transform of length `n` needs.
    pub fn scratch_len(n: usize) -> Result<usize, Error> {
        Ok(FftPlan::new(n)?.scratch_len())
    }

    /// Plans a transform of length `n` and fills its tables in `scratch`.
    pub fn new(n: usize, scratch: &'a mut [Complex]) -> Result<Self, Error> {
        let plan = FftPlan::new(n)?;
        plan.init(scratch)?;
        Ok(Self { plan, scratch })
    }

    /// The plan.
    pub fn plan(&self) -> FftPlan {
        self.plan
    }

    /// The forward transform of `data` (exactly `n` values) in place.
    pub fn forward(&mut self, data: &mut [Complex]) -> Result<(), Error> {
        self.plan.forward(self.scratch, data)
    }

    /// The unnormalised inverse transform of `data` in place.
    pub fn inverse(&mut self, data: &mut [Complex]) -> Result<(), Error> {
        self.plan.inverse(self.scratch, data)
    }
}

/// The Bluestein inner length for `n`.
fn bluestein_len(n: usize) -> Result<usize, Error> {
    n.checked_mul(2)
        .and_then(|x| next_smooth(x - 1))
        .ok_or(Error::FftTooLong)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn naive(x: &[Complex]) -> [Complex; 64] {
        let n = x.len();
        let mut out = [Complex::ZERO; 64];
        for (k, o) in out.iter_mut().enumerate().take(n) {
            for (j, &v) in x.iter().enumerate() {
                *o = add(*o, mul(v, Complex::root(j * k, n)));
            }
        }
        out
    }

    #[test]
    fn smooth_lengths_are_recognised() {
        assert!(is_smooth(1) && is_smooth(400) && is_smooth(16_000) && is_smooth(1350));
        assert!(!is_smooth(0) && !is_smooth(7) && !is_smooth(667));
        assert_eq!(next_smooth(1333), Some(1350));
        assert_eq!(next_smooth(1), Some(1));
        assert_eq!(next_smooth(7), Some(8));
        assert_eq!(next_smooth(usize::MAX), None);
        assert_eq!(Fft::scratch_len(usize::MAX), Err(Error::FftTooLong));
    }

    #[test]
    fn every_short_length_matches_the_naive_dft() {
        let mut scratch = [Complex::ZERO; 1024];
        for n in 1..=40 {
            let x: [Complex; 64] =
                core::array::from_fn(|j| Complex::new(libm::sin(j as f64 * 1.3), (j % 5) as f64));
            let reference = naive(&x[..n]);
            let mut y = x;
            let mut fft = Fft::new(n, &mut scratch).unwrap();
            fft.forward(&mut y[..n]).unwrap();
            for k in 0..n {
                let e = sub(y[k], reference[k]).norm();
                assert!(e < 1e-11, "n = {n}, k = {k}, error {e}");
            }
            fft.inverse(&mut y[..n]).unwrap();
            for j in 0..n {
                assert!(
                    sub(scale(y[j], 1.0 / n as f64), x[j]).norm() < 1e-12,
                    "n = {n}"
                );
            }
        }
    }

    #[test]
    fn wrong_buffers_are_refused() {
        let mut scratch = [Complex::ZERO; 8];
        assert_eq!(
            Fft::new(7, &mut scratch).err(),
            Some(Error::BufferTooSmall {
                needed: 4 * 15 + 7,
                got: 8
            })
        );
        let mut fft = Fft::new(4, &mut scratch).unwrap();
        let mut x = [Complex::ZERO; 5];
        assert!(fft.forward(&mut x).is_err());
        let mut empty = Fft::new(0, &mut scratch).unwrap();
        assert!(empty.plan().is_empty());
        empty.forward(&mut []).unwrap();
    }
}
