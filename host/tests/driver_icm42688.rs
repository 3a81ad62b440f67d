//! The `icm42688` crate (0.2.0, embedded-hal 0.2, I2C only), unmodified, drives the emulated
//! ICM-42688-P through margemu's embedded-hal 1.0 `bus::I2c`, bridged back to 0.2 by
//! `embedded-hal-compat` (`.reverse()`), at 0x68 (AD0 low) and 0x69 (AD0 high). Its published
//! manifest cannot be built on a host (a yanked `esp-println`, unconditional ESP32-C3 crates):
//! the workspace patches in `vendor/icm42688-0.2.0`, the same sources with those dependencies
//! dropped.
//!
//! What the crate does (read in `icm42688-0.2.0/src`, not its docs):
//! - `Icm42688::new(i2c, address)` (`lib.rs`): WHO_AM_I must be 0x47; ACCEL_CONFIG0 and
//!   GYRO_CONFIG0 full scales back to ±16 g / ±2000 °/s (read-modify-write); PWR_MGMT0 to
//!   `PowerMode::SixAxisLowNoise` = 0b10_1111, which sets TEMP_DIS (bit 5): temperature off
//!   (the crate's `…Temp` power modes keep it on). `new_i2c_slew` also soft-resets and writes
//!   DRIVE_CONFIG, waiting 300 ms between steps.
//! - Full scales: `set_accel_range` (±2/4/8/16 g) and `set_gyro_range` (±15.625 … ±2000 °/s),
//!   all of the datasheet's, through read-modify-write of bits 6:5 / 7:5.
//! - Data: every 16-bit value as two single-register reads (low byte first, then high,
//!   big-endian), no burst. `accel_norm` returns g (raw / LSB per g, re-reading the range),
//!   `gyro_norm` **°/s** (raw / LSB per °/s: 16.4 … 2097.2, the datasheet's), `temperature`
//!   °C (raw / 132.48 + 25).
//!
//! - FIFO (`new_fifo`, "development use" helpers): FIFO stop-on-full, timestamps (1 µs deltas),
//!   FIFO_CONFIG1 for packet 1, 2, 3 or 4, both ODRs 1 kHz, ±16 g / ±2000 °/s, sensors on with
//!   temperature; `read_fifo(addr, buf)` is one I2C burst, `read_fifo_cnt` two register reads,
//!   `FifoDataP1`…`P4::to_fifodata_raw` decode packets. Crate bugs met there, worked around
//!   in `fifo_packets_over_i2c` (each against DS-000347's register map and descriptions):
//!   `SIGNAL_PATH_RESET` is 0x48 in its `register.rs`, the datasheet's is 0x4B, so its FIFO
//!   flush writes a reserved address (harmless here: nothing was latched yet); `read_fifo_cnt`
//!   reads FIFO_COUNTL before FIFO_COUNTH, but reading FIFO_COUNTH is what latches both
//!   (FIFO_COUNTL: "Must read FIFO_COUNTH to latch new data"), so its low byte is the previous
//!   latch's: it is called twice; `FifoDataSiP2` takes the gyro of packet 2 from bytes 7–12
//!   (packet 2 has it in 1–6, as its own `FifoDataP2` reads it), so only the raw decoders
//!   are checked for packets 1–3. The SI conversions use g = 9.81 (350 ppm above the standard
//!   gravity the chip's sensitivity is in).
//!
//! - AFSR: the crate never writes INTF_CONFIG1, so AFSR stays on as at power-on and its users
//!   get the gyro stall every flight firmware turns off (2 ms held at each crossing of
//!   ±100 °/s, `margemu_firmware::chip::icm42688p`'s `afsr` module): a finding about the
//!   crate, shown by `the_crate_leaves_afsr_on_and_its_gyro_stalls`. The conversion checks
//!   below turn AFSR off from the rig side first ([`afsr_off`], the one register write a user
//!   of the crate would have to add, through no API of the crate), so they check the
//!   conversions and not the stall.
//!
//! For every accel × gyro full scale, samples are latched between driver calls: zero, ±1 LSB,
//! ±full scale and beyond it (saturation), negative values, −40 … 85 °C; every value the crate
//! returns must be within one LSB of the latched sample (clipped as the register clips).

mod driver_support;

