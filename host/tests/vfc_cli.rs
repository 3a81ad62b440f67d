//! The command line: `margemu loopback --vfc` (a virtual flight controller, its MAVLink read back
//! and scored), and `--dut PORT` on `loopback` and `stream` with a test thread playing the device
//! under test on a real PTY, writing frames from the `mavlink` crate's encoder.

use margemu::dut::mavlink_out::{attitude_quaternion, MavlinkWriter};
use serialport::{SerialPort, TTYPort};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

const SCENE: &str = "duration = 2.0\nrate = 200.0\nseed = 3\nmotion = \"kinematic\"\n\
    [joints.roll]\ntype = \"sine\"\namplitude = 0.3\nfrequency = 0.5\n\
    [joints.yaw]\ntype = \"sine\"\namplitude = 0.6\nfrequency = 0.3\n\
    [sensors.gyro]\nnoise_density = [0.002, 0.002, 0.002]\n";

/// A fresh directory with the scene in it.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("margemu-vfc-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("scene.toml"), SCENE).unwrap();
    dir
}

fn margemu(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(args)
        .output()
        .unwrap()
}

fn text(out: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `(header, rows)` of a CSV file of the session.
fn csv(dir: &Path, name: &str) -> (String, Vec<String>) {
    let text = std::fs::read_to_string(dir.join(name)).unwrap();
    let mut lines = text.lines().map(str::to_owned);
    (lines.next().unwrap(), lines.collect())
}

#[test]
fn loopback_with_a_flight_controller_reads_back_and_scores_its_mavlink() {
    let dir = scratch("vfc");
    std::fs::write(dir.join("params.toml"), "[gda]\nbeta = 0.3\n").unwrap();
    let session = dir.join("session");
    let out = margemu(&[
        "loopback",
        path(&dir.join("scene.toml")),
        "-o",
        path(&session),
        "--vfc",
        "gda",
        "--vfc-params",
        path(&dir.join("params.toml")),
    ]);
    let all = text(&out);
    assert!(out.status.success(), "{all}");
    assert!(
        all.contains("virtual flight controller: gda (beta = 0.3) over "),
        "{all}"
    );
    assert!(
        all.contains("every frame the flight controller sent was decoded"),
        "{all}"
    );
    assert!(
        all.contains("400 of 400 predicted images confirmed byte for byte"),
        "{all}"
    );
    assert!(all.contains("geodesic RMS (rad)"), "{all}");
    for file in [
        "dut_attitude.csv",
        "dut_messages.csv",
        "report.md",
        "errors.csv",
    ] {
        assert!(session.join(file).is_file(), "{file} missing");
    }
    // 2 s at 50 Hz: 100 of each message, in dut_attitude.csv and the session's records. The
    // flight controller's thread runs on the host's scheduler: starved, it may step over an
    // output instant (as a real one would), so a few may be missing, never more than 5 %, and
    // every record agrees on the count.
    let (_, rows) = csv(&session, "dut_attitude.csv");
    let quaternions = rows
        .iter()
        .filter(|r| r.contains("ATTITUDE_QUATERNION"))
        .count();
    assert!(
        (95..=100).contains(&quaternions),
        "{quaternions} quaternions"
    );
    assert_eq!(
        rows.len(),
        2 * quaternions,
        "one ATTITUDE per ATTITUDE_QUATERNION"
    );
    let (_, events) = csv(&session, "events.csv");
    let last = events.last().unwrap();
    assert!(
        last.contains(&format!(
            ",dut,mavlink: {} messages (ATTITUDE {quaternions}; ATTITUDE_QUATERNION {quaternions}; HEARTBEAT 2)",
            2 * quaternions + 2
        )),
        "{last}"
    );
    let meta: toml::Table = std::fs::read_to_string(session.join("meta.toml"))
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(
        meta["dut"]["per_message"]["ATTITUDE_QUATERNION"].as_integer(),
        Some(quaternions as i64)
    );
}

#[test]
fn loopback_with_a_flight_controller_on_the_icm42688p_reads_back_and_scores_its_mavlink() {
    let dir = scratch("vfc-icm");
    let session = dir.join("session");
    let out = margemu(&[
        "loopback",
        path(&dir.join("scene.toml")),
        "--chip",
        "icm42688p",
        "-o",
        path(&session),
        "--vfc",
        "ekf",
    ]);
    let all = text(&out);
    assert!(out.status.success(), "{all}");
    assert!(
        all.contains("over SPI: ICM-42688-P WHO_AM_I 0x47, no magnetometer (heading from the gyroscope alone); 400 samples read (0 warm-up), 0 missed;"),
        "{all}"
    );
    assert!(all.contains("400 skipped mag"), "{all}");
    assert!(
        all.contains("400 of 400 predicted images confirmed byte for byte"),
        "{all}"
    );
    assert!(
        all.contains("every frame the flight controller sent was decoded"),
        "{all}"
    );
    assert!(all.contains("geodesic RMS (rad)"), "{all}");
    assert!(session.join("report.md").is_file());
    let (_, rows) = csv(&session, "dut_attitude.csv");
    assert_eq!(rows.len(), 200);
    let meta: toml::Table = std::fs::read_to_string(session.join("meta.toml"))
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(meta["chip"]["model"].as_str(), Some("icm42688p"));
    assert_eq!(meta["chip"]["accel_range_g"].as_float(), Some(16.0));
    assert_eq!(meta["chip"]["gyro_range_dps"].as_float(), Some(2000.0));
}

/// The built-in `rig` (an ICM-42688-P and an IST8310 compass, 1 kHz for 1 s): the flight
/// controller reads the compass over I2C, and the report says so.
#[test]
fn loopback_with_a_flight_controller_on_the_rig_reads_its_compass() {
    let dir = scratch("vfc-rig");
    let session = dir.join("session");
    let out = margemu(&["loopback", "rig", "-o", path(&session), "--vfc", "ekf"]);
    let all = text(&out);
    assert!(out.status.success(), "{all}");
    assert!(
        all.contains(
            "over SPI: ICM-42688-P WHO_AM_I 0x47; compass IST8310 at I2C 0x0e (identity 0x10): "
        ),
        "{all}"
    );
    assert!(all.contains("1000 samples read"), "{all}");
    assert!(all.contains(" 0 skipped mag"), "{all}");
    assert!(
        all.contains("1000 of 1000 predicted images confirmed byte for byte"),
        "{all}"
    );
    // The compass's set-up and its single measurements, written over I2C at 0x0E (14).
    let (_, writes) = csv(&session, "register_writes.csv");
    let on_compass = |register: &str, value: &str| {
        writes.iter().any(|l| {
            let f: Vec<&str> = l.split(',').collect();
            f[2] == "i2c" && f[3] == "14" && f[4] == register && f[5] == value
        })
    };
    assert!(on_compass("11", "1"), "CNTL2 soft reset");
    assert!(on_compass("65", "36"), "AVGCNTL 16 times");
    assert!(on_compass("10", "1"), "CNTL1 single measurement");
}

#[test]
fn loopback_refuses_a_flight_controller_on_a_chip_without_a_driver() {
    let dir = scratch("vfc-mpu6500");
    let out = margemu(&[
        "loopback",
        path(&dir.join("scene.toml")),
        "--chip",
        "mpu6500",
        "-o",
        path(&dir.join("session")),
        "--vfc",
        "ekf",
    ]);
    assert!(!out.status.success());
    let all = text(&out);
    assert!(
        all.contains("the virtual flight controller has no driver for the MPU-6500"),
        "{all}"
    );
}

#[test]
fn a_bad_parameters_file_is_refused_with_its_location() {
    let dir = scratch("bad-params");
    std::fs::write(dir.join("params.toml"), "[ekf]\nmag_noise = -0.5\n").unwrap();
    let out = margemu(&[
        "loopback",
        path(&dir.join("scene.toml")),
        "-o",
        path(&dir.join("session")),
        "--vfc",
        "ekf",
        "--vfc-params",
        path(&dir.join("params.toml")),
    ]);
    assert!(!out.status.success());
    let all = text(&out);
    assert!(all.contains("params.toml:2:13: "), "{all}");
    assert!(all.contains("not a finite number ≥ 0"), "{all}");
}

/// Plays a device under test on a PTY pair: once the reader has created `dut_messages.csv` in
/// `session`, writes `n` ATTITUDE_QUATERNION frames 10 ms apart. Returns the path the reader
/// opens and the thread (which keeps both ends open until it ends).
fn dut_board(session: PathBuf, n: u32) -> (String, std::thread::JoinHandle<()>) {
    let (mut board, reader_end) = TTYPort::pair().unwrap();
    let name = reader_end.name().unwrap();
    let thread = std::thread::spawn(move || {
        let _keep = reader_end;
        let deadline = Instant::now() + Duration::from_secs(30);
        while !session.join("dut_messages.csv").exists() && Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(5));
        }
        let mut fc = MavlinkWriter::v2();
        for i in 0..n {
            let frame = fc
                .encode(&attitude_quaternion(i * 10, [1.0, 0.0, 0.0, 0.0], [0.0; 3]))
                .unwrap();
            board.write_all(&frame).unwrap();
            std::thread::sleep(Duration::from_millis(10));
        }
        // Until the session has surely ended.
        std::thread::sleep(Duration::from_secs(3));
    });
    (name, thread)
}

