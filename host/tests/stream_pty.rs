//! `margemu::stream` over a real pseudo-terminal pair, against a fake device.
//!
//! The firmware's link handler is not available to these tests yet, so the far end of the PTY is
//! [`fake_device_speaking_the_protocol`]: a small device written here with `protocol::link` that
//! answers Hello, grants absolute credit windows, buffers Images, serves one sample per instant
//! on its own clock (recording what it served), and reports Telemetry. It can also damage its
//! own frames (flipped bits, garbage between frames) and vanish mid-run.

use margemu::scene::Scene;
use margemu::stream::{parse_image_hex, Session, StreamConfig, StreamError};
use margemu_protocol::link::{
    Accumulator, Bus, Capabilities, Chips, Credit, DeviceState, Encoder, FeedResult, FrameRepr,
    HelloAck, Image, Message, Modes, Rate, RegisterWrite, RegisterWriteBatch, Reset, ResetCause,
    Telemetry, MAX_WIRE_LEN,
};
use margemu_protocol::PROTOCOL_VERSION;
use serialport::{SerialPort, TTYPort};
use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How the fake device misbehaves.
#[derive(Clone, Copy, Default)]
struct Faults {
    /// Before every `n`-th frame after Start: garbage bytes, then a bit-flipped copy of it.
    damage_every: Option<u32>,
    /// Drop the PTY (vanish) once this many samples were received.
    vanish_after: Option<u64>,
    /// Announce a reboot (Reset, as after a watchdog reset) once this many samples were served.
    reset_after: Option<u64>,
}

/// What the fake device saw and did.
#[derive(Default, Debug)]
struct DeviceRecord {
    /// Every image received, by index (the first copy).
    received: BTreeMap<u64, Image>,
    /// (index, image) served at each sample instant, in order; underruns are not in it.
    served: Vec<(u64, Image)>,
    underruns: u32,
    /// The indices whose instant passed without their image.
    underrun_indices: Vec<u64>,
    overruns: u32,
    rx_damaged: u32,
    damaged_sent: u32,
    stopped: bool,
}

const CAPACITY: u32 = 512;
const TELEMETRY_EVERY: Duration = Duration::from_millis(20);

/// A fake device on the master end of the PTY, in a thread; see the module docs.
fn fake_device_speaking_the_protocol(
    mut port: TTYPort,
    faults: Faults,
) -> JoinHandle<DeviceRecord> {
    port.set_timeout(Duration::from_millis(2)).unwrap();
    std::thread::spawn(move || {
        let mut dev = Fake {
            enc: Encoder::new(),
            wire: vec![0; MAX_WIRE_LEN],
            rec: DeviceRecord::default(),
            rate: None,
            start: None,
            next_serve: 0,
            last_credit: 0,
            last_telemetry: Instant::now(),
            frames_after_start: 0,
            faults,
            gone: false,
            last_served: None,
        };
        dev.send(
            &mut port,
            &Message::Reset(Reset {
                cause: ResetCause::PowerOn,
            }),
        );
        let mut acc = Accumulator::new();
        let mut buf = [0u8; 4096];
        let mut idle_since = Instant::now();
        loop {
            let n = match port.read(&mut buf) {
                Ok(0) => return dev.rec,
                Ok(n) => n,
                Err(e) if e.kind() == std::io::ErrorKind::TimedOut => 0,
                Err(_) => return dev.rec,
            };
            if n > 0 {
                idle_since = Instant::now();
            }
            // Serve the instants that passed while reading, before acting on what arrived
            // (a board does this from its timer interrupt).
            dev.tick(&mut port);
            let mut input = &buf[..n];
            while !input.is_empty() {
                let result = acc.feed(input);
                input = result.remaining();
                match result {
                    FeedResult::Consumed => {}
                    FeedResult::Success { frame, .. } => match FrameRepr::parse(&frame) {
                        Ok(repr) => dev.on_message(&mut port, repr.message),
                        Err(_) => dev.rec.rx_damaged += 1,
                    },
                    _ => dev.rec.rx_damaged += 1,
                }
            }
            dev.tick(&mut port);
            if dev.gone {
                return dev.rec; // drops the PTY master: the host sees the device vanish
            }
            if (dev.rec.stopped || dev.start.is_none())
                && idle_since.elapsed() > Duration::from_secs(3)
            {
                return dev.rec;
            }
        }
    })
}

