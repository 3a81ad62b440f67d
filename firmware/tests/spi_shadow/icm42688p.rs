//! The ICM-42688-P's flight-controller sequences (`tests/icm42688p/fc_*.rs`, Betaflight,
//! ArduPilot, PX4) on a [`Shadowed`] rig: their [`Rig`](fc::Rig) implemented for it. The
//! drivers run their sampling loops at the sample clock: `loop_starts` switches to it.

#[path = "../icm42688p/fc.rs"]
mod fc;
#[path = "../icm42688p/fc_ardupilot.rs"]
mod fc_ardupilot;
#[path = "../icm42688p/fc_betaflight.rs"]
mod fc_betaflight;
#[path = "../icm42688p/fc_px4.rs"]
pub mod fc_px4;

use margemu_firmware::chip::{Chip, EmulatedChip, PhysicalSample};
use margemu_protocol::regmap::icm42688p::image::ImageConfig;

pub use super::common::transactions::spi;
pub use super::{Shadowed, MS, US};
use fc::{Decoded, Run};

impl fc::Rig for Shadowed {
    fn latch(&mut self, sample: &PhysicalSample, now_ns: u64) {
        self.chip_mut().latch_at(sample, now_ns);
    }
    fn int1(&self, now_ns: u64) -> bool {
        self.chip().int_pin_at(now_ns)
    }
    fn image_config(&self) -> ImageConfig {
        match self.chip() {
            EmulatedChip::Icm42688p(chip) => chip.image_config(),
            EmulatedChip::Mpu6xxx(_) | EmulatedChip::Bmi270(_) => {
                panic!("an ICM-42688-P sequence on another chip")
            }
        }
    }
    fn loop_starts(&mut self) {
        super::Rig::set_fast(self, true);
        super::Rig::loop_starts(self);
    }
    fn set_fast(&mut self, fast: bool) {
        super::Rig::set_fast(self, fast);
    }
}

/// What the driver decoded, as bytes (accel then gyro, little-endian), in order.
fn decoded(run: Run) -> Vec<u8> {
    let words = |d: &Decoded| d.accel.into_iter().chain(d.gyro);
    run.samples
        .iter()
        .flat_map(words)
        .flat_map(i32::to_le_bytes)
        .collect()
}

/// Betaflight at 8 kHz: one 15-byte read per data-ready pulse.
pub fn betaflight_8khz(rig: &mut Shadowed, samples: usize) -> Vec<u8> {
    decoded(fc_betaflight::betaflight_sequence(rig, 3, samples))
}

/// Betaflight at 1 kHz.
pub fn betaflight_1khz(rig: &mut Shadowed, samples: usize) -> Vec<u8> {
    decoded(fc_betaflight::betaflight_sequence(rig, 6, samples))
}

/// ArduPilot polling a 1 kHz FIFO, a register read back after every poll.
pub fn ardupilot_1khz(rig: &mut Shadowed, samples: usize) -> Vec<u8> {
    decoded(fc_ardupilot::ardupilot_sequence(rig, false, samples))
}

/// ArduPilot polling an 8 kHz FIFO.
pub fn ardupilot_8khz(rig: &mut Shadowed, samples: usize) -> Vec<u8> {
    decoded(fc_ardupilot::ardupilot_sequence(rig, true, samples))
}

/// PX4: an 8 kHz FIFO read on its threshold interrupt, registers checked in rotation.
pub fn px4(rig: &mut Shadowed, samples: usize) -> Vec<u8> {
    decoded(fc_px4::px4_sequence(rig, samples))
}

/// Whether PX4 checks register `addr` (of some bank) in its loop.
pub fn is_checked(addr: u8) -> bool {
    fc_px4::CONFIG.iter().any(|&(_, reg, _, _)| reg == addr)
}

#[test]
fn driven_directly_every_sample_is_decoded() {
    let rig = || Shadowed::direct(super::icm42688p());
    fc::assert_complete(&fc_betaflight::betaflight_sequence(&mut rig(), 3, 400), 400);
    fc::assert_complete(
        &fc_ardupilot::ardupilot_sequence(&mut rig(), true, 800),
        800,
    );
    fc::assert_complete(&fc_px4::px4_sequence(&mut rig(), 800), 800);
}
