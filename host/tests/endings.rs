//! How runs end: SIGTERM and SIGHUP end a session as SIGINT does (Stop sent to the device, an
//! `end` row, the completion record says interrupted, the device under test's summary kept), and
//! a clean loopback reports its device stopped. The real binary, real signals, real PTYs.

mod common;

use common::{completion, has_event, long_scene, scratch, send_signal, spawn_margemu, wait_until};
use margemu::rundir::Status;
use std::ffi::OsStr;
use std::path::Path;

/// Starts `margemu loopback` on a long scene into `dir` (with `extra` arguments), sends `signal`
/// once the session has started, and checks it ended as an interrupted session does.
fn interrupt_loopback(name: &str, signal: &str, extra: &[&str]) -> std::path::PathBuf {
    let work = scratch(name);
    let scene = long_scene(&work, 30.0);
    let dir = work.join("session");
    let mut args: Vec<&OsStr> = vec!["loopback".as_ref(), scene.as_os_str()];
    args.extend(["-o".as_ref(), dir.as_os_str()]);
    args.extend(extra.iter().map(OsStr::new));
    let mut child = spawn_margemu(&args, &work);
    wait_until(&mut child, "the session's start row", || {
        has_event(&dir, "start")
    });
    send_signal(&child, signal);
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    // An error exit of margemu's own, not a death by the signal.
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("interrupted"), "{stderr}");
    let (_, mut events) = common::read_csv(&dir, "events.csv");
    // With a device under test, its reader's summary follows the session's `end` row.
    if events.last().is_some_and(|e| e[1] == "dut") {
        events.pop();
    }
    assert_eq!(events.last().unwrap()[1], "end", "{events:?}");
    assert!(
        events.iter().any(|e| e[1] == "stopped"),
        "the device was not stopped: {events:?}"
    );
    let last = events.last().unwrap();
    assert!(last[2].contains("interrupted"), "{last:?}");
    let record = completion(&dir).expect("a completion record");
    assert_eq!(record.status, Status::Interrupted, "{record:?}");
    assert!(record.samples_written < record.samples_expected.unwrap());
    dir
}

#[test]
fn sigterm_ends_a_loopback_session_as_sigint_does() {
    interrupt_loopback("sigterm", "TERM", &[]);
}

#[test]
fn sighup_ends_a_loopback_session_as_sigint_does() {
    interrupt_loopback("sighup", "HUP", &[]);
}

#[test]
fn sigterm_keeps_the_flight_controllers_summary() {
    let dir = interrupt_loopback("sigterm-vfc", "TERM", &["--vfc", "ecf"]);
    let meta = std::fs::read_to_string(dir.join("meta.toml")).unwrap();
    let dut = meta.find("\n[dut]").expect("a [dut] table");
    let done = meta.find("\n[completion]").expect("a [completion] table");
    assert!(dut < done, "the completion record is not last:\n{meta}");
    let (_, events) = common::read_csv(&dir, "events.csv");
    assert_eq!(events.last().unwrap()[1], "dut", "{events:?}");
}

#[test]
fn sigterm_ends_a_simulation_with_its_record() {
    let work = scratch("sigterm-simulate");
    let (child, dir) = common::simulating(&work);
    let partial = dir.join("truth.csv.partial");
    send_signal(&child, "TERM");
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let record = completion(&dir).expect("a completion record");
    assert_eq!(record.status, Status::Interrupted, "{record:?}");
    // The files got their names, and hold every sample the record counts.
    let rows = std::fs::read_to_string(dir.join("truth.csv"))
        .unwrap()
        .lines()
        .count() as u64;
    assert_eq!(rows, record.samples_written + 1);
    assert!(!partial.exists());
    // `filter` does not take the interrupted run for a whole one either.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(["filter", "--filter", "ecf"])
        .arg(&dir)
        .arg("-o")
        .arg(work.join("estimates.csv"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("holds an incomplete run: meta.toml's completion record says interrupted"),
        "{err}"
    );
}

#[test]
fn a_clean_loopback_reports_its_device_stopped() {
    let dir = scratch("clean-loopback");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../hil-fixtures/scenes/mpu6000.toml");
    let out = common::margemu(&[
        "loopback".as_ref(),
        scene.as_os_str(),
        "-o".as_ref(),
        dir.as_os_str(),
    ]);
    assert!(out.contains("; device stopped"), "{out}");
    let record = completion(&dir).unwrap();
    assert_eq!(record.status, Status::Complete);
    assert_eq!(Some(record.samples_written), record.samples_expected);
}

#[test]
fn the_loopback_device_reports_stopped_when_the_host_hangs_up_after_stop() {
    use serialport::TTYPort;
    let scene = common::scene(0.2, 1000.0);
    let dir = scratch("device-stopped");
    let (host, device) = TTYPort::pair().unwrap();
    let session = margemu::stream::Session::new(&scene, common::config(), &dir).unwrap();
    let device = margemu::loopback::spawn_device(device).unwrap();
    session.run_on_port(host, |_| {}).unwrap();
    // The host's end is closed now (the session owned it): the device sees that before it is
    // told to stop, the order that used to end it with a port error.
    let mut guard = 0;
    while !device.has_ended() {
        guard += 1;
        assert!(
            guard < 6000,
            "the device did not notice the host hang up within a minute"
        );
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert_eq!(device.stop().ended, "stopped");
}

#[test]
fn sigterm_as_soon_as_the_directory_exists_still_ends_with_a_record() {
    // The handler is installed before the directory is made, so a signal while the session's
    // images are still being predicted ends the session as interrupted too.
    let work = scratch("sigterm-early");
    let scene = long_scene(&work, 60.0);
    let dir = work.join("session");
    let args: Vec<&OsStr> = vec![
        "loopback".as_ref(),
        scene.as_os_str(),
        "-o".as_ref(),
        dir.as_os_str(),
    ];
    let mut child = spawn_margemu(&args, &work);
    wait_until(&mut child, "the session directory", || dir.is_dir());
    send_signal(&child, "TERM");
    let out = child.wait_with_output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let record = completion(&dir).expect("a completion record");
    assert_eq!(record.status, Status::Interrupted, "{record:?}");
    let (_, events) = common::read_csv(&dir, "events.csv");
    assert_eq!(events.last().unwrap()[1], "end", "{events:?}");
}
