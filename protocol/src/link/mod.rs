//! The host ↔ firmware link: frames, messages and the stream accumulator (every byte is in
//! `docs/spec/link.md`).
//!
//! Layers, bottom up, each usable on its own:
//! 1. **wire**: `0x00, COBS(frame), 0x00` ([`Encoder`], [`stuff`]) and back ([`Accumulator`],
//!    which returns one [`FeedResult`] per delimited frame and resynchronises at every 0x00);
//! 2. **frame**: a 6-byte header (version, kind, sequence number, payload length), the payload
//!    and a CRC-32C ([`Frame`], [`FrameRepr`]);
//! 3. **message**: the payload of each kind ([`Message`]): handshake, configuration, start/stop,
//!    sample batches, credits, telemetry, register writes, reset and error notices.
//!
//! Everything is `no_std`, allocation-free and panic-free on any input; the buffers are fixed
//! by [`MAX_FRAME_LEN`]. Times are integer nanoseconds (`u64`), sample indices `u64`.
//!
//! ```
//! use margemu_protocol::link::{
//!     Accumulator, Encoder, FeedResult, FrameRepr, Image, ImageBatch, Message, MAX_WIRE_LEN,
//! };
//! // Host: a batch of 32 MPU-9250 register images (22 bytes each), starting at sample 640.
//! let images = [Image::from([0x5Au8; 22]); 32];
//! let mut host = Encoder::new();
//! let mut wire = [0u8; MAX_WIRE_LEN];
//! let n = host.encode(&Message::Images(ImageBatch::new(640, &images)), &mut wire)?;
//! assert_eq!(n, 728); // 704 image bytes: 96.7 % of the wire bytes
//! // Device: whatever chunks the UART delivers.
//! let mut rx = Accumulator::new();
//! let (first, second) = wire[..n].split_at(300);
//! assert_eq!(rx.feed(first), FeedResult::Consumed);
//! let FeedResult::Success { frame, remaining } = rx.feed(second) else { panic!() };
//! assert!(remaining.is_empty());
//! let repr = FrameRepr::parse(&frame)?;
//! assert_eq!(repr.seq, 0);
//! let Message::Images(batch) = repr.message else { panic!() };
//! assert_eq!((batch.first_index, batch.images.len()), (640, 32));
//! # Ok::<(), margemu_protocol::link::Error>(())
//! ```

mod accumulator;
mod encoder;
mod error;
mod frame;
mod message;
mod stats;
pub mod wire;

pub use accumulator::{Accumulator, FeedResult};
pub use encoder::{max_wire_len, stuff, Encoder};
pub use error::Error;
pub use frame::{emit_frame, Frame, FrameRepr, CRC32C, CRC_LEN, HEADER_LEN};
pub use message::*;
pub use stats::{RxStats, SeqEvent, SeqTracker};

/// Version of the frame format (header layout, CRC, COBS), byte 0 of every frame.
pub const FRAME_VERSION: u8 = 1;

/// Largest frame before COBS: header, payload and CRC.
pub const MAX_FRAME_LEN: usize = 1536;

/// Largest payload of one frame.
pub const MAX_PAYLOAD_LEN: usize = MAX_FRAME_LEN - HEADER_LEN - CRC_LEN;

/// Largest COBS-encoded frame, without delimiters: the [`Accumulator`]'s buffer.
pub const MAX_ENCODED_LEN: usize = cobs::max_encoding_length(MAX_FRAME_LEN);

/// Largest frame on the wire, with its two delimiters: the size of an output buffer that fits
/// every message.
pub const MAX_WIRE_LEN: usize = max_wire_len(MAX_FRAME_LEN);

/// Worst-case wire bytes of an [`ImageBatch`] of `n` images of `image_len` bytes (COBS worst
/// case, both delimiters).
pub const fn image_batch_wire_len(n: usize, image_len: usize) -> usize {
    max_wire_len(HEADER_LEN + IMAGE_BATCH_HEADER_LEN + n * image_len + CRC_LEN)
}

/// Link efficiency of an [`ImageBatch`] of `n` images of `image_len` bytes in the worst case:
/// image bytes per wire byte (not counting UART start and stop bits).
pub fn image_batch_efficiency(n: usize, image_len: usize) -> f64 {
    (n * image_len) as f64 / image_batch_wire_len(n, image_len) as f64
}
