//! `margemu::stream` over a real pseudo-terminal pair against the real firmware link handler
//! (`margemu_firmware::link::Device`, the loopback device): a complete session and its logs, a
//! device under test writing registers, a device that vanishes, one that reboots mid-run, the
//! stop flag (Ctrl-C), a silent port. One behaviour the real device cannot produce (speaking
//! another protocol version) uses a fake device, named so.

mod common;

use common::{assert_logs_valid, config, read_csv, scene, scratch};
use margemu::loopback::{spawn_device, spawn_device_with, Firmware};
use margemu::stream::{predict_images, Session, StreamConfig, StreamError};
use margemu_firmware::chip::SpiTarget;
use margemu_firmware::link::{Device, Identity};
use margemu_protocol::chip::Image;
use margemu_protocol::link::{
    Accumulator, DeviceState, Encoder, FeedResult, FrameRepr, HelloAck, Message, ResetCause,
    MAX_WIRE_LEN,
};
use margemu_protocol::PROTOCOL_VERSION;
use serialport::{SerialPort, TTYPort};
use std::io::{Read, Write};
use std::ops::ControlFlow;
use std::time::{Duration, Instant};

/// PWR_MGMT_1 = 0x01 over the chip's SPI target, as a driver starting up would write it.
fn dut_writes_pwr_mgmt(device: &mut Firmware) {
    let chip = device.chip_mut();
    chip.select();
    chip.exchange(0x6B);
    chip.exchange(0x01);
    chip.deselect();
}

#[test]
fn a_short_scene_streams_end_to_end_byte_for_byte() {
    let scene = scene(1.0, 1000.0);
    let dir = scratch("ok");
    let (host, device) = TTYPort::pair().unwrap();
    let mut wrote = false;
    let device = spawn_device_with(device, move |dev, _| {
        if !wrote && dev.state() == DeviceState::Running {
            dut_writes_pwr_mgmt(dev);
            wrote = true;
        }
        ControlFlow::Continue(())
    })
    .unwrap();
    let session = Session::new(&scene, config(), &dir).unwrap();
    let predicted: Vec<_> = predict_images(&scene, session.image_settings())
        .map(|s| s.unwrap().image)
        .collect();
    let summary = session.run_on_port(host, |_| {}).unwrap();
    let report = device.stop();
    assert_eq!((summary.sent, summary.stream_len), (1000, 1000));
    let s = summary.served;
    assert_eq!(
        (s.byte_exact, s.mismatched, s.lost()),
        (1000, 0, 0),
        "{s:?}"
    );
    assert_eq!(report.counters.overruns, 0, "host beyond the credit window");
    assert_eq!(report.state, DeviceState::Stopped);
    let t = summary.telemetry.unwrap();
    assert_eq!(t.state, DeviceState::Stopped);
    assert!(t.last_served_index >= 999, "{t:?}");
    assert!(summary.jitter.batches > 0);
    // Logs: complete and parseable.
    assert_logs_valid(&dir);
    let meta: toml::Table = std::fs::read_to_string(dir.join("meta.toml"))
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(meta["samples"].as_integer(), Some(1000));
    assert_eq!(meta["source"].as_str(), Some("images"));
    assert_eq!(meta["image"]["accel_fs"].as_str(), Some("G2"));
    let buffer = margemu::loopback::BUFFER as i64;
    assert_eq!(meta["device"]["buffer_capacity"].as_integer(), Some(buffer));
    let (_, truth) = read_csv(&dir, "truth.csv");
    assert_eq!(truth.len(), 1000);
    let (_, sent) = read_csv(&dir, "sent.csv");
    let first_copies: Vec<_> = sent.iter().filter(|r| r[5] == "0").collect();
    assert_eq!(first_copies.len(), 1000);
    for (k, row) in first_copies.iter().enumerate() {
        assert_eq!(row[0].parse::<u64>().unwrap(), k as u64);
        assert_eq!(row[1], truth[k][0], "t_ns of sample {k}");
        row[2].parse::<i64>().unwrap();
        assert!(row[3].is_empty() || row[3].parse::<i64>().is_ok());
        assert_eq!(Image::parse_hex(&row[4], 22), Some(predicted[k]));
    }
    let (_, served) = read_csv(&dir, "served.csv");
    assert!(served.len() >= 1000);
    let (_, device) = read_csv(&dir, "device.csv");
    let last = device.last().unwrap();
    assert!(last[3].parse::<u64>().unwrap() >= 999);
    assert_eq!(last[4], last[5], "served at the instant the host scheduled");
    let (_, telemetry) = read_csv(&dir, "telemetry.csv");
    assert!(telemetry.len() >= 20, "every 20 ms for 1 s");
    let (_, writes) = read_csv(&dir, "register_writes.csv");
    assert_eq!(&writes[0][2..6], &["spi", "0", "107", "1"], "{writes:?}");
    let (_, events) = read_csv(&dir, "events.csv");
    assert_eq!(
        events.last().unwrap()[1..],
        ["end".to_string(), "completed".to_string()]
    );
}

