//! The BMI270's flight-controller sequences (`tests/bmi270/fc.rs`: Betaflight, ArduPilot) on a
//! [`Shadowed`] rig: their [`Rig`](fc::Rig) implemented for it. Every read of the chip begins
//! with its dummy byte, which the predicted stream and the CPU takeover both serve. The drivers
//! run their sampling loops at the sample clock: `loop_starts` switches to it.
//!
//! **A limit of the shadow path**: a capture holds the address byte and 256 data bytes
//! ([`STREAM_LEN`]), and both drivers write the 328-byte configuration file in one burst: the
//! rest of it is neither stored nor replayed, and the chip reports init_err
//! ([`a_configuration_upload_longer_than_a_capture_is_cut`]). The sequences here bring their
//! upload to the chip directly ([`fc::Rig::upload_burst`]); a board serving a BMI270 over its
//! SPI shadow needs captures at least 330 bytes long for these drivers (the `bmi2` crate's
//! chunked upload fits in any capture length it is configured for).

#[path = "../bmi270/fc.rs"]
mod fc;

use margemu_firmware::chip::{Chip, PhysicalSample, SpiTarget};
use margemu_firmware::spi_shadow::{Outcome, Shadow, STREAM_LEN};

pub use super::Shadowed;
use fc::Run;

impl fc::Rig for Shadowed {
    fn latch(&mut self, sample: &PhysicalSample, now_ns: u64) {
        self.chip_mut().latch_at(sample, now_ns);
    }
    fn advance(&mut self, now_ns: u64) {
        self.chip_mut().advance(now_ns);
    }
    fn now_ns(&self) -> u64 {
        self.chip().now_ns()
    }
    fn int1(&self, now_ns: u64) -> bool {
        self.chip().int_pin_at(now_ns)
    }
    fn loop_starts(&mut self) {
        super::Rig::set_fast(self, true);
        super::Rig::loop_starts(self);
    }
    /// Around the shadow path (see the module docs).
    fn upload_burst(&mut self, file: &[u8]) {
        let chip = self.chip_mut();
        chip.select();
        chip.exchange(0x5E);
        for &b in file {
            chip.exchange(b);
        }
        chip.deselect();
    }
}

/// What the driver decoded, as bytes (accel then gyro, little-endian), in order (the chip's
/// own test crate checks it against what it should be; here it is compared with the run on the
/// chip itself).
fn decoded(run: Run) -> Vec<u8> {
    run.samples
        .iter()
        .flat_map(|d| d.accel.into_iter().chain(d.gyro))
        .flat_map(i16::to_le_bytes)
        .collect()
}

/// Betaflight: gyro 3.2 kHz, accel 800 Hz, one 14-byte read from 0x0C per data-ready edge.
pub fn betaflight(rig: &mut Shadowed, samples: usize) -> Vec<u8> {
    decoded(fc::betaflight(rig, samples))
}

/// ArduPilot: ERR_REG, FIFO_LENGTH and FIFO_DATA polled at 1.6 kHz.
pub fn ardupilot(rig: &mut Shadowed, samples: usize) -> Vec<u8> {
    decoded(fc::ardupilot(rig, samples))
}

#[test]
fn a_configuration_upload_longer_than_a_capture_is_cut() {
    let mut rig = Shadowed::new(super::bmi270());
    fc::read(&mut rig, 0x00, 1); // the dummy read
    fc::write(&mut rig, 0x59, 0x00);
    let mut burst = vec![0x5E];
    burst.extend(fc::config_file(328));
    assert!(burst.len() > STREAM_LEN);
    fc::xfer(&mut rig, &burst);
    let target = rig.target().expect("the shadow path");
    assert_eq!(target.last_outcome(), Some(Outcome::Truncated));
    fc::write(&mut rig, 0x59, 0x01);
    assert_eq!(
        fc::read(&mut rig, 0x21, 1),
        [0x02],
        "init_err: the file was cut"
    );
    // The same file in chunks that fit (as the `bmi2` crate writes it) initialises.
    fc::write(&mut rig, 0x59, 0x00);
    for (i, chunk) in fc::config_file(328).chunks(128).enumerate() {
        let word = i * 64;
        fc::xfer(&mut rig, &[0x5B, (word & 0x0F) as u8, (word >> 4) as u8]);
        let mut burst = vec![0x5E];
        burst.extend_from_slice(chunk);
        fc::xfer(&mut rig, &burst);
    }
    fc::write(&mut rig, 0x59, 0x01);
    assert_eq!(fc::read(&mut rig, 0x21, 1), [0x01]);
}

#[test]
fn a_takeover_serves_the_dummy_byte_first() {
    let mut rig = Shadowed::new(super::bmi270());
    assert_eq!(
        fc::xfer(&mut rig, &[0x80, 0, 0]),
        [0; 3],
        "I2C mode: nothing driven"
    );
    // At the setup clock a read at an address nobody predicted is served by the CPU.
    let miso = fc::xfer(&mut rig, &[0x80 | 0x40, 0, 0, 0]);
    assert_eq!(
        miso,
        [0x00, 0x00, 0xA8, 0x02],
        "address, dummy, ACC_CONF, ACC_RANGE"
    );
    let target = rig.target().expect("the shadow path");
    assert_eq!(target.last_outcome(), Some(Outcome::Fixed));
}

#[test]
fn a_write_through_lands_behind_the_dummy_byte_in_the_stream() {
    let mut chip = super::bmi270();
    chip.select(); // a chip-select toggle: SPI mode
    chip.deselect();
    let mut shadow = Shadow::new();
    shadow.capture(&chip, 0x40, 0);
    assert_eq!(shadow.dummy(), Some(0x00));
    assert_eq!(shadow.stream()[..4], [0x00, 0x00, 0xA8, 0x02]);
    shadow.write_through(&[0x41, 0x01]);
    assert_eq!(shadow.stream()[..4], [0x00, 0x00, 0xA8, 0x01]);
    assert_eq!(shadow.read(0x41), 0x01);
}
