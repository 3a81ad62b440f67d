//! Shared proptest strategies for every message, and helpers that push wire bytes through the
//! accumulator in given chunk sizes.
#![allow(dead_code)]

use margemu_model::perturbation::{Amplitude, PerturbationConfig, Placement};
use margemu_model::sensor::{
    AccelConfig, BiasInstability, GyroConfig, MagConfig, MargConfig, SensorErrors, TemperatureBias,
    Truth,
};
use margemu_protocol::chip::ChipModel;
use margemu_protocol::link::*;
use proptest::prelude::*;

/// Any `f64` bit pattern, NaN payloads included (the link carries them bit for bit).
pub fn f64_bits() -> impl Strategy<Value = f64> {
    any::<u64>().prop_map(f64::from_bits)
}

/// Any `f32` bit pattern.
pub fn f32_bits() -> impl Strategy<Value = f32> {
    any::<u32>().prop_map(f32::from_bits)
}

fn v3() -> impl Strategy<Value = [f64; 3]> {
    prop::array::uniform3(f64_bits())
}

fn m3() -> impl Strategy<Value = [[f64; 3]; 3]> {
    prop::array::uniform3(v3())
}

fn o<S: Strategy>(s: S) -> impl Strategy<Value = Option<S::Value>> {
    prop::option::of(s)
}

pub fn sensor_errors() -> impl Strategy<Value = SensorErrors> {
    let bi = (v3(), f64_bits()).prop_map(|(coefficient, correlation_time_s)| BiasInstability {
        coefficient,
        correlation_time_s,
    });
    let tb = (v3(), f64_bits()).prop_map(|(coefficient, reference_c)| TemperatureBias {
        coefficient,
        reference_c,
    });
    (
        (o(m3()), o(m3()), o(v3()), o(v3())),
        (o(bi), o(v3()), o(tb), o(v3()), o(v3())),
    )
        .prop_map(
            |((sf, mis, bias, nd), (bi, rrw, tb, res, range))| SensorErrors {
                scale_factor: sf,
                misalignment: mis,
                bias,
                noise_density: nd,
                bias_instability: bi,
                rate_random_walk: rrw,
                temperature_bias: tb,
                resolution: res,
                range,
            },
        )
}

pub fn marg_config() -> impl Strategy<Value = MargConfig> {
    (
        (sensor_errors(), o(m3())),
        (sensor_errors(), o(v3())),
        (sensor_errors(), o(m3()), o(v3())),
    )
        .prop_map(|((ge, gs), (ae, la), (me, si, hi))| MargConfig {
            gyro: GyroConfig {
                errors: ge,
                g_sensitivity: gs,
            },
            accel: AccelConfig {
                errors: ae,
                lever_arm_m: la,
            },
            mag: MagConfig {
                errors: me,
                soft_iron: si,
                hard_iron: hi,
            },
        })
}

pub fn perturbation() -> impl Strategy<Value = PerturbationConfig> {
    let amplitude = prop_oneof![
        (f64_bits(), f64_bits()).prop_map(|(lo, hi)| Amplitude::Uniform { lo, hi }),
        Just(Amplitude::Reference),
    ];
    let placement = prop_oneof![
        Just(Placement::PerAxis),
        v3().prop_map(Placement::Direction),
        Just(Placement::RandomDirection),
    ];
    (
        f64_bits(),
        f64_bits(),
        amplitude,
        prop::array::uniform2(f64_bits()),
        placement,
    )
        .prop_map(
            |(window_s, cutoff_hz, amplitude, gap_s, placement)| PerturbationConfig {
                window_s,
                cutoff_hz,
                amplitude,
                gap_s,
                placement,
            },
        )
}

pub fn rate() -> impl Strategy<Value = Rate> {
    (1..=u32::MAX, 1..=u32::MAX).prop_map(|(n, d)| Rate::new(n, d).unwrap())
}

/// Every chip model.
pub fn chip_model() -> impl Strategy<Value = ChipModel> {
    prop::sample::select(ChipModel::ALL.to_vec())
}

