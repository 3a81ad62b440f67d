//! [`AddDevice`]: one more chip for a rig, served beside the one [`Configure`](super::Configure)
//! names (`docs/spec/link.md` §5.14).
//!
//! Configure describes device 0 and drops any other; each AddDevice that follows (before
//! Start, in source (a)) appends the next device, up to [`MAX_DEVICES`] in all. From then on
//! every image of an [`ImageBatch`](super::ImageBatch) is the rig's: each device's image, in
//! device order, back to back (so its length is the sum of their lengths), and each sample
//! instant latches every device at once.
//!
//! ```
//! use margemu_protocol::chip::ChipModel;
//! use margemu_protocol::link::{AddDevice, DeviceBus, Message};
//! let add = AddDevice::new(ChipModel::Ist8310, DeviceBus::I2c);
//! assert_eq!((add.who_am_i, add.image_len, add.i2c_address), (0x10, 6, 0x0E));
//! let mut payload = [0u8; 32];
//! let n = Message::AddDevice(add.clone()).emit(&mut payload)?;
//! assert_eq!(&payload[..n], &[6, 0x10, 6, 1, 0x0E, 0, 0]);
//! assert_eq!(Message::parse(0x05, &payload[..n])?, Message::AddDevice(add));
//! # Ok::<(), margemu_protocol::link::Error>(())
//! ```

use super::RegisterOverride;
use crate::chip::ChipModel;
use crate::link::wire::{Reader, Writer};
use crate::link::Error;

/// Most devices of one rig, the one Configure names included: an IMU, a second IMU and a
/// compass. Each device's chip is held by the device at the size of the largest model, so the
/// rig's size weighs on a small board's RAM.
pub const MAX_DEVICES: usize = 3;

/// Most register overrides of one [`AddDevice`].
pub const MAX_DEVICE_OVERRIDES: usize = 8;

/// Bytes of an [`AddDevice`] before its overrides.
const FIXED_LEN: usize = 7;

/// The bus a device under test reads a rig's device on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DeviceBus {
    /// SPI, on a chip-select line.
    Spi = 0,
    /// I2C, at an address.
    I2c = 1,
}

/// Host → device: one more chip of the rig.
#[derive(Clone, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AddDevice {
    /// The chip model.
    pub chip: ChipModel,
    /// The identity it answers, one of [`ChipModel::identities`].
    pub who_am_i: u8,
    /// Bytes of its image, [`ChipModel::image_len`] (checked by the device, as in Configure).
    pub image_len: u8,
    /// Its bus.
    pub bus: DeviceBus,
    /// Its 7-bit I2C address, one of [`ChipModel::i2c_addresses`] (carried on SPI too: the
    /// chip's own strap).
    pub i2c_address: u8,
    /// SPI: its chip-select line (0 on I2C).
    pub chip_select: u8,
    /// Initial register values, applied in order after its reset.
    pub overrides: heapless::Vec<RegisterOverride, MAX_DEVICE_OVERRIDES>,
}

impl AddDevice {
    /// `chip` with its own identity at its first I2C address on `bus`, chip select 0, no
    /// overrides.
    pub fn new(chip: ChipModel, bus: DeviceBus) -> Self {
        Self {
            chip,
            who_am_i: chip.who_am_i(),
            image_len: chip.image_len() as u8,
            bus,
            i2c_address: chip.i2c_addresses().first().copied().unwrap_or(0),
            chip_select: 0,
            overrides: heapless::Vec::new(),
        }
    }

    pub(crate) fn buffer_len(&self) -> usize {
        FIXED_LEN + 3 * self.overrides.len()
    }

    pub(crate) fn parse(r: &mut Reader<'_>) -> Result<Self, Error> {
        let chip = ChipModel::from_code(r.u8()?).ok_or(Error::UnknownChip)?;
        let who_am_i = r.u8()?;
        let image_len = r.u8()?;
        let bus = match r.u8()? {
            0 => DeviceBus::Spi,
            1 => DeviceBus::I2c,
            _ => return Err(Error::InvalidValue),
        };
        let i2c_address = r.u8()?;
        let chip_select = r.u8()?;
        let count = usize::from(r.u8()?);
        let mut overrides = heapless::Vec::new();
        for _ in 0..count {
            let o = RegisterOverride {
                file: r.u8()?,
                register: r.u8()?,
                value: r.u8()?,
            };
            overrides.push(o).map_err(|_| Error::InvalidValue)?;
        }
        Ok(Self {
            chip,
            who_am_i,
            image_len,
            bus,
            i2c_address,
            chip_select,
            overrides,
        })
    }

    pub(crate) fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        w.bytes(&[
            self.chip.code(),
            self.who_am_i,
            self.image_len,
            self.bus as u8,
            self.i2c_address,
            self.chip_select,
            // At most MAX_DEVICE_OVERRIDES (8).
            self.overrides.len() as u8,
        ])?;
        for o in &self.overrides {
            w.bytes(&[o.file, o.register, o.value])?;
        }
        Ok(())
    }
}
