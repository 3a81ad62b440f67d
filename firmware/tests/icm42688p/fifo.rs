//! FIFO packets byte for byte, counts in bytes or records, overflow and lost packets, flush,
//! partial reads, timestamps and the 8-bit temperature (DS: FIFO).

use super::*;
use margemu_protocol::regmap::icm42688p::image::ImageRepr;

/// A running chip with FIFO_CONFIG1 = `cfg1` in stream mode.
fn fifo_chip(cfg1: u8) -> Icm42688p {
    let mut c = running();
    spi_write(&mut c, 0x5F, &[cfg1]);
    spi_write(&mut c, 0x16, &[0x40]);
    c
}

fn count(c: &mut Icm42688p) -> Vec<u8> {
    spi_read(c, 0x2E, 2)
}

#[test]
fn packet_3_accel_gyro_16_bytes() {
    let mut c = fifo_chip(0x03);
    c.latch_at(&sample(5), MS);
    assert_eq!(count(&mut c), [0x00, 0x10]);
    assert_eq!(
        spi_read(&mut c, 0x30, 16),
        [
            0x68, 0x00, 0x05, 0xFF, 0xF6, 0x08, 0x00, // header, accel
            0x00, 0x05, 0x00, 0x03, 0xFF, 0xFB, // gyro
            0x00, 0x03, 0xE8, // temperature (8 bits), timestamp 1000 µs
        ]
    );
    assert_eq!(count(&mut c), [0x00, 0x00]);
    assert_eq!(
        spi_read(&mut c, 0x30, 2),
        [0xFF, 0xFF],
        "empty: HEADER_MSG set"
    );
}

#[test]
fn packets_1_and_2_single_sensor_8_bytes() {
    let mut c = fifo_chip(0x01);
    let mut warm = sample(5);
    warm.temp_c = 35.0; // TEMP_DATA 1325 → 1325 / 64 = 20.7 → 21
    c.latch_at(&warm, MS);
    assert_eq!(
        spi_read(&mut c, 0x30, 8),
        [0x40, 0x00, 0x05, 0xFF, 0xF6, 0x08, 0x00, 0x15]
    );
    spi_write(&mut c, 0x5F, &[0x02]);
    c.latch_at(&sample(5), 2 * MS);
    assert_eq!(
        spi_read(&mut c, 0x30, 8),
        [0x20, 0x00, 0x05, 0x00, 0x03, 0xFF, 0xFB, 0x00]
    );
}

#[test]
fn packet_4_twenty_bits() {
    let mut c = fifo_chip(0x13);
    let image = ImageRepr {
        temp: 0x0102,
        accel: [0; 3],
        gyro: [0; 3],
        accel20: [4, -4, 0x12348],
        gyro20: [2, -2, -0x12346],
    };
    c.latch_image_at(&image.emit(), MS);
    assert_eq!(count(&mut c), [0x00, 0x14]);
    assert_eq!(
        spi_read(&mut c, 0x30, 20),
        [
            0x78, // header: ACCEL, GYRO, 20, TIMESTAMP_FSYNC = 10
            0x00, 0x00, 0xFF, 0xFF, 0x12, 0x34, // accel bits 19:4
            0x00, 0x00, 0xFF, 0xFF, 0xED, 0xCB, // gyro bits 19:4
            0x01, 0x02, // temperature, 16 bits
            0x03, 0xE8, // timestamp
            0x42, 0xCE, 0x8A, // accel[3:0] ‖ gyro[3:0]
        ]
    );
}

#[test]
fn packet_4_from_physical_values_and_sensors_off() {
    let mut c = fifo_chip(0x13);
    c.latch_at(&sample(5), MS); // 20-bit accel 80, −160, 32768; gyro 80, 48, −80
    let p = spi_read(&mut c, 0x30, 20);
    assert_eq!(p[1..7], [0x00, 0x05, 0xFF, 0xF6, 0x08, 0x00]);
    assert_eq!(p[7..13], [0x00, 0x05, 0x00, 0x03, 0xFF, 0xFB]);
    spi_write(&mut c, 0x4E, &[0x0C]); // accel off
    c.latch_at(&sample(5), 2 * MS);
    let p = spi_read(&mut c, 0x30, 20);
    assert_eq!(p[1..7], [0x80, 0x00].repeat(3), "−524288 in bits 19:4");
    assert_eq!(p[17..], [0x00, 0x00, 0x00]);
}

#[test]
fn odr_change_is_flagged_once() {
    let mut c = fifo_chip(0x03);
    c.latch_at(&sample(1), MS);
    spi_write(&mut c, 0x4F, &[0x05]);
    c.latch_at(&sample(2), 2 * MS);
    c.latch_at(&sample(3), 3 * MS);
    let headers: Vec<u8> = (0..3).map(|_| spi_read(&mut c, 0x30, 16)[0]).collect();
    assert_eq!(headers, [0x68, 0x69, 0x68]);
}

