//! PX4's ICM42688P driver (`src/drivers/imu/invensense/icm42688p/ICM42688P.cpp`, read for its
//! register sequence, no code taken): soft reset, then WHO_AM_I, DEVICE_CONFIG == 0 and
//! RESET_DONE_INT; PWR_MGMT0 = 0x0F; every configured register of banks 0–2 set by
//! read-modify-write (REG_BANK_SEL written only when the bank changes) and checked; FIFO flush.
//! The FIFO runs at 8 kHz with 20-byte high-resolution packets, big-endian, the count in bytes,
//! and the FIFO threshold (8 packets) on INT1, latched, push-pull, active low, cleared by a
//! FIFO read. On each INT1 assertion: one burst from INT_STATUS 0x2D returning INT_STATUS,
//! FIFO_COUNTH, FIFO_COUNTL and the packets; each header must have ACCEL, GYRO and 20 set,
//! HEADER_MSG and the ODR-change bits clear and TIMESTAMP_FSYNC = 10 (0x78). Accel is decoded
//! as the 20-bit value / 4, gyro / 2. After a FIFO read more than 100 ms after the last check,
//! one register of each bank 0–2 is checked, in rotation.

use super::fc::{Decoded, Recorder, Rig, Run};
use super::*;

const PACKET: usize = 20;
/// PX4 checks one configured register of each bank after a FIFO read once more than 100 ms
/// have passed since the last check.
pub const CHECK_INTERVAL_NS: u64 = 100 * MS;
const SAMPLES: usize = 8;

/// (bank, register, set bits, clear bits), as PX4 configures them.
pub const CONFIG: [(u8, u8, u8, u8); 22] = [
    (0, 0x14, 0x06, 0x01), // INT_CONFIG: INT1 latched, push-pull, active low
    (0, 0x16, 0xC0, 0x00), // FIFO_CONFIG: stop on full
    (0, 0x4C, 0x33, 0x40), // INTF_CONFIG0: big-endian data and count, bytes, I2C off
    (0, 0x4D, 0x40, 0x80), // INTF_CONFIG1: AFSR off
    (0, 0x4E, 0x0F, 0x00), // PWR_MGMT0: gyro and accel low noise
    (0, 0x4F, 0x03, 0xEC), // GYRO_CONFIG0: ±2000 °/s, 8 kHz
    (0, 0x50, 0x03, 0xEC), // ACCEL_CONFIG0: ±16 g, 8 kHz
    (0, 0x51, 0x00, 0x0C), // GYRO_CONFIG1: first-order UI filter
    (0, 0x52, 0x00, 0xFF), // GYRO_ACCEL_CONFIG0: UI filters at ODR/2
    (0, 0x53, 0x00, 0x18), // ACCEL_CONFIG1: first-order UI filter
    (0, 0x54, 0x05, 0x08), // TMST_CONFIG: timestamp deltas, 1 µs
    (0, 0x5F, 0x7F, 0x00), // FIFO_CONFIG1: resume, WM_GT_TH, hires, tmst, temp, gyro, accel
    (0, 0x60, (SAMPLES * PACKET) as u8, 0x00), // FIFO_CONFIG2: watermark 160 bytes
    (0, 0x61, 0x00, 0x0F), // FIFO_CONFIG3
    (0, 0x63, 0x08, 0x04), // INT_CONFIG0: FIFO threshold cleared by a FIFO read
    (0, 0x64, 0x40, 0x10), // INT_CONFIG1: 8 µs, async reset off
    (0, 0x65, 0x04, 0x18), // INT_SOURCE0: FIFO threshold on INT1 only
    (1, 0x0B, 0x00, 0x03), // GYRO_CONFIG_STATIC2: AAF and notch on
    (1, 0x0C, 13, 0x32),   // GYRO_CONFIG_STATIC3: AAF 585 Hz
    (1, 0x0D, 170, 0x55),  // GYRO_CONFIG_STATIC4
    (2, 0x03, 13 << 1, 0x65), // ACCEL_CONFIG_STATIC2: AAF 585 Hz, enabled
    (2, 0x04, 170, 0x55),  // ACCEL_CONFIG_STATIC3
];

/// PX4's driver state: the recorder and the bank it believes selected.
pub struct Px4<'a, R: Rig> {
    pub r: Recorder<'a, R>,
    pub bank: u8,
}

