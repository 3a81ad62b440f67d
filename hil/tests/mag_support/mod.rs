//! Shared by the magnetometer client tests (`driver_ist8310.rs`, `driver_qmc5883l.rs`): the
//! emulated chips' time, a test bench that latches fields at explicit instants, a driver delay
//! that moves the chip's clock, known fields and the "within one LSB" check.
#![allow(dead_code)] // each test file uses its own part

use margemu_firmware::chip::{Chip, Ist8310, PhysicalSample, Qmc5883l};
use margemu_hil::bus::{Clock, Shared};

/// One millisecond in the chips' nanoseconds.
pub const MS: u64 = 1_000_000;

/// A chip driven by time through its chip boundary: a field latched at an instant, or the
/// clock moved on with the field it holds.
pub trait MagChip: Chip {
    /// Moves the chip's clock to `now_ns` with `field_ut` sensed from then on.
    fn sense(&mut self, now_ns: u64, field_ut: [f32; 3]) {
        let sample = PhysicalSample {
            mag: field_ut,
            ..PhysicalSample::default()
        };
        Chip::latch_at(self, &sample, now_ns);
    }
}

impl MagChip for Ist8310 {}
impl MagChip for Qmc5883l {}

/// The bench side of one chip: its clock and the field it senses.
pub struct Bench<C> {
    pub chip: Shared<C>,
    pub clock: Clock,
}

impl<C: MagChip> Bench<C> {
    pub fn new(chip: Shared<C>) -> Self {
        Self {
            chip,
            clock: Clock::new(),
        }
    }

    /// Lets time run to `now_ns` with the field held so far (measurements due by then complete
    /// with it), then holds `field_ut` from `now_ns` on.
    pub fn latch(&self, now_ns: u64, field_ut: [f32; 3]) {
        self.run_to(now_ns);
        self.chip.borrow_mut().sense(now_ns, field_ut);
    }

    /// Lets time run to `now_ns` with the field held so far.
    pub fn run_to(&self, now_ns: u64) {
        self.clock
            .advance_ns(now_ns.saturating_sub(self.clock.now_ns()));
        let mut chip = self.chip.borrow_mut();
        Chip::advance(&mut *chip, self.clock.now_ns());
    }

    /// The driver's delay on this bench's clock.
    pub fn delay(&self) -> ChipDelay<C> {
        ChipDelay {
            chip: self.chip.clone(),
            clock: self.clock.clone(),
        }
    }
}

/// The embedded-hal 0.2 `DelayMs<u8>` a driver waits with: returns at once, having moved the
/// bench's clock and the chip's time on by what was asked (the field stays as held).
pub struct ChipDelay<C> {
    chip: Shared<C>,
    clock: Clock,
}

impl<C: MagChip> embedded_hal_02::blocking::delay::DelayMs<u8> for ChipDelay<C> {
    fn delay_ms(&mut self, ms: u8) {
        self.clock.advance_ns(u64::from(ms) * MS);
        let mut chip = self.chip.borrow_mut();
        Chip::advance(&mut *chip, self.clock.now_ns());
    }
}

/// Fractions of full scale every axis takes in turn (all inside the range): zero, small,
/// negative, just inside both ends.
const FRACTIONS: [f32; 12] = [
    0.0, 0.25, -0.25, 0.5, -0.61, 0.999, -0.999, 0.05, -0.013, 0.77, 0.33, -0.9,
];

/// Multiples of one LSB, for the smallest fields.
const LSBS: [f32; 5] = [1.0, -1.0, 0.5, -1.5, 2.0];

/// Known fields (µT, chip axes) inside `full_scale_ut`: each axis a different fraction of its
/// full scale, then a few LSB (`lsb_ut`) on each axis, then an Earth-like field.
pub fn fields_inside(full_scale_ut: [f32; 3], lsb_ut: f32) -> Vec<[f32; 3]> {
    let n = FRACTIONS.len();
    let mut out: Vec<[f32; 3]> = (0..n)
        .map(|i| core::array::from_fn(|a| FRACTIONS[(i + 5 * a) % n] * full_scale_ut[a]))
        .collect();
    out.extend((0..LSBS.len()).map(|i| {
        let k = |a: usize| LSBS[(i + a) % LSBS.len()];
        [k(0) * lsb_ut, k(1) * lsb_ut, k(2) * lsb_ut]
    }));
    out.push([21.5, -1.2, 43.9]);
    out
}

/// Fields beyond `full_scale_ut` on one axis or more.
pub fn fields_beyond(full_scale_ut: [f32; 3]) -> Vec<[f32; 3]> {
    let [x, y, z] = full_scale_ut;
    vec![
        [1.2 * x, 0.0, 0.0],
        [0.1 * x, -1.5 * y, 0.3 * z],
        [-3.0 * x, 2.0 * y, -1.01 * z],
    ]
}

/// How far, in LSB, a raw reading is from the field at `lsb_per_ut`, clipped at `±max_raw`.
pub fn lsb_error(got: i16, field_ut: f32, lsb_per_ut: f32, max_raw: i16) -> f32 {
    let max = f32::from(max_raw);
    let ideal = (field_ut * lsb_per_ut).clamp(-max, max);
    (f32::from(got) - ideal).abs()
}

/// Asserts that `got` is within one LSB of `field_ut` on every axis (sample `k`).
pub fn assert_within_one_lsb(
    k: usize,
    got: [i16; 3],
    field_ut: [f32; 3],
    lsb_per_ut: f32,
    max_raw: [i16; 3],
) {
    for a in 0..3 {
        let err = lsb_error(got[a], field_ut[a], lsb_per_ut, max_raw[a]);
        assert!(
            err <= 1.0,
            "sample {k}, axis {a}: read {got:?} for {field_ut:?} µT ({err} LSB off)"
        );
    }
}
