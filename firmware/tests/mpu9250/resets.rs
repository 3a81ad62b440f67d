//! Reset values, PWR_MGMT_1 (H_RESET, SLEEP, CLKSEL), SIGNAL_PATH_RESET and the USER_CTRL resets
//! (RM sections 3, 4.31–4.34).

use super::*;

#[test]
fn reset_values_after_power_on() {
    let c = Mpu6xxx::with_config(Config {
        self_test: [1, 2, 3, 4, 5, 6],
        accel_offset: [0x1234, 0x5678, 0x9ABC],
        ..Config::default()
    });
    let regs = registers(&c);
    for (addr, value) in regs.iter().enumerate() {
        let expected = match addr {
            0x00..=0x02 => addr as u8 + 1,
            0x0D..=0x0F => addr as u8 - 0x0D + 4,
            0x6B => 0x01,
            0x75 => 0x71,
            0x77 => 0x12,
            0x78 => 0x34,
            0x7A => 0x56,
            0x7B => 0x78,
            0x7D => 0x9A,
            0x7E => 0xBC,
            _ => 0x00,
        };
        assert_eq!(*value, expected, "register {addr:#04x}");
    }
}

#[test]
fn h_reset_restores_every_register_and_self_clears() {
    let mut c = chip();
    let fresh = registers(&c);
    for addr in 0..0x80u8 {
        if addr != 0x6B {
            spi_write(&mut c, addr, &[0xFF]);
        }
    }
    c.latch_at(&at_rest(), MS);
    assert_ne!(registers(&c), fresh);
    assert_eq!(spi(&mut c, &[0x6B, 0x80]), [0x00, 0x00]);
    assert_eq!(spi_read(&mut c, 0x6B, 1), [0x01], "H_RESET reads back 0");
    assert_eq!(registers(&c), fresh);
}

#[test]
fn h_reset_drops_a_sample_waiting_for_the_bus() {
    let mut c = chip();
    c.select();
    c.exchange(0x80 | 0x3B);
    c.latch_at(&at_rest(), MS); // waits for deselect
    c.deselect();
    c.select();
    c.exchange(0x6B);
    c.latch_at(&at_rest(), 2 * MS);
    c.exchange(0x80); // H_RESET inside the same transaction as a pending sample
    c.deselect();
    assert_eq!(spi_read(&mut c, 0x3B, 6), [0; 6]);
}

#[test]
fn sleep_stops_the_sample_clock() {
    let mut c = chip();
    spi_write(&mut c, 0x6B, &[0x40]);
    assert_eq!(spi_read(&mut c, 0x6B, 1), [0x40]);
    c.latch_at(&at_rest(), MS);
    assert_eq!(
        spi_read(&mut c, 0x3A, 1),
        [0x00],
        "no data ready while asleep"
    );
    assert_eq!(spi_read(&mut c, 0x3F, 2), [0x00, 0x00]);
    spi_write(&mut c, 0x6B, &[0x01]);
    c.latch_at(&at_rest(), 2 * MS);
    assert_eq!(spi_read(&mut c, 0x3A, 1), [0x01]);
    assert_eq!(spi_read(&mut c, 0x3F, 2), [0x40, 0x00]);
}

#[test]
fn clksel_reads_back_and_seven_stops_the_clock() {
    let mut c = chip();
    for clksel in 0..8u8 {
        spi_write(&mut c, 0x6B, &[clksel]);
        assert_eq!(spi_read(&mut c, 0x6B, 1), [clksel]);
        assert_eq!(c.is_running(), clksel != 7);
    }
    // ArduPilot writes CLKSEL = 3 (PLL with Z gyro) and requires exactly that read back.
    spi_write(&mut c, 0x6B, &[0x03]);
    assert_eq!(spi_read(&mut c, 0x6B, 1), [0x03]);
}

#[test]
fn signal_path_reset_bits_self_clear_and_keep_the_data() {
    let mut c = chip();
    c.latch_at(&at_rest(), MS);
    spi_write(&mut c, 0x68, &[0xFF]);
    assert_eq!(
        spi_read(&mut c, 0x68, 1),
        [0xF8],
        "bits 2:0 self-clear, 7:3 reserved"
    );
    assert_eq!(
        spi_read(&mut c, 0x3F, 2),
        [0x40, 0x00],
        "sensor registers not cleared"
    );
}

#[test]
fn user_ctrl_resets_self_clear_and_act() {
    let mut c = chip();
    spi_write(&mut c, 0x74, &[1, 2, 3]);
    c.latch_at(&at_rest(), MS);
    spi_write(&mut c, 0x6A, &[0x40 | 0x20 | 0x07]); // FIFO_EN, I2C_MST_EN, all three resets
    assert_eq!(spi_read(&mut c, 0x6A, 1), [0x60]);
    assert_eq!(
        spi_read(&mut c, 0x72, 2),
        [0x00, 0x00],
        "FIFO_RST emptied the FIFO"
    );
    assert_eq!(
        spi_read(&mut c, 0x3B, 14),
        [0; 14],
        "SIG_COND_RST cleared the sensor registers"
    );
}

#[test]
fn power_cycle_resets_both_dies() {
    let mut c = chip();
    i2c_write(&mut c, 0x68, &[0x37, 0x02]);
    i2c_write(&mut c, 0x0C, &[0x0A, 0x16]);
    c.power_cycle();
    assert_eq!(registers(&c), registers(&chip()));
    assert_eq!(c.ak8963().map(|ak| ak.peek(0x0A)), Some(0x00));
}
