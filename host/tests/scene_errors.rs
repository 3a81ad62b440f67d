//! Bad scenes are refused with the file, line, column and reason.

use margemu::scene::Scene;
use std::path::Path;

const BASE: &str = "duration = 1.0\nrate = 100.0\nseed = 1\n";

fn error(text: &str) -> String {
    Scene::parse_str(text, Path::new("scenes/bad.toml"))
        .unwrap_err()
        .to_string()
}

fn assert_error(text: &str, place: &str, reason: &str) {
    let e = error(text);

    assert!(
        e.starts_with(&format!("scenes/bad.toml:{place}: ")),
        "wrong place in: {e}"
    );
    assert!(e.contains(reason), "reason {reason:?} missing in: {e}");
}

#[test]
fn unknown_key() {
    assert_error(
        &format!("{BASE}duraton = 2.0\n"),
        "4:1",
        "unknown field `duraton`",
    );
    assert_error(
        &format!("{BASE}[bench]\nplate_mas = 1.0\n"),
        "5:1",
        "unknown field `plate_mas`",
    );
    assert_error(
        &format!(
            "{BASE}[joints.x]\ntype = \"sine\"\namplitude = 1.0\nfrequency = 1.0\nphse = 0.0\n"
        ),
        "4:1",
        "unknown field `phse`",
    );
}

#[test]
fn wrong_type() {
    assert_error(
        "duration = 1.0\nrate = \"fast\"\nseed = 1\n",
        "2:8",
        "invalid type: string \"fast\"",
    );
    assert_error(
        &format!("{BASE}[bench]\ninitial = [0, 0, 0]\n"),
        "5:11",
        "invalid length 3",
    );
    assert_error(
        &format!("{BASE}motion = \"flying\"\n"),
        "4:10",
        "unknown variant `flying`",
    );
}

#[test]
fn negative_mass() {
    assert_error(
        &format!("{BASE}[bench]\nplate_mass = -0.2\n"),
        "5:14",
        "`bench.plate_mass`: must be finite and > 0, not -0.2",
    );
    assert_error(
        &format!("{BASE}[bench]\nlink_mass = [500.0, -1.0, 200.0]\n"),
        "5:21",
        "`bench.link_mass[1]`: a mass must be finite and > 0, not -1",
    );
}

#[test]
fn not_a_number() {
    assert_error(
        "duration = 1.0\nrate = nan\nseed = 1\n",
        "2:8",
        "`rate`: must be finite and > 0, not NaN",
    );
    assert_error(
        &format!("{BASE}[field]\nreference = [0.5, inf, 0.0]\n"),
        "5:19",
        "`field.reference[1]`: must be finite, not inf",
    );
    assert_error(
        &format!("{BASE}[joints.roll]\ntype = \"sine\"\namplitude = nan\nfrequency = 1.0\n"),
        "6:13",
        "`joints.roll.amplitude`: must be finite",
    );
}

#[test]
fn zero_rate() {
    assert_error(
        "duration = 1.0\nrate = 0.0\nseed = 1\n",
        "2:8",
        "`rate`: must be finite and > 0, not 0",
    );
}

#[test]
fn duration_not_a_multiple_of_the_step() {
    assert_error(
        "duration = 1.0005\nrate = 100.0\nseed = 1\n",
        "1:12",
        "`duration`: 1.0005 s is not a whole number of integrator steps of 0.001 s",
    );
    assert_error(
        &format!("{BASE}[integrator]\nstep = 0.0\n"),
        "5:8",
        "`integrator.step`: must be finite and > 0",
    );
}

