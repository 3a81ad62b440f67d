//! `run.mcap` and `session.mcap` read back by two independent readers, run by Python
//! (`tests/mcap_readers.py`): the `mcap` package with `mcap-ros2-support`, which decodes the CDR
//! with the schema text, and `rosbags`, which opens the file as a ROS 2 bag and deserializes
//! with its own ros2msg parser. Every channel's message count and every message's times are
//! checked against the CSV files of the same run, and the values against theirs: bit for bit
//! where the file holds the same number, within rounding where it holds a conversion.
//! `scripts/test-all` installs the packages; without them the tests say so and pass, except
//! under `CI=true`, where that is a failure.

use margemu::evaluate::device_log::read_meta;
use margemu_protocol::chip::Image;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

const READERS: &str = include_str!("mcap_readers.py");

const SCENE: &str = "duration = 2.0\nrate = 200.0\nseed = 3\nmotion = \"kinematic\"\n\
    [joints.roll]\ntype = \"sine\"\namplitude = 0.3\nfrequency = 0.5\n\
    [joints.yaw]\ntype = \"sine\"\namplitude = 0.6\nfrequency = 0.3\n\
    [joints.x]\ntype = \"sine\"\namplitude = 0.2\nfrequency = 0.4\n\
    [sensors.gyro]\nnoise_density = [0.002, 0.002, 0.002]\n";

/// Whether python3 has the three packages; a failure under `CI=true`.
fn readers_installed() -> bool {
    let probe = Command::new("python3")
        .args(["-c", "import mcap, mcap_ros2, rosbags"])
        .output();
    if probe.is_ok_and(|o| o.status.success()) {
        return true;
    }
    assert!(
        std::env::var_os("CI").is_none(),
        "python3 with mcap, mcap-ros2-support and rosbags is not installed (scripts/test-all installs them)"
    );
    eprintln!("SKIPPED: python3 with mcap, mcap-ros2-support and rosbags is not installed");
    false
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("margemu-mcap-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("scene.toml"), SCENE).unwrap();
    dir
}

fn margemu(args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(args)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "margemu {args:?}: {text}");
}

/// One message as a reader decoded it.
#[derive(Debug, PartialEq)]
struct Msg {
    log: u64,
    publish: u64,
    stamp: Option<u64>,
    frame: String,
    values: Vec<String>,
}

impl Msg {
    fn f(&self, i: usize) -> f64 {
        self.values[i].parse().unwrap()
    }
    fn fs<const N: usize>(&self, from: usize) -> [f64; N] {
        std::array::from_fn(|i| self.f(from + i))
    }
}

/// What both readers found in an MCAP file.
struct Read {
    /// The `mcap` reader's messages per topic, in file order.
    topics: BTreeMap<String, Vec<Msg>>,
    /// The `margemu` metadata record.
    meta: BTreeMap<String, String>,
    /// Channel metadata: (topic, key) → value.
    channel_meta: BTreeMap<(String, String), String>,
}

/// Runs both readers on `file`; checks that they decoded the same messages.
fn read(file: &Path) -> Read {
    let out = Command::new("python3")
        .args(["-c", READERS])
        .arg(file)
        .output()
        .unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut by_reader: BTreeMap<String, BTreeMap<String, Vec<Msg>>> = BTreeMap::new();
    let (mut meta, mut channel_meta) = (BTreeMap::new(), BTreeMap::new());
    for line in text.lines() {
        let f: Vec<&str> = line.split('\t').collect();
        match f[0] {
            "meta" => {
                assert_eq!(f[1], "margemu");
                meta.insert(f[2].to_string(), f[3].to_string());
            }
            "chmeta" => {
                channel_meta.insert((f[1].to_string(), f[2].to_string()), f[3].to_string());
            }
            reader => {
                let msg = Msg {
                    log: f[2].parse().unwrap(),
                    publish: f[3].parse().unwrap(),
                    stamp: (f[4] != "-").then(|| f[4].parse().unwrap()),
                    frame: f[5].to_string(),
                    values: f[6..].iter().map(|s| s.to_string()).collect(),
                };
                let topics = by_reader.entry(reader.to_string()).or_default();
                topics.entry(f[1].to_string()).or_default().push(msg);
            }
        }
    }
    let mut ours = by_reader
        .remove("mcap")
        .expect("the mcap reader read messages");
    let mut theirs = by_reader.remove("rosbags").expect("rosbags read messages");
    // rosbags returns messages in log-time order; the order within one topic is the file's
    // (every topic's times are ascending but `/tf`'s in a session, whose two sources interleave).
    for msgs in ours.values_mut().chain(theirs.values_mut()) {
        msgs.sort_by_key(|m| m.log);
    }
    assert_eq!(
        ours.keys().collect::<Vec<_>>(),
        theirs.keys().collect::<Vec<_>>()
    );
    for (topic, msgs) in &ours {
        assert_eq!(msgs, &theirs[topic], "{topic}: the two readers differ");
    }
    Read {
        topics: ours,
        meta,
        channel_meta,
    }
}

