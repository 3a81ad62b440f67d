//! Hit rate of the SPI shadow path on flight-controller register sequences.
//!
//! Each sequence is a driver's register traffic written from its behaviour (no code taken),
//! as a function over a [`Rig`]: an [`SpiTarget`] that can also latch the next sample (the
//! data-ready the driver waits for) and switch between the driver's setup and sample clocks.
//! [`measure`] runs a sequence twice: on the chip itself (the reference) and through
//! [`ShadowTarget`] (the board's path: shadow, `serve` on a simulated port, replay into the
//! chip, speculation, capture), and compares what the driver decoded. The hit rate counts the
//! reads of the sampling loop (after the driver's initialisation) whose every byte was right.
//!
//! **Adding a sequence.** Write `fn(&mut dyn Rig, samples: usize) -> Vec<u8>` (return what the
//! driver decoded, in order) and add a line to [`SEQUENCES`] with a constructor for its chip.
//! A sequence written over its own rig trait (like `tests/icm42688p/fc.rs`'s `Rig`) plugs in
//! by implementing that trait for `ShadowTarget<C>` (SPI is there; `latch` goes to
//! `chip_mut()`), then reading `ShadowTarget::stats()` after the run: see [`report`].

mod fc_mpu;

use margemu_firmware::chip::{Chip, EmulatedChip, PhysicalSample, SpiTarget};
use margemu_firmware::protocol::chip::ChipModel;
use margemu_firmware::spi_shadow::sim::{self, ShadowTarget, Timing, FAST, SLOW};
use margemu_firmware::spi_shadow::Stats;

/// Nanoseconds in a microsecond.
pub const US: u64 = 1_000;
/// Nanoseconds in a millisecond.
pub const MS: u64 = 1_000_000;

/// What a sequence drives.
pub trait Rig: SpiTarget {
    /// Latches sample `k` (see [`sample`]) at `now_ns`: the chip's data-ready.
    fn latch(&mut self, k: u32, now_ns: u64);
    /// The driver's clock from the next transaction on: setup (`false`, ≤ 1 MHz with gaps,
    /// where a board's CPU takeover is in time) or sample (`true`, 8–20 MHz).
    fn set_fast(&mut self, fast: bool);
    /// The driver's initialisation is over: the sampling loop starts.
    fn loop_starts(&mut self);
}

/// A chip driven directly: the reference.
impl<C: Chip> Rig for C {
    fn latch(&mut self, k: u32, now_ns: u64) {
        self.latch_at(&sample(k), now_ns);
    }
    fn set_fast(&mut self, _fast: bool) {}
    fn loop_starts(&mut self) {}
}

/// The shadow path.
pub struct Shadowed<C>(pub ShadowTarget<C>);

impl<C: Chip> SpiTarget for Shadowed<C> {
    fn select(&mut self) -> u8 {
        self.0.select()
    }
    fn exchange(&mut self, mosi: u8) -> u8 {
        self.0.exchange(mosi)
    }
    fn deselect(&mut self) {
        self.0.deselect()
    }
}

impl<C: Chip> Rig for Shadowed<C> {
    fn latch(&mut self, k: u32, now_ns: u64) {
        self.0.chip_mut().latch_at(&sample(k), now_ns);
    }
    fn set_fast(&mut self, fast: bool) {
        self.0.set_timing(if fast { FAST } else { SLOW });
    }
    fn loop_starts(&mut self) {
        self.0.reset_stats();
    }
}

/// Sample `k`: every axis moves with `k`, so a sample served twice or out of order shows.
pub fn sample(k: u32) -> PhysicalSample {
    let t = (k % 1000) as f32;
    PhysicalSample {
        acc: [0.01 * t, -0.02 * t, 9.80665 - 0.003 * t],
        gyr: [0.001 * t, 0.002 * t, -0.0015 * t],
        mag: [20.0, 0.0, -40.0],
        temp_c: 25.0,
    }
}

/// One transaction; returns the MISO of each byte.
pub fn xfer(rig: &mut dyn Rig, mosi: &[u8]) -> Vec<u8> {
    let mut miso = vec![0; mosi.len()];
    let mut next = rig.select();
    for (slot, &m) in miso.iter_mut().zip(mosi) {
        *slot = next;
        next = rig.exchange(m);
    }
    rig.deselect();
    miso
}