#[test]
fn a_device_that_vanishes_stops_the_session_with_valid_logs() {
    let scene = scene(2.0, 1000.0);
    let dir = scratch("vanish");
    let (host, device) = TTYPort::pair().unwrap();
    let device = spawn_device_with(device, |dev, _| match dev.counters().served >= 300 {
        true => ControlFlow::Break("vanished".into()),
        false => ControlFlow::Continue(()),
    })
    .unwrap();
    let session = Session::new(&scene, config(), &dir).unwrap();
    let started = Instant::now();
    let err = session.run_on_port(host, |_| {}).unwrap_err();
    let report = device.stop();
    assert_eq!(report.ended, "vanished");
    assert!(matches!(err, StreamError::Disconnected { .. }), "{err}");
    assert!(
        err.to_string().starts_with("the device disconnected"),
        "{err}"
    );
    assert!(
        started.elapsed() < Duration::from_millis(1500),
        "stopped promptly"
    );
    let events = assert_logs_valid(&dir);
    let end = events.last().unwrap();
    assert!(
        end[2].starts_with("error: the device disconnected"),
        "{end:?}"
    );
    let (_, sent) = read_csv(&dir, "sent.csv");
    assert!(sent.len() >= 300 && sent.len() < 2000, "{}", sent.len());
    assert!(sent.iter().all(|r| Image::parse_hex(&r[4], 22).is_some()));
    let served = common::served(&dir, 2000);
    assert!(served.len() >= 250, "{}", served.len());
    assert!(served.iter().all(|&(_, underrun, ok)| ok && !underrun));
}

#[test]
fn no_device_on_the_port_is_a_hello_timeout() {
    let scene = scene(0.1, 1000.0);
    let dir = scratch("silent");
    let (_device, host) = TTYPort::pair().unwrap();
    let config = StreamConfig {
        hello_timeout: Duration::from_millis(300),
        ..config()
    };
    let session = Session::new(&scene, config, &dir).unwrap();
    let err = session.run_on_port(host, |_| {}).unwrap_err();
    assert!(matches!(err, StreamError::HelloTimeout { .. }), "{err}");
    let events = assert_logs_valid(&dir);
    assert!(events.last().unwrap()[2].starts_with("error: no HelloAck"));
}

#[test]
fn a_device_reset_mid_run_stops_the_session() {
    let scene = scene(2.0, 1000.0);
    let dir = scratch("reset");
    let (host, device) = TTYPort::pair().unwrap();
    // The board reboots (its watchdog fired): a fresh device announces the reset.
    let device = spawn_device_with(device, |dev, _| {
        if dev.counters().served >= 200 {
            *dev = Device::with_identity(Identity::default(), ResetCause::Watchdog);
        }
        ControlFlow::Continue(())
    })
    .unwrap();
    let session = Session::new(&scene, config(), &dir).unwrap();
    let err = session.run_on_port(host, |_| {}).unwrap_err();
    device.stop();
    assert!(matches!(err, StreamError::DeviceReset { .. }), "{err}");
    assert_eq!(
        err.to_string(),
        "the device reset mid-session (cause: Watchdog)"
    );
    let events = assert_logs_valid(&dir);
    assert!(events
        .iter()
        .any(|e| e[1] == "device_reset" && e[2] == "Watchdog"));
    let (_, device) = read_csv(&dir, "device.csv");
    assert!(!device.is_empty());
}