use embedded_hal_compat::{Reverse, ReverseCompat};
use icm42688::prelude::*;
use icm42688::{
    AccelRange, Address, Error, FifoDataP1, FifoDataP2, FifoDataP3, FifoDataP4, FifoDataSiP4,
    FifoPacketType, GyroRange, I2cSlewRate, PowerMode,
};
use margemu::bus::{self, Clock, Shared};
use margemu_firmware::chip::icm42688p::Config;
use margemu_firmware::chip::{Chip as _, Icm42688p as Chip, PhysicalSample};
use margemu_protocol::regmap::icm42688p::convert::{
    accel_to_raw, accel_to_raw20, fifo_temp8, gyro_to_raw, gyro_to_raw20, temp_to_raw,
};
use margemu_protocol::regmap::icm42688p::{AccelFs, GyroFs};

/// Standard gravity, m/s² per g.
const G: f64 = 9.80665;
const DEG_PER_RAD: f64 = 180.0 / std::f64::consts::PI;
/// TEMP_DATA sensitivity, LSB/°C.
const TEMP_LSB_PER_C: f64 = 132.48;
/// The chip's sample period at its reset ODR (1 kHz; the crate leaves the ODR alone).
const PERIOD_NS: u64 = 1_000_000;

const ACCEL_RANGES: [(AccelRange, u8, f64, f64); 4] = [
    (AccelRange::G16, 0, 16.0, 2048.0),
    (AccelRange::G8, 1, 8.0, 4096.0),
    (AccelRange::G4, 2, 4.0, 8192.0),
    (AccelRange::G2, 3, 2.0, 16384.0),
];
const GYRO_RANGES: [(GyroRange, u8, f64, f64); 8] = [
    (GyroRange::Deg2000, 0, 2000.0, 16.4),
    (GyroRange::Deg1000, 1, 1000.0, 32.8),
    (GyroRange::Deg500, 2, 500.0, 65.5),
    (GyroRange::Deg250, 3, 250.0, 131.0),
    (GyroRange::Deg125, 4, 125.0, 262.0),
    (GyroRange::Deg62_5, 5, 62.5, 524.3),
    (GyroRange::Deg31_25, 6, 31.25, 1048.6),
    (GyroRange::Deg15_625, 7, 15.625, 2097.2),
];

type I2c = Reverse<bus::I2c<Chip>>;
type Icm = icm42688::Icm42688<I2c>;

/// A chip with AD0 as given, and its I2C address as the crate names it.
fn chip(ad0: bool) -> (Shared<Chip>, Address) {
    let chip = Chip::with_config(Config {
        ad0,
        ..Config::default()
    });
    let address = if ad0 {
        Address::Secondary
    } else {
        Address::Primary
    };
    assert_eq!(chip.i2c_address(), address as u8);
    (bus::shared(chip), address)
}

fn connect(chip: &Shared<Chip>) -> I2c {
    bus::I2c::new(chip.clone()).reverse()
}

/// The 0.2 `DelayUs<u8>` `new_i2c_slew` takes: advances a clock and the chip's with it.
struct ChipDelay {
    clock: Clock,
    chip: Shared<Chip>,
}

impl embedded_hal_02::blocking::delay::DelayUs<u8> for ChipDelay {
    fn delay_us(&mut self, us: u8) {
        self.clock.advance_ns(u64::from(us) * 1000);
        self.chip.borrow_mut().advance(self.clock.now_ns());
    }
}

/// Samples for one pair of full scales: edge cases (zero, ±1 LSB, ±full scale, 1.3 × full
/// scale) then pseudo-random values up to 1.3 × full scale on every axis, −40 … 85 °C.
fn samples(
    accel_g: f64,
    accel_lsb: f64,
    gyro_dps: f64,
    gyro_lsb: f64,
    seed: u64,
) -> Vec<PhysicalSample> {
    let a_fs = accel_g * G;
    let g_fs = gyro_dps / DEG_PER_RAD;
    let a_lsb = G / accel_lsb;
    let g_lsb = 1.0 / (gyro_lsb * DEG_PER_RAD);
    let mut out = Vec::new();
    let edges: [(f64, f64); 8] = [
        (0.0, 0.0),
        (a_lsb, g_lsb),
        (-a_lsb, -g_lsb),
        (a_fs, g_fs),
        (-a_fs, -g_fs),
        (1.3 * a_fs, 1.3 * g_fs),
        (-1.3 * a_fs, -1.3 * g_fs),
        (0.5 * a_fs, -0.5 * g_fs),
    ];
    for (i, (a, g)) in edges.into_iter().enumerate() {
        out.push(PhysicalSample {
            acc: [a, -a, 0.25 * a].map(|v| v as f32),
            gyr: [-g, g, 0.75 * g].map(|v| v as f32),
            mag: [0.0; 3],
            temp_c: -40.0 + 16.0 * i as f32,
        });
    }
    let state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    out.extend(driver_support::random_samples(state, a_fs, g_fs).take(24));
    out
}

