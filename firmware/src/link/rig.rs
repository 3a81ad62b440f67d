//! The chips a device serves at once: device 0, named by Configure, and the devices each
//! [`AddDevice`] appends (`docs/spec/link.md` §5.14), up to [`MAX_DEVICES`].
//!
//! A rig's image is every device's image in device order, back to back; [`Rig::latch_image_at`]
//! hands each chip its slice at the same instant. Register writes are drained from every chip in
//! device order; on the wire an SPI write carries its chip select as its address (device 0: 0),
//! an I2C write the address written to.
//!
//! **Chip selects.** A device on chip select `c` takes [`ChipModel::spi_selects`] of them from
//! `c` on: the BMI088's accelerometer die is on `c`, its gyroscope die on `c + 1` (device 0 on
//! 0 and 1). [`Rig::spi_device`] says which device and die a chip select reaches and
//! [`Rig::spi_target`] hands out that die; a write to the BMI088's gyroscope over SPI carries
//! `c + 1`. On I2C such a device answers both dies' addresses
//! ([`ChipModel::second_die_i2c_address`]).
//!
//! Refusals of an AddDevice ([`RigError`]): the rig is full, the chip model, identity, image
//! length or address is not one this firmware emulates (as for Configure), an override the chip
//! has no register file for, an I2C address another device answers (either die's), a chip
//! select another SPI device of the added ones takes (device 0 is on chip select 0 when on SPI,
//! and an added device on one of its selects wins), or a rig image that would exceed
//! [`MAX_IMAGE_LEN`] bytes.
//!
//! ```
//! use margemu_firmware::chip::{Chip, EmulatedChip};
//! use margemu_firmware::link::rig::Rig;
//! use margemu_protocol::chip::ChipModel;
//! use margemu_protocol::link::{AddDevice, DeviceBus};
//! let mut rig = Rig::new(EmulatedChip::new(ChipModel::Icm42688p, 0x47, 0x68).unwrap());
//! rig.add(&AddDevice::new(ChipModel::Ist8310, DeviceBus::I2c)).unwrap();
//! assert_eq!((rig.len(), rig.image_len()), (2, 32 + 6));
//! assert!(rig.add(&AddDevice::new(ChipModel::Ist8310, DeviceBus::I2c)).is_err()); // 0x0E taken
//! ```

use margemu_protocol::chip::{ChipModel, MAX_IMAGE_LEN};
use margemu_protocol::link::{AddDevice, DeviceBus, ErrorCode, MAX_DEVICES};

use crate::chip::{Chip, EmulatedChip, RegisterWrite, SpiTarget};

/// One chip of a rig and its wiring.
#[derive(Clone, Debug)]
pub struct RigDevice {
    /// The chip.
    pub chip: EmulatedChip,
    /// Its bus.
    pub bus: DeviceBus,
    /// SPI: its (first) chip select.
    pub chip_select: u8,
}

impl RigDevice {
    /// On SPI, the die chip select `cs` reaches (0 on its first select).
    fn die_on(&self, cs: u8) -> Option<u8> {
        let die = cs.checked_sub(self.chip_select)?;
        (self.bus == DeviceBus::Spi && die < self.chip.model().spi_selects()).then_some(die)
    }
}

/// The 7-bit I2C addresses a chip of `model` strapped to `address` answers (both dies').
fn die_addresses(model: ChipModel, address: u8) -> [Option<u8>; 2] {
    [Some(address), model.second_die_i2c_address(address)]
}

/// Whether the chip selects `first .. first + n` and `other .. other + m` overlap.
fn selects_overlap(first: u8, n: u8, other: u8, m: u8) -> bool {
    let (a, b) = (u16::from(first), u16::from(other));
    a < b + u16::from(m) && b < a + u16::from(n)
}

/// Why an [`AddDevice`] was refused: the Error code and its detail.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RigError {
    /// The code sent back.
    pub code: ErrorCode,
    /// Its detail.
    pub detail: u32,
}

impl RigError {
    const fn rig(detail: u32) -> Self {
        Self {
            code: ErrorCode::RigRefused,
            detail,
        }
    }
}

/// The devices a device serves (see the module docs).
#[derive(Clone, Debug)]
pub struct Rig {
    primary: EmulatedChip,
    added: [Option<RigDevice>; MAX_DEVICES - 1],
}

impl Rig {
    /// A rig of `chip` alone, as Configure sets it up (on SPI, chip select 0, or on I2C at its
    /// address: the chip answers both until a driver chooses).
    pub fn new(chip: EmulatedChip) -> Self {
        Self {
            primary: chip,
            added: [const { None }; MAX_DEVICES - 1],
        }
    }

