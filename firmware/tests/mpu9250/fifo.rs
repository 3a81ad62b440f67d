//! FIFO_EN, USER_CTRL.FIFO_EN/FIFO_RST, FIFO_COUNTH/L, FIFO_R_W, records and overflow
//! (RM sections 4.11, 4.36–4.37; PS section 4.17).

use super::*;

const G: f32 = 9.80665;

fn sample(n: i16) -> PhysicalSample {
    // Accel x = n LSB at ±2 g, temperature so that TEMP_OUT = 0, gyro x = 0.
    PhysicalSample {
        acc: [f32::from(n) * G / 16384.0, 0.0, 0.0],
        gyr: [0.0; 3],
        mag: [0.0; 3],
        temp_c: 21.0,
    }
}

fn count(c: &mut Mpu6xxx) -> u16 {
    let b = spi_read(c, 0x72, 2);
    u16::from_be_bytes([b[0], b[1]])
}

fn enable(c: &mut Mpu6xxx, fifo_en: u8) {
    spi_write(c, 0x23, &[fifo_en]);
    spi_write(c, 0x6A, &[0x40]);
}

#[test]
fn fourteen_byte_records_in_register_order() {
    let mut c = chip();
    enable(&mut c, 0xF8); // TEMP, GYRO X/Y/Z, ACCEL
    let s = PhysicalSample {
        acc: [G, 2.0 * G / 16384.0 * 258.0 / 2.0, -G],
        gyr: [(1.0f32 / 131.0).to_radians(), 0.0, -2.0f32.to_radians()],
        mag: [0.0; 3],
        temp_c: 22.0,
    };
    c.latch_at(&s, MS);
    assert_eq!(count(&mut c), 14);
    assert_eq!(spi_read(&mut c, 0x74, 14), spi_read(&mut c, 0x3B, 14));
    assert_eq!(count(&mut c), 0);
    c.latch_at(&s, 2 * MS);
    assert_eq!(
        spi_read(&mut c, 0x74, 14),
        [0x40, 0x00, 0x01, 0x02, 0xC0, 0x00, 0x01, 0x4E, 0x00, 0x01, 0x00, 0x00, 0xFE, 0xFA]
    );
}

#[test]
fn fifo_en_selects_the_sensors() {
    let mut c = chip();
    enable(&mut c, 0x08 | 0x10); // ACCEL and GYRO_Z only
    c.latch_at(&sample(5), MS);
    assert_eq!(count(&mut c), 8);
    assert_eq!(spi_read(&mut c, 0x74, 8), [0, 5, 0, 0, 0, 0, 0, 0]);
    enable(&mut c, 0x80); // TEMP only
    c.latch_at(&sample(5), 2 * MS);
    assert_eq!(count(&mut c), 2);
}

#[test]
fn nothing_is_written_without_user_ctrl_fifo_en() {
    let mut c = chip();
    spi_write(&mut c, 0x23, &[0xF8]);
    c.latch_at(&sample(1), MS);
    assert_eq!(count(&mut c), 0);
}

#[test]
fn fifo_count_is_latched_by_reading_fifo_counth() {
    let mut c = chip();
    enable(&mut c, 0x08);
    for k in 0..50 {
        c.latch_at(&sample(k), MS * u64::from(k as u16 + 1));
    }
    assert_eq!(spi_read(&mut c, 0x72, 2), [0x01, 0x2C], "300 bytes");
    c.latch_at(&sample(0), 100 * MS);
    assert_eq!(
        spi_read(&mut c, 0x73, 1),
        [0x2C],
        "FIFO_COUNTL alone keeps the latched value"
    );
    assert_eq!(
        spi_read(&mut c, 0x72, 2),
        [0x01, 0x32],
        "306 after a new COUNTH read"
    );
}

#[test]
fn reading_an_empty_fifo_returns_the_last_byte() {
    let mut c = chip();
    spi_write(&mut c, 0x74, &[0x12, 0x34]);
    assert_eq!(spi_read(&mut c, 0x74, 4), [0x12, 0x34, 0x34, 0x34]);
    assert_eq!(count(&mut c), 0);
}

#[test]
fn overflow_drops_the_oldest_bytes_by_default() {
    let mut c = chip();
    enable(&mut c, 0x08);
    for k in 0..90 {
        c.latch_at(&sample(k), MS * (k as u64 + 1)); // 540 bytes into 512
    }
    assert_eq!(count(&mut c), 512);
    assert_eq!(
        spi_read(&mut c, 0x3A, 1),
        [0x11],
        "FIFO_OFLOW_INT | RAW_DATA_RDY_INT"
    );
    // 28 bytes dropped: the FIFO now starts mid-record, at sample 4's ACCEL_ZOUT, then sample 5.
    assert_eq!(
        spi_read(&mut c, 0x74, 8),
        [0x00, 0x00, 0x00, 0x05, 0x00, 0x00, 0x00, 0x00]
    );
}

#[test]
fn fifo_mode_1_keeps_the_old_data() {
    let mut c = chip();
    spi_write(&mut c, 0x1A, &[0x40]); // FIFO_MODE
    enable(&mut c, 0x08);
    for k in 0..90 {
        c.latch_at(&sample(k), MS * (k as u64 + 1));
    }
    assert_eq!(count(&mut c), 512);
    assert_eq!(
        spi_read(&mut c, 0x74, 2),
        [0x00, 0x00],
        "sample 0 still first"
    );
}

#[test]
fn fifo_rst_empties_and_self_clears() {
    let mut c = chip();
    enable(&mut c, 0x08);
    c.latch_at(&sample(1), MS);
    spi_write(&mut c, 0x6A, &[0x44]);
    assert_eq!(count(&mut c), 0);
    assert_eq!(spi_read(&mut c, 0x6A, 1), [0x40]);
}
