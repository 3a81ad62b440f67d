//! QEMU tests of the BMI088: the `qemu-mps2-an386` firmware (Cortex-M4F), configured by the
//! scene's `[chip] model = "bmi088"` as a BMI088 (both dies), must serve every image equal to
//! the host's prediction byte for byte (the CRC-32C of each 14-byte image in its Served
//! reports), in both source modes ([`margemu_tests::qemu_chip`]):
//!
//! - **(a) images** at 400 Hz, a BMI088 gyro ODR;
//! - **(b) model** at 400 Hz from 100 Hz kinematics: the device converts with the BMI088's
//!   conversion at the ranges the Configure's overrides wrote (over each die's own I2C) into
//!   ACC_RANGE of the accelerometer die (register file 0) and GYRO_RANGE of the gyroscope die
//!   (file 1).
//!
//! The scene's `[chip]` is on SPI (chip selects 0 and 1), not at the power-on ranges (±12 g,
//! ±1000 °/s; power-on is ±6 g, ±2000 °/s) and mounted upside down, so an image that passes was
//! converted at the scene's ranges, on both dies, in the chip's axes. Every image is served,
//! whatever the emulated chip then shows a driver (nothing of a die that is off; the accel at
//! its own ODR). The two tests take turns on one lock: one QEMU at a time.
//!
//! Skipped, with a message, where `qemu-system-arm` or a cross toolchain is missing; under
//! `CI=true` that is a failure instead.

use margemu_protocol::chip::{ChipModel, FullScale};
use margemu_tests::qemu_chip::{image_mode, model_mode, ChipCase};

/// The BMI088 on SPI, ±12 g and ±1000 °/s, upside down; 2 s scenes.
const CASE: ChipCase = ChipCase {
    model: ChipModel::Bmi088,
    chip_toml: r#"
[chip]
model = "bmi088"
bus = "spi"
accel_range = 12
gyro_range = 1000
rotation = [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]
"#,
    full_scale: FullScale {
        accel_g: 12.0,
        gyro_dps: 1000.0,
    },
    image_rate_hz: 400,
    model_rate_hz: 400,
    decimation: 4,
    seconds: 2.0,
};

#[test]
fn bmi088_image_mode_serves_the_hosts_images_byte_for_byte() {
    image_mode(&CASE, 88);
}

#[test]
fn bmi088_model_mode_serves_the_hosts_prediction_bit_for_bit() {
    model_mode(&CASE, 89);
}