/// `(header, rows)` of a CSV file, each row split at commas.
fn csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_owned)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(str::to_owned).collect())
        .collect();
    (header, rows)
}

fn col(header: &[String], name: &str) -> usize {
    header.iter().position(|h| h == name).unwrap()
}

fn num(row: &[String], header: &[String], name: &str) -> f64 {
    row[col(header, name)].parse().unwrap()
}

fn nums<const N: usize>(row: &[String], header: &[String], names: [&str; N]) -> [f64; N] {
    names.map(|n| num(row, header, n))
}

/// Every time of `m` is `t_ns`.
fn at(m: &Msg, t_ns: u64, what: &str) {
    assert_eq!((m.log, m.publish), (t_ns, t_ns), "{what}");
    if let Some(stamp) = m.stamp {
        assert_eq!(stamp, t_ns, "{what}: header stamp");
    }
}

/// The truth channels (and `/tf`'s world→plate) against `truth.csv`, value for value.
fn check_truth(read: &Read, dir: &Path) {
    let (h, rows) = csv(&dir.join("truth.csv"));
    let tf: Vec<&Msg> = read.topics["/tf"]
        .iter()
        .filter(|m| m.values[0] == "world>plate")
        .collect();
    for topic in ["/truth/pose", "/truth/twist", "/truth/imu"] {
        assert_eq!(read.topics[topic].len(), rows.len(), "{topic}");
    }
    assert_eq!(tf.len(), rows.len(), "/tf world>plate");
    for (i, row) in rows.iter().enumerate() {
        let t_ns: u64 = row[0].parse().unwrap();
        let pos = nums(row, &h, ["x", "y", "z"]);
        let q = nums(row, &h, ["qx", "qy", "qz", "qw"]);
        let rate = nums(row, &h, ["wx", "wy", "wz"]);
        let pose = &read.topics["/truth/pose"][i];
        at(pose, t_ns, "/truth/pose");
        assert_eq!(pose.frame, "world");
        assert_eq!(pose.fs::<3>(0), pos, "pose {i}");
        assert_eq!(pose.fs::<4>(3), q, "pose {i}");
        let twist = &read.topics["/truth/twist"][i];
        at(twist, t_ns, "/truth/twist");
        assert_eq!(twist.frame, "plate");
        assert_eq!(twist.fs::<3>(3), rate, "twist {i}");
        // The velocity, world frame in truth.csv, is in plate axes: rotate it back.
        let rot = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            q[3], q[0], q[1], q[2],
        ));
        let v_world = rot * nalgebra::Vector3::from(twist.fs::<3>(0));
        let want = nums(row, &h, ["vx", "vy", "vz"]);
        for k in 0..3 {
            assert!(
                (v_world[k] - want[k]).abs() < 1e-12,
                "twist {i}: {v_world:?}"
            );
        }
        let imu = &read.topics["/truth/imu"][i];
        at(imu, t_ns, "/truth/imu");
        assert_eq!(imu.fs::<4>(0), q);
        assert_eq!(imu.fs::<3>(4), rate);
        assert_eq!(imu.fs::<3>(7), nums(row, &h, ["fx", "fy", "fz"]));
        at(tf[i], t_ns, "/tf");
        assert_eq!(tf[i].fs::<3>(1), pos);
        assert_eq!(tf[i].fs::<4>(4), q);
    }
}

#[test]
fn simulate_writes_a_run_mcap_both_readers_decode_as_its_csv_files() {
    if !readers_installed() {
        return;
    }
    let dir = scratch("simulate");
    let run = dir.join("run");
    let scene = dir.join("scene.toml");
    margemu(&[
        "simulate",
        scene.to_str().unwrap(),
        "-o",
        run.to_str().unwrap(),
        "--mcap",
    ]);
    let read = read(&run.join("run.mcap"));
    check_truth(&read, &run);
    let (h, rows) = csv(&run.join("marg.csv"));
    let (imu, mag) = (&read.topics["/mpu9250/imu"], &read.topics["/mpu9250/mag"]);
    assert_eq!((imu.len(), mag.len()), (rows.len(), rows.len()));
    let f32s = |row: &[String], names: [&str; 3]| names.map(|n| f64::from(num(row, &h, n) as f32));
    for (i, row) in rows.iter().enumerate() {
        let t_ns: u64 = row[0].parse().unwrap();
        at(&imu[i], t_ns, "imu");
        at(&mag[i], t_ns, "mag");
        assert_eq!(imu[i].frame, "plate");
        assert_eq!(imu[i].f(10), -1.0, "orientation unknown");
        assert_eq!(imu[i].fs::<3>(4), f32s(row, ["gyr_x", "gyr_y", "gyr_z"]));
        assert_eq!(imu[i].fs::<3>(7), f32s(row, ["acc_x", "acc_y", "acc_z"]));
        // nu → µT (50 per nu) → T, as the docs state.
        let tesla = f32s(row, ["mag_x", "mag_y", "mag_z"]).map(|b| b * 50.0 / 1e6);
        assert_eq!(mag[i].fs::<3>(0), tesla, "mag {i}");
    }
    assert!(
        !read.topics.contains_key("/events"),
        "simulate has no events"
    );
    assert!(!read.topics.contains_key("/dut/attitude"));
    assert_eq!(read.meta["scene"], "scene");
    assert_eq!(read.meta["seed"], "3");
    assert_eq!(read.meta["field_unit"], "nu");
    assert_eq!(read.meta["tesla_per_unit"], "0.00005");
    let key = ("/mpu9250/mag".to_string(), "tesla_per_unit".to_string());
    assert_eq!(read.channel_meta[&key], "0.00005");
}

