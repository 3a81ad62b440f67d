//! The `bmi2` crate (0.1.2, MIT, embedded-hal 1.0), unmodified, drives the emulated BMI270 over
//! I2C (`margemu_hil::bus::I2c`): its full 8 KB configuration upload, then data and FIFO reads
//! at every range it sets.
//!
//! What the crate does (read in `bmi2-0.1.2/src`, not its docs):
//! - `Bmi2::init(&BMI270_CONFIG_FILE)` (`bmi2.rs`): CHIP_ID (0x24, 0x27 or 0xD1), soft reset,
//!   2 ms, PWR_CONF adv_power_save off (read-modify-write, 450 µs), INIT_CTRL 0, then Bosch's
//!   8192-byte file in chunks of `Burst` − 2 bytes (254 here), each preceded by INIT_ADDR_0/1 =
//!   its word offset, INIT_CTRL 1, adv_power_save back on, 20 ms, and `Err(InitFailed)` unless
//!   INTERNAL_STATUS bit 0 is set.
//! - `get_data()`: one burst of 15 bytes from 0x0C (accel, gyro, SENSORTIME), little-endian;
//!   `get_temperature()`: 0x22/0x23, `None` for 0x8000, else raw / 512 + 23 °C;
//!   `set_acc_range`, `set_gyr_range` (range and OIS range), `set_acc_conf`, `set_gyr_conf`,
//!   `set_pwr_ctrl`, `set_fifo_conf` (FIFO_CONFIG_0/1 in one write), `set_fifo_downs`,
//!   `get_fifo_len`.
//! - `get_fifo_data()` is a stub that reads nothing (its comment: "TODO Fifo is 6KB"): the FIFO
//!   is read here through a second I2C adapter on the same chip, as the crate's own `read`
//!   does a register read (pointer, repeated START, bytes).
//! - Over SPI the crate cannot talk to a BMI270: its `SpiInterface` sets bit 7 on *writes* and
//!   leaves it clear on reads, and takes the second byte of a read, which is the BMI270's dummy
//!   byte (DS 6.2). `the_crates_spi_interface_never_reads_the_chip_id` shows the emulated chip
//!   refusing it as the silicon would.
//!
//! Each value is checked against the sample latched, at the datasheet's sensitivities typed here
//! independently of margemu's conversions: within one LSB, clipped at the 16-bit limits.

use bmi2::interface::{I2cAddr, I2cInterface};
use bmi2::types::{
    AccBwp, AccConf, AccRange, Burst, Error, FifoConf, FifoDowns, FifoTagIntEnable, FilterData,
    GyrBwp, GyrConf, GyrRange, GyrRangeVal, Odr, OisRange, PerfMode, PwrCtrl,
};
use bmi2::Bmi2;
use embedded_hal::i2c::I2c as _;
use margemu_firmware::chip::{Bmi270, PhysicalSample};
use margemu_hil::bus::{self, Clock, Delay, I2c, Shared, SpiDevice};

/// Standard gravity, m/s² per g.
const G: f64 = 9.80665;
/// The I2C address with SDO low.
const ADDRESS: u8 = 0x68;
/// Periods at 1.6 and 3.2 kHz, ns.
const P1600: u64 = 625_000;
const P3200: u64 = 312_500;
/// 10 ms, the temperature's update period.
const MS10: u64 = 10_000_000;

type Driver = Bmi2<I2cInterface<I2c<Bmi270>>, Delay, 256>;

/// A fresh chip initialised by the crate, the clock after its delays.
fn init() -> (Shared<Bmi270>, Driver, Clock) {
    let chip = bus::shared(Bmi270::new());
    let clock = Clock::new();
    let delay = Delay::with_clock(clock.clone());
    let i2c = I2c::new(chip.clone());
    let mut bmi: Driver = Bmi2::new_i2c(i2c, delay, I2cAddr::Default, Burst::new(256));
    bmi.init(&bmi2::config::BMI270_CONFIG_FILE)
        .unwrap_or_else(|e| panic!("init: {e:?}"));
    chip.borrow_mut().advance(clock.now_ns());
    (chip, bmi, clock)
}

