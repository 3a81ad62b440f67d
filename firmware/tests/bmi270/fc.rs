//! Flight-controller sequences on the BMI270, written from the drivers' behaviour (no code
//! taken), reusable on other bus paths: a sequence drives any [`Rig`] (an SPI target that can
//! also latch samples, keep time and show its INT1 level) and returns a [`Run`]: what the
//! driver decoded and what it should have decoded, in order.
//!
//! - [`betaflight`] (`src/main/drivers/accgyro/accgyro_spi_bmi270.c`): chip-select toggle to
//!   select SPI, CHIP_ID, soft reset, toggle, the 328-byte upload without a check, accel 800 Hz
//!   ±16 g, gyro 3.2 kHz ±2000 °/s, data ready on INT1 (push-pull, active high, pulsed), then
//!   one 14-byte read from ACC_X_LSB (address, dummy, 12 data bytes) per rising edge. The
//!   accel runs at a quarter of the gyro's rate: every fourth read brings a new accel sample.
//! - [`ardupilot`] (`libraries/AP_InertialSensor/AP_InertialSensor_BMI270.cpp`): dummy read,
//!   soft reset through its read-back write (CMD never reads back: sent 8 times), dummy read,
//!   CHIP_ID, PWR_CONF 0, INIT_CTRL 0, the 328-byte upload, INIT_CTRL 1, 20 ms, init_ok in
//!   INTERNAL_STATUS, up to 5 tries; then every configuration write read back (accel 1.6 kHz
//!   ±16 g, gyro 3.2 kHz ±2000 °/s with the OIS bit, FIFO stop-on-full with headers, gyro and
//!   accel, FIFO_DOWNS 0x89: the gyro halved to 1.6 kHz, PWR_CONF 2, PWR_CTRL 0x0E, a FIFO flush);
//!   then at 1.6 kHz: ERR_REG (fifo_err: flush), FIFO_LENGTH, at most 8 frames of FIFO_DATA,
//!   parsed by header (0x8C, 0x88, 0x84; 0x80 resets the FIFO), the temperature every 100 polls.

#![allow(dead_code)]

use margemu_firmware::chip::bmi270::Bmi270;
use margemu_firmware::chip::{PhysicalSample, SpiTarget};

/// Nanoseconds in a millisecond.
pub const MS: u64 = 1_000_000;
/// The gyro period at 3.2 kHz.
pub const GYRO_3K2_NS: u64 = 312_500;
/// Standard gravity, m/s².
const G: f32 = 9.80665;

/// What a sequence needs of the device under test besides SPI.
pub trait Rig: SpiTarget {
    /// Latches `sample` taken at `now_ns`.
    fn latch(&mut self, sample: &PhysicalSample, now_ns: u64);
    /// Moves the chip's clock to `now_ns` (the driver waits).
    fn advance(&mut self, now_ns: u64);
    /// The chip's clock.
    fn now_ns(&self) -> u64;
    /// The INT1 level at `now_ns`.
    fn int1(&self, now_ns: u64) -> bool;
    /// The driver's initialisation is over: its sampling loop starts.
    fn loop_starts(&mut self) {}
    /// The configuration file written to INIT_DATA in one SPI burst (a rig whose bus path
    /// cannot carry a transaction that long may bring it to the chip another way).
    fn upload_burst(&mut self, file: &[u8])
    where
        Self: Sized,
    {
        let mut burst = vec![0x5E];
        burst.extend_from_slice(file);
        xfer(self, &burst);
    }
}

impl Rig for Bmi270 {
    fn latch(&mut self, sample: &PhysicalSample, now_ns: u64) {
        self.latch_at(sample, now_ns);
    }
    fn advance(&mut self, now_ns: u64) {
        Bmi270::advance(self, now_ns);
    }
    fn now_ns(&self) -> u64 {
        Bmi270::now_ns(self)
    }
    fn int1(&self, now_ns: u64) -> bool {
        self.int_pin_at(now_ns)
    }
}

/// A sample as a driver decodes it: raw counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Decoded {
    pub accel: [i16; 3],
    pub gyro: [i16; 3],
}

/// The outcome of one sequence.
#[derive(Clone, Debug, Default)]
pub struct Run {
    /// What the driver decoded, in order.
    pub samples: Vec<Decoded>,
    /// What it should have decoded, in order.
    pub expected: Vec<Decoded>,
    /// FIFO resets after the initialisation.
    pub fifo_resets: usize,
    /// Temperatures the driver read (raw, 0x8000 skipped as the driver does).
    pub temperatures: Vec<i16>,
    /// Initialisation tries (ArduPilot).
    pub init_tries: usize,
    /// FIFO frames with one sensor only (ArduPilot parses them; its configuration gives none).
    pub single_frames: usize,
}

