//! The harness the flight-controller sequences run on, reusable for other bus paths: a
//! sequence drives any [`Rig`] (an SPI target that can also latch samples and show its INT1
//! level) and returns a [`Run`]: every SPI transaction in order, the samples the driver decoded
//! and the samples it should have decoded, so a test can check that none was lost or repeated.

use margemu_firmware::chip::{Icm42688p, PhysicalSample, SpiTarget};
use margemu_protocol::regmap::icm42688p::image::{ImageConfig, ImageRepr};

/// Standard gravity, m/s².
const G: f32 = 9.80665;

/// What a sequence needs of the device under test besides SPI: sample injection and INT1.
pub trait Rig: SpiTarget {
    /// Latches `sample` taken at `now_ns`.
    fn latch(&mut self, sample: &PhysicalSample, now_ns: u64);
    /// The INT1 level at `now_ns`.
    fn int1(&self, now_ns: u64) -> bool;
    /// The conversion settings of the chip right now.
    fn image_config(&self) -> ImageConfig;
    /// The driver's initialisation is over: its sampling loop starts (a rig measuring the bus
    /// counts from here, at the driver's sample clock).
    fn loop_starts(&mut self) {}
    /// The driver's SPI clock from the next transaction on: its sample clock (`true`, from
    /// [`Rig::loop_starts`] on) or its low register clock (`false`).
    fn set_fast(&mut self, _fast: bool) {}
}

impl Rig for Icm42688p {
    fn latch(&mut self, sample: &PhysicalSample, now_ns: u64) {
        self.latch_at(sample, now_ns);
    }
    fn int1(&self, now_ns: u64) -> bool {
        self.int_pin_at(now_ns)
    }
    fn image_config(&self) -> ImageConfig {
        Icm42688p::image_config(self)
    }
}

/// A sample whose register values at ±16 g / ±2000 °/s are small integers: accel x = `n` LSB,
/// y = −2n, z = 1 g (2048); gyro x = n (at 16.4 LSB/(°/s)), y = 3, z = −n; 25 °C.
pub fn sample(n: i16) -> PhysicalSample {
    let n = f32::from(n);
    let dps = core::f32::consts::PI / 180.0;
    PhysicalSample {
        acc: [n * G / 2048.0, -2.0 * n * G / 2048.0, G],
        gyr: [n / 16.4 * dps, 3.0 / 16.4 * dps, -n / 16.4 * dps],
        mag: [0.0; 3],
        temp_c: 25.0,
    }
}

/// One SPI transaction, MOSI and MISO aligned.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Transaction {
    pub mosi: Vec<u8>,
    pub miso: Vec<u8>,
}

/// A sample as a driver decodes it (raw counts in the driver's own resolution).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Decoded {
    pub accel: [i32; 3],
    pub gyro: [i32; 3],
}

/// The outcome of one sequence.
#[derive(Clone, Debug, Default)]
pub struct Run {
    pub transactions: Vec<Transaction>,
    /// What the driver decoded, in order.
    pub samples: Vec<Decoded>,
    /// What it should have decoded: every latched sample, in order.
    pub expected: Vec<Decoded>,
    /// FIFO resets the driver made after initialisation (bad header, overflow).
    pub fifo_resets: usize,
    /// Register read-backs that did not match what the driver wrote.
    pub register_mismatches: usize,
}

/// Records every transaction a sequence makes on its rig.
pub struct Recorder<'a, R: Rig> {
    pub rig: &'a mut R,
    pub run: Run,
}

impl<'a, R: Rig> Recorder<'a, R> {
    pub fn new(rig: &'a mut R) -> Self {
        Self {
            rig,
            run: Run::default(),
        }
    }

    /// One transaction; returns MISO.
    pub fn xfer(&mut self, mosi: &[u8]) -> Vec<u8> {
        let miso = super::spi(self.rig, mosi);
        self.run.transactions.push(Transaction {
            mosi: mosi.to_vec(),
            miso: miso.clone(),
        });
        miso
    }

    pub fn write(&mut self, addr: u8, value: u8) {
        self.xfer(&[addr, value]);
    }

    pub fn read(&mut self, addr: u8) -> u8 {
        self.xfer(&[0x80 | addr, 0])[1]
    }

    /// Reads `n` bytes from `addr` in one burst.
    pub fn burst(&mut self, addr: u8, n: usize) -> Vec<u8> {
        let mut mosi = vec![0x80 | addr];
        mosi.resize(n + 1, 0);
        self.xfer(&mosi)[1..].to_vec()
    }

    /// Latches sample `k` at `now_ns` and records what a driver should decode from it:
    /// `shift` = (accel, gyro) right shifts of the 20-bit values, or `None` for 16-bit data.
    pub fn latch(&mut self, k: i16, now_ns: u64, shift: Option<(u32, u32)>) {
        let s = sample(k);
        let repr = ImageRepr::from_physical(s.acc, s.gyr, s.temp_c, &self.rig.image_config());
        self.rig.latch(&s, now_ns);
        self.run.expected.push(match shift {
            None => Decoded {
                accel: repr.accel.map(i32::from),
                gyro: repr.gyro.map(i32::from),
            },
            Some((a, g)) => Decoded {
                accel: repr.accel20.map(|v| v >> a),
                gyro: repr.gyro20.map(|v| v >> g),
            },
        });
    }
}

/// Checks a run: every sample decoded once, in order.
pub fn assert_complete(run: &Run, n: usize) {
    assert_eq!(run.expected.len(), n);
    assert_eq!(
        run.samples.len(),
        run.expected.len(),
        "samples lost or repeated"
    );
    for (i, (got, want)) in run.samples.iter().zip(&run.expected).enumerate() {
        assert_eq!(got, want, "sample {i}");
    }
    assert_eq!(run.fifo_resets, 0);
    assert_eq!(run.register_mismatches, 0);
}