/// Accel and gyro ranges the crate sets, with their datasheet sensitivities.
fn acc_ranges() -> [(AccRange, f64, f64); 4] {
    [
        (AccRange::Range2g, 2.0, 16384.0),
        (AccRange::Range4g, 4.0, 8192.0),
        (AccRange::Range8g, 8.0, 4096.0),
        (AccRange::Range16g, 16.0, 2048.0),
    ]
}

fn gyr_ranges() -> [(GyrRangeVal, f64, f64); 5] {
    [
        (GyrRangeVal::Range2000, 2000.0, 16.4),
        (GyrRangeVal::Range1000, 1000.0, 32.8),
        (GyrRangeVal::Range500, 500.0, 65.6),
        (GyrRangeVal::Range250, 250.0, 131.2),
        (GyrRangeVal::Range125, 125.0, 262.4),
    ]
}

/// Ranges, rates and sensors through the crate, and the FIFO with headers, gyro and accel.
fn configure(bmi: &mut Driver, acc: AccRange, gyr: GyrRangeVal, gyr_odr: Odr) {
    bmi.disable_power_save().unwrap();
    let acc_conf = AccConf {
        odr: Odr::Odr1k6,
        bwp: AccBwp::NormAvg4,
        filter_perf: PerfMode::Perf,
    };
    bmi.set_acc_conf(acc_conf).unwrap();
    bmi.set_acc_range(acc).unwrap();
    let gyr_conf = GyrConf {
        odr: gyr_odr,
        bwp: GyrBwp::Norm,
        noise_perf: PerfMode::Perf,
        filter_perf: PerfMode::Perf,
    };
    bmi.set_gyr_conf(gyr_conf).unwrap();
    let range = GyrRange {
        range: gyr,
        ois_range: OisRange::Range2000,
    };
    bmi.set_gyr_range(range).unwrap();
    let fifo = FifoConf {
        stop_on_full: true,
        time_enable: false,
        tag_int1_en: FifoTagIntEnable::IntEdge,
        tag_int2_en: FifoTagIntEnable::IntEdge,
        header_enable: true,
        aux_enable: false,
        acc_enable: true,
        gyr_enable: true,
    };
    bmi.set_fifo_conf(fifo).unwrap();
    let downs = FifoDowns {
        gyr_downs: 0,
        gyr_filt_data: FilterData::Filtered,
        acc_downs: 0,
        acc_filt_data: FilterData::Filtered,
    };
    bmi.set_fifo_downs(downs).unwrap();
    bmi.send_cmd(bmi2::types::Cmd::FifoFlush).unwrap();
    let on = PwrCtrl {
        aux_en: false,
        gyr_en: true,
        acc_en: true,
        temp_en: true,
    };
    bmi.set_pwr_ctrl(on).unwrap();
}

/// A deterministic spread of samples as fractions of full scale: edges first (zero, ±full
/// scale, beyond it, one LSB), then xorshift values up to ±1.3; temperatures −40 to 85 °C.
fn samples(n: usize, acc_fs_g: f64, gyr_fs_dps: f64) -> Vec<PhysicalSample> {
    let edges = [
        0.0,
        1.0,
        -1.0,
        1.3,
        -1.3,
        0.5,
        -0.5,
        1.0 / 32768.0,
        -1.0 / 32768.0,
    ];
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 * 2.6 - 1.3
    };
    (0..n)
        .map(|i| {
            let u: [f64; 6] = match edges.get(i) {
                Some(&e) => [e, -e, 0.25 * e, -e, e, 0.75 * e],
                None => std::array::from_fn(|_| next()),
            };
            let acc = [u[0], u[1], u[2]].map(|v| (v * acc_fs_g * G) as f32);
            let gyr = [u[3], u[4], u[5]].map(|v| (v * gyr_fs_dps).to_radians() as f32);
            let temp_c = -40.0 + 125.0 * (i % 50) as f32 / 49.0;
            PhysicalSample {
                acc,
                gyr,
                temp_c,
                ..Default::default()
            }
        })
        .collect()
}

