//! Payload layouts pinned byte by byte against the offsets of `docs/spec/link.md` §5.

mod common;

use common::payload;
use margemu_model::perturbation::{Amplitude, PerturbationConfig, Placement};
use margemu_model::sensor::{MargConfig, Truth};
use margemu_protocol::chip::ChipModel;
use margemu_protocol::link::*;

fn parses_back(kind: Kind, bytes: &[u8], message: &Message<'_>) {
    assert_eq!(&Message::parse(kind as u8, bytes).unwrap(), message);
}

#[test]
fn hello_ack() {
    let m = Message::HelloAck(HelloAck {
        protocol_version: 0x0201,
        session: 0x0605_0403,
        firmware: FirmwareVersion {
            major: 7,
            minor: 8,
            patch: 9,
        },
        device_id: core::array::from_fn(|i| 0xA0 + i as u8),
        capabilities: Capabilities {
            chips: Chips::of(ChipModel::Mpu9250) | Chips::of(ChipModel::Mpu6000),
            modes: Modes::IMAGES | Modes::MODEL,
            buses: Buses::SPI,
            max_batch: 0x0B0A,
            buffer_capacity: 0x0F0E_0D0C,
        },
    });
    let b = payload(&m);
    assert_eq!((b.len(), HelloAck::LEN), (37, 37));
    assert_eq!(b[..9], [0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 7, 8, 9]);
    assert_eq!((b[9], b[24]), (0xA0, 0xAF));
    // chips: u32, bit n = model code n (MPU-9250 0, MPU-6000 2); modes; buses; max_batch; capacity.
    assert_eq!(
        b[25..],
        [0x05, 0, 0, 0, 0x03, 0x01, 0x0A, 0x0B, 0x0C, 0x0D, 0x0E, 0x0F]
    );
    parses_back(Kind::HelloAck, &b, &m);
}

#[test]
fn chips_are_a_set_of_model_codes() {
    for model in ChipModel::ALL {
        assert_eq!(Chips::of(model), Chips(1 << model.code()));
        assert!(Chips::of(model).has(model));
        assert_eq!(Chips::of(model).models().collect::<Vec<_>>(), [model]);
    }
    let all = ChipModel::ALL
        .into_iter()
        .fold(Chips::EMPTY, |c, m| c | Chips::of(m));
    assert_eq!(all, Chips(0x3FF));
    assert!(all.models().eq(ChipModel::ALL));
    // Unknown bits (a newer device's models) are kept on the wire and skipped by `models`.
    let newer = Chips(0x8000_0000 | Chips::of(ChipModel::Icm42688p).0);
    assert_eq!(newer.models().collect::<Vec<_>>(), [ChipModel::Icm42688p]);
    let m = Message::HelloAck(HelloAck {
        protocol_version: margemu_protocol::PROTOCOL_VERSION,
        session: 0,
        firmware: FirmwareVersion {
            major: 0,
            minor: 0,
            patch: 0,
        },
        device_id: [0; DEVICE_ID_LEN],
        capabilities: Capabilities {
            chips: newer,
            ..Capabilities::default()
        },
    });
    let b = payload(&m);
    assert_eq!((b[0], b[1]), (4, 0));
    assert_eq!(b[25..29], [0x10, 0, 0, 0x80]);
    parses_back(Kind::HelloAck, &b, &m);
}

#[test]
fn telemetry() {
    let t = Telemetry {
        time_ns: 0x11,
        state: DeviceState::Running,
        samples_served: 0x22,
        underruns: 0x33,
        overruns: 0x44,
        crc_errors: 0x55,
        framing_errors: 0x66,
        lost_frames: 0x77,
        rejected_messages: 0x88,
        buffer_level: 0x99,
        next_index: 0xAA,
        credit_limit: 0xBB,
        last_served_index: 0xCC,
        last_served_time_ns: 0xDD,
    };
    let b = payload(&Message::Telemetry(t));
    assert_eq!(b.len(), TELEMETRY_LEN);
    let at = [
        (0, 0x11),
        (8, 2),
        (9, 0x22),
        (17, 0x33),
        (21, 0x44),
        (25, 0x55),
        (29, 0x66),
        (33, 0x77),
        (37, 0x88),
        (41, 0x99),
        (45, 0xAA),
        (53, 0xBB),
        (61, 0xCC),
        (69, 0xDD),
    ];
    let nonzero: Vec<(usize, u8)> = b
        .iter()
        .copied()
        .enumerate()
        .filter(|&(_, x)| x != 0)
        .collect();
    assert_eq!(nonzero, at);
    assert_eq!(
        t.credit(),
        Credit {
            next_index: 0xAA,
            limit: 0xBB
        }
    );
    parses_back(Kind::Telemetry, &b, &Message::Telemetry(t));
}