/// An image of `len` bytes (≤ [`MAX_IMAGE_LEN`]) of any content.
pub fn image(len: usize) -> impl Strategy<Value = Image> {
    prop::collection::vec(any::<u8>(), len).prop_map(|b| Image::new(&b).unwrap())
}

/// The image length of a batch: every model's, and any other from 1 to [`MAX_IMAGE_LEN`].
pub fn image_len() -> impl Strategy<Value = usize> {
    prop_oneof![chip_model().prop_map(|m| m.image_len()), 1..=MAX_IMAGE_LEN,]
}

/// Images of one length, as many as fit a batch.
pub fn images() -> impl Strategy<Value = Vec<Image>> {
    image_len()
        .prop_flat_map(|len| prop::collection::vec(image(len), 0..=max_images_per_batch(len)))
}

pub fn configure() -> impl Strategy<Value = Configure> {
    // The link carries any file, identity, image length and address; the device judges them.
    let over = (any::<u8>(), any::<u8>(), any::<u8>()).prop_map(|(file, register, value)| {
        RegisterOverride {
            file,
            register,
            value,
        }
    });
    let model = (
        any::<u64>(),
        rate(),
        f64_bits(),
        marg_config(),
        o(perturbation()),
    )
        .prop_map(
            |(seed, truth_rate, mag_ut_per_unit, marg, perturbation)| ModelParams {
                seed,
                truth_rate,
                mag_ut_per_unit,
                marg,
                perturbation,
            },
        );
    let source = prop_oneof![Just(Source::Images), model.prop_map(Source::Model)];
    let overrides = prop::collection::vec(over, 0..=MAX_OVERRIDES);
    let chip = (chip_model(), any::<[u8; 3]>());
    (chip, rate(), any::<u64>(), overrides, source).prop_map(
        |(
            (chip, [who_am_i, image_len, i2c_address]),
            rate,
            telemetry_period_ns,
            overrides,
            source,
        )| Configure {
            chip,
            who_am_i,
            image_len,
            i2c_address,
            rate,
            telemetry_period_ns,
            overrides: overrides.into_iter().collect(),
            source,
        },
    )
}

pub fn truth() -> impl Strategy<Value = Truth> {
    let v = || prop::array::uniform3(f32_bits());
    (v(), v(), v(), v(), o(f32_bits())).prop_map(|(w, f, m, dw, t)| Truth {
        angular_rate: w,
        specific_force: f,
        magnetic_field: m,
        angular_acceleration: dw,
        temperature_c: t,
    })
}

pub fn register_write() -> impl Strategy<Value = RegisterWrite> {
    (any::<u64>(), 0..3u8, any::<[u8; 3]>()).prop_map(|(time_ns, bus, [a, r, v])| RegisterWrite {
        time_ns,
        bus: Bus::from_u8(bus).unwrap(),
        address: a,
        register: r,
        value: v,
    })
}

pub fn hello_ack() -> impl Strategy<Value = HelloAck> {
    (
        (
            any::<u16>(),
            any::<u32>(),
            any::<[u8; 3]>(),
            any::<[u8; DEVICE_ID_LEN]>(),
        ),
        (any::<u32>(), any::<[u8; 2]>(), any::<u16>(), any::<u32>()),
    )
        .prop_map(
            |((pv, session, [ma, mi, pa], device_id), (c, [m, b], mb, cap))| HelloAck {
                protocol_version: pv,
                session,
                firmware: FirmwareVersion {
                    major: ma,
                    minor: mi,
                    patch: pa,
                },
                device_id,
                capabilities: Capabilities {
                    chips: Chips(c),
                    modes: Modes(m),
                    buses: Buses(b),
                    max_batch: mb,
                    buffer_capacity: cap,
                },
            },
        )
}

