//! Identity, interface selection, the dummy byte, bursts, soft resets, reset values, write masks
//! and read-back of both dies, and their I2C targets.

use super::*;
use margemu_firmware::chip::I2cTarget;
use margemu_protocol::regmap::bmi088::Die;

/// Registers whose writes do more than store (commands, FIFO clears, power modes).
fn is_special(die: Die, addr: u8) -> bool {
    match die {
        Die::Accel => addr == 0x7E,
        Die::Gyro => matches!(addr, 0x11 | 0x14 | 0x3C),
    }
}

#[test]
fn accel_is_i2c_until_a_chip_select_edge() {
    let mut c = Bmi088Accel::new();
    assert!(!c.is_spi_mode());
    assert_eq!(spi(&mut c, &[0x80, 0x00, 0x00]), [0x00; 3]); // not decoded
    assert!(c.is_spi_mode());
    assert_eq!(spi(&mut c, &[0x80, 0x00, 0x00]), [0x00, 0x00, 0x1E]);
    let mut c = Bmi088Accel::new();
    spi(&mut c, &[0x41, 0x03]); // lost, but switches to SPI
    assert_eq!(aread1(&mut c, 0x41), 0x01);
}

#[test]
fn accel_reads_begin_with_a_dummy_byte_gyro_reads_do_not() {
    let mut a = spi_accel();
    assert_eq!(aread(&mut a, 0x00, 4), [0x1E, 0x00, 0x00, 0x10]); // CHIP_ID, -, ERR, STATUS
    spi_write(&mut a, 0x40, &[0x8C, 0x02]);
    assert_eq!(aread(&mut a, 0x40, 2), [0x8C, 0x02]);
    let mut g = Bmi088Gyro::new();
    assert_eq!(spi(&mut g, &[0x80, 0x00, 0x00]), [0x00, 0x0F, 0x00]);
    assert_eq!(spi_read(&mut g, 0x0F, 3), [0x00, 0x80, 0x00]); // RANGE, BANDWIDTH, LPM1
}

#[test]
fn power_on_values_of_both_dies() {
    let a = Bmi088Accel::new();
    let g = Bmi088Gyro::new();
    for addr in 0..0x80u8 {
        let want = match addr {
            0x26 => 0x80, // FIFO_DATA of an empty FIFO: over-read
            _ => Die::Accel.reset_value(addr),
        };
        assert_eq!(a.peek(addr), want, "accel {addr:#04x}");
        let want = match addr {
            0x3C => 0x10, // GYRO_SELF_TEST.rate_ok in normal mode
            _ => Die::Gyro.reset_value(addr),
        };
        assert_eq!(g.peek(addr), want, "gyro {addr:#04x}");
    }
    // Typed from the DS register maps.
    let accel = [
        (0x03, 0x10),
        (0x40, 0xA8),
        (0x41, 0x01),
        (0x45, 0x80),
        (0x47, 0x02),
    ];
    let accel2 = [
        (0x48, 0x02),
        (0x49, 0x10),
        (0x7C, 0x03),
        (0x7D, 0x00),
        (0x00, 0x1E),
    ];
    for (addr, v) in accel.into_iter().chain(accel2) {
        assert_eq!(a.peek(addr), v, "accel {addr:#04x}");
    }
    for (addr, v) in [
        (0x00, 0x0F),
        (0x10, 0x80),
        (0x16, 0x0F),
        (0x1E, 0x08),
        (0x3E, 0x00),
    ] {
        assert_eq!(g.peek(addr), v, "gyro {addr:#04x}");
    }
}

#[test]
fn every_written_register_reads_back_through_its_mask() {
    for addr in 0..0x80u8 {
        if !Die::Accel.is_defined(addr) || is_special(Die::Accel, addr) {
            continue;
        }
        for value in [0x00, 0xFF, 0x5A, 0xA5] {
            let mut c = spi_accel();
            let before = aread1(&mut c, addr);
            spi_write(&mut c, addr, &[value]);
            let mask = Die::Accel.write_mask(addr);
            let want = if mask == 0 { before } else { value & mask };
            assert_eq!(
                aread1(&mut c, addr),
                want,
                "accel {addr:#04x} <- {value:#04x}"
            );
        }
    }
    for addr in 0..0x80u8 {
        if !Die::Gyro.is_defined(addr) || is_special(Die::Gyro, addr) {
            continue;
        }
        for value in [0x00, 0xFF, 0x5A, 0xA5] {
            let mut c = Bmi088Gyro::new();
            let before = gread1(&mut c, addr);
            spi_write(&mut c, addr, &[value]);
            let mask = Die::Gyro.write_mask(addr);
            let fixed = if addr == 0x10 { 0x80 } else { 0 }; // BANDWIDTH bit 7 reads 1
            let want = if mask == 0 {
                before
            } else {
                value & mask | fixed
            };
            assert_eq!(
                gread1(&mut c, addr),
                want,
                "gyro {addr:#04x} <- {value:#04x}"
            );
        }
    }
}

