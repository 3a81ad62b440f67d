//! One seeded generator per named stream.
//!
//! Every random draw in margemu comes from a [`StreamRng`] made by [`stream`] from the scene's
//! seed and the stream's name. Streams are independent: adding a model term that draws from its
//! own stream never shifts the draws of another, and the same scene and seed give the same bytes
//! on every run and every machine (ChaCha8 is specified bit for bit and has no platform
//! dependence). The stream names in use are listed in the crate docs ("Random streams").
//!
//! Normal draws come from [`standard_normal`], a 256-layer ziggurat in `f32` whose tables are
//! constants and whose rare slow paths call `libm::expf`/`logf`. It does not use `rand_distr`:
//! that crate's ziggurat calls `exp`/`ln` through `num-traits`, whose `std` feature the host build
//! switches on (nalgebra does), so the host would call the C library's `exp`/`ln` and the firmware
//! `libm`'s, and those disagree in the last bit for 7–10 % of arguments (measured on this machine):
//! host and firmware draws would part ways.
//!
//! ```
//! use margemu_model::rng::stream;
//! use rand_core::Rng;
//! let mut a = stream(7, "reference/x");
//! let mut b = stream(7, "reference/x");
//! let mut c = stream(7, "reference/y");
//! let (x, y, z) = (a.next_u64(), b.next_u64(), c.next_u64());
//! assert_eq!(x, y);
//! assert_ne!(x, z);
//! ```

use rand_chacha::ChaCha8Rng;
use rand_core::SeedableRng;

mod ziggurat;

/// The generator behind every stream.
pub type StreamRng = ChaCha8Rng;

/// The generator of stream `name` for the scene seed `seed`.
///
/// The key is the seed, the ChaCha stream number is the 64-bit FNV-1a hash of the name.
pub fn stream(seed: u64, name: &str) -> StreamRng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(fnv1a64(name.as_bytes()));
    rng
}

/// 64-bit FNV-1a hash (stable across platforms and releases).
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        hash ^= b as u64;
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
    hash
}

/// A uniform draw in `[0, 1)` with 53 random bits (the same on every platform).
pub fn unit_f64(rng: &mut StreamRng) -> f64 {
    use rand_core::Rng;
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// A uniform draw in `[lo, hi)`; `lo` when the interval is empty.
pub fn uniform(rng: &mut StreamRng, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * unit_f64(rng)
}

/// A uniform integer in `[0, n)` (Lemire's multiply-and-reject), or 0 when `n` is 0.
///
/// Consumes one 32-bit word, and another only in the rare rejected cases (fewer than `n / 2³²`).
pub fn below(rng: &mut StreamRng, n: u32) -> u32 {
    use rand_core::Rng;
    if n == 0 {
        return 0;
    }
    let threshold = n.wrapping_neg() % n;
    loop {
        let m = u64::from(rng.next_u32()) * u64::from(n);
        if (m as u32) >= threshold {
            return (m >> 32) as u32;
        }
    }
}

/// A standard normal deviate in single precision (256-layer ziggurat, Marsaglia & Tsang 2000).
///
/// Each attempt takes one 32-bit word: 8 bits choose the layer, 1 bit the sign, 23 bits the
/// magnitude. 98.8 % of the draws end there (one word, one integer compare, one multiply); the
/// others test a wedge with `libm::expf` or sample the tail beyond 3.654 with `libm::logf`, and
/// take more words. Every step is `f32` or integer arithmetic in a fixed order, so the same words
/// give the same deviate on every target.
///
/// ```
/// use margemu_model::rng::{standard_normal, stream};
/// let mut rng = stream(1, "doc");
/// let (mut sum, mut sq) = (0.0f64, 0.0f64);
/// for _ in 0..100_000 {
///     let z = f64::from(standard_normal(&mut rng));
///     sum += z;
///     sq += z * z;
/// }
/// assert!((sum / 1e5).abs() < 0.01 && (sq / 1e5 - 1.0).abs() < 0.02);
/// ```
#[inline]
pub fn standard_normal(rng: &mut StreamRng) -> f32 {
    use rand_core::Rng;
    loop {
        let bits = rng.next_u32();
        let i = (bits & 0xff) as usize;
        let m = bits >> 9;
        let x = if m < ziggurat::K[i] {
            m as f32 * ziggurat::W[i]
        } else {
            match ziggurat::slow(rng, i, m) {
                Some(x) => x,
                None => continue,
            }
        };
        return if bits & 0x100 != 0 { -x } else { x };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_core::Rng;

    #[test]
    fn streams_are_pinned_to_their_first_draws() {
        // Pins the stream derivation: a change here changes every recorded run.
        assert_eq!(fnv1a64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64(b"a"), 0xaf63_dc4c_8601_ec8c);
        let mut rng = stream(42, "reference/x");
        let first = rng.next_u64();
        let mut again = stream(42, "reference/x");
        assert_eq!(first, again.next_u64());
        assert_ne!(first, stream(43, "reference/x").next_u64());
    }

    #[test]
    fn normal_draws_are_pinned() {
        let mut rng = stream(42, "noise/gyro");
        let z: [f32; 4] = core::array::from_fn(|_| standard_normal(&mut rng));
        assert_eq!(z.map(f32::to_bits), PINNED_NORMALS);
    }

    // -0.65299708, -0.74968183, -1.25116193, 0.48747611
    const PINNED_NORMALS: [u32; 4] = [0xbf27_2ad1, 0xbf3f_eb26, 0xbfa0_2613, 0x3ef9_9678];

    #[test]
    fn normal_draws_have_unit_variance_and_bounded_tails() {
        let mut rng = stream(3, "test");
        let n = 1_000_000;
        let (mut sum, mut sq, mut max) = (0.0f64, 0.0f64, 0.0f32);
        for _ in 0..n {
            let z = standard_normal(&mut rng);
            sum += f64::from(z);
            sq += f64::from(z) * f64::from(z);
            max = max.max(libm::fabsf(z));
        }
        let mean = sum / f64::from(n);
        let var = sq / f64::from(n) - mean * mean;
        assert!(mean.abs() < 0.005, "mean {mean}");
        assert!((var - 1.0).abs() < 0.005, "variance {var}");
        assert!(max > 4.5 && max < 7.0, "max {max}");
    }

    #[test]
    fn below_is_uniform_and_in_range() {
        let mut rng = stream(5, "test");
        let mut counts = [0u32; 5];
        for _ in 0..50_000 {
            counts[below(&mut rng, 5) as usize] += 1;
        }
        assert!(
            counts.iter().all(|&c| (9_500..10_500).contains(&c)),
            "{counts:?}"
        );
        assert_eq!(below(&mut rng, 0), 0);
        assert_eq!(below(&mut rng, 1), 0);
    }

    #[test]
    fn uniform_draws_stay_in_range() {
        let mut rng = stream(1, "test");
        for _ in 0..10_000 {
            let u = uniform(&mut rng, -2.0, 3.0);
            assert!((-2.0..3.0).contains(&u));
        }
    }
}
