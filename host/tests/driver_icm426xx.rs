//! The `icm426xx` crate (0.4, embedded-hal 1.0, blocking API), unmodified, drives the emulated
//! ICM-42688-P over SPI (`margemu::bus::SpiDevice`) through its FIFO path.
//!
//! What the crate does (read in `icm426xx-0.4.0/src`, not its docs):
//! - `ICM42688::new(spi).initialize(delay, Config)` (`uninitialized.rs`): soft reset, WHO_AM_I
//!   0x47, INT1 push-pull, FIFO_MODE stop-on-full, big-endian data and FIFO count, I2C off,
//!   AFSR off, **GYRO_FS_SEL = 0 and ACCEL_FS_SEL = 0** (±2000 °/s, ±16 g) at one ODR for both,
//!   ODR timestamps of 16 µs (deltas by default), FIFO_CONFIG1 = HIRES | TEMP | GYRO | ACCEL
//!   (packet 4, 20 bytes) with a 20-byte watermark, then gyro and accel in low-noise mode.
//!   The crate has no full-scale setter: 20-bit FIFO data has a fixed ±16 g / ±2000 °/s scale
//!   anyway (DS-000347 6.1 FIFO packet structure: 18-bit accel at 8192 LSB/g, 19-bit gyro at
//!   131 LSB/(°/s)), so the one full scale it sets is tested, and
//!   `twenty_bit_data_ignores_the_ui_full_scale` writes the other FS_SEL codes through its
//!   low-level register API (`ll()`) to show the FIFO data does not change.
//! - `read_sample()` (`ready.rs`): one SPI burst from INT_STATUS (0x2D) over FIFO_COUNTH/L into
//!   FIFO_DATA (20 bytes); `Err(FifoOverflow)` if INT_STATUS.FIFO_FULL_INT, `None` if the header
//!   says the FIFO is empty, else the decoded packet and whether more bytes than one packet were
//!   counted. `read_fifo(&mut [u32])`: the same burst into a caller's buffer, returning
//!   FIFO_COUNT / 20, the packets in the FIFO (not those that fit in the buffer); the caller
//!   decodes the bytes with the crate's `FifoPacket4`.
//!
//! Each value is checked to within one LSB of the 20-bit format's resolution (4 codes for
//! accel, 2 for gyro) in the units the crate returns: the sample becomes 20-bit codes at the
//! datasheet sensitivity, clipped like the FIFO (never to the invalid code −524288), and is then
//! scaled the crate's way. Two crate bugs are worked around that way:
//! - gyro: `sample_from_packet4` scales by 2000/2^19 °/s per code (262.144 codes per °/s); the
//!   datasheet's 19-bit gyro is 131 LSB/(°/s), i.e. 262 codes: the crate reads 550 ppm low, up
//!   to 144 19-bit LSB (1.1 °/s) near ±2000 °/s (printed in parentheses as "face value").
//! - temperature: packet 4 carries the 16-bit TEMP_DATA value (DS 4.13 and 6.1: °C =
//!   TEMP_DATA / 132.48 + 25; the 2.07 LSB/°C is the 8-bit FIFO_TEMP_DATA of packets 1–3), but
//!   the crate divides it by 2.07 and reads it as **unsigned** (`temperature_raw() -> u16`):
//!   30 °C (662) comes back as 344.8 °C and 20 °C (−662 → 64874) as 31 365 °C. The check
//!   applies the crate's formula to the chip's 16-bit value. (TDK's own ICM-426xx driver
//!   agrees with the datasheet: its `TEMP_SENSITIVITY_2_BYTE` is 1/132.48 "for data register
//!   and FIFO high res. data conversion".)

mod driver_support;

use embedded_hal::spi::SpiDevice as _;
use icm426xx::fifo::FifoPacket4;
use icm426xx::{Config, Error, Sample, Timestamp, ICM42688};
use margemu::bus::{self, Clock, Shared};
use margemu_firmware::chip::{Icm42688p as Chip, PhysicalSample};
use margemu_protocol::regmap::icm42688p::convert::{accel_to_raw20, gyro_to_raw20, temp_to_raw};

