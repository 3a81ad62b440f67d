//! Interface selection, the dummy byte, bursts, soft reset, write masks and read-back.

use super::*;
use margemu_protocol::regmap::bmi270::{is_defined, is_read_only, reset_value, write_mask};

#[test]
fn i2c_mode_until_a_chip_select_edge() {
    let mut c = chip();
    assert!(!c.is_spi_mode());
    // Nothing is decoded in I2C mode: the read returns 0x00 and a write is lost.
    assert_eq!(spi(&mut c, &[0x80, 0x00, 0x00]), [0x00, 0x00, 0x00]);
    assert!(c.is_spi_mode());
    let mut c = chip();
    spi(&mut c, &[0x41, 0x01]); // ACC_RANGE, ignored but switches to SPI
    assert_eq!(read1(&mut c, 0x41), 0x02);
}

#[test]
fn every_read_starts_with_a_dummy_byte() {
    let mut c = spi_chip();
    assert_eq!(spi(&mut c, &[0x80, 0x00, 0x00]), [0x00, 0x00, 0x24]);
    // A burst: dummy, then CHIP_ID, 0x01 (reserved), ERR_REG, STATUS (cmd_rdy).
    assert_eq!(read(&mut c, 0x00, 4), [0x24, 0x00, 0x00, 0x10]);
    // Writes have no dummy byte.
    spi_write(&mut c, 0x40, &[0xAC, 0x03]);
    assert_eq!(read(&mut c, 0x40, 2), [0xAC, 0x03]);
}

#[test]
fn power_on_values() {
    let c = spi_chip();
    for addr in 0..0x80u8 {
        let expected = match addr {
            0x7E | 0x5E => 0,
            0x26 => 0x80, // empty FIFO
            _ => reset_value(addr),
        };
        assert_eq!(c.peek(addr), expected, "register {addr:#04x}");
    }
    assert_eq!([c.peek(0x22), c.peek(0x23)], [0x00, 0x80]); // temperature invalid
    assert_eq!(c.peek(0x21), 0x00); // not_init
}

#[test]
fn every_written_register_reads_back_within_its_mask() {
    for addr in 0..0x80u8 {
        if matches!(addr, 0x59 | 0x5E | 0x7E) || !is_defined(addr) || is_read_only(addr) {
            continue;
        }
        let mut c = spi_chip();
        for value in [0x00, 0xFF, 0x5A, 0xA5] {
            spi_write(&mut c, addr, &[value]);
            assert_eq!(read1(&mut c, addr), value & write_mask(addr), "{addr:#04x}");
        }
    }
}

#[test]
fn read_only_and_reserved_ignore_writes() {
    let mut c = spi_chip();
    for addr in [0x00, 0x01, 0x03, 0x21, 0x5F, 0x7A] {
        let before = read1(&mut c, addr);
        spi_write(&mut c, addr, &[!before]);
        assert_eq!(read1(&mut c, addr), before, "{addr:#04x}");
    }
}

#[test]
fn soft_reset_restores_power_on_values_and_i2c_mode() {
    let mut c = spi_chip();
    spi_write(&mut c, 0x41, &[0x00]);
    spi_write(&mut c, 0x7D, &[0x0E]);
    spi_write(&mut c, 0x7C, &[0x00]);
    upload(&mut c, &config_file(328));
    assert_eq!(read1(&mut c, 0x21), 0x01);
    // CMD = 0xB6, then a byte that must not be decoded (the chip is resetting).
    spi(&mut c, &[0x7E, 0xB6, 0x41]);
    assert!(
        !c.is_spi_mode(),
        "the reset's own chip-select edge does not count"
    );
    assert_eq!(spi(&mut c, &[0x80, 0x00, 0x00]), [0x00; 3]);
    assert_eq!(read1(&mut c, 0x00), 0x24);
    assert_eq!(read(&mut c, 0x7C, 2), [0x03, 0x00]);
    assert_eq!(read1(&mut c, 0x41), 0x02);
    assert_eq!(read1(&mut c, 0x21), 0x00);
    assert_eq!(read1(&mut c, 0x7E), 0x00); // CMD is write-only
}

#[test]
fn other_commands_change_nothing() {
    let mut c = spi_chip();
    spi_write(&mut c, 0x41, &[0x01]);
    spi_write(&mut c, 0x7E, &[0xB0]); // FIFO flush: no FIFO yet
    assert!(c.is_spi_mode());
    assert_eq!(read1(&mut c, 0x41), 0x01);
}

#[test]
fn writes_are_logged_except_init_data() {
    let mut c = spi_chip();
    spi_write(&mut c, 0x7D, &[0x0E]);
    spi_write(&mut c, 0x5E, &config_file(16));
    let w = c.pop_write().expect("PWR_CTRL logged");
    assert_eq!((w.device, w.register, w.value), (0x68, 0x7D, 0x0E));
    assert_eq!(c.pop_write(), None);
}

#[test]
fn a_bare_chip_select_toggle_selects_spi() {
    // Betaflight's bmi270EnableSPI: CS low, CS high, no clocks.
    let mut c = chip();
    c.select();
    c.deselect();
    assert_eq!(read1(&mut c, 0x00), 0x24);
    spi_write(&mut c, 0x7E, &[0xB6]);
    c.select();
    c.deselect();
    assert_eq!(read1(&mut c, 0x00), 0x24);
}
