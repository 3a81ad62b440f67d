//! Fault injection on the link: host ↔ relay ↔ the real firmware `Device`, over two PTY pairs.
//!
//! The relay forwards each direction frame by frame (it splits the stream at the 0x00
//! delimiters) and, while a damage window is open, damages frames of the streaming kinds with a
//! seeded generator: it flips one bit of a frame (never making a 0x00), drops one byte of a
//! frame, or puts a burst of garbage (non-zero bytes, closed by a 0x00) between two frames. Each
//! of these makes exactly one damaged frame at the receiver, so both sides' counters must equal
//! what the relay did. A variant vanishes mid-run (the relay closes both lines).

mod common;

use common::{assert_logs_valid, config, scratch};
use margemu::loopback::DeviceReport;
use margemu::scene::Scene;
use margemu::stream::{Session, SourceMode, StreamConfig, StreamError, Summary};
use margemu_protocol::link::{Accumulator, FeedResult};
use serialport::TTYPort;
use std::io::{Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

/// What the relay did to one direction.
#[derive(Clone, Copy, Debug, Default)]
struct Damage {
    frames: u32,
    flipped: u32,
    dropped: u32,
    garbage: u32,
}

impl Damage {
    /// Damaged frames the receiver must count.
    fn total(&self) -> u32 {
        self.flipped + self.dropped + self.garbage
    }
}

/// xorshift64*: a seeded generator with no dependency (as smoltcp's fault injector).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

/// One direction's frame splitter and damager.
struct Mangler {
    rng: Rng,
    body: Vec<u8>,
    kinds: &'static [u8],
    active: Arc<AtomicBool>,
    damage: Damage,
}

impl Mangler {
    fn new(seed: u64, kinds: &'static [u8], active: Arc<AtomicBool>) -> Self {
        Self {
            rng: Rng(seed),
            body: Vec::new(),
            kinds,
            active,
            damage: Damage::default(),
        }
    }

    fn process(&mut self, input: &[u8], out: &mut Vec<u8>) {
        for &b in input {
            match b {
                0 => self.close_frame(out),
                _ => self.body.push(b),
            }
        }
    }

    /// The kind byte of an intact COBS-encoded frame body.
    fn kind(body: &[u8]) -> Option<u8> {
        let mut wire = Vec::with_capacity(body.len() + 2);
        wire.push(0);
        wire.extend_from_slice(body);
        wire.push(0);
        match Accumulator::new().feed(&wire) {
            FeedResult::Success { frame, .. } => Some(frame.kind()),
            _ => None,
        }
    }

    fn close_frame(&mut self, out: &mut Vec<u8>) {
        let mut body = std::mem::take(&mut self.body);
        let active = self.active.load(Ordering::Relaxed);
        if !body.is_empty() {
            self.damage.frames += 1;
            let eligible = Self::kind(&body).is_some_and(|k| self.kinds.contains(&k));
            if active && eligible {
                match self.rng.below(100) {
                    0..=3 => {
                        let i = self.rng.below(body.len() as u64) as usize;
                        let mut bit = self.rng.below(8);
                        while body[i] ^ (1 << bit) == 0 {
                            bit = (bit + 1) % 8;
                        }
                        body[i] ^= 1 << bit;
                        self.damage.flipped += 1;
                    }
                    4..=7 => {
                        body.remove(self.rng.below(body.len() as u64) as usize);
                        self.damage.dropped += 1;
                    }
                    _ => {}
                }
            }
        }
        out.extend_from_slice(&body);
        out.push(0);
        if active && self.rng.below(100) < 3 {
            let len = 1 + self.rng.below(48) as usize;
            out.extend((0..len).map(|_| 1 + self.rng.below(255) as u8));
            out.push(0);
            self.damage.garbage += 1;
        }
    }
}

/// Forwards `from` → `to` through `mangler` until `stop`, an end of file or an error.
fn relay(
    mut from: TTYPort,
    mut to: TTYPort,
    mut mangler: Mangler,
    stop: Arc<AtomicBool>,
) -> JoinHandle<Damage> {
    std::thread::spawn(move || {
        let mut buf = [0u8; 4096];
        let mut out = Vec::new();
        while !stop.load(Ordering::Relaxed) {
            let n = match from.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => n,
                Err(e) if e.kind() == std::io::ErrorKind::TimedOut => continue,
                Err(_) => break,
            };
            out.clear();
            mangler.process(&buf[..n], &mut out);
            if to.write_all(&out).is_err() {
                break;
            }
        }
        mangler.damage
    })
}

