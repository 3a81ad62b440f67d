//! The MPU-9250 board: the emulated MPU-9250 on its bus, driven by the unmodified `mpu9250`
//! crate (embedded-hal 0.2) through margemu's embedded-hal 1.0 adapters ([`crate::bus`]) and
//! `embedded-hal-compat`.
//!
//! **Bus.** SPI in MARG mode (the AK8963 behind the chip's auxiliary I2C master), as flight
//! controllers wire it. (The
//! crate's `i2c` feature replaces its SPI constructors; the I2C path is exercised by
//! `host/tests/driver_mpu9250.rs` with a second copy of the crate.)
//!
//! **The chip belongs to the device.** The firmware's link handler owns the chip and latches
//! samples into it; the bus adapters share their target through `Rc<RefCell<_>>`. So the board
//! holds a slot, and for each batch of bus transactions ([`Board::init`], [`Board::read`]) the
//! device's chip is moved into the slot and back afterwards ([`std::mem::swap`]): every byte the
//! driver reads comes from the emulated chip's registers through its SPI or I2C target, as on a
//! real board, and the device's chip is never touched by anything else meanwhile.
//!
//! **Set-up.** The driver initialises the chip its own way (reset, WHO_AM_I, full scales, DLPF,
//! sample-rate divider, and the AK8963 through its own path: fuse ROM ASA, 16-bit continuous
//! mode 2), then the board latches the INT pin on raw data ready (LATCH_INT_EN, cleared by any
//! read) and sets the FIFO up with raw register writes on the same bus, as ArduPilot's
//! Invensense driver does (`libraries/AP_InertialSensor/AP_InertialSensor_Invensense.cpp`:
//! `_fifo_reset`, `_read_fifo`; the sequence learnt from it, the code our own): the auxiliary
//! I2C master's slave 0 reads the AK8963's HXL..=ST2 at every sample (what the driver's SPI
//! set-up does already), FIFO_EN takes
//! temperature, gyro, accel and slave 0, so each sample appends one 21-byte record
//! ([`margemu_protocol::regmap::mpu6xxx::fifo`]), the FIFO overflow interrupt is enabled, and the
//! FIFO is reset. [`Board::data_ready`] reads the INT pin's level, as a GPIO. The driver's delays
//! do not sleep and do not move the chip's clock (the device's scene clock): the emulated chip
//! needs no settling time, and the time asked for is reported.
//!
//! **Reading.** [`Board::read`] reads INT_STATUS (first: with INT_ANYRD_2CLEAR any read clears
//! it), FIFO_COUNT, then every whole record in one burst of FIFO_R_W, oldest first. So a flight
//! controller that was late for a data-ready loses nothing while the FIFO holds its samples: 24
//! records in the MPU-9250's 512 bytes (120 ms at 200 Hz, 24 ms at 1 kHz). An overflow
//! (INT_STATUS.FIFO_OFLOW_INT, or a count that is not whole records: the oldest bytes were
//! overwritten) resets the FIFO, returns no samples and is counted ([`Board::overflows`]); the
//! flight controller counts the samples lost as missed.
//!
//! **Conversion and axes** are the chip module's: each record is decoded by
//! [`ImageRepr::parse_marg_record`] and converted with [`ImageRepr::to_physical`] (accelerometer
//! and gyroscope in the chip's axes) and [`ImageRepr::mag_ut_sensor_axes`] (the field in the
//! AK8963's own axes, with the fuse-ROM ASA the driver read), under the full scales the board
//! set. The body frame is the MPU-9250's accel/gyro frame; the AK8963's reading is turned into it
//! with the configured [`MagAlignment`] ([`to_body`], [`crate::vfc::axes`]), by default the chip
//! module's own mapping.

use super::{on_bus, Reading};
use crate::bus::{self, Shared};
use crate::vfc::axes::{BodySample, MagAlignment};
use embedded_hal_compat::ReverseCompat;
use margemu_firmware::chip::Mpu6xxx as Chip;
use margemu_protocol::regmap::ak8963::{self, MagBits};
use margemu_protocol::regmap::mpu6xxx::fifo::{self, MARG_RECORD_LEN};
use margemu_protocol::regmap::mpu6xxx::image::{ImageConfig, ImageRepr};
use margemu_protocol::regmap::mpu6xxx::{bits, reg, AccelFs, GyroFs};
use mpu9250::{
    AccelDataRate, AccelScale, Dlpf, GyroScale, GyroTempDataRate, InterruptConfig, InterruptEnable,
    MagScale, Marg, MpuConfig,
};

