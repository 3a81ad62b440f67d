//! INT_PIN_CFG, INT_ENABLE, INT_STATUS and the INT pin (RM sections 4.19–4.21).

use super::*;

const US: u64 = 1_000;

#[test]
fn data_ready_is_set_by_a_sample_and_cleared_by_reading_int_status() {
    let mut c = chip();
    assert_eq!(spi_read(&mut c, 0x3A, 1), [0x00]);
    c.latch_at(&at_rest(), MS);
    assert_eq!(
        spi_read(&mut c, 0x3A, 1),
        [0x01],
        "set even though RAW_RDY_EN is off"
    );
    assert_eq!(spi_read(&mut c, 0x3A, 1), [0x00], "cleared by the read");
    c.latch_at(&at_rest(), 2 * MS);
    spi_read(&mut c, 0x3B, 14);
    assert_eq!(
        spi_read(&mut c, 0x3A, 1),
        [0x01],
        "other reads do not clear it"
    );
}

#[test]
fn int_anyrd_2clear_clears_on_any_read() {
    let mut c = chip();
    spi_write(&mut c, 0x37, &[0x10]);
    c.latch_at(&at_rest(), MS);
    assert_eq!(spi_read(&mut c, 0x75, 1), [0x71]);
    assert_eq!(spi_read(&mut c, 0x3A, 1), [0x00]);
    c.latch_at(&at_rest(), 2 * MS);
    assert_eq!(i2c_read(&mut c, 0x68, 0x3B, 1), Some(vec![0x00]));
    assert_eq!(i2c_read(&mut c, 0x68, 0x3A, 1), Some(vec![0x00]));
}

#[test]
fn the_prefetch_of_int_status_does_not_clear_it() {
    let mut c = chip();
    c.latch_at(&at_rest(), MS);
    // Read 0x39 only: the chip prefetches 0x3A for a byte that is never clocked.
    assert_eq!(spi_read(&mut c, 0x39, 1), [0x00]);
    assert_eq!(spi_read(&mut c, 0x3A, 1), [0x01]);
}

#[test]
fn latched_int_pin_follows_enabled_status() {
    let mut c = chip();
    spi_write(&mut c, 0x37, &[0x20]); // LATCH_INT_EN, active high, push-pull
    c.latch_at(&at_rest(), MS);
    assert!(
        !c.int_pin(),
        "RAW_RDY_EN off: pin idle although the status bit is set"
    );
    spi_read(&mut c, 0x3A, 1);
    spi_write(&mut c, 0x38, &[0x01]); // RAW_RDY_EN
    c.latch_at(&at_rest(), 2 * MS);
    assert!(c.int_pin());
    c.advance(10 * MS);
    assert!(c.int_pin(), "held until the status is cleared");
    assert_eq!(spi_read(&mut c, 0x3A, 1), [0x01]);
    assert!(!c.int_pin());
}

#[test]
fn pulse_mode_is_50_us_wide() {
    let mut c = chip();
    spi_write(&mut c, 0x38, &[0x01]);
    c.latch_at(&at_rest(), MS);
    assert!(c.int_pin());
    assert_eq!(c.int_pulse_end_ns(), Some(MS + 50 * US));
    assert!(c.int_pin_at(MS + 49 * US));
    assert!(!c.int_pin_at(MS + 50 * US));
    c.advance(MS + 50 * US);
    assert!(!c.int_pin());
    assert_eq!(c.int_pulse_end_ns(), None);
    assert_eq!(
        spi_read(&mut c, 0x3A, 1),
        [0x01],
        "the status stays until read"
    );
}

#[test]
fn active_low_and_open_drain() {
    let mut c = chip();
    spi_write(&mut c, 0x37, &[0x80 | 0x40 | 0x20]); // ACTL, OPEN, LATCH_INT_EN
    spi_write(&mut c, 0x38, &[0x01]);
    assert!(c.int_pin(), "idle high");
    assert!(c.int_open_drain());
    c.latch_at(&at_rest(), MS);
    assert!(!c.int_pin(), "asserted low");
    assert!(c.int_asserted_at(MS));
}

#[test]
fn fifo_overflow_interrupt() {
    let mut c = chip();
    spi_write(&mut c, 0x38, &[0x10]); // FIFO_OFLOW_EN
    spi_write(&mut c, 0x37, &[0x20]);
    let mut fill = vec![0x74];
    fill.resize(1 + 512, 0xEE);
    spi(&mut c, &fill);
    assert_eq!(spi_read(&mut c, 0x3A, 1), [0x00], "full is not overflow");
    assert!(!c.int_pin());
    spi_write(&mut c, 0x74, &[0xEF]);
    assert!(c.int_pin());
    assert_eq!(spi_read(&mut c, 0x3A, 1), [0x10]);
    assert!(!c.int_pin());
}

#[test]
fn int_enable_and_pin_config_read_back() {
    let mut c = chip();
    spi_write(&mut c, 0x37, &[0xFF]);
    spi_write(&mut c, 0x38, &[0xFF]);
    assert_eq!(spi_read(&mut c, 0x37, 2), [0xFF, 0xFF]);
}