#[test]
fn kinematics_sample() {
    let truth = Truth {
        angular_rate: [1.0, 0.0, 0.0],
        specific_force: [0.0, 0.0, 9.80665],
        magnetic_field: [0.0; 3],
        angular_acceleration: [0.0, -2.0, 0.0],
        temperature_c: Some(25.0),
    };
    let samples = [
        truth,
        Truth {
            temperature_c: None,
            ..truth
        },
    ];
    let m = Message::Kinematics(KinematicsBatch::new(3, &samples));
    let b = payload(&m);
    assert_eq!(b.len(), 8 + 2 * TRUTH_LEN);
    assert_eq!(b[..8], [3, 0, 0, 0, 0, 0, 0, 0]);
    let s = &b[8..8 + TRUTH_LEN];
    assert_eq!(s[0..4], 1.0f32.to_le_bytes());
    assert_eq!(s[20..24], 9.80665f32.to_le_bytes());
    assert_eq!(s[40..44], (-2.0f32).to_le_bytes());
    assert_eq!(s[48..53], [0x00, 0x00, 0xC8, 0x41, 0x01]); // 25.0, present
    assert_eq!(b[8 + TRUTH_LEN + 48..], [0, 0, 0, 0, 0]); // absent
    parses_back(Kind::Kinematics, &b, &m);
    // An absent temperature with non-zero bytes, or an unknown flag, is refused.
    let mut bad = b.clone();
    bad[8 + TRUTH_LEN + 48] = 1;
    assert_eq!(Message::parse(0x11, &bad), Err(Error::InvalidValue));
    bad[8 + TRUTH_LEN + 48] = 0;
    bad[8 + TRUTH_LEN + 52] = 2;
    assert_eq!(Message::parse(0x11, &bad), Err(Error::InvalidValue));
}

#[test]
fn register_writes_and_error() {
    let w = [RegisterWrite {
        time_ns: 0x0102,
        bus: Bus::AuxMaster,
        address: 0x0C,
        register: 0x0A,
        value: 0x16,
    }];
    let m = Message::RegisterWrites(RegisterWriteBatch::new(5, &w));
    let b = payload(&m);
    assert_eq!(
        b,
        [5, 0, 0, 0, 0x02, 0x01, 0, 0, 0, 0, 0, 0, 2, 0x0C, 0x0A, 0x16]
    );
    parses_back(Kind::RegisterWrites, &b, &m);
    let m = Message::Error(ErrorReport {
        code: ErrorCode::CreditExceeded,
        seq: 0x0102,
        detail: 0x0A0B_0C0D,
    });
    let b = payload(&m);
    assert_eq!(b, [8, 0x02, 0x01, 0x0D, 0x0C, 0x0B, 0x0A]);
    parses_back(Kind::Error, &b, &m);
    assert_eq!(
        Message::parse(0x86, &[12, 0, 0, 0, 0, 0, 0]),
        Err(Error::InvalidValue)
    );
}