/// Turns AFSR off from the rig side (INTF_CONFIG1 bits 7:6 = 01, the other bits kept, as
/// Betaflight, ArduPilot and PX4 write it): the crate never does.
fn afsr_off(chip: &Shared<Chip>) {
    let value = chip.borrow().peek(0, 0x4D);
    assert!(chip
        .borrow_mut()
        .write_register(0, 0x4D, (value & 0x3F) | 0x40));
    assert!(!chip.borrow().afsr_enabled());
}

/// Worst deviations (accel, gyro, temperature) in LSB of the current full scale.
#[derive(Clone, Copy, Debug, Default)]
struct Worst {
    lsb: [f64; 3],
    saturated: usize,
    negative: usize,
}

impl Worst {
    /// `got` in LSB (the crate's value times its sensitivity), `ideal` the sample in LSB.
    fn add(&mut self, i: usize, got: f64, ideal: f64) {
        let ideal = ideal.clamp(-32768.0, 32767.0);
        self.lsb[i] = self.lsb[i].max((got - ideal).abs());
        self.saturated += usize::from(ideal <= -32768.0 || ideal >= 32767.0);
        self.negative += usize::from(ideal < 0.0);
    }

    fn max(self, o: Self) -> Self {
        Self {
            lsb: [0, 1, 2].map(|i| self.lsb[i].max(o.lsb[i])),
            saturated: self.saturated + o.saturated,
            negative: self.negative + o.negative,
        }
    }
}

impl std::fmt::Display for Worst {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [a, g, t] = self.lsb;
        write!(
            f,
            "accel {a:.3} gyro {g:.3} temp {t:.3} LSB; {} saturated and {} negative values",
            self.saturated, self.negative
        )
    }
}

/// Latches each sample, reads it back through every data call of the crate, and returns the
/// worst deviation. `accel_lsb` / `gyro_lsb`: the chip's sensitivity at the current scales.
fn replay(
    chip: &Shared<Chip>,
    icm: &mut Icm,
    samples: &[PhysicalSample],
    accel_lsb: f64,
    gyro_lsb: f64,
) -> Worst {
    let mut w = Worst::default();
    for p in samples {
        let t = chip.borrow().now_ns() + PERIOD_NS;
        chip.borrow_mut().latch_at(p, t);
        let accel = icm.accel_norm().unwrap();
        let gyro = icm.gyro_norm().unwrap();
        let temp = icm.temperature().unwrap();
        let accel_raw = icm.accel_raw().unwrap();
        let gyro_raw = icm.gyro_raw().unwrap();
        assert_eq!(
            icm.temperature_raw().unwrap(),
            ((f64::from(temp) - 25.0) * TEMP_LSB_PER_C).round() as i16
        );
        let accel = [accel.x, accel.y, accel.z];
        let gyro = [gyro.x, gyro.y, gyro.z];
        let accel_raw = [accel_raw.x, accel_raw.y, accel_raw.z];
        let gyro_raw = [gyro_raw.x, gyro_raw.y, gyro_raw.z];
        for k in 0..3 {
            // accel_norm: g; gyro_norm: °/s.
            let a_ideal = f64::from(p.acc[k]) / G * accel_lsb;
            let g_ideal = f64::from(p.gyr[k]) * DEG_PER_RAD * gyro_lsb;
            w.add(0, f64::from(accel[k]) * accel_lsb, a_ideal);
            w.add(1, f64::from(gyro[k]) * gyro_lsb, g_ideal);
            assert!((f64::from(accel_raw[k]) - f64::from(accel[k]) * accel_lsb).abs() < 0.01);
            assert!((f64::from(gyro_raw[k]) - f64::from(gyro[k]) * gyro_lsb).abs() < 0.01);
        }
        let t_ideal = (f64::from(p.temp_c) - 25.0) * TEMP_LSB_PER_C;
        w.add(2, (f64::from(temp) - 25.0) * TEMP_LSB_PER_C, t_ideal);
    }
    w
}

