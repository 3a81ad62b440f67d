//! The fault schedule on the device (`docs/spec/link.md` §5.16): AddFault held, refused and
//! cleared; sensor faults in source (b) exactly as the host predicts them; the chip faults'
//! edges; the timing faults' latch instants against a hand-advanced clock.

use margemu_firmware::chip::Chip;
use margemu_firmware::fault::FaultSchedule;
use margemu_firmware::link::faults::{clock_lead_ns, ChipEdge, ChipEdges};
use margemu_firmware::link::setup::{self, ChainSetup, DeviceModel};
use margemu_firmware::link::{
    FAULT_NO_DEVICE, FAULT_OVERLAPS, FAULT_SCHEDULE_FULL, FAULT_UNSUPPORTED,
};
use margemu_model::fault::{fault_rng, Fault, FaultKind, Sensor, Window, MAX_FAULTS, UNTIL_END};
use margemu_model::rng::unit_f64;
use margemu_model::sensor::{MargConfig, Truth};
use margemu_protocol::link::{
    AddDevice, AddFault, Configure, DeviceBus, DeviceState, ErrorCode, KinematicsBatch, Message,
    ModelParams, Rate, RegisterOverride, Source,
};

use crate::common::*;

const SEED: u64 = 0xFA17;

fn add(host: &mut Host, dev: &mut Dev, fault: Fault) {
    host.send(dev, &Message::AddFault(AddFault { fault, seed: SEED }), 0);
}

fn win(start_ms: u64, end_ms: u64) -> Window {
    Window::new(start_ms * MS, end_ms * MS)
}

#[test]
fn faults_are_held_refused_with_their_detail_and_cleared_by_configure() {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    let stuck = Fault::new(
        0,
        win(10, 20),
        FaultKind::Stuck {
            sensor: Sensor::Gyr,
        },
    );
    add(&mut host, &mut dev, stuck);
    assert_eq!(errors(&poll(&mut dev, 0)), [(ErrorCode::NotConfigured, 0)]);

    let (mut dev, mut host) = configured();
    add(&mut host, &mut dev, stuck);
    let dropout = Fault::new(
        0,
        win(15, 30),
        FaultKind::Dropout {
            sensor: Sensor::Gyr,
        },
    );
    add(&mut host, &mut dev, dropout); // the same sensor replaced twice at once
    add(
        &mut host,
        &mut dev,
        Fault::new(1, win(0, 5), FaultKind::Nak),
    ); // no device 1
    let late = FaultKind::Late { delay_ns: 1000 };
    let refused = |detail| (ErrorCode::FaultRefused, detail);
    assert_eq!(
        errors(&poll(&mut dev, 0)),
        [refused(FAULT_OVERLAPS), refused(FAULT_NO_DEVICE)]
    );
    assert_eq!(
        dev.faults().iter().map(|e| e.fault).collect::<Vec<_>>(),
        [stuck]
    );

    // A rig's device 1 may not move the shared serving clock; it may miss data-ready pulses.
    host.send(
        &mut dev,
        &Message::AddDevice(AddDevice::new(ChipModel::Ist8310, DeviceBus::I2c)),
        0,
    );
    add(&mut host, &mut dev, Fault::new(1, win(0, 5), late));
    let missing = FaultKind::MissingDrdy { probability: 0.5 };
    add(&mut host, &mut dev, Fault::new(1, win(0, 5), missing));
    assert_eq!(errors(&poll(&mut dev, 0)), [refused(FAULT_UNSUPPORTED)]);
    assert_eq!(dev.faults().iter().count(), 2);

    for i in 2..=MAX_FAULTS as u64 {
        add(
            &mut host,
            &mut dev,
            Fault::new(0, win(100 * i, 100 * i + 1), FaultKind::Nak),
        );
    }
    assert_eq!(errors(&poll(&mut dev, 0)), [refused(FAULT_SCHEDULE_FULL)]);
    assert_eq!(dev.faults().iter().count(), MAX_FAULTS);

    host.configure(&mut dev, Configure::new(ChipModel::Mpu9250, rate_1khz()));
    assert!(dev.faults().is_empty());
    host.start(&mut dev, 0, 0);
    add(&mut host, &mut dev, stuck);
    let running = (ErrorCode::InvalidConfig, DeviceState::Running as u32);
    assert_eq!(errors(&poll(&mut dev, 0)), [running]);
}