/// Standard gravity, m/s² per g (the chip's g and the crate's `STD_GRAVITY`).
const G: f64 = 9.80665;
const RAD_PER_DEG: f64 = std::f64::consts::PI / 180.0;
/// 20-bit codes per g (18 meaningful bits at 8192 LSB/g, the 2 low bits 0).
const ACCEL_CODES_PER_G: f64 = 8192.0 * 4.0;
/// 20-bit codes per °/s (19 meaningful bits at 131 LSB/(°/s), the low bit 0).
const GYRO_CODES_PER_DPS: f64 = 131.0 * 2.0;
/// The largest 18-bit / 19-bit magnitudes: the FIFO never produces −2^17 / −2^18, whose 20-bit
/// code −524288 marks an invalid sample.
const ACCEL_MAX18: f64 = 131_071.0;
const GYRO_MAX19: f64 = 262_143.0;
/// TEMP_DATA sensitivity, LSB/°C.
const TEMP_LSB_PER_C: f64 = 132.48;
/// The crate's output data rate (`Config::default()`): 200 Hz.
const PERIOD_NS: u64 = 5_000_000;

type Spi = bus::SpiDevice<Chip>;
type Icm = ICM42688<Spi, icm426xx::Ready>;

/// A fresh chip, initialised by the crate with its default configuration.
fn init() -> (Shared<Chip>, Icm, Clock) {
    let chip = bus::shared(Chip::new());
    let clock = Clock::new();
    let icm = ICM42688::new(Spi::new(chip.clone()))
        .initialize(bus::Delay::with_clock(clock.clone()), Config::default())
        .unwrap();
    chip.borrow_mut().advance(clock.now_ns());
    (chip, icm, clock)
}

/// A deterministic spread of samples: edge cases first (zero, ±1 LSB, ±full scale, beyond
/// it), then pseudo-random values up to 1.3 × full scale on every axis, temperatures from
/// −40 to 85 °C.
fn samples(n: usize) -> Vec<PhysicalSample> {
    let accel_fs = 16.0 * G;
    let gyro_fs = 2000.0 * RAD_PER_DEG;
    let edges: [f64; 9] = [0.0, 1.0, -1.0, 0.5, -0.5, 0.999, -0.999, 1.3, -1.3];
    let lsb = [1.0 / 131_072.0, -1.0 / 131_072.0];
    let mut out = Vec::new();
    for (i, &u) in edges.iter().chain(lsb.iter()).enumerate() {
        out.push(PhysicalSample {
            acc: [u, -u, u * 0.25].map(|v| (v * accel_fs) as f32),
            gyr: [-u, u, u * 0.75].map(|v| (v * gyro_fs) as f32),
            mag: [0.0; 3],
            temp_c: -40.0 + 12.5 * i as f32,
        });
    }
    let random = n.saturating_sub(out.len());
    out.extend(
        driver_support::random_samples(0x2545_F491_4F6C_DD1D, accel_fs, gyro_fs).take(random),
    );
    out
}

/// Worst deviations (accel, gyro, temperature), in LSB of the 20-bit format's resolution
/// (temperature: of TEMP_DATA), and the crate's values taken at face value.
#[derive(Clone, Copy, Debug, Default)]
struct Worst {
    check: [f64; 3],
    face_value: [f64; 3],
    saturated: usize,
    negative: usize,
}

impl std::fmt::Display for Worst {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [a, g, t] = self.check;
        let [fa, fg, ft] = self.face_value;
        write!(
            f,
            "accel {a:.3} ({fa:.3}) gyro {g:.3} ({fg:.3}) temp {t:.3} ({ft:.1}) LSB; \
             {} saturated and {} negative axis values",
            self.saturated, self.negative
        )
    }
}

/// One axis of one sample.
struct Axis {
    /// What the crate returned.
    got: f64,
    /// The latched value, in the crate's unit.
    sample: f64,
    /// One 20-bit code as the crate scales it.
    unit: f64,
    /// One 20-bit code at the datasheet's sensitivity.
    chip_unit: f64,
    /// Codes per LSB of resolution (accel 4, gyro 2).
    step: f64,
    /// The largest magnitude, in LSB of resolution.
    max: f64,
}