#[test]
fn a_loopback_session_with_a_flight_controller_writes_a_session_mcap_as_its_csv_files() {
    if !readers_installed() {
        return;
    }
    let dir = scratch("loopback");
    let session = dir.join("session");
    let scene = dir.join("scene.toml");
    margemu(&[
        "loopback",
        scene.to_str().unwrap(),
        "-o",
        session.to_str().unwrap(),
        "--vfc",
        "ecf",
        "--mcap",
    ]);
    let read = read(&session.join("session.mcap"));
    check_truth(&read, &session);
    let meta = read_meta(&session).unwrap();
    let start = meta.start_host_ns;

    // The device: every first copy of an image in sent.csv, decoded by the chip's module.
    let (h, rows) = csv(&session.join("sent.csv"));
    let firsts: Vec<&Vec<String>> = rows
        .iter()
        .filter(|r| r[col(&h, "resend")] == "0")
        .collect();
    let (imu, mag) = (&read.topics["/mpu9250/imu"], &read.topics["/mpu9250/mag"]);
    assert_eq!((imu.len(), mag.len()), (firsts.len(), firsts.len()));
    for (i, row) in firsts.iter().enumerate() {
        let t_ns: u64 = row[col(&h, "t_ns")].parse().unwrap();
        let len = meta.chip.model.image_len();
        let image = Image::parse_hex(&row[col(&h, "image")], len).unwrap();
        let r = meta.chip.decode(&image).unwrap();
        at(&imu[i], t_ns, "device imu");
        assert_eq!(imu[i].frame, "mpu9250");
        assert_eq!(imu[i].fs::<3>(4), r.gyr);
        assert_eq!(imu[i].fs::<3>(7), r.acc);
        at(&mag[i], t_ns, "device mag");
        assert_eq!(mag[i].fs::<3>(0), r.mag_ut.unwrap().map(|b| b / 1e6));
    }

    // The device under test: every attitude row, at its host time on the scene's clock.
    let (h, rows) = csv(&session.join("dut_attitude.csv"));
    let dut = &read.topics["/dut/attitude"];
    assert!(rows.len() > 100, "{} attitude rows", rows.len());
    assert_eq!(dut.len(), rows.len());
    let dut_tf: Vec<&Msg> = read.topics["/tf"]
        .iter()
        .filter(|m| m.values[0] == "world>dut")
        .collect();
    assert_eq!(dut_tf.len(), rows.len());
    let mut by_time: Vec<(u64, [f64; 4])> = rows
        .iter()
        .map(|r| {
            let host_ns: i64 = r[0].parse().unwrap();
            let q = nums(r, &h, ["qx", "qy", "qz", "qw"]);
            ((host_ns - start).max(0) as u64, q)
        })
        .collect();
    by_time.sort_by_key(|(t, _)| *t);
    for (i, (t_ns, q)) in by_time.iter().enumerate() {
        at(&dut[i], *t_ns, "dut attitude");
        assert_eq!(dut[i].fs::<4>(3), *q, "dut {i}");
        at(dut_tf[i], *t_ns, "dut tf");
        assert_eq!(dut_tf[i].fs::<4>(4), *q);
    }

    // The events: every row of events.csv but the reader's summary, written after the end.
    let (_, rows) = csv(&session.join("events.csv"));
    let events = &read.topics["/events"];
    let logged: Vec<&Vec<String>> = rows.iter().filter(|r| r[1] != "dut").collect();
    assert_eq!(events.len(), logged.len());
    for (m, row) in events.iter().zip(logged) {
        let host_ns: i64 = row[0].parse().unwrap();
        at(m, (host_ns - start).max(0) as u64, &row[1]);
        let want = match row[2].as_str() {
            "" => row[1].clone(),
            detail => format!("{}: {detail}", row[1]),
        };
        // events.csv turns the commas of a detail into semicolons.
        assert_eq!(m.values[0].replace(',', ";"), want);
    }
    assert_eq!(read.meta["field_unit"], "nu");
}
