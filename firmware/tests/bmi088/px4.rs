//! PX4's BMI088 driver (`src/drivers/imu/bosch/bmi088/`, read in its sources; no code taken),
//! its register traffic replayed against both dies on a bench that latches numbered samples at
//! each die's own rate:
//!
//! - accelerometer (`BMI088_Accelerometer.cpp`): dummy read and ACC_CHIP_ID (0x1E), soft reset,
//!   1 ms, ACC_CHIP_ID again (PX4 reads it twice with `||`: the first read after the reset is the
//!   dummy read), ACC_PWR_CONF = 0, 10 ms, then read-modify-write of ten registers (ACC_PWR_CONF
//!   clear 0x03, ACC_PWR_CTRL 0x04, ACC_CONF 0xAC with bits 1:0 cleared, ACC_RANGE ±24 g,
//!   FIFO_WTM_0/1, FIFO_CONFIG_0 0x03, FIFO_CONFIG_1 0x50, INT1_IO_CONF output, map watermark to
//!   INT1) and a check of every one, FIFO reset (0xB0); then every 1.25 ms one burst from
//!   FIFO_LENGTH_0 (count) and one burst from FIFO_LENGTH_0 over into FIFO_DATA with the frames
//!   (header & 0xFC = 0x84), a register check in rotation every 100 ms and the temperature
//!   (TEMP_MSB, TEMP_LSB) every second;
//! - gyroscope (`BMI088_Gyroscope.cpp`): GYRO_CHIP_ID (0x0F), soft reset, 30 ms, GYRO_CHIP_ID,
//!   read-modify-write and check of GYRO_RANGE ±2000 °/s, GYRO_BANDWIDTH bits 2:0 cleared
//!   (2 kHz, 532 Hz; bit 7 reads 1), GYRO_INT_CTRL fifo_en, FIFO_WM_ENABLE 0x88, FIFO_CONFIG_0
//!   (watermark), FIFO_CONFIG_1 FIFO mode, INT3 push-pull active low with the FIFO interrupt;
//!   FIFO reset (FIFO_CONFIG_0 = 0, FIFO_CONFIG_1 = 0, both restored); then every 1 ms
//!   FIFO_STATUS (overrun resets the FIFO), `count` frames in one burst from FIFO_DATA, and a
//!   register check in rotation every 10 ms.
//!
//! PX4's own register header gives GYRO_RANGE ±250 °/s as 0x04 and ±125 °/s as 0x05; DS 5.5.4
//! has 0x03 and 0x04. PX4 only ever sets ±2000 °/s (0x00), so that never matters.

use super::*;
use margemu_protocol::regmap::bmi088::convert::temp_from_bytes;

/// Both dies on one board, with the samples each latched, in order.
struct Bench {
    accel: Bmi088Accel,
    gyro: Bmi088Gyro,
    now: u64,
    last: [u64; 2],
    k: u32,
    accel_log: Vec<PhysicalSample>,
    gyro_log: Vec<PhysicalSample>,
}

impl Bench {
    fn new() -> Self {
        Self {
            accel: Bmi088Accel::new(),
            gyro: Bmi088Gyro::new(),
            now: 0,
            last: [0; 2],
            k: 0,
            accel_log: Vec::new(),
            gyro_log: Vec::new(),
        }
    }

    /// Lets `ns` pass, latching each die at its own rate.
    fn wait_ns(&mut self, ns: u64) {
        let end = self.now + ns;
        loop {
            let periods = [self.accel.sample_period_ns(), self.gyro.sample_period_ns()];
            let next = |i: usize| periods[i].map(|p| self.last[i] + p).filter(|&t| t <= end);
            let die = match (next(0), next(1)) {
                (Some(a), Some(g)) => usize::from(g < a),
                (Some(_), None) => 0,
                (None, Some(_)) => 1,
                (None, None) => break,
            };
            let t = next(die).unwrap();
            let s = numbered(self.k);
            self.k += 1;
            if die == 0 {
                self.accel.latch_at(&s, t);
                self.accel_log.push(s);
            } else {
                self.gyro.latch_at(&s, t);
                self.gyro_log.push(s);
            }
            self.last[die] = t;
        }
        self.now = end;
        self.accel.advance(end);
        self.gyro.advance(end);
        // A die that is off starts sampling one period after it is switched on.
        let periods = [self.accel.sample_period_ns(), self.gyro.sample_period_ns()];
        for (last, period) in self.last.iter_mut().zip(periods) {
            if period.is_none() {
                *last = end;
            }
        }
    }
}

/// PX4's accel RegisterRead: address, dummy, value.
fn accel_read(c: &mut Bmi088Accel, addr: u8) -> u8 {
    spi(c, &[0x80 | addr, 0, 0])[2]
}

