//! The chip boundary on the device: [`Chip`], the one face every emulated chip shows to the link
//! handler, the SPI shadow, the boards and the host's virtual flight controller, and
//! [`EmulatedChip`], the chip a device runs, chosen by [`Configure`](margemu_protocol::link::Configure).
//!
//! Nothing outside a chip's module names a register: the link latches images and physical
//! samples, the boards ask for the INT level, the SPI shadow asks what a bus read would return,
//! register overrides are applied by the chip through its own bus.
//!
//! ```
//! use margemu_firmware::chip::{Chip, EmulatedChip, PhysicalSample};
//! use margemu_protocol::chip::ChipModel;
//! let mut chip = EmulatedChip::new(ChipModel::Mpu9250, 0x71, 0x68).unwrap();
//! let at_rest = PhysicalSample { acc: [0.0, 0.0, 9.80665], temp_c: 21.0, ..Default::default() };
//! let image = chip.settings().image(&at_rest);
//! chip.latch_image_at(&image, 1_000_000);
//! assert_eq!(chip.model(), ChipModel::Mpu9250);
//! assert!(EmulatedChip::new(ChipModel::Mpu9250, 0x47, 0x68).is_none()); // not its identity
//! ```

use margemu_protocol::chip::{ChipModel, ChipSettings, PhysicalSample};

use super::bmi088::{self, Bmi088};
use super::bmi270::{self, Bmi270};
use super::icm42688p::{self, Icm42688p};
use super::mpu6xxx::{self, Mpu6xxx, Variant};
use super::{I2cTarget, Ist8310, Qmc5883l, RegisterWrite, Rm3100, SpiTarget};