#[test]
fn reserved_registers_read_0_and_ignore_writes() {
    let mut a = spi_accel();
    let mut g = Bmi088Gyro::new();
    for addr in [0x01, 0x1E, 0x42, 0x60, 0x7B] {
        spi_write(&mut a, addr, &[0xFF]);
        assert_eq!(aread1(&mut a, addr), 0, "accel {addr:#04x}");
    }
    for addr in [0x01, 0x12, 0x13, 0x17, 0x3B] {
        spi_write(&mut g, addr, &[0xFF]);
        assert_eq!(gread1(&mut g, addr), 0, "gyro {addr:#04x}");
    }
}

#[test]
fn accel_soft_reset_restores_values_and_i2c_mode() {
    let mut c = running_accel();
    spi_write(&mut c, 0x41, &[0x03]);
    spi_write(&mut c, 0x49, &[0x50]);
    spi(&mut c, &[0x7E, 0xB6, 0x41]); // the byte after the command is not decoded
    assert!(
        !c.is_spi_mode(),
        "the reset's own chip-select edge does not count"
    );
    dummy_read(&mut c);
    assert_eq!(aread(&mut c, 0x7C, 3), [0x03, 0x00, 0x00]);
    assert_eq!(aread1(&mut c, 0x41), 0x01);
    assert_eq!(aread1(&mut c, 0x49), 0x10);
    spi_write(&mut c, 0x7E, &[0x12]); // other values change nothing
    assert!(c.is_spi_mode());
}

#[test]
fn gyro_soft_reset_and_power_modes() {
    let mut g = Bmi088Gyro::new();
    spi_write(&mut g, 0x0F, &[0x02]);
    spi_write(&mut g, 0x14, &[0x12]); // ignored
    assert_eq!(gread1(&mut g, 0x0F), 0x02);
    spi_write(&mut g, 0x14, &[0xB6]);
    assert_eq!(gread1(&mut g, 0x0F), 0x00);
    spi_write(&mut g, 0x0F, &[0x01]);
    spi_write(&mut g, 0x11, &[0x80]); // suspend: configuration kept
    assert_eq!((gread1(&mut g, 0x11), g.sample_period_ns()), (0x80, None));
    spi_write(&mut g, 0x11, &[0x20]); // suspend → deep suspend is not allowed
    assert_eq!(gread1(&mut g, 0x11), 0x80);
    spi_write(&mut g, 0x11, &[0x00]);
    assert_eq!(gread1(&mut g, 0x0F), 0x01);
    spi_write(&mut g, 0x11, &[0x20]); // deep suspend: configuration lost
    assert_eq!((gread1(&mut g, 0x0F), gread1(&mut g, 0x11)), (0x00, 0x20));
    spi_write(&mut g, 0x11, &[0x00]);
    assert_eq!(g.sample_period_ns(), Some(500_000));
    spi_write(&mut g, 0x3C, &[0x01]); // built-in self-test: ready, passed
    assert_eq!(gread1(&mut g, 0x3C), 0x12);
}

#[test]
fn accel_conf_errors_in_err_reg() {
    let mut c = running_accel();
    spi_write(&mut c, 0x40, &[0xB8]); // reserved acc_bwp
    assert_eq!(aread1(&mut c, 0x02), 0x04);
    assert_eq!(c.sample_period_ns(), Some(10 * MS)); // the ODR code is still valid
    spi_write(&mut c, 0x40, &[0xA3]); // reserved ODR: no samples
    assert_eq!((aread1(&mut c, 0x02), c.sample_period_ns()), (0x04, None));
    spi_write(&mut c, 0x40, &[0xAC]);
    assert_eq!(
        (aread1(&mut c, 0x02), c.sample_period_ns()),
        (0x00, Some(625_000))
    );
}

#[test]
fn i2c_targets_at_their_addresses() {
    let mut a = Bmi088Accel::new();
    let mut g = Bmi088Gyro::with_sdo(true);
    assert_eq!((a.i2c_address(), g.i2c_address()), (0x18, 0x69));
    assert_eq!(i2c_read(&mut a, 0x18, 0x00, 1), Some(vec![0x1E])); // no dummy byte on I2C
    assert_eq!(i2c_read(&mut a, 0x19, 0x00, 1), None);
    assert_eq!(i2c_write(&mut a, 0x18, &[0x41, 0x02]), [true; 3]);
    assert_eq!(i2c_read(&mut a, 0x18, 0x40, 2), Some(vec![0xA8, 0x02]));
    assert_eq!(i2c_read(&mut g, 0x69, 0x00, 1), Some(vec![0x0F]));
    assert_eq!(i2c_write(&mut g, 0x69, &[0x0F, 0x03, 0x05]), [true; 4]);
    assert_eq!(i2c_read(&mut g, 0x69, 0x0F, 2), Some(vec![0x03, 0x85]));
    dummy_read(&mut a); // SPI from now on: I2C no longer answers
    assert!(!a.start(0x18, false));
    a.stop();
}

#[test]
fn writes_are_logged_with_the_die_address() {
    let mut a = spi_accel();
    let mut g = Bmi088Gyro::new();
    spi_write(&mut a, 0x7D, &[0x04]);
    spi_write(&mut g, 0x0F, &[0x01]);
    let w = a.pop_write().expect("accel write");
    assert_eq!((w.device, w.register, w.value), (0x18, 0x7D, 0x04));
    let w = g.pop_write().expect("gyro write");
    assert_eq!((w.device, w.register, w.value), (0x68, 0x0F, 0x01));
    assert_eq!((a.pop_write(), g.pop_write()), (None, None));
}
