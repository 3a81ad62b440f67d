//! The messages carried in frames, host → device and device → host.
//!
//! Every message is a plain value type (its "repr"), parsed from and emitted to a frame's
//! payload; all integers are little-endian, floats IEEE 754 bit for bit, and each layout is in
//! `docs/spec/link.md`. Kinds with bit 7 clear travel host → device, with bit 7 set device → host.
//!
//! | kind | message | direction |
//! |------|---------|-----------|
//! | 0x01 | [`Hello`] | host → device |
//! | 0x02 | [`Configure`] | host → device |
//! | 0x03 | [`Start`] | host → device |
//! | 0x04 | [`Message::Stop`] | host → device |
//! | 0x05 | [`AddDevice`] | host → device |
//! | 0x06 | [`AddVibration`] | host → device |
//! | 0x07 | [`AddFault`] | host → device |
//! | 0x10 | [`ImageBatch`] | host → device |
//! | 0x11 | [`KinematicsBatch`] | host → device |
//! | 0x81 | [`HelloAck`] | device → host |
//! | 0x82 | [`Credit`] | device → host |
//! | 0x83 | [`Telemetry`] | device → host |
//! | 0x84 | [`RegisterWriteBatch`] | device → host |
//! | 0x85 | [`Reset`] | device → host |
//! | 0x86 | [`ErrorReport`] | device → host |
//! | 0x87 | [`ServedBatch`] | device → host |
//!
//! ```
//! use margemu_protocol::link::{Image, ImageBatch, Kind, Message};
//! let images = [Image::from([0x11u8; 22]); 2];
//! let msg = Message::Images(ImageBatch::new(1000, &images));
//! assert_eq!((msg.kind(), msg.buffer_len()), (Kind::Images, 9 + 2 * 22));
//! let mut payload = [0u8; 64];
//! let n = msg.emit(&mut payload)?;
//! let back = Message::parse(Kind::Images as u8, &payload[..n])?;
//! assert_eq!(back, msg);
//! # Ok::<(), margemu_protocol::link::Error>(())
//! ```

#[macro_use]
mod macros;
mod batch;
mod configure;
mod device;
mod fault;
mod images;
mod model_terms;
mod session;
mod status;
mod vibration;

pub use batch::{
    Bus, Items, KinematicsBatch, RegisterWrite, RegisterWriteBatch, ServedBatch, ServedSample,
    WireItem, MAX_KINEMATICS_PER_BATCH, MAX_REGISTER_WRITES_PER_BATCH, MAX_SERVED_PER_BATCH,
    TRUTH_LEN,
};
pub use configure::{Configure, ModelParams, Rate, RegisterOverride, Source};
pub use configure::{MAX_CONFIGURE_LEN, MAX_OVERRIDES};
pub use device::{AddDevice, DeviceBus, MAX_DEVICES, MAX_DEVICE_OVERRIDES};
pub use fault::{kind_code as fault_kind_code, AddFault};
pub use images::{
    max_images_per_batch, Image, ImageBatch, ImageItems, IMAGE_BATCH_HEADER_LEN, MAX_IMAGE_LEN,
};
pub use model_terms::{MAX_MARG_CONFIG_LEN, MAX_PERTURBATION_LEN};
pub use session::{
    Buses, Capabilities, Chips, ErrorCode, ErrorReport, FirmwareVersion, Hello, HelloAck, Modes,
    Reset, ResetCause, Start, DEVICE_ID_LEN,
};
pub use status::{Credit, DeviceState, Telemetry, TELEMETRY_LEN};
pub use vibration::{AddVibration, RpmProfile, MAX_RPM_POINTS};

use super::wire::{Reader, Writer};
use super::{Error, MAX_PAYLOAD_LEN};

