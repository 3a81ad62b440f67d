//! The BMI270 behind the chip boundary: `EmulatedChip`, settings, register overrides, images,
//! and what the SPI shadow reads of it (the dummy byte, FIFO pops on a copy, plain writes).

use super::*;
use margemu_firmware::chip::{Chip, EmulatedChip};
use margemu_protocol::chip::{ChipModel, ChipSettings, FullScale};

fn emulated(address: u8) -> EmulatedChip {
    EmulatedChip::new(ChipModel::Bmi270, 0x24, address).expect("the BMI270 is emulated")
}

#[test]
fn emulated_chip_identity_and_addresses() {
    assert!(EmulatedChip::models().any(|m| m == ChipModel::Bmi270));
    assert!(EmulatedChip::new(ChipModel::Bmi270, 0x47, 0x68).is_none());
    assert!(EmulatedChip::new(ChipModel::Bmi270, 0x24, 0x0C).is_none());
    let mut c = emulated(0x69);
    assert_eq!(
        (c.model(), Chip::i2c_address(&c)),
        (ChipModel::Bmi270, 0x69)
    );
    assert_eq!(i2c_read(&mut c, 0x69, 0x00, 1), Some(vec![0x24]));
}

#[test]
fn overrides_go_over_i2c_and_leave_the_chip_for_the_drivers_dummy_read() {
    let mut c = emulated(0x68);
    let fs = FullScale {
        accel_g: 4.0,
        gyro_dps: 250.0,
    };
    let want = ChipSettings::with_full_scale(ChipModel::Bmi270, fs).unwrap();
    for (file, reg, value) in want.config_writes(800.0) {
        assert!(c.write_register(file, reg, value));
    }
    assert!(!c.write_register(1, 0x41, 0x00), "one register file");
    assert_eq!(c.settings(), want);
    assert_eq!(
        c.sample_period_ns(),
        1_250_000,
        "gyro 800 Hz (off: still its rate)"
    );
    assert_eq!(c.pop_write().map(|w| w.register), Some(0x41));
    // Still in I2C mode: the device under test's first SPI read is its dummy read.
    assert_eq!(spi(&mut c, &[0x80 | 0x41, 0, 0]), [0, 0, 0]);
    assert_eq!(spi(&mut c, &[0x80 | 0x41, 0, 0]), [0, 0, 0x01]);
    // Once in SPI mode, overrides go over SPI.
    assert!(c.write_register(0, 0x41, 0x03));
    assert_eq!(read1(&mut c, 0x41), 0x03);
}

#[test]
fn an_image_latches_as_its_physical_sample_would() {
    let mut by_image = ready_chip();
    let mut by_sample = ready_chip();
    for c in [&mut by_image, &mut by_sample] {
        spi_write(c, 0x40, &[0xAC, 0x01, 0xAC, 0x02]); // ±4 g, ±500 °/s
        spi_write(c, 0x7D, &[0x0E]);
    }
    let s = fc::sample(77);
    let image = Chip::settings(&by_image).image(&s);
    Chip::latch_image_at(&mut by_image, &image, MS);
    Chip::latch_at(&mut by_sample, &s, MS);
    assert_eq!(
        read(&mut by_image, 0x00, 0x7F),
        read(&mut by_sample, 0x00, 0x7F)
    );
    assert_eq!(read(&mut by_image, 0x0C, 12), image[..12]);
    assert_eq!(read(&mut by_image, 0x22, 2), image[12..]);
    // A short image latches nothing; the clock moves on.
    Chip::latch_image_at(&mut by_image, &image[..13], 2 * MS);
    assert_eq!(Chip::now_ns(&by_image), 2 * MS);
    assert_eq!(read(&mut by_image, 0x0C, 12), image[..12]);
}

#[test]
fn what_the_spi_shadow_reads() {
    let c = chip();
    // I2C mode: an SPI read gives 0x00 everywhere and a write does nothing.
    assert_eq!((c.spi_peek(0x00), c.spi_read_dummy()), (0x00, None));
    assert_eq!(c.spi_plain_write(0x41, 0x01), None);
    let mut burst = [0xAA; 3];
    c.spi_read_burst(0x00, &mut burst);
    assert_eq!(burst, [0; 3]);
    let mut c = ready_chip();
    spi_write(&mut c, 0x40, &[0xAC, 0x03, 0xAC]);
    spi_write(&mut c, 0x48, &[0x01, 0xD0]);
    spi_write(&mut c, 0x7D, &[0x0E]);
    c.latch_at(&fc::sample(9), MS);
    assert_eq!((c.spi_peek(0x00), c.spi_read_dummy()), (0x24, Some(0x00)));
    assert_eq!(c.burst_start(), 0x0C);
    // The burst is what MISO carries after the address byte: the dummy byte first.
    let mut burst = [0; 13];
    c.spi_read_burst(0x0C, &mut burst);
    assert_eq!(burst[..3], [0x00, 9, 0]);
    assert_eq!(burst[1..], read(&mut c, 0x0C, 12)[..]);
    // FIFO_DATA: the frame on a copy, the chip's FIFO untouched.
    let mut frame = [0; 14];
    c.spi_read_burst(0x26, &mut frame);
    assert_eq!(frame[..4], [0x00, 0x8C, 9, 0]);
    assert_eq!(read(&mut c, 0x24, 2), [13, 0]);
    // Plain writes store through the mask; commands, the upload and power do more.
    assert_eq!(c.spi_plain_write(0x41, 0xFF), Some(0x03));
    assert_eq!(c.spi_plain_write(0x53, 0xFF), Some(0x1E));
    for reg in [0x7E, 0x59, 0x5E, 0x7D, 0x55, 0x00, 0x21] {
        assert_eq!(c.spi_plain_write(reg, 0x01), None, "{reg:#04x}");
    }
    assert_eq!(
        (c.spi_next_address(0x26), c.spi_next_address(0x0C)),
        (0x26, 0x0D)
    );
}