/// The reader logged the `n` frames of [`dut_board`] and the session recorded its summary.
fn assert_dut_logged(session: &Path, n: usize, all: &str) {
    assert!(
        all.contains(&format!(
            "device under test: mavlink: {n} messages (ATTITUDE_QUATERNION {n})"
        )),
        "{all}"
    );
    let (header, rows) = csv(session, "dut_attitude.csv");
    assert_eq!(header, margemu::dut::log::ATTITUDE_COLUMNS);
    assert_eq!(rows.len(), n);
    let times: Vec<i64> = rows
        .iter()
        .map(|r| r.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert!(times.windows(2).all(|w| w[0] <= w[1]), "{times:?}");
    let (_, events) = csv(session, "events.csv");
    let start: i64 = events
        .iter()
        .find(|e| e.split(',').nth(1) == Some("start"))
        .and_then(|e| e.split(',').next())
        .unwrap()
        .parse()
        .unwrap();
    // The reader's clock is the session's: the board wrote from before Start to within 2 s of it.
    assert!(
        times.iter().all(|&t| t > 0 && t < start + 2_000_000_000),
        "{times:?} start {start}"
    );
    assert!(
        events
            .last()
            .unwrap()
            .contains(&format!(",dut,mavlink: {n} messages")),
        "{events:?}"
    );
    let meta: toml::Table = std::fs::read_to_string(session.join("meta.toml"))
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(meta["dut"]["messages"].as_integer(), Some(n as i64));
    assert_eq!(meta["dut"]["end"].as_str(), Some("stopped"));
}

#[test]
fn loopback_logs_a_device_under_test_on_dut() {
    let dir = scratch("loopback-dut");
    let session = dir.join("session");
    let (port, board) = dut_board(session.clone(), 60);
    let out = margemu(&[
        "loopback",
        path(&dir.join("scene.toml")),
        "-o",
        path(&session),
        "--dut",
        &port,
        "--dut-protocol",
        "mavlink",
    ]);
    let all = text(&out);
    assert!(out.status.success(), "{all}");
    assert_dut_logged(&session, 60, &all);
    board.join().unwrap();
}

#[test]
fn stream_logs_a_device_under_test_on_dut() {
    let dir = scratch("stream-dut");
    let session = dir.join("session");
    let (device_end, host_end) = TTYPort::pair().unwrap();
    let device = margemu::loopback::spawn_device(device_end).unwrap();
    let (port, board) = dut_board(session.clone(), 60);
    let out = margemu(&[
        "stream",
        path(&dir.join("scene.toml")),
        "--port",
        &host_end.name().unwrap(),
        "-o",
        path(&session),
        "--dut",
        &port,
    ]);
    device.stop();
    let all = text(&out);
    assert!(out.status.success(), "{all}");
    assert_dut_logged(&session, 60, &all);
    board.join().unwrap();
}

#[test]
fn evaluate_scores_one_message_stream_of_a_loopback_session_by_default() {
    // The flight controller sends ATTITUDE and ATTITUDE_QUATERNION of each sample with one
    // device time stamp: scored together, the stamps would not increase and every second row
    // would be dropped.
    let dir = scratch("vfc-evaluate");
    let session = dir.join("session");
    let out = margemu(&[
        "loopback",
        path(&dir.join("scene.toml")),
        "-o",
        path(&session),
        "--vfc",
        "ekf",
    ]);
    assert!(out.status.success(), "{}", text(&out));
    let out = margemu(&["evaluate", path(&session), "--no-plots"]);
    let all = text(&out);
    assert!(out.status.success(), "{all}");
    assert!(!all.contains("not used"), "{all}");
    assert!(all.contains("rows stamped through the fit"), "{all}");
    assert!(
        all.contains("scored mavlink2/ATTITUDE_QUATERNION (choose another with --message)"),
        "{all}"
    );
    assert!(
        !all.contains("with the stamp of a later row dropped"),
        "{all}"
    );
    let (_, errors) = csv(&session, "errors.csv");
    assert_eq!(errors.len(), 100, "one scored row per sample");
}