struct Fake {
    enc: Encoder,
    wire: Vec<u8>,
    rec: DeviceRecord,
    rate: Option<Rate>,
    start: Option<Instant>,
    next_serve: u64,
    last_credit: u64,
    last_telemetry: Instant,
    frames_after_start: u32,
    faults: Faults,
    gone: bool,
    last_served: Option<(u64, u64)>,
}

impl Fake {
    fn send(&mut self, port: &mut TTYPort, message: &Message<'_>) {
        let n = self.enc.encode(message, &mut self.wire).unwrap();
        if self.start.is_some() {
            self.frames_after_start += 1;
            if let Some(every) = self.faults.damage_every {
                if self.frames_after_start % every == 0 {
                    // Garbage, then this very frame with one bit flipped (same sequence number):
                    // two damaged frames, and the intact copy right after them.
                    let mut bad = self.wire[..n].to_vec();
                    bad[n / 2] ^= 0x10;
                    let _ = port.write_all(&[0x00, 0x42, 0x13, 0x37, 0xFF, 0x07]);
                    let _ = port.write_all(&bad);
                    self.rec.damaged_sent += 2;
                }
            }
        }
        let _ = port.write_all(&self.wire[..n]);
    }

    fn contiguous(&self) -> u64 {
        let mut k = self.next_serve;
        while self.rec.received.contains_key(&k) {
            k += 1;
        }
        k
    }

    fn credit(&self) -> Credit {
        Credit {
            next_index: self.contiguous(),
            limit: self.next_serve + u64::from(CAPACITY),
        }
    }

    fn on_message(&mut self, port: &mut TTYPort, message: Message<'_>) {
        match message {
            Message::Hello(h) => {
                let ack = HelloAck {
                    protocol_version: PROTOCOL_VERSION,
                    session: h.session,
                    capabilities: Capabilities {
                        chips: Chips::MPU9250,
                        modes: Modes::IMAGES,
                        max_batch: 64,
                        buffer_capacity: CAPACITY,
                        ..Capabilities::default()
                    },
                    ..HelloAck::default()
                };
                self.send(port, &Message::HelloAck(ack));
            }
            Message::Configure(c) => {
                self.rate = Some(c.rate);
                let credit = self.credit();
                self.last_credit = credit.limit;
                self.send(port, &Message::Credit(credit));
            }
            Message::Images(batch) => {
                let limit = self.credit().limit;
                for (i, image) in batch.images.iter().enumerate() {
                    let k = batch.first_index + i as u64;
                    if k >= limit {
                        self.rec.overruns += 1;
                    } else if k >= self.next_serve {
                        self.rec.received.entry(k).or_insert(image);
                    }
                }
                if let Some(n) = self.faults.vanish_after {
                    if self.rec.received.len() as u64 >= n {
                        self.gone = true;
                    }
                }
            }
            Message::Start(_) => {
                self.start = Some(Instant::now());
                // The device under test configures the chip: logged as register writes.
                let writes = [RegisterWrite {
                    time_ns: 0,
                    bus: Bus::Spi,
                    address: 0,
                    register: 0x6B,
                    value: 0x01,
                }];
                self.send(
                    port,
                    &Message::RegisterWrites(RegisterWriteBatch::new(0, &writes)),
                );
            }
            Message::Stop => {
                self.rec.stopped = true;
                let t = self.telemetry();
                self.send(port, &Message::Telemetry(t));
            }
            _ => {}
        }
    }

    fn telemetry(&self) -> Telemetry {
        let credit = self.credit();
        let (last_index, last_time) = self.last_served.unwrap_or((0, 0));
        Telemetry {
            time_ns: self.start.map_or(0, |s| s.elapsed().as_nanos() as u64),
            state: if self.rec.stopped {
                DeviceState::Stopped
            } else if self.start.is_some() {
                DeviceState::Running
            } else {
                DeviceState::Configured
            },
            samples_served: self.next_serve,
            underruns: self.rec.underruns,
            overruns: self.rec.overruns,
            crc_errors: 0,
            framing_errors: self.rec.rx_damaged,
            lost_frames: 0,
            rejected_messages: 0,
            buffer_level: self.rec.received.range(self.next_serve..).count() as u32,
            next_index: credit.next_index,
            credit_limit: credit.limit,
            last_served_index: last_index,
            last_served_time_ns: last_time,
        }
    }

