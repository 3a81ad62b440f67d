//! Sensor faults in the source-(a) image prediction: inside a window the served bytes are
//! what the fault defines, outside it they are the fault-free run's, byte for byte.

#![allow(clippy::single_range_in_vec_init)] // lists of changed byte ranges, some of one

use margemu_hil::stream::{predict_images, ImageSettings};
use margemu_sim::scene::Scene;
use std::path::Path;

/// An MPU-9250 (bytes 0..22), an ICM-42688-P (22..54) and an IST8310 (54..60), moving, with
/// noise.
const RIG: &str = "duration = 0.2\nrate = 1000.0\nseed = 3\nmotion = \"kinematic\"\n\
    [joints.roll]\ntype = \"sine\"\namplitude = 0.3\nfrequency = 2.0\n\
    [sensors.gyro]\nnoise_density = [0.01, 0.01, 0.01]\n\
    [sensors.accel]\nnoise_density = [0.01, 0.01, 0.01]\n\
    [sensors.mag]\nnoise_density = [0.001, 0.001, 0.001]\n\
    [[device]]\nname = \"mpu\"\nmodel = \"mpu9250\"\n\
    [[device]]\nname = \"icm\"\nmodel = \"icm42688p\"\nchip_select = 1\n\
    [[device]]\nname = \"compass\"\nmodel = \"ist8310\"\nbus = \"i2c\"\n";

const MPU: usize = 0;
const ICM: usize = 22;
const IST: usize = 54;

/// The window [0.05 s, 0.1 s): samples 50..100.
const INSIDE: std::ops::Range<usize> = 50..100;

fn images(text: &str) -> (Scene, Vec<Vec<u8>>) {
    let scene = Scene::parse_str(text, Path::new("faults.toml")).unwrap();
    let got = predict_images(&scene, &ImageSettings::for_scene(&scene))
        .map(|s| s.unwrap().image.as_bytes().to_vec())
        .collect();
    (scene, got)
}

fn with_fault(table: &str) -> Vec<Vec<u8>> {
    images(&format!(
        "{RIG}[[fault]]\n{table}\nstart = 0.05\nduration = 0.05\n"
    ))
    .1
}

/// Every byte outside the window equal to the clean run's; inside it, the bytes outside
/// `changed` equal too, and `check(k, faulted, clean)` holds.
fn assert_window(
    got: &[Vec<u8>],
    clean: &[Vec<u8>],
    changed: &[std::ops::Range<usize>],
    check: impl Fn(usize, &[u8], &[u8]),
) {
    assert_eq!(got.len(), clean.len());
    for k in 0..clean.len() {
        if !INSIDE.contains(&k) {
            assert_eq!(got[k], clean[k], "sample {k}");
            continue;
        }
        for (i, (a, b)) in got[k].iter().zip(&clean[k]).enumerate() {
            if !changed.iter().any(|r| r.contains(&i)) {
                assert_eq!(a, b, "sample {k} byte {i}");
            }
        }
        check(k, &got[k], &clean[k]);
    }
}

#[test]
fn dropout_writes_each_chips_invalid_value() {
    let (_, clean) = images(RIG);
    // ICM-42688-P accel: −32768 in ACCEL_DATA, −524288 in the 20-bit FIFO fields.
    let got = with_fault("device = \"icm\"\nkind = \"dropout\"\nsensor = \"accel\"");
    let (regs, fifo) = (ICM + 2..ICM + 8, ICM + 14..ICM + 23);
    assert_window(&got, &clean, &[regs.clone(), fifo.clone()], |_, g, _| {
        assert_eq!(&g[regs.clone()], [0x80, 0x00].repeat(3));
        assert_eq!(&g[fifo.clone()], [0xF8, 0x00, 0x00].repeat(3));
    });
    // MPU-9250 gyro: −32768 in GYRO_*OUT, big-endian.
    let got = with_fault("device = \"mpu\"\nkind = \"dropout\"\nsensor = \"gyro\"");
    assert_window(&got, &clean, &[MPU + 8..MPU + 14], |_, g, _| {
        assert_eq!(&g[MPU + 8..MPU + 14], [0x80, 0x00].repeat(3));
    });
    // MPU-9250 magnetometer: the AK8963's ST2.HOFL, the data as measured.
    let got = with_fault("device = \"mpu\"\nkind = \"dropout\"\nsensor = \"mag\"");
    assert_window(&got, &clean, &[MPU + 21..MPU + 22], |_, g, c| {
        assert_eq!(g[MPU + 21], c[MPU + 21] | 0x08);
    });
    // IST8310: −32768, LSB first.
    let got = with_fault("device = \"compass\"\nkind = \"dropout\"\nsensor = \"mag\"");
    assert_window(&got, &clean, &[IST..IST + 6], |_, g, _| {
        assert_eq!(&g[IST..IST + 6], [0x00, 0x80].repeat(3));
    });
}

#[test]
fn stuck_serves_the_image_of_the_held_value() {
    let (_, clean) = images(RIG);
    let got = with_fault("device = \"icm\"\nkind = \"stuck\"\nsensor = \"gyro\"");
    let held = &clean[INSIDE.start - 1];
    let (regs, fifo) = (ICM + 8..ICM + 14, ICM + 23..ICM + 32);
    assert_window(&got, &clean, &[regs.clone(), fifo.clone()], |k, g, c| {
        assert_eq!(&g[regs.clone()], &held[regs.clone()], "sample {k}");
        assert_eq!(&g[fifo.clone()], &held[fifo.clone()], "sample {k}");
        assert_ne!(&c[regs.clone()], &held[regs.clone()], "sample {k}: moving");
    });
}

#[test]
fn bias_serves_the_image_of_the_changed_value() {
    let (scene, clean) = images(RIG);
    let got = with_fault(
        "device = \"mpu\"\nkind = \"bias_step\"\nsensor = \"gyro\"\nbias = [0.5, 0.0, -0.25]",
    );
    let settings = scene.devices()[0].chip.settings;
    assert_window(&got, &clean, &[MPU + 8..MPU + 14], |k, g, c| {
        let (g, c) = (
            settings.decode(&g[..ICM]).unwrap().gyr,
            settings.decode(&c[..ICM]).unwrap().gyr,
        );
        // ±250 °/s: one LSB is 1.3e-4 rad/s.
        let lsb = 250.0f64.to_radians() / 32768.0;
        for (i, bias) in [0.5, 0.0, -0.25].into_iter().enumerate() {
            assert!(
                (g[i] - c[i] - bias).abs() <= lsb,
                "sample {k} axis {i}: {} vs {}",
                g[i],
                c[i]
            );
        }
    });
}

#[test]
fn a_scene_without_faults_serves_the_same_bytes() {
    let (_, clean) = images(RIG);
    assert_eq!(with_fault("kind = \"reset\"").len(), clean.len());
    assert_eq!(with_fault("kind = \"reset\""), clean);
    assert_eq!(images(RIG).1, clean);
}
