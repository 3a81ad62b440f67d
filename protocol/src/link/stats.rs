//! Receive-side bookkeeping shared by host and firmware, so both count the same way: lost frames
//! from sequence numbers ([`SeqTracker`]) and damaged frames by class ([`RxStats`]).
//!
//! # Sequence rule
//! Each sender numbers its frames 0, 1, 2, … from boot (device) or from opening the port (host),
//! wrapping at 2¹⁶. A receiver expects `previous + 1`; a frame with `seq = expected + k` means `k`
//! frames were lost (damaged frames are lost frames too). A repeat of the previous number is a
//! duplicate. After [`Hello`](super::Hello) or [`Reset`](super::Reset) the receiver restarts
//! (`SeqTracker::restart`): the next number is accepted as is.
//!
//! ```
//! use margemu_protocol::link::{RxStats, SeqEvent, SeqTracker};
//! let mut seq = SeqTracker::new();
//! assert_eq!(seq.observe(65534), SeqEvent::First);
//! assert_eq!(seq.observe(65535), SeqEvent::InOrder);
//! assert_eq!(seq.observe(2), SeqEvent::Gap(2)); // 0 and 1 lost
//! let mut stats = RxStats::default();
//! stats.record_seq(SeqEvent::Gap(2));
//! assert_eq!(stats.lost_frames, 2);
//! ```

use super::{Error, FeedResult};

/// What a sequence number says about the frames before it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SeqEvent {
    /// The first frame since (re)start.
    First,
    /// The expected number.
    InOrder,
    /// This many frames were lost before this one.
    Gap(u16),
    /// The same number as the previous frame.
    Duplicate,
}

/// Follows one sender's sequence numbers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SeqTracker {
    last: Option<u16>,
}

impl SeqTracker {
    /// A tracker that accepts any first number.
    pub const fn new() -> Self {
        Self { last: None }
    }

    /// Forgets the previous number (after a session restart or a device reset).
    pub fn restart(&mut self) {
        self.last = None;
    }

    /// Records `seq` and classifies it.
    pub fn observe(&mut self, seq: u16) -> SeqEvent {
        let event = match self.last {
            None => SeqEvent::First,
            Some(last) if seq == last => SeqEvent::Duplicate,
            Some(last) => match seq.wrapping_sub(last.wrapping_add(1)) {
                0 => SeqEvent::InOrder,
                k => SeqEvent::Gap(k),
            },
        };
        self.last = Some(seq);
        event
    }
}

/// Counters of what a receiver saw, in the classes [`Telemetry`](super::Telemetry) reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RxStats {
    /// Intact frames.
    pub frames: u32,
    /// CRC mismatches.
    pub crc_errors: u32,
    /// Other damaged frames (COBS, oversize, truncated, bad length or version).
    pub framing_errors: u32,
    /// Frames missing by sequence number.
    pub lost_frames: u32,
    /// Intact frames whose message did not parse (or was refused by the application).
    pub rejected_messages: u32,
}

impl RxStats {
    /// Counts one accumulator outcome (`Consumed` counts nothing).
    pub fn record(&mut self, result: &FeedResult<'_, '_>) {
        match result {
            FeedResult::Consumed => {}
            FeedResult::Success { .. } => self.frames = self.frames.wrapping_add(1),
            other => self.record_error(other.error().unwrap_or(Error::FrameTruncated)),
        }
    }

    /// Counts a damaged frame or a rejected message by its error.
    pub fn record_error(&mut self, error: Error) {
        let counter = match error {
            Error::FrameBadCrc => &mut self.crc_errors,
            e if e.is_framing() => &mut self.framing_errors,
            _ => &mut self.rejected_messages,
        };
        *counter = counter.wrapping_add(1);
    }

    /// Counts the frames a sequence gap says were lost.
    pub fn record_seq(&mut self, event: SeqEvent) {
        if let SeqEvent::Gap(k) = event {
            self.lost_frames = self.lost_frames.wrapping_add(u32::from(k));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sequence_numbers_wrap_and_restart() {
        let mut t = SeqTracker::new();
        assert_eq!(t.observe(0xFFFF), SeqEvent::First);
        assert_eq!(t.observe(0), SeqEvent::InOrder);
        assert_eq!(t.observe(0), SeqEvent::Duplicate);
        assert_eq!(t.observe(0xFFFF), SeqEvent::Gap(0xFFFE));
        t.restart();
        assert_eq!(t.observe(17), SeqEvent::First);
    }

    #[test]
    fn errors_land_in_their_class() {
        let mut s = RxStats::default();
        s.record(&FeedResult::BadCrc(&[]));
        s.record(&FeedResult::OverFull(&[]));
        s.record(&FeedResult::Consumed);
        s.record_error(Error::UnknownKind);
        s.record_seq(SeqEvent::Gap(3));
        s.record_seq(SeqEvent::Duplicate);
        let expected = RxStats {
            frames: 0,
            crc_errors: 1,
            framing_errors: 1,
            lost_frames: 3,
            rejected_messages: 1,
        };
        assert_eq!(s, expected);
    }
}