#[test]
fn sources_that_do_not_fit_the_mode_or_joint() {
    assert_error(
        &format!("{BASE}[joints.w]\ntype = \"constant\"\nvalue = 1.0\n"),
        "4:1",
        "unknown joint",
    );
    assert_error(
        &format!("{BASE}motion = \"static\"\n[joints.x]\ntype = \"constant\"\nvalue = 1.0\n"),
        "5:1",
        "a static scene takes no joint sources",
    );
    assert_error(
        &format!(
            "{BASE}motion = \"kinematic\"\n[joints.x]\ntype = \"steps\"\npoints = [[0.5, 1.0]]\n"
        ),
        "6:8",
        "`steps` cannot prescribe motion directly",
    );
    assert_error(
        &format!("{BASE}[joints.x]\ntype = \"steps\"\npoints = [[0.5, 1.0], [0.2, 2.0]]\n"),
        "6:24",
        "times must be finite, ≥ 0 and increasing",
    );
    assert_error(
        &format!("{BASE}[joints.y]\ntype = \"random-setpoints\"\nrange = [1.0, 0.0]\nhold = [1.0, 2.0]\n"),
        "6:9",
        "lo ≤ hi",
    );
}

#[test]
fn a_missing_file_is_named() {
    let e = Scene::load(Path::new("/nonexistent/scene.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("/nonexistent/scene.toml: cannot read:"),
        "{e}"
    );
}

/// `[chip]`: an unknown model, a bus or address the chip lacks, an identity, full scale or
/// output rate it does not have, and a rotation that is not one are refused where they are.
#[test]
fn chip_table_errors_are_located() {
    let chip = |body: &str| format!("{BASE}[chip]\n{body}");
    assert_error(
        &chip("model = \"bmi999\"\n"),
        "5:9",
        "no chip model \"bmi999\"; margemu emulates mpu9250, mpu6500, mpu6000, icm20602, icm42688p, bmi270, ist8310, qmc5883l, rm3100, bmi088",
    );
    assert_error(&chip("bus = \"can\"\n"), "5:7", "unknown variant `can`");
    assert_error(
        &chip("model = \"icm42688p\"\nbus = \"i2c\"\naddress = 0x0C\n"),
        "7:11",
        "the ICM-42688-P answers I2C at 0x68, 0x69, not 0x0c",
    );
    assert_error(
        &chip("model = \"mpu6000\"\naddress = 0x69\n"),
        "6:11",
        "an address applies to bus = \"i2c\" only",
    );
    assert_error(
        &chip("model = \"mpu6000\"\nwho_am_i = 0x71\n"),
        "6:12",
        "the MPU-6000 answers 0x68, not 0x71",
    );
    assert_error(
        &chip("model = \"mpu9250\"\naccel_range = 3\n"),
        "6:15",
        "the MPU-9250 has no ±3 g range; its ranges are ± 2, 4, 8, 16 g",
    );
    assert_error(
        &chip("gyro_range = 4000\n"),
        "5:14",
        "the MPU-9250 has no ±4000 °/s range",
    );
    assert_error(
        &chip("rotation = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]]\n"),
        "5:12",
        "is a reflection",
    );
    assert_error(
        &chip("rotation = [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 1.0]]\n"),
        "5:12",
        "is not orthonormal",
    );
    assert_error(
        "duration = 1.0\nrate = 300.0\nseed = 1\n[chip]\nmodel = \"icm42688p\"\n",
        "2:8",
        "300 Hz is not an output rate of the ICM-42688-P",
    );
    assert_error(
        "duration = 1.0\nrate = 8000.0\nseed = 1\n[chip]\nmodel = \"bmi270\"\n",
        "2:8",
        "8000 Hz is not an output rate of the BMI270",
    );
    assert_error(
        &chip("model = \"bmi270\"\nwho_am_i = 0x47\n"),
        "6:12",
        "the BMI270 answers 0x24, not 0x47",
    );
    assert_error(
        &chip("model = \"bmi270\"\ngyro_range = 4000\n"),
        "6:14",
        "the BMI270 has no ±4000 °/s range; its ranges are ± 125, 250, 500, 1000, 2000 °/s",
    );
}

#[test]
fn magnetometer_chip_errors_are_located() {
    let chip = |body: &str| format!("{BASE}[chip]\n{body}");
    assert_error(
        &chip("model = \"ist8310\"\nbus = \"spi\"\n"),
        "6:7",
        "the IST8310 has no spi bus",
    );
    assert_error(
        &chip("model = \"qmc5883l\"\naccel_range = 8\n"),
        "6:15",
        "the QMC5883L is a magnetometer: it has no accel_range",
    );
    assert_error(
        &chip("model = \"qmc5883l\"\nmag_range = 4\n"),
        "6:13",
        "the QMC5883L has no ±4 G range; its ranges are ± 2, 8 G",
    );
    assert_error(
        &chip("model = \"icm42688p\"\nmag_range = 8\n"),
        "6:13",
        "the ICM-42688-P has no magnetometer range to choose",
    );
    assert_error(
        &chip("model = \"ist8310\"\naddress = 0x1E\n"),
        "6:11",
        "the IST8310 answers I2C at 0x0e, 0x0c, 0x0d, 0x0f, not 0x1e",
    );
    let scene = Scene::parse_str(
        &chip("model = \"qmc5883l\"\nmag_range = 8\n"),
        Path::new("q.toml"),
    )
    .unwrap();
    assert_eq!(
        scene.chip.bus,
        margemu::scene::chip::BusKind::I2c,
        "its only bus"
    );
    assert_eq!(scene.chip.settings.mag_range_gauss(), Some(8.0));
}

#[test]
fn rig_errors_are_located() {
    let dev = |body: &str| format!("\n[[device]]\n{body}");
    let imu = dev("name = \"imu\"\nmodel = \"icm42688p\"\n");
    assert_error(
        &format!("{BASE}{imu}{}", dev("model = \"ist8310\"\nbus = \"spi\"\n")),
        "11:7",
        "the IST8310 has no spi bus",
    );
    assert_error(
        &format!(
            "{BASE}{}{}",
            dev("model = \"mpu6000\"\nbus = \"i2c\"\naddress = 0x68\n"),
            dev("model = \"icm42688p\"\nbus = \"i2c\"\naddress = 0x68\n")
        ),
        "13:11",
        "device `mpu6000` answers I2C at 0x68 already",
    );
    assert_error(
        &format!(
            "{BASE}{}{}",
            dev("model = \"mpu9250\"\nbus = \"i2c\"\n"),
            dev("model = \"ist8310\"\naddress = 0x0C\n")
        ),
        "11:11",
        "device `mpu9250` answers I2C at 0x0c already",
    );
    assert_error(
        &format!("{BASE}{imu}{}", dev("model = \"mpu6000\"\n")),
        "9:1",
        "chip select 0 is device `imu`'s already",
    );
    assert_error(
        &format!(
            "{BASE}{imu}{}",
            dev("name = \"imu\"\nmodel = \"mpu6000\"\nchip_select = 1\n")
        ),
        "10:8",
        "device `imu` has that name already",
    );
    assert_error(
        &format!(
            "{BASE}{imu}{}",
            dev("name = \"a b\"\nmodel = \"ist8310\"\n")
        ),
        "10:8",
        "\"a b\" is not a device name",
    );
    assert_error(
        &format!("{BASE}[chip]\nmodel = \"mpu6000\"\n{imu}"),
        "4:1",
        "a scene lists its chips in [chip] or in [[device]], not both",
    );
    assert_error(
        &format!("{BASE}{}", dev("model = \"mpu6000\"\nchip_select = 4\n")),
        "7:15",
        "chip select 4 is not one of 0..=3",
    );
    assert_error(
        &format!("{BASE}{}", dev("model = \"ist8310\"\nchip_select = 1\n")),
        "7:15",
        "a chip select applies to bus = \"spi\" only",
    );
    assert_error(
        &format!(
            "{BASE}{}",
            dev("model = \"mpu6000\"\noffset = [0.0, 0.0, 5.0]\n")
        ),
        "7:10",
        "within ±1 m",
    );
    assert_error(
        &format!(
            "{BASE}{}{}{}",
            dev("model = \"icm42688p\"\n"),
            dev("model = \"icm42688p\"\nname = \"imu2\"\nchip_select = 1\n"),
            dev("model = \"ist8310\"\n")
        ),
        "14:9",
        "the rig's images would take 70 bytes a sample; the link carries at most 64",
    );
    let four: String = (0..4)
        .map(|i| {
            dev(&format!(
                "model = \"mpu6000\"\nchip_select = {}\nname = \"m{i}\"\n",
                i % 4
            ))
        })
        .collect();
    let e = error(&format!("{BASE}{four}"));
    assert!(e.contains("a rig has at most 3 devices"), "{e}");
    // A rate of the IMU's but not the other IMU's: located at the rate.
    assert_error(
        &format!(
            "duration = 1.0\nrate = 250.0\nseed = 1\n{}{}",
            dev("model = \"mpu6000\"\n"),
            dev("model = \"icm42688p\"\nchip_select = 1\n")
        ),
        "2:8",
        "250 Hz is not an output rate of the ICM-42688-P",
    );
}

/// A BMI088 takes two chip selects (its `chip_select` and the next one, the gyro die's) and two
/// I2C addresses (its accel's, and 0x68 or 0x69 for its gyro): clashes with either are refused
/// where they are, naming the die.
#[test]
fn bmi088_rig_errors_are_located() {
    let dev = |body: &str| format!("\n[[device]]\n{body}");
    let bmi = dev("name = \"bmi\"\nmodel = \"bmi088\"\n");
    assert_error(
        &format!("{BASE}{}", dev("model = \"bmi088\"\nchip_select = 3\n")),
        "7:15",
        "the BMI088 takes chip select 3 and the next one (its gyroscope die), but a board has \
         chip selects 0..=3: use one of 0..=2",
    );
    assert_error(
        &format!(
            "{BASE}{bmi}{}",
            dev("model = \"mpu6000\"\nchip_select = 1\n")
        ),
        "11:15",
        "chip select 1 is device `bmi`'s already: the BMI088's gyroscope die (chip_select + 1)",
    );
    assert_error(
        &format!(
            "{BASE}{}{}",
            dev("model = \"mpu6000\"\nchip_select = 2\n"),
            dev("model = \"bmi088\"\nchip_select = 1\n")
        ),
        "11:15",
        "chip select 2, the BMI088's gyroscope die (chip_select + 1), is device `mpu6000`'s already",
    );
    assert_error(
        &format!(
            "{BASE}{}{}",
            dev("model = \"icm42688p\"\nbus = \"i2c\"\n"),
            dev("model = \"bmi088\"\nbus = \"i2c\"\naddress = 0x18\n")
        ),
        "12:11",
        "device `icm42688p` answers I2C at 0x68 already",
    );
    // The rig: accel on 1, gyro on 2, an ICM-42688-P on 0, an RM3100 on 3; and a
    // BMI088 on I2C beside an ICM-42688-P at 0x68 once strapped to 0x19 (gyro 0x69).
    let text = format!(
        "{BASE}{}{}{}",
        dev("model = \"icm42688p\"\n"),
        dev("model = \"bmi088\"\nchip_select = 1\naccel_range = 24\n"),
        dev("model = \"rm3100\"\nchip_select = 3\n")
    );
    let scene = Scene::parse_str(&text, Path::new("rig.toml")).unwrap();
    let selects: Vec<u8> = scene.devices().iter().map(|d| d.chip.chip_select).collect();
    assert_eq!(selects, [0, 1, 3]);
    let text = format!(
        "{BASE}{}{}",
        dev("model = \"icm42688p\"\nbus = \"i2c\"\n"),
        dev("model = \"bmi088\"\nbus = \"i2c\"\naddress = 0x19\n")
    );
    assert!(Scene::parse_str(&text, Path::new("rig.toml")).is_ok());
}

#[test]
fn chip_table_resolves_with_defaults() {
    use margemu_protocol::chip::ChipModel;
    let scene = Scene::parse_str(BASE, Path::new("plain.toml")).unwrap();
    assert_eq!(scene.chip.model, ChipModel::Mpu9250);
    let text = format!(
        "{BASE}[chip]\nmodel = \"ICM-42688-P\"\nbus = \"i2c\"\naddress = 0x69\n\
         accel_range = 4\ngyro_range = 500\n\
         rotation = [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]]\n"
    );
    let scene = Scene::parse_str(&text, Path::new("icm.toml")).unwrap();
    let chip = scene.chip;
    assert_eq!(
        (chip.model, chip.who_am_i, chip.i2c_address),
        (ChipModel::Icm42688p, 0x47, 0x69)
    );
    let fs = chip.settings.full_scale().expect("an IMU");
    assert_eq!((fs.accel_g, fs.gyro_dps), (4.0, 500.0));
    assert_eq!(chip.to_chip([1.0, 2.0, 3.0]), [2.0, 1.0, -3.0]);
}

/// Finite values outside their plausible range are refused with the value and the range.
#[test]
fn implausible_values_show_the_value_and_the_range() {
    assert_error(
        &format!("{BASE}[bench]\ngravity = 5000.0\n"),
        "5:11",
        "`bench.gravity`: 5000 is outside the plausible range [0, 1000] m/s²",
    );
    assert_error(
        &format!("{BASE}[sensors.gyro]\nbias = [0.0, 2e7, 0.0]\n"),
        "5:14",
        "`sensors.gyro.bias[1]`: 2e7 is outside the plausible range [-1e6, 1e6]",
    );
    assert_error(
        &format!("{BASE}[sensors]\ntemperature = [25.0, 5000.0]\n"),
        "5:22",
        "`sensors.temperature[1]`: 5000 is outside the plausible range [-1000, 1000] °C/s",
    );
    assert_error(
        &format!("{BASE}[perturbation]\namplitude = [0.0, 1e9]\n"),
        "5:19",
        "`perturbation.amplitude[1]`: 1e9 is outside the plausible range [0, 1e6] field unit",
    );
    assert_error(
        &format!("{BASE}[joints.roll]\ntype = \"sine\"\namplitude = 0.1\nfrequency = 2e6\n"),
        "7:13",
        "`joints.roll.frequency`: 2e6 is outside the plausible range [0, 1e6] Hz",
    );
    assert_error(
        &format!("{BASE}[control]\novershoot = [0.2, 0.2, 1.5, 0.4, 0.4, 0.4]\n"),
        "5:24",
        "`control.overshoot[2]`: must be in (0, 1), not 1.5",
    );
}

/// Scenes that are not regular files are refused by their type, before anything opens them.
#[test]
fn a_scene_must_be_a_regular_file() {
    let e = Scene::load(Path::new("/dev/zero")).unwrap_err().to_string();
    assert_eq!(e, "/dev/zero: is a character device, not a regular file");
    let e = Scene::load(Path::new("/")).unwrap_err().to_string();
    assert_eq!(e, "/: is a directory, not a regular file");
}

/// Legal but likely wrong inputs load, with located warnings.
#[test]
fn warnings_are_located() {
    let text = format!(
        "{BASE}[joints.yaw]\ntype = \"random-sine\"\namplitude = [0.1, 0.2]\n\
         frequency = [1.0, 70.0]\nsegment = [0.5, 1.0]\n"
    );
    let scene = Scene::parse_str(&text, Path::new("w.toml")).unwrap();
    let warnings: Vec<String> = scene.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(
        warnings,
        [
            "w.toml:7:13: `joints.yaw.frequency`: 70 Hz is above the output Nyquist frequency \
          50 Hz (rate 100 Hz): the samples alias it"
        ]
    );
    let quiet = Scene::parse_str(BASE, Path::new("q.toml")).unwrap();
    assert!(quiet.warnings.is_empty());
}

#[test]
fn filter_errors_are_located() {
    let chip = |body: &str| format!("{BASE}[chip]\n{body}");
    assert_error(
        &chip("model = \"mpu6500\"\n[chip.filters]\ngyro_aaf_delt = 6\n"),
        "7:17",
        "the MPU-6500 takes the filter keys dlpf_cfg, fchoice_b, a_dlpf_cfg, accel_fchoice_b",
    );
    assert_error(
        &chip("model = \"mpu6500\"\n[chip.filters]\ndlpf_cfg = 0\n"),
        "6:1",
        "output rate 100 Hz cannot be produced with dlpf_cfg = 0 (DLPF_CFG 0 and 7 give 8 kHz only",
    );
    assert_error(
        &chip("model = \"mpu6500\"\n[chip.filters]\ndlpf_cfg = 300\n"),
        "7:12",
        "300 is not a register code (0-255)",
    );
    assert_error(
        &chip("model = \"ist8310\"\n[chip.filters]\ndlpf_cfg = 1\n"),
        "6:1",
        "the IST8310 is a magnetometer: it has no filters",
    );
    let dev =
        format!("{BASE}\n[[device]]\nmodel = \"icm42688p\"\n[device.filters]\ngyro_ui_bw = 9\n");
    assert_error(
        &dev,
        "7:1",
        "gyro_ui_bw = 9 is out of range (allowed: 0-7, 14, 15)",
    );
}

#[test]
fn filters_left_out_take_the_defaults() {
    use margemu_protocol::chip::ChainConfig;
    let text = format!("{BASE}[chip]\nmodel = \"mpu9250\"\n[chip.filters]\ndlpf_cfg = 3\n");
    let scene = Scene::parse_str(&text, Path::new("f.toml")).unwrap();
    assert_eq!(
        scene.chip.chain,
        Some(ChainConfig::Mpu6xxx {
            dlpf_cfg: 3,
            fchoice_b: 0,
            a_dlpf_cfg: 0,
            accel_fchoice_b: false
        })
    );
    let plain = Scene::parse_str(BASE, Path::new("p.toml")).unwrap();
    assert_eq!(
        plain.chip.chain,
        Some(ChainConfig::Mpu6xxx {
            dlpf_cfg: 1,
            fchoice_b: 0,
            a_dlpf_cfg: 0,
            accel_fchoice_b: false
        })
    );
    let text = format!("{BASE}[chip]\nmodel = \"qmc5883l\"\n");
    assert_eq!(
        Scene::parse_str(&text, Path::new("q.toml"))
            .unwrap()
            .chip
            .chain,
        None
    );
}

#[test]
fn bad_fault_schedules() {
    let stuck = "[[fault]]\nkind = \"stuck\"\nsensor = \"gyro\"\nstart = 0.2\nduration = 0.5\n";
    assert_error(
        &format!("{BASE}{stuck}[[fault]]\nkind = \"dropout\"\nsensor = \"gyro\"\nstart = 0.5\nduration = 0.1\n"),
        "12:9",
        "`fault[1].start`: fault[1] (dropout gyro on `mpu9250`, 0.5 s to 0.6 s) overlaps fault[0] (stuck gyro on `mpu9250`, 0.2 s to 0.7 s)",
    );
    assert_error(
        &format!(
            "{BASE}[[fault]]\ndevice = \"baro\"\nkind = \"nak\"\nstart = 0.2\nduration = 0.1\n"
        ),
        "5:10",
        "`fault[0].device`: no device `baro`; the devices are mpu9250",
    );
    assert_error(
        &format!("{BASE}[[fault]]\nkind = \"nak\"\nstart = 0.2\nduration = -0.1\n"),
        "7:12",
        "`fault[0].duration`: must be finite and > 0",
    );
}
