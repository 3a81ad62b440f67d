//! `[vibration]`: every form of source resolves into the expected per-device vibration, in each
//! device's chip axes, and every bad input is refused at its file, line and column.

use margemu_model::vibration::{RpmPoint, Shock};
use margemu_sim::scene::vibration::{DeviceVibration, SamplingPath};
use margemu_sim::scene::Scene;
use std::path::{Path, PathBuf};

const BASE: &str = "duration = 1.0\nrate = 1000.0\nseed = 1\nmotion = \"static\"\n";

/// A plate tone of 4 motors with one harmonic, its rpm key given by `rpm`.
fn tone(rpm: &str) -> String {
    format!(
        "{BASE}[[vibration.tones]]\nmotors = 4\n{rpm}\n[[vibration.tones.harmonics]]\n\
         order = 1.0\nlinear = [0.0, 0.0, 3.0]\n"
    )
}

fn parse(text: &str) -> Scene {
    Scene::parse_str(text, Path::new("scenes/v.toml")).unwrap_or_else(|e| panic!("{e}"))
}

fn error(text: &str) -> String {
    Scene::parse_str(text, Path::new("scenes/v.toml"))
        .unwrap_err()
        .to_string()
}

fn assert_error(text: &str, place: &str, reason: &str) {
    let e = error(text);
    assert!(
        e.starts_with(&format!("scenes/v.toml:{place}: ")),
        "wrong place in: {e}"
    );
    assert!(e.contains(reason), "reason {reason:?} missing in: {e}");
}

fn profile(scene: &Scene) -> Vec<(u64, f64)> {
    let tones = &scene.vibration[0].tones;
    tones[0].profile.iter().map(|p| (p.t_ns, p.rpm)).collect()
}

