//! One link frame before COBS: a 6-byte header, the payload, and a CRC-32C.
//!
//! ```text
//! offset  size  field
//! 0       1     version   FRAME_VERSION (1)
//! 1       1     kind      message kind (see `Kind`)
//! 2       2     seq       sequence number, u16 little-endian, per sender, wrapping
//! 4       2     len       payload length in bytes, u16 little-endian, ≤ MAX_PAYLOAD_LEN
//! 6       len   payload   the message (see `message`)
//! 6+len   4     crc       CRC-32C (iSCSI) of bytes 0 .. 6+len, u32 little-endian
//! ```
//!
//! Two levels, as smoltcp's wire types: [`Frame`] is a view over a buffer with field accessors
//! (which never panic, even on a short buffer: out-of-range fields read as zero or empty), and
//! [`FrameRepr`] is the parsed high-level frame with `parse`/`emit`/`buffer_len`.
//!
//! ```
//! use margemu_protocol::link::{Frame, FrameRepr, Message, Start};
//! let repr = FrameRepr { seq: 7, message: Message::Start(Start::until_stop(0)) };
//! let mut buf = [0u8; 32];
//! let n = repr.emit(&mut buf)?;
//! assert_eq!(n, repr.buffer_len());
//! let frame = Frame::new_verified(&buf[..n])?;
//! assert_eq!((frame.seq(), frame.kind(), frame.payload_len()), (7, 0x03, 16));
//! assert_eq!(FrameRepr::parse(&frame)?, repr);
//! # Ok::<(), margemu_protocol::link::Error>(())
//! ```

use super::message::Message;
use super::{Error, FRAME_VERSION, MAX_PAYLOAD_LEN};

/// The CRC of every frame: CRC-32/ISCSI (Castagnoli), poly 0x1EDC6F41, init and xorout
/// 0xFFFFFFFF, reflected in and out; check value of `b"123456789"` is 0xE3069283.
pub static CRC32C: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISCSI);

/// Byte ranges of the header fields.
mod field {
    use core::ops::Range;
    pub const VERSION: usize = 0;
    pub const KIND: usize = 1;
    pub const SEQ: Range<usize> = 2..4;
    pub const LEN: Range<usize> = 4..6;
    pub const PAYLOAD: usize = 6;
}

/// Length of the frame header (version, kind, seq, len).
pub const HEADER_LEN: usize = field::PAYLOAD;
/// Length of the trailing CRC.
pub const CRC_LEN: usize = 4;

/// A view of a frame (header, payload, CRC) over a byte buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Frame<T: AsRef<[u8]>> {
    buffer: T,
}

impl<T: AsRef<[u8]>> Frame<T> {
    /// Wraps `buffer` without any check.
    pub const fn new_unchecked(buffer: T) -> Self {
        Self { buffer }
    }

    /// Wraps `buffer` after [`check_len`](Self::check_len).
    pub fn new_checked(buffer: T) -> Result<Self, Error> {
        let frame = Self::new_unchecked(buffer);
        frame.check_len()?;
        Ok(frame)
    }

    /// Wraps a received frame after checking, in this order: that it holds a header and a CRC
    /// ([`Error::FrameTruncated`]); the CRC ([`Error::FrameBadCrc`], or
    /// [`Error::FrameTruncated`] if the length field announces more bytes than there are);
    /// then the length field and the [`MAX_PAYLOAD_LEN`] limit ([`Error::FrameBadLength`]);
    /// and the version ([`Error::FrameBadVersion`]).
    pub fn new_verified(buffer: T) -> Result<Self, Error> {
        let frame = Self::new_unchecked(buffer);
        let len = frame.buffer.as_ref().len();
        if len < HEADER_LEN + CRC_LEN {
            return Err(Error::FrameTruncated);
        }
        let announced = HEADER_LEN + usize::from(frame.payload_len()) + CRC_LEN;
        let (body, crc) = frame.buffer.as_ref().split_at(len - CRC_LEN);
        if CRC32C.checksum(body).to_le_bytes() != crc {
            return Err(if announced > len {
                Error::FrameTruncated
            } else {
                Error::FrameBadCrc
            });
        }
        if announced != len || usize::from(frame.payload_len()) > MAX_PAYLOAD_LEN {
            return Err(Error::FrameBadLength);
        }
        if frame.version() != FRAME_VERSION {
            return Err(Error::FrameBadVersion);
        }
        Ok(frame)
    }

