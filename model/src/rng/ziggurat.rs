//! The slow paths and the tables of [`super::standard_normal`].

#[path = "ziggurat_tables.rs"]
mod tables;

use super::StreamRng;
use rand_core::Rng;

/// The start of the tail, `x[1]`.
const R: f32 = 3.654_152_9;

/// Fast-path thresholds per layer.
pub(super) const K: [u32; 256] = tables::K;
/// Magnitude scale per layer, `x[i]·2⁻²³`.
pub(super) const W: [f32; 256] = from_bits(tables::W_BITS);
/// The density `exp(−x²/2)` at the layer edges.
const F: [f32; 257] = from_bits(tables::F_BITS);

const fn from_bits<const N: usize>(bits: [u32; N]) -> [f32; N] {
    let mut out = [0.0f32; N];
    let mut i = 0;
    while i < N {
        out[i] = f32::from_bits(bits[i]);
        i += 1;
    }
    out
}

/// A uniform in `(0, 1)` from the top 24 bits of a word.
fn open01(rng: &mut StreamRng) -> f32 {
    ((rng.next_u32() >> 8) as f32 + 0.5) * (1.0 / 16_777_216.0)
}

/// The magnitude drawn in layer `i` with 23-bit magnitude `m` outside the layer's inner
/// rectangle: the tail for the base layer, else the wedge test (`None`: draw again).
#[inline(never)]
pub(super) fn slow(rng: &mut StreamRng, i: usize, m: u32) -> Option<f32> {
    if i == 0 {
        // Marsaglia's tail: x = R + a with a ~ Exp(R), accepted with probability e^{−a²/2}.
        loop {
            let a = -libm::logf(open01(rng)) * (1.0 / R);
            let b = -libm::logf(open01(rng));
            if b + b > a * a {
                return Some(R + a);
            }
        }
    }
    let x = m as f32 * W[i];
    let u = (rng.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0);
    let y = F[i + 1] + (F[i] - F[i + 1]) * u;
    (y < libm::expf(-0.5 * x * x)).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::{standard_normal, stream};

    #[test]
    fn tables_match_their_definition() {
        // x[0] = V/f(R), x[1] = R, x[i+1] = √(−2 ln(V/x[i] + f(x[i]))), x[256] = 0, in f64.
        let (r, v) = (3.654_152_885_361_009_f64, 0.004_928_673_233_99f64);
        let f = |x: f64| libm::exp(-0.5 * x * x);
        let mut x = [0.0f64; 257];
        x[0] = v / f(r);
        x[1] = r;
        for i in 1..255 {
            x[i + 1] = libm::sqrt(-2.0 * libm::log(v / x[i] + f(x[i])));
        }
        for i in 0..256 {
            assert_eq!(
                K[i],
                libm::ceil(8_388_608.0 * x[i + 1] / x[i]) as u32,
                "K[{i}]"
            );
            assert_eq!(W[i], (x[i] / 8_388_608.0) as f32, "W[{i}]");
            assert_eq!(F[i], f(x[i]) as f32, "F[{i}]");
        }
        assert_eq!(F[256], 1.0);
        assert_eq!(R, r as f32);
        // The top layer closes: its area is V.
        assert!((x[255] * (1.0 - f(x[255])) / v - 1.0).abs() < 1e-8);
    }

    #[test]
    fn draws_follow_the_normal_cdf() {
        // Kolmogorov–Smirnov against Φ on 10⁶ draws (the 0.1 % critical value is 1.95/√n), and
        // the tail masses beyond the ziggurat's R and beyond 4.5 within 4 binomial sigmas.
        let n = 1_000_000usize;
        let mut rng = stream(8, "test");
        let mut counts = [0u32; 1601]; // bins of 0.01 over [−8, 8]
        let (mut beyond_r, mut beyond_45) = (0u32, 0u32);
        for _ in 0..n {
            let z = standard_normal(&mut rng);
            let bin = libm::floorf((z + 8.0) * 100.0).clamp(0.0, 1600.0) as usize;
            counts[bin] += 1;
            beyond_r += u32::from(libm::fabsf(z) > R);
            beyond_45 += u32::from(libm::fabsf(z) > 4.5);
        }
        let phi = |x: f64| 0.5 * libm::erfc(-x / core::f64::consts::SQRT_2);
        let (mut cum, mut ks) = (0u32, 0.0f64);
        for (b, &c) in counts.iter().enumerate().take(1600) {
            cum += c;
            let edge = (b as f64 + 1.0) / 100.0 - 8.0;
            ks = ks.max((f64::from(cum) / n as f64 - phi(edge)).abs());
        }
        assert!(ks < 1.95 / libm::sqrt(n as f64), "KS statistic {ks}");
        for (count, x) in [(beyond_r, f64::from(R)), (beyond_45, 4.5)] {
            let p = 2.0 * (1.0 - phi(x));
            let expect = p * n as f64;
            let sigma = libm::sqrt(expect * (1.0 - p));
            assert!(
                (f64::from(count) - expect).abs() < 4.0 * sigma,
                "|z| > {x}: {count} vs {expect}"
            );
        }
    }
}
