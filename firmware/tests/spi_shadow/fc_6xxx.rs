//! The MPU-6000 and ICM-20602 flight-controller sequences (`tests/common/fc.rs`: Betaflight,
//! ArduPilot, PX4) on a [`Shadowed`] rig, through that module's [`Bench`]: numbered samples
//! latched at the chip's own output clock while the driver waits. The drivers run their
//! sampling loops at the sample clock: `loop_starts` switches to it.

use margemu_firmware::chip::{Chip, EmulatedChip, PhysicalSample, SpiTarget};

use super::common::fc::{self, ArduPilotOptions, FcRun};
use super::common::{Bench, BenchChip};
use super::{Rig, Shadowed};

impl SpiTarget for &mut Shadowed {
    fn select(&mut self) -> u8 {
        Shadowed::select(self)
    }
    fn exchange(&mut self, mosi: u8) -> u8 {
        Shadowed::exchange(self, mosi)
    }
    fn deselect(&mut self) {
        Shadowed::deselect(self);
    }
}

impl BenchChip for &mut Shadowed {
    fn sample_period_ns(&self) -> u64 {
        self.chip().sample_period_ns()
    }
    fn is_running(&self) -> bool {
        match self.chip() {
            EmulatedChip::Mpu6xxx(chip) => chip.is_running(),
            EmulatedChip::Icm42688p(chip) => chip.is_running(),
            EmulatedChip::Bmi270(chip) => chip.sample_period_ns().is_some(),
            other => panic!("a 6xxx or ICM sequence on a {:?}", other.model()),
        }
    }
    fn latch_at(&mut self, sample: &PhysicalSample, now_ns: u64) {
        self.chip_mut().latch_at(sample, now_ns);
    }
    fn advance(&mut self, now_ns: u64) {
        self.chip_mut().advance(now_ns);
    }
    fn loop_starts(&mut self) {
        self.set_fast(true);
        Rig::loop_starts(*self);
    }
}

/// What the driver decoded, as bytes (accel x, accel z, temperature, gyro x; big-endian).
fn decoded(run: Result<FcRun, fc::FcError>) -> Vec<u8> {
    let run = run.expect("the driver starts");
    run.records
        .iter()
        .flat_map(|r| [r.accel_x, r.accel_z, r.temp, r.gyro_x])
        .flat_map(i16::to_be_bytes)
        .collect()
}

/// Betaflight's MPU-6000 driver at 8 kHz: one 14-byte burst per data-ready edge.
pub fn betaflight(rig: &mut Shadowed, samples: usize) -> Vec<u8> {
    decoded(fc::fc_betaflight(&mut Bench::new(rig), samples))
}

/// ArduPilot's Invensense driver on the MPU-6000, its FIFO at 1 kHz polled every 1 ms.
pub fn ardupilot_1khz(rig: &mut Shadowed, samples: usize) -> Vec<u8> {
    let options = ArduPilotOptions::default();
    decoded(fc::fc_ardupilot(&mut Bench::new(rig), samples, options))
}

/// The same with fast sampling: 8 kHz, 8 records per poll.
pub fn ardupilot_8khz(rig: &mut Shadowed, samples: usize) -> Vec<u8> {
    let options = ArduPilotOptions {
        fast_sampling: true,
        ..ArduPilotOptions::default()
    };
    decoded(fc::fc_ardupilot(&mut Bench::new(rig), samples / 8, options))
}

/// PX4's ICM-20602 driver: its 8 kHz FIFO read in one transfer every 1 ms.
pub fn px4(rig: &mut Shadowed, samples: usize) -> Vec<u8> {
    decoded(fc::px4_icm20602(&mut Bench::new(rig), samples / 8))
}
