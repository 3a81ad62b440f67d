//! INT_STATUS, INT1/INT2: pulsed or latched, polarity, drive, pulse length and de-assertion,
//! clear modes, FIFO threshold and full (DS 4.12 Interrupts,
//! INT_CONFIG, INT_CONFIG0/1, INT_SOURCE0/3).

use super::*;

#[test]
fn power_on_pin_is_a_pulsed_open_drain_active_low_line() {
    let mut c = running();
    spi_write(&mut c, 0x65, &[0x08]); // data ready on INT1
    assert!(c.int_open_drain());
    c.latch_at(&sample(1), MS);
    assert!(!c.int_pin_at(MS), "asserted = low");
    assert!(c.int_asserted_at(MS));
    assert_eq!(c.int_pulse_end_ns(), Some(MS + 100 * US));
    assert!(!c.int_pin_at(MS + 99 * US));
    assert!(c.int_pin_at(MS + 100 * US));
    c.advance(MS + 100 * US);
    assert_eq!(c.int_pulse_end_ns(), None);
    assert!(c.int_pin());
}

#[test]
fn push_pull_active_high_8us_pulses() {
    let mut c = running();
    spi_write(&mut c, 0x14, &[0x03]);
    spi_write(&mut c, 0x64, &[0x60]);
    spi_write(&mut c, 0x65, &[0x08]);
    assert!(!c.int_open_drain());
    assert!(
        !c.int_pin_at(MS - 1),
        "idle (the power-on RESET_DONE pulse is over)"
    );
    for k in 0..4u64 {
        let t = MS + k * 125 * US;
        c.latch_at(&sample(1), t);
        assert!(c.int_pin_at(t) && c.int_pin_at(t + 7 * US) && !c.int_pin_at(t + 8 * US));
    }
}

#[test]
fn deassert_time_swallows_pulses_at_8khz() {
    let mut c = running();
    spi_write(&mut c, 0x14, &[0x03]);
    spi_write(&mut c, 0x65, &[0x08]); // INT_CONFIG1 at reset: 100 µs, de-assert on
    c.latch_at(&sample(1), MS);
    c.latch_at(&sample(2), MS + 125 * US);
    assert!(
        !c.int_pin_at(MS + 125 * US),
        "100 µs pulse + 100 µs de-assert > 125 µs"
    );
    c.latch_at(&sample(3), MS + 250 * US);
    assert!(c.int_pin_at(MS + 250 * US));
    spi_write(&mut c, 0x64, &[0x20]);
    c.latch_at(&sample(4), MS + 375 * US);
    assert!(c.int_pin_at(MS + 375 * US), "TDEASSERT_DISABLE");
}

#[test]
fn latched_until_int_status_is_read() {
    let mut c = running();
    spi_read(&mut c, 0x2D, 1);
    spi_write(&mut c, 0x14, &[0x07]);
    spi_write(&mut c, 0x65, &[0x08]);
    c.latch_at(&sample(1), MS);
    assert!(c.int_pin_at(MS) && c.int_pin_at(10 * MS));
    assert_eq!(c.int_pulse_end_ns(), None);
    assert_eq!(spi_read(&mut c, 0x2D, 1), [0x08]);
    assert!(!c.int_pin_at(10 * MS));
}

#[test]
fn data_ready_cleared_by_a_data_read() {
    let mut c = running();
    spi_read(&mut c, 0x2D, 1);
    spi_write(&mut c, 0x63, &[0x20]); // UI_DRDY_INT_CLEAR = 10
    c.latch_at(&sample(1), MS);
    assert_eq!(spi_read(&mut c, 0x2D, 1), [0x08]);
    assert_eq!(
        spi_read(&mut c, 0x2D, 1),
        [0x08],
        "a status read does not clear it"
    );
    spi_read(&mut c, 0x1D, 14);
    assert_eq!(spi_read(&mut c, 0x2D, 1), [0x00]);
}

#[test]
fn int2_follows_int_source3() {
    let mut c = running();
    spi_read(&mut c, 0x2D, 1);
    spi_write(&mut c, 0x14, &[0x38]); // INT2 latched, push-pull, active high; INT1 pulsed
    spi_write(&mut c, 0x65, &[0x00]);
    spi_write(&mut c, 0x68, &[0x08]);
    c.latch_at(&sample(1), MS);
    assert!(c.int2_pin_at(MS));
    assert!(c.int_pin_at(MS), "INT1 idle (active low, nothing routed)");
    spi_read(&mut c, 0x2D, 1);
    assert!(!c.int2_pin_at(MS));
}

#[test]
fn fifo_threshold_once_or_every_packet() {
    let mut c = running();
    spi_read(&mut c, 0x2D, 1);
    spi_write(&mut c, 0x5F, &[0x03]);
    spi_write(&mut c, 0x60, &[32, 0]); // watermark 32 bytes
    spi_write(&mut c, 0x16, &[0x40]);
    c.latch_at(&sample(1), MS);
    assert_eq!(spi_read(&mut c, 0x2D, 1), [0x08]);
    c.latch_at(&sample(2), 2 * MS);
    assert_eq!(
        spi_read(&mut c, 0x2D, 1),
        [0x0C],
        "count reached 32: FIFO_THS_INT"
    );
    c.latch_at(&sample(3), 3 * MS);
    assert_eq!(spi_read(&mut c, 0x2D, 1), [0x08], "no new crossing");
    spi_write(&mut c, 0x5F, &[0x23]); // FIFO_WM_GT_TH
    c.latch_at(&sample(4), 4 * MS);
    assert_eq!(spi_read(&mut c, 0x2D, 1), [0x0C]);
}

#[test]
fn fifo_threshold_cleared_by_a_fifo_read_on_a_latched_pin() {
    let mut c = running();
    spi_read(&mut c, 0x2D, 1);
    spi_write(&mut c, 0x14, &[0x06]); // INT1 latched, push-pull, active low
    spi_write(&mut c, 0x5F, &[0x03]);
    spi_write(&mut c, 0x60, &[16, 0]);
    spi_write(&mut c, 0x63, &[0x08]); // FIFO_THS_INT_CLEAR = 10
    spi_write(&mut c, 0x65, &[0x04]);
    spi_write(&mut c, 0x16, &[0x80]);
    c.latch_at(&sample(1), MS);
    assert!(!c.int_pin_at(MS));
    assert_eq!(spi_read(&mut c, 0x2D, 1), [0x0C]);
    assert!(!c.int_pin_at(MS), "a status read leaves FIFO_THS");
    spi_read(&mut c, 0x30, 1);
    assert!(c.int_pin_at(MS), "one FIFO byte read clears it");
}
