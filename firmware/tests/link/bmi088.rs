//! A BMI088 over the link: Configure's overrides reach both dies (file 0 the accelerometer,
//! file 1 the gyroscope) and leave the accelerometer in I2C mode; on two chip selects it serves
//! every image, the gyro at every sample and the accel at its own ODR; in a rig it takes the
//! chip select after its own, and its second I2C address, and a write to its gyroscope comes
//! back on that select.

use margemu_firmware::chip::{Chip, SpiTarget};
use margemu_protocol::chip::{ChipSettings, FullScale};
use margemu_protocol::link::{AddDevice, Bus, Configure, DeviceBus, ErrorCode, Message};

use crate::common::*;

/// 2 kHz, ns.
const PERIOD_NS: u64 = 500_000;

fn xfer(chip: &mut (impl SpiTarget + ?Sized), mosi: &[u8]) -> Vec<u8> {
    let mut miso = vec![chip.select()];
    for &m in mosi {
        miso.push(chip.exchange(m));
    }
    chip.deselect();
    miso.truncate(mosi.len());
    miso
}

/// A distinct 14-byte image for sample `i` (accel, gyro, TEMP_MSB, TEMP_LSB).
fn bmi_image(i: u64) -> Image {
    let mut im = [0u8; 14];
    for (b, byte) in im.iter_mut().enumerate() {
        *byte = (i.wrapping_mul(37).wrapping_add(b as u64 * 13) & 0xFF) as u8;
    }
    Image::from(im)
}

fn writes(out: &[Out]) -> Vec<(Bus, u8, u8, u8)> {
    out.iter()
        .filter_map(|o| match o {
            Out::Writes(_, w) => Some(w.iter().map(|w| (w.bus, w.address, w.register, w.value))),
            _ => None,
        })
        .flatten()
        .collect()
}

#[test]
fn a_bmi088_is_configured_on_both_dies_and_serves_every_image_on_two_chip_selects() {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    poll(&mut dev, 0);
    let fs = FullScale {
        accel_g: 24.0,
        gyro_dps: 1000.0,
    };
    let settings = ChipSettings::with_full_scale(ChipModel::Bmi088, fs).unwrap();
    let cfg = configure_with(&settings, 2000);
    assert_eq!(
        (cfg.who_am_i, cfg.image_len, cfg.i2c_address),
        (0x1E, 14, 0x18)
    );
    host.configure(&mut dev, cfg);
    let out = poll(&mut dev, 0);
    assert!(out.iter().all(|o| matches!(o, Out::Credit(_))), "{out:?}");
    assert_eq!(dev.chip().settings(), settings);
    let EmulatedChip::Bmi088(chip) = dev.chip() else {
        panic!("a BMI088 was configured")
    };
    assert!(!chip.accel().is_spi_mode(), "the overrides went over I2C");
    assert_eq!([0x40, 0x41].map(|r| chip.accel().peek(r)), [0xAC, 0x03]);
    assert_eq!([0x0F, 0x10].map(|r| chip.gyro().peek(r)), [0x01, 0x80]);

    // The driver (PX4's order): accel dummy read, accel on; the gyro on chip select 1.
    let accel = dev.rig_mut().spi_target(0).unwrap();
    assert_eq!(xfer(accel, &[0x80, 0, 0]), [0, 0, 0]);
    assert_eq!(xfer(accel, &[0x80, 0, 0]), [0, 0, 0x1E]);
    xfer(accel, &[0x7C, 0x00]);
    xfer(accel, &[0x7D, 0x04]);
    let gyro = dev.rig_mut().spi_target(1).unwrap();
    assert_eq!(xfer(gyro, &[0x80, 0]), [0, 0x0F]);
    xfer(gyro, &[0x15, 0x80]); // INT_CTRL data_en
    assert!(dev.rig_mut().spi_target(2).is_none());
    let out = poll(&mut dev, 10);
    assert_eq!(
        writes(&out),
        [
            (Bus::Spi, 0, 0x7C, 0x00),
            (Bus::Spi, 0, 0x7D, 0x04),
            (Bus::Spi, 1, 0x15, 0x80)
        ]
    );

    let images: Vec<Image> = (0..20).map(bmi_image).collect();
    host.images(&mut dev, 0, &images, 10);
    host.start(&mut dev, 0, 10);
    let mut accel_from = 0;
    for (k, image) in images.iter().enumerate() {
        poll(&mut dev, 10 + k as u64 * PERIOD_NS); // scene time 0 is the Start's arrival
        let last = dev.last_served().expect("served");
        assert_eq!((last.index, last.image), (k as u64, Some(*image)));
        let gyro = xfer(
            dev.rig_mut().spi_target(1).unwrap(),
            &[0x82, 0, 0, 0, 0, 0, 0],
        );
        assert_eq!(gyro[1..], image[6..12], "gyro at sample {k}");
        // The accel at 1.6 kHz: a new sample once one of its 625 µs periods has begun.
        let t = k as u64 * PERIOD_NS;
        if k == 0 || t / 625_000 != (t - PERIOD_NS) / 625_000 {
            accel_from = k;
        }
        let accel = xfer(
            dev.rig_mut().spi_target(0).unwrap(),
            &[0x92, 0, 0, 0, 0, 0, 0, 0],
        );
        assert_eq!(accel[1], 0x00, "the dummy byte");
        assert_eq!(accel[2..], images[accel_from][..6], "accel at sample {k}");
        // The temperature of the first sample: the next is due after 1.28 s.
        let temp = xfer(dev.rig_mut().spi_target(0).unwrap(), &[0xA2, 0, 0, 0]);
        assert_eq!(temp[2..], images[0][12..], "temperature at sample {k}");
    }
    assert_eq!(accel_from, 19); // 19 · 500 µs = 9.5 ms, the 16th period of 625 µs
}

