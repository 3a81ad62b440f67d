//! A scene's fault schedule streamed to the real firmware `Device` on a virtual clock
//! ([`VirtualPort`]): the session sends one AddFault per fault, the device applies them, and
//! what it serves is what the host predicts, byte for byte, in both source modes — the sensor
//! faults inside the device's model in source (b), the timing faults moving the instants the
//! Served reports carry (`served.csv`'s `time_ns`) inside their windows only.

mod common;

use common::{assert_logs_valid, config, read_csv, scene, scratch};
use margemu::scene::Scene;
use margemu::stream::clock::VirtualClock;
use margemu::stream::VirtualPort;
use margemu::stream::{predict_model, ImageSettings, Session, SourceMode, StreamConfig};
use margemu_firmware::link::faults::clock_lead_ns;
use margemu_model::fault::{Fault, FaultKind, Sensor, Window};
use std::path::Path;

const MS: u64 = 1_000_000;

fn win(start_ms: u64, end_ms: u64) -> Window {
    Window::new(start_ms * MS, end_ms * MS)
}

/// Sensor faults on device 0, and a late window and a fast clock.
fn schedule() -> Vec<Fault> {
    vec![
        Fault::new(
            0,
            win(100, 200),
            FaultKind::Stuck {
                sensor: Sensor::Gyr,
            },
        ),
        Fault::new(
            0,
            win(150, 400),
            FaultKind::Noise {
                sensor: Sensor::Acc,
                std: [0.3; 3],
            },
        ),
        Fault::new(0, win(250, 300), FaultKind::Late { delay_ns: 400_000 }),
        Fault::new(
            0,
            win(500, 600),
            FaultKind::ClockOffset {
                ppm: 5_000.0,
                drift_ppm_per_s: 0.0,
            },
        ),
        Fault::new(
            0,
            win(600, 800),
            FaultKind::Spikes {
                sensor: Sensor::Gyr,
                rate_hz: 50.0,
                amplitude: 2.0,
                axes: 0b111,
            },
        ),
    ]
}

fn faulty_scene() -> Scene {
    let mut s = scene(1.0, 1000.0);
    s.faults = schedule();
    s
}

/// `served.csv`: (index, time_ns, match) of the scene's samples.
fn served(dir: &Path) -> Vec<(u64, u64, bool)> {
    let (_, rows) = read_csv(dir, "served.csv");
    rows.iter()
        .map(|r| (r[1].parse().unwrap(), r[2].parse().unwrap(), r[6] == "1"))
        .filter(|&(k, _, _)| k < 1000)
        .collect()
}

fn run(name: &str, scene: &Scene, source: SourceMode) -> std::path::PathBuf {
    let clock = VirtualClock::new();
    let device: VirtualPort<256> = VirtualPort::new(clock.clone(), 100_000);
    let dir = scratch(&format!("fault-schedule-{name}"));
    let config = StreamConfig {
        port: "virtual".into(),
        source,
        ..config()
    };
    let session = Session::new(scene, config, &dir).unwrap();
    let summary = session.run_with(device, |_| {}).unwrap();
    let v = summary.served;
    assert_eq!(
        (v.byte_exact, v.mismatched, v.unreported),
        (1000, 0, 0),
        "{name}: {v:?}"
    );
    assert_logs_valid(&dir);
    dir
}

/// Where the timing faults put sample `k` (1 kHz).
fn latch(k: u64) -> u64 {
    let t = k * MS;
    match k {
        250..=299 => t + 400_000,
        500..=599 => t - clock_lead_ns(5_000.0, 0.0, t - 500 * MS).round() as u64,
        _ => t,
    }
}

#[test]
fn both_sources_serve_the_prediction_and_report_the_faulted_instants() {
    let scene = faulty_scene();
    let model = SourceMode::Model {
        kinematics_hz: Some(500.0),
    };
    for (name, source) in [("images", SourceMode::Images), ("model", model)] {
        let dir = run(name, &scene, source);
        let rows = served(&dir);
        assert_eq!(rows.len(), 1000, "{name}");
        for (k, time, ok) in rows {
            assert!(ok, "{name}: sample {k}");
            assert_eq!(time, latch(k), "{name}: sample {k}");
        }
    }
}

