//! `evaluate`'s reading of a rig session: a real `margemu loopback rig` session (an
//! ICM-42688-P on SPI and an IST8310 on I2C, mounted upside down, 1 kHz for 1 s), its `sent.csv`
//! decoded as a flight controller reads the rig: the specific force from the IMU's column, the
//! field from the compass's, turned into the IMU's axes; and a `meta.toml` whose compass has no
//! name refused at the file.

mod common;

use margemu::evaluate::device_log::{read_meta, read_sent};
use std::ffi::OsStr;
use std::path::{Path, PathBuf};

/// `margemu loopback rig -o DIR`.
fn rig_session(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("margemu-eval-rig-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let argv = [
        OsStr::new("loopback"),
        "rig".as_ref(),
        "-o".as_ref(),
        dir.as_os_str(),
    ];
    let out = common::margemu(&argv);
    assert!(
        out.contains("1000 of 1000 predicted images confirmed byte for byte"),
        "{out}"
    );
    dir
}

/// `(t_ns, [mx, my, mz], [fx, fy, fz])` of every `truth.csv` row (plate axes, scene unit).
fn truth(dir: &Path) -> Vec<(u64, [f64; 3], [f64; 3])> {
    let text = std::fs::read_to_string(dir.join("truth.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let at = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let [t, mx, fx] = [at("t_ns"), at("mx"), at("fx")];
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let v = |i: usize| -> [f64; 3] { std::array::from_fn(|k| f[i + k].parse().unwrap()) };
            (f[t].parse().unwrap(), v(mx), v(fx))
        })
        .collect()
}

#[test]
fn a_rigs_field_is_its_compass_in_the_imus_axes_within_resolution_and_noise() {
    let dir = rig_session("decode");
    let meta = read_meta(&dir).unwrap();
    let compass = meta.compass.clone().expect("the rig's IST8310");
    assert_eq!(compass.column, "image.compass");
    // The compass is upside down about x, the IMU mounted with the plate's axes.
    assert_eq!(
        compass.to_primary,
        [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]
    );
    let sent = read_sent(&dir.join("sent.csv"), &meta).unwrap();
    let truth = truth(&dir);
    assert_eq!(sent.t_ns.len(), 1000);
    assert_eq!(truth.len(), 1000);
    // The scene's field is normalized: 50 µT per unit. One LSB is 0.3 µT = 0.006 units; the
    // scene's magnetometer noise is 0.002 units/√Hz at 1 kHz, σ = 0.002·√1000 = 0.063 units
    // per axis (each device draws its own).
    let (lsb, sigma) = (0.3 / meta.mag_ut_per_unit, 0.002 * 1000f64.sqrt());
    let n = truth.len() as f64;
    let mut sum = [0.0; 3];
    let mut squares = [0.0; 3];
    for (k, (t, field, _)) in truth.iter().enumerate() {
        assert_eq!(sent.t_ns[k], *t);
        for i in 0..3 {
            let e = sent.mag[k][i] - field[i];
            assert!(e.abs() < 5.0 * sigma + lsb, "sample {k} axis {i}: {e}");
            sum[i] += e;
            squares[i] += e * e;
        }
    }
    for i in 0..3 {
        // No bias beyond half an LSB and the noise's mean (4 standard errors) …
        let mean = sum[i] / n;
        assert!(
            mean.abs() < lsb / 2.0 + 4.0 * sigma / n.sqrt(),
            "axis {i}: mean {mean}"
        );
        // … and a spread of the noise's (an unflipped compass would be off by 2·|m| on y, z).
        let rms = (squares[i] / n).sqrt();
        assert!(
            (rms / sigma - 1.0).abs() < 0.15,
            "axis {i}: RMS {rms} vs σ {sigma}"
        );
        println!("axis {i}: mean error {mean:.5}, RMS {rms:.5} (σ {sigma:.5}, LSB {lsb:.5})");
    }
    // The specific force is the IMU's (at ±16 g, 2048 LSB/g; its noise 0.02·√1000 m/s²).
    let tolerance = 5.0 * 0.02 * 1000f64.sqrt() + 9.81 / 2048.0;
    for ((_, _, f), acc) in truth.iter().zip(&sent.acc) {
        for (got, want) in acc.iter().zip(f) {
            assert!((got - want).abs() < tolerance, "{acc:?} vs {f:?}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_compass_without_a_name_is_refused_at_meta_toml() {
    let dir = rig_session("unnamed");
    let path = dir.join("meta.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let unnamed = text.replace("name = \"compass\"\n", "");
    assert_ne!(unnamed, text);
    std::fs::write(&path, unnamed).unwrap();
    let e = read_meta(&dir).unwrap_err().to_string();
    assert_eq!(
        e,
        format!(
            "{}: [[other_devices]] 1 has no name: its images' column in sent.csv is `image.NAME`",
            path.display()
        )
    );
    let _ = std::fs::remove_dir_all(&dir);
}
