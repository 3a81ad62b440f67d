//! Identity, reset values, SIGNAL_PATH_RESET and the 512-byte FIFO of the MPU-6500.

use super::*;

#[test]
fn identity_and_reset_values() {
    let mut c = chip(Variant::Mpu6500);
    assert_eq!(spi(&mut c, &[0x80 | 0x75, 0x00]), [0x00, 0x70]);
    assert!(c.ak8963().is_none());
    let mpu9250 = registers(&chip(Variant::Mpu9250));
    for (addr, (a, b)) in registers(&c).into_iter().zip(mpu9250).enumerate() {
        if addr != 0x75 {
            assert_eq!(a, b, "register {addr:#04x}: same die as the MPU-9250");
        }
    }
    assert_eq!(c.peek(0x6B), 0x01, "awake after reset, unlike the MPU-6000");
    spi_write(&mut c, 0x6B, &[0x80]);
    assert_eq!(spi_read(&mut c, 0x6B, 1), [0x01]);
    spi_write(&mut c, 0x6B, &[0x03]);
    assert_eq!(spi_read(&mut c, 0x6B, 1), [0x03], "clock select reads back");
}

#[test]
fn signal_path_reset_restarts_the_accelerometer() {
    let mut c = chip(Variant::Mpu6500);
    spi_write(&mut c, 0x1B, &[0x18]);
    spi_write(&mut c, 0x1C, &[0x18]);
    c.latch_at(&numbered(1), 1_000_000);
    c.latch_at(&numbered(2), 1_125_000);
    assert_eq!(spi_read(&mut c, 0x3B, 2), [0x00, 0x01], "1 kHz accel: held");
    spi_write(&mut c, 0x68, &[0x02]); // ACCEL_RST
    assert_eq!(spi_read(&mut c, 0x68, 1), [0x00]);
    c.latch_at(&numbered(3), 1_250_000);
    assert_eq!(spi_read(&mut c, 0x3B, 2), [0x00, 0x03]);
    spi_write(&mut c, 0x68, &[0x05]); // GYRO_RST | TEMP_RST: the accel keeps its clock
    c.latch_at(&numbered(4), 1_375_000);
    assert_eq!(spi_read(&mut c, 0x3B, 2), [0x00, 0x03]);
}

#[test]
fn fifo_holds_512_bytes() {
    let mut c = chip(Variant::Mpu6500);
    spi_write(&mut c, 0x23, &[0x08]);
    spi_write(&mut c, 0x6A, &[0x40]);
    for k in 1..=86 {
        c.latch_at(&numbered(k), k * MS); // 516 bytes
    }
    assert_eq!(spi_read(&mut c, 0x72, 2), [0x02, 0x00]);
    assert_eq!(spi_read(&mut c, 0x3A, 1), [0x11], "FIFO_OFLOW_INT");
}
