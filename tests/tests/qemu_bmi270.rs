//! QEMU tests of the BMI270: the `qemu-mps2-an386` firmware (Cortex-M4F), configured by the
//! scene's `[chip] model = "bmi270"` as a BMI270, must serve every image equal to the host's
//! prediction byte for byte (the CRC-32C of each 14-byte image in its Served reports), in both
//! source modes ([`margemu_tests::qemu_chip`]):
//!
//! - **(a) images** at 400 Hz, a BMI270 gyro ODR (5.6 kB/s of images, about what
//!   `qemu_stream`'s 250 Hz of 22-byte images carries);
//! - **(b) model** at 400 Hz from 100 Hz kinematics: the device converts with the BMI270's
//!   conversion at the ranges the Configure's overrides wrote (over the chip's own I2C) into
//!   ACC_RANGE and GYR_RANGE of its emulated chip.
//!
//! The scene's `[chip]` is on I2C at 0x69 (SDO high), not at the power-on ranges (±4 g,
//! ±500 °/s; power-on is ±8 g, ±2000 °/s) and mounted upside down, so an image that passes was
//! converted at the scene's ranges in the chip's axes. Every image is served, whatever the
//! emulated chip then shows a driver (nothing before its configuration upload; the accel at its
//! own ODR). The two tests take turns on one lock: one QEMU at a time.
//!
//! Skipped, with a message, where `qemu-system-arm` or a cross toolchain is missing; under
//! `CI=true` that is a failure instead.

use margemu_protocol::chip::{ChipModel, FullScale};
use margemu_tests::qemu_chip::{image_mode, model_mode, ChipCase};

/// The BMI270 on I2C at 0x69, ±4 g and ±500 °/s, upside down; 2 s scenes.
const CASE: ChipCase = ChipCase {
    model: ChipModel::Bmi270,
    chip_toml: r#"
[chip]
model = "bmi270"
bus = "i2c"
address = 0x69
accel_range = 4
gyro_range = 500
rotation = [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]
"#,
    full_scale: FullScale {
        accel_g: 4.0,
        gyro_dps: 500.0,
    },
    image_rate_hz: 400,
    model_rate_hz: 400,
    decimation: 4,
    seconds: 2.0,
};

#[test]
fn bmi270_image_mode_serves_the_hosts_images_byte_for_byte() {
    image_mode(&CASE, 27);
}

#[test]
fn bmi270_model_mode_serves_the_hosts_prediction_bit_for_bit() {
    model_mode(&CASE, 31);
}