/// `new`, then the temperature sensor on, then every accel × gyro full scale set through the
/// crate, each checked in the chip's registers and read back through the crate.
fn every_full_scale(ad0: bool) {
    let (chip, address) = chip(ad0);
    let mut icm = Icm::new(connect(&chip), address).unwrap();
    assert!(chip.borrow().afsr_enabled(), "the crate leaves AFSR on");
    afsr_off(&chip);
    assert_eq!(icm.device_id().unwrap(), 0x47);
    assert_eq!(
        chip.borrow().peek(0, 0x4E),
        0x2F,
        "PWR_MGMT0: TEMP_DIS, gyro and accel low noise"
    );
    icm.set_power_mode(PowerMode::SixAxisLowNoiseTemp).unwrap();
    assert_eq!(
        chip.borrow().peek(0, 0x4E),
        0x0F,
        "PWR_MGMT0: temperature on"
    );
    assert_eq!(icm.power_mode().unwrap(), PowerMode::SixAxisLowNoiseTemp);
    let mut total = Worst::default();
    let mut lines = Vec::new();
    for &(accel, a_code, accel_g, accel_lsb) in &ACCEL_RANGES {
        for &(gyro, g_code, gyro_dps, gyro_lsb) in &GYRO_RANGES {
            icm.set_accel_range(accel).unwrap();
            icm.set_gyro_range(gyro).unwrap();
            assert_eq!(icm.accel_range().unwrap(), accel);
            assert_eq!(icm.gyro_range().unwrap(), gyro);
            // The ODR (1 kHz, reset value) is kept by the read-modify-writes.
            assert_eq!(
                chip.borrow().peek(0, 0x50),
                a_code << 5 | 0x06,
                "ACCEL_CONFIG0"
            );
            assert_eq!(
                chip.borrow().peek(0, 0x4F),
                g_code << 5 | 0x06,
                "GYRO_CONFIG0"
            );
            let seed = u64::from(a_code) << 8 | u64::from(g_code) | u64::from(ad0) << 16;
            let samples = samples(accel_g, accel_lsb, gyro_dps, gyro_lsb, seed);
            let w = replay(&chip, &mut icm, &samples, accel_lsb, gyro_lsb);
            let what = format!("0x{:02X} ±{accel_g} g ±{gyro_dps} °/s", address as u8);
            lines.push(format!("{what}: {w}"));
            assert!(w.lsb.iter().all(|d| *d <= 1.0), "{what}: {w}");
            total = total.max(w);
        }
    }
    println!("{}\nworst: {total}", lines.join("\n"));
    assert!(total.saturated > 500 && total.negative > 1000, "{total}");
}

#[test]
fn every_full_scale_at_0x68() {
    every_full_scale(false);
}

#[test]
fn every_full_scale_at_0x69() {
    every_full_scale(true);
}

/// `new` leaves the temperature sensor off (its `SixAxisLowNoise` sets TEMP_DIS): TEMP_DATA
/// reads −32768 (DS 4.16 and PWR_MGMT0), so `temperature()` is 25 − 32768 / 132.48 °C.
#[test]
fn new_leaves_the_temperature_sensor_off() {
    let (chip, address) = chip(true);
    let mut icm = Icm::new(connect(&chip), address).unwrap();
    assert_eq!(icm.power_mode().unwrap(), PowerMode::SixAxisLowNoise);
    let warm = PhysicalSample {
        acc: [0.0, 0.0, G as f32],
        temp_c: 30.0,
        ..PhysicalSample::default()
    };
    chip.borrow_mut().latch_at(&warm, PERIOD_NS);
    assert_eq!(icm.temperature_raw().unwrap(), -32768);
    assert!((icm.accel_norm().unwrap().z - 1.0).abs() < 1.0 / 2048.0);
}

/// The wrong address is not acknowledged; the right one is, on either AD0 level.
#[test]
fn only_the_ad0_address_answers() {
    for ad0 in [false, true] {
        let (chip, address) = chip(ad0);
        let other = if ad0 {
            Address::Primary
        } else {
            Address::Secondary
        };
        assert!(matches!(
            Icm::new(connect(&chip), other),
            Err(Error::BusError(_))
        ));
        assert!(Icm::new(connect(&chip), address).is_ok());
    }
}

