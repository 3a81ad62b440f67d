//! One seeded generator per named stream.
//!
//! Every random draw in margemu comes from a [`StreamRng`] made by [`stream`] from the scene's
//! seed and the stream's name. Streams are independent: adding a model term that draws from its
//! own stream never shifts the draws of another, and the same scene and seed give the same bytes
//! on every run and every machine (ChaCha8 is specified bit for bit and has no platform
//! dependence). The stream names in use are listed in the README ("Random streams").
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
    fn uniform_draws_stay_in_range() {
        let mut rng = stream(1, "test");
        for _ in 0..10_000 {
            let u = uniform(&mut rng, -2.0, 3.0);
            assert!((-2.0..3.0).contains(&u));
        }
    }
}
