//! The link's one flat error enum.
//!
//! Every fallible function of [`crate::link`] returns [`Error`]; nothing in the link panics. The
//! stream accumulator reports damaged frames as [`FeedResult`](super::FeedResult) values, and
//! [`FeedResult::error`](super::FeedResult::error) maps each onto the variant here, so host and
//! firmware count them the same way.
//!
//! ```
//! use margemu_protocol::link::{Error, Frame};
//! assert_eq!(Frame::new_checked(&[1u8, 2, 3][..]).unwrap_err(), Error::FrameTruncated);
//! assert_eq!(Error::FrameBadCrc.to_string(), "frame CRC mismatch");
//! ```

use core::fmt;

/// What went wrong on the link.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum Error {
    /// The COBS encoding of a frame was invalid (a code byte points past the frame's end).
    FrameBadCobs,
    /// The encoded frame exceeded the accumulator's buffer; it was dropped up to the next 0x00.
    FrameOverFull,
    /// The frame is shorter than its header and CRC, or than its length field announces.
    FrameTruncated,
    /// The CRC-32C over header and payload does not match the frame's last four bytes.
    FrameBadCrc,
    /// The CRC matched but the length field disagrees with the frame's size (a sender bug).
    FrameBadLength,
    /// The CRC matched but the frame format version is not [`FRAME_VERSION`](super::FRAME_VERSION).
    FrameBadVersion,
    /// The message kind byte is not one this version knows.
    UnknownKind,
    /// The payload ended before the message did.
    PayloadTooShort,
    /// The payload has bytes after the message's end (or a batch a partial item).
    PayloadTooLong,
    /// A field holds a value outside its documented set (enum code, reserved bit, zero rate).
    InvalidValue,
    /// A [`Configure`](super::Configure) names a chip code this version does not know (its
    /// first payload byte).
    UnknownChip,
    /// A message would not fit in [`MAX_PAYLOAD_LEN`](super::MAX_PAYLOAD_LEN) bytes.
    MessageTooLarge,
    /// The output buffer given to an emit or encode call is too small.
    BufferTooSmall,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::FrameBadCobs => "invalid COBS encoding",
            Self::FrameOverFull => "frame longer than the receive buffer",
            Self::FrameTruncated => "frame truncated",
            Self::FrameBadCrc => "frame CRC mismatch",
            Self::FrameBadLength => "frame length field disagrees with its size",
            Self::FrameBadVersion => "unsupported frame version",
            Self::UnknownKind => "unknown message kind",
            Self::PayloadTooShort => "message payload too short",
            Self::PayloadTooLong => "message payload too long",
            Self::InvalidValue => "field value out of range",
            Self::UnknownChip => "unknown chip model code",
            Self::MessageTooLarge => "message larger than the maximum payload",
            Self::BufferTooSmall => "output buffer too small",
        })
    }
}

impl core::error::Error for Error {}

impl Error {
    /// Whether this is damage the accumulator saw at the framing level (COBS, size, CRC,
    /// version), as opposed to a well-framed message that did not parse.
    pub fn is_framing(&self) -> bool {
        matches!(
            self,
            Self::FrameBadCobs
                | Self::FrameOverFull
                | Self::FrameTruncated
                | Self::FrameBadCrc
                | Self::FrameBadLength
                | Self::FrameBadVersion
        )
    }
}
