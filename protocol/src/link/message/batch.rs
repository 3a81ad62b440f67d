//! Batches of fixed-size items: true kinematics (host → device), register writes and served
//! reports (device → host). Register images, whose length is the chip's, are in `images.rs`.
//!
//! A batch borrows its items: when emitting, from the caller's slice ([`Items::from_slice`]);
//! when parsed, from the frame's payload, validated once at parse time and decoded on access.
//! Either way [`Items::iter`] yields the items by value and two batches compare equal when their
//! items do.
//!
//! ```
//! use margemu_protocol::link::{Bus, Message, RegisterWrite, RegisterWriteBatch};
//! let w = RegisterWrite { time_ns: 5, bus: Bus::Spi, address: 0, register: 0x6B, value: 0x80 };
//! let writes = [w, RegisterWrite { value: 0x01, ..w }];
//! let mut payload = [0u8; 4 + 2 * 12];
//! Message::RegisterWrites(RegisterWriteBatch::new(0, &writes)).emit(&mut payload)?;
//! let Message::RegisterWrites(batch) = Message::parse(0x84, &payload)? else { unreachable!() };
//! assert_eq!(batch.writes.get(1), Some(writes[1]));
//! assert_eq!(batch.writes.iter().count(), 2);
//! # Ok::<(), margemu_protocol::link::Error>(())
//! ```

use core::fmt;

use margemu_model::sensor::Truth;

use crate::link::wire::{Reader, Writer};
use crate::link::{Error, MAX_PAYLOAD_LEN};

/// Bytes in one true-kinematics sample (13 binary32 values and a flags byte).
pub const TRUTH_LEN: usize = 53;

/// Most samples in one [`KinematicsBatch`].
pub const MAX_KINEMATICS_PER_BATCH: usize = (MAX_PAYLOAD_LEN - 8) / TRUTH_LEN;
/// Most entries in one [`RegisterWriteBatch`].
pub const MAX_REGISTER_WRITES_PER_BATCH: usize = (MAX_PAYLOAD_LEN - 4) / RegisterWrite::LEN;
/// Most entries in one [`ServedBatch`].
pub const MAX_SERVED_PER_BATCH: usize = (MAX_PAYLOAD_LEN - 16) / ServedSample::LEN;

/// A fixed-size item of a batch.
pub trait WireItem: Sized + Copy {
    /// Its size on the wire.
    const LEN: usize;
    /// Decodes one item from exactly [`LEN`](Self::LEN) bytes.
    fn parse(bytes: &[u8]) -> Result<Self, Error>;
    /// Encodes it ([`LEN`](Self::LEN) bytes).
    fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error>;
    /// Checks one encoded item; by default by parsing it.
    fn validate(bytes: &[u8]) -> Result<(), Error> {
        Self::parse(bytes).map(drop)
    }
}

/// Flags byte of a kinematics sample: the temperature is present.
const TEMPERATURE_PRESENT: u8 = 0x01;

impl WireItem for Truth {
    const LEN: usize = TRUTH_LEN;
    fn parse(bytes: &[u8]) -> Result<Self, Error> {
        let mut r = Reader::new(bytes);
        let (w, f, m, dw) = (r.f32s()?, r.f32s()?, r.f32s()?, r.f32s()?);
        let t = r.u32()?;
        let temperature_c = match r.u8()? {
            TEMPERATURE_PRESENT => Some(f32::from_bits(t)),
            0 if t == 0 => None,
            _ => return Err(Error::InvalidValue),
        };
        r.finish()?;
        Ok(Truth {
            angular_rate: w,
            specific_force: f,
            magnetic_field: m,
            angular_acceleration: dw,
            temperature_c,
        })
    }
    fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        w.f32s(&self.angular_rate)?;
        w.f32s(&self.specific_force)?;
        w.f32s(&self.magnetic_field)?;
        w.f32s(&self.angular_acceleration)?;
        w.f32(self.temperature_c.unwrap_or(0.0))?;
        w.u8(if self.temperature_c.is_some() {
            TEMPERATURE_PRESENT
        } else {
            0
        })
    }
}

code_enum! {
    /// The bus a register write arrived on.
    pub enum Bus {
        /// SPI (the address field is 0).
        Spi = 0,
        /// I2C (the address field is the 7-bit target address).
        I2c = 1,
        /// The MPU-9250's auxiliary I2C master, writing to the AK8963 on behalf of the device
        /// under test (the address field is the slave address).
        AuxMaster = 2,
    }
}

/// One register write made by the device under test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RegisterWrite {
    /// Device scene time of the write, ns.
    pub time_ns: u64,
    /// Bus.
    pub bus: Bus,
    /// 7-bit I2C address (0 on SPI).
    pub address: u8,
    /// Register address.
    pub register: u8,
    /// Value written.
    pub value: u8,
}

