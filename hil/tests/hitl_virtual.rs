//! A HITL session on a [`VirtualClock`]: every frame is written exactly at its instant, the
//! HEARTBEATs fall at scene seconds 0, 1, 2, and the files say so; nothing here depends on the
//! machine's load.

use margemu_hil::dut::mavlink_in::MavlinkDecoder;
use margemu_hil::hitl::{HitlConfig, HitlSession, HIL_SENSOR_COLUMNS, HIL_SENSOR_FILE};
use margemu_hil::stream::clock::{Clock, VirtualClock};
use margemu_sim::scene::Scene;
use std::sync::atomic::AtomicBool;

const SCENE: &str = "duration = 2.5\nrate = 200.0\nseed = 3\nmotion = \"kinematic\"\n\
[joints.roll]\ntype = \"sine\"\namplitude = 0.2\nfrequency = 1.0\n";

fn dir(name: &str) -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn every_frame_goes_at_its_instant() {
    let scene = Scene::parse_str(SCENE, "virtual.toml".as_ref()).unwrap();
    let dir = dir("hitl_virtual");
    let config = HitlConfig {
        start_delay_ns: 5_000_000,
        ..HitlConfig::default()
    };
    let session = HitlSession::new(&scene, config, &dir).unwrap();
    let clock = VirtualClock::new();
    clock.advance(1_000);
    let mut wire = Vec::new();
    let summary = session
        .run(&mut wire, &clock, &AtomicBool::new(false))
        .unwrap();
    assert_eq!(summary.samples, 500);
    assert_eq!(summary.heartbeats, 3);
    assert_eq!(summary.start_host_ns, 5_001_000);
    assert_eq!(summary.max_late_ns, 0);
    assert_eq!(clock.now_ns(), 5_001_000 + 2_495_000_000);

    // The wire holds exactly those frames, in order: HEARTBEAT before samples 0, 200, 400.
    let mut decoder = MavlinkDecoder::new();
    let mut decoded = Vec::new();
    decoder.feed(&wire, &mut decoded);
    let names: Vec<&str> = decoded.iter().map(|d| d.message.name.as_ref()).collect();
    assert_eq!(names.len(), 503);
    for (i, at) in [0, 201, 402].into_iter().enumerate() {
        assert_eq!(names[at], "HEARTBEAT", "heartbeat {i}");
    }
    assert_eq!(names.iter().filter(|n| **n == "HIL_SENSOR").count(), 500);
    assert_eq!(decoder.counters().bad_bytes, 0);

    let text = std::fs::read_to_string(dir.join(HIL_SENSOR_FILE)).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next().unwrap(), HIL_SENSOR_COLUMNS.join(","));
    for (k, line) in lines.enumerate() {
        let f: Vec<&str> = line.split(',').collect();
        let t_ns = scene.clock.instant(k as u64);
        assert_eq!(f[0], k.to_string());
        assert_eq!(f[1], t_ns.to_string());
        assert_eq!(f[2], (5_001_000 + t_ns).to_string(), "sent at its instant");
        assert_eq!(f[3], "0");
        assert_eq!(f[4], (t_ns / 1000).to_string());
        assert_eq!(f[17], "7167");
    }
    let events = std::fs::read_to_string(dir.join("events.csv")).unwrap();
    assert!(
        events.contains("1000,start,start_host_ns 5001000; 500 samples at 200 Hz"),
        "{events}"
    );
    assert!(events.trim_end().ends_with(",end,completed"), "{events}");
    let meta = std::fs::read_to_string(dir.join("meta.toml")).unwrap();
    assert!(
        meta.contains("status = \"complete\"") && meta.contains("samples_written = 500"),
        "{meta}"
    );
}

#[test]
fn a_stop_ends_the_session_as_interrupted() {
    let scene = Scene::parse_str(SCENE, "virtual.toml".as_ref()).unwrap();
    let dir = dir("hitl_virtual_stop");
    let session = HitlSession::new(&scene, HitlConfig::default(), &dir).unwrap();
    let e = session
        .run(Vec::new(), &VirtualClock::new(), &AtomicBool::new(true))
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "interrupted; the files hold the samples written so far"
    );
    let meta = std::fs::read_to_string(dir.join("meta.toml")).unwrap();
    assert!(meta.contains("status = \"interrupted\""), "{meta}");
}
