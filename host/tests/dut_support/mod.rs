//! Helpers shared by the `dut_*` tests: a real PTY pair, a writer that splits its bytes into
//! random pieces with garbage between frames, and the CSV files read back.

#![allow(dead_code)]

use margemu::dut::{DutProgress, DutReader};
use margemu_model::rng::{below, stream, StreamRng};
use serialport::{SerialPort, TTYPort};
use std::io::{ErrorKind, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// `(reader end, device end)` of a fresh PTY pair; the reader end times out after 5 ms.
pub fn pty() -> (TTYPort, TTYPort) {
    let (mut master, mut slave) = TTYPort::pair().expect("a pseudo-terminal pair");
    master.set_timeout(Duration::from_millis(5)).unwrap();
    slave.set_timeout(Duration::from_millis(200)).unwrap();
    (master, slave)
}

/// A fresh session directory under the target directory.
pub fn session_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes all of `bytes`, retrying while the PTY is full.
pub fn write_fully(port: &mut TTYPort, mut bytes: &[u8]) {
    while !bytes.is_empty() {
        match port.write(bytes) {
            Ok(n) => bytes = &bytes[n..],
            Err(e) if e.kind() == ErrorKind::TimedOut || e.kind() == ErrorKind::Interrupted => {}
            Err(e) => panic!("writing to the PTY: {e}"),
        }
    }
}

/// The device's byte stream: frames with garbage between them, written in pieces.
pub struct Stream {
    rng: StreamRng,
    /// Every byte, in order.
    pub bytes: Vec<u8>,
    /// Garbage bytes in it.
    pub garbage: u64,
}

impl Stream {
    /// An empty stream with its own seeded generator.
    pub fn new(seed: u64) -> Self {
        Self {
            rng: stream(seed, "dut/stream"),
            bytes: Vec::new(),
            garbage: 0,
        }
    }

    /// A uniform integer in `[0, n)`.
    pub fn below(&mut self, n: u32) -> u32 {
        below(&mut self.rng, n)
    }

    /// Up to `max` random garbage bytes, none of them in `banned`.
    pub fn garbage(&mut self, max: u32, banned: &[u8]) {
        for _ in 0..self.below(max + 1) {
            let mut b = self.below(256) as u8;
            while banned.contains(&b) {
                b = self.below(256) as u8;
            }
            self.bytes.push(b);
            self.garbage += 1;
        }
    }

    /// Appends a frame.
    pub fn frame(&mut self, frame: &[u8]) {
        self.bytes.extend_from_slice(frame);
    }

    /// Writes the stream to `port`: the first third one byte per write, the rest in random
    /// pieces of 1 to 64 bytes, pausing now and then so the reader sees separate reads.
    pub fn write_split(&mut self, port: &mut TTYPort) {
        let bytes = std::mem::take(&mut self.bytes);
        let third = bytes.len() / 3;
        for (i, b) in bytes[..third].iter().enumerate() {
            write_fully(port, std::slice::from_ref(b));
            if i % 16 == 0 {
                std::thread::sleep(Duration::from_micros(300));
            }
        }
        let mut i = third;
        while i < bytes.len() {
            let n = (1 + self.below(64) as usize).min(bytes.len() - i);
            write_fully(port, &bytes[i..i + n]);
            i += n;
            if self.below(4) == 0 {
                std::thread::sleep(Duration::from_micros(500));
            }
        }
        self.bytes = bytes;
    }
}

/// Waits (at most 10 s) until the reader's progress satisfies `done`.
pub fn wait_for(reader: &DutReader, done: impl Fn(&DutProgress) -> bool) -> DutProgress {
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let p = reader.progress();
        if done(&p) || Instant::now() > deadline {
            return p;
        }
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// The rows of a CSV file (split at commas), after checking its header.
pub fn rows(path: &Path, header: &str) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(header), "{}", path.display());
    lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

/// A float column.
pub fn num(field: &str) -> f64 {
    field
        .parse()
        .unwrap_or_else(|_| panic!("not a number: {field:?}"))
}

/// The float columns `from..from + N` of a row.
pub fn nums<const N: usize>(row: &[String], from: usize) -> [f64; N] {
    std::array::from_fn(|i| num(&row[from + i]))
}

/// Asserts that two float triples or quadruples agree within `tol` (absolute).
pub fn close(actual: &[f64], expected: &[f64], tol: f64, what: &str) {
    assert_eq!(actual.len(), expected.len(), "{what}");
    for (a, e) in actual.iter().zip(expected) {
        assert!(
            (a - e).abs() <= tol,
            "{what}: {actual:?} differs from {expected:?}"
        );
    }
}

/// The quaternion of ZYX Euler angles (half-angle formula, as truth.rs).
pub fn quat_of(e: [f64; 3]) -> [f64; 4] {
    let (sp, cp) = (0.5 * e[0]).sin_cos();
    let (st, ct) = (0.5 * e[1]).sin_cos();
    let (ss, cs) = (0.5 * e[2]).sin_cos();
    [
        cp * ct * cs + sp * st * ss,
        sp * ct * cs - cp * st * ss,
        cp * st * cs + sp * ct * ss,
        cp * ct * ss - sp * st * cs,
    ]
}