impl WireItem for RegisterWrite {
    const LEN: usize = 12;
    fn parse(bytes: &[u8]) -> Result<Self, Error> {
        let mut r = Reader::new(bytes);
        let write = Self {
            time_ns: r.u64()?,
            bus: Bus::read(&mut r)?,
            address: r.u8()?,
            register: r.u8()?,
            value: r.u8()?,
        };
        r.finish()?;
        Ok(write)
    }
    fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        w.u64(self.time_ns)?;
        w.bytes(&[self.bus as u8, self.address, self.register, self.value])
    }
}

/// Flags of a [`ServedSample`]: the instant was an underrun (the previous image held).
const SERVED_UNDERRUN: u8 = 0x01;
/// Flags of a [`ServedSample`]: no image had been received yet (nothing latched).
const SERVED_EMPTY: u8 = 0x02;

/// What the device served at one sample instant, for the host to check byte for byte.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ServedSample {
    /// CRC-32C ([`CRC32C`](crate::link::CRC32C)) of the image latched into the chip, its
    /// configured length (0 when `empty`).
    pub crc32c: u32,
    /// The sample was missing (an underrun): the previous image was latched again.
    pub underrun: bool,
    /// No image existed yet: nothing was latched.
    pub empty: bool,
}

impl WireItem for ServedSample {
    const LEN: usize = 5;
    fn parse(bytes: &[u8]) -> Result<Self, Error> {
        let mut r = Reader::new(bytes);
        let crc32c = r.u32()?;
        let flags = r.u8()?;
        r.finish()?;
        if flags & !(SERVED_UNDERRUN | SERVED_EMPTY) != 0
            || (flags & SERVED_EMPTY != 0 && crc32c != 0)
        {
            return Err(Error::InvalidValue);
        }
        Ok(Self {
            crc32c,
            underrun: flags & SERVED_UNDERRUN != 0,
            empty: flags & SERVED_EMPTY != 0,
        })
    }
    fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        if self.empty && self.crc32c != 0 {
            return Err(Error::InvalidValue);
        }
        w.u32(self.crc32c)?;
        let mut flags = 0;
        if self.underrun {
            flags |= SERVED_UNDERRUN;
        }
        if self.empty {
            flags |= SERVED_EMPTY;
        }
        w.u8(flags)
    }
}

/// The items of a batch: the caller's slice, or a validated payload region.
pub struct Items<'a, T> {
    repr: ItemsRepr<'a, T>,
}

enum ItemsRepr<'a, T> {
    Values(&'a [T]),
    Wire(&'a [u8]),
}

impl<T> Clone for Items<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for Items<'_, T> {}
impl<T> Clone for ItemsRepr<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for ItemsRepr<'_, T> {}

impl<'a, T: WireItem> Items<'a, T> {
    /// Items to emit.
    pub const fn from_slice(values: &'a [T]) -> Self {
        Self {
            repr: ItemsRepr::Values(values),
        }
    }

    /// Takes every remaining byte of `r` as whole, valid items.
    fn parse(r: &mut Reader<'a>) -> Result<Self, Error> {
        let bytes = r.bytes(r.remaining().len())?;
        if bytes.len() % T::LEN != 0 {
            return Err(Error::PayloadTooLong);
        }
        bytes.chunks_exact(T::LEN).try_for_each(T::validate)?;
        Ok(Self {
            repr: ItemsRepr::Wire(bytes),
        })
    }

    fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        match self.repr {
            ItemsRepr::Values(v) => v.iter().try_for_each(|x| x.emit(w)),
            ItemsRepr::Wire(b) => w.bytes(b),
        }
    }

    /// The number of items.
    pub fn len(&self) -> usize {
        match self.repr {
            ItemsRepr::Values(v) => v.len(),
            ItemsRepr::Wire(b) => b.len() / T::LEN,
        }
    }

    /// Whether there is no item.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Their size on the wire.
    pub fn buffer_len(&self) -> usize {
        self.len() * T::LEN
    }

    /// Item `i`.
    pub fn get(&self, i: usize) -> Option<T> {
        match self.repr {
            ItemsRepr::Values(v) => v.get(i).copied(),
            ItemsRepr::Wire(b) => {
                let at = i.checked_mul(T::LEN)?;
                T::parse(b.get(at..at.checked_add(T::LEN)?)?).ok()
            }
        }
    }

    /// The items, in order.
    pub fn iter(&self) -> impl Iterator<Item = T> + 'a {
        let items = *self;
        (0..self.len()).filter_map(move |i| items.get(i))
    }
}

impl<T: WireItem + PartialEq> PartialEq for Items<'_, T> {
    fn eq(&self, other: &Self) -> bool {
        self.len() == other.len() && self.iter().eq(other.iter())
    }
}

impl<T: WireItem + fmt::Debug> fmt::Debug for Items<'_, T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

/// Host → device: true kinematics (at the configured truth rate) for consecutive samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KinematicsBatch<'a> {
    /// Index of the first sample (at the truth rate); sample `k` is `first_index + k`.
    pub first_index: u64,
    /// The samples, at most [`MAX_KINEMATICS_PER_BATCH`].
    pub samples: Items<'a, Truth>,
}

