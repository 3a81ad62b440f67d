//! Reset values of every bank, soft reset, reserved registers and bits (DS register map).

use super::*;

#[test]
fn bank0_reset_values() {
    let mut c = chip();
    assert_eq!(spi_read(&mut c, 0x11, 1), [0x00]);
    assert_eq!(spi_read(&mut c, 0x13, 4), [0x05, 0x00, 0x00, 0x00]); // 0x15 reserved
    assert_eq!(
        spi_read(&mut c, 0x1D, 14),
        [0x80, 0x00].repeat(7),
        "sensors off"
    );
    assert_eq!(spi_read(&mut c, 0x2D, 1), [0x10], "RESET_DONE_INT");
    assert_eq!(spi_read(&mut c, 0x2D, 1), [0x00], "cleared on read");
    assert_eq!(spi_read(&mut c, 0x31, 8), [0, 0, 0, 0x04, 0, 0, 0, 0]);
    assert_eq!(
        spi_read(&mut c, 0x4B, 11),
        [0x00, 0x30, 0x91, 0x00, 0x06, 0x06, 0x16, 0x11, 0x0D, 0x23, 0x00]
    );
    assert_eq!(spi_read(&mut c, 0x56, 2), [0x82, 0x00]);
    assert_eq!(
        spi_read(&mut c, 0x5F, 11),
        [0x00, 0x00, 0x00, 0x10, 0x00, 0x10, 0x10, 0x00, 0x00, 0x00, 0x00]
    );
    assert_eq!(spi_read(&mut c, 0x6C, 2), [0x00, 0x00]);
    assert_eq!(spi_read(&mut c, 0x70, 1), [0x00]);
    assert_eq!(spi_read(&mut c, 0x75, 2), [0x47, 0x00]);
    assert_eq!(c.sample_period_ns(), MS, "GYRO_ODR 1 kHz");
    assert!(!c.is_running());
}

#[test]
fn banks_1_to_4_reset_values() {
    let mut c = chip();
    bank(&mut c, 1);
    assert_eq!(spi_read(&mut c, 0x03, 1), [0x80]);
    assert_eq!(
        spi_read(&mut c, 0x0B, 9),
        [0xA0, 0x0D, 0xAA, 0x80, 0x1F, 0x1E, 0x20, 0x00, 0x11]
    );
    assert_eq!(spi_read(&mut c, 0x5F, 6), [0x6B, 0x71, 0x66, 0, 0, 0]);
    assert_eq!(
        spi_read(&mut c, 0x75, 8),
        [0x00, 0x01, 0, 0, 0, 0x83, 0x00, 0x5F]
    );
    bank(&mut c, 2);
    assert_eq!(spi_read(&mut c, 0x03, 3), [0x30, 0x40, 0x62]);
    assert_eq!(spi_read(&mut c, 0x3B, 3), [0x5C, 0x61, 0x75]);
    assert_eq!(
        spi_read(&mut c, 0x75, 1),
        [0x00],
        "no WHO_AM_I outside bank 0"
    );
    bank(&mut c, 3);
    assert_eq!(spi_read(&mut c, 0x2A, 1), [0x00]);
    bank(&mut c, 4);
    assert_eq!(
        spi_read(&mut c, 0x40, 9),
        [0xA2, 0x85, 0x51, 0xA4, 0x8C, 0x5C, 0x45, 0x5B, 0x00]
    );
    assert_eq!(
        spi_read(&mut c, 0x76, 10),
        [0x04, 0, 0, 0, 0, 0, 0, 0, 0, 0]
    );
    bank(&mut c, 0);
    assert_eq!(spi_read(&mut c, 0x75, 1), [0x47]);
}

#[test]
fn soft_reset_restores_every_bank_and_keeps_the_log() {
    let mut c = running();
    spi_write(&mut c, 0x4C, &[0xC0]);
    bank(&mut c, 1);
    spi_write(&mut c, 0x0C, &[21]);
    bank(&mut c, 0);
    spi_write(&mut c, 0x5F, &[0x07]);
    spi_write(&mut c, 0x16, &[0x40]);
    c.latch_at(&sample(5), MS);
    spi_read(&mut c, 0x2D, 1);
    let logged = c.write_log().len();
    spi_write(&mut c, 0x11, &[0x01]);
    assert_eq!(c.write_log().len(), logged + 1);
    assert_eq!(spi_read(&mut c, 0x11, 1), [0x00]);
    assert_eq!(spi_read(&mut c, 0x2D, 1), [0x10]);
    assert_eq!(spi_read(&mut c, 0x1D, 4), [0x80, 0x00, 0x80, 0x00]);
    assert_eq!(spi_read(&mut c, 0x2E, 2), [0x00, 0x00], "FIFO emptied");
    for b in 0..5 {
        for a in 0..0x80 {
            let fresh = chip().peek(b, a);
            let expect = if (b, a) == (0, 0x2D) { 0x00 } else { fresh };
            assert_eq!(c.peek(b, a), expect, "bank {b} {a:#04x}");
        }
    }
}

#[test]
fn reserved_addresses_and_bits() {
    let mut c = chip();
    spi_write(&mut c, 0x00, &[0xAB]);
    spi_write(&mut c, 0x4D, &[0xFF]);
    spi_write(&mut c, 0x53, &[0x00]);
    spi_write(&mut c, 0x54, &[0x00]);
    spi_write(&mut c, 0x75, &[0x12]);
    spi_write(&mut c, 0x11, &[0x10]); // SPI_MODE only
    assert_eq!(spi_read(&mut c, 0x00, 1), [0x00]);
    assert_eq!(spi_read(&mut c, 0x4D, 1), [0xDF], "bits 5:4 stay 01");
    assert_eq!(
        spi_read(&mut c, 0x53, 2),
        [0x01, 0x20],
        "reserved bit 0 / bit 5 kept"
    );
    assert_eq!(spi_read(&mut c, 0x75, 1), [0x47]);
    assert_eq!(spi_read(&mut c, 0x11, 1), [0x10]);
    spi_write(&mut c, 0x4B, &[0xFF]);
    assert_eq!(
        spi_read(&mut c, 0x4B, 1),
        [0x00],
        "SIGNAL_PATH_RESET reads 0"
    );
    bank(&mut c, 1);
    spi_write(&mut c, 0x0B, &[0x00]);
    assert_eq!(spi_read(&mut c, 0x0B, 1), [0xA0]);
    spi_write(&mut c, 0x62, &[0x55]);
    assert_eq!(spi_read(&mut c, 0x62, 1), [0x00], "TMSTVAL read only");
}

#[test]
fn banks_5_to_7_reach_only_reg_bank_sel() {
    let mut c = chip();
    spi_read(&mut c, 0x2D, 1);
    bank(&mut c, 0xFD);
    assert_eq!(spi_read(&mut c, 0x75, 2), [0x00, 0x05]);
    spi_write(&mut c, 0x11, &[0x01]);
    bank(&mut c, 0);
    assert_eq!(spi_read(&mut c, 0x75, 1), [0x47]);
    assert_eq!(
        spi_read(&mut c, 0x2D, 1),
        [0x00],
        "the write reached nothing"
    );
}

#[test]
fn who_am_i_follows_the_config() {
    use margemu_firmware::chip::icm42688p::Config;
    let mut c = Icm42688p::with_config(Config {
        who_am_i: 0x44,
        ..Config::default()
    });
    assert_eq!(spi_read(&mut c, 0x75, 1), [0x44]);
    assert_eq!(c.config().who_am_i, 0x44);
}