#[test]
fn a_chip_fault_the_chip_cannot_apply_is_refused_and_the_others_fire_at_their_edges() {
    // A chip without a FIFO cannot overflow one: refused, nothing held.
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    host.configure(&mut dev, Configure::new(ChipModel::Ist8310, rate_1khz()));
    add(
        &mut host,
        &mut dev,
        Fault::new(0, win(3, 6), FaultKind::FifoOverflow),
    );
    assert_eq!(
        errors(&poll(&mut dev, 0)),
        [(ErrorCode::FaultRefused, FAULT_UNSUPPORTED)]
    );
    assert!(dev.faults().is_empty());

    for model in [ChipModel::Mpu9250, ChipModel::Icm42688p, ChipModel::Bmi270] {
        for kind in [
            FaultKind::Reset,
            FaultKind::WrongIdentity { value: 0x12 },
            FaultKind::FifoOverflow,
        ] {
            let mut dev = Dev::new();
            let mut host = Host::new();
            host.hello(&mut dev, 1);
            host.configure(&mut dev, Configure::new(model, rate_1khz()));
            // Every IMU with a FIFO has all three hooks.
            add(&mut host, &mut dev, Fault::new(0, win(3, 6), kind));
            assert_eq!(errors(&poll(&mut dev, 0)), [], "{model:?} {kind:?}");
            host.images(
                &mut dev,
                0,
                &vec![Image::zeroed(model.image_len()).unwrap(); 10],
                0,
            );
            host.start(&mut dev, 0, 0);
            let edges = |dev: &Dev| dev.counters().chip_fault_edges;
            for k in 0..10 {
                poll(&mut dev, k * MS);
                let want = match (kind, k) {
                    (_, 0..=2) => 0,
                    (FaultKind::Reset, _) => 1,
                    (_, 3..=5) => 1,
                    _ => 2,
                };
                assert_eq!(edges(&dev), want, "{model:?} {kind:?} at {k} ms");
            }
        }
    }
}

#[test]
fn chip_edges_fire_once_each_at_the_first_instant_at_or_after_them() {
    let mut s = FaultSchedule::new();
    s.push(
        Fault::new(0, win(2, 4), FaultKind::WrongIdentity { value: 7 }),
        1,
    )
    .unwrap();
    s.push(
        Fault::new(1, Window::new(5 * MS, UNTIL_END), FaultKind::Reset),
        2,
    )
    .unwrap();
    s.push(Fault::new(0, win(0, 9), FaultKind::Nak), 1).unwrap();
    let mut edges = ChipEdges::new();
    let mut at = |t_ns| {
        let mut fired = Vec::new();
        edges.fire_due(&s, t_ns, |e: ChipEdge| fired.push((e.device, e.begins)));
        fired
    };
    assert_eq!(at(MS), []);
    assert_eq!(at(2 * MS), [(0, true)]);
    assert_eq!(at(3 * MS), []);
    // A late poll: the identity's end and the reset's start, in schedule order.
    assert_eq!(at(6 * MS), [(0, false), (1, true)]);
    assert_eq!(at(u64::MAX), []);
}

// ---- source (b): sensor faults ----

fn params() -> ModelParams {
    let mut cfg = MargConfig::default();
    cfg.gyro.errors.noise_density = Some([0.01; 3]);
    ModelParams::new(SEED, Rate::hz(250).unwrap(), cfg)
}

fn model_configure() -> Configure {
    Configure {
        source: Source::Model(params()),
        ..Configure::new(ChipModel::Icm42688p, rate_1khz())
    }
}

fn truth(j: u64) -> Truth {
    Truth {
        angular_rate: [0.02 * j as f32, 0.0, -0.1],
        specific_force: [0.5, 0.0, 9.80665],
        magnetic_field: [0.2, 0.0, 0.4],
        angular_acceleration: [0.0; 3],
        temperature_c: None,
    }
}