/// What every emulated chip does for the link, the boards and the host (see the module docs).
/// Time is the scene time in ns, moved forward only by latches and [`Chip::advance`].
pub trait Chip: SpiTarget + I2cTarget {
    /// The model.
    fn model(&self) -> ChipModel;
    /// The conversion settings in force now (what a physical sample latched now becomes).
    fn settings(&self) -> ChipSettings;
    /// Latches a finished register image of [`ChipModel::image_len`] bytes taken at `now_ns`.
    fn latch_image_at(&mut self, image: &[u8], now_ns: u64);
    /// Latches a physical sample (chip axes) taken at `now_ns`.
    fn latch_at(&mut self, sample: &PhysicalSample, now_ns: u64);
    /// Moves the chip's clock to `now_ns` without a sample.
    fn advance(&mut self, now_ns: u64);
    /// The chip's clock.
    fn now_ns(&self) -> u64;
    /// Nanoseconds between samples under the chip's current rate registers.
    fn sample_period_ns(&self) -> u64;
    /// The electrical level of the (first) interrupt pin at `now_ns` (`true` = high).
    fn int_pin_at(&self, now_ns: u64) -> bool;
    /// Whether that pin is open drain.
    fn int_open_drain(&self) -> bool;
    /// When the current interrupt pulse ends, for a board to schedule the edge.
    fn int_pulse_end_ns(&self) -> Option<u64>;
    /// The oldest register write of the device under test not yet taken.
    fn pop_write(&mut self) -> Option<RegisterWrite>;
    /// Writes the write log lost because nobody took them, cumulative.
    fn writes_dropped(&self) -> u32;
    /// Writes `value` to `register` of register file `file` (numbered as
    /// [`ChipModel::register_files`] says) through the chip's own bus, as a driver would;
    /// `false` if the model has no such file. The write lands in the write log.
    fn write_register(&mut self, file: u8, register: u8, value: u8) -> bool;
    /// The chip's 7-bit I2C address.
    fn i2c_address(&self) -> u8;
    /// What an SPI read of `addr` would return now, without its side effects (in the register
    /// bank selected now, for chips with banks).
    fn spi_peek(&self, addr: u8) -> u8;
    /// The address an SPI burst moves to after `addr` (the same one for FIFO ports).
    fn spi_next_address(&self, addr: u8) -> u8;
    /// What an SPI read of `addr` returns after an SPI write of `value` to it, when the write
    /// only stores a value (through the write mask); `None` when the write does more (resets,
    /// FIFO pushes, bank switches, transfers) or nothing: a board's shadow must then wait for
    /// the chip.
    fn spi_plain_write(&self, addr: u8, value: u8) -> Option<u8>;
    /// The register where drivers start their sample burst: the SPI shadow's first guess.
    fn burst_start(&self) -> u8;
    /// Fills `out` with the data bytes an SPI read burst from `start` would return now, in
    /// order (what MISO carries after the address byte), without its side effects on `self`.
    ///
    /// The default reads [`Chip::spi_peek`] along [`Chip::spi_next_address`], which is exact
    /// only for chips whose reads change nothing a later byte of the burst returns. Chips with
    /// FIFO ports or read-latched counters override it, usually with [`spi_read_burst_on_copy`].
    fn spi_read_burst(&self, start: u8, out: &mut [u8]) {
        let mut addr = start & 0x7F;
        for slot in out {
            *slot = self.spi_peek(addr);
            addr = self.spi_next_address(addr);
        }
    }
    /// The byte an SPI read clocks out before the addressed register's value, if reads have
    /// one now (the BMI270's and the BMI088 accelerometer's dummy byte, in SPI mode);
    /// [`Chip::spi_read_burst`] includes it.
    /// The default: none.
    fn spi_read_dummy(&self) -> Option<u8> {
        None
    }
    /// Fault hook (`margemu_model::fault::FaultKind::Reset`): the chip resets itself to its
    /// power-on register values, as after a power cycle (configuration, FIFO, interrupt state
    /// and data registers as the datasheet gives them after power-up), keeping its clock and
    /// its write log, and goes on taking samples under the power-on settings. A fault window's
    /// own overrides ([`Chip::fault_identity`], [`Chip::fault_fifo_overflow`]) survive it.
    /// Returns whether the chip models the fault.
    ///
    /// No default: each chip decides (every emulated chip implements it).
    fn fault_reset(&mut self) -> bool;
    /// Fault hook (`FaultKind::WrongIdentity`): every identity register of the chip (WHO_AM_I,
    /// CHIP_ID, the AK8963's WIA, …) reads `value` until called again with `None`. Returns
    /// whether the chip models the fault. No default: each chip decides.
    fn fault_identity(&mut self, value: Option<u8>) -> bool;
    /// Fault hook (`FaultKind::FifoOverflow`): while `on`, the FIFO overflows as if nobody had
    /// read it (the chip's overflow flag, interrupt, count and contents as its datasheet says),
    /// from the chip's next sample on and at every sample after it; `false` turns it off (the
    /// FIFO then fills normally; what overflowed stays until the driver resets the FIFO).
    /// Returns `false` for a chip without a FIFO. No default: each chip decides.
    fn fault_fifo_overflow(&mut self, on: bool) -> bool;
    /// The 7-bit I2C addresses the chip acknowledges now, at most two (a board's I2C peripheral
    /// owns two: the MPU-9250's own address, and the AK8963's in bypass mode). The default is
    /// [`Chip::i2c_address`] alone.
    fn i2c_addresses_now(&self) -> [Option<u8>; 2] {
        [Some(self.i2c_address()), None]
    }
}

/// [`Chip::spi_read_burst`] by running the burst on a copy of `chip` (exact whatever the
/// chip's read side effects; costs one copy of the chip).
pub fn spi_read_burst_on_copy<C: SpiTarget + Clone>(chip: &C, start: u8, out: &mut [u8]) {
    let mut copy = chip.clone();
    copy.select();
    let mut next = copy.exchange(0x80 | start);
    let mut slots = out.iter_mut().peekable();
    while let Some(slot) = slots.next() {
        *slot = next;
        if slots.peek().is_some() {
            next = copy.exchange(0x00);
        }
    }
}

/// The chip a device runs: one variant per chip family, chosen at run time by Configure.
#[derive(Clone, Debug)]
#[allow(clippy::large_enum_variant)] // held once per device; no alloc
pub enum EmulatedChip {
    /// The InvenSense 6xxx family (MPU-9250 with its AK8963, MPU-6500, MPU-6000, ICM-20602).
    Mpu6xxx(Mpu6xxx),
    /// The TDK InvenSense ICM-42688-P.
    Icm42688p(Icm42688p),
    /// The Bosch BMI270.
    Bmi270(Bmi270),
    /// The Bosch BMI088 (both dies).
    Bmi088(Bmi088),
    /// The iSentek IST8310 magnetometer.
    Ist8310(Ist8310),
    /// The QST QMC5883L magnetometer.
    Qmc5883l(Qmc5883l),
    /// The PNI RM3100 magnetometer.
    Rm3100(Rm3100),
}