#[test]
fn count_units_and_byte_order() {
    let mut c = fifo_chip(0x03);
    c.latch_at(&sample(1), MS);
    c.latch_at(&sample(2), 2 * MS);
    assert_eq!(count(&mut c), [0x00, 0x20], "bytes, big-endian");
    spi_write(&mut c, 0x4C, &[0x70]);
    assert_eq!(count(&mut c), [0x00, 0x02], "records, big-endian");
    spi_write(&mut c, 0x4C, &[0x40]);
    assert_eq!(count(&mut c), [0x02, 0x00], "records, little-endian");
    spi_write(&mut c, 0x4C, &[0x10]);
    assert_eq!(count(&mut c), [0x20, 0x00], "bytes, little-endian");
}

#[test]
fn little_endian_fifo_data() {
    let mut c = fifo_chip(0x03);
    spi_write(&mut c, 0x4C, &[0xC0]); // ArduPilot's setting
    c.latch_at(&sample(5), MS);
    assert_eq!(count(&mut c), [0x01, 0x00]);
    assert_eq!(
        spi_read(&mut c, 0x30, 16),
        [
            0x68, 0x05, 0x00, 0xF6, 0xFF, 0x00, 0x08, 0x05, 0x00, 0x03, 0x00, 0xFB, 0xFF, 0x00,
            0xE8, 0x03
        ]
    );
}

#[test]
fn stop_on_full_drops_new_packets_and_counts_them() {
    let mut c = fifo_chip(0x03);
    spi_write(&mut c, 0x16, &[0x80]);
    for k in 0..130 {
        c.latch_at(&sample(k), (k as u64 + 1) * MS);
    }
    assert_eq!(count(&mut c), [0x08, 0x00], "2048 bytes");
    assert_eq!(spi_read(&mut c, 0x6C, 2), [0x02, 0x00], "FIFO_LOST_PKT");
    assert_eq!(spi_read(&mut c, 0x2D, 1)[0] & 0x02, 0x02, "FIFO_FULL_INT");
    assert_eq!(
        spi_read(&mut c, 0x30, 3),
        [0x68, 0x00, 0x00],
        "sample 0 is still first"
    );
}

#[test]
fn stream_mode_drops_the_oldest() {
    let mut c = fifo_chip(0x03);
    for k in 0..130 {
        c.latch_at(&sample(k), (k as u64 + 1) * MS);
    }
    assert_eq!(count(&mut c), [0x08, 0x00]);
    assert_eq!(spi_read(&mut c, 0x6C, 1), [0x02]);
    assert_eq!(
        spi_read(&mut c, 0x30, 3),
        [0x68, 0x00, 0x02],
        "sample 2 is first"
    );
}

#[test]
fn flush_and_bypass() {
    let mut c = fifo_chip(0x03);
    c.latch_at(&sample(1), MS);
    spi_write(&mut c, 0x4B, &[0x02]);
    assert_eq!(count(&mut c), [0x00, 0x00]);
    assert_eq!(spi_read(&mut c, 0x4B, 1), [0x00]);
    spi_write(&mut c, 0x16, &[0x00]);
    c.latch_at(&sample(2), 2 * MS);
    assert_eq!(count(&mut c), [0x00, 0x00], "bypass mode stores nothing");
}

#[test]
fn partial_reads_rewind_unless_resume() {
    let mut c = fifo_chip(0x03);
    c.latch_at(&sample(7), MS);
    assert_eq!(spi_read(&mut c, 0x30, 3), [0x68, 0x00, 0x07]);
    assert_eq!(count(&mut c), [0x00, 0x10], "still the whole packet");
    assert_eq!(spi_read(&mut c, 0x30, 3), [0x68, 0x00, 0x07]);
    spi_write(&mut c, 0x5F, &[0x43]);
    assert_eq!(spi_read(&mut c, 0x30, 3), [0x68, 0x00, 0x07]);
    assert_eq!(count(&mut c), [0x00, 0x0D]);
    assert_eq!(
        spi_read(&mut c, 0x30, 2),
        [0xFF, 0xF2],
        "resumed at accel y"
    );
}

#[test]
fn timestamps_resolution_and_delta() {
    let mut c = fifo_chip(0x03);
    spi_write(&mut c, 0x54, &[0x2B]); // 16 µs
    c.latch_at(&sample(1), MS);
    assert_eq!(
        spi_read(&mut c, 0x30, 16)[14..],
        [0x00, 0x3E],
        "1000 / 16 = 62"
    );
    spi_write(&mut c, 0x54, &[0x25]); // 1 µs deltas
    c.latch_at(&sample(1), 3 * MS);
    assert_eq!(
        spi_read(&mut c, 0x30, 16)[14..],
        [0x07, 0xD0],
        "2000 µs since the last"
    );
    spi_write(&mut c, 0x54, &[0x20]); // timestamps off
    c.latch_at(&sample(1), 4 * MS);
    assert_eq!(spi_read(&mut c, 0x30, 16)[14..], [0x00, 0x00]);
}