/// `got` is `physical · lsb_per_unit`, clipped to 16 bits, within one LSB.
fn check(got: i16, physical: f64, lsb_per_unit: f64, what: &str) {
    let want = (physical * lsb_per_unit).clamp(-32768.0, 32767.0);
    assert!(
        (f64::from(got) - want).abs() <= 1.0,
        "{what}: read {got}, expected {want:.3}"
    );
}

/// Accel (at `lsb` LSB/g) of sample `s`.
fn check_acc(acc: [i16; 3], s: &PhysicalSample, lsb: f64, what: &str) {
    for (axis, (&got, &a)) in acc.iter().zip(&s.acc).enumerate() {
        check(got, f64::from(a) / G, lsb, &format!("{what} accel {axis}"));
    }
}

/// Gyro (at `lsb` LSB/(°/s)) of sample `s`.
fn check_gyr(gyr: [i16; 3], s: &PhysicalSample, lsb: f64, what: &str) {
    for (axis, (&got, &w)) in gyr.iter().zip(&s.gyr).enumerate() {
        check(
            got,
            f64::from(w).to_degrees(),
            lsb,
            &format!("{what} gyro {axis}"),
        );
    }
}

/// Accel and gyro of sample `s` at sensitivities `lsb` (LSB/g, LSB/(°/s)).
fn check_sample(acc: [i16; 3], gyr: [i16; 3], s: &PhysicalSample, lsb: (f64, f64), what: &str) {
    check_acc(acc, s, lsb.0, what);
    check_gyr(gyr, s, lsb.1, what);
}

/// The FIFO's bytes, read as a register read of FIFO_DATA (the crate's `get_fifo_data` is a
/// stub).
fn read_fifo(chip: &Shared<Bmi270>, len: usize) -> Vec<u8> {
    let mut i2c = I2c::new(chip.clone());
    let mut bytes = vec![0; len];
    i2c.write_read(ADDRESS, &[0x26], &mut bytes).unwrap();
    bytes
}

fn le3(b: &[u8]) -> [i16; 3] {
    std::array::from_fn(|i| i16::from_le_bytes([b[2 * i], b[2 * i + 1]]))
}

#[test]
fn the_crate_uploads_8k_and_reads_every_sample_at_every_range() {
    let (chip, mut bmi, clock) = init();
    assert!(chip.borrow().is_initialized(), "INTERNAL_STATUS init_ok");
    assert_eq!(
        bmi.get_internal_status().map(|s| s.message as u8).ok(),
        Some(1)
    );
    assert!(!chip.borrow().is_spi_mode(), "I2C all along");
    let n = 60;
    let mut now = clock.now_ns().div_ceil(MS10) * MS10;
    for (i, (gyr, gyr_fs, gyr_lsb)) in gyr_ranges().into_iter().enumerate() {
        let (acc, acc_fs, acc_lsb) = acc_ranges().into_iter().nth(i % 4).unwrap();
        configure(&mut bmi, acc, gyr, Odr::Odr1k6);
        let what = format!("±{acc_fs} g, ±{gyr_fs} °/s");
        let lsb = (acc_lsb, gyr_lsb);
        let batch = samples(n, acc_fs, gyr_fs);
        now = (now / MS10 + 1) * MS10;
        for (k, s) in batch.iter().enumerate() {
            chip.borrow_mut().latch_at(s, now + k as u64 * P1600);
            let d = bmi.get_data().unwrap();
            let (a, g) = ([d.acc.x, d.acc.y, d.acc.z], [d.gyr.x, d.gyr.y, d.gyr.z]);
            check_sample(a, g, s, lsb, &format!("{what}, data {k}"));
            if k == 0 {
                // The first latch after PWR_CTRL takes the temperature (then every 10 ms).
                let t = bmi.get_temperature().unwrap().expect("a valid temperature");
                assert!((t - s.temp_c).abs() <= 1.0 / 512.0, "{what}: {t} °C");
            }
        }
        now += n as u64 * P1600;
        // Every sample in the FIFO, in order: 60 frames of 13 bytes.
        let len = bmi.get_fifo_len().unwrap();
        assert_eq!(len, 13 * n as i16, "{what}: FIFO length");
        let bytes = read_fifo(&chip, 13 * n);
        for (k, (frame, s)) in bytes.chunks(13).zip(&batch).enumerate() {
            assert_eq!(frame[0], 0x8C, "{what}: frame {k} header");
            check_sample(
                le3(&frame[7..]),
                le3(&frame[1..]),
                s,
                lsb,
                &format!("{what}, FIFO {k}"),
            );
        }
        assert_eq!(bmi.get_fifo_len().unwrap(), 0, "{what}: FIFO read empty");
    }
}