/// Sample `n`: at ±16 g / ±2000 °/s its registers read accel (n, −2n, 2048), gyro (n, 3, −n);
/// 23 °C + n/512 K.
pub fn sample(n: i16) -> PhysicalSample {
    let n = f32::from(n);
    let dps = core::f32::consts::PI / 180.0;
    PhysicalSample {
        acc: [n * G / 2048.0, -2.0 * n * G / 2048.0, G],
        gyr: [n / 16.4 * dps, 3.0 / 16.4 * dps, -n / 16.4 * dps],
        mag: [0.0; 3],
        temp_c: 23.0 + n / 512.0,
    }
}

/// Accel of sample `a`, gyro of sample `g`, as the registers hold them.
pub fn decoded(a: i16, g: i16) -> Decoded {
    Decoded {
        accel: [a, -2 * a, 2048],
        gyro: [g, 3, -g],
    }
}

/// One SPI transaction, full duplex: the MISO of each MOSI byte.
pub fn xfer(rig: &mut impl Rig, mosi: &[u8]) -> Vec<u8> {
    let mut miso = Vec::with_capacity(mosi.len());
    let mut next = rig.select();
    for &m in mosi {
        miso.push(next);
        next = rig.exchange(m);
    }
    rig.deselect();
    miso
}

/// A read of `n` registers from `reg`: address, dummy byte, data; returns the data.
pub fn read(rig: &mut impl Rig, reg: u8, n: usize) -> Vec<u8> {
    let mut mosi = vec![0x80 | reg];
    mosi.resize(n + 2, 0);
    xfer(rig, &mosi).split_off(2)
}

/// A one-byte write.
pub fn write(rig: &mut impl Rig, reg: u8, value: u8) {
    xfer(rig, &[reg & 0x7F, value]);
}

/// Waits `ns` (the driver's delay).
fn wait(rig: &mut impl Rig, ns: u64) {
    let now = rig.now_ns();
    rig.advance(now + ns);
}

/// A stand-in for Bosch's 328-byte configuration file (the chip checks its length only).
pub fn config_file(len: usize) -> Vec<u8> {
    (0..len).map(|i| (i * 7 + 3) as u8).collect()
}

fn le(bytes: &[u8], at: usize) -> i16 {
    i16::from_le_bytes([bytes[at], bytes[at + 1]])
}

fn axes(bytes: &[u8], at: usize) -> [i16; 3] {
    [le(bytes, at), le(bytes, at + 2), le(bytes, at + 4)]
}

/// Betaflight at gyro 3.2 kHz / accel 800 Hz over `n` samples (see the module docs).
pub fn betaflight(rig: &mut impl Rig, n: usize) -> Run {
    rig.select(); // bmi270EnableSPI: chip select low, then high
    rig.deselect();
    assert_eq!(read(rig, 0x00, 1), [0x24], "CHIP_ID");
    write(rig, 0x7E, 0xB6);
    wait(rig, 100 * MS);
    rig.select();
    rig.deselect();
    write(rig, 0x7C, 0x00);
    wait(rig, MS);
    write(rig, 0x59, 0x00);
    wait(rig, MS);
    rig.upload_burst(&config_file(328));
    wait(rig, 10 * MS);
    write(rig, 0x59, 0x01);
    for (reg, value) in [
        (0x40, 0xAB), // ACC_CONF: performance, normal filter, 800 Hz
        (0x41, 0x03), // ACC_RANGE: ±16 g
        (0x42, 0xED), // GYR_CONF: performance, normal filter, 3.2 kHz
        (0x43, 0x08), // GYR_RANGE: ±2000 °/s (with the OIS range bit)
        (0x58, 0x04), // INT_MAP_DATA: data ready on INT1
        (0x53, 0x0A), // INT1_IO_CTRL: output, push-pull, active high
        (0x7C, 0x02), // PWR_CONF
        (0x7D, 0x0E), // PWR_CTRL: accel, gyro, temperature
    ] {
        write(rig, reg, value);
        wait(rig, MS);
    }
    let mut run = Run::default();
    let t0 = 200 * MS; // on the accel's 1.25 ms grid
    rig.loop_starts();
    let mut was_high = rig.int1(rig.now_ns());
    for k in 0..n {
        let t = t0 + k as u64 * GYRO_3K2_NS;
        let kk = k as i16;
        rig.latch(&sample(kk), t);
        run.expected.push(decoded(kk - kk % 4, kk));
        let high = rig.int1(t);
        if high && !was_high {
            let mut mosi = [0u8; 14];
            mosi[0] = 0x80 | 0x0C;
            let b = xfer(rig, &mosi);
            run.samples.push(Decoded {
                accel: axes(&b, 2),
                gyro: axes(&b, 8),
            });
        }
        was_high = rig.int1(t + GYRO_3K2_NS / 2);
    }
    run
}

