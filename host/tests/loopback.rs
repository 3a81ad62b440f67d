//! `margemu loopback`: the real firmware link handler behind a pseudo-terminal pair serves
//! every sample, and every image it served equals the host's prediction byte for byte.

use std::process::Command;

fn loopback(scene_text: &str, name: &str) -> String {
    let dir = std::env::temp_dir().join(format!("margemu-loopback-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, scene_text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_margemu"))
        .arg("loopback")
        .arg(&scene)
        .arg("-o")
        .arg(dir.join("session"))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
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