/// The full scales the flight controller sets: ±16 g, ±2000 °/s, 16-bit magnetometer (what
/// flight controllers use, and the widest the chip has: the case study's ±4 g external
/// acceleration fits; its ±50 rad/s do not, the chip clips at ±34.9 rad/s).
pub const ACCEL: (AccelScale, AccelFs) = (AccelScale::_16G, AccelFs::G16);
/// See [`ACCEL`].
pub const GYRO: (GyroScale, GyroFs) = (GyroScale::_2000DPS, GyroFs::Dps2000);
/// See [`ACCEL`].
pub const MAG: (MagScale, MagBits) = (MagScale::_16BITS, MagBits::Bits16);

/// What the host must assume when it computes register images for a chip this board set up:
/// the full scales above, the AK8963 fuse ROM of the emulated part, no offsets.
pub fn image_config() -> ImageConfig {
    ImageConfig {
        accel_fs: ACCEL.1,
        gyro_fs: GYRO.1,
        mag_bits: MAG.1,
        asa: margemu_protocol::regmap::ak8963::EMULATED_ASA,
        gyro_offset: [0; 3],
        accel_offset: [0; 3],
        ..ImageConfig::NOMINAL
    }
}

/// [`image_config`] as the chip boundary's settings of an MPU-9250.
pub fn chip_settings() -> margemu_protocol::chip::ChipSettings {
    margemu_protocol::chip::ChipSettings {
        model: margemu_protocol::chip::ChipModel::Mpu9250,
        conversion: margemu_protocol::chip::Conversion::Mpu6xxx(image_config()),
    }
}

/// SMPLRT_DIV for an output rate with DLPF_CFG = 1 (1 kHz internal): `1000/rate − 1` when the
/// rate divides 1 kHz, else `None` (the register keeps its reset value, 1 kHz). The device
/// latches samples at the scene's instants either way.
pub fn sample_rate_divisor(rate_hz: f64) -> Option<u8> {
    let n = 1000.0 / rate_hz;
    ((1.0..=256.0).contains(&n) && n.fract() == 0.0).then(|| (n as u16 - 1) as u8)
}

/// What the driver found while setting the chip up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InitReport {
    /// MPU-9250 WHO_AM_I.
    pub who_am_i: u8,
    /// AK8963 WIA.
    pub ak8963_wia: u8,
    /// The AK8963 sensitivity adjustments the driver read from the fuse ROM.
    pub mag_adjustments: [f32; 3],
    /// Time the driver asked to wait, ms (not slept).
    pub waited_ms: u32,
    /// The conversion the chip applies now (full scales, ASA, offsets).
    pub image: ImageConfig,
}

mod wiring {
    use super::*;
    use embedded_hal_compat::Reverse;
    use std::cell::RefCell;

    type Spi = Reverse<bus::SpiBus<Chip>>;
    type Cs = Reverse<RefCell<bus::ChipSelect<Chip>>>;
    /// The driver on SPI (a bus and a chip-select pin).
    pub type Driver = mpu9250::Mpu9250<mpu9250::SpiDevice<Spi, Cs>, Marg>;

    /// The bus, as named in reports.
    pub const BUS: &str = "SPI";

    /// The driver on the chip, and the bus faults of its bus.
    pub fn connect(
        chip: &Shared<Chip>,
        delay: &mut BootDelay,
        config: &mut MpuConfig<Marg>,
    ) -> Result<(Driver, bus::BusFaultsHandle<Chip>), String> {
        let (spi, cs) = bus::SpiBus::new(chip.clone());
        let faults = spi.faults();
        let driver = Driver::marg(spi.reverse(), cs.reverse_cell(), delay, config)
            .map_err(|e| format!("{e:?}"))?;
        Ok((driver, faults))
    }

    /// Raw register access on the same SPI bus (for the FIFO, which the driver does not read).
    pub struct Registers(bus::SpiDevice<Chip>);