    /// Checks that the buffer holds exactly a header, the payload its length field announces
    /// (at most [`MAX_PAYLOAD_LEN`]), and a CRC. After this, [`payload`](Self::payload) and
    /// [`crc`](Self::crc) are the real fields.
    pub fn check_len(&self) -> Result<(), Error> {
        let len = self.buffer.as_ref().len();
        if len < HEADER_LEN + CRC_LEN {
            return Err(Error::FrameTruncated);
        }
        let announced = HEADER_LEN + usize::from(self.payload_len()) + CRC_LEN;
        match announced.cmp(&len) {
            core::cmp::Ordering::Greater => Err(Error::FrameTruncated),
            core::cmp::Ordering::Less => Err(Error::FrameBadLength),
            core::cmp::Ordering::Equal if len > crate::link::MAX_FRAME_LEN => {
                Err(Error::FrameBadLength)
            }
            core::cmp::Ordering::Equal => Ok(()),
        }
    }

    /// The underlying buffer.
    pub fn into_inner(self) -> T {
        self.buffer
    }

    fn byte(&self, i: usize) -> u8 {
        self.buffer.as_ref().get(i).copied().unwrap_or(0)
    }

    fn u16_at(&self, at: core::ops::Range<usize>) -> u16 {
        let b = self.buffer.as_ref().get(at).unwrap_or(&[0, 0]);
        u16::from_le_bytes([b[0], b[1]])
    }

    /// The frame format version.
    pub fn version(&self) -> u8 {
        self.byte(field::VERSION)
    }

    /// The message kind byte.
    pub fn kind(&self) -> u8 {
        self.byte(field::KIND)
    }

    /// The sequence number.
    pub fn seq(&self) -> u16 {
        self.u16_at(field::SEQ)
    }

    /// The payload length field.
    pub fn payload_len(&self) -> u16 {
        self.u16_at(field::LEN)
    }

    fn payload_range(&self) -> core::ops::Range<usize> {
        field::PAYLOAD..field::PAYLOAD + usize::from(self.payload_len())
    }

    /// The payload (empty if the buffer is shorter than announced).
    pub fn payload(&self) -> &[u8] {
        self.buffer
            .as_ref()
            .get(self.payload_range())
            .unwrap_or(&[])
    }

    /// The CRC field that follows the payload (0 if the buffer is too short).
    pub fn crc(&self) -> u32 {
        let at = self.payload_range().end;
        match self.buffer.as_ref().get(at..at + CRC_LEN) {
            Some(b) => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            None => 0,
        }
    }

    /// The CRC-32C of the header and payload, as [`crc`](Self::crc) should read.
    pub fn compute_crc(&self) -> u32 {
        let end = self.payload_range().end;
        CRC32C.checksum(self.buffer.as_ref().get(..end).unwrap_or(&[]))
    }

    /// Whether the CRC field matches the header and payload.
    pub fn check_crc(&self) -> bool {
        self.check_len().is_ok() && self.crc() == self.compute_crc()
    }
}

impl<T: AsRef<[u8]> + AsMut<[u8]>> Frame<T> {
    fn set_byte(&mut self, i: usize, v: u8) {
        if let Some(b) = self.buffer.as_mut().get_mut(i) {
            *b = v;
        }
    }

    fn set_u16(&mut self, at: core::ops::Range<usize>, v: u16) {
        if let Some(b) = self.buffer.as_mut().get_mut(at) {
            b.copy_from_slice(&v.to_le_bytes());
        }
    }

    /// Sets the version byte.
    pub fn set_version(&mut self, v: u8) {
        self.set_byte(field::VERSION, v);
    }

