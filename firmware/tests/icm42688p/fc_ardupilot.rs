//! ArduPilot's Invensensev3 driver for the ICM-42688 (`libraries/AP_InertialSensor/
//! AP_InertialSensor_Invensensev3.cpp`, read for its register sequence, no code taken):
//! WHO_AM_I; FIFO reset (FIFO_CONFIG = 0x80 stop-on-full, FIFO_CONFIG1 = 0x07 accel + gyro +
//! temperature, INTF_CONFIG0 = 0xC0 little-endian with the count in records,
//! SIGNAL_PATH_RESET = 0x02 flush); sensors on, ODR, AAFs in banks 1 and 2 (each write wrapped
//! in REG_BANK_SEL writes); AFSR off. Then it polls at the backend rate: FIFO_COUNTH/L (2
//! bytes, little-endian records), FIFO_DATA in reads of at most 2 × 16-byte packets, each
//! header checked with `(header & 0xFC) == 0x68` (a bad one resets the FIFO), and after every
//! poll one read-back of the next bank-0 register it wrote (its checked registers are read
//! without a bank switch), at the low SPI clock as the driver switches to it for the check.

use super::fc::{Decoded, Recorder, Rig, Run};
use super::*;

const PACKET: usize = 16;

pub fn fifo_reset(r: &mut Recorder<impl Rig>) {
    r.write(0x16, 0x80);
    r.write(0x5F, 0x07);
    r.write(0x4C, 0xC0);
    r.write(0x4B, 0x02);
}

fn write_bank(r: &mut Recorder<impl Rig>, bank: u8, reg: u8, value: u8) {
    r.write(0x76, bank);
    r.write(reg, value);
    r.write(0x76, 0);
}

/// Runs ArduPilot's init and polls while `n` samples arrive at 1 kHz (`fast` = false) or
/// 8 kHz (`fast` = true). Every 5th poll is skipped, so reads of 2 records also happen.
pub fn ardupilot_sequence(rig: &mut impl Rig, fast: bool, n: usize) -> Run {
    let mut r = Recorder::new(rig);
    let checked = ardupilot_init(&mut r, fast);
    let period_ns = if fast { 125 * US } else { MS };
    let t0 = 50 * MS;
    r.rig.loop_starts();
    for k in 0..n {
        let t = t0 + k as u64 * period_ns;
        r.latch(k as i16, t, None);
        if k % 5 == 3 && k + 1 < n {
            continue; // a late callback: the next poll finds 2 records
        }
        poll(&mut r);
        let (reg, value) = checked[k % checked.len()];
        r.rig.set_fast(false);
        if r.read(reg) != value {
            r.run.register_mismatches += 1;
        }
        r.rig.set_fast(true);
    }
    r.run
}

/// ArduPilot's `hardware_init` and `start` at 1 kHz (`fast` = false) or 8 kHz: returns its
/// checked registers (bank 0), in the order it re-reads them.
pub fn ardupilot_init(r: &mut Recorder<impl Rig>, fast: bool) -> [(u8, u8); 7] {
    assert_eq!(r.read(0x75), 0x47, "WHO_AM_I");
    fifo_reset(r);
    r.write(0x4E, 0x0F);
    let (odr, delt, deltsqr, shift) = if fast {
        (0x03, 21, 440u16, 6)
    } else {
        (0x06, 8, 64, 9)
    };
    r.write(0x4F, odr);
    r.write(0x50, odr);
    write_bank(r, 1, 0x0C, delt);
    write_bank(r, 1, 0x0D, deltsqr as u8);
    write_bank(r, 1, 0x0E, shift << 4 | (deltsqr >> 8) as u8);
    write_bank(r, 2, 0x03, 5 << 1);
    write_bank(r, 2, 0x04, 25);
    write_bank(r, 2, 0x05, 10 << 4);
    let intf_config1 = r.read(0x4D);
    r.write(0x4D, (intf_config1 & 0x3F) | 0x40);
    [
        (0x16, 0x80),
        (0x5F, 0x07),
        (0x4C, 0xC0),
        (0x4E, 0x0F),
        (0x4F, odr),
        (0x50, odr),
        (0x4D, (intf_config1 & 0x3F) | 0x40),
    ]
}

pub fn poll(r: &mut Recorder<impl Rig>) {
    let count = r.burst(0x2E, 2);
    let mut records = usize::from(u16::from_le_bytes([count[0], count[1]]));
    while records > 0 {
        let take = records.min(2);
        let bytes = r.burst(0x30, take * PACKET);
        for p in bytes.chunks_exact(PACKET) {
            if p[0] & 0xFC != 0x68 {
                fifo_reset(r);
                r.run.fifo_resets += 1;
                return;
            }
            let le = |i: usize| i32::from(i16::from_le_bytes([p[i], p[i + 1]]));
            r.run.samples.push(Decoded {
                accel: [le(1), le(3), le(5)],
                gyro: [le(7), le(9), le(11)],
            });
        }
        records -= take;
    }
}
