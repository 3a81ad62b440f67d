//! Identity, reset values, missing and extra registers, I2C_IF, SIGNAL_PATH_RESET, USER_CTRL and
//! the temperature scale (DS-000176 sections 9–11).

use super::*;
use margemu_firmware::chip::Config;

#[test]
fn identity_and_reset_values() {
    let c = Mpu6xxx::with_config(Config {
        variant: Variant::Icm20602,
        self_test: [1, 2, 3, 4, 5, 6],
        accel_offset: [0x1234, 0x5678, 0x9ABC],
        ..Config::default()
    });
    assert!(c.ak8963().is_none());
    assert_registers(&c, |addr| match addr {
        0x0D..=0x0F => addr as u8 - 0x0D + 4, // SELF_TEST_X/Y/Z_ACCEL
        0x1A => 0x80,                         // CONFIG
        0x50..=0x52 => addr as u8 - 0x50 + 1, // SELF_TEST_X/Y/Z_GYRO
        0x6B => 0x41,                         // asleep, CLKSEL 1
        0x75 => 0x12,
        0x77 => 0x12,
        0x78 => 0x34,
        0x7A => 0x56,
        0x7B => 0x78,
        0x7D => 0x9A,
        0x7E => 0xBC,
        _ => 0x00,
    });
}

#[test]
fn clock_read_back_and_reset() {
    let mut c = awake();
    assert_eq!(spi_read(&mut c, 0x6B, 1), [0x01]);
    spi_write(&mut c, 0x6B, &[0x03]);
    assert_eq!(spi_read(&mut c, 0x6B, 1), [0x03]);
    spi_write(&mut c, 0x6B, &[0x80]);
    assert_eq!(spi_read(&mut c, 0x6B, 1), [0x41]);
    assert_eq!(spi_read(&mut c, 0x1A, 1), [0x80]);
}

#[test]
fn no_auxiliary_master_ext_sens_data_or_dmp() {
    let mut c = awake();
    // I2C_MST_CTRL, slave 0, slave 4, I2C_SLV0_DO, I2C_MST_DELAY_CTRL, BANK_SEL..MEM_R_W.
    let absent = [
        0x24, 0x25, 0x27, 0x31, 0x34, 0x63, 0x67, 0x6D, 0x6E, 0x6F, 0x00, 0x0C,
    ];
    assert_writes_ignored(&mut c, &absent, 0x8C);
    spi_write(&mut c, 0x6A, &[0x20]); // I2C_MST_EN: reserved here, nothing starts
    c.latch_at(&numbered(3), MS);
    assert_eq!(spi_read(&mut c, 0x49, 7), [0; 7], "no EXT_SENS_DATA");
    assert_eq!(spi_read(&mut c, 0x53, 13), [0; 13], "no EXT_SENS_DATA");
    assert_eq!(
        spi_read(&mut c, 0x36, 1),
        [0x00],
        "FSYNC_INT, not I2C_MST_STATUS"
    );
}

#[test]
fn extra_registers_are_read_write() {
    let mut c = awake();
    spi_write(&mut c, 0x20, &[0x11, 0x22, 0x33]); // ACCEL_WOM_X/Y/Z_THR
    spi_write(&mut c, 0x60, &[0x03, 0xF0]); // FIFO_WM_TH1/2
    spi_write(&mut c, 0x50, &[0xAA]); // SELF_TEST_X_GYRO
    spi_write(&mut c, 0x1D, &[0xF8]); // FIFO_SIZE, DEC2_CFG, ACCEL_FCHOICE_B
    spi_write(&mut c, 0x11, &[0xC9]); // undocumented; ArduPilot writes and checks 0xC9
    c.latch_at(&numbered(3), MS);
    assert_eq!(spi_read(&mut c, 0x20, 3), [0x11, 0x22, 0x33]);
    assert_eq!(
        spi_read(&mut c, 0x60, 2),
        [0x03, 0xF0],
        "not overwritten by a sample"
    );
    assert_eq!(spi_read(&mut c, 0x50, 1), [0xAA]);
    assert_eq!(spi_read(&mut c, 0x1D, 1), [0xF8]);
    assert_eq!(spi_read(&mut c, 0x11, 1), [0xC9]);
    assert_eq!(c.accel_period_ns(), 250_000);
}

#[test]
fn i2c_if_dis_in_either_register() {
    let mut c = chip(Variant::Icm20602);
    assert_eq!(i2c_read(&mut c, 0x68, 0x75, 1), Some(vec![0x12]));
    spi_write(&mut c, 0x70, &[0x40]); // I2C_IF.I2C_IF_DIS
    assert_eq!(i2c_read(&mut c, 0x68, 0x75, 1), None);
    assert_eq!(spi_read(&mut c, 0x70, 1), [0x40]);
    spi_write(&mut c, 0x70, &[0x00]);
    spi_write(&mut c, 0x6A, &[0x10]); // USER_CTRL.I2C_IF_DIS
    assert_eq!(i2c_read(&mut c, 0x68, 0x75, 1), None);
}

#[test]
fn signal_path_and_user_ctrl_resets() {
    let mut c = awake();
    spi_write(&mut c, 0x68, &[0x07]);
    assert_eq!(
        spi_read(&mut c, 0x68, 1),
        [0x04],
        "ACCEL_RST, TEMP_RST self-clear; bit 2 kept"
    );
    spi_write(&mut c, 0x6A, &[0x47]);
    assert_eq!(
        spi_read(&mut c, 0x6A, 1),
        [0x42],
        "FIFO_RST, SIG_COND_RST self-clear"
    );
}

#[test]
fn temperature_scale() {
    // TEMP_OUT / 326.8 + 25 °C: 25 °C → 0, 35 °C → 3268, 0 °C → −8170.
    let mut c = awake();
    assert_temperature_scale(&mut c, [(25.0f32, 0i16), (35.0, 3268), (0.0, -8170)]);
}
