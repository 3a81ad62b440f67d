//! The device-under-test reader on MSP, over a real PTY pair: frames from an independent encoder
//! (the `multiwii_serial_protocol_v2` crate), v1 and v2 mixed, in random pieces with garbage
//! between them; and the request/response poll against a board played by a test thread that
//! parses the requests with that crate's parser.

mod dut_support;

use dut_support::{close, nums, pty, quat_of, rows, session_dir, wait_for, Stream};
use margemu::dut::log::{
    ATTITUDE_COLUMNS, ATTITUDE_FILE, IMU_COLUMNS, IMU_FILE, MESSAGES_COLUMNS, MESSAGES_FILE,
};
use margemu::dut::msp::MspVersion;
use margemu::dut::{DutConfig, DutEnd, DutProtocol, DutReader};
use margemu::truth::geodesic_angle;
use multiwii_serial_protocol_v2::{MspPacket, MspPacketDirection, MspParser};
use serialport::TTYPort;
use std::io::{ErrorKind, Read};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Instant;

const MSP_STATUS: u16 = 101;
const MSP_RAW_IMU: u16 = 102;
const MSP_ATTITUDE: u16 = 108;

/// A frame from the board (`'>'`, or `'!'` for an error reply), by the crate's encoder.
fn board_frame(cmd: u16, data: Vec<u8>, version: MspVersion, error: bool) -> Vec<u8> {
    let packet = MspPacket {
        cmd,
        direction: if error {
            MspPacketDirection::Unsupported
        } else {
            MspPacketDirection::FromFlightController
        },
        data,
    };
    let mut out = match version {
        MspVersion::V1 => vec![0; packet.packet_size_bytes()],
        MspVersion::V2 => vec![0; packet.packet_size_bytes_v2()],
    };
    match version {
        MspVersion::V1 => packet.serialize(&mut out).unwrap(),
        MspVersion::V2 => packet.serialize_v2(&mut out).unwrap(),
    }
    out
}

