//! `margemu loopback`: the real firmware link handler behind a pseudo-terminal pair serves
//! every sample, and every image it served equals the host's prediction byte for byte.

mod common;

use std::ffi::OsStr;
use std::process::Command;

fn loopback(scene_text: &str, name: &str) -> String {
    loopback_with(scene_text, name, &[])
}

fn loopback_with(scene_text: &str, name: &str, args: &[&str]) -> String {
    let dir = std::env::temp_dir().join(format!("margemu-loopback-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, scene_text).unwrap();
    let session = dir.join("session");
    let mut argv = vec![
        OsStr::new("loopback"),
        scene.as_os_str(),
        "-o".as_ref(),
        session.as_os_str(),
    ];
    argv.extend(args.iter().map(OsStr::new));
    let stdout = common::margemu(&argv);
    for log in [
        "meta.toml",
        "truth.csv",
        "sent.csv",
        "served.csv",
        "device.csv",
        "telemetry.csv",
        "events.csv",
    ] {
        assert!(dir.join("session").join(log).exists(), "{log} missing");
    }
    stdout
}

/// Every row of `served.csv` of the session in `dir` (after its header, checked).
fn served_rows(name: &str) -> Vec<Vec<String>> {
    let dir = std::env::temp_dir().join(format!("margemu-loopback-{}-{name}", std::process::id()));
    let text = std::fs::read_to_string(dir.join("session/served.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(margemu::stream::log::SERVED_COLUMNS));
    lines
        .map(|l| l.split(',').map(str::to_owned).collect())
        .collect()
}

#[test]
fn every_sample_is_served_and_confirmed_byte_for_byte() {
    let scene = "duration = 1.0\nrate = 1000.0\nseed = 4\nmotion = \"kinematic\"\n\
        [joints.roll]\ntype = \"sine\"\namplitude = 0.8\nfrequency = 1.0\n\
        [joints.x]\ntype = \"sine\"\namplitude = 0.1\nfrequency = 2.0\n\
        [sensors.gyro]\nnoise_density = [0.01, 0.01, 0.01]\n";
    let out = loopback(scene, "1khz");
    assert!(
        out.contains("served 1000 samples (0 underruns, 0 overruns)"),
        "{out}"
    );
    assert!(
        out.contains("1000 of 1000 predicted images confirmed byte for byte"),
        "{out}"
    );
    // served.csv: one row per instant, in order, at the scheduled instant, each a match.
    let rows = served_rows("1khz");
    assert_eq!(rows.len(), 1000);
    for (k, row) in rows.iter().enumerate() {
        assert_eq!(row[1], k.to_string());
        assert_eq!(row[2], (k * 1_000_000).to_string(), "device time of {k}");
        assert_eq!(row[3].len(), 8);
        assert_eq!(&row[4..], ["0", "0", "1"], "sample {k}");
    }
}

#[test]
fn an_8khz_scene_streams_without_loss() {
    let scene = "duration = 0.5\nrate = 8000.0\nseed = 5\nmotion = \"kinematic\"\n\
        [joints.yaw]\ntype = \"sine\"\namplitude = 1.0\nfrequency = 3.0\n";
    let out = loopback(scene, "8khz");
    assert!(
        out.contains("4000 of 4000 predicted images confirmed byte for byte"),
        "{out}"
    );
}

#[test]
fn source_model_serves_the_predicted_images_byte_for_byte() {
    // Noise, bias, a temperature ramp with its bias term, and µT: every model input the device
    // takes from Configure and the kinematics, held for 4 output samples each.
    let scene = "duration = 1.0\nrate = 1000.0\nseed = 9\nmotion = \"kinematic\"\n\
        [field]\nunit = \"uT\"\nreference = [20.0, 0.0, -45.0]\n\
        [joints.roll]\ntype = \"sine\"\namplitude = 0.8\nfrequency = 1.0\n\
        [joints.yaw]\ntype = \"sine\"\namplitude = 1.2\nfrequency = 0.5\n\
        [sensors]\ntemperature = [20.0, 5.0]\n\
        [sensors.gyro]\nnoise_density = [0.01, 0.01, 0.01]\nbias = [0.01, 0.0, -0.02]\n\
        temperature_bias = { coefficient = [0.001, 0.0, 0.0], reference = 25.0 }\n\
        [sensors.accel]\nnoise_density = [0.02, 0.02, 0.02]\n\
        [sensors.mag]\nnoise_density = [0.1, 0.1, 0.1]\nhard_iron = [1.0, -2.0, 0.5]\n";
    let out = loopback_with(
        scene,
        "model",
        &["--source", "model", "--kinematics-rate", "250"],
    );
    assert!(out.contains("sent 250/250 kinematics samples"), "{out}");
    assert!(
        out.contains("1000 of 1000 predicted images confirmed byte for byte"),
        "{out}"
    );
    let dir = std::env::temp_dir().join(format!(
        "margemu-loopback-{}-model/session",
        std::process::id()
    ));
    let meta: toml::Table = std::fs::read_to_string(dir.join("meta.toml"))
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(meta["source"].as_str(), Some("model"));
    assert_eq!(meta["kinematics_hold"].as_integer(), Some(4));
    let sent = std::fs::read_to_string(dir.join("sent.csv")).unwrap();
    let mut lines = sent.lines();
    assert_eq!(
        lines.next(),
        Some(margemu::stream::log::SENT_KINEMATICS_COLUMNS)
    );
    let second: Vec<&str> = lines.nth(1).unwrap().split(',').collect();
    assert_eq!((second[0], second[1]), ("1", "4000000"));
    assert_eq!(second[16], "20.02", "the temperature ramp at 4 ms");
    // The device stops by itself at the scene's end: exactly the scene's instants, in order,
    // none underrun, each as predicted (an instant after the end would have an empty match).
    let rows = served_rows("model");
    assert_eq!(rows.len(), 1000);
    for (k, row) in rows.iter().enumerate() {
        assert_eq!(row[1], k.to_string());
        assert_eq!(&row[4..], ["0", "0", "1"], "sample {k}");
    }
    assert!(out.contains("served 1000 samples (0 underruns"), "{out}");
}

#[test]
fn source_model_refuses_a_perturbation_before_sending_anything() {
    let scene = "duration = 1.0\nrate = 200.0\nseed = 3\nmotion = \"static\"\n\
        [perturbation]\namplitude = [0.0, 4.0]\n";
    let dir =
        std::env::temp_dir().join(format!("margemu-loopback-{}-perturbed", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("scene.toml"), scene).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(["loopback", "--source", "model", "-o"])
        .arg(dir.join("session"))
        .arg(dir.join("scene.toml"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("source mode model cannot run this scene: the scene has a [perturbation]"),
        "{stderr}"
    );
    assert!(
        !dir.join("session/sent.csv").exists(),
        "nothing prepared, nothing sent"
    );
    let calm = scene.replace("[perturbation]\namplitude = [0.0, 4.0]\n", "");
    std::fs::write(dir.join("calm.toml"), calm).unwrap();
    let bad_rate = Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args([
            "loopback",
            "--source",
            "model",
            "--kinematics-rate",
            "300",
            "-o",
        ])
        .arg(dir.join("session"))
        .arg(dir.join("calm.toml"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&bad_rate.stderr);
    assert!(
        stderr.contains("the kinematics rate 300 Hz does not divide the output rate 200 Hz"),
        "{stderr}"
    );
}