impl Axis {
    fn add_to(&self, w: &mut Worst, i: usize) {
        // The sample in codes, unrounded, clipped as the FIFO clips.
        let ideal =
            (self.sample / self.chip_unit / self.step).clamp(-self.max, self.max) * self.step;
        let check = (self.got / self.unit - ideal).abs() / self.step;
        let face_value = (self.got - ideal * self.chip_unit).abs() / (self.chip_unit * self.step);
        w.check[i] = w.check[i].max(check);
        w.face_value[i] = w.face_value[i].max(face_value);
        w.saturated += usize::from(ideal.abs() >= self.max * self.step);
        w.negative += usize::from(ideal < 0.0);
    }
}

/// How far `s` (what the crate decoded) is from `p` (what was latched).
fn deviation(w: &mut Worst, s: &Sample, p: &PhysicalSample) {
    let full = (1u32 << 19) as f64;
    let (ax, ay, az) = s.accel.expect("packet 4 carries accel");
    let (gx, gy, gz) = s.gyro.expect("packet 4 carries gyro");
    for (k, got) in [ax, ay, az].into_iter().enumerate() {
        let a = Axis {
            got: f64::from(got),
            sample: f64::from(p.acc[k]),
            unit: G * 16.0 / full,
            chip_unit: G / ACCEL_CODES_PER_G,
            step: 4.0,
            max: ACCEL_MAX18,
        };
        a.add_to(w, 0);
    }
    for (k, got) in [gx, gy, gz].into_iter().enumerate() {
        let a = Axis {
            got: f64::from(got),
            sample: f64::from(p.gyr[k]),
            unit: RAD_PER_DEG * 2000.0 / full,
            chip_unit: RAD_PER_DEG / GYRO_CODES_PER_DPS,
            step: 2.0,
            max: GYRO_MAX19,
        };
        a.add_to(w, 1);
    }
    // TEMP_DATA as the chip computes it, then the crate's (unsigned, 2.07 LSB/°C) reading.
    let raw = ((f64::from(p.temp_c) - 25.0) * TEMP_LSB_PER_C)
        .round()
        .clamp(-32768.0, 32767.0) as i16;
    // (Rounded first: the crate's unsigned reading of a negative value is what is compared.)
    let got = (f64::from(s.temperature_celsius) - 25.0) * 2.07;
    w.check[2] = w.check[2].max((got - f64::from(raw as u16)).abs());
    let face = (f64::from(s.temperature_celsius) - f64::from(p.temp_c)).abs() * TEMP_LSB_PER_C;
    w.face_value[2] = w.face_value[2].max(face);
}

/// Latches `batch` samples one ODR period apart, then reads the FIFO dry through the crate:
/// every packet in order, `more` set on all but the last, the ODR timestamp deltas (16 µs)
/// matching the latch instants, then `None`.
/// `previous_tick`: the 16 µs tick of the last packet pushed since the FIFO was reset.
fn replay(
    chip: &Shared<Chip>,
    icm: &mut Icm,
    samples: &[PhysicalSample],
    batch: usize,
    previous_tick: &mut Option<u64>,
) -> Worst {
    let mut w = Worst::default();
    let mut t = chip.borrow().now_ns();
    let mut read = 0;
    for chunk in samples.chunks(batch) {
        for p in chunk {
            t += PERIOD_NS;
            chip.borrow_mut().latch_at(p, t);
        }
        let instants: Vec<u64> = (0..chunk.len() as u64)
            .map(|k| t - (chunk.len() as u64 - 1 - k) * PERIOD_NS)
            .collect();
        for (k, p) in chunk.iter().enumerate() {
            let (s, more) = icm
                .read_sample()
                .unwrap()
                .unwrap_or_else(|| panic!("sample {read} missing from the FIFO"));
            assert_eq!(more, k + 1 < chunk.len(), "more-data flag of sample {read}");
            let tick = instants[k] / 16_000;
            let delta = previous_tick.map_or(0, |p| tick - p) as u16;
            *previous_tick = Some(tick);
            assert_eq!(s.timestamp, Timestamp::OdrTimestamp(delta), "sample {read}");
            deviation(&mut w, &s, p);
            read += 1;
        }
        assert!(
            icm.read_sample().unwrap().is_none(),
            "FIFO empty after {read}"
        );
    }
    assert_eq!(read, samples.len());
    w
}

