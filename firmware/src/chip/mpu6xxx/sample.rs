//! One sample instant: conversion, the AK8963's schedule, the auxiliary master, the FIFO,
//! RAW_DATA_RDY and the atomic swap of the data registers.
//!
//! Order within a sample (as on the silicon, where the I2C master reads the slaves after the
//! sensor registers are loaded and before data ready when WAIT_FOR_ES is set — the emulation
//! always behaves as if it were, since everything happens in one step):
//! 1. the AK8963 completes the measurements due by `now_ns` (it runs whatever the MPU does);
//! 2. if the MPU's clock runs (not SLEEP, CLKSEL ≠ 7): the new accel/temp/gyro bytes, the slave
//!    reads into EXT_SENS_DATA, the FIFO record, INT_STATUS.RAW_DATA_RDY_INT (set whether or not
//!    it is enabled, so polling drivers see it; the pin follows INT_ENABLE), and the swap.
//!
//! **Sensor rates** (physical samples): the accelerometer takes a new value only at its own
//! internal rate (4 kHz with ACCEL_FCHOICE_B, else 1 kHz; always 1 kHz on the MPU-6000), the
//! gyro at its own (32, 8 or 1 kHz), each decided by a `regmap::mpu6xxx::rates::SensorClock` on
//! the latch instants; the temperature takes every latch. Between a sensor's samples its
//! registers and FIFO bytes repeat the last value, as the RM tables in `rates` describe.
//! Latched at the output rate the gyro takes every latch and the accelerometer repeats when
//! the output rate is above its own. Register images (source mode (a), and the model's images
//! in source mode (b)) follow the same rule: an image is what the sensors would measure at its
//! instant, and the part's own clocks decide which of its values reach the registers and the
//! FIFO, so a driver sees the datasheet's update pattern in every source mode.
//!
//! **Temperature** is converted with the part's own scale (`Variant::temp_to_raw`: 333.87 LSB/°C
//! from 21 °C on the MPU-9250/6500, 340 from 36.53 °C on the MPU-6000, 326.8 from 25 °C on the
//! ICM-20602).

use margemu_protocol::regmap::mpu6xxx::image::{field, ImageRepr, IMAGE_LEN};
use margemu_protocol::regmap::mpu6xxx::{bits, DATA_LEN, SENSOR_LEN};

use super::super::{MagSource, PhysicalSample};
use super::Mpu6xxx;

/// ACCEL_XOUT_H..=ACCEL_ZOUT_L, TEMP_OUT_H..=TEMP_OUT_L and GYRO_XOUT_H..=GYRO_ZOUT_L within
/// the sensor bytes.
const ACCEL: core::ops::Range<usize> = 0..6;
const TEMP: core::ops::Range<usize> = 6..8;
const GYRO: core::ops::Range<usize> = 8..14;

impl Mpu6xxx {
    pub(super) fn latch_physical(&mut self, sample: &PhysicalSample, now_ns: u64) {
        let cfg = self.image_config();
        let repr = ImageRepr::from_physical(sample.acc, sample.gyr, sample.temp_c, [0.0; 3], &cfg);
        let mut sensors = [0u8; SENSOR_LEN];
        repr.emit_sensors(&mut sensors);
        self.sample(&sensors, MagSource::Physical(sample.mag), now_ns, true);
    }

    pub(super) fn latch_registers(&mut self, image: &[u8; IMAGE_LEN], now_ns: u64) {
        let mut sensors = [0u8; SENSOR_LEN];
        sensors.copy_from_slice(&image[field::SENSORS]);
        let mut data = [0u8; 6];
        data.copy_from_slice(&image[field::MAG]);
        let source = MagSource::Registers {
            data,
            st2: image[field::ST2],
        };
        self.sample(&sensors, source, now_ns, true);
    }

    /// One sample instant; `sensor_rates` applies the accelerometer's and the gyro's own rates.
    fn sample(
        &mut self,
        sensors: &[u8; SENSOR_LEN],
        mag: MagSource,
        now_ns: u64,
        sensor_rates: bool,
    ) {
        self.now_ns = self.now_ns.max(now_ns);
        self.latched = true;
        if let Some(ak) = &mut self.ak {
            ak.advance(self.now_ns, mag);
        }
        if !self.is_running() {
            return;
        }
        let mut data: [u8; DATA_LEN] = self.latest_data();
        let (accel_period, gyro_period) = (self.accel_period_ns(), self.gyro_period_ns());
        let accel_new = !sensor_rates || self.accel_clock.take(accel_period, self.now_ns);
        let gyro_new = !sensor_rates || self.gyro_clock.take(gyro_period, self.now_ns);
        for (new, range) in [(accel_new, ACCEL), (true, TEMP), (gyro_new, GYRO)] {
            if new {
                data[range.clone()].copy_from_slice(&sensors[range]);
            }
        }
        self.aux_sample(&mut data[SENSOR_LEN..]);
        self.fifo_push_record(&data);
        if self.fault.fifo_overflow {
            self.fifo_fill(&data);
        }
        self.raise_interrupt(bits::INT_RAW_RDY);
        self.publish_data(data);
    }

    /// Sets `status` bits in INT_STATUS; starts an INT pulse if one of them is enabled.
    pub(super) fn raise_interrupt(&mut self, status: u8) {
        self.int_status |= status;
        if status & self.int_sources() != 0 {
            self.int_pulse_ns = Some(self.now_ns);
        }
    }
}

// The mode (b) path converts through the same function the host uses: keep `ImageRepr` unused
// fields honest by testing the equivalence here.
#[cfg(test)]
mod tests {
    use super::super::Config;
    use super::*;
    use margemu_protocol::regmap::mpu6xxx::image::ImageConfig;

    #[test]
    fn physical_and_image_paths_give_the_same_registers() {
        let sample = PhysicalSample {
            acc: [1.0, -2.0, 9.0],
            gyr: [0.1, 0.2, -0.3],
            mag: [20.0, -5.0, 40.0],
            temp_c: 30.5,
        };
        let mut a = Mpu6xxx::new();
        let mut b = Mpu6xxx::new();
        a.latch_at(&sample, 1_000);
        let cfg = ImageConfig {
            asa: Config::default().asa,
            ..ImageConfig::NOMINAL
        };
        let image =
            ImageRepr::from_physical(sample.acc, sample.gyr, sample.temp_c, sample.mag, &cfg);
        b.latch_image_at(&image.emit(), 1_000);
        for addr in 0..0x80 {
            assert_eq!(a.peek(addr), b.peek(addr), "register {addr:#04x}");
        }
    }
}
