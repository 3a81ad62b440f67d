//! Access rules per register: reset values, writable bits, read-only registers and burst
//! addressing (DS: register map and register description).

use super::reg;

/// `(reset value, writable bits)` of a listed register; `None` for reserved addresses.
/// Read-only registers have no writable bits.
const fn spec(addr: u8) -> Option<(u8, u8)> {
    let s = match addr {
        reg::CHIP_ID => (super::CHIP_ID, 0),
        reg::ERR_REG => (0x00, 0),
        reg::STATUS => (0x10, 0),
        0x04..=0x1A => (0x00, 0), // aux, accel, gyro data and sensor time
        reg::EVENT => (0x01, 0),
        0x1C..=0x20 => (0x00, 0), // INT_STATUS_0/1, SC_OUT_0/1, WR_GEST_ACT
        reg::INTERNAL_STATUS => (0x00, 0),
        reg::TEMPERATURE_0 => (0x00, 0),
        reg::TEMPERATURE_1 => (0x80, 0),
        reg::FIFO_LENGTH_0 | reg::FIFO_LENGTH_1 | reg::FIFO_DATA => (0x00, 0),
        reg::FEAT_PAGE => (0x00, 0x07),
        0x30..=0x3F => (0x00, 0xFF), // FEATURES of the selected page
        reg::ACC_CONF => (0xA8, 0xFF),
        reg::ACC_RANGE => (0x02, 0x03),
        reg::GYR_CONF => (0xA9, 0xFF),
        reg::GYR_RANGE => (0x00, 0x0F),
        0x44 => (0x46, 0xFF), // AUX_CONF
        reg::FIFO_DOWNS => (0x88, 0xFF),
        0x46 => (0x00, 0xFF), // FIFO_WTM_0
        0x47 => (0x02, 0x1F), // FIFO_WTM_1
        reg::FIFO_CONFIG_0 => (0x02, 0x03),
        reg::FIFO_CONFIG_1 => (0x10, 0xFF),
        0x4A => (0x00, 0),    // SATURATION
        0x4B => (0x20, 0xFE), // AUX_DEV_ID
        0x4C => (0x83, 0xCF), // AUX_IF_CONF
        0x4D => (0x42, 0xFF), // AUX_RD_ADDR
        0x4E => (0x4C, 0xFF), // AUX_WR_ADDR
        0x4F => (0x02, 0xFF), // AUX_WR_DATA
        0x52 => (0x00, 0xFF), // ERR_REG_MSK
        reg::INT1_IO_CTRL | reg::INT2_IO_CTRL => (0x00, 0x1E),
        reg::INT_LATCH => (0x00, 0x01),
        0x56..=reg::INT_MAP_DATA => (0x00, 0xFF), // INT1/INT2_MAP_FEAT, INT_MAP_DATA
        reg::INIT_CTRL => (0x00, 0xFF),
        reg::INIT_ADDR_0 => (0x00, 0x0F),
        reg::INIT_ADDR_1 => (0x00, 0xFF),
        reg::INIT_DATA => (0x00, 0xFF), // port into the configuration RAM; reads 0 here
        reg::INTERNAL_ERROR => (0x00, 0),
        0x68 => (0x01, 0x03), // AUX_IF_TRIM
        0x69 => (0x00, 0x06), // GYR_CRT_CONF
        0x6A => (0x00, 0x02), // NVM_CONF
        reg::IF_CONF => (0x00, 0x31),
        0x6C => (0xFF, 0xFF),        // DRV
        0x6D => (0x00, 0x0D),        // ACC_SELF_TEST
        0x6E => (0x00, 0),           // GYR_SELF_TEST_AXES
        0x70 => (0x00, 0x0F),        // NV_CONF
        0x71..=0x77 => (0x00, 0xFF), // OFFSET_0..=6
        reg::PWR_CONF => (0x03, 0x07),
        reg::PWR_CTRL => (0x00, 0x0F),
        reg::CMD => (0x00, 0xFF), // write-only, reads 0
        _ => return None,
    };
    Some(s)
}

/// Whether the datasheet lists `addr`.
pub const fn is_defined(addr: u8) -> bool {
    spec(addr).is_some()
}

/// The power-on (and soft-reset) value of `addr`; 0 for reserved addresses.
pub const fn reset_value(addr: u8) -> u8 {
    match spec(addr) {
        Some((value, _)) => value,
        None => 0,
    }
}

/// The bits of `addr` a write changes; 0 for read-only and reserved registers.
pub const fn write_mask(addr: u8) -> u8 {
    match spec(addr) {
        Some((_, mask)) => mask,
        None => 0,
    }
}

/// Whether `addr` is listed and read-only.
pub const fn is_read_only(addr: u8) -> bool {
    matches!(spec(addr), Some((_, 0)))
}

/// The register a burst moves to after `addr`: the next one, wrapping at 0x7F, except on the
/// FIFO_DATA and INIT_DATA ports, which stay.
pub const fn next_address(addr: u8) -> u8 {
    match addr {
        reg::FIFO_DATA | reg::INIT_DATA => addr,
        _ => addr.wrapping_add(1) & 0x7F,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reset_values_of_the_registers_drivers_read() {
        assert_eq!(reset_value(reg::CHIP_ID), 0x24);
        assert_eq!(reset_value(reg::STATUS), 0x10);
        assert_eq!(reset_value(reg::ACC_CONF), 0xA8);
        assert_eq!(reset_value(reg::ACC_RANGE), 0x02);
        assert_eq!(reset_value(reg::GYR_CONF), 0xA9);
        assert_eq!(reset_value(reg::PWR_CONF), 0x03);
        assert_eq!(reset_value(reg::PWR_CTRL), 0x00);
        assert_eq!(
            [
                reset_value(reg::TEMPERATURE_0),
                reset_value(reg::TEMPERATURE_1)
            ],
            [0x00, 0x80]
        );
    }

    #[test]
    fn read_only_and_reserved() {
        assert!(is_read_only(reg::CHIP_ID));
        assert!(is_read_only(reg::INTERNAL_STATUS));
        assert!(!is_read_only(reg::CMD));
        assert!(!is_read_only(0x01)); // reserved, not read-only
        assert!(!is_defined(0x01));
        assert_eq!(write_mask(0x01), 0);
        assert_eq!(write_mask(reg::PWR_CTRL), 0x0F);
    }

    #[test]
    fn bursts_stay_on_ports_and_wrap() {
        assert_eq!(next_address(reg::ACC_X_LSB), 0x0D);
        assert_eq!(next_address(reg::INIT_DATA), reg::INIT_DATA);
        assert_eq!(next_address(reg::FIFO_DATA), reg::FIFO_DATA);
        assert_eq!(next_address(0x7F), 0x00);
    }
}
