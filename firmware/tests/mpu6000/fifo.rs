//! The MPU-6000's 1024-byte FIFO (PS-MPU-6000A section 7.17) and its records.

use super::*;

fn count(c: &mut Mpu6xxx) -> u16 {
    let b = spi_read(c, 0x72, 2);
    u16::from_be_bytes([b[0], b[1]])
}

#[test]
fn fourteen_byte_records_with_the_held_accel() {
    let mut c = awake();
    spi_write(&mut c, 0x1B, &[0x18]);
    spi_write(&mut c, 0x1C, &[0x18]);
    spi_write(&mut c, 0x23, &[0xF8]);
    spi_write(&mut c, 0x6A, &[0x40]);
    for k in 7..=9 {
        c.latch_at(&numbered(k), k * 125_000);
    }
    assert_eq!(count(&mut c), 42);
    let fifo = spi_read(&mut c, 0x74, 42);
    // 7 · 125 µs lies in the first millisecond, 8 · 125 µs opens the second: 9 repeats 8.
    let accel: Vec<i16> = fifo.chunks(14).map(|r| be(r, 0)).collect();
    let gyro: Vec<i16> = fifo.chunks(14).map(|r| be(r, 8)).collect();
    assert_eq!(accel, [7, 8, 8]);
    assert_eq!(gyro, [7, 8, 9]);
    assert_eq!(
        &fifo[28..],
        [0x00, 0x08, 0xFF, 0xF8, 0x08, 0x00, 0xF7, 0x54, 0x00, 0x09, 0xFF, 0xF7, 0x00, 0x07]
    );
}

#[test]
fn holds_1024_bytes() {
    let mut c = awake();
    spi_write(&mut c, 0x1A, &[0x01]);
    spi_write(&mut c, 0x23, &[0x08]); // accel only: 6-byte records
    spi_write(&mut c, 0x6A, &[0x40]);
    for k in 1..=170 {
        c.latch_at(&numbered(k), k * MS); // 1020 bytes
    }
    assert_eq!(count(&mut c), 1020);
    assert_eq!(spi_read(&mut c, 0x3A, 1), [0x01], "no overflow yet");
    c.latch_at(&numbered(171), 171 * MS);
    assert_eq!(count(&mut c), 1024);
    assert_eq!(spi_read(&mut c, 0x3A, 1), [0x11], "FIFO_OFLOW_INT");
    // Two bytes of sample 1 were dropped: the FIFO starts at its ACCEL_YOUT (−8 at ±2 g),
    // then ACCEL_ZOUT (1 g = 16384).
    assert_eq!(spi_read(&mut c, 0x74, 4), [0xFF, 0xF8, 0x40, 0x00]);
}
