//! Device → host status: the flow-control window ([`Credit`]) and the counters ([`Telemetry`]).
//!
//! # Credit rule
//! Credits are absolute, not increments, so a lost [`Credit`] frame loses nothing: the next one
//! (or the next [`Telemetry`]) carries the whole window again. The host may send a sample of
//! index `i` only if `i < limit` of the most recent window it received; a sample at or beyond it
//! is an overrun (dropped and counted by the device). The device computes
//! `limit = oldest index still buffered or to be served + buffer capacity`.
//!
//! ```
//! use margemu_protocol::link::Credit;
//! let window = Credit { next_index: 100, limit: 164 };
//! assert_eq!(window.available(90), 74); // the host already sent up to 89
//! assert_eq!(window.available(200), 0);
//! ```

use crate::link::wire::{Reader, Writer};
use crate::link::Error;

/// Device → host: the window of sample indices the host may send.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Credit {
    /// The device has received every sample below this index (contiguously); a host that sent
    /// more has lost frames and may resend from here.
    pub next_index: u64,
    /// The host may send samples with index `< limit`.
    pub limit: u64,
}

impl Credit {
    /// Payload length.
    pub const LEN: usize = 16;

    /// How many samples the host may send now, if its next unsent index is `next_to_send`.
    pub fn available(&self, next_to_send: u64) -> u64 {
        self.limit.saturating_sub(next_to_send)
    }

    pub(crate) fn parse(r: &mut Reader<'_>) -> Result<Self, Error> {
        Ok(Self {
            next_index: r.u64()?,
            limit: r.u64()?,
        })
    }

    pub(crate) fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        w.u64(self.next_index)?;
        w.u64(self.limit)
    }
}

code_enum! {
    /// The device's session state.
    pub enum DeviceState {
        /// No valid configuration (after boot or [`Hello`](super::Hello)).
        Idle = 0,
        /// Configured, buffering, not serving.
        Configured = 1,
        /// Serving samples on the scene clock.
        Running = 2,
        /// Stopped by [`Stop`](super::Message::Stop); the last sample is held.
        Stopped = 3,
    }
}

/// Length of the [`Telemetry`] payload.
pub const TELEMETRY_LEN: usize = 8 + 1 + 8 + 7 * 4 + 4 * 8;

/// Device → host: the device's counters, sent periodically and after [`Stop`](super::Message::Stop).
/// Every counter is cumulative since the last [`Hello`](super::Hello) (or boot) and wraps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Telemetry {
    /// Device scene time when this was sent, ns.
    pub time_ns: u64,
    /// Session state.
    pub state: DeviceState,
    /// Samples served (sample instants passed while running).
    pub samples_served: u64,
    /// Sample instants at which the sample was missing (host late; last sample held).
    pub underruns: u32,
    /// Samples received beyond the credit limit (host early; dropped).
    pub overruns: u32,
    /// Frames with a CRC mismatch.
    pub crc_errors: u32,
    /// Other damaged frames: COBS, oversize, truncated, bad length or version.
    pub framing_errors: u32,
    /// Frames missing according to the host's sequence numbers.
    pub lost_frames: u32,
    /// Well-framed messages the device could not parse or refused.
    pub rejected_messages: u32,
    /// Samples buffered now.
    pub buffer_level: u32,
    /// As [`Credit::next_index`].
    pub next_index: u64,
    /// As [`Credit::limit`].
    pub credit_limit: u64,
    /// Index of the last sample served (meaningless while `samples_served` is 0).
    pub last_served_index: u64,
    /// Scene time at which it was served, ns.
    pub last_served_time_ns: u64,
}

impl Telemetry {
    /// The credit window carried in this telemetry.
    pub fn credit(&self) -> Credit {
        Credit {
            next_index: self.next_index,
            limit: self.credit_limit,
        }
    }

    pub(crate) fn parse(r: &mut Reader<'_>) -> Result<Self, Error> {
        Ok(Self {
            time_ns: r.u64()?,
            state: DeviceState::read(r)?,
            samples_served: r.u64()?,
            underruns: r.u32()?,
            overruns: r.u32()?,
            crc_errors: r.u32()?,
            framing_errors: r.u32()?,
            lost_frames: r.u32()?,
            rejected_messages: r.u32()?,
            buffer_level: r.u32()?,
            next_index: r.u64()?,
            credit_limit: r.u64()?,
            last_served_index: r.u64()?,
            last_served_time_ns: r.u64()?,
        })
    }

    pub(crate) fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        w.u64(self.time_ns)?;
        w.u8(self.state as u8)?;
        w.u64(self.samples_served)?;
        for v in [
            self.underruns,
            self.overruns,
            self.crc_errors,
            self.framing_errors,
            self.lost_frames,
            self.rejected_messages,
            self.buffer_level,
        ] {
            w.u32(v)?;
        }
        for v in [
            self.next_index,
            self.credit_limit,
            self.last_served_index,
            self.last_served_time_ns,
        ] {
            w.u64(v)?;
        }
        Ok(())
    }
}
