//! The `bmi088` crate (0.2.1, embedded-hal 1.0, BSD-3-Clause), unmodified, drives the emulated
//! BMI088's two dies, each on its own chip select (`margemu_hil::bus::SpiDevice` over a shared
//! [`Bmi088Accel`] and [`Bmi088Gyro`]).
//!
//! What the crate does (read in `bmi088-0.2.1/src`, not its docs):
//! - `Accelerometer::setup`: ACC_SOFTRESET = 0xB6, 5 ms, up to five reads of ACC_CHIP_ID for
//!   0x1E (10 ms apart), ACC_PWR_CTRL = 0x04, 50 ms. It never reads the accelerometer's dummy
//!   CHIP_ID first, so its first transaction, the soft reset, reaches a die still in I2C mode:
//!   the reset is lost, and that transaction's chip-select edge is what switches the die to SPI
//!   (harmless right after power-on). It never writes ACC_PWR_CONF (0x03, "suspend", at reset):
//!   it follows DS 3 (quick start), where ACC_PWR_CTRL = 4 alone enters normal mode, which the
//!   emulation follows too. It has no accelerometer range setter: data stays at the reset range,
//!   ±6 g (5461.33 LSB/g). `get_accel` reads 8 bytes from 0x12 and drops the dummy byte.
//! - `Gyroscope::setup`: GYRO_SOFTRESET = 0xB6, 100 ms, GYRO_CHIP_ID 0x0F, `set_range(2000)`
//!   (GYRO_RANGE 0x00), `set_bandwidth(1000)`, GYRO_LPM1 = 0. `set_range(dps)` writes ±1000 °/s
//!   for anything below 2000. **Crate bug**: `set_bandwidth` swaps its two codes: asking for
//!   less than 2000 Hz writes 0x01 (2000 Hz, 230 Hz filter), asking for 2000 Hz writes 0x02
//!   (1000 Hz): its default "1000 Hz" runs the gyro at 2 kHz. `get_gyro` reads 7 bytes from 0x02.
//! - The crate's I2C interface is `unimplemented!()`; only SPI is usable.
//!
//! Each value the crate returns is checked against the latched sample to within one LSB at the
//! ranges the crate can set (accel ±6 g; gyro ±2000 and ±1000 °/s), sample by sample, in order,
//! with one sample latched at each die's output rate before each read.

use bmi088::{Accelerometer, Builder, Gyroscope, SpiInterface};
use margemu_firmware::chip::bmi088::{Bmi088Accel, Bmi088Gyro};
use margemu_firmware::chip::PhysicalSample;
use margemu_hil::bus::{self, Clock, Delay, Shared, SpiDevice};

const G: f64 = 9.80665;

type Accel = Accelerometer<SpiInterface<SpiDevice<Bmi088Accel>>>;
type Gyro = Gyroscope<SpiInterface<SpiDevice<Bmi088Gyro>>>;

/// Both dies powered on, each set up by the crate.
struct Board {
    accel_chip: Shared<Bmi088Accel>,
    gyro_chip: Shared<Bmi088Gyro>,
    accel: Accel,
    gyro: Gyro,
    clock: Clock,
}

fn board() -> Board {
    let accel_chip = bus::shared(Bmi088Accel::new());
    let gyro_chip = bus::shared(Bmi088Gyro::new());
    let clock = Clock::new();
    let mut delay = Delay::with_clock(clock.clone());
    let mut accel = Builder::new_accel_spi(SpiDevice::new(accel_chip.clone()));
    accel.setup(&mut delay).expect("accel setup");
    let mut gyro = Builder::new_gyro_spi(SpiDevice::new(gyro_chip.clone()));
    gyro.setup(&mut delay).expect("gyro setup");
    accel_chip.borrow_mut().advance(clock.now_ns());
    gyro_chip.borrow_mut().advance(clock.now_ns());
    Board {
        accel_chip,
        gyro_chip,
        accel,
        gyro,
        clock,
    }
}

/// A deterministic spread: zero, ±full scale and beyond first, then xorshift values up to 1.3 ×
/// full scale on every axis.
fn samples(n: usize, accel_fs_g: f64, gyro_fs_dps: f64) -> Vec<PhysicalSample> {
    let edges = [0.0, 1.0, -1.0, 0.5, -0.25, 0.999, -0.999, 1.3, -1.3];
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut unit = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 * 2.6 - 1.3
    };
    (0..n)
        .map(|i| {
            let u: [f64; 3] = match edges.get(i) {
                Some(&e) => [e, -e, e * 0.5],
                None => [unit(), unit(), unit()],
            };
            PhysicalSample {
                acc: u.map(|v| (v * accel_fs_g * G) as f32),
                gyr: u.map(|v| (v * gyro_fs_dps).to_radians() as f32),
                mag: [0.0; 3],
                temp_c: 25.0,
            }
        })
        .collect()
}

