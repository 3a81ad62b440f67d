//! The device-under-test reader on MAVLink, over a real PTY pair: frames from the `mavlink`
//! crate's own encoder (and, in an ignored test, from pymavlink), MAVLink 1 and 2 mixed, written
//! in random pieces with garbage between them.

mod dut_support;

use dut_support::{close, num, nums, pty, quat_of, rows, session_dir, wait_for, Stream};
use margemu::dut::log::{
    ATTITUDE_COLUMNS, ATTITUDE_FILE, IMU_COLUMNS, IMU_FILE, MESSAGES_COLUMNS, MESSAGES_FILE,
};
use margemu::dut::mavlink_out::{attitude, attitude_quaternion, MavlinkWriter};
use margemu::dut::{spawn_dut_reader, DutEnd, DutProtocol};
use margemu::truth::geodesic_angle;
use mavlink::dialects::common::{
    HighresImuUpdatedFlags, MavMessage, ATTITUDE_DATA, ATTITUDE_QUATERNION_DATA, HIGHRES_IMU_DATA,
    SCALED_IMU_DATA, SYSTEM_TIME_DATA,
};
use mavlink::{MavHeader, MavlinkVersion, Message};
use std::time::Instant;

const G: f64 = 9.80665;

/// What one frame must become.
struct Sent {
    version: MavlinkVersion,
    header: MavHeader,
    message: MavMessage,
    payload_len: u8,
}

fn random_message(s: &mut Stream, i: u32) -> MavMessage {
    let f = |s: &mut Stream, scale: f32| (s.below(20_001) as f32 - 10_000.0) * scale;
    let i16r = |s: &mut Stream| (s.below(65_536) as i32 - 32_768) as i16;
    match i % 5 {
        0 => MavMessage::ATTITUDE(ATTITUDE_DATA {
            time_boot_ms: 1000 + i,
            roll: f(s, 3.1e-4),
            pitch: f(s, 1.5e-4),
            yaw: f(s, 3.1e-4),
            rollspeed: f(s, 1e-3),
            pitchspeed: 0.0,
            yawspeed: 0.0,
        }),
        1 => {
            let q = [f(s, 1e-4), f(s, 1e-4), f(s, 1e-4), f(s, 1e-4)];
            MavMessage::ATTITUDE_QUATERNION(ATTITUDE_QUATERNION_DATA {
                time_boot_ms: 1000 + i,
                q1: q[0],
                q2: q[1],
                q3: q[2],
                q4: q[3],
                ..Default::default()
            })
        }
        2 => MavMessage::SCALED_IMU(SCALED_IMU_DATA {
            time_boot_ms: 1000 + i,
            xacc: i16r(s),
            yacc: i16r(s),
            zacc: i16r(s),
            xgyro: i16r(s),
            ygyro: i16r(s),
            zgyro: i16r(s),
            xmag: i16r(s),
            ymag: i16r(s),
            zmag: i16r(s),
        }),
        3 => MavMessage::HIGHRES_IMU(HIGHRES_IMU_DATA {
            time_usec: 5_000_000_000 + u64::from(i),
            xacc: f(s, 2e-3),
            yacc: f(s, 2e-3),
            zacc: f(s, 2e-3),
            xgyro: f(s, 1e-3),
            ygyro: f(s, 1e-3),
            zgyro: f(s, 1e-3),
            xmag: f(s, 1e-4),
            ymag: f(s, 1e-4),
            zmag: f(s, 1e-4),
            fields_updated: HighresImuUpdatedFlags::all(),
            ..Default::default()
        }),
        _ => MavMessage::SYSTEM_TIME(SYSTEM_TIME_DATA {
            time_unix_usec: u64::from(i),
            time_boot_ms: i,
        }),
    }
}

fn frame(version: MavlinkVersion, header: MavHeader, m: &MavMessage) -> Vec<u8> {
    let mut out = Vec::new();
    mavlink::write_versioned_msg(&mut out, version, header, m).unwrap();
    out
}

/// The margemu quaternion of a NED/FRD one, normalized.
fn from_ned_q(q: [f32; 4]) -> [f64; 4] {
    let q = q.map(f64::from);
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    [q[0] / n, q[1] / n, -q[2] / n, -q[3] / n]
}

/// ZYX Euler angles of a unit quaternion (an independent formula, away from gimbal lock).
fn euler_of(q: [f64; 4]) -> [f64; 3] {
    let [w, x, y, z] = q;
    [
        (2.0 * (w * x + y * z)).atan2(1.0 - 2.0 * (x * x + y * y)),
        (2.0 * (w * y - z * x)).clamp(-1.0, 1.0).asin(),
        (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z)),
    ]
}

