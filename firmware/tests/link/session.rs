//! Handshake, configuration, telemetry, register writes and refusals.

use margemu_firmware::chip::SpiTarget;
use margemu_firmware::link::DEFAULT_TELEMETRY_PERIOD_NS;
use margemu_model::perturbation::PerturbationConfig;
use margemu_model::sensor::MargConfig;
use margemu_protocol::link::{
    Bus, Configure, Credit, DeviceState, ErrorCode, Message, ModelParams, Modes, RegisterOverride,
    ResetCause, Source, Start,
};

use crate::common::*;

#[test]
fn handshake_answers_with_capabilities_after_the_boot_reset() {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 0xDEAD_BEEF);
    let out = poll(&mut dev, 0);
    assert_eq!(out[0], Out::Reset(ResetCause::PowerOn));
    let Out::HelloAck(ack) = &out[1] else {
        panic!("{out:?}")
    };
    assert_eq!(ack.session, 0xDEAD_BEEF);
    assert_eq!(ack.protocol_version, margemu_protocol::PROTOCOL_VERSION);
    let caps = ack.capabilities;
    assert!(caps.chips.has(ChipModel::Mpu9250) && caps.chips.has(ChipModel::Mpu6500));
    assert!(caps.modes.contains(Modes::IMAGES | Modes::MODEL));
    // The batch of the shortest image: 6-byte magnetometer images, 252 to a frame.
    assert_eq!((caps.buffer_capacity, caps.max_batch), (CAP as u32, 252));
    assert_eq!(out.len(), 2, "idle: no credit, no telemetry");
    assert_eq!(poll(&mut dev, 1_000 * MS), vec![]);
}

#[test]
fn configure_grants_the_whole_buffer_and_applies_overrides() {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    poll(&mut dev, 0);
    let mut cfg = Configure {
        who_am_i: 0x73,
        ..Configure::new(ChipModel::Mpu9250, rate_1khz())
    };
    cfg.overrides
        .push(RegisterOverride {
            file: 0,
            register: 0x1B,
            value: 0x18,
        })
        .unwrap();
    cfg.overrides
        .push(RegisterOverride {
            file: 1,
            register: 0x0A,
            value: 0x16,
        })
        .unwrap();
    host.configure(&mut dev, cfg);
    let out = poll(&mut dev, 0);
    assert_eq!(
        out,
        vec![Out::Credit(Credit {
            next_index: 0,
            limit: CAP as u64
        })],
        "overrides are not reported as writes of the device under test"
    );
    assert_eq!(dev.state(), DeviceState::Configured);
    let EmulatedChip::Mpu6xxx(chip) = dev.chip() else {
        panic!("an MPU-9250 was configured")
    };
    assert_eq!(chip.peek(0x75), 0x73);
    assert_eq!(chip.peek(0x1B), 0x18);
    assert_eq!(chip.ak8963().unwrap().peek(0x0A), 0x16);
    assert_eq!(chip.peek(0x37) & 0x02, 0, "bypass restored");
}

#[test]
fn refusals_are_answered_and_counted() {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    poll(&mut dev, 0);
    host.send(&mut dev, &Message::Start(Start::until_stop(0)), 0);
    host.configure(
        &mut dev,
        Configure {
            who_am_i: 0x42,
            ..Configure::new(ChipModel::Mpu9250, rate_1khz())
        },
    );
    let mut p = ModelParams::new(1, rate_1khz(), MargConfig::default());
    p.perturbation = Some(PerturbationConfig::default());
    host.configure(
        &mut dev,
        Configure {
            source: Source::Model(p),
            ..Configure::new(ChipModel::Mpu9250, rate_1khz())
        },
    );
    let out = poll(&mut dev, 0);
    let codes: Vec<_> = out
        .iter()
        .filter_map(|o| match o {
            Out::Error(e) => Some((e.code, e.seq)),
            _ => None,
        })
        .collect();
    assert_eq!(
        codes,
        vec![
            (ErrorCode::NotConfigured, 1),
            (ErrorCode::UnsupportedChip, 2),
            (ErrorCode::UnsupportedMode, 3)
        ]
    );
    assert_eq!(dev.counters().rx.rejected_messages, 3);
    assert_eq!(dev.state(), DeviceState::Idle);
}

