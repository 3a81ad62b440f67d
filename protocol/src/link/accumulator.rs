//! The stream accumulator: bytes in, in any chunking, frame outcomes out, as values.
//!
//! Host serial RX and firmware UART RX feed the same [`Accumulator`]. It buffers COBS bytes up
//! to a 0x00 delimiter, decodes them in place, verifies the frame
//! ([`Frame::new_verified`]) and returns one [`FeedResult`] per delimited frame, together with
//! the input it has not looked at yet: call [`Accumulator::feed`] again with `remaining` until
//! it returns [`FeedResult::Consumed`]. Empty frames (consecutive 0x00) are skipped silently,
//! which is why senders start every frame with a 0x00: whatever garbage came before is closed
//! off as one damaged frame, and the next good frame is always recovered. An encoded frame longer
//! than [`MAX_ENCODED_LEN`] is dropped up to the next 0x00 and reported there as
//! [`FeedResult::OverFull`]. Nothing here panics, on any input.
//!
//! ```
//! use margemu_protocol::link::{Accumulator, Encoder, FeedResult, FrameRepr, Message, Start};
//! let mut enc = Encoder::new();
//! let mut wire = [0u8; 64];
//! let n = enc.encode(&Message::Start(Start::until_stop(5)), &mut wire)?;
//! let mut acc = Accumulator::new();
//! let mut got = None;
//! for byte in wire[..n].chunks(1) {                // one byte at a time, as a UART would
//!     let mut input = byte;
//!     while !input.is_empty() {
//!         match acc.feed(input) {
//!             FeedResult::Consumed => break,
//!             FeedResult::Success { frame, remaining } => {
//!                 // The message borrows the accumulator: handle it before feeding more.
//!                 if let Message::Start(start) = FrameRepr::parse(&frame)?.message {
//!                     got = Some(start);
//!                 }
//!                 input = remaining;
//!             }
//!             damaged => input = damaged.remaining(), // count `damaged.error()`
//!         }
//!     }
//! }
//! assert_eq!(got, Some(Start::until_stop(5)));
//! # Ok::<(), margemu_protocol::link::Error>(())
//! ```

use super::{Error, Frame, MAX_ENCODED_LEN};