/// `new_i2c_slew`: soft reset, bank 0, DRIVE_CONFIG's I2C slew rate (bits 5:3), then as `new`.
#[test]
fn new_i2c_slew_resets_and_sets_the_slew_rate() {
    let (chip, address) = chip(true);
    // Something a soft reset must undo.
    let mut icm = Icm::new(connect(&chip), address).unwrap();
    icm.set_accel_range(AccelRange::G2).unwrap();
    let i2c = icm.free();
    let mut delay = ChipDelay {
        clock: Clock::new(),
        chip: chip.clone(),
    };
    let mut icm = Icm::new_i2c_slew(i2c, address, I2cSlewRate::I2cSlwe12ns, &mut delay).unwrap();
    assert_eq!(
        delay.clock.now_ns(),
        5 * 300_000_000,
        "five waits of 1200 × 250 µs"
    );
    assert_eq!(
        chip.borrow().peek(0, 0x13) & 0x38,
        0b011 << 3,
        "DRIVE_CONFIG: I2C_SLEW_RATE"
    );
    assert_eq!(icm.accel_range().unwrap(), AccelRange::G16);
    assert_eq!(chip.borrow().peek(0, 0x4E), 0x2F, "PWR_MGMT0");
    assert_eq!(chip.borrow().peek(0, 0x76), 0, "REG_BANK_SEL");
}

/// `new_fifo` for each packet type, then 20 samples latched 1 ms apart (the ODR it sets) and
/// read in one `read_fifo` burst, each packet decoded by the crate: the codes must be exactly
/// the chip's conversion of the sample (16-bit at ±16 g / ±2000 °/s, 8-bit FIFO temperature,
/// 20-bit; 1 µs timestamp deltas), packet 4's SI values within 1 LSB in the crate's units.
#[test]
fn fifo_packets_over_i2c() {
    let packets = [
        (FifoPacketType::Packet1, 0x05, 0x40, 8),
        (FifoPacketType::Packet2, 0x06, 0x20, 8),
        (FifoPacketType::Packet3, 0x07, 0x68, 16),
        (FifoPacketType::Packet4, 0x17, 0x78, 20),
    ];
    for (n, (kind, config1, header, len)) in packets.into_iter().enumerate() {
        let (chip, address) = chip(n % 2 == 1);
        let mut delay = ChipDelay {
            clock: Clock::new(),
            chip: chip.clone(),
        };
        let mut icm = Icm::new_fifo(connect(&chip), address, kind, &mut delay).unwrap();
        afsr_off(&chip);
        let peek = |addr| chip.borrow().peek(0, addr);
        assert_eq!(peek(0x16), 0x80, "FIFO_CONFIG: stop on full");
        assert_eq!(peek(0x5F), config1, "FIFO_CONFIG1");
        assert_eq!(
            peek(0x54),
            0x37,
            "TMST_CONFIG: TO_REGS, DELTA, (FSYNC), EN; 1 µs"
        );
        assert_eq!(
            (peek(0x4F), peek(0x50)),
            (0x06, 0x06),
            "±2000 °/s, ±16 g, 1 kHz"
        );
        assert_eq!(
            peek(0x4E),
            0x0F,
            "PWR_MGMT0: six axes low noise, temperature on"
        );
        assert_eq!(
            peek(0x48),
            0,
            "its SIGNAL_PATH_RESET (0x48) is reserved: ignored"
        );
        let samples = samples(16.0, 2048.0, 2000.0, 16.4, 42 + n as u64);
        let samples = &samples[..20];
        let mut t = chip.borrow().now_ns();
        for p in samples {
            t += PERIOD_NS;
            chip.borrow_mut().latch_at(p, t);
        }
        let count = (samples.len() * len) as u16;
        // FIFO_COUNTL before FIFO_COUNTH: the first call's low byte is the reset latch (0).
        assert_eq!(icm.read_fifo_cnt().unwrap(), count & 0xFF00);
        assert_eq!(icm.read_fifo_cnt().unwrap(), count);
        let mut buf = vec![0u8; usize::from(count)];
        assert_eq!(icm.read_fifo(0x30, &mut buf).unwrap(), header);
        let mut worst = [0f64; 2];
        for (k, (b, p)) in buf.chunks_exact_mut(len).zip(samples).enumerate() {
            assert_eq!(b[0], header, "{kind:?} {k}");
            let accel16 = p.acc.map(|a| accel_to_raw(a, AccelFs::G16));
            let gyro16 = p.gyr.map(|w| gyro_to_raw(w, GyroFs::Dps2000));
            let temp8 = fifo_temp8(temp_to_raw(p.temp_c));
            let delta = if k == 0 { 0 } else { 1000 };
            match kind {
                FifoPacketType::Packet1 => {
                    let d = FifoDataP1::to_fifodata_raw(b);
                    assert_eq!(([d.ax, d.ay, d.az], d.t), (accel16, temp8), "{kind:?} {k}");
                }
                FifoPacketType::Packet2 => {
                    let d = FifoDataP2::to_fifodata_raw(b);
                    assert_eq!(([d.gx, d.gy, d.gz], d.t), (gyro16, temp8), "{kind:?} {k}");
                }
                FifoPacketType::Packet3 => {
                    let d = FifoDataP3::to_fifodata_raw(b);
                    let got = ([d.ax, d.ay, d.az], [d.gx, d.gy, d.gz], d.t, d.ts);
                    assert_eq!(got, (accel16, gyro16, temp8, delta), "{kind:?} {k}");
                }
                FifoPacketType::Packet4 => {
                    let d = FifoDataP4::to_fifodata_raw(b);
                    let got = ([d.ax, d.ay, d.az], [d.gx, d.gy, d.gz], d.t, d.ts);
                    let want = (
                        p.acc.map(accel_to_raw20),
                        p.gyr.map(gyro_to_raw20),
                        temp_to_raw(p.temp_c),
                        delta,
                    );
                    assert_eq!(got, want, "{kind:?} {k}");
                    // SI: m/s² on its g = 9.81 and rad/s, against the clipped sample in codes
                    // (18-bit accel in steps of 4, 19-bit gyro in steps of 2).
                    let si = FifoDataSiP4::to_fifodata_si(&d);
                    let a_unit = 9.81 / 32768.0;
                    let g_unit = 1.0 / (262.0 * DEG_PER_RAD);
                    for (i, got) in [si.ax, si.ay, si.az].into_iter().enumerate() {
                        let ideal = (f64::from(p.acc[i]) / G * 8192.0).clamp(-131071.0, 131071.0);
                        let dev = (f64::from(got) / a_unit / 4.0 - ideal).abs();
                        worst[0] = worst[0].max(dev);
                    }
                    for (i, got) in [si.gx, si.gy, si.gz].into_iter().enumerate() {
                        let ideal =
                            (f64::from(p.gyr[i]) * DEG_PER_RAD * 131.0).clamp(-262143.0, 262143.0);
                        let dev = (f64::from(got) / g_unit / 2.0 - ideal).abs();
                        worst[1] = worst[1].max(dev);
                    }
                    let temp = (f64::from(si.t) - 25.0) * TEMP_LSB_PER_C;
                    assert!((temp - f64::from(temp_to_raw(p.temp_c))).abs() < 0.01);
                }
            }
        }
        assert!(
            worst.iter().all(|d| *d <= 1.0),
            "{kind:?} SI: {worst:?} LSB"
        );
        // Now empty: the first call pairs the new high byte (0) with the old low byte.
        assert_eq!(
            icm.read_fifo_cnt().unwrap(),
            count & 0x00FF,
            "stale low byte"
        );
        assert_eq!(icm.read_fifo_cnt().unwrap(), 0, "FIFO empty");
    }
}

