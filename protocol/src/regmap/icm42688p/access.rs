//! Access rules per register: reset values, writable bits, read-only and self-clearing
//! registers, burst addressing (DS register map and register descriptions).

use super::{bank0, bank3, bits, BANKS, REG_BANK_SEL};

/// The emulated part's factory trim: bank 1 GYRO_CONFIG_STATIC6..=9 (0x0F..=0x12), bank 1
/// X/Y/ZG_ST_DATA (0x5F..=0x61) and bank 2 X/Y/ZA_ST_DATA (0x3B..=0x3D), as `(bank, addr, value)`.
pub const FACTORY_TRIM: [(u8, u8, u8); 10] = [
    (1, 0x0F, 0x1F),
    (1, 0x10, 0x1E),
    (1, 0x11, 0x20),
    (1, 0x12, 0x00),
    (1, 0x5F, 0x6B),
    (1, 0x60, 0x71),
    (1, 0x61, 0x66),
    (2, 0x3B, 0x5C),
    (2, 0x3C, 0x61),
    (2, 0x3D, 0x75),
];

/// `(reset value, writable bits)` of a listed register; `None` for reserved addresses.
const fn spec(bank: u8, addr: u8) -> Option<(u8, u8)> {
    if addr == REG_BANK_SEL && bank < BANKS {
        return Some((0x00, 0x07));
    }
    let mut i = 0;
    while i < FACTORY_TRIM.len() {
        let (b, a, v) = FACTORY_TRIM[i];
        if b == bank && a == addr {
            let mask = if bank == 1 && addr == 0x12 {
                0x3F
            } else {
                0xFF
            };
            return Some((v, mask));
        }
        i += 1;
    }
    match bank {
        0 => bank0_spec(addr),
        1 => bank1_spec(addr),
        2 => match addr {
            0x03 => Some((0x30, 0x7F)),
            0x04 => Some((0x40, 0xFF)),
            0x05 => Some((0x62, 0xFF)),
            _ => None,
        },
        3 => match addr {
            bank3::CLKDIV => Some((0x00, 0x7F)),
            _ => None,
        },
        4 => match addr {
            0x40 => Some((0xA2, 0xFF)),
            0x41 => Some((0x85, 0xFF)),
            0x42 => Some((0x51, 0xFF)),
            0x43 => Some((0xA4, 0xFF)),
            0x44 => Some((0x8C, 0xFF)),
            0x45 => Some((0x5C, 0xFF)),
            0x46 => Some((0x45, 0xFF)),
            0x47 => Some((0x5B, 0xFF)),
            0x48 | 0x4A..=0x51 | 0x77..=0x7F => Some((0x00, 0xFF)),
            _ => None,
        },
        _ => None,
    }
}

const fn bank0_spec(addr: u8) -> Option<(u8, u8)> {
    // Read-only and read-to-clear registers have no writable bits.
    Some(match addr {
        0x11 => (0x00, 0x10), // SPI_MODE; SOFT_RESET_CONFIG acts and reads 0
        0x13 => (0x05, 0x3F),
        0x14 => (0x00, 0x3F),
        0x16 => (0x00, 0xC0),
        0x1D | 0x1F | 0x21 | 0x23 | 0x25 | 0x27 | 0x29 => (0x80, 0x00),
        0x1E | 0x20 | 0x22 | 0x24 | 0x26 | 0x28 | 0x2A | 0x2B | 0x2C => (0x00, 0x00),
        0x2D => (0x10, 0x00),
        0x2E | 0x2F => (0x00, 0x00),
        0x30 => (0xFF, 0x00),
        0x31..=0x33 | 0x35..=0x38 => (0x00, 0x00),
        0x34 => (0x04, 0x00),
        0x4B => (0x00, 0x00), // every bit acts and reads 0
        0x4C => (0x30, 0xF3),
        0x4D => (0x91, 0xCF), // bits 5:4 reserved
        0x4E => (0x00, 0x3F),
        0x4F | 0x50 => (0x06, 0xEF),
        0x51 => (0x16, 0xEF),
        0x52 => (0x11, 0xFF),
        0x53 => (0x0D, 0x1E),
        0x54 => (0x23, 0x1F),
        0x56 => (0x82, 0xFB),
        0x57 => (0x00, 0x0F),
        0x5F => (0x00, 0x7F),
        0x60 => (0x00, 0xFF),
        0x61 => (0x00, 0x0F),
        0x62 => (0x10, 0x73),
        0x63 => (0x00, 0x3F),
        0x64 => (0x10, 0x70),
        0x65 => (0x10, 0x7F),
        0x66 | 0x69 => (0x00, 0x0F),
        0x68 => (0x00, 0x7F),
        0x6C | 0x6D => (0x00, 0x00),
        0x70 => (0x00, 0x7F),
        0x75 => (0x47, 0x00),
        _ => return None,
    })
}

