//! What the device reports it served, checked against the host's prediction.
//!
//! The device reports every sample instant it serves (`docs/spec/link.md` §5.13): the index, the
//! CRC-32C of the 22-byte image it latched into the chip, and whether the instant was an
//! underrun (the previous image held) or empty (nothing latched yet). [`ServedCheck`] compares
//! each entry with the CRC-32C of the image the host predicted for that index and keeps the
//! counts a session reports ([`ServedStats`]). An index reported twice counts once.
//!
//! ```
//! use margemu::stream::ServedCheck;
//! use margemu_protocol::link::{ServedSample, CRC32C};
//! let predicted = [[1u8; 22], [2u8; 22]];
//! let mut check = ServedCheck::new(predicted.iter().map(|im| CRC32C.checksum(im)).collect());
//! let served = |im: &[u8; 22], underrun| ServedSample { crc32c: CRC32C.checksum(im), underrun, empty: false };
//! assert_eq!(check.observe(0, &served(&predicted[0], false)), Some(true));
//! assert_eq!(check.observe(1, &served(&predicted[0], true)), Some(false)); // held: an underrun
//! assert_eq!(check.observe(2, &served(&predicted[1], true)), None); // after the scene's end
//! let stats = check.stats();
//! assert_eq!((stats.byte_exact, stats.underruns, stats.after_end, stats.lost()), (1, 1, 1, 1));
//! ```

use margemu_protocol::link::ServedSample;

/// Counts of the served samples, over the scene's indices `0 .. samples`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ServedStats {
    /// Samples in the scene.
    pub samples: u64,
    /// Entries received (duplicates and indices after the scene's end included).
    pub reported: u64,
    /// Scene indices served with exactly the predicted image (not an underrun).
    pub byte_exact: u64,
    /// Scene indices served as underruns or empty (the sample was missing at its instant).
    pub underruns: u64,
    /// Scene indices served, not as an underrun, with an image other than the predicted one.
    pub mismatched: u64,
    /// The first such index.
    pub first_mismatch: Option<u64>,
    /// Scene indices never reported (a lost Served frame, or a session that ended early).
    pub unreported: u64,
    /// Entries for instants after the scene's last sample (none from a device that honours
    /// Start's `end_index`).
    pub after_end: u64,
    /// The highest index reported.
    pub last_index: Option<u64>,
}

impl ServedStats {
    /// Scene samples not confirmed served byte for byte: underruns, mismatches and unreported.
    pub fn lost(&self) -> u64 {
        self.samples - self.byte_exact
    }
}

/// The running comparison of Served entries with the prediction (see the module docs).
#[derive(Clone, Debug)]
pub struct ServedCheck {
    expected: Vec<u32>,
    seen: Vec<bool>,
    stats: ServedStats,
}

impl ServedCheck {
    /// A check against the predicted images' CRC-32C, by sample index.
    pub fn new(expected: Vec<u32>) -> Self {
        let n = expected.len();
        Self {
            seen: vec![false; n],
            stats: ServedStats {
                samples: n as u64,
                unreported: n as u64,
                ..ServedStats::default()
            },
            expected,
        }
    }

    /// Records the entry of `index`; returns whether its image is the predicted one (`None`
    /// after the scene's end).
    pub fn observe(&mut self, index: u64, entry: &ServedSample) -> Option<bool> {
        let s = &mut self.stats;
        s.reported += 1;
        s.last_index = s.last_index.max(Some(index));
        let Some(&expected) = usize::try_from(index)
            .ok()
            .and_then(|i| self.expected.get(i))
        else {
            s.after_end += 1;
            return None;
        };
        let matches = !entry.empty && entry.crc32c == expected;
        let seen = &mut self.seen[index as usize];
        if !std::mem::replace(seen, true) {
            s.unreported -= 1;
            if entry.underrun || entry.empty {
                s.underruns += 1;
            } else if matches {
                s.byte_exact += 1;
            } else {
                s.mismatched += 1;
                s.first_mismatch.get_or_insert(index);
            }
        }
        Some(matches)
    }

    /// The counts so far.
    pub fn stats(&self) -> ServedStats {
        self.stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn duplicates_count_once_and_mismatches_are_located() {
        let mut check = ServedCheck::new(vec![10, 11, 12]);
        let entry = |crc32c| ServedSample {
            crc32c,
            underrun: false,
            empty: false,
        };
        assert_eq!(check.observe(1, &entry(99)), Some(false));
        assert_eq!(check.observe(1, &entry(11)), Some(true)); // a repeat: counted once
        assert_eq!(check.observe(0, &entry(10)), Some(true));
        let s = check.stats();
        assert_eq!(
            (s.reported, s.byte_exact, s.mismatched, s.unreported),
            (3, 1, 1, 1)
        );
        assert_eq!((s.first_mismatch, s.lost()), (Some(1), 2));
        let empty = ServedSample {
            crc32c: 0,
            underrun: false,
            empty: true,
        };
        assert_eq!(check.observe(2, &empty), Some(false));
        assert_eq!(check.stats().underruns, 1);
    }
}