/// `(register, set bits, clear bits)`, PX4's `register_cfg`, with the read-modify-write.
fn set_and_clear<C: SpiTarget>(chip: &mut C, read: fn(&mut C, u8) -> u8, cfg: (u8, u8, u8)) {
    let (reg, set, clear) = cfg;
    let orig = read(chip, reg);
    let val = (orig & !clear) | set;
    if val != orig {
        spi(chip, &[reg, val]);
    }
}

fn check<C>(chip: &mut C, read: fn(&mut C, u8) -> u8, (reg, set, clear): (u8, u8, u8)) -> bool {
    let v = read(chip, reg);
    v & set == set && v & clear == 0
}

/// Accel register configuration for 2 samples per transfer (watermark 14 bytes).
const ACCEL_CFG: [(u8, u8, u8); 10] = [
    (0x7C, 0x00, 0x03),
    (0x7D, 0x04, 0x00),
    (0x40, 0xAC, 0x03),
    (0x41, 0x03, 0x00),
    (0x46, 14, !14),
    (0x47, 0, 0xFF),
    (0x48, 0x03, 0x00),
    (0x49, 0x50, 0x00),
    (0x53, 0x08, 0x00),
    (0x58, 0x02, 0x00),
];

/// Gyro register configuration for 2 samples per transfer (watermark 2 frames), INT3 variant.
const GYRO_CFG: [(u8, u8, u8); 8] = [
    (0x0F, 0x00, 0x00),
    (0x10, 0x00, 0x07),
    (0x15, 0x40, 0x00),
    (0x1E, 0x88, 0x00),
    (0x3D, 2, !2),
    (0x3E, 0x40, 0x00),
    (0x16, 0x00, 0x03),
    (0x18, 0x04, 0x00),
];

fn px4_accel_init(b: &mut Bench) {
    spi(&mut b.accel, &[0x80, 0, 0]); // probe: dummy read
    assert_eq!(accel_read(&mut b.accel, 0x00), 0x1E, "probe");
    spi(&mut b.accel, &[0x7E, 0xB6]);
    b.wait_ns(MS);
    let id = accel_read(&mut b.accel, 0x00);
    assert!(
        id == 0x1E || accel_read(&mut b.accel, 0x00) == 0x1E,
        "reset done"
    );
    spi(&mut b.accel, &[0x7C, 0x00]);
    b.wait_ns(10 * MS);
    for cfg in ACCEL_CFG {
        set_and_clear(&mut b.accel, accel_read, cfg);
    }
    for cfg in ACCEL_CFG {
        assert!(check(&mut b.accel, accel_read, cfg), "accel {:#04x}", cfg.0);
    }
    assert_eq!(accel_read(&mut b.accel, 0x41) & 0x03, 0x03); // ConfigureAccel
    spi(&mut b.accel, &[0x7E, 0xB0]); // FIFOReset
}

fn gyro_init(b: &mut Bench) {
    assert_eq!(gread1(&mut b.gyro, 0x00), 0x0F, "probe");
    spi(&mut b.gyro, &[0x14, 0xB6]);
    b.wait_ns(30 * MS);
    assert_eq!(gread1(&mut b.gyro, 0x00), 0x0F, "reset done");
    b.wait_ns(MS);
    for cfg in GYRO_CFG {
        set_and_clear(&mut b.gyro, gread1, cfg);
    }
    for cfg in GYRO_CFG {
        assert!(check(&mut b.gyro, gread1, cfg), "gyro {:#04x}", cfg.0);
    }
    // FIFOReset: both configuration registers to 0, then restored.
    spi(&mut b.gyro, &[0x3D, 0x00]);
    spi(&mut b.gyro, &[0x3E, 0x00]);
    for cfg in [GYRO_CFG[4], GYRO_CFG[5]] {
        set_and_clear(&mut b.gyro, gread1, cfg);
    }
}

/// One accel FIFO_READ: the count, then one burst from FIFO_LENGTH_0 into FIFO_DATA; the
/// accel X/Y/Z of every 0x84 frame.
fn px4_accel_fifo_read(c: &mut Bmi088Accel) -> Vec<[i16; 3]> {
    let len = spi(c, &[0xA4, 0, 0, 0]);
    let count = usize::from(u16::from_le_bytes([len[2], len[3] & 0x3F]));
    let samples = count / 7;
    if samples == 0 {
        return Vec::new();
    }
    let mut mosi = vec![0u8; samples * 7 + 4];
    mosi[0] = 0xA4;
    let miso = spi(c, &mosi);
    let fifo_count = usize::from(u16::from_le_bytes([miso[2], miso[3] & 0x3F]));
    let data = &miso[4..];
    let mut out = Vec::new();
    let mut i = 0;
    while i < fifo_count.min(data.len()) {
        match data[i] & 0xFC {
            0x84 if i + 7 <= data.len() => {
                let w = words(&data[i + 1..i + 7]);
                out.push([w[0], w[1], w[2]]);
                i += 7;
            }
            0x40 | 0x48 | 0x50 => i += 2,
            0x44 => i += 4,
            _ => i += 1,
        }
    }
    out
}