fn le(values: &[i16]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// margemu's ZYX Euler angles (rad) of an `MSP_ATTITUDE` (Betaflight/INAV signs: roll right wing
/// down, pitch nose down, yaw the compass heading).
fn msp_euler(roll: i16, pitch: i16, heading: i16) -> [f64; 3] {
    let yaw = -f64::from(heading);
    let yaw = if yaw <= -180.0 { yaw + 360.0 } else { yaw };
    [f64::from(roll) / 10.0, f64::from(pitch) / 10.0, yaw].map(f64::to_radians)
}

fn check_attitude_row(row: &[String], (roll, pitch, heading): (i16, i16, i16)) {
    assert_eq!(row[3], "", "MSP has no device time");
    let e = msp_euler(roll, pitch, heading);
    close(&nums::<3>(row, 4), &e, 1e-12, "euler");
    assert!(geodesic_angle(&nums::<4>(row, 7), &quat_of(e)) < 1e-14);
}

fn reader(dir: &std::path::Path, host: TTYPort, poll_hz: f64, v: MspVersion) -> DutReader {
    let config = DutConfig {
        msp_poll_hz: poll_hz,
        msp_requests: v,
        ..DutConfig::new(DutProtocol::Msp)
    };
    DutReader::spawn(host, config, dir, Instant::now()).unwrap()
}

#[test]
fn msp_from_an_independent_encoder_in_random_pieces_with_garbage_decodes_exactly() {
    let dir = session_dir("dut_msp_split");
    let (host, mut device) = pty();
    // The requests it writes are never answered here.
    let reader = reader(&dir, host, 5.0, MspVersion::V1);
    let mut s = Stream::new(2);
    // (version, name, payload length, attitude or raw IMU)
    let mut sent = Vec::new();
    for i in 0..48u32 {
        let v = if s.below(2) == 0 {
            MspVersion::V1
        } else {
            MspVersion::V2
        };
        let r = |s: &mut Stream, half: u32| (s.below(2 * half - 1) as i32 - half as i32 + 1) as i16;
        let (cmd, data, name, error) = match i % 4 {
            0 => {
                let a = (r(&mut s, 1800), r(&mut s, 900), s.below(360) as i16);
                sent.push((v, "MSP_ATTITUDE", 6, Some(Ok(a))));
                (MSP_ATTITUDE, le(&[a.0, a.1, a.2]), "", false)
            }
            1 => {
                let raw: [i16; 9] = std::array::from_fn(|_| r(&mut s, 32768));
                sent.push((v, "MSP_RAW_IMU", 18, Some(Err(raw))));
                (MSP_RAW_IMU, le(&raw), "", false)
            }
            2 => {
                let status: Vec<u8> = (0..11).map(|_| s.below(256) as u8).collect();
                (MSP_STATUS, status, "MSP_CMD_101", false)
            }
            _ => (250, Vec::new(), "MSP_CMD_250_ERROR", true),
        };
        if !name.is_empty() {
            sent.push((v, name, data.len(), None));
        }
        s.garbage(24, b"$");
        s.frame(&board_frame(cmd, data, v, error));
    }
    s.garbage(24, b"$");
    s.write_split(&mut device);
    let total = s.bytes.len() as u64;
    wait_for(&reader, |p| p.counters.bytes == total);
    let summary = reader.stop().unwrap();

    assert_eq!(summary.end, DutEnd::Stopped);
    let c = summary.counters;
    assert_eq!(
        (c.bytes, c.bad_bytes, c.bad_frames, c.undecoded),
        (total, s.garbage, 0, 0)
    );
    let messages = rows(&dir.join(MESSAGES_FILE), MESSAGES_COLUMNS);
    let attitude = rows(&dir.join(ATTITUDE_FILE), ATTITUDE_COLUMNS);
    let imu = rows(&dir.join(IMU_FILE), IMU_COLUMNS);
    assert_eq!((messages.len(), attitude.len(), imu.len()), (48, 12, 12));
    let (mut att, mut raw_rows) = (attitude.iter(), imu.iter());
    for (row, (v, name, len, sample)) in messages.iter().zip(sent) {
        let wire = match v {
            MspVersion::V1 => "msp1",
            MspVersion::V2 => "msp2",
        };
        assert_eq!(&row[1..], [wire, name, "", "", "", &len.to_string()]);
        match sample {
            Some(Ok(a)) => {
                let r = att.next().unwrap();
                assert_eq!(&r[..3], &row[..3]);
                check_attitude_row(r, a);
            }
            Some(Err(raw)) => {
                let r = raw_rows.next().unwrap();
                assert_eq!(&r[..4], &[&row[0], wire, "MSP_RAW_IMU", ""]);
                // Raw counts, unscaled, in the order acc, gyro, mag.
                assert_eq!(nums::<9>(r, 4), raw.map(f64::from));
            }
            None => {}
        }
    }
}

#[test]
fn betaflight_attitude_signs_through_the_whole_path() {
    let dir = session_dir("dut_msp_signs");
    let (host, mut device) = pty();
    let reader = reader(&dir, host, 5.0, MspVersion::V1);
    // Right wing 20° down, nose 10° down, heading 90° (east); then heading 270° (west).
    for a in [[200, 100, 90], [0, 0, 270]] {
        let f = board_frame(MSP_ATTITUDE, le(&a), MspVersion::V1, false);
        dut_support::write_fully(&mut device, &f);
    }
    wait_for(&reader, |p| p.messages == 2);
    reader.stop().unwrap();
    let attitude = rows(&dir.join(ATTITUDE_FILE), ATTITUDE_COLUMNS);
    let d = f64::to_radians;
    close(
        &nums::<3>(&attitude[0], 4),
        &[d(20.0), d(10.0), d(-90.0)],
        1e-15,
        "east",
    );
    close(
        &nums::<3>(&attitude[1], 4),
        &[0.0, 0.0, d(90.0)],
        1e-15,
        "west",
    );
}

/// What the board played by a test thread saw and answered.
#[derive(Debug, Default)]
struct Board {
    attitude_requests: u64,
    imu_requests: u64,
    other: u64,
    /// The replies, in order: `Ok` an attitude, `Err` a raw IMU reading.
    replies: Vec<Result<(i16, i16, i16), [i16; 9]>>,
}

/// A board answering MSP_ATTITUDE and MSP_RAW_IMU requests in `version` until `stop`.
fn board(mut port: TTYPort, version: MspVersion, stop: Arc<AtomicBool>) -> JoinHandle<Board> {
    use serialport::SerialPort;
    port.set_timeout(std::time::Duration::from_millis(2))
        .unwrap();
    std::thread::spawn(move || {
        let mut parser = MspParser::new();
        let mut b = Board::default();
        let mut buf = [0u8; 256];
        while !stop.load(Ordering::Relaxed) {
            let n = match port.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => n,
                Err(e) if e.kind() == ErrorKind::TimedOut => continue,
                Err(_) => break,
            };
            for &byte in &buf[..n] {
                let Ok(Some(p)) = parser.parse(byte) else {
                    continue;
                };
                assert_eq!(p.direction, MspPacketDirection::ToFlightController);
                let k = b.replies.len() as i16;
                let (reply, data) = match p.cmd {
                    MSP_ATTITUDE => {
                        b.attitude_requests += 1;
                        let a = (10 * k, -5 * k, k % 360);
                        (Ok(a), le(&[a.0, a.1, a.2]))
                    }
                    MSP_RAW_IMU => {
                        b.imu_requests += 1;
                        let raw = [k, -k, 2048, 2 * k, 0, -3, 100, -100, k];
                        (Err(raw), le(&raw))
                    }
                    _ => {
                        b.other += 1;
                        continue;
                    }
                };
                dut_support::write_fully(&mut port, &board_frame(p.cmd, data, version, false));
                b.replies.push(reply);
            }
        }
        b
    })
}