#[test]
fn configure_with_the_model() {
    let mut marg = MargConfig::default();
    marg.gyro.errors.bias = Some([0.5, 0.0, 0.0]);
    marg.mag.hard_iron = Some([0.0, 0.0, -1.0]);
    let mut params = ModelParams::new(0x2A, Rate::hz(200).unwrap(), marg);
    params.mag_ut_per_unit = 50.0;
    params.perturbation = Some(PerturbationConfig {
        amplitude: Amplitude::Reference,
        placement: Placement::RandomDirection,
        ..PerturbationConfig::default()
    });
    let cfg = Configure {
        source: Source::Model(params),
        who_am_i: 0x73,
        ..Configure::new(ChipModel::Mpu9250, Rate::new(1000, 3).unwrap())
    };
    let m = Message::Configure(cfg);
    let b = payload(&m);
    // chip 0 (MPU-9250) answering 0x73 (MPU-9255), 22-byte images, I2C 0x68; then source 1.
    assert_eq!(
        b[..22],
        [0, 0x73, 22, 0x68, 1, 0xE8, 0x03, 0, 0, 3, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]
    );
    let p = &b[22..];
    assert_eq!(
        p[..16],
        [0x2A, 0, 0, 0, 0, 0, 0, 0, 200, 0, 0, 0, 1, 0, 0, 0]
    );
    assert_eq!(p[16..24], 50.0f64.to_le_bytes());
    // Gyro: mask bit 2 (bias) and its 3 values; accel: nothing; mag: bit 10 (hard iron).
    assert_eq!(p[24..26], [0x04, 0x00]);
    assert_eq!(p[26..34], 0.5f64.to_le_bytes());
    assert_eq!(p[50..54], [0x00, 0x00, 0x00, 0x04]);
    assert_eq!(p[70..78], (-1.0f64).to_le_bytes());
    // Perturbation: present; 2 s, 5 Hz, Reference, gaps 1..5 s, RandomDirection.
    assert_eq!(p[78], 1);
    assert_eq!(p[79..87], 2.0f64.to_le_bytes());
    assert_eq!(p[87..95], 5.0f64.to_le_bytes());
    assert_eq!(p[95], 1);
    assert_eq!(p[96..104], 1.0f64.to_le_bytes());
    assert_eq!(p[104..112], 5.0f64.to_le_bytes());
    assert_eq!(p[112..], [2]);
    parses_back(Kind::Configure, &b, &m);
    // A reserved mask bit, or hard iron on the gyroscope, is refused.
    let mut bad = b.clone();
    bad[22 + 25] = 0x04;
    assert_eq!(Message::parse(0x02, &bad), Err(Error::InvalidValue));
}

#[test]
fn largest_configure_fits_a_frame() {
    let v = Some([1.0; 3]);
    let m3 = Some([[1.0; 3]; 3]);
    let mut marg = MargConfig::default();
    for e in [
        &mut marg.gyro.errors,
        &mut marg.accel.errors,
        &mut marg.mag.errors,
    ] {
        (e.scale_factor, e.misalignment, e.bias, e.noise_density) = (m3, m3, v, v);
        (e.rate_random_walk, e.resolution, e.range) = (v, v, v);
        e.bias_instability = Some(margemu_model::sensor::BiasInstability {
            coefficient: [1.0; 3],
            correlation_time_s: 1.0,
        });
        e.temperature_bias = Some(margemu_model::sensor::TemperatureBias {
            coefficient: [1.0; 3],
            reference_c: 1.0,
        });
    }
    (
        marg.gyro.g_sensitivity,
        marg.accel.lever_arm_m,
        marg.mag.soft_iron,
        marg.mag.hard_iron,
    ) = (m3, v, m3, v);
    let mut params = ModelParams::new(1, Rate::hz(1).unwrap(), marg);
    params.perturbation = Some(PerturbationConfig {
        placement: Placement::Direction([1.0; 3]),
        ..Default::default()
    });
    let mut cfg = Configure {
        source: Source::Model(params),
        ..Configure::new(ChipModel::Mpu9250, Rate::hz(1).unwrap())
    };
    let o = RegisterOverride {
        file: 1, // the MPU-9250's AK8963
        register: 0x10,
        value: 0x80,
    };
    while cfg.overrides.push(o).is_ok() {}
    let m = Message::Configure(cfg);
    assert_eq!(m.buffer_len(), MAX_CONFIGURE_LEN);
    assert_eq!((MAX_CONFIGURE_LEN, MAX_MARG_CONFIG_LEN), (1399, 1182));
    let b = payload(&m);
    parses_back(Kind::Configure, &b, &m);
    let mut bad = b.clone();
    bad[21] = 33;
    assert_eq!(Message::parse(0x02, &bad), Err(Error::InvalidValue));
}