/// Device → host: register writes of the device under test, oldest first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RegisterWriteBatch<'a> {
    /// Writes lost since the previous batch because the device's log was full.
    pub dropped: u32,
    /// The writes, at most [`MAX_REGISTER_WRITES_PER_BATCH`].
    pub writes: Items<'a, RegisterWrite>,
}

/// Device → host: what the device served at consecutive output sample instants.
///
/// Entry `k` is sample `first_index + k`, latched at scene time
/// `rate.sample_time_ns(first_index + k)` (`first_time_ns` for the first entry).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ServedBatch<'a> {
    /// Output sample index of the first entry.
    pub first_index: u64,
    /// Device scene time of the first entry, ns.
    pub first_time_ns: u64,
    /// The entries, at most [`MAX_SERVED_PER_BATCH`].
    pub samples: Items<'a, ServedSample>,
}

impl<'a> ServedBatch<'a> {
    /// A batch of `samples` starting at output index `first_index`, served at `first_time_ns`.
    pub const fn new(first_index: u64, first_time_ns: u64, samples: &'a [ServedSample]) -> Self {
        Self {
            first_index,
            first_time_ns,
            samples: Items::from_slice(samples),
        }
    }
    pub(crate) fn parse(r: &mut Reader<'a>) -> Result<Self, Error> {
        let first_index = r.u64()?;
        let first_time_ns = r.u64()?;
        let samples = Items::parse(r)?;
        Ok(Self {
            first_index,
            first_time_ns,
            samples,
        })
    }
    pub(crate) fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        w.u64(self.first_index)?;
        w.u64(self.first_time_ns)?;
        self.samples.emit(w)
    }
    pub(crate) fn buffer_len(&self) -> usize {
        16 + self.samples.buffer_len()
    }
}

impl<'a> KinematicsBatch<'a> {
    /// A batch of `samples` starting at truth index `first_index`.
    pub const fn new(first_index: u64, samples: &'a [Truth]) -> Self {
        Self {
            first_index,
            samples: Items::from_slice(samples),
        }
    }
    pub(crate) fn parse(r: &mut Reader<'a>) -> Result<Self, Error> {
        let first_index = r.u64()?;
        let samples = Items::parse(r)?;
        Ok(Self {
            first_index,
            samples,
        })
    }
    pub(crate) fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        w.u64(self.first_index)?;
        self.samples.emit(w)
    }
    pub(crate) fn buffer_len(&self) -> usize {
        8 + self.samples.buffer_len()
    }
}

impl<'a> RegisterWriteBatch<'a> {
    /// A batch of `writes`, after `dropped` lost ones.
    pub const fn new(dropped: u32, writes: &'a [RegisterWrite]) -> Self {
        Self {
            dropped,
            writes: Items::from_slice(writes),
        }
    }
    pub(crate) fn parse(r: &mut Reader<'a>) -> Result<Self, Error> {
        let dropped = r.u32()?;
        let writes = Items::parse(r)?;
        Ok(Self { dropped, writes })
    }
    pub(crate) fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        w.u32(self.dropped)?;
        self.writes.emit(w)
    }
    pub(crate) fn buffer_len(&self) -> usize {
        4 + self.writes.buffer_len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::Message;

    #[test]
    fn served_batch_round_trips_byte_for_byte() {
        let samples = [
            ServedSample {
                crc32c: 0x0403_0201,
                underrun: false,
                empty: false,
            },
            ServedSample {
                crc32c: 0xDDCC_BBAA,
                underrun: true,
                empty: false,
            },
            ServedSample {
                crc32c: 0,
                underrun: true,
                empty: true,
            },
        ];
        let msg = Message::Served(ServedBatch::new(0x10, 0x20, &samples));
        let mut buf = [0u8; 64];
        let n = msg.emit(&mut buf).unwrap();
        assert_eq!(n, msg.buffer_len());
        #[rustfmt::skip]
        let expected = [
            0x10, 0, 0, 0, 0, 0, 0, 0, // first_index
            0x20, 0, 0, 0, 0, 0, 0, 0, // first_time_ns
            0x01, 0x02, 0x03, 0x04, 0x00, // crc, flags
            0xAA, 0xBB, 0xCC, 0xDD, 0x01,
            0x00, 0x00, 0x00, 0x00, 0x03,
        ];
        assert_eq!(&buf[..n], &expected);
        assert_eq!(Message::parse(0x87, &buf[..n]).unwrap(), msg);
        // Reserved flag bits, a CRC with `empty`, and a partial entry are rejected.
        let mut bad = expected;
        bad[20] = 0x04;
        assert_eq!(Message::parse(0x87, &bad), Err(Error::InvalidValue));
        let mut bad = expected;
        bad[26] = 1;
        assert_eq!(Message::parse(0x87, &bad), Err(Error::InvalidValue));
        assert_eq!(
            Message::parse(0x87, &expected[..n - 1]),
            Err(Error::PayloadTooLong)
        );
        assert_eq!(MAX_SERVED_PER_BATCH, 302);
    }
}