#[test]
fn msp_polls_the_board_and_logs_its_replies() {
    for version in [MspVersion::V1, MspVersion::V2] {
        let dir = session_dir(&format!("dut_msp_poll_{version:?}"));
        let (host, device) = pty();
        let stop = Arc::new(AtomicBool::new(false));
        let board = board(device, version, stop.clone());
        let reader = reader(&dir, host, 200.0, version);
        wait_for(&reader, |p| p.messages >= 60);
        stop.store(true, Ordering::Relaxed);
        let board = board.join().unwrap();
        let replies = board.replies.len() as u64;
        wait_for(&reader, |p| p.messages == replies);
        let summary = reader.stop().unwrap();

        assert!(replies >= 60, "{version:?}: {board:?}");
        assert_eq!(board.other, 0);
        // Every poll asks for both, attitude first.
        assert!((board.attitude_requests as i64 - board.imu_requests as i64).abs() <= 1);
        assert!(summary.requests_sent >= board.attitude_requests + board.imu_requests);
        let c = summary.counters;
        assert_eq!((c.bad_bytes, c.bad_frames, c.undecoded), (0, 0, 0));
        let messages = rows(&dir.join(MESSAGES_FILE), MESSAGES_COLUMNS);
        let attitude = rows(&dir.join(ATTITUDE_FILE), ATTITUDE_COLUMNS);
        let imu = rows(&dir.join(IMU_FILE), IMU_COLUMNS);
        assert_eq!(messages.len() as u64, replies);
        assert_eq!(attitude.len() as u64, board.attitude_requests);
        assert_eq!(imu.len() as u64, board.imu_requests);
        let (mut att, mut raw_rows) = (attitude.iter(), imu.iter());
        for reply in &board.replies {
            match reply {
                Ok(a) => check_attitude_row(att.next().unwrap(), *a),
                Err(raw) => assert_eq!(nums::<9>(raw_rows.next().unwrap(), 4), raw.map(f64::from)),
            }
        }
    }
}
