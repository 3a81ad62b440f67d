//! A whole `margemu hitl` session against `mock_px4`, a stand-in flight controller on the far
//! end of a real pseudo-terminal: it decodes the HIL_SENSOR frames, runs margemu's reference
//! EKF and answers with ATTITUDE_QUATERNION on its own boot clock; `margemu evaluate` scores
//! the session. The scored figures do not depend on the machine's load: the flight controller
//! stamps each answer with its sample's time (its boot offset added), and the evaluation maps
//! those device times onto the scene's axis with its clock fit. And bad input: a port that is
//! not there, an address that is none, a scene the line cannot carry.

mod hitl_support;

use hitl_support::{fresh, margemu, mock_px4, spawn_margemu, MockReport, SAMPLES};
use margemu::evaluate::run::{evaluate, Clock, EvalOptions, Source};
use serialport::{SerialPort, TTYPort};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn a_flight_controllers_attitude_comes_back_and_is_scored() {
    let (dir, scene) = fresh("hitl_session_mock_px4");
    let (mut master, slave) = TTYPort::pair().expect("a pseudo-terminal pair");
    master.set_timeout(Duration::from_millis(5)).unwrap();
    let path = slave.name().expect("the PTY's path");
    let done = Arc::new(AtomicBool::new(false));
    let flag = done.clone();
    let fc = std::thread::spawn(move || mock_px4(master, [20.0, 0.0, -40.0], &flag));
    let session = dir.join("session");
    let s = session.to_str().unwrap();
    let child = spawn_margemu(&["hitl", scene.to_str().unwrap(), "--port", &path, "-o", s]);
    let out = child.wait_with_output().unwrap();
    done.store(true, Ordering::Relaxed);
    let report: MockReport = fc.join().unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(report.hil_sensors, SAMPLES as u64, "{report:?}");
    assert_eq!(report.heartbeats, 2, "{report:?}");
    assert_eq!(report.bad_frames, 0, "{report:?}");
    drop(slave);

    // Every answer was read back: the reader's rows are the flight controller's replies.
    let rows = hitl_support::csv_rows(&session.join("dut_attitude.csv"));
    assert_eq!(rows.len() as u64, report.replies);
    let meta = std::fs::read_to_string(session.join("meta.toml")).unwrap();
    assert!(
        meta.contains("[dut]") && meta.contains("status = \"complete\""),
        "{meta}"
    );
    let events = std::fs::read_to_string(session.join("events.csv")).unwrap();
    assert!(events.contains(",start,start_host_ns "), "{events}");

    let scored = margemu(&["evaluate", s]);
    assert!(scored.status.success(), "{}", stderr(&scored));
    let eval = evaluate(&Source::Session(session.clone()), &EvalOptions::default()).unwrap();
    let scores = &eval.scores;
    eprintln!(
        "mock_px4 (EKF) through margemu hitl: geodesic RMS {:.3}° max {:.3}° over {} instants; latency {:?}; clock {:?}",
        scores.geodesic_rms.to_degrees(),
        scores.geodesic_max.to_degrees(),
        scores.count,
        eval.latency_applied_ns,
        eval.clock
    );
    // The device clock (boot time) is found and used: 73 s ahead of scene time.
    match &eval.clock {
        Clock::Fitted(_, used) => assert!(*used, "{:?}", eval.clock),
        other => panic!("no clock fit: {other:?}"),
    }
    assert!(scores.count >= SAMPLES * 9 / 10, "{}", scores.count);
    assert!(scores.geodesic_rms.to_degrees() < 2.0, "{scores:?}");
}

#[test]
fn a_port_that_is_not_there_is_named() {
    let (dir, scene) = fresh("hitl_session_no_port");
    let o = dir.join("session");
    let out = margemu(&[
        "hitl",
        scene.to_str().unwrap(),
        "--port",
        "/dev/margemu-no-such-port",
        "-o",
        o.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let e = stderr(&out);
    assert!(
        e.contains("cannot open the flight controller's port /dev/margemu-no-such-port"),
        "{e}"
    );
    assert!(!o.exists(), "nothing is written before the link is open");
    // A scene in normalized units is sent at --gauss-per-unit, with a warning.
    let out = margemu(&[
        "hitl",
        "figure3",
        "--port",
        "/dev/margemu-no-such-port",
        "--gauss-per-unit",
        "0.45",
    ]);
    let e = stderr(&out);
    assert!(
        e.contains(
            "warning: the scene's field is in normalized units; sent as 0.45 gauss per unit"
        ),
        "{e}"
    );
}

#[test]
fn a_bad_udp_address_is_named() {
    let (_, scene) = fresh("hitl_session_bad_udp");
    let s = scene.to_str().unwrap();
    for (args, expected) in [
        (
            vec!["--udp", "localhost"],
            "--udp `localhost` is no usable address",
        ),
        (
            vec!["--udp", "no.such.host.invalid:14560"],
            "--udp `no.such.host.invalid:14560` is no usable address",
        ),
        (
            vec!["--udp", "127.0.0.1:14560", "--bind", "127.0.0.1:x"],
            "--bind `127.0.0.1:x` is no usable address",
        ),
    ] {
        let mut all = vec!["hitl", s];
        all.extend(args);
        let out = margemu(&all);
        assert!(!out.status.success());
        assert!(stderr(&out).contains(expected), "{}", stderr(&out));
    }
}

#[test]
fn a_scene_the_line_cannot_carry_is_refused() {
    let (dir, scene) = fresh("hitl_session_slow_line");
    let (_master, slave) = TTYPort::pair().expect("a pseudo-terminal pair");
    let path = slave.name().unwrap();
    let o = dir.join("session");
    let out = margemu(&[
        "hitl",
        scene.to_str().unwrap(),
        "--port",
        &path,
        "--baud",
        "57600",
        "-o",
        o.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let e = stderr(&out);
    assert!(e.contains("the scene's 100 Hz needs 76210 bit/s"), "{e}");
    assert!(e.contains("more than the line's 57600 baud"), "{e}");
    let out = margemu(&[
        "hitl",
        scene.to_str().unwrap(),
        "--port",
        &path,
        "--gauss-per-unit",
        "0",
        "-o",
        o.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
}