/// `got` is `physical · lsb_per_unit` to within one LSB, saturating as the chip does.
fn assert_within_1_lsb(got: i16, physical: f64, lsb_per_unit: f64, what: &str) {
    let want = (physical * lsb_per_unit).clamp(-32768.0, 32767.0);
    assert!(
        (f64::from(got) - want).abs() <= 1.0,
        "{what}: the crate read {got}, the sample is {want:.2} LSB"
    );
}

/// Latches each sample one period after the last and reads it back through the crate.
fn check_accel(b: &mut Board, samples: &[PhysicalSample], lsb_per_g: f64) {
    let period = b.accel_chip.borrow().sample_period_ns().expect("accel on");
    for (i, s) in samples.iter().enumerate() {
        b.clock.advance_ns(period);
        b.accel_chip.borrow_mut().latch_at(s, b.clock.now_ns());
        let got = b.accel.get_accel().expect("get_accel");
        for (axis, (&raw, &a)) in got.iter().zip(&s.acc).enumerate() {
            let what = format!("accel {i} axis {axis}");
            assert_within_1_lsb(raw, f64::from(a) / G, lsb_per_g, &what);
        }
    }
}

fn check_gyro(b: &mut Board, samples: &[PhysicalSample], lsb_per_dps: f64) {
    let period = b
        .gyro_chip
        .borrow()
        .sample_period_ns()
        .expect("gyro normal");
    for (i, s) in samples.iter().enumerate() {
        b.clock.advance_ns(period);
        b.gyro_chip.borrow_mut().latch_at(s, b.clock.now_ns());
        let got = b.gyro.get_gyro().expect("get_gyro");
        for (axis, (&raw, &w)) in got.iter().zip(&s.gyr).enumerate() {
            let what = format!("gyro {i} axis {axis}");
            assert_within_1_lsb(raw, f64::from(w).to_degrees(), lsb_per_dps, &what);
        }
    }
}

#[test]
fn the_crate_sets_up_both_dies() {
    let b = board();
    let accel = b.accel_chip.borrow();
    assert!(accel.is_spi_mode());
    assert!(accel.is_on());
    assert_eq!([accel.peek(0x7C), accel.peek(0x7D)], [0x03, 0x04]); // PWR_CONF never written
    assert_eq!(accel.peek(0x41), 0x01); // ±6 g, the reset range
    assert_eq!(accel.sample_period_ns(), Some(10_000_000)); // 100 Hz, the reset ODR
    let gyro = b.gyro_chip.borrow();
    assert_eq!(
        [gyro.peek(0x0F), gyro.peek(0x10), gyro.peek(0x11)],
        [0x00, 0x81, 0x00]
    );
    // The crate asked for 1000 Hz; its swapped codes give 2000 Hz (see the module docs).
    assert_eq!(gyro.sample_period_ns(), Some(500_000));
    // The delays the crate waited: 5 + 50 ms (accel) and 100 ms (gyro).
    assert_eq!(b.clock.now_ns(), 155_000_000);
}

#[test]
fn every_accel_sample_in_order_at_the_reset_range() {
    let mut b = board();
    let lsb_per_g = 32768.0 / (1.5 * 4.0); // DS 5.3.4 at ACC_RANGE = 1
    check_accel(&mut b, &samples(500, 6.0, 2000.0), lsb_per_g);
}

#[test]
fn every_gyro_sample_in_order_at_both_ranges_it_sets() {
    let mut b = board();
    check_gyro(&mut b, &samples(500, 16.0, 2000.0), 16.384);
    b.gyro.set_range(1000).expect("set_range");
    assert_eq!(b.gyro_chip.borrow().peek(0x0F), 0x01);
    check_gyro(&mut b, &samples(500, 16.0, 1000.0), 32.768);
    b.gyro.set_range(2000).expect("set_range");
    check_gyro(&mut b, &samples(100, 16.0, 2000.0), 16.384);
}

#[test]
fn both_dies_interleaved_at_their_own_rates() {
    let mut b = board();
    let s = samples(400, 6.0, 2000.0);
    // 20 gyro samples (2 kHz) per accel sample (100 Hz): the accel keeps its last sample.
    let mut last_accel: Option<&PhysicalSample> = None;
    for (i, sample) in s.iter().enumerate() {
        b.clock.advance_ns(500_000);
        let now = b.clock.now_ns();
        b.gyro_chip.borrow_mut().latch_at(sample, now);
        if i % 20 == 0 {
            b.accel_chip.borrow_mut().latch_at(sample, now);
            last_accel = Some(sample);
        }
        let gyro = b.gyro.get_gyro().expect("get_gyro");
        let accel = b.accel.get_accel().expect("get_accel");
        let want_accel = last_accel.expect("latched at i = 0");
        for axis in 0..3 {
            let dps = f64::from(sample.gyr[axis]).to_degrees();
            assert_within_1_lsb(gyro[axis], dps, 16.384, &format!("gyro {i}"));
            let in_g = f64::from(want_accel.acc[axis]) / G;
            assert_within_1_lsb(accel[axis], in_g, 32768.0 / 6.0, &format!("accel {i}"));
        }
    }
}
