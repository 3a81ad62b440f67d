//! WHO_AM_I, PRODUCT_ID, the missing magnetometer and the I2C interface.

use super::*;

#[test]
fn who_am_i_and_product_id() {
    let mut c = chip(Variant::Mpu6000);
    assert_eq!(spi(&mut c, &[0x80 | 0x75, 0x00]), [0x00, 0x68]);
    assert_eq!(spi(&mut c, &[0x80 | 0x0C, 0x00]), [0x00, 0x58], "rev. D8");
    spi_write(&mut c, 0x0C, &[0x14]);
    spi_write(&mut c, 0x75, &[0x12]);
    assert_eq!(spi_read(&mut c, 0x0C, 1), [0x58], "PRODUCT_ID is read only");
    assert_eq!(spi_read(&mut c, 0x75, 1), [0x68]);
}

#[test]
fn no_magnetometer_behind_bypass() {
    let mut c = chip(Variant::Mpu6000);
    assert!(c.ak8963().is_none());
    assert_eq!(i2c_write(&mut c, 0x68, &[0x37, 0x02]), [true, true, true]);
    assert_eq!(i2c_read(&mut c, 0x0C, 0x00, 1), None, "nobody at 0x0C");
}

#[test]
fn i2c_answers_until_i2c_if_dis() {
    let mut c = chip(Variant::Mpu6000);
    assert_eq!(i2c_read(&mut c, 0x68, 0x75, 1), Some(vec![0x68]));
    assert_eq!(i2c_read(&mut c, 0x68, 0x0C, 1), Some(vec![0x58]));
    spi_write(&mut c, 0x6A, &[0x10]); // I2C_IF_DIS
    assert_eq!(i2c_read(&mut c, 0x68, 0x75, 1), None);
    assert_eq!(spi_read(&mut c, 0x6A, 1), [0x10]);
    spi_write(&mut c, 0x6B, &[0x80]);
    assert_eq!(
        i2c_read(&mut c, 0x68, 0x75, 1),
        Some(vec![0x68]),
        "reset re-enables I2C"
    );
}
