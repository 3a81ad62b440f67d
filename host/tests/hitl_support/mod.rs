//! Helpers shared by the `hitl_*` tests: the scene, `margemu` runs, MAVLink 2 framing by hand
//! (so the tests do not decode with margemu's own reader), pymavlink as an independent decoder,
//! and `mock_px4`, a stand-in flight controller.

#![allow(dead_code)]

use margemu::dut::mavlink_out::{attitude_quaternion, MavlinkWriter};
use margemu::offline::FilterKind;
use margemu_filters::filter::Imu;
use margemu_filters::init::Initial;
use mavlink::dialects::common::{MavMessage, HIL_SENSOR_DATA};
use mavlink::{MavlinkVersion, Message};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// 2 s at 100 Hz, kinematic roll, pitch, yaw and height, the field in µT, a temperature ramp.
pub const SCENE: &str = r#"
duration = 2.0
rate = 100.0
seed = 7
motion = "kinematic"

[field]
reference = [20.0, 0.0, -40.0]
unit = "uT"

[sensors]
temperature = [20.0, 0.5]

[joints.z]
type = "sine"
amplitude = 0.5
frequency = 0.5

[joints.roll]
type = "sine"
amplitude = 0.3
frequency = 0.5

[joints.pitch]
type = "sine"
amplitude = 0.2
frequency = 0.3

[joints.yaw]
type = "sine"
amplitude = 0.5
frequency = 0.2
"#;

/// Samples of [`SCENE`].
pub const SAMPLES: usize = 200;

/// A fresh directory under the target directory, with [`SCENE`] in it as `scene.toml`.
pub fn fresh(name: &str) -> (PathBuf, PathBuf) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, SCENE).unwrap();
    (dir, scene)
}

/// `margemu ARGS…`, waited for.
pub fn margemu(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(args)
        .output()
        .expect("margemu runs")
}

/// `margemu ARGS…`, started.
pub fn spawn_margemu(args: &[&str]) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("margemu starts")
}

/// The rows of a CSV file after its header, split at commas.
pub fn csv_rows(path: &Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

/// Whether python3 with pymavlink is there; without it, `false` after saying so, and a panic
/// under `CI=true`.
pub fn have_pymavlink() -> bool {
    let probe = Command::new("python3")
        .args(["-c", "import pymavlink"])
        .output();
    if matches!(&probe, Ok(o) if o.status.success()) {
        return true;
    }
    assert!(
        std::env::var_os("CI").is_none(),
        "python3 with pymavlink is not installed (scripts/test-all installs it)"
    );
    eprintln!("SKIPPED: python3 with pymavlink is not installed (pip install pymavlink)");
    false
}

/// pymavlink's MAVLink 2 parser over stdin: one line per message,
/// `HIL_SENSOR time_usec xacc … temperature fields_updated id`, `HEARTBEAT type autopilot`,
/// or `BAD` for bytes that failed (a bad CRC among them).
const PYMAVLINK_READER: &str = r#"
import sys
from pymavlink.dialects.v20 import common as m2
mav = m2.MAVLink(None)
mav.robust_parsing = True
for m in mav.parse_buffer(sys.stdin.buffer.read()) or []:
    t = m.get_type()
    if t == 'BAD_DATA':
        print('BAD')
    elif t == 'HIL_SENSOR':
        v = [m.time_usec, m.xacc, m.yacc, m.zacc, m.xgyro, m.ygyro, m.zgyro, m.xmag, m.ymag,
             m.zmag, m.abs_pressure, m.diff_pressure, m.pressure_alt, m.temperature,
             m.fields_updated, m.id]
        print('HIL_SENSOR ' + ' '.join(repr(x) for x in v))
    elif t == 'HEARTBEAT':
        print('HEARTBEAT %d %d %d %d' % (m.type, m.autopilot, m.get_srcSystem(), m.get_srcComponent()))
    else:
        print('OTHER ' + t)
"#;

/// What pymavlink decoded from `bytes`: its output lines.
pub fn pymavlink_decode(bytes: &[u8]) -> Vec<String> {
    let mut child = Command::new("python3")
        .args(["-c", PYMAVLINK_READER])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("python3 runs");
    child.stdin.take().unwrap().write_all(bytes).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "pymavlink failed");
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect()
}