fn sensor_faults() -> Vec<Fault> {
    vec![
        Fault::new(
            0,
            win(10, 30),
            FaultKind::Stuck {
                sensor: Sensor::Gyr,
            },
        ),
        Fault::new(
            0,
            win(20, 60),
            FaultKind::Noise {
                sensor: Sensor::Acc,
                std: [0.5; 3],
            },
        ),
        Fault::new(0, win(0, 5), FaultKind::Nak), // another class keeps its index
        Fault::new(
            0,
            Window::new(40 * MS, UNTIL_END),
            FaultKind::Spikes {
                sensor: Sensor::Gyr,
                rate_hz: 200.0,
                amplitude: 3.0,
                axes: 0b011,
            },
        ),
        Fault::new(
            0,
            win(70, 80),
            FaultKind::Dropout {
                sensor: Sensor::Acc,
            },
        ),
        Fault::new(
            0,
            win(50, 90),
            FaultKind::BiasStep {
                sensor: Sensor::Acc,
                bias: [1.0, -1.0, 0.0],
            },
        ),
    ]
}

/// The 100 images the device serves at 1 kHz in source (b) with `faults`.
fn serve_model(faults: &[Fault]) -> Vec<Image> {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    host.configure(&mut dev, model_configure());
    for f in faults {
        add(&mut host, &mut dev, *f);
    }
    let sent: Vec<Truth> = (0..25).map(truth).collect();
    host.send(
        &mut dev,
        &Message::Kinematics(KinematicsBatch::new(0, &sent)),
        0,
    );
    host.start(&mut dev, 0, 0);
    let mut images = Vec::new();
    for k in 0..100u64 {
        let out = poll(&mut dev, k * MS);
        assert_eq!(errors(&out), []);
        images.push(dev.last_served().unwrap().image.unwrap());
    }
    images
}

/// The host's prediction: the same model, its faults pushed in order with the device's seed.
fn predict_model(faults: &[Fault]) -> Vec<Image> {
    let cfg = model_configure();
    let p = params();
    let chip = setup::build_chip(&cfg).unwrap();
    let mut model =
        DeviceModel::new(&p.marg, cfg.rate, SEED, &chip, &ChainSetup::default()).unwrap();
    for f in faults {
        model.push_fault(f, SEED).unwrap();
    }
    (0..100u64)
        .map(|k| setup::model_image(&mut model, k * MS, &truth(k / 4), p.mag_ut_per_unit, &chip))
        .collect()
}

#[test]
fn sensor_faults_in_source_b_are_served_as_the_host_predicts_and_only_in_their_windows() {
    let faults = sensor_faults();
    let served = serve_model(&faults);
    assert_eq!(served, predict_model(&faults));
    let clean = serve_model(&[]);
    assert_eq!(clean, predict_model(&[]));
    // ICM-42688-P image: accel at bytes 2..8, gyro at 8..14 (after TEMP_DATA).
    let accel = |im: &Image| im[2..8].to_vec();
    let gyro = |im: &Image| im[8..14].to_vec();
    for k in 0..10 {
        assert_eq!(served[k], clean[k], "before every window: {k}");
    }
    for k in 10..30 {
        assert_eq!(
            gyro(&served[k]),
            gyro(&served[9]),
            "gyro stuck at sample 9's: {k}"
        );
    }
    for k in 30..40 {
        assert_eq!(gyro(&served[k]), gyro(&clean[k]), "gyro released: {k}");
    }
    let noisy = (20..50)
        .filter(|&k| accel(&served[k]) != accel(&clean[k]))
        .count();
    assert_eq!(noisy, 30);
    let spiked = (40..100)
        .filter(|&k| gyro(&served[k]) != gyro(&clean[k]))
        .count();
    assert!(
        (3..40).contains(&spiked),
        "{spiked} spikes at 200/s over 60 ms"
    );
}

// ---- timing faults ----

/// Serves 40 samples of source (a) at 1 kHz under `faults`, polling every 10 µs; returns each
/// sample's (index, latch time) as the Served reports give them (a batch's first entry at its
/// time, the others at their nominal instants) and the reports' (first index, first time,
/// entries).
fn serve_timed(faults: &[Fault], configure: Configure) -> Timed {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    host.configure(&mut dev, configure);
    for f in faults {
        add(&mut host, &mut dev, *f);
    }
    assert_eq!(errors(&poll(&mut dev, 0)), []);
    host.images(&mut dev, 0, &images(0, 40), 0);
    host.start_scene(&mut dev, 40, 0);
    let (mut latches, mut reports) = (Vec::new(), Vec::new());
    let mut t = 0;
    while t < 45 * MS {
        for o in poll(&mut dev, t) {
            if let Out::Served(first, time, entries) = o {
                reports.push((first, time, entries.len()));
                latches.push((first, time));
                latches.extend((first + 1..first + entries.len() as u64).map(|k| (k, nominal(k))));
            }
        }
        if let Some(s) = dev.last_served() {
            assert!(s.time_ns <= t, "latched at {} by {t}", s.time_ns);
        }
        t += 10_000;
    }
    (latches, reports)
}

