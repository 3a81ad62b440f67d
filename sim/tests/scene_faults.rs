//! `[[fault]]`: schedules resolve to the shared fault definition; bad ones get a located error.

use margemu_model::fault::{Fault, FaultKind, Sensor, Window, MAX_FAULTS, UNTIL_END};
use margemu_sim::scene::Scene;
use std::path::Path;

/// A rig: `imu` (ICM-42688-P on SPI, no magnetometer), `compass` (IST8310 on I2C).
const RIG: &str = "duration = 4.0\nrate = 1000.0\nseed = 1\nmotion = \"static\"\n\
    [[device]]\nname = \"imu\"\nmodel = \"icm42688p\"\n\
    [[device]]\nname = \"compass\"\nmodel = \"ist8310\"\nbus = \"i2c\"\n";

fn parse(text: &str) -> Result<Scene, String> {
    Scene::parse_str(text, Path::new("bad.toml")).map_err(|e| e.to_string())
}

fn faults(tables: &str) -> Vec<Fault> {
    parse(&format!("{RIG}{tables}")).unwrap().faults
}

/// The error of `RIG` + `tables`, which must be at `line:col` (counted in the whole text) and
/// contain `reason`.
fn assert_error(tables: &str, place: &str, reason: &str) {
    let e = parse(&format!("{RIG}{tables}")).unwrap_err();
    assert!(
        e.starts_with(&format!("bad.toml:{place}: ")),
        "wrong place in: {e}"
    );
    assert!(e.contains(reason), "reason {reason:?} missing in: {e}");
}

/// RIG has 11 lines; the first fault table starts on line 12.
const F: &str = "[[fault]]\n";

#[test]
fn a_schedule_resolves_in_file_order() {
    let got = faults(&format!(
        "{F}device = \"imu\"\nkind = \"stuck\"\nsensor = \"gyro\"\nstart = 1.0\nduration = 0.5\n\
         {F}device = 1\nkind = \"mag_saturation\"\nfield = [5.0, 0.0, 0.0]\nstart = 2.0\nuntil_end = true\n\
         {F}kind = \"spikes\"\nsensor = \"accel\"\nrate = 20.0\namplitude = 3.0\naxes = \"xz\"\nstart = 0.0\nduration = 4.0\n\
         {F}kind = \"bias_step\"\nsensor = \"gyro\"\nbias = 0.1\nstart = 0.5\nduration = 1.0\n\
         {F}kind = \"clock_stretch\"\ndevice = \"compass\"\nstretch = 250.0\nstart = 0.5\nduration = 1.0\n\
         {F}kind = \"wrong_identity\"\nidentity = 0x00\nstart = 3.0\nduration = 0.25\n"
    ));
    assert_eq!(
        got,
        [
            Fault::new(
                0,
                Window::new(1_000_000_000, 1_500_000_000),
                FaultKind::Stuck {
                    sensor: Sensor::Gyr
                }
            ),
            Fault::new(
                1,
                Window::new(2_000_000_000, UNTIL_END),
                FaultKind::MagSaturation {
                    field: [5.0, 0.0, 0.0]
                }
            ),
            Fault::new(
                0,
                Window::new(0, 4_000_000_000),
                FaultKind::Spikes {
                    sensor: Sensor::Acc,
                    rate_hz: 20.0,
                    amplitude: 3.0,
                    axes: 0b101
                }
            ),
            Fault::new(
                0,
                Window::new(500_000_000, 1_500_000_000),
                FaultKind::BiasStep {
                    sensor: Sensor::Gyr,
                    bias: [0.1; 3]
                }
            ),
            Fault::new(
                1,
                Window::new(500_000_000, 1_500_000_000),
                FaultKind::ClockStretch {
                    stretch_ns: 250_000
                }
            ),
            Fault::new(
                0,
                Window::new(3_000_000_000, 3_250_000_000),
                FaultKind::WrongIdentity { value: 0 }
            ),
        ]
    );
}

#[test]
fn every_kind_parses_with_its_parameters() {
    let kinds = [
        "kind = \"stuck_at\"\nsensor = \"accel\"\nvalue = [0.0, 0.0, 9.8]",
        "kind = \"dropout\"\nsensor = \"accel\"",
        "kind = \"scale\"\nsensor = \"gyro\"\nfactor = [1.1, 1.0, 0.9]",
        "kind = \"noise\"\nsensor = \"gyro\"\nstd = 0.05",
        "kind = \"reset\"",
        "kind = \"fifo_overflow\"",
        "kind = \"nak\"",
        "kind = \"corrupt\"\nprobability = 0.01",
        "kind = \"clock_offset\"\nppm = 150.0\ndrift = -2.0",
        "kind = \"drdy_jitter\"\nmax_jitter = 40.0",
        "kind = \"missing_drdy\"\nprobability = 0.5",
        "kind = \"late\"\ndelay = 300.0",
    ];
    for k in kinds {
        let got = faults(&format!("{F}{k}\nstart = 1.0\nduration = 1.0\n"));
        assert_eq!(got.len(), 1, "{k}");
        assert!(k.contains(got[0].kind.name()), "{k}");
    }
}

