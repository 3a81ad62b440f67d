//! Payload layouts pinned byte by byte against the offsets of `docs/spec/link.md` §5.

mod common;

use common::payload;
use margemu_model::perturbation::{Amplitude, PerturbationConfig, Placement};
use margemu_model::sensor::{MargConfig, Truth};
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
            chips: Chips::MPU9250 | Chips::WHO_AM_I_68,
            modes: Modes::IMAGES | Modes::MODEL,
            buses: Buses::SPI,
            max_batch: 0x0B0A,
            buffer_capacity: 0x0F0E_0D0C,
        },
    });
    let b = payload(&m);
    assert_eq!(b.len(), 34);
    assert_eq!(b[..9], [0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 7, 8, 9]);
    assert_eq!((b[9], b[24]), (0xA0, 0xAF));
    assert_eq!(
        b[25..],
        [0x09, 0x03, 0x01, 0x0A, 0x0B, 0x0C, 0x0D, 0x0E, 0x0F]
    );
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
        Message::parse(0x86, &[10, 0, 0, 0, 0, 0, 0]),
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
        ..Configure::new(0x73, Rate::new(1000, 3).unwrap())
    };
    let m = Message::Configure(cfg);
    let b = payload(&m);
    assert_eq!(
        b[..19],
        [0x73, 1, 0xE8, 0x03, 0, 0, 3, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]
    );
    let p = &b[19..];
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
    bad[19 + 25] = 0x04;
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
        ..Configure::new(0x71, Rate::hz(1).unwrap())
    };
    let o = RegisterOverride {
        file: RegisterFile::Ak8963,
        register: 0x10,
        value: 0x80,
    };
    while cfg.overrides.push(o).is_ok() {}
    let m = Message::Configure(cfg);
    assert_eq!(m.buffer_len(), MAX_CONFIGURE_LEN);
    assert_eq!((MAX_CONFIGURE_LEN, MAX_MARG_CONFIG_LEN), (1396, 1182));
    let b = payload(&m);
    parses_back(Kind::Configure, &b, &m);
    let mut bad = b.clone();
    bad[18] = 33;
    assert_eq!(Message::parse(0x02, &bad), Err(Error::InvalidValue));
}
