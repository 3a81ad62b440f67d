//! Register sequences of flight-controller drivers for the InvenSense 6xxx family on SPI,
//! written from the drivers' behaviour (no code taken). Setup runs at the setup clock, the
//! sampling loop at the sample clock; register checks use the setup clock, as the drivers do.

use super::{burst, read, write, xfer, Rig, MS, US};

/// Registers (RM-MPU-9250A-00).
const SMPLRT_DIV: u8 = 0x19;
const CONFIG: u8 = 0x1A;
const GYRO_CONFIG: u8 = 0x1B;
const ACCEL_CONFIG: u8 = 0x1C;
const ACCEL_CONFIG2: u8 = 0x1D;
const FIFO_EN: u8 = 0x23;
const INT_PIN_CFG: u8 = 0x37;
const INT_ENABLE: u8 = 0x38;
const ACCEL_XOUT_H: u8 = 0x3B;
const EXT_SENS_DATA_00: u8 = 0x49;
const SIGNAL_PATH_RESET: u8 = 0x68;
const USER_CTRL: u8 = 0x6A;
const PWR_MGMT_1: u8 = 0x6B;
const PWR_MGMT_2: u8 = 0x6C;
const FIFO_COUNTH: u8 = 0x72;
const FIFO_R_W: u8 = 0x74;
const WHO_AM_I: u8 = 0x75;

/// Betaflight's MPU-6500/9250 SPI driver: reset, signal path reset, PLL clock, ±2000 °/s,
/// ±16 g, DLPF 0 (8 kHz), INT_ANYRD_2CLEAR, data-ready interrupt, I2C interface off, all at
/// the 1 MHz setup clock; then on every data-ready (8 kHz) one 14-byte burst from
/// ACCEL_XOUT_H (accel, temperature, gyro) at the fast clock.
pub fn betaflight(rig: &mut dyn Rig, samples: usize) -> Vec<u8> {
    rig.set_fast(false);
    write(rig, PWR_MGMT_1, 0x80);
    let who = read(rig, WHO_AM_I);
    write(rig, PWR_MGMT_1, 0x80);
    write(rig, SIGNAL_PATH_RESET, 0x07);
    write(rig, PWR_MGMT_1, 0x00);
    write(rig, PWR_MGMT_1, 0x01);
    write(rig, GYRO_CONFIG, 3 << 3);
    write(rig, ACCEL_CONFIG, 3 << 3);
    write(rig, CONFIG, 0);
    write(rig, SMPLRT_DIV, 0);
    write(rig, INT_PIN_CFG, 0x10);
    write(rig, INT_ENABLE, 0x01);
    write(rig, USER_CTRL, 0x10);
    let mut decoded = vec![who];
    rig.set_fast(true);
    rig.loop_starts();
    for k in 0..samples {
        rig.latch(k as u32, 10 * MS + k as u64 * 125 * US);
        decoded.extend(burst(rig, ACCEL_XOUT_H, 14));
    }
    decoded
}

/// ArduPilot's Invensense driver (MPU-9250 on SPI, compass elsewhere): WHO_AM_I, reset,
/// I2C interface off, Z-gyro clock (read back), FIFO reset and FIFO_EN accel + temperature +
/// gyro (14-byte records), DLPF 188 Hz (1 kHz), ±2000 °/s, ±16 g, latched data-ready cleared by
/// any read. Then it polls at 1 kHz: FIFO_COUNTH (2 bytes), and FIFO_R_W for the whole
/// records counted (none when the FIFO is empty); every 20th poll reads back the next of its
/// checked registers at the setup clock. The polls drift against the samples: a late poll
/// finds 2 records, an early one none.
pub fn ardupilot(rig: &mut dyn Rig, samples: usize) -> Vec<u8> {
    ardupilot_with_compass(rig, samples, false)
}

/// [`ardupilot`] with the AK8963 read through the auxiliary bus: every 10 ms (10 polls) its
/// compass driver, on the same bus thread, reads EXT_SENS_DATA_00 (7 bytes) at the fast clock
/// between two polls. That read follows no fixed transaction.
pub fn ardupilot_with_ak8963(rig: &mut dyn Rig, samples: usize) -> Vec<u8> {
    ardupilot_with_compass(rig, samples, true)
}