    /// Sets the kind byte.
    pub fn set_kind(&mut self, v: u8) {
        self.set_byte(field::KIND, v);
    }

    /// Sets the sequence number.
    pub fn set_seq(&mut self, v: u16) {
        self.set_u16(field::SEQ, v);
    }

    /// Sets the payload length field.
    pub fn set_payload_len(&mut self, v: u16) {
        self.set_u16(field::LEN, v);
    }

    /// The payload, mutable (empty if the buffer is shorter than announced).
    pub fn payload_mut(&mut self) -> &mut [u8] {
        let range = self.payload_range();
        self.buffer.as_mut().get_mut(range).unwrap_or(&mut [])
    }

    /// Computes the CRC of header and payload and writes it after the payload (no-op if the
    /// buffer is too short).
    pub fn fill_crc(&mut self) {
        let crc = self.compute_crc();
        let at = self.payload_range().end;
        if let Some(b) = self.buffer.as_mut().get_mut(at..at + CRC_LEN) {
            b.copy_from_slice(&crc.to_le_bytes());
        }
    }
}

/// A parsed frame: its sequence number and message.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameRepr<'a> {
    /// The sender's sequence number.
    pub seq: u16,
    /// The message.
    pub message: Message<'a>,
}

impl<'a> FrameRepr<'a> {
    /// Parses the message of a frame (checked with [`Frame::new_verified`] or
    /// [`Frame::new_checked`]; the version is checked again here, the CRC is not).
    pub fn parse<T: AsRef<[u8]> + ?Sized>(frame: &Frame<&'a T>) -> Result<Self, Error> {
        frame.check_len()?;
        if frame.version() != FRAME_VERSION {
            return Err(Error::FrameBadVersion);
        }
        let payload = frame.buffer.as_ref();
        let payload = payload.get(frame.payload_range()).unwrap_or(&[]);
        Ok(Self {
            seq: frame.seq(),
            message: Message::parse(frame.kind(), payload)?,
        })
    }

    /// The length of the emitted frame: header, payload and CRC.
    pub fn buffer_len(&self) -> usize {
        HEADER_LEN + self.message.buffer_len() + CRC_LEN
    }

    /// Writes the frame (header, payload, CRC) to the front of `buf`; returns its length.
    pub fn emit(&self, buf: &mut [u8]) -> Result<usize, Error> {
        emit_frame(self.seq, &self.message, buf)
    }
}