/// ArduPilot's `write_register`: write, read back, up to 8 tries; whether it read back.
fn write_verified(rig: &mut impl Rig, reg: u8, value: u8) -> bool {
    for _ in 0..8 {
        write(rig, reg, value);
        if read(rig, reg, 1) == [value] {
            return true;
        }
    }
    false
}

/// ArduPilot's `hardware_init` with a configuration file of `file_len` bytes; returns whether
/// it initialised and the tries it took.
pub fn ardupilot_init(rig: &mut impl Rig, file_len: usize) -> (bool, usize) {
    wait(rig, 5 * MS);
    for tries in 1..=5 {
        read(rig, 0x00, 1); // the dummy read: switches to SPI
        wait(rig, MS);
        assert!(!write_verified(rig, 0x7E, 0xB6), "CMD never reads back");
        wait(rig, 5 * MS);
        read(rig, 0x00, 1);
        wait(rig, MS);
        if read(rig, 0x00, 1) != [0x24] {
            continue;
        }
        write(rig, 0x7C, 0x00); // PWR_CONF, no read-back
        wait(rig, MS);
        write_verified(rig, 0x59, 0x00);
        rig.upload_burst(&config_file(file_len));
        write_verified(rig, 0x59, 0x01);
        wait(rig, 20 * MS);
        if read(rig, 0x21, 1)[0] & 1 == 1 {
            return (true, tries);
        }
    }
    (false, 5)
}

/// ArduPilot: initialisation, configuration with read-back, then `polls` FIFO polls at
/// 1.6 kHz while the chip latches at 3.2 kHz (see the module docs).
pub fn ardupilot(rig: &mut impl Rig, polls: usize) -> Run {
    let mut run = Run::default();
    let (ok, tries) = ardupilot_init(rig, 328);
    assert!(ok, "init_ok");
    run.init_tries = tries;
    for (reg, value) in [
        (0x40, 0x8C), // ACC_CONF: performance, OSR4, 1.6 kHz
        (0x41, 0x03), // ACC_RANGE: ±16 g
        (0x42, 0xED), // GYR_CONF: performance, normal, 3.2 kHz
        (0x43, 0x08), // GYR_RANGE: ±2000 °/s with the OIS range bit
        (0x48, 0x01), // FIFO_CONFIG_0: stop on full
        (0x49, 0xD0), // FIFO_CONFIG_1: gyro, accel, headers
        (0x45, 0x89), // FIFO_DOWNS: filtered data, gyro halved
        (0x7C, 0x02), // PWR_CONF: FIFO self-wake-up
        (0x7D, 0x0E), // PWR_CTRL: accel, gyro, temperature
    ] {
        assert!(write_verified(rig, reg, value), "{reg:#04x} reads back");
    }
    write_verified(rig, 0x7E, 0xB0); // fifo_reset: CMD never reads back, 8 flushes
    let t0 = 300 * MS; // on the 625 µs grid
    rig.loop_starts();
    let mut k = 0i16;
    for poll in 0..polls {
        for _ in 0..2 {
            let t = t0 + u64::from(k as u16) * GYRO_3K2_NS;
            rig.latch(&sample(k), t);
            if k % 2 == 0 {
                run.expected.push(decoded(k, k));
            }
            k += 1;
        }
        ardupilot_poll(rig, &mut run, poll);
    }
    run
}

/// One `read_fifo` call.
fn ardupilot_poll(rig: &mut impl Rig, run: &mut Run, poll: usize) {
    if read(rig, 0x02, 1)[0] & 0x40 != 0 {
        write_verified(rig, 0x7E, 0xB0);
        run.fifo_resets += 1;
        return;
    }
    let len = read(rig, 0x24, 2);
    let mut fifo_length = usize::from(u16::from_le_bytes([len[0], len[1]]));
    if fifo_length & 0x8000 != 0 || fifo_length == 0 {
        return;
    }
    fifo_length = fifo_length.min(8 * 13);
    let data = read(rig, 0x26, fifo_length);
    let mut p = 0;
    while fifo_length >= 12 {
        let frame_len = match data[p] & 0xFC {
            0x84 | 0x88 => {
                run.single_frames += 1;
                7
            }
            0x8C => {
                run.samples.push(Decoded {
                    gyro: axes(&data, p + 1),
                    accel: axes(&data, p + 7),
                });
                13
            }
            0x40 | 0x50 => 2,
            0x44 => 4,
            0x48 => 5,
            0x80 => {
                write_verified(rig, 0x7E, 0xB0);
                run.fifo_resets += 1;
                return;
            }
            _ => 2,
        };
        p += frame_len;
        fifo_length -= frame_len;
    }
    if poll % 100 == 99 {
        let t = read(rig, 0x22, 2);
        let raw = u16::from_le_bytes([t[0], t[1]]);
        if raw != 0x8000 {
            run.temperatures.push(raw as i16);
        }
    }
}
