//! A session's memory does not depend on the scene's length: a scene of 10⁹ samples (10⁶ s at
//! 1 kHz) streams to the real firmware `Device` behind a PTY pair, in either source mode, and is
//! stopped by the session's stop flag once a few thousand samples were served, every one byte for
//! byte the prediction. The session predicts lazily, so it starts at once and its logs cover what
//! it predicted, not the scene; the process's peak resident memory stays far below what one
//! byte per sample would take.
//!
//! In a file of its own so that the peak memory is this test binary's alone.

mod common;

use common::{config, read_csv, scratch};
use margemu::loopback::spawn_device;
use margemu::scene::Scene;
use margemu::stream::{Progress, ServedStats, Session, SourceMode, StreamConfig, StreamError};
use serialport::TTYPort;
use std::path::Path;
use std::sync::atomic::Ordering;

/// 10⁶ s at 1 kHz: 10⁹ samples.
fn endless_scene() -> Scene {
    let text = "duration = 1e6\nrate = 1000.0\nseed = 11\nmotion = \"kinematic\"\n\
         [joints.roll]\ntype = \"sine\"\namplitude = 0.8\nfrequency = 2.0\n\
         [sensors.gyro]\nnoise_density = [0.01, 0.01, 0.01]\n";
    Scene::parse_str(text, Path::new("endless.toml")).unwrap()
}

/// Served samples after which the test stops the session.
const SERVED: u64 = 3000;

/// Streams the endless scene until `SERVED` samples were confirmed; returns what the device
/// had reported serving by then.
fn stream_until_stopped(config: StreamConfig, dir: &Path) -> ServedStats {
    let scene = endless_scene();
    assert_eq!(scene.samples(), 1_000_000_000);
    let (host, device) = TTYPort::pair().unwrap();
    let session = Session::new(&scene, config, dir).unwrap();
    assert_eq!(session.sample_count(), 1_000_000_000);
    let device = spawn_device(device).unwrap();
    let stop = session.stop_flag();
    let mut last = None;
    let result = session.run_on_port(host, |p: &Progress| {
        if p.served.byte_exact >= SERVED {
            stop.store(true, Ordering::Relaxed);
        }
        last = Some(p.served);
    });
    device.stop();
    assert!(
        matches!(result, Err(StreamError::Interrupted)),
        "{:?}",
        result.map(|s| s.served)
    );
    last.expect("progress was reported")
}

/// The served rows all match the prediction, and the logs hold about what was streamed.
fn assert_logs_bounded(dir: &Path, served: &ServedStats) {
    let (_, rows) = read_csv(dir, "served.csv");
    assert!(rows.len() as u64 >= SERVED);
    assert!(
        rows.iter().all(|r| r[6] == "1"),
        "a served image mismatched"
    );
    let (_, truth) = read_csv(dir, "truth.csv");
    let predicted = truth.len() as u64;
    assert!(predicted >= served.byte_exact, "{predicted} truth rows");
    assert!(
        predicted < 100_000,
        "{predicted} truth rows: predicted far ahead"
    );
}

/// The peak resident memory of this process, kB (`VmHWM`).
fn peak_rss_kb() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap();
    let line = status.lines().find(|l| l.starts_with("VmHWM:")).unwrap();
    line.split_whitespace().nth(1).unwrap().parse().unwrap()
}

fn check(served: &ServedStats) {
    assert_eq!(served.samples, 1_000_000_000);
    assert!(served.byte_exact >= SERVED, "{served:?}");
    assert_eq!(
        (served.mismatched, served.underruns, served.unverifiable),
        (0, 0, 0),
        "{served:?}"
    );
    // One byte per sample would be 1 GB.
    let peak = peak_rss_kb();
    assert!(peak < 256 * 1024, "peak resident memory {peak} kB");
    println!("{served:?}; peak resident memory {peak} kB");
}

#[test]
fn a_billion_sample_scene_streams_images_in_bounded_memory() {
    let dir = scratch("bounded-images");
    let served = stream_until_stopped(config(), &dir);
    check(&served);
    assert_logs_bounded(&dir, &served);
    let (_, sent) = read_csv(&dir, "sent.csv");
    assert!(sent.len() as u64 >= served.byte_exact);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_billion_sample_scene_streams_kinematics_in_bounded_memory() {
    let dir = scratch("bounded-model");
    let config = StreamConfig {
        source: SourceMode::Model {
            kinematics_hz: Some(250.0),
        },
        ..config()
    };
    let served = stream_until_stopped(config, &dir);
    check(&served);
    assert_logs_bounded(&dir, &served);
    let (_, sent) = read_csv(&dir, "sent.csv");
    assert!(sent.len() as u64 * 4 >= served.byte_exact);
    std::fs::remove_dir_all(&dir).unwrap();
}
