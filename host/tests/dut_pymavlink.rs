//! The device-under-test reader on MAVLink from an independent encoder: pymavlink, run by
//! Python on the PTY's device end. `scripts/test-all` installs pymavlink; without it the test
//! says so and passes, except under `CI=true`, where that is a failure.

mod dut_support;

use dut_support::{check_attitude, check_imu, pty, rows, session_dir, wait_for};
use margemu::dut::log::{
    ATTITUDE_COLUMNS, ATTITUDE_FILE, IMU_COLUMNS, IMU_FILE, MESSAGES_COLUMNS, MESSAGES_FILE,
};
use margemu::dut::{spawn_dut_reader, DutProtocol};
use mavlink::dialects::common::{
    MavMessage, ATTITUDE_DATA, ATTITUDE_QUATERNION_DATA, HIGHRES_IMU_DATA, SCALED_IMU_DATA,
};
use mavlink::Message;
use std::time::Instant;

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

/// An independent encoder: pymavlink (`pip install pymavlink`, which `scripts/test-all` does).
/// Without python3 or pymavlink it says so and passes, except under `CI=true`.
#[test]
fn pymavlink_frames_decode() {
    let probe = std::process::Command::new("python3")
        .args(["-c", "import pymavlink"])
        .output();
    if !matches!(&probe, Ok(o) if o.status.success()) {
        assert!(
            std::env::var_os("CI").is_none(),
            "python3 with pymavlink is not installed (scripts/test-all installs it)"
        );
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