/// The outcome of [`Accumulator::feed`]: one per delimited frame, or `Consumed`.
#[derive(Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FeedResult<'a, 'b> {
    /// Every input byte was taken and no frame ended.
    Consumed,
    /// A frame arrived intact (CRC, length and version checked).
    Success {
        /// The decoded frame, borrowed from the accumulator.
        frame: Frame<&'a [u8]>,
        /// Input after the frame's delimiter.
        remaining: &'b [u8],
    },
    /// The encoded frame did not fit the buffer; it was dropped up to this delimiter.
    OverFull(&'b [u8]),
    /// Invalid COBS: a code byte points past the frame's end.
    BadCobs(&'b [u8]),
    /// Shorter than a header and CRC, or than its length field announces.
    Truncated(&'b [u8]),
    /// CRC mismatch.
    BadCrc(&'b [u8]),
    /// Intact CRC but a length field that disagrees with the frame's size.
    BadLength(&'b [u8]),
    /// Intact CRC but an unknown frame version.
    BadVersion(&'b [u8]),
}

impl<'b> FeedResult<'_, 'b> {
    /// The input not looked at yet (empty for `Consumed`).
    pub fn remaining(&self) -> &'b [u8] {
        match *self {
            Self::Consumed => &[],
            Self::Success { remaining, .. } => remaining,
            Self::OverFull(r)
            | Self::BadCobs(r)
            | Self::Truncated(r)
            | Self::BadCrc(r)
            | Self::BadLength(r)
            | Self::BadVersion(r) => r,
        }
    }

    /// The damage, as the crate's error (`None` for `Consumed` and `Success`).
    pub fn error(&self) -> Option<Error> {
        Some(match self {
            Self::Consumed | Self::Success { .. } => return None,
            Self::OverFull(_) => Error::FrameOverFull,
            Self::BadCobs(_) => Error::FrameBadCobs,
            Self::Truncated(_) => Error::FrameTruncated,
            Self::BadCrc(_) => Error::FrameBadCrc,
            Self::BadLength(_) => Error::FrameBadLength,
            Self::BadVersion(_) => Error::FrameBadVersion,
        })
    }

    fn damaged(error: Error, remaining: &'b [u8]) -> Self {
        match error {
            Error::FrameBadCobs => Self::BadCobs(remaining),
            Error::FrameBadCrc => Self::BadCrc(remaining),
            Error::FrameBadLength => Self::BadLength(remaining),
            Error::FrameBadVersion => Self::BadVersion(remaining),
            Error::FrameOverFull => Self::OverFull(remaining),
            _ => Self::Truncated(remaining),
        }
    }
}

/// Reassembles frames from a byte stream (see the module docs).
#[derive(Clone, Debug)]
pub struct Accumulator {
    buf: [u8; MAX_ENCODED_LEN],
    len: usize,
    overfull: bool,
}

impl Default for Accumulator {
    fn default() -> Self {
        Self::new()
    }
}

impl Accumulator {
    /// An empty accumulator (about 1.5 KB).
    pub const fn new() -> Self {
        Self {
            buf: [0; MAX_ENCODED_LEN],
            len: 0,
            overfull: false,
        }
    }

    /// Drops any partial frame (e.g. after reopening a port).
    pub fn reset(&mut self) {
        self.len = 0;
        self.overfull = false;
    }

    /// The bytes of the current partial frame.
    pub fn pending(&self) -> usize {
        self.len
    }

    /// Appends to the partial frame, or switches to dropping when it would not fit.
    fn extend(&mut self, bytes: &[u8]) {
        if self.overfull {
            return;
        }
        let end = self.len + bytes.len();
        match self.buf.get_mut(self.len..end) {
            Some(dst) => {
                dst.copy_from_slice(bytes);
                self.len = end;
            }
            None => self.overfull = true,
        }
    }

    /// Takes `input` up to and including the next frame's delimiter and returns that frame's
    /// outcome with the rest of the input, or [`FeedResult::Consumed`] if no frame ended.
    pub fn feed<'a, 'b>(&'a mut self, mut input: &'b [u8]) -> FeedResult<'a, 'b> {
        loop {
            let Some(end) = input.iter().position(|&b| b == 0) else {
                self.extend(input);
                return FeedResult::Consumed;
            };
            let (body, rest) = (&input[..end], &input[end + 1..]);
            self.extend(body);
            if self.overfull {
                self.reset();
                return FeedResult::OverFull(rest);
            }
            if self.len == 0 {
                input = rest;
                continue;
            }
            let len = core::mem::take(&mut self.len);
            return self.decode(len, rest);
        }
    }

    fn decode<'a, 'b>(&'a mut self, len: usize, rest: &'b [u8]) -> FeedResult<'a, 'b> {
        let Some(encoded) = self.buf.get_mut(..len) else {
            return FeedResult::OverFull(rest);
        };
        let decoded = match cobs::decode_in_place(encoded) {
            Ok(n) => n,
            Err(_) => return FeedResult::BadCobs(rest),
        };
        let bytes = self.buf.get(..decoded).unwrap_or(&[]);
        match Frame::new_verified(bytes) {
            Ok(frame) => FeedResult::Success {
                frame,
                remaining: rest,
            },
            Err(e) => FeedResult::damaged(e, rest),
        }
    }
}

// With `defmt`, the outcomes (frame view included) must really be loggable.
#[cfg(feature = "defmt")]
const _: fn() = || {
    fn is_format<T: defmt::Format>() {}
    is_format::<FeedResult<'static, 'static>>();
    is_format::<Error>();
};

#[cfg(test)]
mod tests {
    use super::*;

    // `Message::Stop`, seq 0: 0x00, COBS(01 04 00 00 00 00 23 A9 5F 58), 0x00.
    const STOP: [u8; 13] = [
        0x00, 0x03, 0x01, 0x04, 0x01, 0x01, 0x01, 0x05, 0x23, 0xA9, 0x5F, 0x58, 0x00,
    ];

    #[test]
    fn byte_at_a_time() {
        let mut acc = Accumulator::new();
        for (i, b) in STOP.iter().enumerate() {
            let r = acc.feed(core::slice::from_ref(b));
            if i < STOP.len() - 1 {
                assert_eq!(r, FeedResult::Consumed, "byte {i}");
            } else {
                let FeedResult::Success { frame, remaining } = r else {
                    panic!("{r:?}")
                };
                assert_eq!((frame.kind(), frame.seq(), remaining.len()), (0x04, 0, 0));
            }
        }
    }

    #[test]
    fn empty_frames_are_skipped_and_remaining_is_returned() {
        let mut stream = [0u8; 3 + 2 * STOP.len()];
        stream[3..16].copy_from_slice(&STOP);
        stream[16..].copy_from_slice(&STOP);
        let mut acc = Accumulator::new();
        let r = acc.feed(&stream);
        assert!(matches!(r, FeedResult::Success { .. }));
        assert_eq!(r.remaining(), &STOP[..]);
        assert_eq!(r.error(), None);
        // The second frame's leading 0x00 closes an empty frame: skipped.
        let r = acc.feed(&STOP);
        assert_eq!(r.remaining(), &[] as &[u8]);
        assert_eq!(acc.feed(&[0, 0, 0]), FeedResult::Consumed);
    }

    #[test]
    fn damage_is_one_outcome_per_delimited_frame() {
        let mut acc = Accumulator::new();
        assert_eq!(
            acc.feed(&[0x00, 0x05, 0x01, 0x00]),
            FeedResult::BadCobs(&[])
        );
        assert_eq!(
            acc.feed(&[0x02, 0x01, 0x00, 0x07]),
            FeedResult::Truncated(&[0x07])
        );
        assert_eq!(acc.pending(), 0);
        assert_eq!(acc.feed(&[0x07; 10]), FeedResult::Consumed);
        assert_eq!(acc.pending(), 10);
        acc.reset();
        assert_eq!(acc.pending(), 0);
        let mut crc = STOP;
        crc[10] ^= 0x80;
        assert_eq!(acc.feed(&crc).error(), Some(Error::FrameBadCrc));
        for _ in 0..MAX_ENCODED_LEN / 100 + 1 {
            assert_eq!(acc.feed(&[0x33; 100]), FeedResult::Consumed);
        }
        assert_eq!(acc.feed(&[0x00, 0x09]), FeedResult::OverFull(&[0x09]));
    }
}