    impl Registers {
        /// On the bus of the driver, sharing its `faults`.
        pub fn new(chip: &Shared<Chip>, faults: bus::BusFaultsHandle<Chip>) -> Self {
            Self(bus::SpiDevice::new(chip.clone()).sharing_faults(faults))
        }

        /// The bus faults.
        pub fn faults(&self) -> bus::BusFaultsHandle<Chip> {
            self.0.faults()
        }

        /// Reads `buf.len()` bytes from `addr` on (one burst; FIFO_R_W does not increment).
        pub fn read(&mut self, addr: u8, buf: &mut [u8]) -> Result<(), String> {
            use embedded_hal::spi::{Operation, SpiDevice as _};
            self.0
                .transaction(&mut [Operation::Write(&[0x80 | addr]), Operation::Read(buf)])
                .map_err(|e| format!("{e:?}"))
        }

        pub fn write(&mut self, addr: u8, value: u8) -> Result<(), String> {
            use embedded_hal::spi::SpiDevice as _;
            self.0.write(&[addr, value]).map_err(|e| format!("{e:?}"))
        }
    }
}

use wiring::Registers;
pub use wiring::{Driver, BUS};

/// The driver's `DelayMs<u8>`: adds up the time asked for, returns at once.
#[derive(Debug, Default)]
pub struct BootDelay {
    waited_ms: u32,
}

impl embedded_hal_02::blocking::delay::DelayMs<u8> for BootDelay {
    fn delay_ms(&mut self, ms: u8) {
        self.waited_ms = self.waited_ms.saturating_add(u32::from(ms));
    }
}

/// The MPU-9250 on the flight controller's bus.
pub struct Board {
    /// The device's chip during a transaction batch; a spare part otherwise.
    slot: Shared<Chip>,
    /// The driver, kept for the life of the board (it owns the bus it set the chip up on).
    _driver: Driver,
    /// Raw register access on the same bus, for the FIFO.
    regs: Registers,
    /// INT_PIN_CFG.ACTL as the board configured it.
    active_low: bool,
    /// USER_CTRL as the board set it (FIFO and I2C master enabled).
    user_ctrl: u8,
    /// The conversion of the chip as the board set it up (full scales, the fuse-ROM ASA).
    conversion: ImageConfig,
    overflows: u64,
}

impl Board {
    /// Sets the device's `chip` up through the driver (see the module docs); `rate_hz` is the
    /// sample rate the board asks for ([`sample_rate_divisor`]).
    pub fn init(chip: &mut Chip, rate_hz: f64) -> Result<(Self, InitReport), String> {
        let slot = bus::shared(Chip::new());
        on_bus(&slot, chip, || {
            let mut config = MpuConfig::marg();
            config
                .accel_scale(ACCEL.0)
                .gyro_scale(GYRO.0)
                .mag_scale(MAG.0)
                .accel_data_rate(AccelDataRate::DlpfConf(Dlpf::_1))
                .gyro_temp_data_rate(GyroTempDataRate::DlpfConf(Dlpf::_1));
            if let Some(div) = sample_rate_divisor(rate_hz) {
                config.sample_rate_divisor(div);
            }
            let mut delay = BootDelay::default();
            let (mut driver, faults) = wiring::connect(&slot, &mut delay, &mut config)?;
            let e = |e| format!("{e:?}");
            let who_am_i = mpu9250::Mpu9250::who_am_i(&mut driver).map_err(e)?;
            let ak8963_wia = driver.ak8963_who_am_i().map_err(e)?;
            // Keep ACTL as the driver set it, latch INT until any read, no bypass: the
            // AK8963 is read by slave 0 into the FIFO.
            let pin = driver.get_interrupt_config().map_err(e)?;
            let pin = InterruptConfig::from_bits_truncate(pin.bits() & !bits::INT_BYPASS_EN)
                | InterruptConfig::LATCH_INT_EN
                | InterruptConfig::INT_ANYRD_CLEAR;
            driver.interrupt_config(pin).map_err(e)?;
            driver
                .enable_interrupts(InterruptEnable::RAW_RDY_EN | InterruptEnable::FIFO_OVERFLOW_EN)
                .map_err(e)?;
            let mut regs = Registers::new(&slot, faults);
            let user_ctrl = fifo_setup(&mut regs)?;
            let conversion = ImageConfig {
                asa: driver.raw_mag_sensitivity_adjustments(),
                ..image_config()
            };
            let report = InitReport {
                who_am_i,
                ak8963_wia,
                mag_adjustments: driver.mag_sensitivity_adjustments(),
                waited_ms: delay.waited_ms,
                image: slot.borrow().image_config(),
            };
            let board = Self {
                slot: slot.clone(),
                _driver: driver,
                regs,
                active_low: pin.contains(InterruptConfig::ACL),
                user_ctrl,
                conversion,
                overflows: 0,
            };
            Ok((board, report))
        })
    }