#[test]
fn configure_names_the_chip() {
    let rate = Rate::hz(1000).unwrap();
    for model in ChipModel::ALL {
        let cfg = Configure::new(model, rate);
        assert_eq!(
            (cfg.chip, cfg.who_am_i, usize::from(cfg.image_len)),
            (model, model.identities()[0], model.image_len())
        );
        assert_eq!(cfg.i2c_address, model.i2c_addresses()[0]);
        let m = Message::Configure(cfg);
        let b = payload(&m);
        assert_eq!(b.len(), 22);
        assert_eq!(
            b[..5],
            [
                model.code(),
                model.who_am_i(),
                model.image_len() as u8,
                model.i2c_addresses()[0],
                0
            ]
        );
        parses_back(Kind::Configure, &b, &m);
    }
    assert_eq!(
        ChipModel::ALL.map(|m| (m.code(), m.image_len())),
        [
            (0, 22),
            (1, 14),
            (2, 14),
            (3, 14),
            (4, 32),
            (5, 14),
            (6, 6),
            (7, 6),
            (8, 9),
            (9, 14)
        ]
    );
    // Identity, image length and address are carried as they are (the device judges them);
    // an override's file is a plain byte numbered by the model.
    let mut cfg = Configure::new(ChipModel::Icm42688p, rate);
    (cfg.who_am_i, cfg.image_len, cfg.i2c_address) = (0x71, 22, 0x0C);
    let o = RegisterOverride {
        file: 4,
        register: 0x7B,
        value: 0x02,
    };
    cfg.overrides.push(o).unwrap();
    let m = Message::Configure(cfg);
    let b = payload(&m);
    assert_eq!(b[..5], [4, 0x71, 22, 0x0C, 0]);
    assert_eq!(b[21..], [1, 4, 0x7B, 0x02]);
    parses_back(Kind::Configure, &b, &m);
    // An unknown chip code is refused.
    for code in [10, 0x80, 0xFF] {
        let mut bad = b.clone();
        bad[0] = code;
        assert_eq!(
            Message::parse(0x02, &bad),
            Err(Error::UnknownChip),
            "{code}"
        );
    }
}

#[test]
fn image_batch() {
    assert_eq!(IMAGE_BATCH_HEADER_LEN, 9);
    for model in ChipModel::ALL {
        let len = model.image_len();
        let images: Vec<Image> = (0..3u8)
            .map(|k| Image::new(&vec![0x10 * (k + 1); len]).unwrap())
            .collect();
        let m = Message::Images(ImageBatch::new(0x0102, &images));
        let b = payload(&m);
        assert_eq!(b.len(), IMAGE_BATCH_HEADER_LEN + 3 * len, "{model:?}");
        assert_eq!(b[..9], [0x02, 0x01, 0, 0, 0, 0, 0, 0, len as u8]);
        assert!(b[9..9 + len].iter().all(|&x| x == 0x10));
        assert!(b[9 + 2 * len..].iter().all(|&x| x == 0x30));
        parses_back(Kind::Images, &b, &m);
        let Ok(Message::Images(batch)) = Message::parse(0x10, &b) else {
            panic!("{model:?}")
        };
        assert_eq!(
            (batch.images.len(), batch.images.image_len()),
            (3, len),
            "{model:?}"
        );
        assert_eq!(batch.images.get(2), Some(images[2]));
        assert_eq!(batch.images.get(3), None);
    }
    // No image: length byte 0.
    let m = Message::Images(ImageBatch::new(5, &[]));
    let b = payload(&m);
    assert_eq!(b, [5, 0, 0, 0, 0, 0, 0, 0, 0]);
    parses_back(Kind::Images, &b, &m);
}

#[test]
fn image_batch_refusals() {
    let index = [7u8, 0, 0, 0, 0, 0, 0, 0];
    let parse = |len: u8, images: &[u8]| {
        let b = [&index[..], &[len], images].concat();
        Message::parse(Kind::Images as u8, &b).map(|m| m.buffer_len())
    };
    assert_eq!(parse(0, &[]), Ok(9));
    assert_eq!(parse(32, &[0x20; 64]), Ok(73));
    assert_eq!(parse(1, &[0x01; 3]), Ok(12));
    // A rig's image: up to 64 bytes.
    assert_eq!(parse(38, &[0x5A; 76]), Ok(85));
    assert_eq!(parse(64, &[0; 64]), Ok(73));
    // Length 0 with images, above 64, or not dividing the images' bytes.
    assert_eq!(parse(0, &[1]), Err(Error::InvalidValue));
    assert_eq!(parse(0, &[0; 22]), Err(Error::InvalidValue));
    assert_eq!(parse(65, &[0; 65]), Err(Error::InvalidValue));
    assert_eq!(parse(65, &[]), Err(Error::InvalidValue));
    assert_eq!(parse(0xFF, &[0; 255]), Err(Error::InvalidValue));
    assert_eq!(parse(22, &[0; 23]), Err(Error::PayloadTooLong));
    assert_eq!(parse(22, &[0; 14]), Err(Error::PayloadTooLong));
    assert_eq!(parse(14, &[0; 22]), Err(Error::PayloadTooLong));
    // No length byte at all.
    assert_eq!(
        Message::parse(Kind::Images as u8, &index),
        Err(Error::PayloadTooShort)
    );
}

