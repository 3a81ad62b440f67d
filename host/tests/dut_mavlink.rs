//! The device-under-test reader on MAVLink, over a real PTY pair: frames from the `mavlink`
//! crate's own encoder (and, in an ignored test, from pymavlink), MAVLink 1 and 2 mixed, written
//! in random pieces with garbage between them.

mod dut_support;

use dut_support::{
    check_attitude, check_imu, close, nums, pty, quat_of, rows, session_dir, wait_for, Stream,
};
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
