//! QEMU test of a fault schedule (`docs/spec/link.md` §5.16): the scene's faults go to the
//! `qemu-mps2-an386` firmware as AddFault messages, and what it serves on the emulated
//! Cortex-M4F is checked against the host's prediction on x86-64:
//!
//! - source (b): the device's model applies the sensor faults (a stuck gyroscope, accelerometer
//!   noise, gyro spikes) and its serving loop the timing faults (late samples, a fast and
//!   drifting clock, data-ready jitter); every served image's CRC-32C equals the host's
//!   prediction (the same `margemu_model::fault::SensorFaults` code, noise and spike draws
//!   included), and every Served batch carries the latch instant the host's copy of the
//!   serving clock predicts;
//! - source (a): the same timing faults on an image stream (the images carry no sensor fault:
//!   source (a)'s are applied by the host's image prediction).
//!
//! The faults are filled into `Scene::faults` programmatically. Skipped, with a message, where
//! `qemu-system-arm` or a cross toolchain is missing; under `CI=true` that is a failure instead.

use margemu_model::fault::{Fault, FaultKind, Sensor, Window};
use margemu_tests::model_source::ModelStream;
use margemu_tests::motion_scene;
use margemu_tests::qemu;
use margemu_tests::qemu_session::{
    build_board, image_session, model_script, predicted_crcs, run_images, run_model, scratch,
};
use margemu_tests::served::{predicted_latches, ServedLog};

const MS: u64 = 1_000_000;

fn win(start_ms: u64, end_ms: u64) -> Window {
    Window::new(start_ms * MS, end_ms * MS)
}

/// The timing faults: samples 0.3 ms late, a clock 3000 ppm fast drifting by 2000 ppm/s, and
/// data-ready jitter of up to 0.8 ms.
fn timing() -> Vec<Fault> {
    vec![
        Fault::new(0, win(200, 300), FaultKind::Late { delay_ns: 300_000 }),
        Fault::new(
            0,
            win(400, 700),
            FaultKind::ClockOffset {
                ppm: 3_000.0,
                drift_ppm_per_s: 2_000.0,
            },
        ),
        Fault::new(0, win(800, 900), FaultKind::DrdyJitter { max_ns: 800_000 }),
    ]
}

/// Every Served batch's time against the host's copy of the serving clock; the shifted samples
/// (each a batch of its own) all reported. Returns how many were shifted.
fn check_latches(served: &ServedLog, latches: &[u64], rate: margemu_protocol::link::Rate) -> usize {
    for (&first, &time) in &served.batch_times {
        if let Some(&want) = latches.get(first as usize) {
            assert_eq!(time, want, "the batch starting at sample {first}");
        }
    }
    let shifted: Vec<u64> = (0..latches.len() as u64)
        .filter(|&k| latches[k as usize] != rate.sample_time_ns(k))
        .collect();
    for k in &shifted {
        assert!(
            served.batch_times.contains_key(k),
            "shifted sample {k} in a batch of its own"
        );
    }
    shifted.len()
}

#[test]
fn model_mode_serves_sensor_and_timing_faults_as_the_host_predicts() {
    if !qemu::prerequisites_or_skip("qemu_faults") {
        return;
    }
    let (elf, build) = build_board();
    let mut scene = motion_scene(500, 1.0, 9);
    let clean = ModelStream::from_scene(&scene, 5).unwrap();
    scene.faults = vec![
        Fault::new(
            0,
            win(100, 250),
            FaultKind::Stuck {
                sensor: Sensor::Gyr,
            },
        ),
        Fault::new(
            0,
            win(150, 500),
            FaultKind::Noise {
                sensor: Sensor::Acc,
                std: [0.5; 3],
            },
        ),
        Fault::new(
            0,
            win(600, 1000),
            FaultKind::Spikes {
                sensor: Sensor::Gyr,
                rate_hz: 40.0,
                amplitude: 1.5,
                axes: 0b101,
            },
        ),
    ];
    scene.faults.extend(timing());
    let stream = ModelStream::from_scene(&scene, 5).unwrap();
    assert_eq!(stream.faults.len(), 6);
    let differ = |a: usize, b: usize| {
        (a..b)
            .filter(|&k| stream.images[k] != clean.images[k])
            .count()
    };
    assert_eq!(differ(0, 50), 0, "before the first window");
    assert_eq!(differ(50, 125), 75, "the stuck gyroscope and the noise");
    assert!(differ(300, 500) > 0, "the spikes");

    let predicted = stream.predicted_crcs();
    let script = model_script(&stream, stream.configure(50_000_000));
    let run = run_model(&elf, &script, &predicted, 500);
    let latches = predicted_latches(&stream.faults, stream.out_rate, 500);
    let shifted = check_latches(&run.report.served, &latches, stream.out_rate);
    assert!(shifted > 150, "{shifted} samples shifted");
    eprintln!(
        "qemu_faults (model): build {build:.2?}, boot + stream {:.2?}: {} of {} images served \
         byte-exact under 6 faults; {shifted} samples latched off their instants, each as \
         predicted",
        run.streamed, run.check.exact, run.check.expected
    );
}

#[test]
fn image_mode_serves_timing_faults_as_the_host_predicts() {
    if !qemu::prerequisites_or_skip("qemu_faults") {
        return;
    }
    let (elf, _) = build_board();
    let mut scene = motion_scene(250, 1.0, 12);
    scene.faults = timing();
    let dir = scratch("faults-images");
    let session = image_session(&scene, &dir);
    let predicted = predicted_crcs(&scene, &session);
    let faults = margemu::stream::fault_messages(&scene);
    let run = run_images(&elf, session, &dir, &predicted, 250);
    let rate = margemu_protocol::link::Rate::hz(250).unwrap();
    let latches = predicted_latches(&faults, rate, 250);
    let shifted = check_latches(&run.served, &latches, rate);
    assert!(shifted > 75, "{shifted} samples shifted");
    eprintln!(
        "qemu_faults (images): {} of {} images served byte-exact; {shifted} samples latched off \
         their instants, each as predicted",
        run.check.exact, run.check.expected
    );
}
