//! The MPU-9250 board: the emulated MPU-9250 on its bus, driven by the unmodified `mpu9250`
//! crate (embedded-hal 0.2) through margemu's embedded-hal 1.0 adapters ([`crate::bus`]) and
//! `embedded-hal-compat`.
//!
//! **Bus.** SPI in MARG mode (the AK8963 behind the chip's auxiliary I2C master, read with the
//! accelerometer and gyroscope in one 21-byte burst), as flight controllers wire it. (The
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
//! read). [`Board::data_ready`] reads that pin's level, as a GPIO. The driver's delays do not
//! sleep and do not move the chip's clock (the device's scene clock): the emulated chip needs
//! no settling time, and the time asked for is reported.
//!
//! **Axes.** The body frame is the MPU-9250's accel/gyro frame; the AK8963's reading is turned
//! into it with the configured [`MagAlignment`] ([`to_body`], [`crate::vfc::axes`]).

use super::Reading;
use crate::bus::{self, Shared};
use crate::vfc::axes::{BodySample, MagAlignment};
use embedded_hal_compat::ReverseCompat;
use margemu_firmware::chip::Mpu6xxx as Chip;
use margemu_protocol::regmap::ak8963::MagBits;
use margemu_protocol::regmap::mpu6xxx::image::ImageConfig;
use margemu_protocol::regmap::mpu6xxx::{AccelFs, GyroFs};
use mpu9250::{
    AccelDataRate, AccelScale, Dlpf, GyroScale, GyroTempDataRate, InterruptConfig, InterruptEnable,
    MagScale, Marg, MargMeasurements, MpuConfig,
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

    pub fn connect(
        chip: &Shared<Chip>,
        delay: &mut BootDelay,
        config: &mut MpuConfig<Marg>,
    ) -> Result<Driver, String> {
        let (spi, cs) = bus::SpiBus::new(chip.clone());
        Driver::marg(spi.reverse(), cs.reverse_cell(), delay, config).map_err(|e| format!("{e:?}"))
    }
}

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
    driver: Driver,
    /// INT_PIN_CFG.ACTL as the board configured it.
    active_low: bool,
}

/// Runs `f` with the device's `chip` in `slot` (the adapters' target), then puts it back.
fn on_bus<R>(slot: &Shared<Chip>, chip: &mut Chip, f: impl FnOnce() -> R) -> R {
    std::mem::swap(chip, &mut *slot.borrow_mut());
    let result = f();
    std::mem::swap(chip, &mut *slot.borrow_mut());
    result
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
            let mut driver = wiring::connect(&slot, &mut delay, &mut config)?;
            let e = |e| format!("{e:?}");
            let who_am_i = mpu9250::Mpu9250::who_am_i(&mut driver).map_err(e)?;
            let ak8963_wia = driver.ak8963_who_am_i().map_err(e)?;
            // Keep what the driver set (bypass and ACTL on I2C), latch INT until any read.
            let pin = driver.get_interrupt_config().map_err(e)?;
            driver
                .interrupt_config(
                    pin | InterruptConfig::LATCH_INT_EN | InterruptConfig::INT_ANYRD_CLEAR,
                )
                .map_err(e)?;
            driver
                .enable_interrupts(InterruptEnable::RAW_RDY_EN)
                .map_err(e)?;
            let report = InitReport {
                who_am_i,
                ak8963_wia,
                mag_adjustments: driver.mag_sensitivity_adjustments(),
                waited_ms: delay.waited_ms,
                image: slot.borrow().image_config(),
            };
            let board = Self {
                slot: slot.clone(),
                driver,
                active_low: pin.contains(InterruptConfig::ACL),
            };
            Ok((board, report))
        })
    }

    /// Whether the INT pin says a new sample is waiting (its level, read like a GPIO).
    pub fn data_ready(&self, chip: &Chip) -> bool {
        chip.int_pin() != self.active_low
    }

    /// Reads accelerometer, temperature, gyroscope and magnetometer with the driver's burst
    /// (`all`), in the driver's units (see [`crate::vfc::axes`]); the read clears INT.
    pub fn read(&mut self, chip: &mut Chip) -> Result<MargMeasurements<[f32; 3]>, String> {
        let Self { slot, driver, .. } = self;
        on_bus(slot, chip, || {
            driver.all::<[f32; 3]>().map_err(|e| format!("{e:?}"))
        })
    }
}

/// The driver's burst as a [`Reading`]: m/s² and rad/s in the chip's axes, the field in µT in
/// the AK8963's axes (the driver gives milligauss; 1 µT = 10 mG).
pub fn reading(m: &MargMeasurements<[f32; 3]>) -> Reading {
    let wide = |v: [f32; 3]| v.map(f64::from);
    Reading {
        acc: wide(m.accel),
        gyro: wide(m.gyro),
        mag_ut: Some(wide(m.mag).map(|mg| mg * 0.1)),
    }
}

/// A [`Reading`] of this board in body axes: accelerometer and gyroscope as they are, the
/// magnetometer turned by `alignment` (the same values as [`crate::vfc::axes::to_body`] of the driver's
/// burst).
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

    #[test]
    fn the_driver_sets_the_chip_up_and_reads_a_latched_sample() {
        let mut chip = Chip::new();
        let (mut board, init) = Board::init(&mut chip, 200.0).unwrap();
        assert_eq!((init.who_am_i, init.ak8963_wia), (0x71, 0x48));
        assert_eq!(init.image, image_config());
        assert_eq!(chip.output_rate_hz(), 200.0);
        assert!(!board.data_ready(&chip));
        let sample = PhysicalSample {
            acc: [1.0, -2.0, 9.80665],
            gyr: [0.5, -1.0, 30.0],
            mag: [20.0, -5.0, -40.0],
            temp_c: 30.0,
        };
        // Two periods: the AK8963 (100 Hz) measures by then.
        for k in 1..=2 {
            chip.latch_at(&sample, k * 10_000_000);
        }
        assert!(board.data_ready(&chip));
        let m = board.read(&mut chip).unwrap();
        assert!(!board.data_ready(&chip), "the read clears INT");
        let body = crate::vfc::axes::to_body(m.accel, m.gyro, m.mag, &Default::default());
        assert_eq!(to_body(&reading(&m), &Default::default()), body);
        for i in 0..3 {
            assert!(
                (body.acc[i] - f64::from(sample.acc[i])).abs() < 0.01,
                "{body:?}"
            );
            assert!(
                (body.gyro[i] - f64::from(sample.gyr[i])).abs() < 0.04,
                "{body:?}"
            );
            assert!(
                (body.mag_ut[i] - f64::from(sample.mag[i])).abs() < 0.2,
                "{body:?}"
            );
        }
    }
}