fn check_attitude(row: &[String], m: &MavMessage) {
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

fn check_imu(row: &[String], m: &MavMessage) {
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

#[test]
fn mavlink_1_and_2_in_random_pieces_with_garbage_decode_exactly() {
    let dir = session_dir("dut_mavlink_split");
    let (host, mut device) = pty();
    let reader = spawn_dut_reader(host, DutProtocol::Mavlink, &dir, Instant::now()).unwrap();
    let mut s = Stream::new(1);
    let mut sent = Vec::new();
    for i in 0..60u32 {
        let version = if s.below(2) == 0 {
            MavlinkVersion::V1
        } else {
            MavlinkVersion::V2
        };
        let header = MavHeader {
            system_id: 1 + s.below(250),
            component_id: s.below(256) as u8,
            sequence: i as u8,
        };
        let message = random_message(&mut s, i);
        let bytes = frame(version, header, &message);
        // Garbage of any value, start bytes included.
        s.garbage(24, &[]);
        s.frame(&bytes);
        sent.push(Sent {
            version,
            header,
            message,
            payload_len: bytes[1],
        });
    }
    s.garbage(24, &[]);
    s.write_split(&mut device);
    let total = s.bytes.len() as u64;
    wait_for(&reader, |p| p.counters.bytes == total);
    let summary = reader.stop().unwrap();

    assert_eq!(summary.end, DutEnd::Stopped);
    let c = summary.counters;
    assert_eq!((c.bytes, c.bad_bytes, c.undecoded), (total, s.garbage, 0));
    assert_eq!(summary.total_messages(), 60);
    assert_eq!(summary.messages["ATTITUDE"], 12);

    let messages = rows(&dir.join(MESSAGES_FILE), MESSAGES_COLUMNS);
    let attitude = rows(&dir.join(ATTITUDE_FILE), ATTITUDE_COLUMNS);
    let imu = rows(&dir.join(IMU_FILE), IMU_COLUMNS);
    assert_eq!((messages.len(), attitude.len(), imu.len()), (60, 24, 24));
    assert_eq!(
        (summary.attitude_rows, summary.imu_rows),
        (attitude.len() as u64, imu.len() as u64)
    );
    let (mut att, mut imus) = (attitude.iter(), imu.iter());
    let mut last_ns = i64::MIN;
    for (row, e) in messages.iter().zip(&sent) {
        let wire = match e.version {
            MavlinkVersion::V1 => "mavlink1",
            MavlinkVersion::V2 => "mavlink2",
        };
        let expected = [
            wire.to_string(),
            e.message.message_name().to_string(),
            e.header.system_id.to_string(),
            e.header.component_id.to_string(),
            e.header.sequence.to_string(),
            e.payload_len.to_string(),
        ];
        assert_eq!(&row[1..], &expected[..]);
        let host_ns: i64 = row[0].parse().unwrap();
        assert!(host_ns >= last_ns && host_ns > 0, "receive times in order");
        last_ns = host_ns;
        let sample = match e.message {
            MavMessage::ATTITUDE(_) | MavMessage::ATTITUDE_QUATERNION(_) => att.next(),
            MavMessage::SCALED_IMU(_) | MavMessage::HIGHRES_IMU(_) => imus.next(),
            _ => continue,
        };
        let sample = sample.expect("a sample row for each sample message");
        assert_eq!(
            &sample[..3],
            &row[..3],
            "same receive time, protocol, message"
        );
        match e.message {
            MavMessage::ATTITUDE(_) | MavMessage::ATTITUDE_QUATERNION(_) => {
                check_attitude(sample, &e.message)
            }
            _ => check_imu(sample, &e.message),
        }
    }
}

#[test]
fn a_vanishing_port_ends_the_reader_with_its_rows_intact() {
    let dir = session_dir("dut_mavlink_vanish");
    let (host, mut device) = pty();
    let reader = spawn_dut_reader(host, DutProtocol::Mavlink, &dir, Instant::now()).unwrap();
    let mut fc = MavlinkWriter::v2();
    for k in 0..10 {
        let q = quat_of([0.1 * f64::from(k), 0.0, 0.0]);
        let bytes = fc.encode(&attitude_quaternion(k, q, [0.0; 3])).unwrap();
        dut_support::write_fully(&mut device, &bytes);
    }
    wait_for(&reader, |p| p.messages == 10);
    // Half a frame, then the device is gone.
    let half = fc
        .encode(&attitude(10, [1.0, 0.0, 0.0, 0.0], [0.0; 3]))
        .unwrap();
    dut_support::write_fully(&mut device, &half[..half.len() / 2]);
    drop(device);
    let deadline = Instant::now() + std::time::Duration::from_secs(5);
    while !reader.is_finished() && Instant::now() < deadline {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    assert!(reader.is_finished(), "the reader ends by itself");
    let summary = reader.stop().unwrap();
    assert!(
        matches!(summary.end, DutEnd::Disconnected(_)),
        "{:?}",
        summary.end
    );
    let attitude = rows(&dir.join(ATTITUDE_FILE), ATTITUDE_COLUMNS);
    assert_eq!(attitude.len(), 10);
    for (k, row) in attitude.iter().enumerate() {
        assert_eq!(row[3], (k * 1000).to_string());
        close(
            &nums::<3>(row, 4),
            &[0.1 * k as f64, 0.0, 0.0],
            1e-6,
            "roll",
        );
    }
    assert_eq!(rows(&dir.join(MESSAGES_FILE), MESSAGES_COLUMNS).len(), 10);
}

#[test]
fn mavlink_out_round_trips_q_and_minus_q() {
    let dir = session_dir("dut_mavlink_round_trip");
    let (host, mut device) = pty();
    let reader = spawn_dut_reader(host, DutProtocol::Mavlink, &dir, Instant::now()).unwrap();
    let mut s = Stream::new(3);
    let half_pi = std::f64::consts::FRAC_PI_2;
    let mut quats = vec![
        [1.0, 0.0, 0.0, 0.0],
        quat_of([0.3, half_pi, -1.0]),
        quat_of([0.3, -half_pi, 2.0]),
        quat_of([0.0, 0.0, std::f64::consts::PI]),
    ];
    for _ in 0..16 {
        let q: [f64; 4] = std::array::from_fn(|_| f64::from(s.below(2001)) / 1000.0 - 1.0);
        let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        quats.push(q.map(|v| v / n));
    }
    let mut sent = Vec::new();
    let (mut v1, mut v2) = (MavlinkWriter::v1(), MavlinkWriter::v2().with_ids(42, 200));
    for q in quats {
        for q in [q, q.map(|v| -v)] {
            for quaternion_message in [true, false] {
                let fc = if s.below(2) == 0 { &mut v1 } else { &mut v2 };
                let m = if quaternion_message {
                    attitude_quaternion(7, q, [0.1, 0.2, 0.3])
                } else {
                    attitude(7, q, [0.1, 0.2, 0.3])
                };
                s.frame(&fc.encode(&m).unwrap());
                sent.push((q, quaternion_message));
            }
        }
    }
    s.write_split(&mut device);
    let total = s.bytes.len() as u64;
    wait_for(&reader, |p| p.counters.bytes == total);
    let summary = reader.stop().unwrap();
    assert_eq!(summary.counters.bad_bytes, 0);
    let attitude = rows(&dir.join(ATTITUDE_FILE), ATTITUDE_COLUMNS);
    assert_eq!(attitude.len(), sent.len());
    for (row, (q, quaternion_message)) in attitude.iter().zip(sent) {
        let got = nums::<4>(row, 7);
        assert!(
            geodesic_angle(&got, &q) < 1e-6,
            "{row:?} is not the attitude of {q:?}"
        );
        if quaternion_message {
            // ATTITUDE_QUATERNION keeps the sign it was given.
            close(&got, &q, 1e-6, "signed quaternion");
        }
    }
}

/// pymavlink's encoder, run by Python on the PTY's device end: 40 frames (every third
/// MAVLink 1), garbage before each, written in pieces of 1–16 bytes.
const PYMAVLINK_WRITER: &str = r#"
import os, random, sys
from pymavlink.dialects.v10 import common as m1
from pymavlink.dialects.v20 import common as m2

class Sink:
    def write(self, b):
        pass

fd = os.open(sys.argv[1], os.O_WRONLY | os.O_NOCTTY)
rng = random.Random(11)
out, garbage = bytearray(), 0
for i in range(40):
    mav = (m1 if i % 3 == 0 else m2).MAVLink(Sink(), srcSystem=7, srcComponent=3)
    mav.seq = i
    k = i % 4
    if k == 0:
        msg = mav.attitude_encode(1000 + i, 0.01 * i, -0.02 * i, 0.03 * i - 1.0, 0.0, 0.0, 0.0)
    elif k == 1:
        msg = mav.attitude_quaternion_encode(1000 + i, 1.0, 0.01 * i, -0.02 * i, 0.03 * i, 0.0, 0.0, 0.0)
    elif k == 2:
        msg = mav.scaled_imu_encode(1000 + i, 10 * i, -20 * i, -1000, i, -i, 2 * i, 300, -200, 100)
    else:
        msg = mav.highres_imu_encode(5000000000 + i, 0.1 * i, -0.2 * i, -9.8, 0.01 * i, 0.0,
                                     -0.01 * i, 0.2, 0.0, -0.4, 1013.0, 0.0, 10.0, 25.0, 0x1FF)
    n = rng.randrange(9)
    out += bytes(rng.randrange(256) for _ in range(n))
    garbage += n
    out += msg.pack(mav)
i = 0
while i < len(out):
    n = rng.randrange(1, 17)
    os.write(fd, bytes(out[i:i + n]))
    i += n
print(garbage, len(out))
"#;

/// The messages `PYMAVLINK_WRITER` sends, as the `mavlink` crate types them.
fn pymavlink_message(i: u32) -> MavMessage {
    let x = f64::from(i);
    match i % 4 {
        0 => MavMessage::ATTITUDE(ATTITUDE_DATA {
            time_boot_ms: 1000 + i,
            roll: (0.01 * x) as f32,
            pitch: (-0.02 * x) as f32,
            yaw: (0.03 * x - 1.0) as f32,
            ..Default::default()
        }),
        1 => MavMessage::ATTITUDE_QUATERNION(ATTITUDE_QUATERNION_DATA {
            time_boot_ms: 1000 + i,
            q1: 1.0,
            q2: (0.01 * x) as f32,
            q3: (-0.02 * x) as f32,
            q4: (0.03 * x) as f32,
            ..Default::default()
        }),
        2 => {
            let i = i as i16;
            MavMessage::SCALED_IMU(SCALED_IMU_DATA {
                time_boot_ms: 1000 + i as u32,
                xacc: 10 * i,
                yacc: -20 * i,
                zacc: -1000,
                xgyro: i,
                ygyro: -i,
                zgyro: 2 * i,
                xmag: 300,
                ymag: -200,
                zmag: 100,
            })
        }
        _ => MavMessage::HIGHRES_IMU(HIGHRES_IMU_DATA {
            time_usec: 5_000_000_000 + u64::from(i),
            xacc: (0.1 * x) as f32,
            yacc: (-0.2 * x) as f32,
            zacc: -9.8,
            xgyro: (0.01 * x) as f32,
            ygyro: 0.0,
            zgyro: (-0.01 * x) as f32,
            xmag: 0.2,
            ymag: 0.0,
            zmag: -0.4,
            ..Default::default()
        }),
    }
}

/// An independent encoder: pymavlink (`pip install pymavlink`). Ignored by default (CI does not
/// install Python packages); run with `cargo test -p margemu --test dut_mavlink -- --ignored`.
/// Without python3 or pymavlink it says so and passes.
#[test]
#[ignore = "needs python3 with pymavlink"]
fn pymavlink_frames_decode() {
    let probe = std::process::Command::new("python3")
        .args(["-c", "import pymavlink"])
        .output();
    if !matches!(&probe, Ok(o) if o.status.success()) {
        eprintln!("SKIPPED: python3 with pymavlink is not installed (pip install pymavlink)");
        return;
    }
    let dir = session_dir("dut_mavlink_pymavlink");
    let (host, device) = pty();
    let path = serialport::SerialPort::name(&device).expect("the PTY's device path");
    let reader = spawn_dut_reader(host, DutProtocol::Mavlink, &dir, Instant::now()).unwrap();
    let out = std::process::Command::new("python3")
        .args(["-c", PYMAVLINK_WRITER, &path])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let counts: Vec<u64> = String::from_utf8(out.stdout)
        .unwrap()
        .split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect();
    let (garbage, total) = (counts[0], counts[1]);
    wait_for(&reader, |p| p.counters.bytes == total);
    let summary = reader.stop().unwrap();
    drop(device);
    assert_eq!(
        (summary.counters.bad_bytes, summary.counters.undecoded),
        (garbage, 0)
    );
    let messages = rows(&dir.join(MESSAGES_FILE), MESSAGES_COLUMNS);
    let attitude = rows(&dir.join(ATTITUDE_FILE), ATTITUDE_COLUMNS);
    let imu = rows(&dir.join(IMU_FILE), IMU_COLUMNS);
    assert_eq!((messages.len(), attitude.len(), imu.len()), (40, 20, 20));
    for (i, row) in messages.iter().enumerate() {
        let m = pymavlink_message(i as u32);
        let wire = if i % 3 == 0 { "mavlink1" } else { "mavlink2" };
        assert_eq!(
            &row[1..6],
            [wire, m.message_name(), "7", "3", &i.to_string()]
        );
        let sample = if i % 4 < 2 {
            &attitude[i / 4 * 2 + i % 4]
        } else {
            &imu[i / 4 * 2 + i % 4 - 2]
        };
        if i % 4 < 2 {
            check_attitude(sample, &m);
        } else {
            check_imu(sample, &m);
        }
    }
}