#[test]
fn the_same_scene_gives_the_same_schedule() {
    let text = format!(
        "{RIG}{F}kind = \"noise\"\nsensor = \"gyro\"\nstd = 0.05\nstart = 1.0\nduration = 1.0\n"
    );
    assert_eq!(parse(&text).unwrap().faults, parse(&text).unwrap().faults);
}

#[test]
fn unknown_device_kind_and_sensor() {
    assert_error(
        &format!("{F}device = \"gps\"\nkind = \"nak\"\nstart = 1.0\nduration = 1.0\n"),
        "13:10",
        "no device `gps`; the devices are imu, compass",
    );
    assert_error(
        &format!("{F}device = 2\nkind = \"nak\"\nstart = 1.0\nduration = 1.0\n"),
        "13:10",
        "no device 2: the rig has devices 0 to 1",
    );
    assert_error(
        &format!("{F}kind = \"stall\"\nstart = 1.0\nduration = 1.0\n"),
        "13:8",
        "unknown fault kind `stall`",
    );
    assert_error(
        &format!("{F}kind = \"stuck\"\nsensor = \"baro\"\nstart = 1.0\nduration = 1.0\n"),
        "14:10",
        "unknown sensor `baro`",
    );
    assert_error(
        &format!("{F}kind = \"nak\"\nstart = 1.0\nduration = 1.0\ncolour = 1\n"),
        "16:1",
        "unknown field `colour`",
    );
}

#[test]
fn missing_and_foreign_parameters() {
    assert_error(
        &format!("{F}kind = \"stuck\"\nstart = 1.0\nduration = 1.0\n"),
        "12:1",
        "a `stuck` fault needs `sensor`",
    );
    assert_error(
        &format!(
            "{F}kind = \"spikes\"\nsensor = \"gyro\"\nrate = 5.0\nstart = 1.0\nduration = 1.0\n"
        ),
        "12:1",
        "needs `amplitude`",
    );
    assert_error(
        &format!(
            "{F}kind = \"stuck\"\nsensor = \"gyro\"\nrate = 5.0\nstart = 1.0\nduration = 1.0\n"
        ),
        "15:8",
        "`fault[0].rate`: does not apply to a `stuck` fault",
    );
    assert_error(
        &format!("{F}kind = \"reset\"\nsensor = \"gyro\"\nstart = 1.0\nduration = 1.0\n"),
        "14:10",
        "does not apply to a `reset` fault",
    );
}

#[test]
fn sensors_and_features_the_chip_does_not_have() {
    assert_error(
        &format!("{F}kind = \"dropout\"\nsensor = \"mag\"\nstart = 1.0\nduration = 1.0\n"),
        "14:10",
        "device `imu` (ICM-42688-P) has no magnetometer",
    );
    assert_error(&format!("{F}device = \"compass\"\nkind = \"stuck\"\nsensor = \"gyro\"\nstart = 1.0\nduration = 1.0\n"), "15:10", "(IST8310) has no gyroscope");
    assert_error(
        &format!(
            "{F}kind = \"mag_saturation\"\nfield = [1.0, 0.0, 0.0]\nstart = 1.0\nduration = 1.0\n"
        ),
        "13:8",
        "has no magnetometer",
    );
    assert_error(
        &format!(
            "{F}device = \"compass\"\nkind = \"fifo_overflow\"\nstart = 1.0\nduration = 1.0\n"
        ),
        "14:8",
        "(IST8310) has no FIFO",
    );
    assert_error(
        &format!("{F}kind = \"clock_stretch\"\nstretch = 10.0\nstart = 1.0\nduration = 1.0\n"),
        "13:8",
        "device `imu` is on SPI",
    );
    // The rig's devices share one serving clock: only the first may have its latch moved.
    assert_error(
        &format!("{F}device = \"compass\"\nkind = \"late\"\ndelay = 100.0\nstart = 1.0\nduration = 1.0\n"),
        "14:8",
        "only the first device (`imu`) can have it",
    );
    let missing = faults(&format!(
        "{F}device = \"compass\"\nkind = \"missing_drdy\"\nprobability = 0.5\nstart = 1.0\nduration = 1.0\n"
    ));
    assert_eq!(
        missing[0].device, 1,
        "a missing data-ready pulse is any device's"
    );
}

#[test]
fn bad_windows() {
    assert_error(
        &format!("{F}kind = \"nak\"\nstart = 1.0\nduration = -0.5\n"),
        "15:12",
        "must be finite and > 0",
    );
    assert_error(
        &format!("{F}kind = \"nak\"\nstart = 1.0\nduration = 0.0\n"),
        "15:12",
        "must be finite and > 0",
    );
    assert_error(
        &format!("{F}kind = \"nak\"\nstart = 4.0\nduration = 1.0\n"),
        "14:9",
        "before the run's end (4 s)",
    );
    assert_error(
        &format!("{F}kind = \"nak\"\nstart = -1.0\nduration = 1.0\n"),
        "14:9",
        "≥ 0",
    );
    assert_error(
        &format!("{F}kind = \"nak\"\nstart = nan\nduration = 1.0\n"),
        "14:9",
        "must be finite",
    );
    assert_error(
        &format!("{F}kind = \"nak\"\nstart = 1.0\nduration = 1.0\nuntil_end = true\n"),
        "16:13",
        "not both",
    );
    assert_error(
        &format!("{F}kind = \"nak\"\nstart = 1.0\n"),
        "12:1",
        "needs `duration` (s) or `until_end = true`",
    );
}

