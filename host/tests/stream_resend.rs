//! Go-back-N against the real firmware `Device` (the loopback device behind a PTY pair): sample
//! batches the device never received are sent again from its `next_index`, in time to be
//! served byte for byte, in both source modes.

mod common;

use common::{config, scratch};
use margemu::scene::Scene;
use margemu::stream::{Session, SourceMode, StreamConfig, Summary};
use margemu_protocol::link::{Accumulator, FeedResult, FrameRepr, Message};
use serialport::TTYPort;
use std::io::Write;

/// The host's side of the port, losing the sample batches whose first index is in `lose`
/// (each only once): the frames a noisy line would have destroyed.
struct LosingBatches<W> {
    inner: W,
    lose: Vec<u64>,
    lost: Vec<u64>,
    acc: Accumulator,
}

impl<W: Write> Write for LosingBatches<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.write_all(buf).map(|()| buf.len())
    }

    /// The session writes one whole frame per call.
    fn write_all(&mut self, frame: &[u8]) -> std::io::Result<()> {
        let mut first = None;
        if let FeedResult::Success { frame: f, .. } = self.acc.feed(frame) {
            first = match FrameRepr::parse(&f).map(|r| r.message) {
                Ok(Message::Images(b)) => Some(b.first_index),
                Ok(Message::Kinematics(b)) => Some(b.first_index),
                _ => None,
            };
        }
        self.acc.reset();
        if let Some(i) = first.filter(|i| self.lose.contains(i) && !self.lost.contains(i)) {
            self.lost.push(i);
            return Ok(());
        }
        self.inner.write_all(frame)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

fn batches_of_16(source: SourceMode) -> StreamConfig {
    StreamConfig {
        source,
        batch: 16,
        ..config()
    }
}

fn scene(rate: f64) -> Scene {
    let text = format!(
        "duration = 1.0\nrate = {rate}\nseed = 21\nmotion = \"kinematic\"\n\
         [joints.pitch]\ntype = \"sine\"\namplitude = 0.7\nfrequency = 1.5\n\
         [sensors.gyro]\nnoise_density = [0.01, 0.01, 0.01]\n"
    );
    Scene::parse_str(&text, std::path::Path::new("resend.toml")).unwrap()
}

fn run(name: &str, scene: &Scene, config: StreamConfig, lose: &[u64]) -> (Summary, Vec<u64>) {
    let dir = scratch(&format!("resend-{name}"));
    let (host, device) = TTYPort::pair().unwrap();
    let device = margemu::loopback::spawn_device(device).unwrap();
    let session = Session::new(scene, config, &dir).unwrap();
    let reader = host.try_clone_native().unwrap();
    let writer = LosingBatches {
        inner: host,
        lose: lose.to_vec(),
        lost: Vec::new(),
        acc: Accumulator::new(),
    };
    // The writer is moved into the session; what it lost is known from `lose`.
    let summary = session.run(reader, writer, |_| {}).unwrap();
    let report = device.stop();
    assert!(
        report.counters.rx.lost_frames >= lose.len() as u32,
        "{report:?}"
    );
    let events = std::fs::read_to_string(dir.join("events.csv")).unwrap();
    let resends: Vec<u64> = events
        .lines()
        .filter(|l| l.split(',').nth(1) == Some("resend"))
        .map(|l| {
            let detail = l.split(',').nth(2).unwrap();
            let index = detail.strip_prefix("device next_index ").unwrap();
            index.split(' ').next().unwrap().parse().unwrap()
        })
        .collect();
    (summary, resends)
}

#[test]
fn lost_image_batches_are_resent_and_served_byte_for_byte() {
    let scene = scene(1000.0);
    // The prefill goes up to the 200 ms lead: one lost batch of it, two paced ones, the last.
    let lose = [160, 480, 992];
    let (summary, resends) = run("images", &scene, batches_of_16(SourceMode::Images), &lose);
    assert_eq!(
        resends, lose,
        "one go-back per lost batch, from its first index"
    );
    assert_eq!(summary.resends, 3);
    assert!(summary.resent >= 3 * 16, "{}", summary.resent);
    let s = summary.served;
    assert_eq!((s.byte_exact, s.lost()), (1000, 0), "{s:?}");
    // sent.csv: every item once, and the lost ones again, flagged.
    let dir = summary.dir;
    let sent = std::fs::read_to_string(dir.join("sent.csv")).unwrap();
    let rows: Vec<Vec<&str>> = sent
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    let resent: Vec<&Vec<&str>> = rows.iter().filter(|r| r[5] == "1").collect();
    assert_eq!(resent.len() as u64, summary.resent);
    assert!(
        resent.iter().all(|r| r[3].is_empty()),
        "resends carry no lateness"
    );
    for i in lose {
        assert!(resent.iter().any(|r| r[0] == i.to_string()), "{i} resent");
    }
    assert_eq!(rows.len() as u64, 1000 + summary.resent);
}

#[test]
fn lost_kinematics_batches_are_resent_in_source_mode_model() {
    let scene = scene(2000.0);
    let source = SourceMode::Model {
        kinematics_hz: Some(500.0),
    };
    let lose = [96, 304];
    let (summary, resends) = run("model", &scene, batches_of_16(source), &lose);
    assert_eq!(resends, lose);
    let s = summary.served;
    assert_eq!((s.byte_exact, s.lost()), (2000, 0), "{s:?}");
}

#[test]
fn nothing_is_resent_without_loss() {
    // Mid-stream a batch still in flight leaves no item held beyond the device's next_index, so
    // nothing is resent however late the PTY delivers; after the last batch the 20 ms margin
    // (the default) covers delivery.
    let scene = scene(1000.0);
    let (summary, resends) = run("clean", &scene, batches_of_16(SourceMode::Images), &[]);
    assert!(resends.is_empty(), "{resends:?}");
    assert_eq!((summary.resends, summary.resent), (0, 0));
    assert_eq!(summary.served.byte_exact, 1000);
}
