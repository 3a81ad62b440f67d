//! One sample instant (DS: 5.2 DATA_8..19, TEMPERATURE_0/1, STATUS; PWR_CTRL, ACC_CONF,
//! GYR_CONF): which sensors take the latch, little-endian data, drdy bits, and the atomic swap
//! of the data registers when the bus is idle.
//!
//! Nothing changes before the configuration upload has succeeded. A sensor that is off keeps
//! its last data and raises no drdy. The gyro takes every latch (the sample clock is the
//! gyro's ODR); the accelerometer and the temperature take a latch only when one of their own
//! periods has begun (`Tick`): the accel ODR (at most 1.6 kHz) and 10 ms.

use margemu_protocol::regmap::bmi270::image::{field, ImageRepr, IMAGE_LEN};
use margemu_protocol::regmap::bmi270::{bits, reg};

use super::super::tick::Tick;
use super::super::PhysicalSample;
use super::{Bmi270, LATCH_LEN};

/// How often the temperature register is updated, ns (ArduPilot's BMI270 driver: "temperature
/// sensor updated every 10ms"; the BMI160 datasheet says the same of its own).
pub const TEMP_PERIOD_NS: u64 = 10_000_000;

/// The dividers of the slower sensors and of the FIFO's downsampling, restarted by a soft
/// reset and by writes to the registers that set their rates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Ticks {
    pub(super) accel: Tick,
    pub(super) temp: Tick,
    pub(super) fifo_gyro: Tick,
    pub(super) fifo_accel: Tick,
}

impl Bmi270 {
    pub(super) fn latch_physical(&mut self, sample: &PhysicalSample, now_ns: u64) {
        let cfg = self.image_config();
        let repr = ImageRepr::from_physical(sample.acc, sample.gyr, sample.temp_c, &cfg);
        self.latch_image(&repr.emit(), now_ns);
    }

    pub(super) fn latch_image(&mut self, image: &[u8; IMAGE_LEN], now_ns: u64) {
        self.advance(now_ns);
        if !self.is_initialized() {
            return;
        }
        let (now, pwr) = (self.now_ns, self.pwr_ctrl());
        let mut latch = self.visible_latch();
        let mut drdy = 0;
        let accel_period = self.accel_period_ns();
        if pwr & bits::ACC_EN != 0 && self.ticks.accel.take(now, accel_period) {
            copy_field(&mut latch, image, field::ACCEL);
            drdy |= bits::DRDY_ACC;
        }
        if pwr & bits::GYR_EN != 0 {
            copy_field(&mut latch, image, field::GYRO);
            drdy |= bits::DRDY_GYR;
        }
        let temp_on = pwr & (bits::TEMP_EN | bits::ACC_EN | bits::GYR_EN) != 0;
        if temp_on && self.ticks.temp.take(now, TEMP_PERIOD_NS) {
            copy_field(&mut latch, image, field::TEMP);
        }
        self.fifo_push_sample(&latch, drdy);
        self.raise_data_ready(drdy);
        if self.spi.is_active() || self.i2c.is_active() {
            let waiting = self.pending.map_or(0, |(_, d)| d);
            self.pending = Some((latch, drdy | waiting));
        } else {
            self.show(&latch, drdy);
        }
    }

    /// The data and temperature registers as they read now (or as a waiting sample left them).
    fn visible_latch(&self) -> [u8; LATCH_LEN] {
        if let Some((latch, _)) = self.pending {
            return latch;
        }
        let mut latch = [0; LATCH_LEN];
        for (i, byte) in latch.iter_mut().enumerate() {
            *byte = self.stored(data_address(i));
        }
        latch
    }

    /// Writes a latched sample into the registers and raises `drdy` in STATUS.
    pub(super) fn show(&mut self, latch: &[u8; LATCH_LEN], drdy: u8) {
        for (i, &byte) in latch.iter().enumerate() {
            self.set(data_address(i), byte);
        }
        let status = self.stored(reg::STATUS) | drdy;
        self.set(reg::STATUS, status);
    }
}

/// The register of latch (image) byte `i`: 0x0C..=0x17, then TEMPERATURE_0/1.
fn data_address(i: usize) -> u8 {
    if i < field::TEMP.start {
        reg::ACC_X_LSB + i as u8
    } else {
        reg::TEMPERATURE_0 + (i - field::TEMP.start) as u8
    }
}

/// Copies the bytes of `range` from `image` into `latch`.
fn copy_field(
    latch: &mut [u8; LATCH_LEN],
    image: &[u8; IMAGE_LEN],
    range: core::ops::Range<usize>,
) {
    if let (Some(to), Some(from)) = (latch.get_mut(range.clone()), image.get(range)) {
        to.copy_from_slice(from);
    }
}
