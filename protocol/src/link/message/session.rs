//! Session messages: the handshake ([`Hello`], [`HelloAck`]), [`Start`], [`Reset`] and
//! [`ErrorReport`], with the capability sets the device advertises.
//!
//! ```
//! use margemu_protocol::chip::ChipModel;
//! use margemu_protocol::link::{Capabilities, Chips, Modes};
//! let chips = Chips::of(ChipModel::Mpu9250) | Chips::of(ChipModel::Icm42688p);
//! let caps = Capabilities { chips, ..Capabilities::default() };
//! assert!(caps.chips.has(ChipModel::Icm42688p) && !caps.chips.has(ChipModel::Mpu6000));
//! assert!(!caps.modes.contains(Modes::MODEL));
//! ```

use crate::chip::ChipModel;
use crate::link::wire::{Reader, Writer};
use crate::link::Error;

/// Length of the device identifier in [`HelloAck`] (an MCU unique ID, zero-padded).
pub const DEVICE_ID_LEN: usize = 16;

/// The chip models a device can emulate: bit `n` is the [`ChipModel`] of code `n`; unknown bits
/// are kept (a newer peer may set them).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Chips(pub u32);

impl Chips {
    /// No chip.
    pub const EMPTY: Self = Self(0);

    /// The set of one model.
    pub const fn of(model: ChipModel) -> Self {
        Self(1 << model.code())
    }

    /// Whether every model of `other` is in `self`.
    pub fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }

    /// Whether `model` is in the set.
    pub fn has(self, model: ChipModel) -> bool {
        self.contains(Self::of(model))
    }

    /// The known models in the set, in code order.
    pub fn models(self) -> impl Iterator<Item = ChipModel> {
        ChipModel::ALL.into_iter().filter(move |m| self.has(*m))
    }
}

impl core::ops::BitOr for Chips {
    type Output = Self;
    fn bitor(self, rhs: Self) -> Self {
        Self(self.0 | rhs.0)
    }
}

flags! {
    /// The sample sources a device supports (see [`Source`](super::Source)).
    pub struct Modes {
        /// (a) finished register images from the host.
        const IMAGES = 0;
        /// (b) true kinematics from the host and the sensor model on the device.
        const MODEL = 1;
    }
}

flags! {
    /// The buses on which the device serves the emulated chip.
    pub struct Buses {
        /// SPI target.
        const SPI = 0;
        /// I2C target.
        const I2C = 1;
    }
}

/// What a device can do, sent in [`HelloAck`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Capabilities {
    /// Emulated chip models.
    pub chips: Chips,
    /// Sample sources.
    pub modes: Modes,
    /// Buses.
    pub buses: Buses,
    /// The most samples the device accepts in one batch message.
    pub max_batch: u16,
    /// The device's sample buffer, in samples of the configured source.
    pub buffer_capacity: u32,
}

/// A firmware version, semantic.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FirmwareVersion {
    /// Major.
    pub major: u8,
    /// Minor.
    pub minor: u8,
    /// Patch.
    pub patch: u8,
}

/// Host → device: opens (or reopens) a session. The device answers [`HelloAck`] and returns to
/// the idle state, dropping any configuration and buffered samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Hello {
    /// The host's [`PROTOCOL_VERSION`](crate::PROTOCOL_VERSION).
    pub protocol_version: u16,
    /// A host-chosen session number, echoed in [`HelloAck`].
    pub session: u32,
}

impl Hello {
    /// Payload length.
    pub const LEN: usize = 6;

    pub(crate) fn parse(r: &mut Reader<'_>) -> Result<Self, Error> {
        Ok(Self {
            protocol_version: r.u16()?,
            session: r.u32()?,
        })
    }

    pub(crate) fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        w.u16(self.protocol_version)?;
        w.u32(self.session)
    }
}

/// Device → host: answers [`Hello`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HelloAck {
    /// The device's [`PROTOCOL_VERSION`](crate::PROTOCOL_VERSION); the host stops on mismatch.
    pub protocol_version: u16,
    /// The session number of the [`Hello`] answered.
    pub session: u32,
    /// Firmware version.
    pub firmware: FirmwareVersion,
    /// Device identifier (MCU unique ID, zero-padded).
    pub device_id: [u8; DEVICE_ID_LEN],
    /// What the device can do.
    pub capabilities: Capabilities,
}

impl HelloAck {
    /// Payload length.
    pub const LEN: usize = 2 + 4 + 3 + DEVICE_ID_LEN + 4 + 2 + 2 + 4;

    pub(crate) fn parse(r: &mut Reader<'_>) -> Result<Self, Error> {
        Ok(Self {
            protocol_version: r.u16()?,
            session: r.u32()?,
            firmware: FirmwareVersion {
                major: r.u8()?,
                minor: r.u8()?,
                patch: r.u8()?,
            },
            device_id: r.array()?,
            capabilities: Capabilities {
                chips: Chips(r.u32()?),
                modes: Modes(r.u8()?),
                buses: Buses(r.u8()?),
                max_batch: r.u16()?,
                buffer_capacity: r.u32()?,
            },
        })
    }

    pub(crate) fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        w.u16(self.protocol_version)?;
        w.u32(self.session)?;
        w.bytes(&[
            self.firmware.major,
            self.firmware.minor,
            self.firmware.patch,
        ])?;
        w.bytes(&self.device_id)?;
        let c = &self.capabilities;
        w.u32(c.chips.0)?;
        w.bytes(&[c.modes.0, c.buses.0])?;
        w.u16(c.max_batch)?;
        w.u32(c.buffer_capacity)
    }
}

