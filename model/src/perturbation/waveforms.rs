//! The artificial signal of eq. 19: five waveforms at random block positions.
//!
//! A window of `n` samples is cut into blocks of `L_w = round(n/10)` samples (half away from
//! zero, as MATLAB's `round`). The five waveforms (square, sawtooth 0→1, sine `f₁`, sine `f₂`,
//! triangle 0→½→0) each fill one block, at the odd block positions of the 1-based reference code
//! (0-based blocks 0, 2, 4, 6, 8) in a random permutation; the other samples are zero, and a block
//! that would run past the window is cut. With `j = k − s` the sample's offset in its block,
//! `t = j/L_w ∈ [0, 1)`:
//!
//! | waveform | value |
//! |---|---|
//! | square | `r₁` |
//! | sawtooth | `r₂·t` |
//! | sine | `r₃·sin(2π f₁ t)`, `r₄·sin(2π f₂ t)` (f in cycles per block, as eq. 19 writes it) |
//! | triangle | `(r₅/π)·asin(sin(π t)) = r₅·min(t, 1 − t)` (computed in the closed form) |
//!
//! with `r_i ~ N(0, 1)` and `f₁, f₂ ~ U(0.5, 2.5)`. The draws come in a fixed order: the
//! permutation (Fisher–Yates, 4 draws), `r₁…r₅`, `f₁`, `f₂`.
//!
//! ```
//! use margemu_model::perturbation::fft::Complex;
//! use margemu_model::perturbation::waveforms::Waveforms;
//! use margemu_model::rng::stream;
//! let w = Waveforms::draw(&mut stream(1, "doc"));
//! let mut data = [Complex::ZERO; 400];
//! w.render(&mut data);
//! // Odd (0-based) blocks stay zero.
//! assert!(data[40..80].iter().all(|z| z.re == 0.0));
//! ```

use super::fft::Complex;
use crate::rng::{below, standard_normal, uniform, StreamRng};
use core::f64::consts::PI;

/// The random parameters of one artificial signal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Waveforms {
    /// The 0-based block of each waveform (square, sawtooth, sine f₁, sine f₂, triangle).
    pub blocks: [usize; 5],
    /// Amplitudes `r₁…r₅`.
    pub amplitudes: [f64; 5],
    /// Sine frequencies `f₁`, `f₂`, cycles per block.
    pub frequencies: [f64; 2],
}

impl Waveforms {
    /// Draws the parameters from `rng`.
    pub fn draw(rng: &mut StreamRng) -> Self {
        let mut positions = [0usize, 2, 4, 6, 8];
        for i in (1..5).rev() {
            let j = below(rng, i as u32 + 1) as usize;
            positions.swap(i, j);
        }
        let amplitudes = core::array::from_fn(|_| f64::from(standard_normal(rng)));
        let f1 = uniform(rng, 0.5, 2.5);
        let f2 = uniform(rng, 0.5, 2.5);
        Self {
            blocks: positions,
            amplitudes,
            frequencies: [f1, f2],
        }
    }

    /// The block length for a window of `n` samples, `round(n/10)`.
    pub fn block_len(n: usize) -> usize {
        n / 10 + usize::from(n % 10 >= 5)
    }

    /// Writes the signal to `data[k].re` (and zeros to `data[k].im`), `n = data.len()`.
    pub fn render(&self, data: &mut [Complex]) {
        let n = data.len();
        data.fill(Complex::ZERO);
        let lw = Self::block_len(n);
        if lw == 0 {
            return;
        }
        let inv = 1.0 / lw as f64;
        for (shape, (&block, &r)) in self.blocks.iter().zip(&self.amplitudes).enumerate() {
            let start = block.saturating_mul(lw);
            for j in 0..lw {
                let Some(z) = data.get_mut(start.saturating_add(j)) else {
                    break;
                };
                let t = j as f64 * inv;
                z.re = match shape {
                    0 => r,
                    1 => r * t,
                    2 => r * libm::sin(2.0 * PI * self.frequencies[0] * t),
                    3 => r * libm::sin(2.0 * PI * self.frequencies[1] * t),
                    _ => r * if t < 0.5 { t } else { 1.0 - t },
                };
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::stream;

    #[test]
    fn blocks_follow_the_formulas() {
        let w = Waveforms {
            blocks: [8, 6, 4, 2, 0],
            amplitudes: [1.0, 2.0, 1.0, -1.0, 4.0],
            frequencies: [1.0, 0.5],
        };
        let mut d = [Complex::ZERO; 100];
        w.render(&mut d);
        assert!(d[80..90].iter().all(|z| z.re == 1.0)); // square
        assert_eq!(d[65].re, 1.0); // sawtooth 2·5/10
        assert!((d[42].re - libm::sin(2.0 * PI * 0.2)).abs() < 1e-15); // sine f₁ = 1
        assert!((d[25].re + 1.0).abs() < 1e-15); // −sin(2π·0.5·0.5)
        assert_eq!(
            [d[0].re, d[5].re, d[8].re],
            [0.0, 2.0, 4.0 * 0.19999999999999996]
        );
        for b in [1, 3, 5, 7, 9] {
            assert!(d[b * 10..b * 10 + 10].iter().all(|z| z.re == 0.0));
        }
    }

    #[test]
    fn draws_are_permutations_in_range() {
        let mut rng = stream(9, "test");
        for _ in 0..100 {
            let w = Waveforms::draw(&mut rng);
            let mut b = w.blocks;
            b.sort_unstable();
            assert_eq!(b, [0, 2, 4, 6, 8]);
            assert!(w.frequencies.iter().all(|f| (0.5..2.5).contains(f)));
        }
        assert_eq!(Waveforms::block_len(15), 2);
        assert_eq!(Waveforms::block_len(14), 1);
        assert_eq!(Waveforms::block_len(16_000), 1600);
    }

    #[test]
    fn short_windows_cut_the_last_blocks() {
        let w = Waveforms::draw(&mut stream(2, "test"));
        let mut d = [Complex::new(9.0, 9.0); 13]; // L_w = 1: blocks 0..8 fit
        w.render(&mut d);
        assert!(d.iter().all(|z| z.im == 0.0 && z.re.is_finite()));
        let mut tiny = [Complex::ZERO; 3]; // L_w = 0: all zero
        w.render(&mut tiny);
        assert!(tiny.iter().all(|z| z.re == 0.0));
    }
}