/// The crate leaves AFSR on (it never writes INTF_CONFIG1): through its own `gyro_raw`, a rate
/// stepping from 90 to 110 °/s at ±2000 °/s reads the 90 °/s value for the 2 ms after the
/// switch, then the live one; with AFSR off (a rig-side write) the step shows at once.
#[test]
fn the_crate_leaves_afsr_on_and_its_gyro_stalls() {
    for afsr in [true, false] {
        let (chip, address) = chip(false);
        let mut icm = Icm::new(connect(&chip), address).unwrap();
        assert_eq!(
            chip.borrow().peek(0, 0x4D),
            0x91,
            "INTF_CONFIG1 at its reset value"
        );
        if !afsr {
            afsr_off(&chip);
        }
        let at_dps = |dps: f64| PhysicalSample {
            gyr: [(dps / DEG_PER_RAD) as f32, 0.0, 0.0],
            ..PhysicalSample::default()
        };
        let (slow, fast) = (gyro_to_raw(at_dps(90.0).gyr[0], GyroFs::Dps2000), 1804);
        assert_eq!(gyro_to_raw(at_dps(110.0).gyr[0], GyroFs::Dps2000), fast);
        let mut xs = Vec::new();
        for (k, dps) in [90.0, 110.0, 110.0, 110.0, 110.0].into_iter().enumerate() {
            chip.borrow_mut()
                .latch_at(&at_dps(dps), (k as u64 + 1) * PERIOD_NS);
            xs.push(icm.gyro_raw().unwrap().x);
        }
        let want = if afsr {
            [slow, slow, slow, fast, fast]
        } else {
            [slow, fast, fast, fast, fast]
        };
        assert_eq!(xs, want, "AFSR {}", if afsr { "on" } else { "off" });
    }
}