/// Raw bank 0 register read beside the driver (its SPI device is released between calls).
fn reg(chip: &Shared<Chip>, addr: u8) -> u8 {
    let mut buf = [0x80 | addr, 0];
    Spi::new(chip.clone()).transfer_in_place(&mut buf).unwrap();
    buf[1]
}

#[test]
fn initialize_configures_packet_4_at_16_g_2000_dps() {
    let (chip, _icm, clock) = init();
    assert!(
        clock.now_ns() >= 1_200_000,
        "1 ms after reset, 200 µs after power-on"
    );
    let expected = [
        (
            0x4E,
            0x0F,
            "PWR_MGMT0: gyro and accel low noise, temperature on",
        ),
        (0x4F, 0x07, "GYRO_CONFIG0: ±2000 °/s, 200 Hz"),
        (0x50, 0x07, "ACCEL_CONFIG0: ±16 g, 200 Hz"),
        (0x16, 0xC0, "FIFO_CONFIG: stop on full"),
        (
            0x5F,
            0x37,
            "FIFO_CONFIG1: WM_GT_TH, HIRES, TEMP, GYRO, ACCEL",
        ),
        (0x60, 20, "FIFO_CONFIG2: watermark 20 bytes"),
    ];
    for (addr, value, what) in expected {
        assert_eq!(reg(&chip, addr), value, "{what}");
    }
    assert_eq!(
        reg(&chip, 0x4C) & 0x73,
        0x33,
        "INTF_CONFIG0: big-endian, bytes, I2C off"
    );
    assert_eq!(
        reg(&chip, 0x54) & 0x1F,
        0x1D,
        "TMST_CONFIG: 16 µs deltas, TMST_EN"
    );
    assert_eq!(chip.borrow().sample_period_ns(), PERIOD_NS);
    assert_eq!(chip.borrow().peek(0, 0x76), 0, "back in bank 0");
}

#[test]
fn every_sample_through_the_fifo_within_one_lsb() {
    let (chip, mut icm, _) = init();
    let samples = samples(400);
    let mut total = Worst::default();
    let mut tick = None;
    // Batches of 1, then several packets per read-out (up to 40 = 800 bytes of 2048).
    for (batch, part) in [(1, 0..100), (3, 100..199), (7, 199..300), (40, 300..400)] {
        let w = replay(&chip, &mut icm, &samples[part], batch, &mut tick);
        println!("batches of {batch}: {w}");
        assert!(w.check.iter().all(|d| *d <= 1.0), "batches of {batch}: {w}");
        for i in 0..3 {
            total.check[i] = total.check[i].max(w.check[i]);
            total.face_value[i] = total.face_value[i].max(w.face_value[i]);
        }
        total.saturated += w.saturated;
        total.negative += w.negative;
    }
    println!("worst: {total}");
    assert!(total.saturated > 50 && total.negative > 500, "{total}");
}

#[test]
fn twenty_bit_data_ignores_the_ui_full_scale() {
    let (chip, mut icm, _) = init();
    let samples = samples(60);
    let mut tick = None;
    for code in 0..4u8 {
        // The crate's low-level register API: bank 0 ACCEL_CONFIG0 / GYRO_CONFIG0.
        let mut bank0 = icm.ll().bank::<0>();
        bank0
            .accel_config0()
            .modify(|_, w| w.accel_fs_sel(code))
            .unwrap();
        bank0
            .gyro_config0()
            .modify(|_, w| w.gyro_fs_sel(2 * code))
            .unwrap();
        assert_eq!(reg(&chip, 0x50), code << 5 | 0x07);
        assert_eq!(reg(&chip, 0x4F), (2 * code) << 5 | 0x07);
        let part = &samples[usize::from(code) * 15..usize::from(code + 1) * 15];
        let w = replay(&chip, &mut icm, part, 5, &mut tick);
        assert!(
            w.check.iter().all(|d| *d <= 1.0),
            "FS codes {code}/{}: {w}",
            2 * code
        );
    }
}