    /// Whether the INT pin says a new sample is waiting (its level, read like a GPIO).
    pub fn data_ready(&self, chip: &Chip) -> bool {
        chip.int_pin() != self.active_low
    }

    /// Reads every whole record in the FIFO, oldest first (see the module docs); empty after an
    /// overflow, which resets the FIFO and is counted.
    pub fn read(&mut self, chip: &mut Chip) -> Result<Vec<Reading>, String> {
        let Self {
            slot,
            regs,
            user_ctrl,
            conversion,
            overflows,
            ..
        } = self;
        on_bus(slot, chip, || {
            let mut status = [0u8; 1];
            regs.read(reg::INT_STATUS, &mut status)?;
            let mut count = [0u8; 2];
            regs.read(reg::FIFO_COUNTH, &mut count)?;
            let records = fifo::whole_records(u16::from_be_bytes(count));
            let records = match records {
                Some(n) if status[0] & bits::INT_FIFO_OFLOW == 0 => n,
                _ => {
                    *overflows += 1;
                    fifo_reset(regs, *user_ctrl)?;
                    return Ok(Vec::new());
                }
            };
            let mut bytes = vec![0u8; records * MARG_RECORD_LEN];
            if !bytes.is_empty() {
                regs.read(reg::FIFO_R_W, &mut bytes)?;
            }
            Ok(bytes
                .chunks_exact(MARG_RECORD_LEN)
                .filter_map(|r| <&[u8; MARG_RECORD_LEN]>::try_from(r).ok())
                .map(|r| reading(r, conversion))
                .collect())
        })
    }

    /// The bus faults of its SPI bus (the driver's and the FIFO reads').
    pub fn faults(&self) -> bus::BusFaultsHandle<Chip> {
        self.regs.faults()
    }

    /// FIFO overflows so far (each one reset the FIFO).
    pub fn overflows(&self) -> u64 {
        self.overflows
    }
}

/// Slave 0 reads the AK8963's HXL..=ST2 at each sample, the FIFO takes MARG records, and starts
/// empty; USER_CTRL as set.
fn fifo_setup(regs: &mut Registers) -> Result<u8, String> {
    let mut user = [0u8; 1];
    regs.read(reg::USER_CTRL, &mut user)?;
    let user_ctrl = (user[0] | bits::USER_I2C_MST_EN | bits::USER_FIFO_EN)
        & !(bits::USER_FIFO_RST | bits::USER_I2C_MST_RST | bits::USER_SIG_COND_RST);
    // 400 kHz master clock, as the driver sets it on SPI.
    regs.write(reg::I2C_MST_CTRL, 0x0D)?;
    regs.write(reg::I2C_SLV0_ADDR, bits::SLV_RNW | ak8963::I2C_ADDRESS)?;
    regs.write(reg::I2C_SLV0_REG, ak8963::reg::HXL)?;
    regs.write(reg::I2C_SLV0_CTRL, bits::SLV_EN | fifo::SLV0_LEN as u8)?;
    fifo_reset(regs, user_ctrl)?;
    Ok(user_ctrl)
}

/// Stops the FIFO, empties it, and starts it again with MARG records (ArduPilot's
/// `_fifo_reset` does the same steps).
fn fifo_reset(regs: &mut Registers, user_ctrl: u8) -> Result<(), String> {
    regs.write(reg::FIFO_EN, 0)?;
    regs.write(
        reg::USER_CTRL,
        (user_ctrl & !bits::USER_FIFO_EN) | bits::USER_FIFO_RST,
    )?;
    regs.write(reg::USER_CTRL, user_ctrl)?;
    regs.write(reg::FIFO_EN, fifo::FIFO_EN_MARG)
}