impl Default for EmulatedChip {
    /// An MPU-9250 at power-on (the default chip).
    fn default() -> Self {
        Self::Mpu6xxx(Mpu6xxx::new())
    }
}

impl EmulatedChip {
    /// A chip of `model` answering `who_am_i` at I2C address `i2c_address`, just powered on;
    /// `None` if the model is not emulated here, or lacks that identity or address.
    pub fn new(model: ChipModel, who_am_i: u8, i2c_address: u8) -> Option<Self> {
        if !model.identities().contains(&who_am_i) || !model.i2c_addresses().contains(&i2c_address)
        {
            return None;
        }
        let ad0 = model.i2c_addresses().get(1) == Some(&i2c_address);
        match model {
            ChipModel::Icm42688p => {
                return Some(Self::Icm42688p(Icm42688p::with_config(icm42688p::Config {
                    ad0,
                    who_am_i,
                })))
            }
            ChipModel::Bmi270 => {
                return Some(Self::Bmi270(Bmi270::with_config(bmi270::Config {
                    sdo: ad0,
                })))
            }
            ChipModel::Bmi088 => {
                return Some(Self::Bmi088(Bmi088::new(bmi088::Config { sdo: ad0 })))
            }
            ChipModel::Ist8310 => return Some(Self::Ist8310(Ist8310::with_address(i2c_address))),
            ChipModel::Qmc5883l => {
                return Some(Self::Qmc5883l(Qmc5883l::with_address(i2c_address)))
            }
            ChipModel::Rm3100 => {
                let pins = i2c_address.wrapping_sub(0x20);
                return Some(Self::Rm3100(Rm3100::with_pins(
                    pins & 1 != 0,
                    pins & 2 != 0,
                )));
            }
            _ => {}
        }
        let variant = Variant::for_model(model, who_am_i)?;
        Some(Self::Mpu6xxx(Mpu6xxx::with_config(mpu6xxx::Config {
            variant,
            ad0,
            ..mpu6xxx::Config::default()
        })))
    }

    /// The models this firmware emulates.
    pub fn models() -> impl Iterator<Item = ChipModel> {
        ChipModel::ALL.into_iter().filter(|m| {
            matches!(
                m,
                ChipModel::Icm42688p
                    | ChipModel::Bmi270
                    | ChipModel::Bmi088
                    | ChipModel::Ist8310
                    | ChipModel::Qmc5883l
                    | ChipModel::Rm3100
            ) || Variant::for_model(*m, m.who_am_i()).is_some()
        })
    }
}

impl EmulatedChip {
    /// The SPI target on the `die`-th chip select the chip takes
    /// ([`ChipModel::spi_selects`]): die 0 is the chip itself (its own [`SpiTarget`]; the
    /// BMI088's accelerometer die), die 1 the BMI088's gyroscope die; `None` past the chip's
    /// selects.
    pub fn die_spi_target(&mut self, die: u8) -> Option<&mut dyn SpiTarget> {
        match (self, die) {
            (Self::Bmi088(chip), _) => chip.die_spi_target(die),
            (chip, 0) => Some(chip),
            _ => None,
        }
    }
}

/// Forwards a method call to the chip inside every variant.
macro_rules! each_chip {
    ($self:expr, $chip:ident => $call:expr) => {
        match $self {
            EmulatedChip::Mpu6xxx($chip) => $call,
            EmulatedChip::Icm42688p($chip) => $call,
            EmulatedChip::Bmi270($chip) => $call,
            EmulatedChip::Bmi088($chip) => $call,
            EmulatedChip::Ist8310($chip) => $call,
            EmulatedChip::Qmc5883l($chip) => $call,
            EmulatedChip::Rm3100($chip) => $call,
        }
    };
}

impl SpiTarget for EmulatedChip {
    fn select(&mut self) -> u8 {
        each_chip!(self, c => c.select())
    }
    fn exchange(&mut self, mosi: u8) -> u8 {
        each_chip!(self, c => c.exchange(mosi))
    }
    fn deselect(&mut self) {
        each_chip!(self, c => c.deselect())
    }
}