#[test]
fn image_batch_of_mixed_lengths_is_not_emitted() {
    let (a, b) = (Image::from([1u8; 22]), Image::from([2u8; 14]));
    let c = Image::from([3u8; 32]);
    let mut wire = [0u8; MAX_WIRE_LEN];
    let mut buf = [0u8; MAX_PAYLOAD_LEN];
    for mixed in [[a, b], [b, a], [a, c], [c, a]] {
        let m = Message::Images(ImageBatch::new(0, &mixed));
        assert_eq!(m.emit(&mut buf), Err(Error::InvalidValue), "{mixed:?}");
        assert_eq!(
            Encoder::new().encode(&m, &mut wire),
            Err(Error::InvalidValue),
            "{mixed:?}"
        );
    }
    // Nor a batch of empty images (the wire says "no image" with length 0).
    let empty = [Image::default(); 2];
    let m = Message::Images(ImageBatch::new(0, &empty));
    assert_eq!(m.emit(&mut buf), Err(Error::InvalidValue));
}

#[test]
fn images_per_batch_by_length() {
    // (1526 − 9) / image length.
    let expected = [(1, 1517), (14, 108), (22, 68), (32, 47)];
    for (len, n) in expected {
        assert_eq!(max_images_per_batch(len), n, "{len}");
        let images = vec![Image::new(&vec![0x77; len]).unwrap(); n + 1];
        let fits = Message::Images(ImageBatch::new(0, &images[..n]));
        assert!(fits.buffer_len() <= MAX_PAYLOAD_LEN);
        let mut wire = [0u8; MAX_WIRE_LEN];
        assert!(Encoder::new().encode(&fits, &mut wire).is_ok(), "{len}");
        let over = Message::Images(ImageBatch::new(0, &images));
        assert!(over.buffer_len() > MAX_PAYLOAD_LEN);
        assert_eq!(
            Encoder::new().encode(&over, &mut wire),
            Err(Error::MessageTooLarge),
            "{len}"
        );
    }
    for model in ChipModel::ALL {
        assert!(max_images_per_batch(model.image_len()) >= 47);
    }
}

#[test]
fn add_device_carries_the_rig_device_and_refuses_what_it_cannot() {
    use margemu_protocol::link::{AddDevice, DeviceBus, RegisterOverride};
    let mut add = AddDevice::new(ChipModel::Rm3100, DeviceBus::Spi);
    add.chip_select = 2;
    add.overrides
        .push(RegisterOverride {
            file: 0,
            register: 0x0B,
            value: 0x94,
        })
        .unwrap();
    let m = Message::AddDevice(add);
    let b = payload(&m);
    assert_eq!(b, [8, 0x22, 9, 0, 0x20, 2, 1, 0, 0x0B, 0x94]);
    parses_back(Kind::AddDevice, &b, &m);
    // A bus byte other than 0 or 1, an unknown chip code, more overrides than 8, a short payload.
    assert_eq!(
        Message::parse(0x05, &[8, 0x22, 9, 2, 0x20, 0, 0]),
        Err(Error::InvalidValue)
    );
    assert_eq!(
        Message::parse(0x05, &[10, 0x24, 14, 0, 0x68, 0, 0]),
        Err(Error::UnknownChip)
    );
    let nine = [&[8u8, 0x22, 9, 1, 0x20, 0, 9][..], &[0u8; 27]].concat();
    assert_eq!(Message::parse(0x05, &nine), Err(Error::InvalidValue));
    assert!(Message::parse(0x05, &[8, 0x22, 9, 1]).is_err());
}