/// One FIFO record as a [`Reading`], through the chip module's conversion under `conversion`:
/// m/s² and rad/s in the chip's axes, the field in µT in the AK8963's own axes.
pub fn reading(record: &[u8; MARG_RECORD_LEN], conversion: &ImageConfig) -> Reading {
    let repr = ImageRepr::parse_marg_record(record);
    let physical = repr.to_physical(conversion);
    Reading {
        acc: physical.acc,
        gyro: physical.gyr,
        mag_ut: Some(repr.mag_ut_sensor_axes(conversion)),
    }
}

/// A [`Reading`] of this board in body axes: accelerometer and gyroscope as they are, the
/// magnetometer turned by `alignment`.
pub fn to_body(r: &Reading, alignment: &MagAlignment) -> BodySample {
    BodySample {
        gyro: r.gyro,
        acc: r.acc,
        mag_ut: alignment.apply(r.mag_ut.unwrap_or_default()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use margemu_firmware::chip::PhysicalSample;

    #[test]
    fn divisors_for_rates_that_divide_1_khz() {
        assert_eq!(sample_rate_divisor(200.0), Some(4));
        assert_eq!(sample_rate_divisor(1000.0), Some(0));
        assert_eq!(sample_rate_divisor(1000.0 / 256.0), Some(255));
        assert_eq!(sample_rate_divisor(300.0), None);
        assert_eq!(sample_rate_divisor(2000.0), None);
    }

    fn sample(k: u64) -> PhysicalSample {
        PhysicalSample {
            acc: [1.0, -2.0, 9.80665 + k as f32 * 0.01],
            gyr: [0.5, -1.0, 30.0],
            mag: [20.0, -5.0, -40.0],
            temp_c: 30.0,
        }
    }

    #[test]
    fn the_board_sets_the_chip_up_and_reads_every_sample_from_the_fifo() {
        let mut chip = Chip::new();
        let (mut board, init) = Board::init(&mut chip, 200.0).unwrap();
        assert_eq!((init.who_am_i, init.ak8963_wia), (0x71, 0x48));
        assert_eq!(init.image, image_config());
        assert_eq!(chip.output_rate_hz(), 200.0);
        assert!(!board.data_ready(&chip));
        // Four periods before the board looks: the FIFO keeps them all; the AK8963 (100 Hz)
        // has measured by the second.
        for k in 1..=4 {
            chip.latch_at(&sample(k), k * 5_000_000);
        }
        assert!(board.data_ready(&chip));
        let got = board.read(&mut chip).unwrap();
        assert!(!board.data_ready(&chip), "the read clears INT");
        assert_eq!(got.len(), 4);
        assert!(board.read(&mut chip).unwrap().is_empty());
        for (k, r) in (1..=4).zip(&got) {
            let s = sample(k);
            let body = to_body(r, &MagAlignment::default());
            for i in 0..3 {
                // One LSB: 1/2048 g, 1/16.4 °/s, 0.15 µT.
                assert!((body.acc[i] - f64::from(s.acc[i])).abs() < 5e-3, "{body:?}");
                assert!(
                    (body.gyro[i] - f64::from(s.gyr[i])).abs() < 1.1e-3,
                    "{body:?}"
                );
                if k >= 2 {
                    assert!(
                        (body.mag_ut[i] - f64::from(s.mag[i])).abs() < 0.2,
                        "{body:?}"
                    );
                }
            }
        }
        assert_eq!(board.overflows(), 0);
    }

    #[test]
    fn an_overflow_resets_the_fifo_is_counted_and_reading_resumes() {
        let mut chip = Chip::new();
        let (mut board, _) = Board::init(&mut chip, 200.0).unwrap();
        // 25 records of 21 bytes do not fit in 512.
        for k in 1..=25 {
            chip.latch_at(&sample(k), k * 5_000_000);
        }
        assert!(board.read(&mut chip).unwrap().is_empty());
        assert_eq!(board.overflows(), 1);
        chip.latch_at(&sample(26), 26 * 5_000_000);
        let got = board.read(&mut chip).unwrap();
        assert_eq!(got.len(), 1);
        assert!(
            (got[0].acc[2] - f64::from(sample(26).acc[2])).abs() < 5e-3,
            "{got:?}"
        );
        assert_eq!(board.overflows(), 1);
    }
}
