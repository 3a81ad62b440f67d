//! The chip faults on the BMI088 (`Chip::fault_*` hooks, on both dies): a forced FIFO overflow
//! as each die's FIFO reports one (the accelerometer's skip frame, the gyroscope's
//! FIFO_STATUS.fifo_overrun), exact again after a FIFO reset; a reset powers both dies up
//! again (the accelerometer suspended and back in I2C mode).

use margemu_firmware::chip::bmi088::{Bmi088, Config};
use margemu_firmware::chip::Chip;

use super::fifo::{accel_k, fifo_accel, fifo_gyro, fifo_length, gyro_k};
use super::*;

#[test]
fn a_forced_accel_overflow_fills_the_fifo_and_the_next_burst_skips() {
    for stop in [true, false] {
        let mut c = fifo_accel(stop);
        c.fault_fifo_overflow(true);
        accel_k(&mut c, 1);
        assert_eq!(fifo_length(&mut c), 146 * 7, "full: 146 frames of 7 bytes");
        let bytes = aread(&mut c, 0x26, 3);
        assert_eq!(bytes[..2], [0x40, 1], "a skip frame: one frame lost");
        assert_eq!(bytes[2], 0x84, "then acceleration frames");
        c.fault_fifo_overflow(false);
        spi_write(&mut c, 0x7E, &[0xB0]); // FIFO reset
        accel_k(&mut c, 2);
        assert_eq!(fifo_length(&mut c), 7, "one frame after the fault");
        assert_eq!(
            aread(&mut c, 0x26, 3),
            [0x84, 0x55, 0x01],
            "2/8 g at 1365 LSB/g: 341"
        );
    }
}

#[test]
fn a_forced_gyro_overflow_sets_fifo_overrun_until_the_fifo_is_configured_again() {
    for mode in [0x40, 0x80] {
        let mut g = fifo_gyro(mode);
        g.fault_fifo_overflow(true);
        gyro_k(&mut g, 1);
        let status = gread1(&mut g, 0x0E);
        assert_eq!(status & 0x80, 0x80, "FIFO_STATUS.fifo_overrun");
        assert_eq!(status & 0x7F, if mode == 0x40 { 100 } else { 99 }, "full");
        g.fault_fifo_overflow(false);
        spi_write(&mut g, 0x3E, &[mode]); // a FIFO_CONFIG_1 write empties it
        gyro_k(&mut g, 2);
        assert_eq!(gread1(&mut g, 0x0E), 1, "one frame, no overrun");
    }
}

#[test]
fn a_reset_powers_both_dies_up_again() {
    let mut chip = Bmi088::new(Config::default());
    let mut fresh = chip.clone();
    assert!(chip.write_register(0, 0x7D, 0x04)); // ACC_PWR_CTRL: on
    assert!(chip.write_register(1, 0x0F, 0x03)); // GYRO_RANGE: ±250 °/s
    chip.advance(3_000_000);
    assert!(Chip::fault_reset(&mut chip));
    assert_eq!(chip.now_ns(), 3_000_000, "the clock is kept");
    assert!(!chip.accel().is_spi_mode() && !chip.accel().is_on());
    fresh.advance(3_000_000);
    for addr in (0..0x80).filter(|a| !(0x18..=0x1A).contains(a)) {
        assert_eq!(
            chip.accel().peek(addr),
            fresh.accel().peek(addr),
            "accel {addr:#04x}"
        );
        assert_eq!(
            chip.gyro().peek(addr),
            fresh.gyro().peek(addr),
            "gyro {addr:#04x}"
        );
    }
}
