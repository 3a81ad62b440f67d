//! SPI target: read flag, bursts, ports, masks (PS section 7.5, RM section 3).

use super::*;
use margemu_firmware::chip::Variant;

#[test]
fn who_am_i_of_each_variant() {
    for (variant, id) in [
        (Variant::Mpu9250, 0x71),
        (Variant::Mpu9255, 0x73),
        (Variant::Mpu6500, 0x70),
        (Variant::WhoAmI68, 0x68),
    ] {
        let mut chip = Mpu6xxx::with_config(Config {
            variant,
            ..Config::default()
        });
        assert_eq!(spi(&mut chip, &[0x80 | 0x75, 0x00]), [0x00, id]);
    }
}

#[test]
fn write_then_read_back() {
    let mut c = chip();
    assert_eq!(spi(&mut c, &[0x19, 0x09]), [0x00, 0x00]); // SMPLRT_DIV = 9
    assert_eq!(spi(&mut c, &[0x80 | 0x19, 0x00]), [0x00, 0x09]);
}

#[test]
fn bursts_increment_the_address() {
    let mut c = chip();
    // SMPLRT_DIV, CONFIG, GYRO_CONFIG, ACCEL_CONFIG, ACCEL_CONFIG2 in one burst write.
    assert_eq!(spi(&mut c, &[0x19, 0x04, 0x03, 0x18, 0x10, 0x05]), [0; 6]);
    assert_eq!(
        spi(&mut c, &[0x80 | 0x19, 0, 0, 0, 0, 0]),
        [0x00, 0x04, 0x03, 0x18, 0x10, 0x05]
    );
}

#[test]
fn bursts_wrap_from_0x7f_to_0x00() {
    let mut c = chip();
    spi_write(&mut c, 0x7F, &[0xA5, 0x11]); // 0x7F (reserved), then SELF_TEST_X_GYRO
    assert_eq!(spi_read(&mut c, 0x7F, 2), [0xA5, 0x11]);
}

#[test]
fn fifo_r_w_bursts_stay_on_the_port() {
    let mut c = chip();
    spi_write(&mut c, 0x74, &[0x10, 0x20, 0x30]); // three bytes into the FIFO
    assert_eq!(spi_read(&mut c, 0x72, 2), [0x00, 0x03]);
    assert_eq!(
        spi(&mut c, &[0x80 | 0x74, 0, 0, 0]),
        [0x00, 0x10, 0x20, 0x30]
    );
    assert_eq!(spi_read(&mut c, 0x72, 2), [0x00, 0x00]);
}

#[test]
fn mem_r_w_bursts_stay_on_the_port() {
    let mut c = chip();
    spi_write(&mut c, 0x6F, &[1, 2, 3]); // DMP memory: not emulated, must not spill over
    assert_eq!(spi_read(&mut c, 0x70, 1), [0x00]);
    assert_eq!(spi_read(&mut c, 0x6F, 3), [0x00, 0x00, 0x00]);
}

#[test]
fn the_prefetched_byte_after_a_burst_is_not_consumed() {
    let mut c = chip();
    spi_write(&mut c, 0x74, &[0xAA, 0xBB]);
    // One byte read: the chip prefetches the second for a byte that is never clocked.
    assert_eq!(spi(&mut c, &[0x80 | 0x74, 0x00]), [0x00, 0xAA]);
    assert_eq!(spi_read(&mut c, 0x72, 2), [0x00, 0x01]);
    assert_eq!(spi(&mut c, &[0x80 | 0x74, 0x00]), [0x00, 0xBB]);
}

#[test]
fn read_only_registers_ignore_writes() {
    let mut c = chip();
    for addr in [0x35u8, 0x36, 0x3A, 0x3B, 0x48, 0x49, 0x60, 0x72, 0x73, 0x75] {
        spi_write(&mut c, addr, &[0x5A]);
        let expected = if addr == 0x75 { 0x71 } else { 0x00 };
        assert_eq!(
            spi_read(&mut c, addr, 1),
            [expected],
            "register {addr:#04x}"
        );
    }
}

#[test]
fn reserved_bits_read_back_what_was_written() {
    let mut c = chip();
    spi_write(&mut c, 0x1A, &[0x80 | 0x03]); // CONFIG bit 7 is reserved
    spi_write(&mut c, 0x1B, &[0x04 | 0x18]); // GYRO_CONFIG bit 2 is reserved
    spi_write(&mut c, 0x1D, &[0xC0 | 0x05]); // ACCEL_CONFIG2 bits 7:6 reserved
    spi_write(&mut c, 0x6A, &[0x88]); // USER_CTRL bits 7 and 3 reserved
    spi_write(&mut c, 0x61, &[0x3C]); // undocumented register
    assert_eq!(spi_read(&mut c, 0x1A, 4), [0x83, 0x1C, 0x00, 0xC5]);
    assert_eq!(spi_read(&mut c, 0x6A, 1), [0x88]);
    assert_eq!(spi_read(&mut c, 0x61, 1), [0x3C]);
}

#[test]
fn miso_is_zero_during_the_address_byte_and_unselected_bytes_are_ignored() {
    let mut c = chip();
    assert_eq!(c.exchange(0x19), 0x00); // not selected
    assert_eq!(c.exchange(0x42), 0x00);
    assert_eq!(spi_read(&mut c, 0x19, 1), [0x00]);
    assert_eq!(c.select(), 0x00);
    c.deselect();
}

#[test]
fn a_second_select_restarts_the_transaction() {
    let mut c = chip();
    c.select();
    c.exchange(0x19); // write to SMPLRT_DIV, but the data byte never comes
    assert_eq!(c.select(), 0x00);
    assert_eq!(c.exchange(0x80 | 0x75), 0x71);
    c.deselect();
    assert_eq!(spi_read(&mut c, 0x19, 1), [0x00]);
}
