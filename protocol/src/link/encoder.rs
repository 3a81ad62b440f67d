//! The sending side: message → frame → COBS → wire bytes, with the sender's sequence numbers.
//!
//! On the wire every frame is `0x00, COBS(frame), 0x00`. The leading delimiter closes off any
//! partial frame or garbage at the receiver, so the frame that follows is always recovered; a
//! receiver skips the empty frame between two consecutive delimiters. The worst-case wire size
//! of a frame of `n` bytes is [`max_wire_len`]`(n) = n + ⌈n/254⌉ + 2`.
//!
//! ```
//! use margemu_protocol::link::{Encoder, Message, MAX_WIRE_LEN};
//! let mut enc = Encoder::new();
//! let mut wire = [0u8; MAX_WIRE_LEN];
//! let n = enc.encode(&Message::Stop, &mut wire)?;
//! // 0x00 | COBS of [version 1, kind 0x04, seq 0, 0, len 0, 0, CRC (4)] | 0x00
//! assert_eq!(&wire[..4], &[0x00, 0x03, 0x01, 0x04]);
//! assert_eq!((n, wire[n - 1], enc.next_seq()), (13, 0x00, 1));
//! # Ok::<(), margemu_protocol::link::Error>(())
//! ```

use super::frame::emit_frame;
use super::{Error, Message, MAX_FRAME_LEN};

/// The worst-case wire length of a frame of `frame_len` bytes: COBS adds one byte per started
/// 254 bytes (at least one), plus the leading and trailing 0x00.
pub const fn max_wire_len(frame_len: usize) -> usize {
    cobs::max_encoding_length(frame_len) + 2
}

/// COBS-encodes `frame` into `out` as `0x00, COBS(frame), 0x00`; returns the bytes written.
pub fn stuff(frame: &[u8], out: &mut [u8]) -> Result<usize, Error> {
    let (first, rest) = out.split_first_mut().ok_or(Error::BufferTooSmall)?;
    *first = 0;
    let n = cobs::try_encode(frame, rest).map_err(|_| Error::BufferTooSmall)?;
    *rest.get_mut(n).ok_or(Error::BufferTooSmall)? = 0;
    Ok(n + 2)
}

/// Encodes messages for one direction of the link, numbering its frames 0, 1, 2, … (wrapping).
#[derive(Clone, Debug)]
pub struct Encoder {
    seq: u16,
    frame: [u8; MAX_FRAME_LEN],
}

impl Default for Encoder {
    fn default() -> Self {
        Self::new()
    }
}

impl Encoder {
    /// An encoder whose first frame has sequence number 0 (about 1.5 KB of scratch).
    pub const fn new() -> Self {
        Self {
            seq: 0,
            frame: [0; MAX_FRAME_LEN],
        }
    }

    /// The sequence number of the next frame.
    pub fn next_seq(&self) -> u16 {
        self.seq
    }

    /// Sets the sequence number of the next frame.
    pub fn set_next_seq(&mut self, seq: u16) {
        self.seq = seq;
    }

    /// Writes the wire bytes of `message` to the front of `out` (at most
    /// [`MAX_WIRE_LEN`](super::MAX_WIRE_LEN)); returns their length. The sequence number
    /// advances only on success.
    pub fn encode(&mut self, message: &Message<'_>, out: &mut [u8]) -> Result<usize, Error> {
        let n = emit_frame(self.seq, message, &mut self.frame)?;
        let written = stuff(self.frame.get(..n).unwrap_or(&[]), out)?;
        self.seq = self.seq.wrapping_add(1);
        Ok(written)
    }
}