code_enum! {
    /// The kind byte of a frame: which message its payload holds.
    pub enum Kind {
        /// [`Hello`].
        Hello = 0x01,
        /// [`Configure`].
        Configure = 0x02,
        /// [`Start`].
        Start = 0x03,
        /// [`Message::Stop`].
        Stop = 0x04,
        /// [`AddDevice`].
        AddDevice = 0x05,
        /// [`AddVibration`].
        AddVibration = 0x06,
        /// [`AddFault`].
        AddFault = 0x07,
        /// [`ImageBatch`].
        Images = 0x10,
        /// [`KinematicsBatch`].
        Kinematics = 0x11,
        /// [`HelloAck`].
        HelloAck = 0x81,
        /// [`Credit`].
        Credit = 0x82,
        /// [`Telemetry`].
        Telemetry = 0x83,
        /// [`RegisterWriteBatch`].
        RegisterWrites = 0x84,
        /// [`Reset`].
        Reset = 0x85,
        /// [`ErrorReport`].
        Error = 0x86,
        /// [`ServedBatch`].
        Served = 0x87,
    }
}

impl Kind {
    /// Whether the host sends this kind (bit 7 clear).
    pub fn is_host_to_device(self) -> bool {
        (self as u8) & 0x80 == 0
    }
}