#[test]
fn bad_numbers() {
    assert_error(
        &format!("{F}kind = \"corrupt\"\nprobability = 1.5\nstart = 1.0\nduration = 1.0\n"),
        "14:15",
        "must be in [0, 1], not 1.5",
    );
    assert_error(
        &format!("{F}kind = \"missing_drdy\"\nprobability = -0.1\nstart = 1.0\nduration = 1.0\n"),
        "14:15",
        "must be in [0, 1]",
    );
    assert_error(&format!("{F}kind = \"bias_step\"\nsensor = \"gyro\"\nbias = [0.0, inf, 0.0]\nstart = 1.0\nduration = 1.0\n"), "15:14", "must be finite");
    assert_error(
        &format!(
            "{F}kind = \"noise\"\nsensor = \"gyro\"\nstd = -1.0\nstart = 1.0\nduration = 1.0\n"
        ),
        "15:7",
        "must be ≥ 0",
    );
    assert_error(&format!("{F}kind = \"spikes\"\nsensor = \"gyro\"\nrate = 5.0\namplitude = 1.0\naxes = \"xx\"\nstart = 1.0\nduration = 1.0\n"), "17:8", "distinct axes");
    assert_error(
        &format!("{F}kind = \"wrong_identity\"\nidentity = 256\nstart = 1.0\nduration = 1.0\n"),
        "14:12",
        "must be 0 to 255",
    );
    assert_error(
        &format!("{F}kind = \"late\"\ndelay = 0.0\nstart = 1.0\nduration = 1.0\n"),
        "14:9",
        "µs",
    );
}

#[test]
fn overlapping_exclusive_faults_name_both() {
    let stuck = "kind = \"stuck\"\nsensor = \"gyro\"\nstart = 1.0\nduration = 1.0\n";
    let dropout = "kind = \"dropout\"\nsensor = \"gyro\"\nstart = 1.5\nduration = 1.0\n";
    assert_error(
        &format!("{F}{stuck}{F}{dropout}"),
        "20:9",
        "fault[1] (dropout gyro on `imu`, 1.5 s to 2.5 s) overlaps fault[0] (stuck gyro on `imu`, 1 s to 2 s)",
    );
    // Other sensor, other device, back to back, additive kinds: all fine.
    let accel = dropout.replace("gyro", "accel");
    assert_eq!(faults(&format!("{F}{stuck}{F}{accel}")).len(), 2);
    let later = dropout.replace("1.5", "2.0");
    assert_eq!(faults(&format!("{F}{stuck}{F}{later}")).len(), 2);
    let bias = "kind = \"bias_step\"\nsensor = \"gyro\"\nbias = 0.1\nstart = 1.0\nduration = 2.0\n";
    assert_eq!(faults(&format!("{F}{bias}{F}{bias}")).len(), 2);
    let nak = "kind = \"nak\"\nstart = 0.0\nuntil_end = true\n";
    assert_error(
        &format!("{F}{nak}{F}kind = \"corrupt\"\nprobability = 0.1\nstart = 3.0\nduration = 0.1\n"),
        "19:9",
        "overlaps fault[0] (nak on `imu`, 0 s to the end)",
    );
}

#[test]
fn at_most_max_faults() {
    let one = "kind = \"bias_step\"\nsensor = \"gyro\"\nbias = 0.1\nstart = 1.0\nduration = 1.0\n";
    let ok: String = (0..MAX_FAULTS).map(|_| format!("{F}{one}")).collect();
    assert_eq!(faults(&ok).len(), MAX_FAULTS);
    let e = parse(&format!("{RIG}{ok}{F}{one}")).unwrap_err();
    assert!(
        e.contains(&format!(
            "`fault[{MAX_FAULTS}]`: a scene has at most {MAX_FAULTS} faults"
        )),
        "{e}"
    );
    let line = 12 + 6 * MAX_FAULTS;
    assert!(e.starts_with(&format!("bad.toml:{line}:1: ")), "{e}");
}

#[test]
fn a_single_chip_scene_takes_device_0_by_default() {
    let text = "duration = 1.0\nrate = 100.0\nseed = 1\nmotion = \"static\"\n\
        [[fault]]\nkind = \"dropout\"\nsensor = \"mag\"\nstart = 0.5\nduration = 0.1\n";
    let scene = parse(text).unwrap();
    assert_eq!(scene.faults[0].device, 0);
    assert_eq!(
        scene.faults[0].kind,
        FaultKind::Dropout {
            sensor: Sensor::Mag
        }
    );
}
