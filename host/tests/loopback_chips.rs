//! Every chip's fixture scene streams through `margemu loopback` in both source modes, and the
//! real firmware link handler serves every image as the host predicted, byte for byte; the
//! session's `meta.toml` records the chip; `--chip` swaps the chip of a scene.

mod common;

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../hil-fixtures/scenes")
        .join(name)
}

/// Runs `margemu loopback` on `scene` with `args`; returns stdout and the session directory.
fn loopback(scene: &Path, tag: &str, args: &[&str]) -> (String, PathBuf) {
    let dir = std::env::temp_dir().join(format!("margemu-chips-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut argv = vec![
        OsStr::new("loopback"),
        scene.as_os_str(),
        "-o".as_ref(),
        dir.as_os_str(),
    ];
    argv.extend(args.iter().map(OsStr::new));
    let stdout = common::margemu(&argv);
    (stdout, dir)
}

fn meta(dir: &Path) -> toml::Table {
    std::fs::read_to_string(dir.join("meta.toml"))
        .unwrap()
        .parse()
        .unwrap()
}

fn check_chip_fixture(file: &str, model: &str, samples: usize, image_len: i64) {
    check_chip_scene(&fixture(file), model, samples, image_len);
}

fn check_chip_scene(scene: &Path, model: &str, samples: usize, image_len: i64) {
    for source in ["images", "model"] {
        let tag = format!("{model}-{source}");
        let (out, dir) = loopback(scene, &tag, &["--source", source]);
        let confirmed = format!("{samples} of {samples} predicted images confirmed byte for byte");
        assert!(out.contains(&confirmed), "{tag}: {out}");
        assert!(out.contains("(0 underruns, 0 overruns)"), "{tag}: {out}");
        let chip = meta(&dir)["chip"].as_table().unwrap().clone();
        assert_eq!(chip["model"].as_str(), Some(model), "{tag}");
        assert_eq!(chip["image_len"].as_integer(), Some(image_len), "{tag}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn icm42688p_fixture_is_served_as_predicted_in_both_source_modes() {
    check_chip_fixture("icm42688p.toml", "icm42688p", 8000, 32);
}

#[test]
fn bmi270_fixture_is_served_as_predicted_in_both_source_modes() {
    check_chip_fixture("bmi270.toml", "bmi270", 3200, 14);
}

#[test]
fn mpu6000_fixture_is_served_as_predicted_in_both_source_modes() {
    check_chip_fixture("mpu6000.toml", "mpu6000", 1000, 14);
}

/// A standalone magnetometer as the scene's only chip: its 6-byte images (at the scene's range)
/// are served as predicted in both source modes, whatever rate the scene runs at.
#[test]
fn magnetometers_alone_are_served_as_predicted_in_both_source_modes() {
    let dir = std::env::temp_dir().join(format!("margemu-mag-scenes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (model, chip_table) in [
        (
            "ist8310",
            "model = \"ist8310\"\nbus = \"i2c\"\naddress = 0x0C\n",
        ),
        ("qmc5883l", "model = \"qmc5883l\"\nmag_range = 8\n"),
        ("rm3100", "model = \"rm3100\"\nbus = \"spi\"\n"),
    ] {
        let scene = dir.join(format!("{model}.toml"));
        let text = format!(
            "duration = 1.0\nrate = 250.0\nseed = 31\nmotion = \"kinematic\"\n\n[chip]\n{chip_table}\n\
             [joints.yaw]\ntype = \"sine\"\namplitude = 1.5\nfrequency = 1.0\n"
        );
        std::fs::write(&scene, text).unwrap();
        let image_len = if model == "rm3100" { 9 } else { 6 };
        check_chip_scene(&scene, model, 250, image_len);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The fixture rig (an ICM-42688-P on SPI and an IST8310 on I2C): every rig image served as
/// predicted; `sent.csv` names each device's image column, `meta.toml` lists the other device.
#[test]
fn rig_fixture_serves_every_devices_image_as_predicted() {
    let (out, dir) = loopback(&fixture("rig.toml"), "rig", &[]);
    assert!(
        out.contains("1000 of 1000 predicted images confirmed byte for byte"),
        "{out}"
    );
    let sent = std::fs::read_to_string(dir.join("sent.csv")).unwrap();
    let mut lines = sent.lines();
    assert_eq!(
        lines.next(),
        Some("index,t_ns,send_ns,late_ns,image.imu,image.compass,resend")
    );
    let row: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!((row[4].len(), row[5].len()), (64, 12), "{row:?}");
    check_device_truth(&dir);
    let meta = meta(&dir);
    assert_eq!(meta["chip"]["name"].as_str(), Some("imu"));
    let others = meta["other_devices"].as_array().unwrap();
    assert_eq!(others.len(), 1);
    assert_eq!(others[0]["model"].as_str(), Some("ist8310"));
    assert_eq!(others[0]["name"].as_str(), Some("compass"));
    // Source model cannot run a rig: refused before anything is sent, with the reason.
    let out = Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(["loopback", "--source", "model", "--force", "-o"])
        .arg(&dir)
        .arg(fixture("rig.toml"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("a rig streams register images"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The BMI088 (both dies behind one device) in both source modes: on SPI at its fastest gyro
/// ODR (2 kHz; the accel takes 4 images of 5 at 1.6 kHz) at ±24 g, upside down, and on I2C at
/// 0x19 (its gyro at 0x69) at 400 Hz, ±3 g and ±250 °/s: every 14-byte image as predicted.
#[test]
fn bmi088_is_served_as_predicted_in_both_source_modes() {
    let dir = std::env::temp_dir().join(format!("margemu-bmi088-scenes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (tag, rate, chip_table) in [
        (
            "spi",
            2000,
            "bus = \"spi\"\naccel_range = 24\ngyro_range = 2000\n\
             rotation = [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]\n",
        ),
        (
            "i2c",
            400,
            "bus = \"i2c\"\naddress = 0x19\naccel_range = 3\ngyro_range = 250\n",
        ),
    ] {
        let scene = dir.join(format!("bmi088-{tag}.toml"));
        let text = format!(
            "duration = 1.0\nrate = {rate}.0\nseed = 88\nmotion = \"kinematic\"\n\n\
             [chip]\nmodel = \"bmi088\"\n{chip_table}\n\
             [joints.roll]\ntype = \"sine\"\namplitude = 0.5\nfrequency = 2.0\n\n\
             [joints.yaw]\ntype = \"sine\"\namplitude = 1.0\nfrequency = 1.0\n\n\
             [sensors.gyro]\nnoise_density = [0.004, 0.004, 0.004]\n\n\
             [sensors.accel]\nnoise_density = [0.02, 0.02, 0.02]\n"
        );
        std::fs::write(&scene, text).unwrap();
        check_chip_scene(&scene, "bmi088", rate, 14);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A rig of three (an ICM-42688-P on chip select 0, a BMI088 on 1 and 2, an RM3100 on 3, at
/// 1 kHz): every rig image (32 + 14 + 9 bytes) served as predicted, each device's column named.
#[test]
fn a_rig_with_a_bmi088_serves_every_devices_image_as_predicted() {
    let dir = std::env::temp_dir().join(format!("margemu-bmi088-rig-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("rig.toml");
    let text = "duration = 1.0\nrate = 1000.0\nseed = 4268\nmotion = \"kinematic\"\n\n\
        [[device]]\nname = \"icm\"\nmodel = \"icm42688p\"\naccel_range = 16\n\n\
        [[device]]\nname = \"bmi\"\nmodel = \"bmi088\"\nchip_select = 1\naccel_range = 24\n\
        offset = [0.01, 0.0, 0.0]\n\n\
        [[device]]\nname = \"mag\"\nmodel = \"rm3100\"\nchip_select = 3\n\
        rotation = [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]\n\n\
        [joints.pitch]\ntype = \"sine\"\namplitude = 0.4\nfrequency = 1.5\n\n\
        [sensors.gyro]\nnoise_density = [0.004, 0.004, 0.004]\n";
    std::fs::write(&scene, text).unwrap();
    let (out, run) = loopback(&scene, "bmi088-rig", &[]);
    assert!(
        out.contains("1000 of 1000 predicted images confirmed byte for byte"),
        "{out}"
    );
    assert!(out.contains("(0 underruns, 0 overruns)"), "{out}");
    let sent = std::fs::read_to_string(run.join("sent.csv")).unwrap();
    let mut lines = sent.lines();
    assert_eq!(
        lines.next(),
        Some("index,t_ns,send_ns,late_ns,image.icm,image.bmi,image.mag,resend")
    );
    let row: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!((row[4].len(), row[5].len(), row[6].len()), (64, 28, 18));
    let others = meta(&run)["other_devices"].as_array().unwrap().clone();
    let models: Vec<_> = others
        .iter()
        .map(|d| d["model"].as_str().unwrap())
        .collect();
    assert_eq!(models, ["bmi088", "rm3100"]);
    assert_eq!(others[0]["chip_select"].as_integer(), Some(1));
    let _ = std::fs::remove_dir_all(&run);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `device_truth.csv` of the fixture rig: a row per sample and device; the compass (flipped
/// about x, 2 cm and 4 cm off the centre) sees the IMU's rate and field turned by its rotation,
/// and a specific force that differs from the IMU's turned one by its lever arm alone.
fn check_device_truth(dir: &Path) {
    let text = std::fs::read_to_string(dir.join("device_truth.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("t_ns,device,wx,wy,wz,fx,fy,fz,dwx,dwy,dwz,mx,my,mz")
    );
    let rows: Vec<Vec<String>> = lines
        .map(|l| l.split(',').map(str::to_owned).collect())
        .collect();
    assert_eq!(rows.len(), 2 * 1000);
    let num = |row: &[String], i: usize| row[i].parse::<f64>().unwrap();
    let vector = |row: &[String], first: usize| [0, 1, 2].map(|k| num(row, first + k));
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    // The fixture's compass: flipped about x, at r = (0, 0.02, -0.04) m on the plate.
    let (flip, r) = ([1.0, -1.0, -1.0], [0.0, 0.02, -0.04]);
    let mut largest_lever = 0.0f64;
    for pair in rows.chunks(2) {
        let [imu, compass] = pair else { panic!() };
        assert_eq!(
            (imu[1].as_str(), compass[1].as_str(), &imu[0]),
            ("imu", "compass", &compass[0])
        );
        // The IMU sits at the plate's reference point with its axes: its rows are the plate's.
        let (w, f, dw) = (vector(imu, 2), vector(imu, 5), vector(imu, 8));
        let lever = [cross(dw, r), cross(w, cross(w, r))];
        for axis in 0..3 {
            for first in [2, 11] {
                // Rate and field: the same vectors in the flipped axes, exactly.
                assert_eq!(
                    num(compass, first + axis),
                    flip[axis] * num(imu, first + axis)
                );
            }
            // f + ω̇×r + ω×(ω×r), in the compass's axes.
            let at_r = f[axis] + lever[0][axis] + lever[1][axis];
            let got = num(compass, 5 + axis);
            assert!((got - flip[axis] * at_r).abs() < 1e-9, "{got} vs {at_r}");
            largest_lever = largest_lever.max((lever[0][axis] + lever[1][axis]).abs());
        }
    }
    // The wobble's angular acceleration makes the lever arm felt: metres per second squared.
    assert!(largest_lever > 0.5, "{largest_lever}");
}

#[test]
fn chip_flag_swaps_the_chip_or_says_why_not() {
    let (out, dir) = loopback(&fixture("figure3.toml"), "swap", &["--chip", "icm20602"]);
    assert!(
        out.contains("3000 of 3000 predicted images confirmed byte for byte"),
        "{out}"
    );
    let chip = meta(&dir)["chip"].as_table().unwrap().clone();
    assert_eq!(chip["model"].as_str(), Some("icm20602"));
    let _ = std::fs::remove_dir_all(&dir);
    let out = Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(["loopback", "--chip", "bmi999"])
        .arg(fixture("figure3.toml"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no chip model \"bmi999\""), "{err}");
}
