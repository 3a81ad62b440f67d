//! Data ready in INT_STATUS_1 and on INT1/INT2: mapping, pulsed and latched modes, level,
//! open drain and output enable.

use super::*;
use margemu_firmware::chip::Chip;

/// Pulse length of a non-latched data-ready, ns.
const PULSE_NS: u64 = 156_250;

/// Uploaded, accel and gyro at 1.6 kHz, both on.
fn running() -> Bmi270 {
    let mut c = ready_chip();
    spi_write(&mut c, 0x40, &[0xAC, 0x03, 0xAC]);
    spi_write(&mut c, 0x7D, &[0x0E]);
    c
}

#[test]
fn int1_is_not_driven_until_its_output_is_enabled() {
    let mut c = running();
    spi_write(&mut c, 0x58, &[0x04]); // data ready on INT1, output still disabled
    c.latch_at(&fc::sample(1), MS);
    assert!(c.int_pin_at(MS), "released: the pull-up");
    assert!(c.int_open_drain(), "not driven");
    assert_eq!(c.int_pulse_end_ns(), Some(MS + PULSE_NS));
}

#[test]
fn betaflights_pin_pulses_high_for_each_sample() {
    let mut c = running();
    spi_write(&mut c, 0x58, &[0x04]);
    spi_write(&mut c, 0x53, &[0x0A]); // output, push-pull, active high
    assert!(!c.int_pin_at(0) && !c.int_open_drain());
    for k in 0..4u64 {
        let t = MS + k * 625_000;
        c.latch_at(&fc::sample(k as i16), t);
        assert!(c.int_pin_at(t));
        assert_eq!(Chip::int_pulse_end_ns(&c), Some(t + PULSE_NS));
        assert!(c.int_pin_at(t + PULSE_NS - 1));
        assert!(!c.int_pin_at(t + PULSE_NS), "the pulse has ended");
    }
    assert!(c.int2_pin_at(MS), "INT2 not driven: the pull-up");
}

#[test]
fn active_low_open_drain() {
    let mut c = running();
    spi_write(&mut c, 0x58, &[0x04]);
    spi_write(&mut c, 0x53, &[0x0C]); // output, open drain, active low
    assert!(c.int_open_drain());
    assert!(c.int_pin_at(0), "idle high");
    c.latch_at(&fc::sample(1), MS);
    assert!(!c.int_pin_at(MS), "pulled low");
    assert!(c.int_pin_at(MS + PULSE_NS));
}

#[test]
fn the_status_flags_clear_with_the_pulse_or_on_read() {
    let mut c = running();
    c.latch_at(&fc::sample(1), MS);
    c.advance(MS + 1_000);
    assert_eq!(
        read1(&mut c, 0x1D),
        0xC0,
        "acc_drdy and gyr_drdy, not mapped anyway"
    );
    assert_eq!(read1(&mut c, 0x1D), 0x00, "cleared on read");
    c.latch_at(&fc::sample(2), 2 * MS);
    c.advance(2 * MS + PULSE_NS);
    assert_eq!(
        read1(&mut c, 0x1D),
        0x00,
        "non-latched: gone with the pulse"
    );
}

#[test]
fn latched_mode_holds_until_int_status_1_is_read() {
    let mut c = running();
    spi_write(&mut c, 0x53, &[0x0A]);
    spi_write(&mut c, 0x55, &[0x01]); // INT_LATCH
    spi_write(&mut c, 0x58, &[0x04]);
    c.latch_at(&fc::sample(1), MS);
    c.advance(5 * MS);
    assert!(c.int_pin_at(5 * MS), "held");
    assert_eq!(c.int_pulse_end_ns(), None);
    assert_eq!(read1(&mut c, 0x1D), 0xC0);
    assert!(!c.int_pin_at(5 * MS), "released by the read");
}

#[test]
fn int2_follows_its_own_mapping_and_control() {
    let mut c = running();
    spi_write(&mut c, 0x54, &[0x0A]); // INT2 output, active high
    spi_write(&mut c, 0x58, &[0x40]); // data ready on INT2 only
    spi_write(&mut c, 0x53, &[0x0A]);
    c.latch_at(&fc::sample(1), MS);
    assert!(c.int2_pin_at(MS));
    assert!(!c.int_pin_at(MS), "INT1 not mapped");
    assert_eq!(c.int_pulse_end_ns(), None, "no INT1 pulse to schedule");
}

#[test]
fn no_interrupt_without_new_data() {
    let mut c = running();
    spi_write(&mut c, 0x58, &[0x04]);
    spi_write(&mut c, 0x53, &[0x0A]);
    spi_write(&mut c, 0x7D, &[0x08]); // temperature only
    c.latch_at(&fc::sample(1), MS);
    assert!(!c.int_pin_at(MS));
    assert_eq!(read1(&mut c, 0x1D), 0x00);
}

#[test]
fn a_soft_reset_clears_the_interrupt_state() {
    let mut c = running();
    spi_write(&mut c, 0x55, &[0x01]);
    c.latch_at(&fc::sample(1), MS);
    spi_write(&mut c, 0x7E, &[0xB6]);
    dummy_read(&mut c);
    assert_eq!(read1(&mut c, 0x1D), 0x00);
    assert_eq!(read1(&mut c, 0x55), 0x00);
}