#[test]
fn a_full_fifo_is_reported_as_overflow() {
    let (chip, mut icm, _) = init();
    let samples = samples(103);
    let mut t = chip.borrow().now_ns();
    // 102 packets of 20 bytes fit in 2048; the 103rd is dropped (stop on full).
    for p in &samples[..102] {
        t += PERIOD_NS;
        chip.borrow_mut().latch_at(p, t);
    }
    let (_, more) = icm.read_sample().unwrap().unwrap();
    assert!(more);
    for p in &samples[..=102] {
        t += PERIOD_NS;
        chip.borrow_mut().latch_at(p, t);
    }
    assert!(matches!(icm.read_sample(), Err(Error::FifoOverflow)));
    // SIGNAL_PATH_RESET.FIFO_FLUSH through the crate empties it.
    icm.reset_fifo().unwrap();
    assert!(icm.read_sample().unwrap().is_none());
}

/// One packet 4 from 20 FIFO bytes, as the crate's `FifoPacket4` (its fields in FIFO order).
fn packet4(b: &[u8]) -> FifoPacket4 {
    FifoPacket4 {
        fifo_header: b[0],
        accel_data_x1: b[1],
        accel_data_x0: b[2],
        accel_data_y1: b[3],
        accel_data_y0: b[4],
        accel_data_z1: b[5],
        accel_data_z0: b[6],
        gyro_data_x1: b[7],
        gyro_data_x0: b[8],
        gyro_data_y1: b[9],
        gyro_data_y0: b[10],
        gyro_data_z1: b[11],
        gyro_data_z0: b[12],
        temp_data1: b[13],
        temp_data0: b[14],
        timestamp_h: b[15],
        timestamp_l: b[16],
        ext_accel_x_gyro_x: b[17],
        ext_accel_y_gyro_y: b[18],
        ext_accel_z_gyro_z: b[19],
    }
}

/// The packet's 20-bit codes, as the crate assembles them, are exactly the chip's conversion
/// of the sample (bits 19:12, 11:4 and the extension nibbles in their places).
fn assert_codes(k: usize, q: &FifoPacket4, p: &PhysicalSample) {
    assert_eq!(
        q.fifo_header, 0x78,
        "packet {k}: ACCEL | GYRO | 20 | TIMESTAMP_ODR"
    );
    let accel = [q.accel_data_x(), q.accel_data_y(), q.accel_data_z()];
    let gyro = [q.gyro_data_x(), q.gyro_data_y(), q.gyro_data_z()];
    assert_eq!(accel, p.acc.map(accel_to_raw20), "packet {k} accel");
    assert_eq!(gyro, p.gyr.map(gyro_to_raw20), "packet {k} gyro");
    assert_eq!(
        q.temperature_raw() as i16,
        temp_to_raw(p.temp_c),
        "packet {k} temp"
    );
}

/// The bytes `read_fifo` left in its `u32` buffer (the crate casts the buffer to bytes in
/// memory order): [command, INT_STATUS, FIFO_COUNTH, FIFO_COUNTL, FIFO data …].
fn fifo_bytes(buf: &[u32]) -> Vec<u8> {
    buf.iter().flat_map(|w| w.to_ne_bytes()).collect()
}