/// One gyro FIFO_READ: FIFO_STATUS, then the frames; `None` when PX4 resets the FIFO.
fn px4_gyro_fifo_read(g: &mut Bmi088Gyro) -> Option<Vec<[i16; 3]>> {
    let status = gread1(g, 0x0E);
    if status & 0x80 != 0 {
        return None;
    }
    let n = usize::from(status & 0x7F);
    let bytes = spi_read(g, 0x3F, n * 6);
    Some(
        bytes
            .chunks(6)
            .map(|f| {
                let w = words(f);
                [w[0], w[1], w[2]]
            })
            .collect(),
    )
}

fn assert_accel(got: &[[i16; 3]], want: &[PhysicalSample]) {
    assert_eq!(got.len(), want.len(), "accel sample count");
    for (i, (g, s)) in got.iter().zip(want).enumerate() {
        for (axis, (&raw, &a)) in g.iter().zip(&s.acc).enumerate() {
            let what = format!("accel sample {i} axis {axis}");
            let in_g = f64::from(a) / f64::from(G);
            assert_within_1_lsb(raw, in_g, acc_lsb_per_g(3), &what);
        }
    }
}

fn assert_gyro(got: &[[i16; 3]], want: &[PhysicalSample]) {
    assert_eq!(got.len(), want.len(), "gyro sample count");
    for (i, (g, s)) in got.iter().zip(want).enumerate() {
        for (axis, (&raw, &w)) in g.iter().zip(&s.gyr).enumerate() {
            let what = format!("gyro sample {i} axis {axis}");
            let dps = f64::from(w).to_degrees();
            assert_within_1_lsb(raw, dps, gyr_lsb_per_dps(0), &what);
        }
    }
}

#[test]
fn px4_accel_sequence_at_1600_hz() {
    let mut b = Bench::new();
    px4_accel_init(&mut b);
    assert_eq!(b.accel.sample_period_ns(), Some(625_000));
    let start = b.accel_log.len();
    let mut got = Vec::new();
    let mut temperature = None;
    for poll in 1..=1600 {
        b.wait_ns(1_250_000);
        got.extend(px4_accel_fifo_read(&mut b.accel));
        if poll % 80 == 0 {
            let cfg = ACCEL_CFG[poll / 80 % ACCEL_CFG.len()];
            assert!(
                check(&mut b.accel, accel_read, cfg),
                "periodic check {:#04x}",
                cfg.0
            );
        }
        if poll % 800 == 0 {
            let t = spi(&mut b.accel, &[0xA2, 0, 0, 0]);
            temperature = temp_from_bytes([t[2], t[3]]);
        }
    }
    assert_eq!(got.len(), 3200, "2 s at 1.6 kHz");
    assert_accel(&got, &b.accel_log[start..]);
    assert_eq!(temperature, Some(30.0));
}

#[test]
fn px4_gyro_sequence_at_2000_hz() {
    let mut b = Bench::new();
    gyro_init(&mut b);
    assert_eq!(b.gyro.sample_period_ns(), Some(500_000));
    let start = b.gyro_log.len();
    assert_eq!(gread1(&mut b.gyro, 0x0E), 0, "empty after the FIFO reset");
    let mut got = Vec::new();
    for poll in 1..=2000 {
        b.wait_ns(MS);
        got.extend(px4_gyro_fifo_read(&mut b.gyro).expect("no overrun"));
        if poll % 10 == 0 {
            let cfg = GYRO_CFG[poll / 10 % GYRO_CFG.len()];
            assert!(
                check(&mut b.gyro, gread1, cfg),
                "periodic check {:#04x}",
                cfg.0
            );
        }
    }
    assert_eq!(got.len(), 4000, "2 s at 2 kHz");
    assert_gyro(&got, &b.gyro_log[start..]);
}

#[test]
fn px4_both_dies_on_one_board_and_a_late_gyro_poll() {
    let mut b = Bench::new();
    px4_accel_init(&mut b);
    gyro_init(&mut b);
    let (a0, g0) = (b.accel_log.len(), b.gyro_log.len());
    // The accel FIFO was reset before the gyro's init: its frames since are all there.
    spi(&mut b.accel, &[0x7E, 0xB0]);
    let a0 = a0.max(b.accel_log.len());
    let (mut acc, mut gyr) = (Vec::new(), Vec::new());
    for _ in 0..100 {
        b.wait_ns(2_500_000);
        acc.extend(px4_accel_fifo_read(&mut b.accel));
        gyr.extend(px4_gyro_fifo_read(&mut b.gyro).expect("no overrun"));
    }
    assert_accel(&acc, &b.accel_log[a0..]);
    assert_gyro(&gyr, &b.gyro_log[g0..]);
    // 60 ms without a poll: 120 gyro frames do not fit in 100; PX4 sees the overrun.
    b.wait_ns(60 * MS);
    assert_eq!(px4_gyro_fifo_read(&mut b.gyro), None);
    assert_eq!(gread1(&mut b.gyro, 0x0E), 0x80 | 100);
}