    /// Serves every sample whose instant has passed; sends Credit and Telemetry when due.
    fn tick(&mut self, port: &mut TTYPort) {
        let (Some(start), Some(rate)) = (self.start, self.rate) else {
            return;
        };
        if self.rec.stopped {
            return;
        }
        let now = start.elapsed().as_nanos() as u64;
        while rate.sample_time_ns(self.next_serve) <= now {
            let k = self.next_serve;
            match self.rec.received.get(&k) {
                Some(image) => self.rec.served.push((k, *image)),
                None => {
                    self.rec.underruns += 1;
                    self.rec.underrun_indices.push(k);
                }
            }
            self.last_served = Some((k, rate.sample_time_ns(k)));
            self.next_serve += 1;
        }
        if self
            .faults
            .reset_after
            .is_some_and(|n| self.next_serve >= n)
        {
            self.faults.reset_after = None;
            self.send(
                port,
                &Message::Reset(Reset {
                    cause: ResetCause::Watchdog,
                }),
            );
        }
        let credit = self.credit();
        if credit.limit >= self.last_credit + u64::from(CAPACITY / 4) {
            self.last_credit = credit.limit;
            self.send(port, &Message::Credit(credit));
        }
        if self.last_telemetry.elapsed() >= TELEMETRY_EVERY {
            self.last_telemetry = Instant::now();
            let t = self.telemetry();
            self.send(port, &Message::Telemetry(t));
        }
    }
}