/// Host → device: start serving. The device sets its scene clock to `t0_ns` now and serves
/// sample `i` at scene time [`Rate::sample_time_ns`](super::Rate::sample_time_ns)`(i)` for every
/// `i < end_index`; at the instant of sample `end_index` it stops by itself, serving nothing for
/// it, so a scene's end never depends on when Stop arrives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Start {
    /// Scene time at the instant the device receives this message, ns.
    pub t0_ns: u64,
    /// The first output sample index not to serve (the scene's sample count);
    /// [`Start::UNBOUNDED`] serves until Stop.
    pub end_index: u64,
}

impl Default for Start {
    /// Scene time 0, serving until Stop.
    fn default() -> Self {
        Self::until_stop(0)
    }
}

impl Start {
    /// Payload length.
    pub const LEN: usize = 16;

    /// `end_index` of a session that runs until Stop.
    pub const UNBOUNDED: u64 = u64::MAX;

    /// Starts at scene time `t0_ns` and serves until Stop.
    pub const fn until_stop(t0_ns: u64) -> Self {
        Self {
            t0_ns,
            end_index: Self::UNBOUNDED,
        }
    }

    /// Starts at scene time `t0_ns` and serves samples `0..samples` (those at or after `t0_ns`).
    pub const fn scene(t0_ns: u64, samples: u64) -> Self {
        Self {
            t0_ns,
            end_index: samples,
        }
    }

    pub(crate) fn parse(r: &mut Reader<'_>) -> Result<Self, Error> {
        Ok(Self {
            t0_ns: r.u64()?,
            end_index: r.u64()?,
        })
    }

    pub(crate) fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        w.u64(self.t0_ns)?;
        w.u64(self.end_index)
    }
}

code_enum! {
    /// Why the device (re)booted.
    pub enum ResetCause {
        /// Not known.
        Unknown = 0,
        /// Power-on.
        PowerOn = 1,
        /// Software request.
        Software = 2,
        /// Watchdog.
        Watchdog = 3,
        /// Reset pin.
        Pin = 4,
        /// Brown-out.
        Brownout = 5,
    }
}

/// Device → host: sent once after boot, so the host detects a device reset mid-session.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Reset {
    /// Why it booted.
    pub cause: ResetCause,
}

impl Reset {
    /// Payload length.
    pub const LEN: usize = 1;

    pub(crate) fn parse(r: &mut Reader<'_>) -> Result<Self, Error> {
        Ok(Self {
            cause: ResetCause::read(r)?,
        })
    }

    pub(crate) fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        w.u8(self.cause as u8)
    }
}

code_enum! {
    /// What the device refused.
    pub enum ErrorCode {
        /// [`Hello`] with a protocol version the device does not speak.
        UnsupportedVersion = 1,
        /// A frame of a kind the device does not know (or that travels the other way).
        UnknownMessage = 2,
        /// A well-framed message whose payload did not parse.
        MalformedMessage = 3,
        /// [`Configure`](super::Configure) names a chip the device cannot emulate.
        UnsupportedChip = 4,
        /// [`Configure`](super::Configure) asks for a source the device does not support
        /// (`detail` 1: a perturbation), or an [`AddVibration`](super::AddVibration) came in
        /// source (a) (`detail` 2).
        UnsupportedMode = 5,
        /// The configuration was refused (the model rejected a term; `detail` may say which: 2
        /// while running, 7 an [`AddVibration`](super::AddVibration) the device cannot hold).
        InvalidConfig = 6,
        /// [`Start`] or samples before a valid [`Configure`](super::Configure).
        NotConfigured = 7,
        /// Samples beyond the credit limit (they were dropped and counted as overruns).
        CreditExceeded = 8,
        /// Anything else.
        Internal = 9,
        /// [`AddDevice`](super::AddDevice) refused: the rig is full, its address or chip
        /// select is another device's, the source is the on-device model, or the rig's image
        /// would be too long (`detail`: 1 full, 2 I2C address taken, 3 chip select taken, 4
        /// model source, 5 image over [`MAX_IMAGE_LEN`](crate::chip::MAX_IMAGE_LEN)).
        RigRefused = 10,
        /// [`AddFault`](super::AddFault) refused (`detail`: 1 the schedule is full, 2 it
        /// overlaps a fault it may not overlap, 3 no such device in the rig, 4 the device's chip
        /// cannot apply this chip fault; `docs/spec/link.md` §5.16).
        FaultRefused = 11,
    }
}

/// Device → host: a refusal, tied to the frame that caused it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ErrorReport {
    /// What was refused.
    pub code: ErrorCode,
    /// Sequence number of the host frame that caused it.
    pub seq: u16,
    /// Code-specific detail (e.g. the offending kind byte or sample index, truncated).
    pub detail: u32,
}

impl ErrorReport {
    /// Payload length.
    pub const LEN: usize = 7;

    pub(crate) fn parse(r: &mut Reader<'_>) -> Result<Self, Error> {
        Ok(Self {
            code: ErrorCode::read(r)?,
            seq: r.u16()?,
            detail: r.u32()?,
        })
    }

    pub(crate) fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        w.u8(self.code as u8)?;
        w.u16(self.seq)?;
        w.u32(self.detail)
    }
}
