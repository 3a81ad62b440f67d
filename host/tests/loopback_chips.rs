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
    for source in ["images", "model"] {
        let tag = format!("{model}-{source}");
        let (out, dir) = loopback(&fixture(file), &tag, &["--source", source]);
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
