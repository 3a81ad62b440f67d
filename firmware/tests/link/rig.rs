//! Rigs: AddDevice after Configure, rig images latched into every device at once, and every
//! refusal with its code and detail.

use crate::common::*;
use margemu_firmware::chip::{Chip, I2cTarget};
use margemu_protocol::link::{
    AddDevice, Configure, DeviceBus, ErrorCode, Message, ModelParams, RegisterOverride, Source,
    CRC32C,
};

fn add(host: &mut Host, dev: &mut Dev, a: AddDevice) {
    host.send(dev, &Message::AddDevice(a), 0);
}

/// An ICM-42688-P rig with an IST8310 on I2C and an MPU-6000 on chip select 1.
fn rig() -> (Dev, Host) {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    host.configure(&mut dev, Configure::new(ChipModel::Icm42688p, rate_1khz()));
    add(
        &mut host,
        &mut dev,
        AddDevice::new(ChipModel::Ist8310, DeviceBus::I2c),
    );
    let mut mpu = AddDevice::new(ChipModel::Mpu6000, DeviceBus::Spi);
    mpu.chip_select = 1;
    add(&mut host, &mut dev, mpu);
    let out = poll(&mut dev, 0);
    assert_eq!(errors(&out), [], "{out:?}");
    (dev, host)
}

#[test]
fn a_rig_image_latches_every_device_at_once() {
    let (mut dev, mut host) = rig();
    assert_eq!((dev.rig().len(), dev.rig().image_len()), (3, 32 + 6 + 14));
    // The IST8310 measures once triggered: CNTL1 = 1 through its I2C target.
    let mag = dev
        .rig_mut()
        .i2c_target(0x0E)
        .expect("the IST8310 answers 0x0E");
    assert_eq!(mag.model(), ChipModel::Ist8310);
    assert!(mag.start(0x0E, false) && mag.write(0x0A) && mag.write(0x01));
    mag.stop();
    // The ICM's sensors on (PWR_MGMT0 = 0x0F), or its data registers read "off" (-32768).
    assert!(dev
        .rig_mut()
        .chip_mut(0)
        .unwrap()
        .write_register(0, 0x4E, 0x0F));
    // The MPU-6000 awake (PWR_MGMT_1 = 0x01), or it keeps its registers at reset.
    assert!(dev
        .rig_mut()
        .chip_mut(2)
        .unwrap()
        .write_register(0, 0x6B, 0x01));
    let mut bytes = [0u8; 52];
    for (i, b) in bytes.iter_mut().enumerate() {
        *b = i as u8;
    }
    let rig_image = Image::new(&bytes).unwrap();
    host.images(&mut dev, 0, &[rig_image; 20], 0);
    host.start_scene(&mut dev, 20, 0);
    let out = poll(&mut dev, 30 * MS);
    let served = served(&out);
    assert_eq!(served.len(), 20, "{out:?}");
    assert_eq!(served[0].1.crc32c, CRC32C.checksum(&bytes));
    // Each device holds its slice: the ICM's TEMP_DATA1.., the IST8310's data (after its
    // 1 ms single measurement), the MPU-6000's ACCEL_XOUT_H...
    let icm = dev.rig().chip(0).unwrap();
    assert_eq!([icm.spi_peek(0x1D), icm.spi_peek(0x1E)], [0, 1]);
    let mut mpu_burst = [0u8; 14];
    dev.rig()
        .chip(2)
        .unwrap()
        .spi_read_burst(0x3B, &mut mpu_burst);
    assert_eq!(mpu_burst, core::array::from_fn(|i| 38 + i as u8));
    let mag = dev.rig_mut().i2c_target(0x0E).unwrap();
    assert!(mag.start(0x0E, false) && mag.write(0x03));
    assert!(mag.start(0x0E, true));
    let data: Vec<u8> = (0..6).map(|_| mag.read()).collect();
    mag.stop();
    assert_eq!(data, (32..38).collect::<Vec<u8>>());
    assert_eq!(dev.rig().spi_device(1), Some((2, 0))); // the MPU-6000
    let mpu = dev.rig_mut().spi_target(1).unwrap();
    mpu.select();
    assert_eq!(mpu.exchange(0x80 | 0x75), 0x68); // WHO_AM_I, clocked out next
    mpu.deselect();
    assert!(dev.rig_mut().spi_target(2).is_none());
}

