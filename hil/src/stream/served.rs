//! What the device reports it served, checked against the host's prediction.
//!
//! The device reports every sample instant it serves (`docs/spec/link.md` §5.13): the index, the
//! CRC-32C of the 22-byte image it latched into the chip, and whether the instant was an
//! underrun (the previous image held) or empty (nothing latched yet). [`ServedCheck`] compares
//! each entry with the CRC-32C of the image the host predicted for that index and keeps the
//! counts a session reports ([`ServedStats`]). An index reported twice counts once.
//!
//! The check keeps a bounded window of predictions ([`served_window`] samples: what a device can
//! still report given its credit window), so its memory does not depend on the scene's length. An
//! entry it cannot check (an index older than the window, or an image not predicted yet, which
//! a device that follows `docs/spec/link.md` never reports) is counted as **unverifiable**, not
//! dropped.
//!
//! ```
//! use margemu_hil::stream::ServedCheck;
//! use margemu_protocol::link::{ServedSample, CRC32C};
//! let predicted = [[1u8; 22], [2u8; 22]];
//! let mut check = ServedCheck::new(2, 16);
//! for (k, image) in predicted.iter().enumerate() {
//!     check.expect(k as u64, CRC32C.checksum(image));
//! }
//! let served = |im: &[u8; 22], underrun| ServedSample { crc32c: CRC32C.checksum(im), underrun, empty: false };
//! assert_eq!(check.observe(0, &served(&predicted[0], false)), Some(true));
//! assert_eq!(check.observe(1, &served(&predicted[0], true)), Some(false)); // held: an underrun
//! assert_eq!(check.observe(2, &served(&predicted[1], true)), None); // after the scene's end
//! let stats = check.stats();
//! assert_eq!((stats.byte_exact, stats.underruns, stats.after_end, stats.lost()), (1, 1, 1, 1));
//! ```

use super::window::Window;
use margemu_protocol::link::{ServedSample, MAX_SERVED_PER_BATCH};

/// Most predictions a check (or a session's window of items) keeps, whatever the device
/// announces: about 32 MB of 32-byte images at most.
pub const MAX_WINDOW: usize = 1 << 20;

/// How many output samples behind the newest prediction a device can still report serving,
/// when it holds at most `buffer_capacity` items of `hold` output samples each (1 in source
/// images) and reports what it served in order, at most one Served frame behind
/// (`docs/spec/link.md` §5.13, §7).
///
/// The host predicts an item when it writes it, and writes only below the newest credit limit
/// `L = s + buffer_capacity`, where `s` is the oldest item the device holds or serves next: so
/// it has predicted at most `(s + buffer_capacity) · hold` output samples. The device has served
/// everything before `s · hold`, and reports it in order with at most one frame of entries
/// ([`MAX_SERVED_PER_BATCH`]) waiting; a report therefore starts no earlier than
/// `s · hold − MAX_SERVED_PER_BATCH`, which is within `buffer_capacity · hold +
/// MAX_SERVED_PER_BATCH` of the newest prediction. One more hold covers the item being written.
/// Capped at [`MAX_WINDOW`].
pub fn served_window(buffer_capacity: u32, hold: u32) -> usize {
    let items = u64::from(buffer_capacity) + 1;
    let span = items * u64::from(hold.max(1)) + MAX_SERVED_PER_BATCH as u64;
    span.min(MAX_WINDOW as u64) as usize
}

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
    /// Scene indices never reported (a lost Served frame, or a session that ended early), or
    /// reported only in unverifiable entries.
    pub unreported: u64,
    /// Entries that could not be checked: for an index older than the window of predictions
    /// the check keeps ([`served_window`]), or, not as an underrun, for a sample not predicted
    /// yet. A device that follows the link spec sends none.
    pub unverifiable: u64,
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

/// Whether the check keeps the prediction of a sample, and whether it was reported.
#[derive(Clone, Copy, Debug, Default)]
struct Slot {
    /// The CRC-32C of the predicted image, once predicted.
    expected: Option<u32>,
    /// An entry for the index was counted.
    seen: bool,
}