fn scene(duration: f64, rate: f64) -> Scene {
    let text = format!(
        "duration = {duration}\nrate = {rate}\nseed = 11\nmotion = \"kinematic\"\n\
         [joints.roll]\ntype = \"sine\"\namplitude = 0.8\nfrequency = 2.0\n\
         [joints.yaw]\ntype = \"sine\"\namplitude = 1.5\nfrequency = 0.7\n\
         [sensors.gyro]\nnoise_density = [0.01, 0.01, 0.01]\n"
    );
    Scene::parse_str(&text, std::path::Path::new("stream-test.toml")).unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("margemu-stream-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn config() -> StreamConfig {
    StreamConfig {
        port: "pty".into(),
        lead: Duration::from_millis(100),
        ..StreamConfig::default()
    }
}

/// Runs `scene` against the fake device; returns the session's result, the predicted images and
/// what the device recorded.
fn stream(scene: &Scene, dir: &Path, faults: Faults) -> Outcome {
    stream_with(scene, dir, faults, config())
}

type Outcome = (
    Result<margemu::stream::Summary, StreamError>,
    Vec<Image>,
    DeviceRecord,
);

fn stream_with(scene: &Scene, dir: &Path, faults: Faults, config: StreamConfig) -> Outcome {
    let (master, slave) = TTYPort::pair().unwrap();
    let device = fake_device_speaking_the_protocol(master, faults);
    let session = Session::new(scene, config, dir).unwrap();
    let predicted: Vec<Image> = session.samples().iter().map(|s| s.image).collect();
    let result = session.run_on_port(slave, |_| {});
    let record = device.join().unwrap();
    (result, predicted, record)
}

fn read_csv(dir: &Path, name: &str) -> (String, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(dir.join(name)).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().to_string();
    let n = header.split(',').count();
    let rows: Vec<Vec<String>> = lines
        .map(|l| {
            let row: Vec<String> = l.split(',').map(str::to_string).collect();
            assert_eq!(row.len(), n, "{name}: `{l}`");
            row
        })
        .collect();
    (header, rows)
}

/// Every sample of the scene was served at its instant, in order (an instant after the last
/// sample, before Stop arrived, holds the last sample: not a lost one).
fn assert_no_lost_samples(record: &DeviceRecord, total: u64) {
    let late: Vec<&u64> = record
        .underrun_indices
        .iter()
        .filter(|&&k| k < total)
        .collect();
    assert!(late.is_empty(), "host late for {late:?}");
    let served: Vec<u64> = record.served.iter().map(|(k, _)| *k).collect();
    let wrong = served.iter().enumerate().find(|&(i, &k)| i as u64 != k);
    assert_eq!(wrong, None, "served out of order");
    assert_eq!(
        served.len() as u64,
        total,
        "served {} of {total}",
        served.len()
    );
}

#[test]
fn a_short_scene_streams_end_to_end_byte_for_byte() {
    let scene = scene(1.0, 1000.0);
    let dir = scratch("ok");
    let (result, predicted, record) = stream(&scene, &dir, Faults::default());
    let summary = result.unwrap();
    assert_eq!(summary.sent, 1000);
    assert_no_lost_samples(&record, 1000);
    assert_eq!(record.overruns, 0, "host beyond the credit window");
    assert_eq!(record.served.len(), 1000, "every sample served");
    for (k, image) in &record.served {
        assert_eq!(image, &predicted[*k as usize], "sample {k}");
    }
    assert!(record.stopped);
    let t = summary.telemetry.unwrap();
    assert_eq!(t.state, DeviceState::Stopped);
    assert_eq!(t.last_served_index, 999);
    assert!(summary.jitter.batches > 0);
    // Logs: complete and parseable.
    let meta: toml::Table = std::fs::read_to_string(dir.join("meta.toml"))
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(meta["samples"].as_integer(), Some(1000));
    assert_eq!(meta["image"]["accel_fs"].as_str(), Some("G2"));
    assert_eq!(meta["device"]["buffer_capacity"].as_integer(), Some(512));
    let (_, truth) = read_csv(&dir, "truth.csv");
    assert_eq!(truth.len(), 1000);
    let (header, sent) = read_csv(&dir, "sent.csv");
    assert_eq!(header, margemu::stream::log::SENT_COLUMNS);
    let sent: Vec<_> = sent.into_iter().filter(|r| r[5] == "0").collect();
    assert_eq!(sent.len(), 1000);
    for (k, row) in sent.iter().enumerate() {
        assert_eq!(row[0].parse::<u64>().unwrap(), k as u64);
        assert_eq!(row[1], truth[k][0], "t_ns of sample {k}");
        row[2].parse::<i64>().unwrap();
        assert!(row[3].is_empty() || row[3].parse::<i64>().is_ok());
        assert_eq!(parse_image_hex(&row[4]), Some(predicted[k]));
    }
    let (_, device) = read_csv(&dir, "device.csv");
    let last = device.last().unwrap();
    assert_eq!(last[3], "999");
    assert_eq!(last[4], last[5], "served at the instant the host scheduled");
    let (_, telemetry) = read_csv(&dir, "telemetry.csv");
    assert!(telemetry.len() >= 10);
    let (_, writes) = read_csv(&dir, "register_writes.csv");
    assert_eq!(&writes[0][2..6], &["spi", "0", "107", "1"]);
    let (_, events) = read_csv(&dir, "events.csv");
    assert_eq!(
        events.last().unwrap()[1..],
        ["end".to_string(), "completed".to_string()]
    );
}

#[test]
fn damaged_device_frames_are_counted_and_the_stream_goes_on() {
    let scene = scene(0.6, 1000.0);
    let dir = scratch("damaged");
    let faults = Faults {
        damage_every: Some(3),
        ..Faults::default()
    };
    let (result, predicted, record) = stream(&scene, &dir, faults);
    let summary = result.unwrap();
    assert!(record.damaged_sent >= 10, "{}", record.damaged_sent);
    let rx = summary.host_rx;
    let damaged = rx.crc_errors + rx.framing_errors;
    // Each injection is garbage (one damaged frame) and a flipped copy (one more, usually).
    assert!(
        damaged >= record.damaged_sent / 2,
        "{rx:?} for {} injected",
        record.damaged_sent
    );
    assert_no_lost_samples(&record, 600);
    for (k, image) in &record.served {
        assert_eq!(image, &predicted[*k as usize]);
    }
    let (_, events) = read_csv(&dir, "events.csv");
    assert!(events.iter().any(|e| e[1] == "host_rx_errors"));
}

#[test]
fn a_device_that_vanishes_stops_the_session_with_valid_logs() {
    let scene = scene(2.0, 1000.0);
    let dir = scratch("vanish");
    let faults = Faults {
        vanish_after: Some(300),
        ..Faults::default()
    };
    let started = Instant::now();
    let (result, _, record) = stream(&scene, &dir, faults);
    let err = result.unwrap_err();
    assert!(matches!(err, StreamError::Disconnected { .. }), "{err}");
    assert!(
        err.to_string().starts_with("the device disconnected"),
        "{err}"
    );
    assert!(
        started.elapsed() < Duration::from_secs(2),
        "stopped promptly"
    );
    assert!(record.received.len() >= 300);
    let (_, sent) = read_csv(&dir, "sent.csv");
    assert!(sent.len() >= 300 && sent.len() < 2000, "{}", sent.len());
    for row in &sent {
        assert!(parse_image_hex(&row[4]).is_some());
    }
    let (_, events) = read_csv(&dir, "events.csv");
    let end = events.last().unwrap();
    assert_eq!(end[1], "end");
    assert!(
        end[2].starts_with("error: the device disconnected"),
        "{end:?}"
    );
}

#[test]
fn no_device_on_the_port_is_a_hello_timeout() {
    let scene = scene(0.1, 1000.0);
    let dir = scratch("silent");
    let (_master, slave) = TTYPort::pair().unwrap();
    let config = StreamConfig {
        hello_timeout: Duration::from_millis(300),
        ..config()
    };
    let session = Session::new(&scene, config, &dir).unwrap();
    let err = session.run_on_port(slave, |_| {}).unwrap_err();
    assert!(matches!(err, StreamError::HelloTimeout { .. }), "{err}");
    let (_, events) = read_csv(&dir, "events.csv");
    assert!(events.last().unwrap()[2].starts_with("error: no HelloAck"));
}

#[test]
fn a_device_reset_mid_run_stops_the_session() {
    let scene = scene(2.0, 1000.0);
    let dir = scratch("reset");
    let faults = Faults {
        reset_after: Some(200),
        ..Faults::default()
    };
    let (result, _, _) = stream(&scene, &dir, faults);
    let err = result.unwrap_err();
    assert!(matches!(err, StreamError::DeviceReset { .. }), "{err}");
    assert_eq!(
        err.to_string(),
        "the device reset mid-session (cause: Watchdog)"
    );
    let (_, events) = read_csv(&dir, "events.csv");
    assert!(events
        .iter()
        .any(|e| e[1] == "device_reset" && e[2] == "Watchdog"));
    assert_eq!(events.last().unwrap()[1], "end");
    let (_, device) = read_csv(&dir, "device.csv");
    assert!(!device.is_empty());
}

#[test]
fn the_stop_flag_interrupts_with_flushed_logs() {
    let scene = scene(5.0, 1000.0);
    let dir = scratch("interrupt");
    let (master, slave) = TTYPort::pair().unwrap();
    let device = fake_device_speaking_the_protocol(master, Faults::default());
    let session = Session::new(&scene, config(), &dir).unwrap();
    let stop = session.stop_flag();
    // What a Ctrl-C handler does.
    std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(300));
        stop.store(true, std::sync::atomic::Ordering::Relaxed);
    });
    let err = session.run_on_port(slave, |_| {}).unwrap_err();
    assert!(matches!(err, StreamError::Interrupted), "{err}");
    let record = device.join().unwrap();
    let (_, sent) = read_csv(&dir, "sent.csv");
    assert!(sent.len() >= 300 && sent.len() < 1000, "{}", sent.len());
    // Every row the device holds was logged before it was written to the port.
    assert!(record.received.len() <= sent.len());
    assert!(record.stopped, "the device was asked to stop");
    let (_, events) = read_csv(&dir, "events.csv");
    assert!(events.last().unwrap()[2].starts_with("error: interrupted"));
}