const BATCH_KINDS: &[u8] = &[0x10, 0x11]; // Images, Kinematics
const REPORT_KINDS: &[u8] = &[0x82, 0x83, 0x87]; // Credit, Telemetry, Served

struct Outcome {
    result: Result<Summary, StreamError>,
    device: DeviceReport,
    to_device: Damage,
    to_host: Damage,
}

/// Streams `scene` through the relay; damage is on from `window.0` to `window.1` after the
/// session starts; the relay vanishes at `vanish_at` if given.
fn through_relay(
    scene: &Scene,
    dir: &std::path::Path,
    config: StreamConfig,
    window: (Duration, Duration),
    vanish_at: Option<Duration>,
) -> Outcome {
    let (host_line, relay_host) = TTYPort::pair().unwrap();
    let (relay_device, device_line) = TTYPort::pair().unwrap();
    let device = margemu::loopback::spawn_device(device_line).unwrap();
    let (active, stop) = (
        Arc::new(AtomicBool::new(false)),
        Arc::new(AtomicBool::new(false)),
    );
    let mut ports = [relay_host, relay_device];
    for p in &mut ports {
        serialport::SerialPort::set_timeout(p, Duration::from_millis(2)).unwrap();
    }
    let [relay_host, relay_device] = ports;
    let to_device = relay(
        relay_host.try_clone_native().unwrap(),
        relay_device.try_clone_native().unwrap(),
        Mangler::new(0x5EED_0001, BATCH_KINDS, active.clone()),
        stop.clone(),
    );
    let to_host = relay(
        relay_device,
        relay_host,
        Mangler::new(0x5EED_0002, REPORT_KINDS, active.clone()),
        stop.clone(),
    );
    let session = Session::new(scene, config, dir).unwrap();
    let (a, s) = (active.clone(), stop.clone());
    let control = std::thread::spawn(move || {
        std::thread::sleep(window.0);
        a.store(true, Ordering::Relaxed);
        match vanish_at {
            Some(at) => {
                std::thread::sleep(at - window.0);
                s.store(true, Ordering::Relaxed);
            }
            None => {
                std::thread::sleep(window.1 - window.0);
                a.store(false, Ordering::Relaxed);
            }
        }
    });
    let result = session.run_on_port(host_line, |_| {});
    control.join().unwrap();
    std::thread::sleep(Duration::from_millis(50));
    stop.store(true, Ordering::Relaxed);
    let to_device = to_device.join().expect("the relay did not panic");
    let to_host = to_host.join().expect("the relay did not panic");
    Outcome {
        result,
        device: device.stop(),
        to_device,
        to_host,
    }
}

fn fault_scene(rate: f64) -> Scene {
    let text = format!(
        "duration = 3.0\nrate = {rate}\nseed = 17\nmotion = \"kinematic\"\n\
         [joints.roll]\ntype = \"sine\"\namplitude = 0.8\nfrequency = 2.0\n\
         [joints.x]\ntype = \"sine\"\namplitude = 0.2\nfrequency = 1.0\n\
         [sensors.gyro]\nnoise_density = [0.01, 0.01, 0.01]\n"
    );
    Scene::parse_str(&text, std::path::Path::new("faults.toml")).unwrap()
}