/// The rig: a BMI088 (accel on chip select 1, gyro on 2), an ICM-42688-P on 0 and an
/// RM3100 on 3; every chip select reaches its die, and an I2C BMI088 takes both its addresses.
#[test]
fn a_bmi088_in_a_rig_takes_two_chip_selects_and_two_addresses() {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    host.configure(&mut dev, Configure::new(ChipModel::Icm42688p, rate_1khz()));
    let mut bmi = AddDevice::new(ChipModel::Bmi088, DeviceBus::Spi);
    bmi.chip_select = 1;
    host.send(&mut dev, &Message::AddDevice(bmi), 0);
    // Chip select 2 is the BMI088's gyro; 3 is free.
    let mut rm = AddDevice::new(ChipModel::Rm3100, DeviceBus::Spi);
    rm.chip_select = 2;
    host.send(&mut dev, &Message::AddDevice(rm.clone()), 0);
    rm.chip_select = 3;
    host.send(&mut dev, &Message::AddDevice(rm), 0);
    let out = poll(&mut dev, 0);
    assert_eq!(errors(&out), [(ErrorCode::RigRefused, 3)], "{out:?}");
    let rig = dev.rig();
    assert_eq!((rig.len(), rig.image_len()), (3, 32 + 14 + 9));
    let routes = [0, 1, 2, 3, 4].map(|cs| rig.spi_device(cs));
    assert_eq!(
        routes,
        [Some((0, 0)), Some((1, 0)), Some((1, 1)), Some((2, 0)), None]
    );
    let id = |dev: &mut Dev, cs: u8, mosi: &[u8]| xfer(dev.rig_mut().spi_target(cs).unwrap(), mosi);
    assert_eq!(id(&mut dev, 0, &[0xF5, 0])[1], 0x47); // ICM-42688-P WHO_AM_I
    id(&mut dev, 1, &[0x80, 0]); // the accel's switch to SPI
    assert_eq!(id(&mut dev, 1, &[0x80, 0, 0])[2], 0x1E);
    assert_eq!(id(&mut dev, 2, &[0x80, 0])[1], 0x0F);
    assert_eq!(id(&mut dev, 3, &[0xB6, 0])[1], 0x22); // RM3100 REVID
                                                      // A write to the gyro comes back on chip select 2, the accel's on 1.
    id(&mut dev, 2, &[0x0F, 0x04]);
    id(&mut dev, 1, &[0x41, 0x02]);
    let out = poll(&mut dev, 10);
    assert_eq!(
        writes(&out),
        [(Bus::Spi, 1, 0x41, 0x02), (Bus::Spi, 2, 0x0F, 0x04)]
    );

    // On I2C at 0x18 its gyro would answer 0x68, the ICM-42688-P's; at 0x19 it takes 0x69.
    let mut dev = Dev::new();
    host.hello(&mut dev, 2);
    host.configure(&mut dev, Configure::new(ChipModel::Icm42688p, rate_1khz()));
    let bmi = AddDevice::new(ChipModel::Bmi088, DeviceBus::I2c);
    host.send(&mut dev, &Message::AddDevice(bmi.clone()), 0);
    let bmi = AddDevice {
        i2c_address: 0x19,
        ..bmi
    };
    host.send(&mut dev, &Message::AddDevice(bmi), 0);
    assert_eq!(errors(&poll(&mut dev, 0)), [(ErrorCode::RigRefused, 2)]);
    let rig = dev.rig_mut();
    for (address, model) in [(0x19, ChipModel::Bmi088), (0x69, ChipModel::Bmi088)] {
        let chip = rig.i2c_target(address).expect("answered");
        assert_eq!(chip.model(), model, "{address:#04x}");
    }
    assert_eq!(
        rig.i2c_target(0x68).map(|c| c.model()),
        Some(ChipModel::Icm42688p)
    );
}