/// Every chip the device cannot serve as asked is refused with UnsupportedChip (detail: the
/// model's code), and images of another length than the configured chip's are malformed.
#[test]
fn chips_identities_image_lengths_and_addresses_are_checked() {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    poll(&mut dev, 0);
    let mpu = Configure::new(ChipModel::Mpu9250, rate_1khz());
    let refused = [
        Configure {
            who_am_i: 0x47,
            ..mpu.clone()
        },
        Configure {
            image_len: 32,
            ..mpu.clone()
        },
        Configure {
            i2c_address: 0x0C,
            ..mpu.clone()
        },
        Configure {
            overrides: [RegisterOverride {
                file: 5,
                register: 0,
                value: 0,
            }]
            .into_iter()
            .collect(),
            ..mpu.clone()
        },
    ];
    for cfg in refused {
        host.configure(&mut dev, cfg);
    }
    let mut out = poll(&mut dev, 0); // at most four errors wait between polls
                                     // A chip code this version does not know: the payload does not parse, the answer says why.
    host.send_patched(&mut dev, &Message::Configure(mpu.clone()), |p| p[0] = 0xC8);
    let six = Configure::new(ChipModel::Mpu6500, rate_1khz());
    assert_eq!(usize::from(six.image_len), 14);
    host.configure(&mut dev, six);
    host.images(&mut dev, 0, &[Image::from([0u8; 22])], 0);
    host.images(&mut dev, 0, &[Image::from([0u8; 14])], 0);
    out.extend(poll(&mut dev, 0));
    let codes: Vec<_> = out
        .iter()
        .filter_map(|o| match o {
            Out::Error(e) => Some((e.code, e.detail)),
            _ => None,
        })
        .collect();
    assert_eq!(
        codes,
        vec![
            (ErrorCode::UnsupportedChip, 0),
            (ErrorCode::UnsupportedChip, 0),
            (ErrorCode::UnsupportedChip, 0),
            (ErrorCode::InvalidConfig, 0),
            (ErrorCode::UnsupportedChip, 0xC8),
            (ErrorCode::MalformedMessage, 22),
        ]
    );
    assert_eq!(dev.state(), DeviceState::Configured);
    assert_eq!(dev.buffer_level(), 1, "the 14-byte image was taken");
}

#[test]
fn telemetry_is_periodic_while_configured() {
    let (mut dev, _host) = configured();
    assert_eq!(poll(&mut dev, DEFAULT_TELEMETRY_PERIOD_NS - 1), vec![]);
    let out = poll(&mut dev, DEFAULT_TELEMETRY_PERIOD_NS);
    let t = telemetry(&out).expect("telemetry");
    assert_eq!(t.state, DeviceState::Configured);
    assert_eq!((t.samples_served, t.buffer_level), (0, 0));
    assert_eq!(t.credit_limit, CAP as u64);
    assert_eq!(credits(&out).len(), 1, "a credit goes with every telemetry");
    assert_eq!(poll(&mut dev, DEFAULT_TELEMETRY_PERIOD_NS + 1), vec![]);
}

#[test]
fn register_writes_of_the_device_under_test_are_reported() {
    let (mut dev, mut host) = configured();
    host.images(&mut dev, 0, &images(0, 4), 0);
    host.start(&mut dev, 0, 0);
    poll(&mut dev, 0);
    poll(&mut dev, 2 * MS);
    let chip = dev.chip_mut();
    for (reg, value) in [(0x1B, 0x08), (0x6B, 0x01)] {
        chip.select();
        chip.exchange(reg);
        chip.exchange(value);
        chip.deselect();
    }
    let out = poll(&mut dev, 2 * MS + 10);
    let writes: Vec<_> = out
        .iter()
        .filter_map(|o| match o {
            Out::Writes(d, w) => Some((*d, w.clone())),
            _ => None,
        })
        .collect();
    assert_eq!(writes.len(), 1);
    let (dropped, w) = &writes[0];
    assert_eq!(*dropped, 0);
    let got: Vec<_> = w
        .iter()
        .map(|w| (w.time_ns, w.bus, w.address, w.register, w.value))
        .collect();
    assert_eq!(
        got,
        vec![
            (2 * MS + 10, Bus::Spi, 0, 0x1B, 0x08),
            (2 * MS + 10, Bus::Spi, 0, 0x6B, 0x01)
        ]
    );
    // Writes beyond the chip's log are counted as dropped in the next batch.
    let chip = dev.chip_mut();
    for i in 0..200u32 {
        chip.select();
        chip.exchange(0x19);
        chip.exchange(i as u8);
        chip.deselect();
    }
    let out = poll(&mut dev, 3 * MS);
    let (dropped, n): (u32, usize) = out
        .iter()
        .filter_map(|o| match o {
            Out::Writes(d, w) => Some((*d, w.len())),
            _ => None,
        })
        .fold((0, 0), |(d, n), (dd, nn)| (d + dd, n + nn));
    assert_eq!((dropped, n), (72, 128));
}

#[test]
fn hello_resets_the_session() {
    let (mut dev, mut host) = configured();
    host.images(&mut dev, 0, &images(0, 8), 0);
    host.hello(&mut dev, 9);
    let out = poll(&mut dev, 0);
    assert!(
        matches!(&out[..], [Out::HelloAck(a)] if a.session == 9),
        "{out:?}"
    );
    assert_eq!((dev.state(), dev.buffer_level()), (DeviceState::Idle, 0));
}

#[test]
fn device_size_is_bounded() {
    use margemu_firmware::link::Device;
    let sizes = [
        core::mem::size_of::<Device<64>>(),
        core::mem::size_of::<Device<128>>(),
        core::mem::size_of::<Device<256>>(),
    ];
    eprintln!("size_of Device<64>, <128>, <256>: {sizes:?}");
    // Accumulator + encoder scratch + wire buffer (~4.6 KB), the rig (up to four chips of
    // ~3.6 KB), the model, the fault schedule (~8 KB: the model's sensor-fault engine with its
    // 16 streams 5.8 KB, the schedule 0.9 KB, the serving clock's streams 1.3 KB), and the ring
    // (one slot of ~136 bytes per sample: a rig's image).
    assert!(sizes[1] < 56 * 1024, "{sizes:?}");
    assert!(sizes[2] - sizes[1] <= 128 * 136, "{sizes:?}");
}
