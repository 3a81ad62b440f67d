//! Reset values, missing registers, PWR_MGMT_1 (reset to sleep, clock read-back) and
//! SIGNAL_PATH_RESET (RM-MPU-6000A sections 3, 4.28, 4.30).

use super::*;
use margemu_firmware::chip::Config;

#[test]
fn reset_values_with_the_factory_trim() {
    let c = Mpu6xxx::with_config(Config {
        variant: Variant::Mpu6000,
        self_test: [1, 2, 3, 4, 5, 6],
        accel_offset: [0x1234, 0x5678, 0x9ABC],
        ..Config::default()
    });
    assert_registers(&c, |addr| match addr {
        0x06 => 0x12, // XA_OFFS_H
        0x07 => 0x34,
        0x08 => 0x56,
        0x09 => 0x78,
        0x0A => 0x9A,
        0x0B => 0xBC,
        0x0C => 0x58,                     // PRODUCT_ID
        0x0D..=0x10 => addr as u8 - 0x0C, // SELF_TEST_X/Y/Z/A
        0x6B => 0x40,                     // asleep, internal oscillator
        0x75 => 0x68,
        _ => 0x00,
    });
}

#[test]
fn missing_registers_read_zero_and_ignore_writes() {
    let mut c = awake();
    // ACCEL_CONFIG2, LP_ACCEL_ODR (MPU-6500 and later), I2C_IF (ICM-20602), the MPU-6500's
    // accel offsets 0x77.., the reserved top.
    let absent = [0x1D, 0x1E, 0x70, 0x71, 0x76, 0x77, 0x78, 0x7A, 0x7D, 0x7F];
    assert_writes_ignored(&mut c, &absent, 0xA5);
    // A burst crosses them: 0x1C, 0x1D (gone), 0x1E (gone), 0x1F.
    spi_write(&mut c, 0x1C, &[0x18, 0x08, 0x01, 0x22]);
    assert_eq!(spi_read(&mut c, 0x1C, 4), [0x18, 0x00, 0x00, 0x22]);
}

#[test]
fn h_reset_goes_to_sleep_and_self_clears() {
    let mut c = awake();
    spi_write(&mut c, 0x1B, &[0x18]);
    spi_write(&mut c, 0x06, &[0x00, 0x00]);
    spi_write(&mut c, 0x6B, &[0x80]);
    assert_eq!(
        spi_read(&mut c, 0x6B, 1),
        [0x40],
        "DEVICE_RESET reads 0, SLEEP set"
    );
    assert_eq!(registers(&c), registers(&chip(Variant::Mpu6000)));
    c.latch_at(&numbered(5), MS);
    assert_eq!(spi_read(&mut c, 0x3A, 1), [0x00], "asleep: no data ready");
    assert_eq!(spi_read(&mut c, 0x43, 2), [0x00, 0x00]);
}

#[test]
fn clock_select_reads_back_and_wakes() {
    let mut c = chip(Variant::Mpu6000);
    spi_write(&mut c, 0x6B, &[0x03]); // PLL with gyro Z, SLEEP cleared
    assert_eq!(spi_read(&mut c, 0x6B, 1), [0x03]);
    assert!(c.is_running());
    spi_write(&mut c, 0x1B, &[0x18]);
    c.latch_at(&numbered(5), MS);
    assert_eq!(spi_read(&mut c, 0x3A, 1), [0x01]);
    assert_eq!(spi_read(&mut c, 0x43, 2), [0x00, 0x05]);
    spi_write(&mut c, 0x6B, &[0x07]);
    assert_eq!(spi_read(&mut c, 0x6B, 1), [0x07]);
    assert!(!c.is_running(), "CLKSEL 7 stops the clock");
}

#[test]
fn signal_path_reset_self_clears_and_restarts_the_accelerometer() {
    let mut c = awake();
    spi_write(&mut c, 0x1C, &[0x18]);
    spi_write(&mut c, 0x1B, &[0x18]);
    c.latch_at(&numbered(1), 8 * 125_000);
    c.latch_at(&numbered(2), 9 * 125_000);
    assert_eq!(
        spi_read(&mut c, 0x3B, 2),
        [0x00, 0x01],
        "same accel period: held"
    );
    spi_write(&mut c, 0x68, &[0x07]);
    assert_eq!(
        spi_read(&mut c, 0x68, 1),
        [0x00],
        "GYRO/ACCEL/TEMP_RESET self-clear"
    );
    assert_eq!(
        spi_read(&mut c, 0x43, 2),
        [0x00, 0x02],
        "data registers kept"
    );
    c.latch_at(&numbered(3), 10 * 125_000);
    assert_eq!(
        spi_read(&mut c, 0x3B, 2),
        [0x00, 0x03],
        "restarted: a new accel value"
    );
    spi_write(&mut c, 0x68, &[0xF8]);
    assert_eq!(
        spi_read(&mut c, 0x68, 1),
        [0xF8],
        "reserved bits 7:3 stored"
    );
}

#[test]
fn temperature_scale() {
    // TEMP_OUT / 340 + 36.53 °C (RM section 4.18): 36.53 °C → 0, 46.53 °C → 3400,
    // 25 °C → −3920.2 → −3920.
    let mut c = awake();
    assert_temperature_scale(&mut c, [(36.53f32, 0i16), (46.53, 3400), (25.0, -3920)]);
}
