//! One sample instant (DS: 5.2 DATA_8..19, TEMPERATURE_0/1, STATUS; PWR_CTRL): conversion at
//! the configured ranges, little-endian data, drdy bits, and the atomic swap of the data
//! registers when the bus is idle. A sensor that is off keeps its last data and raises no drdy.

use margemu_protocol::regmap::bmi270::convert::{accel_to_raw, gyro_to_raw, temp_to_raw};
use margemu_protocol::regmap::bmi270::{bits, reg, AccRange, GyrRange, DATA_LEN};

use super::super::PhysicalSample;
use super::{Bmi270, LATCH_LEN};

impl Bmi270 {
    pub(super) fn latch_physical(&mut self, sample: &PhysicalSample, now_ns: u64) {
        self.advance(now_ns);
        let pwr = self.pwr_ctrl();
        let mut latch = self.visible_latch();
        let mut drdy = 0;
        if pwr & bits::ACC_EN != 0 {
            let range = AccRange::from_reg(self.stored(reg::ACC_RANGE));
            put(&mut latch, 0, sample.acc.map(|a| accel_to_raw(a, range)));
            drdy |= bits::DRDY_ACC;
        }
        if pwr & bits::GYR_EN != 0 {
            let range = GyrRange::from_reg(self.stored(reg::GYR_RANGE));
            put(&mut latch, 6, sample.gyr.map(|w| gyro_to_raw(w, range)));
            drdy |= bits::DRDY_GYR;
        }
        if pwr & (bits::TEMP_EN | bits::ACC_EN | bits::GYR_EN) != 0 {
            put(&mut latch, DATA_LEN, [temp_to_raw(sample.temp_c)]);
        }
        self.fifo_push_sample(&latch, drdy);
        if self.spi.is_active() {
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

/// The register of latch byte `i`: 0x0C..=0x17, then TEMPERATURE_0/1.
fn data_address(i: usize) -> u8 {
    if i < DATA_LEN {
        reg::ACC_X_LSB + i as u8
    } else {
        reg::TEMPERATURE_0 + (i - DATA_LEN) as u8
    }
}

/// Little-endian `values` from latch byte `at` on (bytes past the end are dropped).
fn put<const N: usize>(latch: &mut [u8; LATCH_LEN], at: usize, values: [i16; N]) {
    let bytes = values.iter().flat_map(|v| v.to_le_bytes());
    for (slot, byte) in latch.iter_mut().skip(at).zip(bytes) {
        *slot = byte;
    }
}