    /// Appends the device `add` describes, reset and with its overrides applied.
    pub fn add(&mut self, add: &AddDevice) -> Result<(), RigError> {
        let Some(slot) = self.added.iter().position(Option::is_none) else {
            return Err(RigError::rig(1));
        };
        let unsupported = RigError {
            code: ErrorCode::UnsupportedChip,
            detail: u32::from(add.chip.code()),
        };
        if usize::from(add.image_len) != add.chip.image_len() {
            return Err(unsupported);
        }
        let mut chip =
            EmulatedChip::new(add.chip, add.who_am_i, add.i2c_address).ok_or(unsupported)?;
        let mine = die_addresses(add.chip, add.i2c_address);
        let taken_address = self.chips().any(|c| {
            let theirs = die_addresses(c.model(), c.i2c_address());
            mine.iter().flatten().any(|a| theirs.contains(&Some(*a)))
        });
        if add.bus == DeviceBus::I2c && taken_address {
            return Err(RigError::rig(2));
        }
        let n = add.chip.spi_selects();
        let taken_select = self.added().any(|d| {
            let m = d.chip.model().spi_selects();
            d.bus == DeviceBus::Spi && selects_overlap(add.chip_select, n, d.chip_select, m)
        });
        if add.bus == DeviceBus::Spi && taken_select {
            return Err(RigError::rig(3));
        }
        if self.image_len() + add.chip.image_len() > MAX_IMAGE_LEN {
            return Err(RigError::rig(5));
        }
        for o in &add.overrides {
            if !chip.write_register(o.file, o.register, o.value) {
                return Err(RigError {
                    code: ErrorCode::InvalidConfig,
                    detail: u32::from(o.file),
                });
            }
        }
        while chip.pop_write().is_some() {}
        let chip_select = match add.bus {
            DeviceBus::Spi => add.chip_select,
            DeviceBus::I2c => 0,
        };
        if let Some(free) = self.added.get_mut(slot) {
            *free = Some(RigDevice {
                chip,
                bus: add.bus,
                chip_select,
            });
        }
        Ok(())
    }

    /// Device 0, named by Configure.
    pub fn primary(&self) -> &EmulatedChip {
        &self.primary
    }

    /// Device 0, for a board's bus targets.
    pub fn primary_mut(&mut self) -> &mut EmulatedChip {
        &mut self.primary
    }

    /// The devices [`Rig::add`] appended, in order.
    pub fn added(&self) -> impl Iterator<Item = &RigDevice> {
        self.added.iter().flatten()
    }

    /// Every chip, device 0 first.
    pub fn chips(&self) -> impl Iterator<Item = &EmulatedChip> {
        core::iter::once(&self.primary).chain(self.added().map(|d| &d.chip))
    }

    fn chips_mut(&mut self) -> impl Iterator<Item = &mut EmulatedChip> {
        let added = self.added.iter_mut().flatten().map(|d| &mut d.chip);
        core::iter::once(&mut self.primary).chain(added)
    }

    /// Devices in the rig (at least 1).
    pub fn len(&self) -> usize {
        1 + self.added().count()
    }

    /// Never: a rig has device 0.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Bytes of the rig's image: the devices' image lengths summed.
    pub fn image_len(&self) -> usize {
        self.chips().map(|c| c.model().image_len()).sum()
    }

    /// Device `i`'s chip.
    pub fn chip(&self, i: usize) -> Option<&EmulatedChip> {
        self.chips().nth(i)
    }

    /// Device `i`'s chip, for a board's bus target.
    pub fn chip_mut(&mut self, i: usize) -> Option<&mut EmulatedChip> {
        self.chips_mut().nth(i)
    }

    /// The chip an I2C START to `address` reaches: the first device answering it now.
    pub fn i2c_target(&mut self, address: u8) -> Option<&mut EmulatedChip> {
        self.chips_mut()
            .find(|c| c.i2c_addresses_now().contains(&Some(address)))
    }

    /// The device (its index, device 0 first) and die (0 on the device's first select) on SPI
    /// chip select `cs`: an added SPI device taking it, else device 0 on its own selects.
    pub fn spi_device(&self, cs: u8) -> Option<(usize, u8)> {
        let added = self
            .added()
            .enumerate()
            .find_map(|(i, d)| Some((i + 1, d.die_on(cs)?)));
        added.or_else(|| (cs < self.primary.model().spi_selects()).then_some((0, cs)))
    }

    /// The SPI target on chip select `cs` ([`Rig::spi_device`]): a chip, or the BMI088's
    /// gyroscope die on its device's second select.
    pub fn spi_target(&mut self, cs: u8) -> Option<&mut dyn SpiTarget> {
        let (device, die) = self.spi_device(cs)?;
        self.chip_mut(device)?.die_spi_target(die)
    }

    /// Latches the rig image `image` at `now_ns`: each device its slice, in order. An image of
    /// another length than [`Rig::image_len`] latches nothing and only moves the clocks.
    pub fn latch_image_at(&mut self, image: &[u8], now_ns: u64) {
        if image.len() != self.image_len() {
            return self.advance(now_ns);
        }
        let mut rest = image;
        for chip in self.chips_mut() {
            let (mine, others) = rest.split_at(chip.model().image_len().min(rest.len()));
            chip.latch_image_at(mine, now_ns);
            rest = others;
        }
    }

    /// Moves every chip's clock to `now_ns`.
    pub fn advance(&mut self, now_ns: u64) {
        for chip in self.chips_mut() {
            chip.advance(now_ns);
        }
    }

    /// The oldest register write not yet taken, device by device, with the chip select of the
    /// die written to (device 0 on 0, a BMI088's gyroscope on its device's select + 1; the
    /// device's select for I2C writes, 0 for device 0's).
    pub fn pop_write(&mut self) -> Option<(RegisterWrite, u8)> {
        if let Some(w) = self.primary.pop_write() {
            return Some((w, die_of(&self.primary, &w)));
        }
        self.added.iter_mut().flatten().find_map(|d| {
            let w = d.chip.pop_write()?;
            Some((w, d.chip_select.wrapping_add(die_of(&d.chip, &w))))
        })
    }

    /// Writes lost by every chip's log, cumulative (wrapping).
    pub fn writes_dropped(&self) -> u32 {
        self.chips()
            .fold(0u32, |n, c| n.wrapping_add(c.writes_dropped()))
    }
}

/// Which die of `chip` a write went to: 1 for the second die's address, else 0.
fn die_of(chip: &EmulatedChip, w: &RegisterWrite) -> u8 {
    let second = chip.model().second_die_i2c_address(chip.i2c_address());
    u8::from(second == Some(w.device))
}
