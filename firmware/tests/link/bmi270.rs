//! A BMI270 over the link: Configure's overrides (ranges and both ODRs) reach it over its own
//! I2C and leave it in I2C mode for the driver's first SPI read; the driver's upload and
//! configuration come back as register writes (the INIT_DATA bytes excepted); once
//! initialised, it serves every image, read behind its dummy byte.

use margemu_firmware::chip::SpiTarget;
use margemu_protocol::chip::{ChipSettings, FullScale};
use margemu_protocol::link::Bus;

use crate::common::*;

/// 1.6 kHz, ns.
const PERIOD_NS: u64 = 625_000;

fn xfer(chip: &mut impl SpiTarget, mosi: &[u8]) -> Vec<u8> {
    let mut miso = vec![chip.select()];
    for &m in mosi {
        miso.push(chip.exchange(m));
    }
    chip.deselect();
    miso.truncate(mosi.len());
    miso
}

/// A distinct 14-byte image for sample `i` (accel, gyro, temperature, little-endian).
fn bmi_image(i: u64) -> Image {
    let mut im = [0u8; 14];
    for (b, byte) in im.iter_mut().enumerate() {
        *byte = (i.wrapping_mul(29).wrapping_add(b as u64 * 11) & 0xFF) as u8;
    }
    Image::from(im)
}

#[test]
fn a_bmi270_is_configured_brought_up_by_its_driver_and_serves_every_image() {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    poll(&mut dev, 0);
    let fs = FullScale {
        accel_g: 16.0,
        gyro_dps: 2000.0,
    };
    let settings = ChipSettings::with_full_scale(ChipModel::Bmi270, fs).unwrap();
    let cfg = configure_with(&settings, 1600);
    assert_eq!(
        (cfg.who_am_i, cfg.image_len, cfg.i2c_address),
        (0x24, 14, 0x68)
    );
    host.configure(&mut dev, cfg);
    let out = poll(&mut dev, 0);
    assert!(out.iter().all(|o| matches!(o, Out::Credit(_))), "{out:?}");
    let EmulatedChip::Bmi270(chip) = dev.chip() else {
        panic!("a BMI270 was configured")
    };
    assert!(!chip.is_spi_mode(), "the overrides went over I2C");
    let conf = [0x40, 0x41, 0x42, 0x43].map(|r| chip.peek(r));
    assert_eq!(
        conf,
        [0xAC, 0x03, 0xAC, 0x00],
        "1.6 kHz both, ±16 g, ±2000 °/s"
    );

    // The driver: dummy read, the 328-byte upload, sensors on.
    let chip = dev.chip_mut();
    assert_eq!(xfer(chip, &[0x80, 0, 0]), [0, 0, 0]);
    xfer(chip, &[0x59, 0x00]);
    let mut upload = vec![0x5E];
    upload.resize(1 + 328, 0xC8);
    xfer(chip, &upload);
    xfer(chip, &[0x59, 0x01]);
    assert_eq!(xfer(chip, &[0x80 | 0x21, 0, 0]), [0, 0, 0x01], "init_ok");
    xfer(chip, &[0x7D, 0x0E]);
    let out = poll(&mut dev, 10);
    let writes: Vec<_> = out
        .iter()
        .filter_map(|o| match o {
            Out::Writes(_, w) => Some(w.iter().map(|w| (w.bus, w.register, w.value))),
            _ => None,
        })
        .flatten()
        .collect();
    assert_eq!(
        writes,
        [
            (Bus::Spi, 0x59, 0x00),
            (Bus::Spi, 0x59, 0x01),
            (Bus::Spi, 0x7D, 0x0E)
        ]
    );

    let images: Vec<Image> = (0..20).map(bmi_image).collect();
    host.images(&mut dev, 0, &images, 10);
    host.start(&mut dev, 0, 10);
    for (k, image) in images.iter().enumerate() {
        poll(&mut dev, 10 + k as u64 * PERIOD_NS); // scene time 0 is the Start's arrival
        let last = dev.last_served().expect("served");
        assert_eq!((last.index, last.image), (k as u64, Some(*image)));
        let chip = dev.chip_mut();
        let data = xfer(chip, &[0x80 | 0x0C; 14]);
        assert_eq!(data[1], 0x00, "the dummy byte");
        assert_eq!(data[2..], image[..12], "sample {k}");
        // The temperature is taken every 10 ms: the first image's until 16 samples on.
        let temp = xfer(chip, &[0x80 | 0x22, 0, 0, 0]);
        let temp_of = &images[k - k % 16];
        assert_eq!(temp[2..], temp_of[12..], "temperature at sample {k}");
    }
}