/// Any message of the link.
///
/// The value is about 1.7 KB because [`Configure`] carries the whole sensor model; the batches
/// borrow their items from the frame (or from the caller's slice when emitting).
#[derive(Clone, Debug, PartialEq)]
#[allow(clippy::large_enum_variant)] // no alloc: `Configure` is held by value, once per session
pub enum Message<'a> {
    /// Host: opens a session.
    Hello(Hello),
    /// Host: chip, rate and sample source.
    Configure(Configure),
    /// Host: start serving samples.
    Start(Start),
    /// Host: stop serving samples (empty payload).
    Stop,
    /// Host: one more chip of a rig.
    AddDevice(AddDevice),
    /// Host: one piece of the source-(b) sampling chain.
    AddVibration(AddVibration),
    /// Host: one scripted fault of the schedule.
    AddFault(AddFault),
    /// Host: finished register images.
    Images(ImageBatch<'a>),
    /// Host: true kinematics for the on-device model.
    Kinematics(KinematicsBatch<'a>),
    /// Device: answers [`Hello`].
    HelloAck(HelloAck),
    /// Device: flow-control window.
    Credit(Credit),
    /// Device: counters and state.
    Telemetry(Telemetry),
    /// Device: register writes made by the device under test.
    RegisterWrites(RegisterWriteBatch<'a>),
    /// Device: it (re)booted.
    Reset(Reset),
    /// Device: it refused something.
    Error(ErrorReport),
    /// Device: what it served at each sample instant.
    Served(ServedBatch<'a>),
}

impl<'a> Message<'a> {
    /// The message's kind.
    pub fn kind(&self) -> Kind {
        match self {
            Self::Hello(_) => Kind::Hello,
            Self::Configure(_) => Kind::Configure,
            Self::Start(_) => Kind::Start,
            Self::Stop => Kind::Stop,
            Self::AddDevice(_) => Kind::AddDevice,
            Self::AddVibration(_) => Kind::AddVibration,
            Self::AddFault(_) => Kind::AddFault,
            Self::Images(_) => Kind::Images,
            Self::Kinematics(_) => Kind::Kinematics,
            Self::HelloAck(_) => Kind::HelloAck,
            Self::Credit(_) => Kind::Credit,
            Self::Telemetry(_) => Kind::Telemetry,
            Self::RegisterWrites(_) => Kind::RegisterWrites,
            Self::Reset(_) => Kind::Reset,
            Self::Error(_) => Kind::Error,
            Self::Served(_) => Kind::Served,
        }
    }

    /// Parses the payload of a frame of kind byte `kind`. Every byte is accounted for: a payload
    /// with bytes left over is [`Error::PayloadTooLong`], one longer than
    /// [`MAX_PAYLOAD_LEN`] is [`Error::MessageTooLarge`].
    pub fn parse(kind: u8, payload: &'a [u8]) -> Result<Self, Error> {
        if payload.len() > MAX_PAYLOAD_LEN {
            return Err(Error::MessageTooLarge);
        }
        let kind = Kind::from_u8(kind).ok_or(Error::UnknownKind)?;
        let mut r = Reader::new(payload);
        let msg = match kind {
            Kind::Hello => Self::Hello(Hello::parse(&mut r)?),
            Kind::Configure => Self::Configure(Configure::parse(&mut r)?),
            Kind::Start => Self::Start(Start::parse(&mut r)?),
            Kind::Stop => Self::Stop,
            Kind::AddDevice => Self::AddDevice(AddDevice::parse(&mut r)?),
            Kind::AddVibration => Self::AddVibration(AddVibration::parse(&mut r)?),
            Kind::AddFault => Self::AddFault(AddFault::parse(&mut r)?),
            Kind::Images => Self::Images(ImageBatch::parse(&mut r)?),
            Kind::Kinematics => Self::Kinematics(KinematicsBatch::parse(&mut r)?),
            Kind::HelloAck => Self::HelloAck(HelloAck::parse(&mut r)?),
            Kind::Credit => Self::Credit(Credit::parse(&mut r)?),
            Kind::Telemetry => Self::Telemetry(Telemetry::parse(&mut r)?),
            Kind::RegisterWrites => Self::RegisterWrites(RegisterWriteBatch::parse(&mut r)?),
            Kind::Reset => Self::Reset(Reset::parse(&mut r)?),
            Kind::Error => Self::Error(ErrorReport::parse(&mut r)?),
            Kind::Served => Self::Served(ServedBatch::parse(&mut r)?),
        };
        r.finish()?;
        Ok(msg)
    }

    /// The length of the payload [`emit`](Self::emit) writes.
    pub fn buffer_len(&self) -> usize {
        match self {
            Self::Hello(_) => Hello::LEN,
            Self::Configure(m) => m.buffer_len(),
            Self::Start(_) => Start::LEN,
            Self::Stop => 0,
            Self::AddDevice(m) => m.buffer_len(),
            Self::AddVibration(m) => m.buffer_len(),
            Self::AddFault(m) => m.buffer_len(),
            Self::Images(m) => m.buffer_len(),
            Self::Kinematics(m) => m.buffer_len(),
            Self::HelloAck(_) => HelloAck::LEN,
            Self::Credit(_) => Credit::LEN,
            Self::Telemetry(_) => TELEMETRY_LEN,
            Self::RegisterWrites(m) => m.buffer_len(),
            Self::Reset(_) => Reset::LEN,
            Self::Error(_) => ErrorReport::LEN,
            Self::Served(m) => m.buffer_len(),
        }
    }

    /// Writes the payload to the front of `buf`; returns its length
    /// ([`buffer_len`](Self::buffer_len)).
    pub fn emit(&self, buf: &mut [u8]) -> Result<usize, Error> {
        let mut w = Writer::new(buf);
        match self {
            Self::Hello(m) => m.emit(&mut w),
            Self::Configure(m) => m.emit(&mut w),
            Self::Start(m) => m.emit(&mut w),
            Self::Stop => Ok(()),
            Self::AddDevice(m) => m.emit(&mut w),
            Self::AddVibration(m) => m.emit(&mut w),
            Self::AddFault(m) => m.emit(&mut w),
            Self::Images(m) => m.emit(&mut w),
            Self::Kinematics(m) => m.emit(&mut w),
            Self::HelloAck(m) => m.emit(&mut w),
            Self::Credit(m) => m.emit(&mut w),
            Self::Telemetry(m) => m.emit(&mut w),
            Self::RegisterWrites(m) => m.emit(&mut w),
            Self::Reset(m) => m.emit(&mut w),
            Self::Error(m) => m.emit(&mut w),
            Self::Served(m) => m.emit(&mut w),
        }?;
        Ok(w.position())
    }
}