/// Writes the frame of `message` with sequence number `seq` (header, payload, CRC) to the front
/// of `buf`; returns its length. The same as [`FrameRepr::emit`], without moving the message.
pub fn emit_frame(seq: u16, message: &Message<'_>, buf: &mut [u8]) -> Result<usize, Error> {
    let payload_len = message.buffer_len();
    if payload_len > MAX_PAYLOAD_LEN {
        return Err(Error::MessageTooLarge);
    }
    let len = HEADER_LEN + payload_len + CRC_LEN;
    let buf = buf.get_mut(..len).ok_or(Error::BufferTooSmall)?;
    let mut frame = Frame::new_unchecked(buf);
    frame.set_version(FRAME_VERSION);
    frame.set_kind(message.kind() as u8);
    frame.set_seq(seq);
    // `payload_len <= MAX_PAYLOAD_LEN < u16::MAX`.
    frame.set_payload_len(payload_len as u16);
    message.emit(frame.payload_mut())?;
    frame.fill_crc();
    Ok(len)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::{Credit, Start};

    // Start { t0_ns: 0x0102030405060708, end_index: 0x1112131415161718 }, seq 0x1234.
    static START: [u8; 26] = [
        0x01, 0x03, 0x34, 0x12, 0x10, 0x00, // header
        0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01, // t0_ns
        0x18, 0x17, 0x16, 0x15, 0x14, 0x13, 0x12, 0x11, // end_index
        0x87, 0xB5, 0x0D, 0xF8, // CRC-32C
    ];
    const START_MESSAGE: Start = Start {
        t0_ns: 0x0102_0304_0506_0708,
        end_index: 0x1112_1314_1516_1718,
    };

    #[test]
    fn crc_check_value() {
        assert_eq!(CRC32C.checksum(b"123456789"), 0xE306_9283);
    }

    #[test]
    fn deconstruct() {
        let frame = Frame::new_verified(&START[..]).unwrap();
        assert_eq!(frame.version(), 1);
        assert_eq!(frame.kind(), 0x03);
        assert_eq!(frame.seq(), 0x1234);
        assert_eq!(frame.payload_len(), 16);
        assert_eq!(frame.payload(), &START[6..22]);
        assert_eq!(frame.crc(), 0xF80D_B587);
        let repr = FrameRepr::parse(&frame).unwrap();
        assert_eq!(repr.message, Message::Start(START_MESSAGE));
    }

    #[test]
    fn construct() {
        let repr = FrameRepr {
            seq: 0x1234,
            message: Message::Start(START_MESSAGE),
        };
        let mut buf = [0xAAu8; 26];
        assert_eq!(repr.emit(&mut buf), Ok(26));
        assert_eq!(buf, START);
        assert_eq!(repr.emit(&mut buf[..25]), Err(Error::BufferTooSmall));
    }

    #[test]
    fn verification_order() {
        let mut bad = START;
        bad[8] ^= 0x10;
        assert_eq!(Frame::new_verified(&bad[..]), Err(Error::FrameBadCrc));
        assert_eq!(
            Frame::new_verified(&START[..25]),
            Err(Error::FrameTruncated)
        );
        assert_eq!(Frame::new_verified(&START[..9]), Err(Error::FrameTruncated));
        // A valid CRC over a frame whose length field lies.
        let mut long = [0u8; 19];
        long[..6].copy_from_slice(&START[..6]);
        long[4] = 7;
        Frame::new_unchecked(&mut long[..]).fill_crc();
        let crc = CRC32C.checksum(&long[..15]).to_le_bytes();
        long[15..].copy_from_slice(&crc);
        assert_eq!(Frame::new_verified(&long[..]), Err(Error::FrameBadLength));
        let mut v2 = START;
        v2[0] = 2;
        Frame::new_unchecked(&mut v2[..]).fill_crc();
        assert_eq!(Frame::new_verified(&v2[..]), Err(Error::FrameBadVersion));
    }

    #[test]
    fn accessors_never_panic_on_short_buffers() {
        for n in 0..START.len() {
            let f = Frame::new_unchecked(&START[..n]);
            let _ = (f.version(), f.kind(), f.seq(), f.payload(), f.crc());
            let _ = (f.compute_crc(), f.check_crc(), f.check_len());
            let mut buf = START;
            let mut f = Frame::new_unchecked(&mut buf[..n]);
            f.set_seq(1);
            f.set_payload_len(0xFFFF);
            f.payload_mut();
            f.fill_crc();
        }
    }

    #[test]
    fn oversized_message_is_refused() {
        use crate::link::{max_images_per_batch, Image, ImageBatch, MAX_FRAME_LEN};
        // At most 1526 payload bytes: the 9-byte header and 47 images of 32 bytes (1513).
        let images = [Image::from([0u8; 32]); 48];
        assert_eq!(max_images_per_batch(32), 47);
        let mut buf = [0u8; MAX_FRAME_LEN + 32];
        let too_many = FrameRepr {
            seq: 0,
            message: Message::Images(ImageBatch::new(0, &images)),
        };
        assert_eq!(too_many.emit(&mut buf), Err(Error::MessageTooLarge));
        let most = FrameRepr {
            seq: 0,
            message: Message::Images(ImageBatch::new(0, &images[1..])),
        };
        assert_eq!(most.emit(&mut buf), Ok(MAX_FRAME_LEN - 13));
        assert_eq!(
            Frame::new_verified(&buf[..MAX_FRAME_LEN - 13]).map(|f| f.payload_len()),
            Ok(1513)
        );
        let credit = FrameRepr {
            seq: 0,
            message: Message::Credit(Credit::default()),
        };
        assert_eq!(credit.emit(&mut buf), Ok(HEADER_LEN + 16 + CRC_LEN));
    }
}