pub fn telemetry() -> impl Strategy<Value = Telemetry> {
    (
        (any::<u64>(), 0..4u8, any::<u64>()),
        any::<[u32; 7]>(),
        any::<[u64; 4]>(),
    )
        .prop_map(|((time_ns, s, served), c, i)| Telemetry {
            time_ns,
            state: DeviceState::from_u8(s).unwrap(),
            samples_served: served,
            underruns: c[0],
            overruns: c[1],
            crc_errors: c[2],
            framing_errors: c[3],
            lost_frames: c[4],
            rejected_messages: c[5],
            buffer_level: c[6],
            next_index: i[0],
            credit_limit: i[1],
            last_served_index: i[2],
            last_served_time_ns: i[3],
        })
}

/// Any AddFault: a window of at least 1 ns, each kind with parameters in range.
pub fn add_fault() -> impl Strategy<Value = AddFault> {
    use margemu_model::fault::{Fault, FaultKind, Sensor, Window};
    let sensor = (0..3u8).prop_map(|c| Sensor::from_code(c).unwrap());
    let f = || -1e6f32..1e6;
    let v = || [f(), f(), f()];
    let kind = prop_oneof![
        sensor
            .clone()
            .prop_map(|sensor| FaultKind::Stuck { sensor }),
        (sensor.clone(), v()).prop_map(|(sensor, value)| FaultKind::StuckAt { sensor, value }),
        sensor
            .clone()
            .prop_map(|sensor| FaultKind::Dropout { sensor }),
        (sensor.clone(), f(), f(), 0..8u8).prop_map(|(sensor, rate_hz, amplitude, axes)| {
            FaultKind::Spikes {
                sensor,
                rate_hz,
                amplitude,
                axes,
            }
        }),
        (sensor.clone(), v()).prop_map(|(sensor, bias)| FaultKind::BiasStep { sensor, bias }),
        (sensor.clone(), v()).prop_map(|(sensor, factor)| FaultKind::Scale { sensor, factor }),
        (sensor, v()).prop_map(|(sensor, std)| FaultKind::Noise { sensor, std }),
        v().prop_map(|field| FaultKind::MagSaturation { field }),
        Just(FaultKind::Reset),
        any::<u8>().prop_map(|value| FaultKind::WrongIdentity { value }),
        Just(FaultKind::FifoOverflow),
        Just(FaultKind::Nak),
        f().prop_map(|probability| FaultKind::Corrupt { probability }),
        any::<u32>().prop_map(|stretch_ns| FaultKind::ClockStretch { stretch_ns }),
        (f(), f()).prop_map(|(ppm, drift_ppm_per_s)| FaultKind::ClockOffset {
            ppm,
            drift_ppm_per_s
        }),
        any::<u32>().prop_map(|max_ns| FaultKind::DrdyJitter { max_ns }),
        f().prop_map(|probability| FaultKind::MissingDrdy { probability }),
        any::<u32>().prop_map(|delay_ns| FaultKind::Late { delay_ns }),
    ];
    (any::<u8>(), any::<u64>(), 0..u64::MAX, 1..=u64::MAX, kind).prop_map(
        |(device, seed, start, len, kind)| AddFault {
            fault: Fault::new(
                device,
                Window::new(start, start.saturating_add(len).max(start + 1)),
                kind,
            ),
            seed,
        },
    )
}

/// A message with owned batches; [`Owned::message`] borrows them.
#[derive(Clone, Debug)]
pub enum Owned {
    Msg(Box<Message<'static>>),
    Images(u64, Vec<Image>),
    Kinematics(u64, Vec<Truth>),
    Writes(u32, Vec<RegisterWrite>),
}

impl Owned {
    pub fn message(&self) -> Message<'_> {
        match self {
            Self::Msg(m) => (**m).clone(),
            Self::Images(i, v) => Message::Images(ImageBatch::new(*i, v)),
            Self::Kinematics(i, v) => Message::Kinematics(KinematicsBatch::new(*i, v)),
            Self::Writes(d, v) => Message::RegisterWrites(RegisterWriteBatch::new(*d, v)),
        }
    }
}