/// Each sample's (index, latch time), and the Served reports' (first index, time, entries).
type Timed = (Vec<(u64, u64)>, Vec<(u64, u64, usize)>);

fn nominal(k: u64) -> u64 {
    k * MS
}

#[test]
fn late_and_clock_offset_move_the_latch_inside_their_windows_only() {
    let late = Fault::new(0, win(5, 10), FaultKind::Late { delay_ns: 300_000 });
    let offset = FaultKind::ClockOffset {
        ppm: 20_000.0,
        drift_ppm_per_s: 100_000.0,
    };
    let clock = Fault::new(0, win(20, 30), offset);
    let cfg = Configure::new(ChipModel::Mpu9250, rate_1khz());
    let (latches, reports) = serve_timed(&[late, clock], cfg);
    assert_eq!(latches.len(), 40);
    for &(k, at) in &latches {
        let t = nominal(k);
        let want = match k {
            5..=9 => t + 300_000,
            20..=29 => {
                let lead = clock_lead_ns(20_000.0, 100_000.0, t - 20 * MS);
                (t as f64 - lead).round() as u64
            }
            _ => t,
        };
        assert_eq!(at, want, "sample {k}");
    }
    // 2 % fast and drifting: sample 29 comes 0.18 ms + 0.004 ms early.
    assert_eq!(latches[29].1, 29 * MS - 184_050);
    // Each shifted sample is a Served batch of its own, carrying its latch time.
    for &(first, time, n) in &reports {
        let shifted = latches[first as usize].1 != nominal(first);
        assert_eq!(time, latches[first as usize].1);
        assert!(!shifted || n == 1, "{first}: {n} entries");
    }
    let reported: usize = reports.iter().map(|r| r.2).sum();
    assert_eq!(reported, 40);
}

#[test]
fn jitter_draws_from_the_faults_own_stream_and_never_reorders() {
    let jitter = Fault::new(0, win(10, 20), FaultKind::DrdyJitter { max_ns: 2_500_000 });
    let nak = Fault::new(0, win(0, 40), FaultKind::Nak);
    let cfg = Configure::new(ChipModel::Mpu9250, rate_1khz());
    let (latches, _) = serve_timed(&[nak, jitter], cfg);
    // The jitter fault is device 0's second: its stream is fault_rng(SEED, 1).
    let mut rng = fault_rng(SEED, 1);
    let mut floor = 0;
    for &(k, at) in &latches {
        let mut want = nominal(k);
        if (10..20).contains(&k) {
            want += (unit_f64(&mut rng) * 2_500_000.0) as u64;
        }
        want = want.max(floor);
        floor = want;
        assert_eq!(at, want, "sample {k}");
    }
    assert!(
        latches.windows(2).any(|w| w[0].1 == w[1].1),
        "a jitter past the next instant"
    );
}

#[test]
fn missing_data_ready_keeps_the_int_pin_where_it_was() {
    let mut cfg = Configure::new(ChipModel::Mpu9250, rate_1khz());
    // INT_ENABLE (0x38) RAW_RDY_EN: a 50 µs active-high pulse per sample.
    cfg.overrides
        .push(RegisterOverride {
            file: 0,
            register: 0x38,
            value: 0x01,
        })
        .unwrap();
    let missing = Fault::new(0, win(10, 20), FaultKind::MissingDrdy { probability: 1.0 });
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    host.configure(&mut dev, cfg);
    add(&mut host, &mut dev, missing);
    host.images(&mut dev, 0, &images(0, 30), 0);
    host.start_scene(&mut dev, 30, 0);
    for k in 0..25u64 {
        let just_after = k * MS + 10_000;
        poll(&mut dev, just_after);
        let pulse = dev.int_pin_at(0, just_after);
        assert!(dev.chip().int_pin_at(just_after), "the chip pulses at {k}");
        assert_eq!(pulse, !(10..20).contains(&k), "sample {k}");
        let data = dev.last_served().unwrap();
        assert_eq!(
            (data.index, data.image),
            (k, Some(image(k))),
            "the data still update"
        );
    }
}
