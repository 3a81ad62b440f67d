//! Helpers shared by the `dut_*` tests: a real PTY pair, a writer that splits its bytes into
//! random pieces with garbage between frames, and the CSV files read back.

#![allow(dead_code)]

use margemu::dut::{DutProgress, DutReader};
use margemu::truth::geodesic_angle;
use margemu_model::rng::{below, stream, StreamRng};
use mavlink::dialects::common::MavMessage;
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

/// Standard gravity (MAVLink's milli-g).
pub const G: f64 = 9.80665;

/// The margemu quaternion of a NED/FRD one, normalized.
pub fn from_ned_q(q: [f32; 4]) -> [f64; 4] {
    let q = q.map(f64::from);
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    [q[0] / n, q[1] / n, -q[2] / n, -q[3] / n]
}

/// ZYX Euler angles of a unit quaternion (an independent formula, away from gimbal lock).
pub fn euler_of(q: [f64; 4]) -> [f64; 3] {
    let [w, x, y, z] = q;
    [
        (2.0 * (w * x + y * z)).atan2(1.0 - 2.0 * (x * x + y * y)),
        (2.0 * (w * y - z * x)).clamp(-1.0, 1.0).asin(),
        (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z)),
    ]
}

pub fn check_attitude(row: &[String], m: &MavMessage) {
    match m {
        MavMessage::ATTITUDE(d) => {
            assert_eq!(num(&row[3]), f64::from(d.time_boot_ms) * 1000.0);
            // Roll stays, pitch and yaw change sign: exact.
            let e = [f64::from(d.roll), -f64::from(d.pitch), -f64::from(d.yaw)];
            assert_eq!(nums::<3>(row, 4), e, "{row:?}");
            assert!(geodesic_angle(&nums::<4>(row, 7), &quat_of(e)) < 1e-14);
        }
        MavMessage::ATTITUDE_QUATERNION(d) => {
            let q = from_ned_q([d.q1, d.q2, d.q3, d.q4]);
            close(&nums::<4>(row, 7), &q, 1e-15, "quaternion");
            close(&nums::<3>(row, 4), &euler_of(q), 1e-9, "euler");
        }
        _ => unreachable!(),
    }
}

pub fn check_imu(row: &[String], m: &MavMessage) {
    let frd = |v: [f64; 3], k: f64| [v[0] * k, -v[1] * k, -v[2] * k];
    let (t, a, g, b) = match m {
        MavMessage::SCALED_IMU(d) => {
            let v = |x: i16, y: i16, z: i16| [x, y, z].map(f64::from);
            (
                f64::from(d.time_boot_ms) * 1000.0,
                frd(v(d.xacc, d.yacc, d.zacc), G / 1000.0),
                frd(v(d.xgyro, d.ygyro, d.zgyro), 1e-3),
                frd(v(d.xmag, d.ymag, d.zmag), 0.1),
            )
        }
        MavMessage::HIGHRES_IMU(d) => {
            let v = |x: f32, y: f32, z: f32| [x, y, z].map(f64::from);
            (
                d.time_usec as f64,
                frd(v(d.xacc, d.yacc, d.zacc), 1.0),
                frd(v(d.xgyro, d.ygyro, d.zgyro), 1.0),
                frd(v(d.xmag, d.ymag, d.zmag), 100.0),
            )
        }
        _ => unreachable!(),
    };
    assert_eq!(num(&row[3]), t);
    close(&nums::<3>(row, 4), &a, 1e-12, "accel");
    close(&nums::<3>(row, 7), &g, 1e-15, "gyro");
    close(&nums::<3>(row, 10), &b, 1e-12, "mag");
}