#[test]
fn read_fifo_bursts_whole_and_partial_packets() {
    let (chip, mut icm, _) = init();
    let samples = samples(40);
    let mut t = chip.borrow().now_ns();
    for p in &samples[..25] {
        t += PERIOD_NS;
        chip.borrow_mut().latch_at(p, t);
    }
    // Room for 10 packets: it reports the 25 counted, the other 15 stay in the FIFO.
    let mut buf = [0u32; (4 + 10 * 20) / 4];
    assert_eq!(icm.read_fifo(&mut buf).unwrap(), 25);
    let bytes = fifo_bytes(&buf);
    assert_eq!(
        u16::from_be_bytes([bytes[2], bytes[3]]),
        25 * 20,
        "FIFO_COUNT"
    );
    for (k, b) in bytes[4..].chunks_exact(20).enumerate() {
        assert_codes(k, &packet4(b), &samples[k]);
    }
    // 28 data bytes: packet 10 whole and 8 bytes of packet 11. FIFO_RESUME_PARTIAL_RD is
    // clear, so packet 11 is read again from its start (DS: FIFO_CONFIG1).
    let mut buf = [0u32; 8];
    assert_eq!(icm.read_fifo(&mut buf).unwrap(), 15);
    let bytes = fifo_bytes(&buf);
    assert_codes(10, &packet4(&bytes[4..24]), &samples[10]);
    assert_eq!(bytes[24], 0x78, "packet 11's header");
    // The rest, one packet at a time, then the other 15 samples in one burst.
    for (k, p) in samples.iter().enumerate().take(25).skip(11) {
        let (s, more) = icm.read_sample().unwrap().unwrap();
        assert_eq!(more, k < 24);
        let mut w = Worst::default();
        deviation(&mut w, &s, p);
        assert!(w.check.iter().all(|d| *d <= 1.0), "sample {k}: {w}");
    }
    assert!(icm.read_sample().unwrap().is_none());
    for p in &samples[25..] {
        t += PERIOD_NS;
        chip.borrow_mut().latch_at(p, t);
    }
    let mut buf = [0u32; (4 + 15 * 20) / 4];
    assert_eq!(icm.read_fifo(&mut buf).unwrap(), 15);
    let bytes = fifo_bytes(&buf);
    for (k, b) in bytes[4..].chunks_exact(20).enumerate() {
        assert_codes(25 + k, &packet4(b), &samples[25 + k]);
    }
    assert!(icm.read_sample().unwrap().is_none());
}

/// The interrupt-driven loop the crate is set up for: INT1 latched, active high, on FIFO_THS
/// (20-byte watermark, WM_GT_TH), cleared by the first FIFO byte read (INT_CONFIG0
/// FIFO_THS_INT_CLEAR = 10), not by the INT_STATUS read in the same burst.
#[test]
fn fifo_threshold_drives_int1() {
    let (chip, mut icm, _) = init();
    let pin = |chip: &Shared<Chip>| chip.borrow().int_pin();
    assert_eq!(
        reg(&chip, 0x65) & 0x14,
        0x14,
        "INT_SOURCE0: FIFO_THS, RESET_DONE (reset)"
    );
    // RESET_DONE_INT, routed to INT1 from reset, holds the latched pin until INT_STATUS is read.
    assert!(pin(&chip), "RESET_DONE after the soft reset");
    assert!(icm.read_sample().unwrap().is_none());
    assert!(!pin(&chip), "INT_STATUS read");
    let samples = samples(8);
    let mut t = chip.borrow().now_ns();
    let mut latch = |chip: &Shared<Chip>, p: &PhysicalSample| {
        t += PERIOD_NS;
        chip.borrow_mut().latch_at(p, t);
    };
    latch(&chip, &samples[0]);
    assert!(pin(&chip), "one packet reaches the watermark");
    assert!(!icm.read_sample().unwrap().unwrap().1);
    assert!(!pin(&chip), "cleared by the FIFO read");
    for p in &samples[1..4] {
        latch(&chip, p);
    }
    assert!(pin(&chip));
    let (_, more) = icm.read_sample().unwrap().unwrap();
    assert!(
        more && !pin(&chip),
        "cleared by the first FIFO byte, 2 packets left"
    );
    assert!(icm.read_sample().unwrap().unwrap().1);
    assert!(!icm.read_sample().unwrap().unwrap().1);
    latch(&chip, &samples[4]);
    assert!(pin(&chip), "WM_GT_TH: the next packet raises it again");
}
