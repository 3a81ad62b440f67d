//! QEMU tests of the ICM-42688-P: the `qemu-mps2-an386` firmware (Cortex-M4F), configured by the
//! scene's `[chip] model = "icm42688p"` as an ICM-42688-P, must serve every image equal to the
//! host's prediction byte for byte (the CRC-32C of each 32-byte image in its Served reports), in
//! both source modes ([`margemu_tests::qemu_chip`]):
//!
//! - **(a) images**, as `qemu_stream` does for the MPU-9250: the host's 32-byte ICM images at
//!   200 Hz (an ICM ODR; 6.4 kB/s of images, about what `qemu_stream`'s 250 Hz of 22-byte images
//!   carries); the device latches them into its emulated ICM-42688-P.
//! - **(b) model**, as `qemu_model` does: the host sends the truth as Kinematics at 100 Hz; the
//!   device runs the shared sensor model at the ICM's 500 Hz ODR and converts with the ICM's
//!   conversion at the full scales the Configure's overrides wrote into GYRO_CONFIG0 and
//!   ACCEL_CONFIG0 of its emulated chip.
//!
//! The scene's `[chip]` is not the power-on one: ±8 g and ±1000 °/s, and mounted turned 90°
//! about z, so an image that passes was converted at the scene's full scales in the chip's axes.
//! The two tests take turns on one lock: one QEMU at a time.
//!
//! Skipped, with a message, where `qemu-system-arm` or a cross toolchain is missing; under
//! `CI=true` that is a failure instead.

use margemu_protocol::chip::{ChipModel, FullScale};
use margemu_tests::qemu_chip::{image_mode, model_mode, ChipCase};

/// The ICM-42688-P on SPI, not at its power-on full scales, turned 90° about z; 2 s scenes.
const CASE: ChipCase = ChipCase {
    model: ChipModel::Icm42688p,
    chip_toml: r#"
[chip]
model = "icm42688p"
bus = "spi"
accel_range = 8
gyro_range = 1000
rotation = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
"#,
    full_scale: FullScale {
        accel_g: 8.0,
        gyro_dps: 1000.0,
    },
    image_rate_hz: 200,
    model_rate_hz: 500,
    decimation: 5,
    seconds: 2.0,
};

#[test]
fn icm42688p_image_mode_serves_the_hosts_images_byte_for_byte() {
    image_mode(&CASE, 13);
}

#[test]
fn icm42688p_model_mode_serves_the_hosts_prediction_bit_for_bit() {
    model_mode(&CASE, 17);
}