fn ardupilot_with_compass(rig: &mut dyn Rig, samples: usize, compass: bool) -> Vec<u8> {
    rig.set_fast(false);
    let mut decoded = vec![read(rig, WHO_AM_I)];
    write(rig, PWR_MGMT_1, 0x80);
    write(rig, USER_CTRL, 0x10);
    write(rig, PWR_MGMT_1, 0x03);
    decoded.push(read(rig, PWR_MGMT_1));
    let checked = [
        (PWR_MGMT_2, 0x00),
        (FIFO_EN, 0xF8),
        (CONFIG, 0x01),
        (SMPLRT_DIV, 0x00),
        (GYRO_CONFIG, 0x18),
        (ACCEL_CONFIG, 0x18),
        (INT_ENABLE, 0x01),
    ];
    write(rig, FIFO_EN, 0x00);
    write(rig, USER_CTRL, 0x10);
    write(rig, USER_CTRL, 0x10 | 0x04);
    write(rig, USER_CTRL, 0x10 | 0x40);
    for (reg, value) in checked {
        write(rig, reg, value);
    }
    write(rig, INT_PIN_CFG, 0x30);
    rig.set_fast(true);
    rig.loop_starts();
    let mut polls = 0usize;
    let mut check = 0usize;
    let mut poll = |rig: &mut dyn Rig, decoded: &mut Vec<u8>| {
        let count = burst(rig, FIFO_COUNTH, 2);
        let records = usize::from(u16::from_be_bytes([count[0], count[1]])) / 14;
        if records > 0 {
            decoded.extend(burst(rig, FIFO_R_W, records.min(8) * 14));
        }
        polls += 1;
        if polls.is_multiple_of(20) {
            let (reg, value) = checked[check % checked.len()];
            check += 1;
            rig.set_fast(false);
            decoded.push(u8::from(read(rig, reg) == value));
            rig.set_fast(true);
        }
    };
    for k in 0..samples {
        rig.latch(k as u32, 10 * MS + k as u64 * MS);
        if k % 7 == 3 {
            continue; // a late poll: the next one finds 2 records
        }
        poll(rig, &mut decoded);
        if compass && k % 10 == 5 {
            decoded.extend(burst(rig, EXT_SENS_DATA_00, 7));
        }
        if k % 50 == 17 {
            poll(rig, &mut decoded); // an early poll: the FIFO is empty
        }
    }
    decoded
}

/// PX4's MPU-9250 driver: reset, then its register table at the 1 MHz register clock
/// (PLL clock, accel ±16 g without DLPF, gyro ±2000 °/s at 8 kHz, FIFO mode, FIFO_EN gyro +
/// accel: 12-byte records, I2C interface off, data-ready interrupt), each read back once. At
/// 1 kHz (every 8 samples) it reads FIFO_COUNTH/L (a 3-byte transfer) then, at 20 MHz, one
/// transfer from FIFO_COUNTH carrying the count again and the records; every 100 ms it reads
/// back one register of its table at the register clock.
pub fn px4(rig: &mut dyn Rig, samples: usize) -> Vec<u8> {
    rig.set_fast(false);
    write(rig, PWR_MGMT_1, 0x80);
    let mut decoded = vec![read(rig, WHO_AM_I)];
    let table = [
        (PWR_MGMT_1, 0x01),
        (ACCEL_CONFIG, 0x18),
        (ACCEL_CONFIG2, 0x08),
        (GYRO_CONFIG, 0x18 | 0x01),
        (CONFIG, 0x40 | 0x07),
        (USER_CTRL, 0x40 | 0x10),
        (FIFO_EN, 0x78),
        (INT_PIN_CFG, 0x10),
        (INT_ENABLE, 0x01),
    ];
    for (reg, value) in table {
        write(rig, reg, value);
    }
    for (reg, _) in table {
        decoded.push(read(rig, reg));
    }
    write(rig, USER_CTRL, 0x40 | 0x10 | 0x04); // FIFO reset
    rig.loop_starts();
    let mut checked = 0usize;
    for k in 0..samples {
        rig.latch(k as u32, 10 * MS + k as u64 * 125 * US);
        if k % 8 != 7 {
            continue;
        }
        rig.set_fast(true);
        let count = burst(rig, FIFO_COUNTH, 2);
        let bytes = usize::from(u16::from_be_bytes([count[0], count[1]]));
        let records = (bytes / 12).min(10);
        let mut mosi = vec![0x80 | FIFO_COUNTH];
        mosi.resize(3 + records * 12, 0);
        let transfer = xfer(rig, &mosi);
        decoded.extend(&transfer[1..]);
        if k % 800 == 799 {
            rig.set_fast(false);
            let (reg, value) = table[checked % table.len()];
            checked += 1;
            decoded.push(u8::from(read(rig, reg) == value));
        }
    }
    decoded
}
