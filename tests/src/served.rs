//! What the device reports it served (`Served` frames, `docs/spec/link.md` §5.13), collected
//! and checked against the host's prediction, byte for byte through the CRC-32C of each image.
//!
//! ```
//! use margemu_protocol::link::{ServedBatch, ServedSample, CRC32C};
//! use margemu_tests::served::ServedLog;
//! let images = [[1u8; 22], [2u8; 22]];
//! let predicted: Vec<u32> = images.iter().map(|i| CRC32C.checksum(i)).collect();
//! let entry = |crc32c| ServedSample { crc32c, underrun: false, empty: false };
//! let mut log = ServedLog::default();
//! log.record(&ServedBatch::new(0, 0, &[entry(predicted[0]), entry(predicted[0])]));
//! let check = log.check(&predicted);
//! assert_eq!((check.exact, check.mismatched.as_slice()), (1, &[1u64][..]));
//! ```

use std::collections::BTreeMap;
use std::io::{self, Read};
use std::sync::{Arc, Mutex, PoisonError};

use margemu_protocol::link::{Message, ServedBatch, ServedSample};

use crate::qemu::LinkDecoder;

/// Every Served entry seen, by output sample index.
#[derive(Clone, Debug, Default)]
pub struct ServedLog {
    entries: BTreeMap<u64, ServedSample>,
    /// Each batch's first index and the scene time it carries (a sample a timing fault moved is
    /// a batch of its own, at its latch time).
    pub batch_times: BTreeMap<u64, u64>,
    /// Entries for an index already reported (the device reports each instant once).
    pub duplicates: u64,
}

impl ServedLog {
    /// Adds the entries of one Served frame.
    pub fn record(&mut self, batch: &ServedBatch<'_>) {
        self.batch_times
            .insert(batch.first_index, batch.first_time_ns);
        for (index, s) in (batch.first_index..).zip(batch.samples.iter()) {
            if self.entries.insert(index, s).is_some() {
                self.duplicates += 1;
            }
        }
    }

    /// Entries collected.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether nothing was collected.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The entry of output sample `index`.
    pub fn get(&self, index: u64) -> Option<ServedSample> {
        self.entries.get(&index).copied()
    }

    /// Compares samples `0..predicted.len()` with the CRC-32C of the predicted images.
    pub fn check(&self, predicted: &[u32]) -> Check {
        let mut check = Check {
            expected: predicted.len(),
            ..Check::default()
        };
        for (index, &crc) in (0u64..).zip(predicted) {
            match self.get(index) {
                None => check.missing.push(index),
                Some(s) if s.underrun || s.empty => check.underruns.push(index),
                Some(s) if s.crc32c != crc => check.mismatched.push(index),
                Some(_) => check.exact += 1,
            }
        }
        check
    }
}

/// A reader that decodes, on the side, the Served frames in what passes through it: wrap the
/// device → host half of a port handed to a host that ignores them (`margemu::stream::Session`).
pub struct ServedTap<R> {
    inner: R,
    decoder: LinkDecoder,
    log: Arc<Mutex<(ServedLog, u64)>>,
}

impl<R: Read> ServedTap<R> {
    /// Wraps `inner`.
    pub fn new(inner: R) -> Self {
        Self {
            inner,
            decoder: LinkDecoder::default(),
            log: Arc::default(),
        }
    }

    /// A handle on what has been decoded so far: the Served log and the damaged frames.
    pub fn log(&self) -> Arc<Mutex<(ServedLog, u64)>> {
        Arc::clone(&self.log)
    }
}

impl<R: Read> Read for ServedTap<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        let mut guard = self.log.lock().unwrap_or_else(PoisonError::into_inner);
        let (log, damaged) = &mut *guard;
        self.decoder.feed(&buf[..n], &mut |m: &Message<'_>| {
            if let Message::Served(batch) = m {
                log.record(batch);
            }
        });
        *damaged = self.decoder.damaged;
        Ok(n)
    }
}

/// The outcome of [`ServedLog::check`]. Indices are output sample indices, ascending.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Check {
    /// Samples predicted.
    pub expected: usize,
    /// Served with exactly the predicted image.
    pub exact: usize,
    /// Never reported (a lost Served frame, or not served yet).
    pub missing: Vec<u64>,
    /// Reported as an underrun (the sample was not there in time) or as empty.
    pub underruns: Vec<u64>,
    /// Served, but not the predicted image.
    pub mismatched: Vec<u64>,
}

impl Check {
    /// Whether every predicted sample was served exactly.
    pub fn all_exact(&self) -> bool {
        self.exact == self.expected
    }

    /// One line: the counts and the first few indices of each failure.
    pub fn summary(&self) -> String {
        let first = |v: &[u64]| format!("{} {}", v.len(), ranges(v));
        format!(
            "{} of {} byte-exact; missing {}; underrun {}; mismatched {}",
            self.exact,
            self.expected,
            first(&self.missing),
            first(&self.underruns),
            first(&self.mismatched)
        )
    }
}

/// `[a..=b, c..=d]` for ascending indices, at most eight ranges shown.
fn ranges(v: &[u64]) -> String {
    let mut out: Vec<(u64, u64)> = Vec::new();
    for &i in v {
        match out.last_mut() {
            Some((_, end)) if *end + 1 == i => *end = i,
            _ => out.push((i, i)),
        }
    }
    let shown: Vec<String> = out
        .iter()
        .take(8)
        .map(|(a, b)| format!("{a}..={b}"))
        .collect();
    let more = if out.len() > 8 { ", …" } else { "" };
    format!("[{}{more}]", shown.join(", "))
}

/// The scene time each output sample `0 .. n` at `rate` is latched at under `faults`, by the
/// firmware's own serving clock (`margemu_firmware::link::faults::FaultClock`), as the device
/// runs it: what a Served batch starting at that sample carries.
pub fn predicted_latches(
    faults: &[margemu_protocol::link::AddFault],
    rate: margemu_protocol::link::Rate,
    n: u64,
) -> Vec<u64> {
    use margemu_firmware::fault::FaultSchedule;
    use margemu_firmware::link::faults::FaultClock;
    let mut schedule = FaultSchedule::new();
    for f in faults {
        schedule
            .push(f.fault, f.seed)
            .expect("a schedule the device takes");
    }
    let mut clock = FaultClock::new();
    (0..n)
        .map(|k| {
            let t = rate.sample_time_ns(k);
            let latch = clock.latch_ns(&schedule, k, t);
            clock.latch(&schedule, latch, t, |_| None);
            latch
        })
        .collect()
}
