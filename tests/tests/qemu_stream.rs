//! QEMU streaming test: a `margemu::stream::Session` streams a short kinematic scene (1 s at
//! 500 Hz, gyro noise) to the `qemu-mps2-an386` firmware over UART0's PTY, and every sample the
//! firmware's link handler latched into its emulated chip is checked byte for byte against the
//! host's prediction.
//!
//! The session ignores the device's `Served` reports, so the test tees what the session reads
//! from the port into a side channel and decodes them afterwards: each carries the CRC-32C of
//! the 22-byte image served at an index, compared with `CRC32C.checksum` of the predicted image.
//! The device's final Telemetry must report no underrun and no overrun.
//!
//! Skipped, with a message, where `qemu-system-arm` or a cross toolchain is missing; under
//! `CI=true` that is a failure instead.

use std::collections::BTreeMap;
use std::io::{self, Read};
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use margemu::scene::Scene;
use margemu::stream::{Session, StreamConfig};
use margemu_protocol::link::{Message, CRC32C};
use margemu_tests::qemu::{self, LinkDecoder, Qemu};

/// 1 s at 500 Hz, two sine joints, gyro noise. (At 1 kHz, ~23 KB/s towards the device, QEMU's
/// CMSDK UART falls behind: it takes one received byte per chardev round trip, and the device
/// underruns after a few hundred ms.)
const SCENE: &str = "duration = 1.0\nrate = 500.0\nseed = 11\nmotion = \"kinematic\"\n\
     [joints.roll]\ntype = \"sine\"\namplitude = 0.8\nfrequency = 2.0\n\
     [joints.yaw]\ntype = \"sine\"\namplitude = 1.5\nfrequency = 0.7\n\
     [sensors.gyro]\nnoise_density = [0.01, 0.01, 0.01]\n";

/// A reader that copies every byte it returns into a shared buffer.
struct Tee<R> {
    inner: R,
    copy: Arc<Mutex<Vec<u8>>>,
}

impl<R: Read> Read for Tee<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.copy
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .extend_from_slice(&buf[..n]);
        Ok(n)
    }
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("margemu-qemu-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn session_streams_to_qemu_byte_for_byte() {
    if !qemu::prerequisites_or_skip("qemu_stream") {
        return;
    }
    let t = Instant::now();
    let elf = qemu::board_elf().unwrap_or_else(|e| panic!("board ELF: {e}"));
    let build = t.elapsed();

    let scene = Scene::parse_str(SCENE, std::path::Path::new("qemu-stream.toml"))
        .unwrap_or_else(|e| panic!("{e}"));
    let dir = scratch("stream");
    let config = StreamConfig {
        port: "qemu mps2-an386 UART0 (pty)".into(),
        lead: Duration::from_millis(100),
        ..StreamConfig::default()
    };
    let session = Session::new(&scene, config, &dir).unwrap_or_else(|e| panic!("session: {e}"));
    let predicted: Vec<u32> = session
        .samples()
        .iter()
        .map(|s| CRC32C.checksum(&s.image))
        .collect();
    assert_eq!(predicted.len(), 500);

    let t = Instant::now();
    let (qemu, uart0) = Qemu::boot(&elf).unwrap_or_else(|e| panic!("boot: {e}"));
    let port = uart0.into_port();
    let reader = port.try_clone_native().expect("clone the PTY");
    let copy = Arc::new(Mutex::new(Vec::new()));
    let tee = Tee {
        inner: reader,
        copy: Arc::clone(&copy),
    };
    let result = session.run(tee, port, |_| {});
    let streamed = t.elapsed();
    let summary = result.unwrap_or_else(|e| {
        panic!(
            "session: {e}; logs in {}\nQEMU printed:\n{}",
            dir.display(),
            qemu.output()
        )
    });
    drop(qemu);

    // Decode the device's Served reports from what the session read.
    let bytes = std::mem::take(&mut *copy.lock().unwrap_or_else(|e| e.into_inner()));
    let mut decoder = LinkDecoder::default();
    let mut served: BTreeMap<u64, (u32, bool)> = BTreeMap::new();
    let mut duplicates = 0usize;
    decoder.feed(&bytes, &mut |m: &Message<'_>| {
        if let Message::Served(batch) = m {
            for (k, s) in batch.samples.iter().enumerate() {
                let index = batch.first_index + k as u64;
                if served.insert(index, (s.crc32c, s.underrun)).is_some() {
                    duplicates += 1;
                }
            }
        }
    });
    assert_eq!(decoder.damaged, 0, "damaged frames from the device");
    assert_eq!(duplicates, 0, "indices reported served twice");

    let mut missing = Vec::new();
    let mut wrong = Vec::new();
    for (index, &crc) in predicted.iter().enumerate() {
        match served.get(&(index as u64)) {
            None => missing.push(index),
            Some(&(got, underrun)) if underrun || got != crc => wrong.push((index, underrun)),
            Some(_) => {}
        }
    }
    assert!(
        missing.is_empty(),
        "{} of {} samples never reported served (first {:?}); logs in {}",
        missing.len(),
        predicted.len(),
        &missing[..missing.len().min(10)],
        dir.display()
    );
    assert!(
        wrong.is_empty(),
        "{} samples served differently from the prediction, (index, underrun) {:?}",
        wrong.len(),
        &wrong[..wrong.len().min(10)]
    );

    let telemetry = summary.telemetry.expect("the device's final Telemetry");
    assert_eq!(telemetry.underruns, 0, "{telemetry:?}");
    assert_eq!(telemetry.overruns, 0, "{telemetry:?}");
    assert_eq!(summary.sent, summary.samples, "{summary:?}");
    assert!(telemetry.samples_served >= 500, "{telemetry:?}");
    let _ = std::fs::remove_dir_all(&dir);

    eprintln!(
        "qemu_stream: build {build:.2?}, boot + stream of {} samples {streamed:.2?}; device served \
         {} (0 underruns, 0 overruns), {} confirmed by CRC-32C; credit stalls {}, jitter {:?}",
        predicted.len(),
        telemetry.samples_served,
        predicted.len(),
        summary.credit_stalls,
        summary.jitter
    );
}
