//! I2C addressing by SA0/SA1 and refused writes (DS §4.5), the SPI address byte with STATUS on
//! MISO (DS §4.4), auto-increment on both buses.

use margemu_firmware::chip::{I2cTarget, SpiTarget};

use super::*;

#[test]
fn i2c_answers_only_the_address_of_its_pins() {
    for (sa0, sa1, own) in [
        (false, false, 0x20),
        (true, false, 0x21),
        (false, true, 0x22),
        (true, true, 0x23),
    ] {
        let mut mag = Rm3100::with_pins(sa0, sa1);
        for address in 0..0x80u8 {
            assert_eq!(mag.start(address, false), address == own, "{address:#04x}");
            mag.stop();
            assert_eq!(mag.start(address, true), address == own, "{address:#04x}");
            mag.stop();
        }
        assert_eq!(read(&mut mag, Link::I2c(own), 0x36, 1), [0x22]);
    }
}

#[test]
fn bytes_after_a_nak_are_ignored() {
    let mut mag = Rm3100::new();
    assert_eq!(i2c_write(&mut mag, 0x21, &[0x0B, 0x92]), [false; 3]);
    assert!(!mag.start(0x21, true));
    assert_eq!(mag.read(), 0xFF, "nobody drives SDA");
    mag.stop();
    assert_eq!(i2c_read(&mut mag, 0x21, 0x0B, 1), None);
    assert_eq!(read(&mut mag, Link::I2c(ADDRESS), 0x0B, 1), [0x96]);
}

#[test]
fn i2c_refuses_writes_it_cannot_carry_out() {
    let l = Link::I2c(ADDRESS);
    let mut mag = Rm3100::new();
    write_reg(&mut mag, l, 0x35, 0x03); // clears the NACK bits
    assert_eq!(read(&mut mag, l, 0x35, 1), [0x0B]);
    // Undefined and read-only registers: the data byte is not acknowledged, NACK0.
    assert_eq!(
        i2c_write(&mut mag, ADDRESS, &[0x0A, 0x01]),
        [true, true, false]
    );
    assert_eq!(read(&mut mag, l, 0x35, 1), [0x1B]);
    write_reg(&mut mag, l, 0x35, 0x03);
    // POLL during continuous mode: ignored, NACK1.
    write_reg(&mut mag, l, 0x01, 0x71);
    assert_eq!(
        i2c_write(&mut mag, ADDRESS, &[0x00, 0x70]),
        [true, true, false]
    );
    assert_eq!(read(&mut mag, l, 0x00, 2), [0x00, 0x71], "POLL not stored");
    assert_eq!(read(&mut mag, l, 0x35, 1), [0x2B]);
    // CMM during a single measurement: ignored, NACK1.
    write_reg(&mut mag, l, 0x01, 0x70);
    write_reg(&mut mag, l, 0x35, 0x03);
    write_reg(&mut mag, l, 0x00, 0x70);
    assert_eq!(
        i2c_write(&mut mag, ADDRESS, &[0x01, 0x71]),
        [true, true, false]
    );
    assert_eq!(read(&mut mag, l, 0x01, 1), [0x70]);
    assert_eq!(read(&mut mag, l, 0x35, 1), [0x2B]);
    mag.advance(7 * MS);
    write_reg(&mut mag, l, 0x01, 0x71);
    assert!(mag.is_continuous(), "accepted once the measurement is done");
}

#[test]
fn i2c_burst_crosses_registers_and_ignores_the_read_flag() {
    let mut mag = Rm3100::new();
    let l = Link::I2c(ADDRESS);
    // 0x0A is not a register: that byte is refused and the burst goes on to TMRC.
    assert!(!write(&mut mag, l, 0x08, &[0x01, 0x90, 0x55, 0x95]));
    assert_eq!(read(&mut mag, l, 0x08, 4), [0x01, 0x90, 0x00, 0x95]);
    assert_eq!(
        read(&mut mag, l, 0x80 | 0x0B, 1),
        [0x95],
        "7-bit register address"
    );
    assert_eq!(read(&mut mag, l, 0x7F, 2), [0x00, 0x00], "wraps to POLL");
}

#[test]
fn spi_returns_status_during_the_address_byte() {
    let mut mag = Rm3100::new();
    assert_eq!(spi(&mut mag, &[0x80 | 0x36, 0x00]), [0x00, 0x22]);
    write_reg(&mut mag, Link::Spi, 0x00, 0x10); // POLL x
    mag.advance(3 * MS);
    assert_eq!(spi(&mut mag, &[0x80 | 0x36, 0x00]), [0x80, 0x22], "DRDY");
    assert_eq!(
        spi(&mut mag, &[0x80 | 0x24, 0, 0, 0]),
        [0x80, 0, 0, 0],
        "the results go out after STATUS"
    );
    assert_eq!(spi(&mut mag, &[0x80 | 0x34, 0x00]), [0x00, 0x00]);
}

#[test]
fn spi_burst_write_and_read_auto_increment() {
    let mut mag = Rm3100::new();
    assert_eq!(
        spi(&mut mag, &[0x04, 0x00, 0x32, 0x00, 0x64, 0x01, 0x90]),
        [0; 7]
    );
    assert_eq!(mag.cycle_counts(), [50, 100, 400]);
    assert_eq!(
        spi(&mut mag, &[0x80 | 0x04, 0, 0, 0, 0, 0, 0, 0, 0]),
        [0x00, 0x00, 0x32, 0x00, 0x64, 0x01, 0x90, 0x00, 0x96]
    );
}

#[test]
fn spi_deselect_ends_the_transaction() {
    let mut mag = Rm3100::new();
    mag.select();
    mag.exchange(0x0B);
    mag.deselect();
    mag.exchange(0x92); // not selected: not decoded
    assert_eq!(read(&mut mag, Link::Spi, 0x0B, 1), [0x96]);
}
