//! The `margemu` binary: `scene check`, `simulate` and its byte-identical reruns.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn margemu(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(args)
        .output()
        .expect("runs margemu")
}

fn fixture(name: &str) -> String {
    format!(
        "{}/../hil-fixtures/scenes/{name}",
        env!("CARGO_MANIFEST_DIR")
    )
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("margemu-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn same_scene_and_seed_give_byte_identical_files() {
    // The case-study scene draws random setpoints and sines from its seed.
    let (a, b) = (scratch("a"), scratch("b"));
    for dir in [&a, &b] {
        let out = margemu(&[
            "simulate",
            &fixture("case-study.toml"),
            "-o",
            dir.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    for file in ["truth.csv", "meta.toml", "marg.csv", "perturbation.csv"] {
        let (x, y) = (
            std::fs::read(a.join(file)).unwrap(),
            std::fs::read(b.join(file)).unwrap(),
        );
        assert!(x.len() > 1000, "{file} is too short");
        assert!(x == y, "{file} differs between two runs");
    }
    // Another seed gives another run.
    let text = std::fs::read_to_string(fixture("case-study.toml"))
        .unwrap()
        .replace("seed = 2021", "seed = 2022");
    let other = scratch("c");
    std::fs::create_dir_all(&other).unwrap();
    let scene = other.join("case-study-2022.toml");
    std::fs::write(&scene, text).unwrap();
    let run = other.join("run");
    let out = margemu(&[
        "simulate",
        scene.to_str().unwrap(),
        "-o",
        run.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    assert_ne!(
        std::fs::read(a.join("truth.csv")).unwrap(),
        std::fs::read(run.join("truth.csv")).unwrap()
    );
}

#[test]
fn simulate_writes_truth_with_the_documented_header_and_metadata() {
    let dir = scratch("header");
    let out = margemu(&[
        "simulate",
        &fixture("static.toml"),
        "-o",
        dir.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let truth = std::fs::read_to_string(dir.join("truth.csv")).unwrap();
    let header = truth.lines().next().unwrap();
    assert!(
        header.starts_with("t_ns,x,y,z,roll,pitch,yaw,qw,qx,qy,qz,wx,wy,wz,fx,fy,fz,"),
        "{header}"
    );
    assert_eq!(truth.lines().count(), 1 + 2000);
    assert_eq!(
        truth.lines().nth(2).unwrap().split(',').next(),
        Some("5000000")
    );
    let meta: toml::Table = std::fs::read_to_string(dir.join("meta.toml"))
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(meta["seed"].as_integer(), Some(1));
    assert_eq!(meta["scene_sha256"].as_str().map(str::len), Some(64));
    assert!(meta["scene_text"]
        .as_str()
        .unwrap()
        .contains("motion = \"static\""));
}

#[test]
fn scene_check_prints_the_derived_gains() {
    let out = margemu(&["scene", "check", &fixture("figure3.toml")]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.starts_with("ok: "), "{text}");
    for joint in ["x ", "y ", "z ", "roll ", "pitch ", "yaw "] {
        assert!(
            text.lines().any(|l| l.starts_with(joint)),
            "no row for {joint} in {text}"
        );
    }
    assert!(text.contains("Kp") && text.contains("Ki") && text.contains("Kd"));
}

#[test]
fn a_bad_scene_fails_with_its_location() {
    let dir = scratch("bad");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("bad.toml");
    std::fs::write(
        &scene,
        "duration = 1.0\nrate = 100.0\nseed = 1\n[bench]\nplate_mass = -1.0\n",
    )
    .unwrap();
    for args in [
        vec!["scene", "check"],
        vec!["simulate", "-o", dir.to_str().unwrap()],
    ] {
        let mut args = args.clone();
        args.insert(
            if args[0] == "scene" { 2 } else { 1 },
            scene.to_str().unwrap(),
        );
        let out = margemu(&args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(
            err.contains(&format!("{}:5:14: `bench.plate_mass`", scene.display())),
            "{err}"
        );
    }
    assert!(
        !Path::new(&dir.join("truth.csv")).exists(),
        "no output for a refused scene"
    );
}

#[test]
fn chips_lists_every_model_with_its_facts() {
    let out = margemu(&["chips"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for part in [
        "MPU-9250",
        "MPU-6500",
        "MPU-6000",
        "ICM-20602",
        "ICM-42688-P",
        "BMI270",
        "BMI088",
    ] {
        assert!(
            text.contains(&format!("{part} ([chip] model")),
            "{part}: {text}"
        );
    }
    let out = margemu(&["chips", "icm42688p"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("WHO_AM_I:     0x47"), "{text}");
    assert!(text.contains("image:        32 bytes"), "{text}");
    assert!(
        text.contains("± 15.625, 31.25, 62.5, 125, 250, 500, 1000, 2000 °/s"),
        "{text}"
    );
    assert!(text.contains("not emulated:"), "{text}");
    let out = margemu(&["chips", "bmi270"]);
    let text = String::from_utf8_lossy(&out.stdout);
    for line in [
        "CHIP_ID:      0x24",
        "buses:        SPI, I2C at 0x68, 0x69",
        "accel ranges: ± 2, 4, 8, 16 g (power-on ±8 g)",
        "gyro ranges:  ± 125, 250, 500, 1000, 2000 °/s (power-on ±2000 °/s)",
        "output rates: 3200 Hz, 1600 Hz, 800 Hz, 400 Hz, 200 Hz, 100 Hz, 50 Hz, 25 Hz (the gyro's",
        "image:        14 bytes",
    ] {
        assert!(text.contains(line), "{line}: {text}");
    }
    let out = margemu(&["chips", "bmi088"]);
    let text = String::from_utf8_lossy(&out.stdout);
    for line in [
        "ACC_CHIP_ID:  0x1e",
        "buses:        SPI on 2 chip selects (accel die, then gyro die), I2C at 0x18, 0x19 \
         (accel die; gyro die at 0x68, 0x69 alike)",
        "accel ranges: ± 3, 6, 12, 24 g (power-on ±6 g)",
        "gyro ranges:  ± 125, 250, 500, 1000, 2000 °/s (power-on ±2000 °/s)",
        "output rates: 2000 Hz, 1000 Hz, 400 Hz, 200 Hz, 100 Hz (the gyro's",
        "image:        14 bytes",
    ] {
        assert!(text.contains(line), "{line}: {text}");
    }
    let out = margemu(&["chips", "bmi999"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("no chip model \"bmi999\"; margemu emulates mpu9250"),
        "{err}"
    );
}

/// Output into a pipe nobody reads (`margemu … | head` after head has quit) ends the process
/// by SIGPIPE, as for any command-line tool, instead of a panic in `println!`.
#[test]
fn output_into_a_closed_pipe_ends_quietly() {
    use std::os::unix::process::ExitStatusExt;
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(["scene", "check", &fixture("case-study.toml")])
        .stdout(writer)
        .stderr(std::process::Stdio::piped())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    const SIGPIPE: i32 = 13; // Linux
    assert_eq!(out.status.signal(), Some(SIGPIPE), "{:?}", out.status);
}
