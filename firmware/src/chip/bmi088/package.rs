//! [`Bmi088`]: the whole part, both dies in one package, as a device serves it (behind the chip
//! boundary, `boundary.rs`).
//!
//! - **Two chip selects.** Its own [`SpiTarget`] is the accelerometer die (CSB1: the identity
//!   ACC_CHIP_ID 0x1E, the dummy byte, the I2C → SPI switch); [`Bmi088::die_spi_target`] reaches
//!   either die, the gyroscope die (CSB2) as die 1. A rig puts the gyro on the chip select after
//!   the accel's ([`ChipModel::spi_selects`](margemu_protocol::chip::ChipModel::spi_selects)).
//! - **Two I2C addresses.** Its [`I2cTarget`] is the bus both dies sit on: a START reaches each
//!   die, the one strapped to the address acknowledges; reads are the wired AND of the two
//!   (the other die does not drive SDA). The accel answers 0x18 (SDO1 low) or 0x19, the gyro
//!   0x68 or 0x69, both pins strapped alike ([`Config::sdo`]).
//! - **Samples.** An image ([`margemu_protocol::regmap::bmi088::image`]) latches the gyro at
//!   every served sample (the served rate is the gyro's ODR) and the accelerometer only when
//!   one of its own ODR periods (from time 0, on the chip's clock) has begun since its last
//!   sample, as the BMI270 does: at gyro 2 kHz and accel 1.6 kHz the accel takes 4 images of
//!   5. The temperature reaches the registers with an accel sample at most every 1.28 s. A die
//!   that is off (accel: ACC_PWR_CTRL ≠ 0x04; gyro: not in normal mode) takes nothing; its
//!   clock moves on. A physical sample is converted at the ranges in force into the same image.
//!
//! ```
//! use margemu_firmware::chip::bmi088::{Bmi088, Config};
//! use margemu_firmware::chip::{I2cTarget, SpiTarget};
//! let mut chip = Bmi088::new(Config { sdo: true });
//! let read = |chip: &mut Bmi088, address: u8| {
//!     chip.start(address, false);
//!     chip.write(0x00);
//!     chip.start(address, true);
//!     let id = chip.read();
//!     chip.stop();
//!     id
//! };
//! assert_eq!((read(&mut chip, 0x19), read(&mut chip, 0x69)), (0x1E, 0x0F));
//! let gyro = chip.die_spi_target(1).unwrap();
//! gyro.select();
//! assert_eq!(gyro.exchange(0x80), 0x0F); // CHIP_ID clocked out next: no dummy byte
//! gyro.deselect();
//! ```

use margemu_protocol::chip::PhysicalSample;
use margemu_protocol::regmap::bmi088::accel::{reg as acc_reg, AccRange};
use margemu_protocol::regmap::bmi088::gyro::{reg as gyr_reg, Bandwidth, GyroRange};
use margemu_protocol::regmap::bmi088::image::{field, ImageConfig, ImageRepr, IMAGE_LEN};

use super::super::tick::Tick;
use super::super::{I2cTarget, SpiTarget};
use super::{Bmi088Accel, Bmi088Gyro};

/// How the part is wired.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Config {
    /// SDO1 and SDO2 high: I2C 0x19 (accel) and 0x69 (gyro); low: 0x18 and 0x68.
    pub sdo: bool,
}

/// The emulated BMI088 package (see the [module docs](self)).
#[derive(Clone, Debug)]
pub struct Bmi088 {
    config: Config,
    pub(super) accel: Bmi088Accel,
    pub(super) gyro: Bmi088Gyro,
    /// The accelerometer's own rate on the chip's clock, and the period it runs at.
    accel_tick: (Tick, u64),
}

impl Bmi088 {
    /// Both dies just powered on.
    pub fn new(config: Config) -> Self {
        Self {
            config,
            accel: Bmi088Accel::with_sdo(config.sdo),
            gyro: Bmi088Gyro::with_sdo(config.sdo),
            accel_tick: (Tick::default(), 0),
        }
    }

    /// The wiring the part was built with.
    pub fn config(&self) -> Config {
        self.config
    }

    /// The accelerometer die.
    pub fn accel(&self) -> &Bmi088Accel {
        &self.accel
    }

    /// The gyroscope die.
    pub fn gyro(&self) -> &Bmi088Gyro {
        &self.gyro
    }