#[test]
fn the_stop_flag_interrupts_with_flushed_logs() {
    let scene = scene(5.0, 1000.0);
    let dir = scratch("interrupt");
    let (host, device) = TTYPort::pair().unwrap();
    // Held open after the session ends, as a serial line stays: the Stop is still delivered.
    let _line = host.try_clone_native().unwrap();
    let device = spawn_device(device).unwrap();
    let session = Session::new(&scene, config(), &dir).unwrap();
    let stop = session.stop_flag();
    // What a Ctrl-C handler does.
    std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(300));
        stop.store(true, std::sync::atomic::Ordering::Relaxed);
    });
    let err = session.run_on_port(host, |_| {}).unwrap_err();
    assert!(matches!(err, StreamError::Interrupted), "{err}");
    // The device serves what it holds (a graceful stop: up to the 200 ms lead), then stops.
    std::thread::sleep(Duration::from_millis(400));
    let report = device.stop();
    assert_eq!(
        report.state,
        DeviceState::Stopped,
        "the device was asked to stop"
    );
    let events = assert_logs_valid(&dir);
    assert!(events.last().unwrap()[2].starts_with("error: interrupted"));
    let (_, sent) = read_csv(&dir, "sent.csv");
    assert!(sent.len() >= 300 && sent.len() < 1000, "{}", sent.len());
    // Every sample the device served was logged as sent before it was written to the port.
    assert!(report.counters.served <= sent.len() as u64);
}

#[test]
fn the_cli_names_a_silent_port() {
    let (_device, host) = TTYPort::pair().unwrap();
    let path = host.name().unwrap();
    let dir = scratch("cli");
    let scene = format!(
        "{}/../hil-fixtures/scenes/static.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args([
            "stream",
            &scene,
            "--port",
            &path,
            "-o",
            dir.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("no HelloAck within 2s"), "{stderr}");
    assert!(dir.join("meta.toml").exists() && dir.join("truth.csv").exists());
    let ports = std::process::Command::new(env!("CARGO_BIN_EXE_margemu"))
        .arg("ports")
        .output()
        .unwrap();
    assert!(ports.status.success());
}

/// A fake device that answers Hello with a HelloAck of the next protocol version (the real
/// device speaks only the current one), then stays on the line until the host closes it.
fn fake_device_of_the_next_protocol_version(mut port: TTYPort) -> std::thread::JoinHandle<()> {
    port.set_timeout(Duration::from_millis(5)).unwrap();
    std::thread::spawn(move || {
        let (mut acc, mut enc) = (Accumulator::new(), Encoder::new());
        let (mut buf, mut wire) = ([0u8; 256], [0u8; MAX_WIRE_LEN]);
        let deadline = Instant::now() + Duration::from_secs(3);
        while Instant::now() < deadline {
            let n = match port.read(&mut buf) {
                Ok(0) => return,
                Ok(n) => n,
                Err(e) if e.kind() == std::io::ErrorKind::TimedOut => continue,
                Err(_) => return,
            };
            let mut input = &buf[..n];
            while !input.is_empty() {
                let r = acc.feed(input);
                input = r.remaining();
                if let FeedResult::Success { frame, .. } = r {
                    if let Ok(Message::Hello(h)) = FrameRepr::parse(&frame).map(|f| f.message) {
                        let ack = HelloAck {
                            protocol_version: PROTOCOL_VERSION + 1,
                            session: h.session,
                            capabilities: Device::<8>::capabilities(),
                            ..HelloAck::default()
                        };
                        let n = enc.encode(&Message::HelloAck(ack), &mut wire).unwrap();
                        port.write_all(&wire[..n]).unwrap();
                    }
                }
            }
        }
    })
}

#[test]
fn fake_device_of_another_protocol_version_is_refused() {
    let scene = scene(0.1, 1000.0);
    let dir = scratch("version");
    let (host, device) = TTYPort::pair().unwrap();
    let fake = fake_device_of_the_next_protocol_version(device);
    let session = Session::new(&scene, config(), &dir).unwrap();
    let err = session.run_on_port(host, |_| {}).unwrap_err();
    fake.join().unwrap();
    assert_eq!(
        err.to_string(),
        format!(
            "the device speaks link protocol {}, this host {PROTOCOL_VERSION}",
            PROTOCOL_VERSION + 1
        )
    );
    let events = assert_logs_valid(&dir);
    assert!(events.iter().any(|e| e[1] == "hello_ack"));
    let (_, sent) = read_csv(&dir, "sent.csv");
    assert!(sent.is_empty(), "nothing streamed");
}