/// Any message of either direction, of any size that fits a frame.
pub fn message() -> impl Strategy<Value = Owned> {
    let m = |s: BoxedStrategy<Message<'static>>| s.prop_map(|m| Owned::Msg(Box::new(m)));
    prop_oneof![
        m((any::<u16>(), any::<u32>())
            .prop_map(|(p, s)| Message::Hello(Hello {
                protocol_version: p,
                session: s
            }))
            .boxed()),
        m(configure().prop_map(Message::Configure).boxed()),
        m((any::<u64>(), any::<u64>())
            .prop_map(|(t0_ns, end_index)| Message::Start(Start { t0_ns, end_index }))
            .boxed()),
        m(Just(Message::Stop).boxed()),
        m(add_fault().prop_map(Message::AddFault).boxed()),
        (any::<u64>(), images()).prop_map(|(i, v)| Owned::Images(i, v)),
        (
            any::<u64>(),
            prop::collection::vec(truth(), 0..=MAX_KINEMATICS_PER_BATCH)
        )
            .prop_map(|(i, v)| Owned::Kinematics(i, v)),
        m(hello_ack().prop_map(Message::HelloAck).boxed()),
        m((any::<u64>(), any::<u64>())
            .prop_map(|(n, l)| Message::Credit(Credit {
                next_index: n,
                limit: l
            }))
            .boxed()),
        m(telemetry().prop_map(Message::Telemetry).boxed()),
        (
            any::<u32>(),
            prop::collection::vec(register_write(), 0..=MAX_REGISTER_WRITES_PER_BATCH)
        )
            .prop_map(|(d, v)| Owned::Writes(d, v)),
        m((0..6u8)
            .prop_map(|c| Message::Reset(Reset {
                cause: ResetCause::from_u8(c).unwrap()
            }))
            .boxed()),
        m((1..10u8, any::<u16>(), any::<u32>())
            .prop_map(|(c, seq, detail)| Message::Error(ErrorReport {
                code: ErrorCode::from_u8(c).unwrap(),
                seq,
                detail,
            }))
            .boxed()),
    ]
}

/// The wire bytes of `message` with sequence number `seq`.
pub fn wire(seq: u16, message: &Message<'_>) -> Vec<u8> {
    let mut enc = Encoder::new();
    enc.set_next_seq(seq);
    let mut out = [0u8; MAX_WIRE_LEN];
    let n = enc.encode(message, &mut out).expect("encode");
    out[..n].to_vec()
}

/// The payload bytes of `message`.
pub fn payload(message: &Message<'_>) -> Vec<u8> {
    let mut out = vec![0u8; message.buffer_len()];
    assert_eq!(message.emit(&mut out), Ok(out.len()));
    out
}

/// What came out of the accumulator, owned.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// An intact frame's bytes (header, payload, CRC).
    Frame(Vec<u8>),
    /// A damaged one.
    Damaged(Error),
}

/// Feeds `bytes` in chunks whose sizes cycle through `chunks` (each ≥ 1).
pub fn feed(acc: &mut Accumulator, bytes: &[u8], chunks: &[usize]) -> Vec<Outcome> {
    let mut out = Vec::new();
    let mut at = 0;
    for &size in chunks.iter().cycle() {
        if at >= bytes.len() {
            break;
        }
        let end = (at + size.max(1)).min(bytes.len());
        let mut input = &bytes[at..end];
        at = end;
        loop {
            match acc.feed(input) {
                FeedResult::Consumed => break,
                FeedResult::Success { frame, remaining } => {
                    out.push(Outcome::Frame(frame.into_inner().to_vec()));
                    input = remaining;
                }
                damaged => {
                    out.push(Outcome::Damaged(damaged.error().unwrap()));
                    input = damaged.remaining();
                }
            }
        }
    }
    out
}

/// The frame bytes (without COBS) of `message` with sequence number `seq`.
pub fn frame(seq: u16, message: &Message<'_>) -> Vec<u8> {
    let mut out = vec![0u8; MAX_FRAME_LEN];
    let n = emit_frame(seq, message, &mut out).expect("emit");
    out.truncate(n);
    out
}