#[test]
fn images_of_one_device_are_refused_once_the_rig_has_more() {
    let (mut dev, mut host) = rig();
    host.images(&mut dev, 0, &[Image::from([0u8; 32])], 0);
    let out = poll(&mut dev, 0);
    assert_eq!(errors(&out), [(ErrorCode::MalformedMessage, 32)]);
}

#[test]
fn add_device_refusals_say_why() {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    host.configure(&mut dev, Configure::new(ChipModel::Icm42688p, rate_1khz()));
    let mut mpu = AddDevice::new(ChipModel::Mpu6000, DeviceBus::Spi);
    (mpu.chip_select, mpu.i2c_address) = (1, 0x69);
    add(&mut host, &mut dev, mpu.clone());
    assert_eq!(errors(&poll(&mut dev, 0)), []);
    // Chip select 1 is the MPU-6000's; I2C 0x68 is device 0's.
    add(&mut host, &mut dev, mpu);
    add(
        &mut host,
        &mut dev,
        AddDevice::new(ChipModel::Icm42688p, DeviceBus::I2c),
    );
    // 46 bytes of images and 32 more would exceed 64.
    let mut icm = AddDevice::new(ChipModel::Icm42688p, DeviceBus::Spi);
    (icm.chip_select, icm.i2c_address) = (2, 0x69);
    add(&mut host, &mut dev, icm);
    // An image length not the model's.
    let wrong_len = AddDevice {
        image_len: 7,
        ..AddDevice::new(ChipModel::Qmc5883l, DeviceBus::I2c)
    };
    add(&mut host, &mut dev, wrong_len);
    // An override of a register file the chip lacks.
    let mut bad_file = AddDevice::new(ChipModel::Qmc5883l, DeviceBus::I2c);
    bad_file
        .overrides
        .push(RegisterOverride {
            file: 3,
            register: 9,
            value: 0,
        })
        .unwrap();
    add(&mut host, &mut dev, bad_file);
    // The third device fits (52 bytes of images); a fourth does not.
    add(
        &mut host,
        &mut dev,
        AddDevice::new(ChipModel::Qmc5883l, DeviceBus::I2c),
    );
    add(
        &mut host,
        &mut dev,
        AddDevice::new(ChipModel::Ist8310, DeviceBus::I2c),
    );
    let out = poll(&mut dev, 0);
    assert_eq!(
        errors(&out),
        [
            (ErrorCode::RigRefused, 3),
            (ErrorCode::RigRefused, 2),
            (ErrorCode::RigRefused, 5),
            (ErrorCode::UnsupportedChip, 7),
        ],
        "{out:?}"
    );
    // The error queue holds four; the rest (the bad override, the fourth device) were counted.
    assert_eq!((dev.rig().len(), dev.rig().image_len()), (3, 52));
    assert_eq!(dev.counters().rx.rejected_messages, 6);
}

#[test]
fn add_device_needs_a_configured_image_session() {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    poll(&mut dev, 0);
    add(
        &mut host,
        &mut dev,
        AddDevice::new(ChipModel::Ist8310, DeviceBus::I2c),
    );
    assert_eq!(errors(&poll(&mut dev, 0)), [(ErrorCode::NotConfigured, 0)]);
    let params = ModelParams::new(1, rate_1khz(), Default::default());
    let cfg = Configure {
        source: Source::Model(params),
        ..Configure::new(ChipModel::Mpu9250, rate_1khz())
    };
    host.configure(&mut dev, cfg);
    add(
        &mut host,
        &mut dev,
        AddDevice::new(ChipModel::Ist8310, DeviceBus::I2c),
    );
    assert_eq!(errors(&poll(&mut dev, 0)), [(ErrorCode::RigRefused, 4)]);
    // A new Configure drops the added devices.
    host.configure(&mut dev, Configure::new(ChipModel::Mpu9250, rate_1khz()));
    assert_eq!(dev.rig().len(), 1);
}

#[test]
fn a_rig_image_longer_than_the_link_carries_is_refused() {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    host.configure(&mut dev, Configure::new(ChipModel::Icm42688p, rate_1khz()));
    let mut second = AddDevice::new(ChipModel::Icm42688p, DeviceBus::Spi);
    (second.chip_select, second.i2c_address) = (1, 0x69);
    add(&mut host, &mut dev, second);
    add(
        &mut host,
        &mut dev,
        AddDevice::new(ChipModel::Ist8310, DeviceBus::I2c),
    );
    assert_eq!(errors(&poll(&mut dev, 0)), [(ErrorCode::RigRefused, 5)]);
    assert_eq!((dev.rig().len(), dev.rig().image_len()), (2, 64));
}