/// Writes `value` to `addr`.
pub fn write(rig: &mut dyn Rig, addr: u8, value: u8) {
    xfer(rig, &[addr & 0x7F, value]);
}

/// Reads one register.
pub fn read(rig: &mut dyn Rig, addr: u8) -> u8 {
    xfer(rig, &[0x80 | addr, 0])[1]
}

/// Reads `n` bytes from `addr` in one burst.
pub fn burst(rig: &mut dyn Rig, addr: u8, n: usize) -> Vec<u8> {
    let mut mosi = vec![0x80 | addr];
    mosi.resize(n + 1, 0);
    xfer(rig, &mosi)[1..].to_vec()
}

/// A driver's register traffic over `samples` samples; returns what it decoded.
pub type Sequence = fn(&mut dyn Rig, usize) -> Vec<u8>;

/// Builds the chip a sequence drives, just powered on.
pub type NewChip = fn() -> EmulatedChip;

/// Every sequence measured: name, chip, sequence.
pub const SEQUENCES: &[(&str, NewChip, Sequence)] = &[
    ("betaflight-mpu9250", mpu9250, fc_mpu::betaflight),
    ("ardupilot-mpu9250", mpu9250, fc_mpu::ardupilot),
    ("px4-mpu9250", mpu9250, fc_mpu::px4),
];

fn mpu9250() -> EmulatedChip {
    EmulatedChip::new(ChipModel::Mpu9250, 0x71, 0x68).expect("an emulated model")
}

/// Samples each sequence runs over.
const SAMPLES: usize = 2000;

/// What one sequence measured through the shadow path.
pub struct Measured {
    /// The outcomes of the sampling loop's transactions.
    pub stats: Stats,
    /// Whether the driver decoded the same through the shadow path as from the chip itself
    /// (not when a read missed: a learning miss at the loop's start is enough).
    pub decoded_same: bool,
    /// [`ShadowTarget::divergences`].
    pub divergences: u32,
}

/// Runs `sequence` on the chip and through the shadow path.
pub fn measure(chip: NewChip, sequence: Sequence, samples: usize) -> Measured {
    let mut direct = chip();
    let want = sequence(&mut direct, samples);
    let mut shadowed = Shadowed(ShadowTarget::new(chip(), SLOW));
    let got = sequence(&mut shadowed, samples);
    Measured {
        stats: shadowed.0.stats(),
        decoded_same: got == want,
        divergences: shadowed.0.divergences(),
    }
}

/// Prints one line of figures and returns the hit rate (reads with every byte right).
pub fn report(name: &str, stats: &Stats) -> f64 {
    let reads = stats.reads();
    let rate = f64::from(stats.served_right()) / f64::from(reads.max(1));
    println!(
        "{name:<22} reads {reads:>5}  hit {:>5}  fixed {:>4}  miss {:>3}  stale {:>2}  \
         truncated {:>2}  writes {:>4}  hit rate {:.2} %",
        stats.hits,
        stats.fixed,
        stats.misses,
        stats.stale,
        stats.truncated,
        stats.writes,
        100.0 * rate
    );
    rate
}

#[test]
fn flight_controller_sequences_hit_at_least_99_percent() {
    for &(name, chip, sequence) in SEQUENCES {
        let m = measure(chip, sequence, SAMPLES);
        let rate = report(name, &m.stats);
        assert_eq!(
            m.divergences, 0,
            "{name}: the simulation handed out other bytes"
        );
        assert!(rate >= 0.99, "{name}: hit rate {:.2} %", 100.0 * rate);
        println!(
            "{name:<22} decoded as from the chip itself: {}",
            m.decoded_same
        );
    }
}

#[test]
fn the_old_rule_alone_misses_the_count_then_data_pair() {
    // The pair alternates two starts, so no start is seen in 4 consecutive bursts: without
    // the successor table every loop read would have missed. The fallback stays unlearned.
    let mut shadowed = Shadowed(ShadowTarget::new(mpu9250(), SLOW));
    fc_mpu::ardupilot(&mut shadowed, 200);
    assert_eq!(shadowed.0.speculator().fallback(), None);
}

#[test]
fn transfer_drives_any_target() {
    let mut chip = mpu9250();
    let mut miso = [0u8; 2];
    sim::transfer(&mut chip, &[0x80 | 0x75, 0], &mut miso);
    assert_eq!(miso, [0x00, 0x71]);
    let _: Timing = FAST;
}