#[test]
fn the_cli_names_a_silent_port() {
    let (_master, slave) = TTYPort::pair().unwrap();
    let path = slave.name().unwrap();
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

/// The loopback figures against the fake device (the firmware's handler will replace
/// it): `cargo test --release -p margemu --test stream_pty -- --ignored --nocapture`.
#[test]
#[ignore = "long: 60 s at 1 kHz and 10 s at 8 kHz in real time"]
fn long_runs_lose_nothing_and_report_jitter() {
    for (duration, rate) in [(10.0, 8000.0), (60.0, 1000.0)] {
        let scene = scene(duration, rate);
        let dir = scratch(&format!("long-{rate}"));
        let config = StreamConfig {
            lead: Duration::from_millis(20),
            ..config()
        };
        let (result, predicted, record) = stream_with(&scene, &dir, Faults::default(), config);
        let summary = result.unwrap();
        let total = predicted.len() as u64;
        assert_no_lost_samples(&record, total);
        for (k, image) in &record.served {
            assert_eq!(image, &predicted[*k as usize], "sample {k}");
        }
        let j = summary.jitter;
        println!(
            "{duration} s at {rate} Hz: {total} samples served, {} batches, pacing late p50 {} µs, p99 {} µs, max {} µs, credit stalls {}",
            j.batches,
            j.p50_ns / 1000,
            j.p99_ns / 1000,
            j.max_ns / 1000,
            summary.credit_stalls
        );
    }
}