/// Damage in both directions from 0.3 s to 2.3 s of a 3 s scene: every damaged frame counted on
/// both sides, nothing served but the predicted images, everything after the window served
/// byte for byte, the session ends cleanly with valid logs.
fn damaged_both_ways(name: &str, rate: f64, source: SourceMode) {
    let scene = fault_scene(rate);
    let dir = scratch(name);
    let window = (Duration::from_millis(300), Duration::from_millis(2300));
    let o = through_relay(
        &scene,
        &dir,
        StreamConfig { source, ..config() },
        window,
        None,
    );
    let summary = o.result.expect("the session ends cleanly");
    let (d, h) = (o.to_device, o.to_host);
    println!(
        "{name}: to device {d:?}, to host {h:?}, resends {}",
        summary.resends
    );
    for kind in [
        d.flipped + h.flipped,
        d.dropped + h.dropped,
        d.garbage + h.garbage,
    ] {
        assert!(kind > 0, "every kind of damage was exercised: {d:?} {h:?}");
    }
    assert!(d.total() > 0 && h.total() > 0, "{d:?} {h:?}");
    // The host counted every frame damaged on its way in, and nothing else.
    let rx = summary.host_rx;
    assert_eq!(rx.crc_errors + rx.framing_errors, h.total(), "{rx:?} {h:?}");
    assert_eq!(rx.rejected_messages, 0);
    // So did the device, and so says its last telemetry.
    let dev = o.device.counters.rx;
    assert_eq!(
        dev.crc_errors + dev.framing_errors,
        d.total(),
        "{dev:?} {d:?}"
    );
    assert_eq!(dev.rejected_messages, 0);
    let t = summary.telemetry.unwrap();
    assert_eq!(t.crc_errors + t.framing_errors, d.total());
    // Lost batches were sent again.
    assert!(summary.resends > 0, "{d:?}");
    // Never a corrupted sample; after the window, every sample byte for byte.
    let s = summary.served;
    assert_eq!(s.mismatched, 0, "{s:?}");
    let total = scene.samples();
    let after = (2.5 * rate) as u64; // 200 ms after the window closed
    let served = common::served(&dir, total);
    let late: Vec<_> = served.iter().filter(|&&(k, _, _)| k >= after).collect();
    assert_eq!(
        late.len() as u64,
        total - after,
        "every later sample reported"
    );
    assert!(late.iter().all(|&&(_, underrun, ok)| ok && !underrun));
    let events = assert_logs_valid(&dir);
    assert!(events.iter().any(|e| e[1] == "host_rx_errors"));
    assert!(events.iter().any(|e| e[1] == "resend"));
    assert_eq!(events.last().unwrap()[2], "completed");
}

#[test]
fn damaged_frames_are_counted_on_both_sides_and_the_image_stream_recovers() {
    damaged_both_ways("faults-images", 1000.0, SourceMode::Images);
}

#[test]
fn damaged_frames_are_counted_on_both_sides_and_the_kinematics_stream_recovers() {
    let source = SourceMode::Model {
        kinematics_hz: Some(500.0),
    };
    damaged_both_ways("faults-model", 2000.0, source);
}

#[test]
fn the_far_end_vanishing_mid_run_ends_the_session_with_valid_logs() {
    let scene = fault_scene(1000.0);
    let dir = scratch("faults-vanish");
    let window = (Duration::from_millis(300), Duration::ZERO);
    let o = through_relay(
        &scene,
        &dir,
        config(),
        window,
        Some(Duration::from_millis(1000)),
    );
    let err = o.result.unwrap_err();
    assert!(matches!(err, StreamError::Disconnected { .. }), "{err}");
    assert!(
        o.device.ended == "end of file" || o.device.ended.starts_with("port error"),
        "{}",
        o.device.ended
    );
    let events = assert_logs_valid(&dir);
    assert!(events.last().unwrap()[2].starts_with("error: the device disconnected"));
    // What was served before is on record, and never a corrupted sample.
    let served = common::served(&dir, scene.samples());
    assert!(served.len() > 500, "{}", served.len());
    assert!(served.iter().all(|&(_, underrun, ok)| ok || underrun));
}
