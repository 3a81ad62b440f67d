//! The chip faults on the BMI270 (`Chip::fault_*` hooks): a reset loses the configuration
//! upload and returns the chip to I2C mode, as a power cycle does, until a driver brings it up
//! again; a forced FIFO overflow fills the FIFO and sets ERR_REG.fifo_err in stream mode until
//! a flush; a wrong CHIP_ID fails the drivers' probe.

use margemu_firmware::chip::Chip;

use super::fifo::{fifo_chip, fifo_length, latch_numbered};
use super::*;

#[test]
fn a_reset_loses_the_upload_and_the_spi_mode_until_the_driver_brings_it_up_again() {
    let mut c = fifo_chip(0x01, 0xD0);
    latch_numbered(&mut c, 1);
    assert_eq!(read(&mut c, 0x12, 2), 164i16.to_le_bytes(), "GYR_X");
    let now = c.now_ns();
    assert!(Chip::fault_reset(&mut c));
    assert_eq!(c.now_ns(), now, "the clock is kept");
    assert!(!c.is_spi_mode(), "back in I2C mode, as after power-up");
    assert_eq!(
        spi(&mut c, &[0x80 | 0x21, 0, 0]),
        [0, 0, 0],
        "the switching transaction"
    );
    let fresh = spi_chip();
    for addr in (0..0x80).filter(|a| !(0x18..=0x1A).contains(a)) {
        assert_eq!(c.peek(addr), fresh.peek(addr), "register {addr:#04x}");
    }
    assert_eq!(read1(&mut c, 0x21), 0x00, "INTERNAL_STATUS: not_init");
    assert_eq!(
        read1(&mut c, 0x7D),
        0x00,
        "PWR_CTRL: a read-back sees the reset"
    );
    // Sensors enabled without the upload: the data registers stay at their reset value.
    spi_write(&mut c, 0x7D, &[0x0E]);
    latch_numbered(&mut c, 2);
    assert_eq!(read(&mut c, 0x12, 2), [0, 0]);
    // A driver's bring-up (upload, then its configuration) recovers.
    upload(&mut c, &config_file(328));
    assert_eq!(read1(&mut c, 0x21), 0x01, "init_ok");
    spi_write(&mut c, 0x40, &[0xAC, 0x03, 0xAC]);
    spi_write(&mut c, 0x43, &[0x08]);
    spi_write(&mut c, 0x7D, &[0x0E]);
    latch_numbered(&mut c, 3);
    assert_eq!(read(&mut c, 0x12, 2), (3 * 164i16).to_le_bytes());
}

#[test]
fn a_forced_overflow_fills_the_fifo_and_sets_fifo_err_until_a_flush() {
    let mut c = fifo_chip(0x00, 0xD0); // stream mode, headers, accel + gyro: 13-byte frames
    assert!(Chip::fault_fifo_overflow(&mut c, true));
    latch_numbered(&mut c, 1);
    assert_eq!(
        fifo_length(&mut c),
        157 * 13,
        "as many whole frames as fit in 2 KB"
    );
    assert_eq!(read1(&mut c, 0x02) & 0x40, 0x40, "ERR_REG.fifo_err");
    let frame = read(&mut c, 0x26, 13);
    assert_eq!(frame[..3], [0x8C, 164, 0], "copies of the sample's frame");
    latch_numbered(&mut c, 2);
    assert_eq!(
        fifo_length(&mut c),
        157 * 13,
        "full again at the next sample"
    );
    assert!(Chip::fault_fifo_overflow(&mut c, false));
    spi_write(&mut c, 0x7E, &[0xB0]); // FIFO flush
    assert_eq!(read1(&mut c, 0x02), 0x00);
    latch_numbered(&mut c, 3);
    assert_eq!(fifo_length(&mut c), 13, "one frame: exact after the fault");
    assert_eq!(
        read(&mut c, 0x26, 3),
        [0x8C, (3 * 164) as u8, ((3 * 164) >> 8) as u8]
    );
}

#[test]
fn stop_on_full_mode_fills_without_fifo_err() {
    let mut c = fifo_chip(0x01, 0xD0);
    assert!(Chip::fault_fifo_overflow(&mut c, true));
    latch_numbered(&mut c, 1);
    assert_eq!(fifo_length(&mut c), 157 * 13);
    assert_eq!(
        read1(&mut c, 0x02),
        0x00,
        "stop-on-full: the lost frame is no error"
    );
}

#[test]
fn a_wrong_chip_id_fails_the_probe() {
    let mut c = spi_chip();
    assert!(Chip::fault_identity(&mut c, Some(0x00)));
    assert_ne!(
        read1(&mut c, 0x00),
        0x24,
        "Betaflight and ArduPilot probe CHIP_ID = 0x24"
    );
    assert!(Chip::fault_identity(&mut c, None));
    assert_eq!(read1(&mut c, 0x00), 0x24);
}
