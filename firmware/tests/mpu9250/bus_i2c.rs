//! I2C target: address and AD0, register pointer, repeated START, bursts, I2C_IF_DIS, bypass
//! (PS sections 7.3–7.4, RM INT_PIN_CFG and USER_CTRL).

use super::*;

#[test]
fn address_0x68_and_0x69_with_ad0() {
    let mut low = chip();
    assert_eq!(i2c_read(&mut low, 0x68, 0x75, 1), Some(vec![0x71]));
    assert_eq!(i2c_read(&mut low, 0x69, 0x75, 1), None);
    let mut high = Mpu6xxx::with_config(Config {
        ad0: true,
        ..Config::default()
    });
    assert_eq!(i2c_read(&mut high, 0x69, 0x75, 1), Some(vec![0x71]));
    assert_eq!(i2c_read(&mut high, 0x68, 0x75, 1), None);
}

#[test]
fn bytes_after_a_nack_are_ignored() {
    let mut c = chip();
    assert_eq!(
        i2c_write(&mut c, 0x50, &[0x19, 0x07]),
        [false, false, false]
    );
    assert_eq!(c.read(), 0xFF);
    assert_eq!(i2c_read(&mut c, 0x68, 0x19, 1), Some(vec![0x00]));
}

#[test]
fn pointer_write_burst_and_repeated_start_read() {
    let mut c = chip();
    assert_eq!(
        i2c_write(&mut c, 0x68, &[0x19, 0x07, 0x01, 0x08]),
        [true; 5]
    );
    assert_eq!(
        i2c_read(&mut c, 0x68, 0x19, 3),
        Some(vec![0x07, 0x01, 0x08])
    );
    // The pointer survives a STOP: a read without a pointer write continues after 0x1B.
    assert!(c.start(0x68, true));
    assert_eq!(c.read(), 0x00); // 0x1C
    c.stop();
}

#[test]
fn pointer_keeps_seven_bits_and_ports_do_not_increment() {
    let mut c = chip();
    assert_eq!(i2c_write(&mut c, 0x68, &[0x80 | 0x74, 1, 2]), [true; 4]); // FIFO_R_W twice
    assert_eq!(
        i2c_read(&mut c, 0x68, 0x72, 3),
        Some(vec![0x00, 0x02, 0x01])
    );
    assert_eq!(i2c_read(&mut c, 0x68, 0x74, 1), Some(vec![0x02]));
}

#[test]
fn i2c_if_dis_silences_the_mpu_until_reset() {
    let mut c = chip();
    spi_write(&mut c, 0x6A, &[0x10]);
    assert_eq!(i2c_read(&mut c, 0x68, 0x75, 1), None);
    spi_write(&mut c, 0x6B, &[0x80]);
    assert_eq!(i2c_read(&mut c, 0x68, 0x75, 1), Some(vec![0x71]));
}

#[test]
fn bypass_exposes_the_ak8963_only_with_the_master_off() {
    let mut c = chip();
    assert_eq!(
        i2c_read(&mut c, 0x0C, 0x00, 1),
        None,
        "bypass off after reset"
    );
    assert_eq!(i2c_write(&mut c, 0x68, &[0x37, 0x02]), [true; 3]); // BYPASS_EN
    assert!(c.bypass_active());
    assert_eq!(i2c_read(&mut c, 0x0C, 0x00, 1), Some(vec![0x48]));
    assert_eq!(i2c_write(&mut c, 0x68, &[0x6A, 0x20]), [true; 3]); // I2C_MST_EN
    assert_eq!(i2c_read(&mut c, 0x0C, 0x00, 1), None);
    assert_eq!(i2c_write(&mut c, 0x68, &[0x6A, 0x00]), [true; 3]);
    assert_eq!(i2c_read(&mut c, 0x0C, 0x00, 2), Some(vec![0x48, 0x00]));
}

#[test]
fn no_bypass_on_a_part_without_magnetometer() {
    let mut c = Mpu6xxx::with_config(Config {
        variant: margemu_firmware::chip::Variant::Mpu6500,
        ..Config::default()
    });
    i2c_write(&mut c, 0x68, &[0x37, 0x02]);
    assert_eq!(i2c_read(&mut c, 0x0C, 0x00, 1), None);
}

#[test]
fn bypass_writes_reach_the_ak8963() {
    let mut c = chip();
    i2c_write(&mut c, 0x68, &[0x37, 0x02]);
    assert_eq!(i2c_write(&mut c, 0x0C, &[0x0A, 0x16]), [true; 3]); // CNTL1
    assert_eq!(i2c_read(&mut c, 0x0C, 0x0A, 1), Some(vec![0x16]));
}