    /// The SPI target of die `die` (0 the accelerometer on CSB1, 1 the gyroscope on CSB2).
    pub fn die_spi_target(&mut self, die: u8) -> Option<&mut dyn SpiTarget> {
        match die {
            0 => Some(&mut self.accel),
            1 => Some(&mut self.gyro),
            _ => None,
        }
    }

    /// The ranges in force on each die.
    pub fn image_config(&self) -> ImageConfig {
        ImageConfig {
            acc_range: AccRange::from_reg(self.accel.peek(acc_reg::ACC_RANGE)),
            gyr_range: GyroRange::from_reg(self.gyro.peek(gyr_reg::RANGE)),
        }
    }

    /// Latches an image taken at `now_ns` (see the [module docs](self)).
    pub fn latch_image_at(&mut self, image: &[u8; IMAGE_LEN], now_ns: u64) {
        let part = |range: core::ops::Range<usize>| {
            let mut out = [0u8; 6];
            for (o, b) in out.iter_mut().zip(image.get(range).unwrap_or(&[])) {
                *o = *b;
            }
            out
        };
        let (accel, gyro, temp) = (part(field::ACCEL), part(field::GYRO), part(field::TEMP));
        self.gyro.latch_data(gyro, now_ns);
        match self.accel.sample_period_ns() {
            Some(period) if self.accel_takes(now_ns, period) => {
                self.accel.latch_data(accel, [temp[0], temp[1]], now_ns);
            }
            _ => self.accel.advance(now_ns),
        }
    }

    /// Converts `sample` at the ranges in force and latches the image at `now_ns`.
    pub fn latch_at(&mut self, sample: &PhysicalSample, now_ns: u64) {
        let cfg = self.image_config();
        let repr = ImageRepr::from_physical(sample.acc, sample.gyr, sample.temp_c, &cfg);
        self.latch_image_at(&repr.emit(), now_ns);
    }

    /// Moves both dies' clocks to `now_ns`.
    pub fn advance(&mut self, now_ns: u64) {
        self.accel.advance(now_ns);
        self.gyro.advance(now_ns);
    }

    /// The chip's clock (both dies keep the same).
    pub fn now_ns(&self) -> u64 {
        self.gyro.now_ns().max(self.accel.now_ns())
    }

    /// The served sample period: the gyro's ODR in normal mode, else the accel's while it
    /// runs, else the gyro's ODR setting.
    pub fn sample_period_ns(&self) -> u64 {
        self.gyro
            .sample_period_ns()
            .or_else(|| self.accel.sample_period_ns())
            .unwrap_or_else(|| Bandwidth::from_reg(self.gyro.peek(gyr_reg::BANDWIDTH)).period_ns())
    }

    /// The accelerometer's rate divider starts over (after a power cycle).
    pub(super) fn restart_accel_clock(&mut self) {
        self.accel_tick = (Tick::default(), 0);
    }

    /// Whether an accel sample is due at `now_ns` at `period` (the divider restarts when the
    /// period changes).
    fn accel_takes(&mut self, now_ns: u64, period: u64) -> bool {
        let (tick, at) = &mut self.accel_tick;
        if *at != period {
            (*tick, *at) = (Tick::default(), period);
        }
        tick.take(now_ns, period)
    }
}

impl SpiTarget for Bmi088 {
    fn select(&mut self) -> u8 {
        self.accel.select()
    }
    fn exchange(&mut self, mosi: u8) -> u8 {
        self.accel.exchange(mosi)
    }
    fn deselect(&mut self) {
        self.accel.deselect();
    }
}

impl I2cTarget for Bmi088 {
    fn start(&mut self, address: u8, read: bool) -> bool {
        let accel = self.accel.start(address, read);
        let gyro = self.gyro.start(address, read);
        accel || gyro
    }
    fn write(&mut self, byte: u8) -> bool {
        let accel = I2cTarget::write(&mut self.accel, byte);
        let gyro = I2cTarget::write(&mut self.gyro, byte);
        accel || gyro
    }
    fn read(&mut self) -> u8 {
        I2cTarget::read(&mut self.accel) & I2cTarget::read(&mut self.gyro)
    }
    fn stop(&mut self) {
        self.accel.stop();
        self.gyro.stop();
    }
}