#[test]
fn at_3200_hz_the_crate_reads_the_accel_every_second_sample() {
    let (chip, mut bmi, clock) = init();
    configure(
        &mut bmi,
        AccRange::Range16g,
        GyrRangeVal::Range2000,
        Odr::Odr3k2,
    );
    let lsb = (2048.0, 16.4);
    let batch = samples(40, 16.0, 2000.0);
    let t0 = (clock.now_ns() / MS10 + 1) * MS10;
    for (k, s) in batch.iter().enumerate() {
        chip.borrow_mut().latch_at(s, t0 + k as u64 * P3200);
        let d = bmi.get_data().unwrap();
        let (a, g) = ([d.acc.x, d.acc.y, d.acc.z], [d.gyr.x, d.gyr.y, d.gyr.z]);
        // The accelerometer (1.6 kHz) took the even samples only.
        check_acc(a, &batch[k - k % 2], lsb.0, &format!("data {k}"));
        check_gyr(g, s, lsb.1, &format!("data {k}"));
    }
    // The FIFO: gyro-only frames (0x88) between the frames with both (0x8C).
    let len = usize::try_from(bmi.get_fifo_len().unwrap()).unwrap();
    assert_eq!(len, 20 * 13 + 20 * 7);
    let bytes = read_fifo(&chip, len);
    let mut headers = Vec::new();
    let mut p = 0;
    while p < bytes.len() {
        headers.push(bytes[p]);
        p += if bytes[p] == 0x8C { 13 } else { 7 };
    }
    assert_eq!(headers, [0x8C, 0x88].repeat(20));
}

#[test]
fn a_truncated_upload_fails_init() {
    let chip = bus::shared(Bmi270::new());
    let clock = Clock::new();
    let i2c = I2c::new(chip.clone());
    let mut bmi: Driver = Bmi2::new_i2c(
        i2c,
        Delay::with_clock(clock),
        I2cAddr::Default,
        Burst::new(256),
    );
    let file = &bmi2::config::BMI270_CONFIG_FILE[..4096];
    assert!(matches!(bmi.init(file), Err(Error::InitFailed)));
    assert!(!chip.borrow().is_initialized());
}

#[test]
fn the_crates_spi_interface_never_reads_the_chip_id() {
    let chip = bus::shared(Bmi270::new());
    let spi = SpiDevice::new(chip.clone());
    let mut bmi: Bmi2<_, Delay, 256> = Bmi2::new_spi(spi, Delay::new(), Burst::new(256));
    // Its CHIP_ID read is a *write* of register 0x00 (no read flag), and it takes the dummy
    // byte's position for the value: 0x00, whatever the mode.
    assert!(matches!(bmi.get_chip_id(), Ok(0x00)));
    assert!(matches!(
        bmi.init(&bmi2::config::BMI270_CONFIG_FILE),
        Err(Error::InvalidChipId)
    ));
}