#[test]
fn source_b_serves_the_sensor_faults_inside_their_windows_only() {
    let settings = |s: &Scene| ImageSettings::for_scene(s);
    let images = |s: &Scene| -> Vec<_> {
        let p = predict_model(s, &settings(s), Some(500.0)).unwrap();
        p.samples.map(|s| s.unwrap().sample.image).collect()
    };
    let clean = images(&scene(1.0, 1000.0));
    let faulty = images(&faulty_scene());
    // MPU-9250 image: accel at bytes 0..6, gyro at 8..14.
    let gyro = |im: &margemu_protocol::link::Image| im[8..14].to_vec();
    let accel = |im: &margemu_protocol::link::Image| im[0..6].to_vec();
    assert_eq!(faulty[..100], clean[..100]);
    assert!((100..200).all(|k| gyro(&faulty[k]) == gyro(&clean[99])));
    assert!(
        (150..400)
            .filter(|&k| accel(&faulty[k]) != accel(&clean[k]))
            .count()
            > 240
    );
    assert_eq!(
        faulty[400..600],
        clean[400..600],
        "timing faults leave the data alone"
    );
    let spikes = (600..800)
        .filter(|&k| gyro(&faulty[k]) != gyro(&clean[k]))
        .count();
    assert!(
        (2..30).contains(&spikes),
        "{spikes} spikes at 50/s over 0.2 s"
    );
    assert_eq!(faulty[800..], clean[800..]);
}

#[test]
fn a_schedule_the_device_would_refuse_is_refused_before_anything_is_sent() {
    let mut s = scene(0.1, 1000.0);
    s.faults = vec![Fault::new(1, win(0, 10), FaultKind::Late { delay_ns: 10 })];
    let dir = scratch("fault-schedule-refused");
    let err = Session::new(&s, config(), &dir).err().expect("refused");
    let text = err.to_string();
    assert!(text.contains("fault 1 (late on device 1)"), "{text}");
    assert!(!dir.exists(), "nothing written");
    s.faults = vec![Fault::new(0, win(0, 10), FaultKind::Nak); 17];
    let err = Session::new(&s, config(), &dir).err().expect("refused");
    assert!(err.to_string().contains("17 faults"), "{err}");
}

/// The schedule's sensor faults and a dropout: source (a)'s images (the host's model) and
/// source (b)'s (the device's model, kinematics at the output rate) are the same bytes, with
/// the faults and without.
#[test]
fn both_source_modes_serve_the_same_faulted_bytes() {
    use margemu::stream::predict_images;
    let with_dropout = |mut s: Scene| {
        s.faults.push(Fault::new(
            0,
            win(850, 900),
            FaultKind::Dropout {
                sensor: Sensor::Acc,
            },
        ));
        s
    };
    let (clean, faulty) = (scene(1.0, 1000.0), with_dropout(faulty_scene()));
    let mut per_scene = Vec::new();
    for s in [&clean, &faulty] {
        let settings = ImageSettings::for_scene(s);
        // Source (b)'s die temperature without a `[sensors] temperature` ramp.
        let images_settings = ImageSettings {
            default_temp_c: margemu_firmware::link::setup::DEFAULT_TEMP_C,
            ..settings
        };
        let a: Vec<_> = predict_images(s, &images_settings)
            .map(|p| p.unwrap().image)
            .collect();
        let b: Vec<_> = predict_model(s, &settings, Some(1000.0))
            .unwrap()
            .samples
            .map(|p| p.unwrap().sample.image)
            .collect();
        assert_eq!(a.len(), 1000);
        for (k, (x, y)) in a.iter().zip(&b).enumerate() {
            assert_eq!(x, y, "sample {k}");
        }
        per_scene.push(a);
    }
    let differ = per_scene[0]
        .iter()
        .zip(&per_scene[1])
        .filter(|(c, f)| c != f)
        .count();
    // The faults changed the bytes (stuck, noise, spikes, the dropout's −32768), in both modes.
    assert!(differ > 300, "{differ} samples differ");
    assert_eq!(
        &per_scene[1][860][0..2],
        &[0x80, 0x00],
        "dropout: ACCEL_XOUT = −32768"
    );
}
