//! One sample instant: conversion, sensors that are off, the FIFO packet, DATA_RDY_INT and the
//! atomic swap of the data registers (DS 4.11 Sensor Data
//! Registers, 4.16 Standard Power Modes, FIFO, PWR_MGMT0).
//!
//! A sensor that is off (PWR_MGMT0: gyro not in low-noise mode, accel not in a low-power or
//! low-noise mode, temperature disabled or both off) reads −32768 (0x8000), in the data
//! registers and in the FIFO (20-bit: −524288). Turning a sensor off writes 0x8000 at once.
//! A running gyro's new values pass through AFSR (`afsr.rs`), which may hold an axis.

use margemu_protocol::regmap::icm42688p::convert::{INVALID16, INVALID20};
use margemu_protocol::regmap::icm42688p::image::{field, ImageRepr, IMAGE_LEN};
use margemu_protocol::regmap::icm42688p::{bits, DATA_LEN};

use super::super::PhysicalSample;
use super::fifo::PacketSource;
use super::Icm42688p;

impl Icm42688p {
    pub(super) fn latch_physical(&mut self, sample: &PhysicalSample, now_ns: u64) {
        let cfg = self.image_config();
        let repr = ImageRepr::from_physical(sample.acc, sample.gyr, sample.temp_c, &cfg);
        self.sample(&repr.emit(), now_ns);
    }

    pub(super) fn latch_registers(&mut self, image: &[u8; IMAGE_LEN], now_ns: u64) {
        self.sample(image, now_ns);
    }

    fn sample(&mut self, image: &[u8; IMAGE_LEN], now_ns: u64) {
        self.now_ns = self.now_ns.max(now_ns);
        if !self.is_running() {
            return;
        }
        let repr = ImageRepr::parse(image);
        let mut data = [0u8; DATA_LEN];
        data.copy_from_slice(&image[field::REGISTERS]);
        self.invalidate_off_sensors(&mut data);
        let mut hires: [i32; 6] = core::array::from_fn(|i| {
            if i < 3 {
                repr.accel20[i]
            } else {
                repr.gyro20[i - 3]
            }
        });
        if !self.accel_on() {
            hires[..3].fill(INVALID20);
        }
        if self.gyro_on() {
            let mut gyro20 = [hires[3], hires[4], hires[5]];
            self.afsr_apply(&mut data, &mut gyro20);
            hires[3..].copy_from_slice(&gyro20);
        } else {
            hires[3..].fill(INVALID20);
        }
        self.fifo_push_sample(&PacketSource { data: &data, hires });
        self.raise_interrupt(bits::DATA_RDY_INT);
        self.publish_data(data);
    }

    /// Writes −32768 into the fields of the sensors that are off.
    fn invalidate_off_sensors(&self, data: &mut [u8; DATA_LEN]) {
        let invalid = INVALID16.to_be_bytes();
        let fields = [
            (self.temp_on(), field::TEMP),
            (self.accel_on(), field::ACCEL),
            (self.gyro_on(), field::GYRO),
        ];
        for (on, range) in fields {
            if !on {
                if let Some(bytes) = data.get_mut(range) {
                    for pair in bytes.chunks_exact_mut(2) {
                        pair.copy_from_slice(&invalid);
                    }
                }
            }
        }
    }

    /// PWR_MGMT0 was written: the data registers of sensors now off read −32768.
    pub(super) fn power_changed(&mut self) {
        let mut data = self.latest_data();
        let before = data;
        self.invalidate_off_sensors(&mut data);
        if data != before {
            self.publish_data(data);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::super::SpiTarget;
    use super::*;
    use margemu_protocol::regmap::icm42688p::image::ImageConfig;

    fn power_on(chip: &mut Icm42688p) {
        chip.select();
        chip.exchange(0x4E);
        chip.exchange(0x0F);
        chip.deselect();
    }

    #[test]
    fn physical_and_image_paths_give_the_same_registers() {
        let sample = PhysicalSample {
            acc: [1.0, -2.0, 9.0],
            gyr: [0.1, 0.2, -0.3],
            mag: [0.0; 3],
            temp_c: 30.5,
        };
        let mut a = Icm42688p::new();
        let mut b = Icm42688p::new();
        power_on(&mut a);
        power_on(&mut b);
        a.latch_at(&sample, 1_000);
        let image =
            ImageRepr::from_physical(sample.acc, sample.gyr, sample.temp_c, &ImageConfig::NOMINAL);
        b.latch_image_at(&image.emit(), 1_000);
        for bank in 0..5 {
            for addr in 0..0x80 {
                assert_eq!(a.peek(bank, addr), b.peek(bank, addr), "{bank}:{addr:#04x}");
            }
        }
    }
}