/// Checks pymavlink's lines against `marg.csv` and `truth.csv` of `margemu simulate` of the
/// same scene: every frame's CRC held, one HIL_SENSOR per sample, and every value as the
/// documented conversion gives it (FRD: `(x, −y, −z)`; µT × 0.01 = gauss).
pub fn check_against_simulate(lines: &[String], run: &Path) {
    assert!(
        !lines.iter().any(|l| l == "BAD"),
        "a frame failed pymavlink's CRC"
    );
    let sensors: Vec<Vec<f64>> = lines
        .iter()
        .filter_map(|l| l.strip_prefix("HIL_SENSOR "))
        .map(|l| l.split(' ').map(|x| x.parse().unwrap()).collect())
        .collect();
    let heartbeats = lines.iter().filter(|l| l.starts_with("HEARTBEAT")).count();
    assert_eq!(heartbeats, 2, "one at 0 s and one at 1 s");
    assert!(
        lines.iter().any(|l| l == "HEARTBEAT 0 8 255 190"),
        "{lines:?}"
    );
    let marg = csv_rows(&run.join("marg.csv"));
    let truth = csv_rows(&run.join("truth.csv"));
    assert_eq!(sensors.len(), SAMPLES);
    assert_eq!(marg.len(), SAMPLES);
    let f = |s: &str| s.parse::<f64>().unwrap();
    for (k, ((s, m), t)) in sensors.iter().zip(&marg).zip(&truth).enumerate() {
        let t_ns: u64 = m[0].parse().unwrap();
        assert_eq!(s[0] as u64, t_ns / 1000, "time_usec of {k}");
        // marg.csv holds f32 values, shortest round trip: parsed as f32, they are the readings.
        let g = |s: &str| f64::from(s.parse::<f32>().unwrap());
        let frd = |i: usize| [g(&m[i]), -g(&m[i + 1]), -g(&m[i + 2])];
        let (acc, gyr) = (frd(1), frd(4));
        for i in 0..3 {
            assert_eq!(s[1 + i], acc[i], "acc {k}.{i}: exact (f32 sign flips)");
            assert_eq!(s[4 + i], gyr[i], "gyr {k}.{i}");
        }
        let mag = frd(7).map(|ut| (ut * 0.01) as f32);
        for i in 0..3 {
            let resolution = f64::from(f32::EPSILON) * f64::from(mag[i].abs()).max(1e-30);
            assert!(
                (s[7 + i] - f64::from(mag[i])).abs() <= resolution,
                "mag {k}.{i}"
            );
        }
        let z = f(&t[3]);
        assert_eq!(s[12] as f32, z as f32, "pressure_alt {k}");
        let p = 1013.25 * (1.0 - 2.25577e-5 * z).powf(5.25588);
        assert!(
            (s[10] - p).abs() < 1e-3,
            "abs_pressure {k}: {} vs {p}",
            s[10]
        );
        assert_eq!(s[11], 0.0, "diff_pressure");
        let temp = 20.0 + 0.5 * t_ns as f64 * 1e-9;
        assert!((s[13] - temp).abs() <= 1e-5 * temp, "temperature {k}");
        assert_eq!(s[14] as u32, 0x1BFF, "fields_updated {k}");
        assert_eq!(s[15], 0.0, "id {k}");
    }
}