const fn bank1_spec(addr: u8) -> Option<(u8, u8)> {
    Some(match addr {
        0x03 => (0x80, 0x3F),
        0x0B => (0xA0, 0x03),
        0x0C => (0x0D, 0x3F),
        0x0D => (0xAA, 0xFF),
        0x0E => (0x80, 0xFF),
        0x13 => (0x11, 0x70),
        0x62..=0x64 => (0x00, 0x00),
        0x7A => (0x83, 0x42),
        0x7B => (0x00, 0x06),
        0x7C => (0x5F, 0x9F),
        _ => return None,
    })
}

/// Whether `(bank, addr)` is a register the datasheet lists (else it is reserved).
pub const fn is_defined(bank: u8, addr: u8) -> bool {
    spec(bank, addr).is_some()
}

/// Reset value of `(bank, addr)`: the datasheet's, the part's trim for factory-trimmed
/// registers, 0 for reserved addresses.
pub const fn reset_value(bank: u8, addr: u8) -> u8 {
    match spec(bank, addr) {
        Some((value, _)) => value,
        None => 0x00,
    }
}

/// Bits a serial-interface write stores in `(bank, addr)`; the others keep their value
/// (reserved bits their reset value). 0 for read-only, read-to-clear and reserved registers.
pub const fn write_mask(bank: u8, addr: u8) -> u8 {
    match spec(bank, addr) {
        Some((_, mask)) => mask,
        None => 0x00,
    }
}

/// Bits of `(bank, addr)` that act when written as 1 and read back 0: DEVICE_CONFIG bit 0
/// (soft reset) and SIGNAL_PATH_RESET bits 6, 5, 3, 2, 1.
pub const fn self_clearing_mask(bank: u8, addr: u8) -> u8 {
    match (bank, addr) {
        (0, bank0::DEVICE_CONFIG) => bits::SOFT_RESET_CONFIG,
        (0, bank0::SIGNAL_PATH_RESET) => 0x6E,
        _ => 0x00,
    }
}

/// Whether `(bank, addr)` is a listed register a write cannot change (data, status, counts,
/// WHO_AM_I, timestamps).
pub const fn is_read_only(bank: u8, addr: u8) -> bool {
    is_defined(bank, addr) && write_mask(bank, addr) == 0 && self_clearing_mask(bank, addr) == 0
}

/// The register a burst reaches after `addr`: the next one in the same bank (wrapping at 0x7F),
/// except FIFO_DATA in bank 0, which a burst keeps reading (DS: SPI interface).
pub const fn next_address(bank: u8, addr: u8) -> u8 {
    if bank == 0 && addr == bank0::FIFO_DATA {
        addr
    } else {
        addr.wrapping_add(1) & 0x7F
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bank0_reset_values() {
        let expected: [(u8, u8); 12] = [
            (0x13, 0x05),
            (0x1D, 0x80),
            (0x2D, 0x10),
            (0x30, 0xFF),
            (0x4C, 0x30),
            (0x4D, 0x91),
            (0x51, 0x16),
            (0x52, 0x11),
            (0x53, 0x0D),
            (0x54, 0x23),
            (0x64, 0x10),
            (0x65, 0x10),
        ];
        for (addr, value) in expected {
            assert_eq!(reset_value(0, addr), value, "{addr:#04x}");
        }
        assert_eq!(reset_value(0, 0x00), 0);
        assert_eq!(reset_value(7, 0x76), 0, "no bank 7");
    }

    #[test]
    fn masks_and_access() {
        assert_eq!(write_mask(0, bank0::INTF_CONFIG1), 0xCF);
        assert_eq!(write_mask(0, bank0::DEVICE_CONFIG), 0x10);
        assert!(is_read_only(0, bank0::WHO_AM_I));
        assert!(is_read_only(0, bank0::INT_STATUS));
        assert!(!is_read_only(0, bank0::SIGNAL_PATH_RESET));
        assert!(!is_read_only(0, 0x00), "reserved, not read-only");
        for bank in 0..BANKS {
            assert_eq!(write_mask(bank, REG_BANK_SEL), 0x07);
        }
        assert_eq!(write_mask(1, 0x12), 0x3F);
    }

    #[test]
    fn bursts_stay_on_fifo_data() {
        assert_eq!(next_address(0, 0x2D), 0x2E);
        assert_eq!(next_address(0, 0x30), 0x30);
        assert_eq!(next_address(1, 0x30), 0x31);
        assert_eq!(next_address(2, 0x7F), 0x00);
    }
}