impl<R: Rig> Px4<'_, R> {
    pub fn select(&mut self, bank: u8) {
        if bank != self.bank {
            self.r.write(0x76, bank);
            self.bank = bank;
        }
    }

    fn read(&mut self, bank: u8, reg: u8) -> u8 {
        self.select(bank);
        self.r.read(reg)
    }

    fn set_and_clear(&mut self, (bank, reg, set, clear): (u8, u8, u8, u8)) {
        let value = self.read(bank, reg);
        let new = (value & !clear) | set;
        if new != value {
            self.r.write(reg, new);
        }
    }

    fn check(&mut self, (bank, reg, set, clear): (u8, u8, u8, u8)) -> bool {
        let value = self.read(bank, reg);
        value & set == set && value & clear == 0
    }
}

/// Runs PX4's reset, configuration and `n` samples at 8 kHz.
pub fn px4_sequence(rig: &mut impl Rig, n: usize) -> Run {
    let mut p = px4_init(rig);
    let t0 = 40 * MS;
    let (mut last_check, mut checks) = (t0, 0usize);
    for k in 0..n {
        let t = t0 + k as u64 * 125 * US;
        p.r.latch(k as i16, t, Some((2, 1)));
        if p.r.rig.int1(t) {
            continue; // active low: not asserted
        }
        p.select(0);
        let bytes = p.r.burst(0x2D, 3 + SAMPLES * PACKET);
        transfer(&mut p.r, &bytes);
        if t - last_check > CHECK_INTERVAL_NS {
            let (b0, b1, b2) = (checks % 17, checks % 3, checks % 2);
            for cfg in [CONFIG[b0], CONFIG[17 + b1], CONFIG[20 + b2]] {
                if !p.check(cfg) {
                    p.r.run.register_mismatches += 1;
                }
            }
            (last_check, checks) = (t, checks + 1);
        }
    }
    p.r.run
}

/// PX4's reset, configuration, check and FIFO flush, up to its sampling loop.
pub fn px4_init<R: Rig>(rig: &mut R) -> Px4<'_, R> {
    let mut p = Px4 {
        r: Recorder::new(rig),
        bank: 0,
    };
    p.r.write(0x11, 0x01); // DEVICE_CONFIG: soft reset
    assert_eq!(p.read(0, 0x75), 0x47);
    assert_eq!(p.read(0, 0x11), 0x00);
    assert_ne!(p.read(0, 0x2D) & 0x10, 0, "RESET_DONE_INT");
    p.r.write(0x4E, 0x0F);
    for cfg in CONFIG {
        p.set_and_clear(cfg);
    }
    for cfg in CONFIG {
        if !p.check(cfg) {
            p.r.run.register_mismatches += 1;
        }
    }
    p.select(0);
    let flush = p.r.read(0x4B) | 0x02;
    p.r.write(0x4B, flush);
    p.r.rig.loop_starts();
    p
}

/// PX4's `FIFORead` of one burst from INT_STATUS: an overflow (FIFO_FULL_INT, or a count of
/// the whole FIFO) or a bad header counts a FIFO reset and drops the burst.
pub fn transfer(r: &mut Recorder<impl Rig>, bytes: &[u8]) {
    let (status, count) = (bytes[0], u16::from_be_bytes([bytes[1], bytes[2]]));
    if status & 0x02 != 0 || usize::from(count) >= 2048 {
        r.run.fifo_resets += 1;
        return;
    }
    let packets = (usize::from(count) / PACKET).min(SAMPLES);
    for p in bytes[3..].chunks_exact(PACKET).take(packets) {
        let h = p[0];
        let valid = h & 0x80 == 0 && h & 0x70 == 0x70 && h & 0x0C == 0x08 && h & 0x03 == 0;
        if !valid {
            r.run.fifo_resets += 1;
            return;
        }
        let raw20 = |hi: usize, ext: u8| {
            let x = u32::from(p[hi]) << 12 | u32::from(p[hi + 1]) << 4 | u32::from(ext & 0x0F);
            ((x << 12) as i32) >> 12
        };
        r.run.samples.push(Decoded {
            accel: core::array::from_fn(|i| raw20(1 + 2 * i, p[17 + i] >> 4) / 4),
            gyro: core::array::from_fn(|i| raw20(7 + 2 * i, p[17 + i]) / 2),
        });
    }
}