/// The running comparison of Served entries with the prediction (see the module docs).
#[derive(Clone, Debug)]
pub struct ServedCheck {
    window: Window<Slot>,
    stats: ServedStats,
}

impl ServedCheck {
    /// A check of a scene of `samples` samples that keeps `span` predictions
    /// ([`served_window`]); the predictions come in order through [`ServedCheck::expect`].
    pub fn new(samples: u64, span: usize) -> Self {
        Self {
            window: Window::new(span),
            stats: ServedStats {
                samples,
                unreported: samples,
                ..ServedStats::default()
            },
        }
    }

    /// The CRC-32C of the image predicted for sample `index` (in order; an index the window
    /// has already moved past is ignored).
    pub fn expect(&mut self, index: u64, crc32c: u32) {
        if index < self.window.start() || index >= self.stats.samples {
            return;
        }
        self.extend_to(index);
        if let Some(slot) = self.window.get_mut(index) {
            slot.expected = Some(crc32c);
        }
    }

    /// Makes the window reach `index` (at or after its start), forgetting the oldest.
    fn extend_to(&mut self, index: u64) {
        if index >= self.window.end() + self.window.span() as u64 {
            self.window
                .forget_below(index + 1 - self.window.span() as u64);
        }
        while self.window.end() <= index {
            self.window.push(Slot::default());
        }
    }

    /// Records the entry of `index`; returns whether its image is the predicted one (`None`
    /// after the scene's end, and for an unverifiable entry).
    pub fn observe(&mut self, index: u64, entry: &ServedSample) -> Option<bool> {
        let s = &mut self.stats;
        s.reported += 1;
        s.last_index = s.last_index.max(Some(index));
        if index >= s.samples {
            s.after_end += 1;
            return None;
        }
        if index < self.window.start() {
            s.unverifiable += 1;
            return None;
        }
        self.extend_to(index);
        let slot = self.window.get_mut(index).expect("extended to it");
        let matches = slot.expected.map(|e| !entry.empty && entry.crc32c == e);
        if std::mem::replace(&mut slot.seen, true) {
            return matches;
        }
        let s = &mut self.stats;
        if entry.underrun || entry.empty {
            s.unreported -= 1;
            s.underruns += 1;
        } else {
            match matches {
                None => s.unverifiable += 1,
                Some(true) => {
                    s.unreported -= 1;
                    s.byte_exact += 1;
                }
                Some(false) => {
                    s.unreported -= 1;
                    s.mismatched += 1;
                    s.first_mismatch.get_or_insert(index);
                }
            }
        }
        matches
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
        let mut check = ServedCheck::new(3, 8);
        (0..3).for_each(|k| check.expect(k, 10 + k as u32));
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

    #[test]
    fn a_report_older_than_the_window_is_unverifiable() {
        let ok = |crc32c| ServedSample {
            crc32c,
            underrun: false,
            empty: false,
        };
        let mut check = ServedCheck::new(100, 4);
        (0..10).for_each(|k| check.expect(k, k as u32));
        // Predictions 6..10 are kept; 5 is older than the window.
        assert_eq!(check.observe(5, &ok(5)), None);
        assert_eq!(check.observe(6, &ok(6)), Some(true));
        // Not predicted yet, and not an underrun: nothing to check it against.
        assert_eq!(check.observe(10, &ok(10)), None);
        // An underrun needs no prediction; it moves the window on.
        let held = ServedSample {
            underrun: true,
            ..ok(10)
        };
        assert_eq!(check.observe(20, &held), None);
        check.expect(11, 11); // the window has moved past 11: ignored
        assert_eq!(check.observe(11, &ok(11)), None);
        let s = check.stats();
        assert_eq!(
            (s.reported, s.byte_exact, s.underruns, s.unverifiable),
            (5, 1, 1, 3)
        );
        assert_eq!((s.unreported, s.lost()), (98, 99));
    }

    #[test]
    fn the_window_covers_the_credit_window_and_a_served_frame() {
        assert_eq!(served_window(4096, 1), 4097 + 302);
        assert_eq!(served_window(128, 4), 129 * 4 + 302);
        assert_eq!(served_window(u32::MAX, 8), MAX_WINDOW);
    }
}