/// Splits MAVLink 2 frames out of `buf` (consumed as they are taken), checking each CRC with
/// the `mavlink` crate's CRC and extra-CRC table; returns the messages and the damaged count.
pub fn take_frames(buf: &mut Vec<u8>) -> (Vec<MavMessage>, u64) {
    let mut out = Vec::new();
    let mut bad = 0;
    loop {
        let Some(start) = buf.iter().position(|&b| b == 0xFD) else {
            buf.clear();
            break;
        };
        buf.drain(..start);
        if buf.len() < 10 {
            break;
        }
        let len = usize::from(buf[1]);
        let total = 10 + len + 2;
        if buf.len() < total {
            break;
        }
        let id = u32::from(buf[7]) | u32::from(buf[8]) << 8 | u32::from(buf[9]) << 16;
        let crc = u16::from_le_bytes([buf[10 + len], buf[11 + len]]);
        let ok = crc == mavlink::calculate_crc(&buf[1..10 + len], MavMessage::extra_crc(id));
        match MavMessage::parse(MavlinkVersion::V2, id, &buf[10..10 + len]) {
            Ok(m) if ok => {
                out.push(m);
                buf.drain(..total);
            }
            _ => {
                bad += 1;
                buf.drain(..1);
            }
        }
    }
    (out, bad)
}

/// What the stand-in flight controller saw.
#[derive(Debug, Default)]
pub struct MockReport {
    pub hil_sensors: u64,
    pub heartbeats: u64,
    pub bad_frames: u64,
    pub replies: u64,
}

/// Offset of the stand-in flight controller's boot clock from scene time 0 (ms).
pub const MOCK_BOOT_MS: u32 = 73_000;

/// `mock_px4`: a test double of a PX4 board in HITL mode on `port` (a byte stream that times
/// out now and then) until `done` is set. It decodes every HIL_SENSOR, turns FRD back into
/// margemu's body axes, runs margemu's reference EKF on it and answers each sample with an
/// ATTITUDE_QUATERNION stamped on its own boot clock: `MOCK_BOOT_MS` + the sample's
/// `time_usec` (a flight controller's clock runs from its boot, not from the scene).
pub fn mock_px4<P: Read + Write>(
    mut port: P,
    mag_reference: [f64; 3],
    done: &std::sync::atomic::AtomicBool,
) -> MockReport {
    let params = margemu::offline::FilterParams::defaults(FilterKind::Ekf);
    let mut filter = params.build(mag_reference, Initial::FirstSample).unwrap();
    let mut writer = MavlinkWriter::v2();
    let mut report = MockReport::default();
    let mut buf = Vec::new();
    let mut chunk = [0u8; 512];
    let mut last_us: Option<u64> = None;
    while !done.load(std::sync::atomic::Ordering::Relaxed) {
        match port.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => buf.extend_from_slice(&chunk[..n]),
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::TimedOut | std::io::ErrorKind::WouldBlock
                ) =>
            {
                continue
            }
            Err(_) => break,
        }
        let (messages, bad) = take_frames(&mut buf);
        report.bad_frames += bad;
        for m in messages {
            match m {
                MavMessage::HEARTBEAT(_) => report.heartbeats += 1,
                MavMessage::HIL_SENSOR(h) => {
                    report.hil_sensors += 1;
                    let dt = last_us.map_or(0.0, |u| (h.time_usec - u) as f64 * 1e-6);
                    last_us = Some(h.time_usec);
                    filter.update(&imu_of(&h), dt);
                    let boot_ms = MOCK_BOOT_MS + (h.time_usec / 1000) as u32;
                    let q = filter.quaternion();
                    let frame = writer
                        .encode(&attitude_quaternion(boot_ms, q, [0.0; 3]))
                        .unwrap();
                    port.write_all(&frame).unwrap();
                    report.replies += 1;
                }
                _ => {}
            }
        }
    }
    report
}

/// A HIL_SENSOR back in margemu's body axes (FRD → x forward, y left, z up).
fn imu_of(h: &HIL_SENSOR_DATA) -> Imu<f64> {
    let flu = |v: [f32; 3]| [f64::from(v[0]), -f64::from(v[1]), -f64::from(v[2])];
    Imu {
        gyro: flu([h.xgyro, h.ygyro, h.zgyro]),
        acc: flu([h.xacc, h.yacc, h.zacc]),
        mag: flu([h.xmag, h.ymag, h.zmag]),
    }
}