impl I2cTarget for EmulatedChip {
    fn start(&mut self, address: u8, read: bool) -> bool {
        each_chip!(self, c => c.start(address, read))
    }
    fn write(&mut self, byte: u8) -> bool {
        each_chip!(self, c => I2cTarget::write(c, byte))
    }
    fn read(&mut self) -> u8 {
        each_chip!(self, c => I2cTarget::read(c))
    }
    fn stop(&mut self) {
        each_chip!(self, c => c.stop())
    }
}

impl Chip for EmulatedChip {
    fn model(&self) -> ChipModel {
        each_chip!(self, c => c.model())
    }
    fn settings(&self) -> ChipSettings {
        each_chip!(self, c => c.settings())
    }
    fn latch_image_at(&mut self, image: &[u8], now_ns: u64) {
        each_chip!(self, c => Chip::latch_image_at(c, image, now_ns))
    }
    fn latch_at(&mut self, sample: &PhysicalSample, now_ns: u64) {
        each_chip!(self, c => Chip::latch_at(c, sample, now_ns))
    }
    fn advance(&mut self, now_ns: u64) {
        each_chip!(self, c => Chip::advance(c, now_ns))
    }
    fn now_ns(&self) -> u64 {
        each_chip!(self, c => Chip::now_ns(c))
    }
    fn sample_period_ns(&self) -> u64 {
        each_chip!(self, c => Chip::sample_period_ns(c))
    }
    fn int_pin_at(&self, now_ns: u64) -> bool {
        each_chip!(self, c => Chip::int_pin_at(c, now_ns))
    }
    fn int_open_drain(&self) -> bool {
        each_chip!(self, c => Chip::int_open_drain(c))
    }
    fn int_pulse_end_ns(&self) -> Option<u64> {
        each_chip!(self, c => Chip::int_pulse_end_ns(c))
    }
    fn pop_write(&mut self) -> Option<RegisterWrite> {
        each_chip!(self, c => Chip::pop_write(c))
    }
    fn writes_dropped(&self) -> u32 {
        each_chip!(self, c => c.writes_dropped())
    }
    fn write_register(&mut self, file: u8, register: u8, value: u8) -> bool {
        each_chip!(self, c => Chip::write_register(c, file, register, value))
    }
    fn i2c_address(&self) -> u8 {
        each_chip!(self, c => Chip::i2c_address(c))
    }
    fn spi_peek(&self, addr: u8) -> u8 {
        each_chip!(self, c => c.spi_peek(addr))
    }
    fn spi_next_address(&self, addr: u8) -> u8 {
        each_chip!(self, c => c.spi_next_address(addr))
    }
    fn spi_plain_write(&self, addr: u8, value: u8) -> Option<u8> {
        each_chip!(self, c => c.spi_plain_write(addr, value))
    }
    fn burst_start(&self) -> u8 {
        each_chip!(self, c => c.burst_start())
    }
    fn spi_read_burst(&self, start: u8, out: &mut [u8]) {
        each_chip!(self, c => c.spi_read_burst(start, out))
    }
    fn spi_read_dummy(&self) -> Option<u8> {
        each_chip!(self, c => c.spi_read_dummy())
    }
    fn i2c_addresses_now(&self) -> [Option<u8>; 2] {
        each_chip!(self, c => c.i2c_addresses_now())
    }
    fn fault_reset(&mut self) -> bool {
        each_chip!(self, c => Chip::fault_reset(c))
    }
    fn fault_identity(&mut self, value: Option<u8>) -> bool {
        each_chip!(self, c => Chip::fault_identity(c, value))
    }
    fn fault_fifo_overflow(&mut self, on: bool) -> bool {
        each_chip!(self, c => Chip::fault_fifo_overflow(c, on))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every emulated chip holds its chip module's power-on settings right after power-on, under
    /// each of its identities and addresses, and reaches the settings `config_writes` stands
    /// for through those writes: the host reads both from the chip module, never from a chip.
    #[test]
    fn power_on_settings_are_the_chip_modules() {
        use margemu_protocol::chip::FullScale;
        assert_eq!(
            EmulatedChip::default().settings(),
            ChipSettings::power_on(ChipModel::Mpu9250)
        );
        for model in EmulatedChip::models() {
            for &who_am_i in model.identities() {
                for &address in model.i2c_addresses() {
                    let chip = EmulatedChip::new(model, who_am_i, address).unwrap();
                    let at = (model, who_am_i, address);
                    assert_eq!(chip.settings(), ChipSettings::power_on(model), "{at:?}");
                }
            }
            let fs = FullScale {
                accel_g: ChipSettings::accel_ranges_g(model).last().unwrap_or(0.0),
                gyro_dps: ChipSettings::gyro_ranges_dps(model).last().unwrap_or(0.0),
            };
            let want = match ChipSettings::mag_ranges_gauss(model).last() {
                Some(&gauss) => ChipSettings::power_on(model).with_mag_range(gauss).unwrap(),
                None if model.is_magnetometer_only() => ChipSettings::power_on(model),
                None => ChipSettings::with_full_scale(model, fs).unwrap(),
            };
            let mut chip =
                EmulatedChip::new(model, model.who_am_i(), model.i2c_addresses()[0]).unwrap();
            for (file, register, value) in want.config_writes(1000.0) {
                assert!(chip.write_register(file, register, value), "{model:?}");
            }
            assert_eq!(chip.settings(), want, "{model:?} at its largest ranges");
        }
    }

    /// The register holding the identity of `model` (of its first die).
    fn identity_register(model: ChipModel) -> u8 {
        match model {
            ChipModel::Bmi270 | ChipModel::Bmi088 | ChipModel::Ist8310 => 0x00,
            ChipModel::Qmc5883l => 0x0D,
            ChipModel::Rm3100 => 0x36,
            _ => 0x75,
        }
    }

    fn i2c_read(chip: &mut EmulatedChip, address: u8, register: u8) -> Option<u8> {
        let acked = chip.start(address, false) && I2cTarget::write(chip, register);
        let value = (acked && chip.start(address, true)).then(|| I2cTarget::read(chip));
        chip.stop();
        value
    }

    /// Every emulated chip implements the reset and wrong-identity hooks, and the FIFO one
    /// exactly when it has a FIFO; a reset brings back the power-on settings after a
    /// configuration, and a wrong identity shows in every die's identity register until
    /// restored.
    #[test]
    fn every_chip_implements_its_fault_hooks() {
        for model in EmulatedChip::models() {
            let address = model.i2c_addresses()[0];
            let mut chip = EmulatedChip::new(model, model.who_am_i(), address).unwrap();
            let dies = [Some(address), model.second_die_i2c_address(address)];
            let reg = identity_register(model);
            let ids = |chip: &mut EmulatedChip| dies.map(|d| d.map(|d| i2c_read(chip, d, reg)));
            let before = ids(&mut chip);
            assert_eq!(before[0], Some(Some(model.who_am_i())), "{model:?}");
            assert!(
                before.iter().flatten().all(Option::is_some),
                "{model:?}: {before:?}"
            );
            assert!(chip.fault_identity(Some(0xA5)), "{model:?}");
            let wrong = ids(&mut chip);
            assert!(
                wrong.iter().flatten().all(|v| *v == Some(0xA5)),
                "{model:?}: {wrong:?}"
            );
            assert!(chip.fault_identity(None));
            assert_eq!(ids(&mut chip), before, "{model:?}: restored");

            let has_fifo = !matches!(
                model,
                ChipModel::Ist8310 | ChipModel::Qmc5883l | ChipModel::Rm3100
            );
            assert_eq!(chip.fault_fifo_overflow(true), has_fifo, "{model:?}");
            assert_eq!(chip.fault_fifo_overflow(false), has_fifo, "{model:?}");

            let power_on = ChipSettings::power_on(model);
            let fs = margemu_protocol::chip::FullScale {
                accel_g: ChipSettings::accel_ranges_g(model).last().unwrap_or(0.0),
                gyro_dps: ChipSettings::gyro_ranges_dps(model).last().unwrap_or(0.0),
            };
            let configured = match ChipSettings::mag_ranges_gauss(model).last() {
                Some(&gauss) => power_on.with_mag_range(gauss).unwrap(),
                None if model.is_magnetometer_only() => power_on,
                None => ChipSettings::with_full_scale(model, fs).unwrap(),
            };
            for (file, register, value) in configured.config_writes(1000.0) {
                assert!(chip.write_register(file, register, value), "{model:?}");
            }
            assert_eq!(chip.settings(), configured, "{model:?}");
            chip.advance(5_000_000);
            assert!(chip.fault_reset(), "{model:?}");
            assert_eq!(chip.settings(), power_on, "{model:?}: power-on settings");
            assert_eq!(chip.now_ns(), 5_000_000, "{model:?}: the clock is kept");
        }
    }
}
