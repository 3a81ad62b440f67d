//! The ICM-20602's FIFO: 1008 bytes, FIFO_EN's two bits each bringing TEMP_OUT along.

use super::*;

fn count(c: &mut Mpu6xxx) -> u16 {
    let b = spi_read(c, 0x72, 2);
    u16::from_be_bytes([b[0], b[1]])
}

fn fifo_with(fifo_en: u8) -> Mpu6xxx {
    let mut c = awake();
    spi_write(&mut c, 0x1A, &[0x01]); // 1 kHz
    spi_write(&mut c, 0x1B, &[0x18]);
    spi_write(&mut c, 0x1C, &[0x18]);
    spi_write(&mut c, 0x23, &[fifo_en]);
    spi_write(&mut c, 0x6A, &[0x40]);
    c
}

#[test]
fn record_layouts() {
    // TEMP_OUT at 30 °C: (30 − 25) · 326.8 = 1634 = 0x0662.
    let mut c = fifo_with(0x18);
    c.latch_at(&numbered(5), MS);
    assert_eq!(
        spi_read(&mut c, 0x74, 14),
        [0x00, 0x05, 0xFF, 0xFB, 0x08, 0x00, 0x06, 0x62, 0x00, 0x05, 0xFF, 0xFB, 0x00, 0x07]
    );
    let mut c = fifo_with(0x10); // GYRO_FIFO_EN: temperature and gyro
    c.latch_at(&numbered(5), MS);
    assert_eq!(
        spi_read(&mut c, 0x74, 8),
        [0x06, 0x62, 0x00, 0x05, 0xFF, 0xFB, 0x00, 0x07]
    );
    let mut c = fifo_with(0x08); // ACCEL_FIFO_EN: accel and temperature
    c.latch_at(&numbered(5), MS);
    assert_eq!(count(&mut c), 8);
    assert_eq!(
        spi_read(&mut c, 0x74, 8),
        [0x00, 0x05, 0xFF, 0xFB, 0x08, 0x00, 0x06, 0x62]
    );
    let mut c = fifo_with(0xE7); // reserved bits only
    c.latch_at(&numbered(5), MS);
    assert_eq!(count(&mut c), 0);
}

#[test]
fn holds_1008_bytes() {
    let mut c = fifo_with(0x18);
    for k in 1..=72 {
        c.latch_at(&numbered(k), k * MS);
    }
    assert_eq!(count(&mut c), 1008, "72 records");
    assert_eq!(spi_read(&mut c, 0x3A, 1), [0x01]);
    spi_write(&mut c, 0x1A, &[0x41]); // FIFO_MODE: keep the old data
    c.latch_at(&numbered(73), 73 * MS);
    assert_eq!(count(&mut c), 1008);
    assert_eq!(spi_read(&mut c, 0x3A, 1), [0x11], "FIFO_OFLOW_INT");
    assert_eq!(
        be(&spi_read(&mut c, 0x74, 14), 8),
        1,
        "record 1 still first"
    );
}