/// A fresh folder for scene and CSV files.
fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("margemu-vib-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A scene file with an `rpm_csv = "rpm.csv"` tone and `csv` as that file, loaded.
fn load_with_csv(tag: &str, csv: &str) -> (Result<Scene, String>, PathBuf) {
    let dir = temp_dir(tag);
    std::fs::write(dir.join("rpm.csv"), csv).unwrap();
    let scene_path = dir.join("v.toml");
    std::fs::write(&scene_path, tone("rpm_csv = \"rpm.csv\"")).unwrap();
    let scene = Scene::load(&scene_path).map_err(|e| e.to_string());
    (scene, dir)
}

#[test]
fn a_scene_without_vibration_has_an_empty_entry_per_device() {
    let scene = parse(BASE);
    assert_eq!(scene.vibration, vec![DeviceVibration::default()]);
    assert_eq!(scene.sampling, SamplingPath::Auto);
    let rig = margemu_sim::scene::builtin::load("rig").unwrap();
    assert_eq!(rig.vibration.len(), 2);
    assert!(rig.vibration.iter().all(DeviceVibration::is_empty));
}

#[test]
fn path_selects_the_sampling_path() {
    for (name, path) in [
        ("auto", SamplingPath::Auto),
        ("internal", SamplingPath::Internal),
        ("output", SamplingPath::Output),
    ] {
        let scene = parse(&format!("{BASE}[vibration]\npath = \"{name}\"\n"));
        assert_eq!(scene.sampling, path, "{name}");
    }
    assert_error(
        &format!("{BASE}[vibration]\npath = \"fast\"\n"),
        "6:8",
        "unknown variant `fast`",
    );
}

#[test]
fn a_constant_rpm_is_one_point_at_the_start() {
    let scene = parse(&format!(
        "{BASE}[[vibration.tones]]\nmotors = 3\nspread = 0.02\nrpm = 12000\n\
         [[vibration.tones.harmonics]]\norder = 1.0\nlinear = [0.0, 0.0, 3.0]\n\
         angular = [0.0, 0.0, 0.5]\n[[vibration.tones.harmonics]]\norder = 2.0\n"
    ));
    let tone = &scene.vibration[0].tones[0];
    assert_eq!(tone.motors, 3);
    assert_eq!(tone.spread, 0.02);
    assert_eq!(
        tone.profile,
        [RpmPoint {
            t_ns: 0,
            rpm: 12000.0
        }]
    );
    let h = tone.harmonics();
    assert_eq!(h.len(), 2);
    assert_eq!(
        (h[0].order, h[0].linear, h[0].angular),
        (1.0, [0.0, 0.0, 3.0], [0.0, 0.0, 0.5])
    );
    assert_eq!(
        (h[1].order, h[1].linear, h[1].angular),
        (2.0, [0.0; 3], [0.0; 3])
    );
}

#[test]
fn a_ramp_is_two_points() {
    let scene = parse(&tone(
        "rpm_ramp = { from = 6000, to = 18000, start = 1.0, end = 9.0 }",
    ));
    assert_eq!(
        profile(&scene),
        [(1_000_000_000, 6000.0), (9_000_000_000, 18000.0)]
    );
}

#[test]
fn steps_hold_each_value_until_the_next_time() {
    let scene = parse(&tone(
        "rpm_steps = [[0.0, 6000], [2.0, 9000], [4.0000000004, 12000]]",
    ));
    assert_eq!(
        profile(&scene),
        [
            (0, 6000.0),
            (2_000_000_000, 6000.0),
            (2_000_000_000, 9000.0),
            (4_000_000_000, 9000.0),
            (4_000_000_000, 12000.0),
        ]
    );
}

#[test]
fn a_csv_profile_is_its_rows_relative_to_the_scene_file() {
    let (scene, dir) = load_with_csv("rows", "t_s,rpm\n0.0,6000\n0.5,9000\n1.25,12000\n");
    let scene = scene.unwrap();
    assert_eq!(
        profile(&scene),
        [(0, 6000.0), (500_000_000, 9000.0), (1_250_000_000, 12000.0)]
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn random_and_shock_sources_take_their_values() {
    let scene = parse(&format!(
        "{BASE}[[vibration.random]]\npsd = [[20.0, 0.01], [80.0, 0.04], [2000.0, 0.007]]\n\
         gains = [1.0, 1.0, 0.5]\n[[vibration.shocks]]\nat = 0.5\nduration = 0.011\n\
         linear = [0.0, 0.0, 490.0]\nangular = [0.1, 0.0, 0.0]\n"
    ));
    let v = &scene.vibration[0];
    let random = v.random.unwrap();
    let psd: Vec<_> = random
        .points()
        .iter()
        .map(|p| (p.f_hz, p.g2_per_hz))
        .collect();
    assert_eq!(psd, [(20.0, 0.01), (80.0, 0.04), (2000.0, 0.007)]);
    assert_eq!(random.gains, [1.0, 1.0, 0.5]);
    assert_eq!(random.axes, None);
    let shock = Shock {
        t_ns: 500_000_000,
        duration_ns: 11_000_000,
        linear: [0.0, 0.0, 490.0],
        angular: [0.1, 0.0, 0.0],
    };
    assert_eq!(v.shocks, [shock]);
    assert_eq!(v.max_frequency_hz(), 2000.0);
    let gains = parse(&format!(
        "{BASE}[[vibration.random]]\npsd = [[20.0, 0.01], [80.0, 0.04]]\n"
    ));
    assert_eq!(gains.vibration[0].random.unwrap().gains, [1.0; 3]);
}

/// An IMU with the plate's axes and a compass turned 90° about z, at 1 kHz.
const RIG: &str = "duration = 1.0\nrate = 1000.0\nseed = 1\nmotion = \"static\"\n\
    [[device]]\nname = \"imu\"\nmodel = \"icm42688p\"\n\
    [[device]]\nname = \"compass\"\nmodel = \"ist8310\"\n\
    rotation = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]\n";

#[test]
fn plate_sources_reach_every_device_in_its_chip_axes() {
    let scene = parse(&format!(
        "{RIG}[[vibration.tones]]\nmotors = 2\nrpm = 6000\n[[vibration.tones.harmonics]]\n\
         order = 2.0\nlinear = [1.0, 2.0, 3.0]\nangular = [0.5, 0.0, 0.0]\n\
         [[vibration.random]]\npsd = [[20.0, 0.01], [80.0, 0.04]]\ngains = [1.0, 0.5, 0.25]\n\
         [[vibration.shocks]]\nat = 0.25\nduration = 0.01\nlinear = [0.0, 10.0, 0.0]\n"
    ));
    let [imu, compass] = &scene.vibration[..] else {
        panic!("two devices")
    };
    let h = |v: &DeviceVibration| v.tones[0].harmonics()[0];
    assert_eq!(
        (h(imu).linear, h(imu).angular),
        ([1.0, 2.0, 3.0], [0.5, 0.0, 0.0])
    );
    assert_eq!(
        (h(compass).linear, h(compass).angular),
        ([2.0, -1.0, 3.0], [0.0, -0.5, 0.0])
    );
    assert_eq!(h(compass).order, 2.0);
    assert_eq!(compass.tones[0].profile, imu.tones[0].profile);
    // The random source keeps plate-axis gains and carries the rotation.
    let (ri, rc) = (imu.random.unwrap(), compass.random.unwrap());
    assert_eq!((ri.gains, rc.gains), ([1.0, 0.5, 0.25], [1.0, 0.5, 0.25]));
    assert_eq!(ri.axes, None);
    assert_eq!(
        rc.axes,
        Some([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    );
    assert_eq!(imu.shocks[0].linear, [0.0, 10.0, 0.0]);
    assert_eq!(compass.shocks[0].linear, [10.0, 0.0, 0.0]);
}

#[test]
fn a_device_key_routes_a_source_to_that_device_only() {
    let scene = parse(&format!(
        "{RIG}[[vibration.shocks]]\ndevice = \"compass\"\nat = 0.25\nduration = 0.01\n\
         linear = [1.0, 0.0, 0.0]\n[[vibration.random]]\ndevice = \"imu\"\n\
         psd = [[20.0, 0.01], [80.0, 0.04]]\n[[vibration.random]]\ndevice = \"compass\"\n\
         psd = [[30.0, 0.02], [90.0, 0.02]]\n"
    ));
    let [imu, compass] = &scene.vibration[..] else {
        panic!("two devices")
    };
    assert!(imu.shocks.is_empty());
    assert_eq!(compass.shocks[0].linear, [0.0, -1.0, 0.0]);
    assert_eq!(imu.random.unwrap().points()[0].f_hz, 20.0);
    assert_eq!(compass.random.unwrap().points()[0].f_hz, 30.0);
    // `[chip]`'s name names device 0.
    let named = parse(&format!(
        "{BASE}[chip]\nname = \"fc\"\n[[vibration.shocks]]\ndevice = \"fc\"\nat = 0.1\n\
         duration = 0.01\n"
    ));
    assert_eq!(named.vibration[0].shocks.len(), 1);
}

#[test]
fn unknown_keys_are_refused() {
    assert_error(
        &format!("{BASE}[vibration]\npat = \"auto\"\n"),
        "6:1",
        "unknown field `pat`",
    );
    assert_error(
        &tone("rpm = 1\nmoters = 4"),
        "8:1",
        "unknown field `moters`",
    );
    assert_error(
        &tone("rpm_ramp = { from = 1, to = 2, start = 0, stop = 1 }"),
        "7:43",
        "unknown field `stop`",
    );
    assert_error(
        &format!("{BASE}[[vibration.shocks]]\nat = 0.1\nduration = 0.01\npeak = 1.0\n"),
        "8:1",
        "unknown field `peak`",
    );
}

#[test]
fn unknown_device_names_list_the_devices() {
    assert_error(
        &format!("{RIG}[[vibration.shocks]]\ndevice = \"gps\"\nat = 0.1\nduration = 0.01\n"),
        "13:10",
        "`vibration.shocks[0].device`: no device is named `gps`; the devices are imu, compass",
    );
}

#[test]
fn at_most_one_random_source_reaches_a_device() {
    let psd = "psd = [[20.0, 0.01], [80.0, 0.04]]";
    assert_error(
        &format!(
            "{RIG}[[vibration.random]]\ndevice = \"compass\"\n{psd}\n[[vibration.random]]\n{psd}\n"
        ),
        "15:1",
        "`vibration.random[1]`: device `compass` has a random source already \
         (`vibration.random[0]`): at most one reaches a device",
    );
}

#[test]
fn limits_are_named() {
    let five = tone("rpm = 6000").replace(BASE, "").repeat(5);
    assert_error(
        &format!("{BASE}{five}"),
        "29:1",
        "`vibration.tones[4]`: device `mpu9250` would take more than 4 tone sources",
    );
    let harmonics = "[[vibration.tones.harmonics]]\norder = 1.0\n".repeat(7);
    assert_error(
        &format!("{BASE}[[vibration.tones]]\nmotors = 1\nrpm = 1\n{harmonics}"),
        "20:1",
        "`vibration.tones[0].harmonics[6]`: a tone source has at most 6 harmonics",
    );
    let shocks = "[[vibration.shocks]]\nat = 0.1\nduration = 0.01\n".repeat(9);
    assert_error(
        &format!("{BASE}{shocks}"),
        "29:1",
        "`vibration.shocks[8]`: device `mpu9250` would take more than 8 shocks",
    );
    for motors in [0, 9] {
        assert_error(
            &tone("rpm = 1").replace("motors = 4", &format!("motors = {motors}")),
            "6:10",
            &format!("`vibration.tones[0].motors`: must be 1 to 8 (the most one tone source drives), not {motors}"),
        );
    }
    let many: Vec<String> = (1..=17).map(|f| format!("[{}.0, 0.01]", 10 * f)).collect();
    assert_error(
        &format!("{BASE}[[vibration.random]]\npsd = [{}]\n", many.join(", ")),
        "6:7",
        "`vibration.random[0].psd`: a PSD has 2 to 16 `[Hz, g²/Hz]` breakpoints, not 17",
    );
}

#[test]
fn the_rpm_is_given_exactly_once() {
    assert_error(
        &tone("rpm = 1\nrpm_steps = [[0.0, 1]]"),
        "8:13",
        "`vibration.tones[0].rpm_steps`: `rpm` gives the rpm already: give one of `rpm`, \
         `rpm_ramp`, `rpm_steps`, `rpm_csv`",
    );
    assert_error(
        &tone(""),
        "5:1",
        "`vibration.tones[0]`: a tone source needs its rpm: one of `rpm`, `rpm_ramp`",
    );
}

#[test]
fn rpms_and_times_are_checked() {
    assert_error(
        &tone("rpm = -5"),
        "7:7",
        "`vibration.tones[0].rpm`: must be finite and ≥ 0, not -5",
    );
    assert_error(
        &tone("rpm = nan"),
        "7:7",
        "`vibration.tones[0].rpm`: must be finite and ≥ 0, not NaN",
    );
    assert_error(
        &tone("rpm = 2e6"),
        "7:7",
        "2e6 is outside the plausible range [0, 1e6] rpm",
    );
    assert_error(
        &tone("rpm_ramp = { from = 6000, to = -1, start = 1.0, end = 2.0 }"),
        "7:32",
        "`vibration.tones[0].rpm_ramp.to`: must be finite and ≥ 0, not -1",
    );
    assert_error(
        &tone("rpm_ramp = { from = 6000, to = 9000, start = 2.0, end = 1.0 }"),
        "7:57",
        "`vibration.tones[0].rpm_ramp.end`: the ramp must end after it starts (2 s), not at 1 s",
    );
    assert_error(
        &tone("rpm_steps = [[0.0, 6000], [2.0, 9000], [1.5, 12000]]"),
        "7:41",
        "`vibration.tones[0].rpm_steps[2][0]`: steps go in time order: 1.5 s does not come \
         after the previous step's 2 s",
    );
    assert_error(
        &tone("rpm_steps = [[-1.0, 6000]]"),
        "7:15",
        "`vibration.tones[0].rpm_steps[0][0]`: must be finite and ≥ 0, not -1",
    );
    assert_error(
        &tone("rpm_steps = [[0.0, inf]]"),
        "7:20",
        "`vibration.tones[0].rpm_steps[0][1]`: must be finite and ≥ 0, not inf",
    );
    assert_error(
        &tone("rpm_steps = []"),
        "7:13",
        "`vibration.tones[0].rpm_steps`: needs at least one `[time s, rpm]` step",
    );
    assert_error(
        &tone("rpm = 1\nspread = 1.0"),
        "8:10",
        "`vibration.tones[0].spread`: must be finite, ≥ 0 and < 1, not 1",
    );
}

#[test]
fn harmonics_are_checked() {
    assert_error(
        &format!("{BASE}[[vibration.tones]]\nmotors = 1\nrpm = 1\n"),
        "5:1",
        "`vibration.tones[0]`: a tone source needs at least one `[[vibration.tones.harmonics]]`",
    );
    assert_error(
        &tone("rpm = 1").replace("order = 1.0", "order = 0.0"),
        "9:9",
        "`vibration.tones[0].harmonics[0].order`: must be finite and > 0, not 0",
    );
    assert_error(
        &tone("rpm = 1").replace("[0.0, 0.0, 3.0]", "[0.0, inf, 3.0]"),
        "10:16",
        "`vibration.tones[0].harmonics[0].linear[1]`: must be finite, not inf",
    );
}

#[test]
fn psds_are_checked() {
    let random = |psd: &str| format!("{BASE}[[vibration.random]]\npsd = {psd}\n");
    assert_error(
        &random("[[20.0, 0.01], [20.0, 0.02]]"),
        "6:23",
        "`vibration.random[0].psd[1][0]`: breakpoint frequencies must increase: 20 Hz does not \
         come after 20 Hz",
    );
    assert_error(
        &random("[[20.0, 0.01], [80.0, 0.0]]"),
        "6:29",
        "`vibration.random[0].psd[1][1]`: must be finite and > 0, not 0",
    );
    assert_error(
        &random("[[20.0, -0.01], [80.0, 0.01]]"),
        "6:15",
        "`vibration.random[0].psd[0][1]`: must be finite and > 0, not -0.01",
    );
    assert_error(
        &random("[[20.0, 0.01]]"),
        "6:7",
        "`vibration.random[0].psd`: a PSD has 2 to 16 `[Hz, g²/Hz]` breakpoints, not 1",
    );
    assert_error(
        &random("[[nan, 0.01], [80.0, 0.01]]"),
        "6:9",
        "`vibration.random[0].psd[0][0]`: must be finite and > 0, not NaN",
    );
    assert_error(
        &random("[[1.0, 0.01], [80.0, 0.01]]"),
        "6:9",
        "`vibration.random[0].psd[0][0]`: the lowest breakpoint, 1 Hz, is too low for the \
         synthesis at 32000 Hz: it must be at least 7.8125 Hz (the rate / 4096)",
    );
    assert_error(
        &format!("{BASE}[[vibration.random]]\npsd = [[20.0, 0.01], [80.0, 0.01]]\ngains = [1.0, -1.0, 1.0]\n"),
        "7:15",
        "`vibration.random[0].gains[1]`: must be finite and ≥ 0, not -1",
    );
}

#[test]
fn shocks_are_checked() {
    let shock = |body: &str| format!("{BASE}[[vibration.shocks]]\n{body}\n");
    assert_error(
        &shock("at = 0.1\nduration = 0.0"),
        "7:12",
        "`vibration.shocks[0].duration`: must be finite and > 0, not 0",
    );
    assert_error(
        &shock("at = 0.1\nduration = 1e-12"),
        "7:12",
        "`vibration.shocks[0].duration`: must be at least 1 ns, not 0.000000000001 s",
    );
    assert_error(
        &shock("at = nan\nduration = 0.01"),
        "6:6",
        "`vibration.shocks[0].at`: must be finite and ≥ 0, not NaN",
    );
    assert_error(
        &shock("at = 0.1\nduration = 0.01\nangular = [0.0, 0.0, -1e5]"),
        "8:22",
        "`vibration.shocks[0].angular[2]`: -1e5 is outside the plausible range [-1e4, 1e4] rad/s",
    );
}

#[test]
fn csv_problems_name_the_csv_line() {
    for (tag, csv, reason) in [
        (
            "word",
            "t_s,rpm\n0,6000\n0.5,fast\n",
            ":3: `rpm` = \"fast\" is not a number",
        ),
        (
            "back",
            "t_s,rpm\n0,6000\n0.5,7000\n0.25,8000\n",
            ":4: t_s = 0.25 does not increase",
        ),
        (
            "neg",
            "t_s,rpm\n0,-6000\n",
            ":2: `rpm` = -6000 is outside the plausible range [0, 1e6] rpm",
        ),
        (
            "negt",
            "t_s,rpm\n-1,6000\n",
            ":2: `t_s` = -1 is outside the plausible range [0, 1e7] s",
        ),
        (
            "col",
            "t,rpm\n0,6000\n",
            ": no column `t_s` in the header (columns: t, rpm)",
        ),
        (
            "empty",
            "t_s,rpm\n",
            ": needs at least 1 data rows, found 0",
        ),
    ] {
        let (scene, dir) = load_with_csv(tag, csv);
        let e = scene.unwrap_err();
        let scene_at = format!(
            "{}:7:11: `vibration.tones[0].rpm_csv`: ",
            dir.join("v.toml").display()
        );
        let csv_at = format!("{}{reason}", dir.join("rpm.csv").display());
        assert!(e.starts_with(&scene_at), "{tag}: {e}");
        assert!(e.ends_with(&csv_at), "{tag}: {e}");
        std::fs::remove_dir_all(dir).unwrap();
    }
    let dir = temp_dir("missing");
    let scene_path = dir.join("v.toml");
    std::fs::write(&scene_path, tone("rpm_csv = \"none.csv\"")).unwrap();
    let e = Scene::load(&scene_path).unwrap_err().to_string();
    let at = format!(
        "v.toml:7:11: `vibration.tones[0].rpm_csv`: {}: cannot read:",
        dir.join("none.csv").display()
    );
    assert!(e.contains(&at), "{e}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn late_shocks_and_aliasing_on_the_output_path_are_warned_about() {
    let text = format!(
        "{BASE}[vibration]\npath = \"output\"\n[[vibration.shocks]]\nat = 1.0\nduration = 0.001\n"
    );
    let scene = parse(&text);
    let warnings: Vec<String> = scene.warnings.iter().map(ToString::to_string).collect();
    assert_eq!(
        warnings,
        [
            "scenes/v.toml:8:6: `vibration.shocks[0].at`: the shock starts at 1 s, not before \
             the run ends (1 s): it never happens",
            "scenes/v.toml:6:8: `vibration.path`: vibration reaches above the output Nyquist \
             frequency 500 Hz (`mpu9250` up to 1500 Hz): on the output path the samples alias it",
        ]
    );
    // The same content on the automatic path, starting within the run: nothing to warn about.
    let fine = parse(
        &text
            .replace("output", "auto")
            .replace("at = 1.0", "at = 0.5"),
    );
    assert!(fine.warnings.is_empty(), "{:?}", fine.warnings);
}
