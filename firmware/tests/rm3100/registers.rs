//! Reset values (DS Table 5-1) and read-back of every written register through its mask, over
//! both buses.

use super::*;

/// The register file at power-on, 0x00..=0x36.
fn reset_value(addr: u8) -> u8 {
    match addr {
        0x05 | 0x07 | 0x09 => 0xC8, // cycle counts 0x00C8
        0x0B => 0x96,               // TMRC ~37 Hz
        0x35 => 0x1B,               // HSHAKE
        0x36 => 0x22,               // REVID
        _ => 0x00,
    }
}

#[test]
fn reset_values_over_i2c_and_spi() {
    for link in [Link::I2c(ADDRESS), Link::Spi] {
        let mut mag = Rm3100::new();
        let all = read(&mut mag, link, 0x00, 0x37);
        for (addr, &value) in all.iter().enumerate() {
            // Reading the results with DRDY clear (earlier in the burst) set NACK2.
            let want = match addr {
                0x35 => 0x5B,
                _ => reset_value(addr as u8),
            };
            assert_eq!(value, want, "{link:?} {addr:#04x}");
        }
        assert_eq!(read(&mut Rm3100::new(), link, 0x35, 1), [0x1B], "{link:?}");
        // One register at a time, as ArduPilot's probe does.
        for addr in 0x04..=0x09 {
            assert_eq!(
                read(&mut mag, link, addr, 1),
                [reset_value(addr)],
                "{link:?}"
            );
        }
    }
}

#[test]
fn written_registers_read_back_through_their_masks() {
    // (register, written, read back): CMM keeps bits 6..2 and 0, BIST its writable bits (the
    // OK bits read 0 until a self test ran), HSHAKE the DRC bits with bit 3 always set.
    let cases = [
        (0x04, 0xA5, 0xA5),
        (0x05, 0x5A, 0x5A),
        (0x06, 0xFF, 0xFF),
        (0x07, 0x01, 0x01),
        (0x08, 0x12, 0x12),
        (0x09, 0x34, 0x34),
        (0x0B, 0x94, 0x94),
        (0x0B, 0x0F, 0x0F),
        (0x33, 0x7F, 0x0F),
        (0x33, 0x80, 0x80),
        (0x35, 0xFC, 0x08),
        (0x35, 0x03, 0x0B),
        (0x01, 0x79, 0x79),
        (0x01, 0x82, 0x00),
        (0x00, 0xFF, 0x70),
        (0x00, 0x8F, 0x00),
    ];
    for link in [Link::I2c(ADDRESS), Link::Spi] {
        let mut mag = Rm3100::new();
        for (reg, value, back) in cases {
            assert!(write(&mut mag, link, reg, &[value]), "{link:?} {reg:#04x}");
            assert_eq!(read(&mut mag, link, reg, 1), [back], "{link:?} {reg:#04x}");
        }
        assert_eq!(mag.cycle_counts(), [0xA55A, 0xFF01, 0x1234]);
    }
}

#[test]
fn read_only_registers_keep_their_values() {
    for link in [Link::I2c(ADDRESS), Link::Spi] {
        let mut mag = Rm3100::new();
        for reg in [0x24, 0x2C, 0x34, 0x36] {
            write(&mut mag, link, reg, &[0x55]);
        }
        assert_eq!(read(&mut mag, link, 0x24, 9), [0; 9], "{link:?}");
        // NACK0 (the refused writes) and NACK2 (the results read without DRDY).
        assert_eq!(
            read(&mut mag, link, 0x34, 3),
            [0x00, 0x5B, 0x22],
            "{link:?}"
        );
    }
}

#[test]
fn cycle_counts_set_in_one_burst() {
    // PNI's example (DS §5.7.1, §5.8.1): 100 counts on all axes from one address byte.
    for link in [Link::I2c(ADDRESS), Link::Spi] {
        let mut mag = Rm3100::new();
        assert!(write(&mut mag, link, 0x04, &[0, 100, 0, 100, 0, 100]));
        assert_eq!(mag.cycle_counts(), [100; 3], "{link:?}");
        assert_eq!(
            read(&mut mag, link, 0x04, 6),
            [0, 100, 0, 100, 0, 100],
            "{link:?}"
        );
    }
}
