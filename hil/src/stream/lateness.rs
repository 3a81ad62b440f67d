//! [`Lateness`]: how late paced batches were written, kept as a fixed histogram so that a
//! session's pacing statistics take the same memory for a second or a day.
//!
//! Bins are log-spaced with 128 per octave: every value below 128 ns has its own bin, and a larger
//! value `v` falls in a bin `[b, b + b/128)`. A percentile is the lower bound of the bin holding
//! the nearest-rank sample, so it is exact below 128 ns and otherwise at most 1/128 (0.8 %) below
//! the exact nearest-rank value; the largest value is kept exactly. Negative values count as 0.
//!
//! ```
//! use margemu_hil::stream::Lateness;
//! let mut late = Lateness::new();
//! (1..=100).for_each(|ns| late.record(ns));
//! late.record(1_000_000);
//! let j = late.stats();
//! assert_eq!((j.batches, j.p50_ns, j.max_ns), (101, 51, 1_000_000));
//! assert!(j.p99_ns == 100);
//! ```

use super::JitterStats;

/// Bins per octave (and the values below this have one bin each).
const PER_OCTAVE: u64 = 128;
/// log2 of [`PER_OCTAVE`].
const OCTAVE_BITS: u32 = 7;
/// Octaves above the exact range, up to `i64::MAX`.
const OCTAVES: usize = 63 - OCTAVE_BITS as usize;
const BINS: usize = PER_OCTAVE as usize * (1 + OCTAVES);

/// A histogram of lateness values, ns (see the module docs).
#[derive(Clone, Debug)]
pub struct Lateness {
    counts: Box<[u64]>,
    total: u64,
    max_ns: i64,
    last_ns: i64,
}

impl Default for Lateness {
    fn default() -> Self {
        Self::new()
    }
}

impl Lateness {
    /// No values yet.
    pub fn new() -> Self {
        Self {
            counts: vec![0; BINS].into_boxed_slice(),
            total: 0,
            max_ns: 0,
            last_ns: 0,
        }
    }

    /// Counts one value, ns.
    pub fn record(&mut self, ns: i64) {
        let ns = ns.max(0);
        self.counts[bin_of(ns as u64)] += 1;
        self.total += 1;
        self.max_ns = self.max_ns.max(ns);
        self.last_ns = ns;
    }

    /// The latest value recorded (0 before any).
    pub fn last_ns(&self) -> i64 {
        self.last_ns
    }

    /// Count, nearest-rank median and 99th percentile (see the module docs), largest.
    pub fn stats(&self) -> JitterStats {
        JitterStats {
            batches: self.total,
            p50_ns: self.percentile(0.5),
            p99_ns: self.percentile(0.99),
            max_ns: self.max_ns,
        }
    }

    fn percentile(&self, p: f64) -> i64 {
        if self.total == 0 {
            return 0;
        }
        let rank = ((p * self.total as f64).ceil() as u64).clamp(1, self.total);
        let mut seen = 0;
        for (bin, &count) in self.counts.iter().enumerate() {
            seen += count;
            if seen >= rank {
                return (lower_bound(bin) as i64).min(self.max_ns);
            }
        }
        self.max_ns
    }
}

fn bin_of(v: u64) -> usize {
    if v < PER_OCTAVE {
        return v as usize;
    }
    let octave = 63 - v.leading_zeros() - OCTAVE_BITS; // ≥ 0
    let mantissa = (v >> octave) - PER_OCTAVE; // the 7 bits below the leading one
    (PER_OCTAVE * (1 + u64::from(octave)) + mantissa) as usize
}

fn lower_bound(bin: usize) -> u64 {
    let bin = bin as u64;
    if bin < PER_OCTAVE {
        return bin;
    }
    let octave = bin / PER_OCTAVE - 1;
    (PER_OCTAVE + bin % PER_OCTAVE) << octave
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bins_hold_their_values_within_a_128th() {
        for v in [
            0u64,
            1,
            127,
            128,
            129,
            255,
            256,
            1000,
            123_456_789,
            i64::MAX as u64,
        ] {
            let b = bin_of(v);
            let low = lower_bound(b);
            assert!(low <= v && v - low <= v / 128, "{v}: bin {b} from {low}");
            assert!(b < BINS);
        }
        assert!(bin_of(i64::MAX as u64) == BINS - 1);
    }

    #[test]
    fn percentiles_agree_with_the_exact_ones_within_the_precision() {
        let values: Vec<i64> = (0..10_000).map(|i| (i * i * 37) % 5_000_000).collect();
        let mut h = Lateness::new();
        values.iter().for_each(|&v| h.record(v));
        let exact = JitterStats::from_lateness(&values);
        let got = h.stats();
        assert_eq!((got.batches, got.max_ns), (exact.batches, exact.max_ns));
        for (g, e) in [(got.p50_ns, exact.p50_ns), (got.p99_ns, exact.p99_ns)] {
            assert!(g <= e && e - g <= e / 128, "{g} against {e}");
        }
        assert_eq!(Lateness::new().stats(), JitterStats::default());
        h.record(-5);
        assert_eq!(h.last_ns(), 0);
    }
}
