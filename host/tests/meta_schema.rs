//! `meta.toml` as the CLI writes it reads back through its schema (`margemu::meta`): a
//! `simulate` run with its completion record, and a `loopback` session with a virtual flight
//! controller with every table present (`[chip]`, `[image]`, `[device]`, `[dut]`,
//! `[completion]`).

use margemu::meta::{read, MetaFile};
use margemu::rundir::Status;
use std::path::{Path, PathBuf};
use std::process::Command;

const SCENE: &str = "duration = 1.0\nrate = 200.0\nseed = 5\nmotion = \"kinematic\"\n\
    [joints.roll]\ntype = \"sine\"\namplitude = 0.3\nfrequency = 0.5\n";

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("margemu-meta-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("scene.toml"), SCENE).unwrap();
    dir
}

fn margemu(dir: &Path, args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_margemu"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn a_simulate_run_reads_back_through_the_schema() {
    let dir = scratch("simulate");
    margemu(&dir, &["simulate", "scene.toml", "-o", "run"]);
    let meta = match read(&dir.join("run")).unwrap() {
        MetaFile::Run(m) => m,
        other => panic!("not a run: {other:?}"),
    };
    assert_eq!(meta.margemu_version, env!("CARGO_PKG_VERSION"));
    assert_eq!((meta.seed, meta.samples, meta.rate_hz), (5, 200, 200.0));
    assert_eq!(meta.motion, "kinematic");
    assert_eq!(meta.scene_text, SCENE);
    assert_eq!(meta.truth_columns[0], "t_ns");
    assert_eq!(meta.pid.len(), 6);
    let c = meta.completion.expect("a completion record");
    assert_eq!((c.status, c.samples_written), (Status::Complete, 200));
}

#[test]
fn a_loopback_session_with_a_flight_controller_reads_back_with_every_table() {
    let dir = scratch("loopback");
    margemu(
        &dir,
        &["loopback", "scene.toml", "-o", "session", "--vfc", "gda"],
    );
    let meta = match read(&dir.join("session")).unwrap() {
        MetaFile::Session(m) => m,
        other => panic!("not a session: {other:?}"),
    };
    assert_eq!(meta.protocol_version, margemu_protocol::PROTOCOL_VERSION);
    assert_eq!(
        (meta.seed, meta.samples, meta.source.as_str()),
        (5, 200, "images")
    );
    assert_eq!(meta.scene_text, SCENE);
    assert_eq!(meta.chip.model, "mpu9250");
    assert!(meta.image.is_some(), "no [image]");
    let device = meta.device.expect("a [device] table");
    assert_eq!(device.protocol_version, margemu_protocol::PROTOCOL_VERSION);
    let dut = meta.dut.expect("a [dut] table");
    assert_eq!(dut.protocol, "mavlink");
    assert_eq!(dut.messages, dut.per_message.values().sum::<u64>());
    assert!(
        dut.per_message.contains_key("ATTITUDE_QUATERNION"),
        "{dut:?}"
    );
    let c = meta.completion.expect("a completion record");
    assert_eq!((c.status, c.samples_written), (Status::Complete, 200));
}
