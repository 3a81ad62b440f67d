//! `[[device]]`: a rig of several chips served at once from one scene.
//!
//! ```toml
//! [[device]]
//! name = "imu"
//! model = "icm42688p"
//! bus = "spi"
//! chip_select = 0
//! accel_range = 16
//! gyro_range = 2000
//!
//! [[device]]
//! name = "compass"
//! model = "ist8310"           # I2C only
//! address = 0x0E
//! offset = [0.0, 0.0, 0.03]   # m, plate axes
//! rotation = [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]]
//! ```
//!
//! Each `[[device]]` takes every key of `[chip]` (the model, bus, address or chip select,
//! identity, mounting rotation and lever arm, ranges, name). A scene names its chips either in
//! `[chip]` (one device) or in `[[device]]` (one to [`MAX_DEVICES`]), not both; without either it
//! has the MPU-9250 at power-on. The first device is the scene's primary chip
//! ([`super::Scene::chip`]); [`super::Scene::devices`] lists them all.
//!
//! Checked across devices, each refusal located at the offending key: names unique (a name
//! is the device's column in the logs: letters, digits, `_` and `-`), no two I2C devices
//! answering one address (an MPU-9250 on I2C also answers 0x0C, its AK8963 in bypass mode; a
//! BMI088 its gyro die's 0x68 or 0x69 too), no two SPI devices on one chip select (a BMI088
//! takes its `chip_select` for the accel die and the next one for the gyro die), the scene's
//! rate an output rate of every IMU in the rig (a magnetometer measures on its own schedule),
//! and the devices' images together at most [`MAX_IMAGE_LEN`] bytes (64: two ICM-42688-Ps, or
//! an IMU, a second IMU and a compass).
//!
//! ```
//! let text = "duration = 1.0\nrate = 1000.0\nseed = 1\n\
//!     [[device]]\nmodel = \"icm42688p\"\n[[device]]\nmodel = \"ist8310\"\n";
//! let scene = margemu_sim::scene::Scene::parse_str(text, std::path::Path::new("rig.toml")).unwrap();
//! let names: Vec<_> = scene.devices().into_iter().map(|d| d.name).collect();
//! assert_eq!(names, ["icm42688p", "ist8310"]);
//! ```

use super::chip::{self, hexes, BusKind, ChipSetup, ChipSpec};
use super::error::{PathPart, Violation};
use margemu_protocol::chip::{ChipModel, MAX_IMAGE_LEN};
pub use margemu_protocol::link::MAX_DEVICES;

/// One device of a scene: its name in the logs and its chip.
#[derive(Clone, Debug, PartialEq)]
pub struct Device {
    /// Unique within the scene.
    pub name: String,
    /// The chip, its wiring, mounting and ranges.
    pub chip: ChipSetup,
}

/// The devices of a scene, device 0 and the others: `[chip]` or `[[device]]` (absent: the
/// default MPU-9250).
pub(crate) fn resolve(
    chip: Option<&ChipSpec>,
    devices: &[ChipSpec],
    rate: f64,
) -> Result<(Device, Vec<Device>), Violation> {
    let mut rig = resolve_all(chip, devices, rate)?.into_iter();
    let primary = rig
        .next()
        .ok_or_else(|| Violation::at(&["device"], "no device"))?;
    Ok((primary, rig.collect()))
}

fn resolve_all(
    chip: Option<&ChipSpec>,
    devices: &[ChipSpec],
    rate: f64,
) -> Result<Vec<Device>, Violation> {
    if devices.is_empty() {
        let setup = chip::resolve(chip, rate)?;
        let name = chip.and_then(|c| c.name.clone());
        if let Some(name) = &name {
            check_name(name).map_err(|why| Violation::at(&["chip", "name"], why))?;
        }
        let name = name.unwrap_or_else(|| setup.model.name().to_owned());
        return Ok(vec![Device { name, chip: setup }]);
    }
    if chip.is_some() {
        return Err(Violation::at(
            &["chip"],
            "a scene lists its chips in [chip] or in [[device]], not both",
        ));
    }
    if devices.len() > MAX_DEVICES {
        return Err(Violation::at(
            &["device"],
            format!("a rig has at most {MAX_DEVICES} devices"),
        )
        .index(MAX_DEVICES));
    }
    let mut rig: Vec<Device> = Vec::with_capacity(devices.len());
    for (i, spec) in devices.iter().enumerate() {
        let at = |key: &str| device_path(i, key);
        let setup = chip::resolve(Some(spec), rate).map_err(|v| in_device(v, i))?;
        let name = match &spec.name {
            Some(name) => {
                check_name(name).map_err(|why| Violation::at_path(at("name"), why))?;
                name.clone()
            }
            None => setup.model.name().to_owned(),
        };
        if let Some(other) = rig.iter().find(|d| d.name == name) {
            let key = if spec.name.is_some() { "name" } else { "model" };
            return Err(Violation::at_path(
                at(key),
                format!(
                    "device `{}` has that name already: give each device a `name`",
                    other.name
                ),
            ));
        }
        if let Some((other, address)) = i2c_clash(&rig, &setup) {
            return Err(Violation::at_path(
                at("address"),
                format!(
                    "device `{other}` answers I2C at {} already",
                    hexes(&[address])
                ),
            ));
        }
        if let Some(why) = spi_clash(&rig, &setup) {
            return Err(Violation::at_path(at("chip_select"), why));
        }
        let image_len: usize = rig.iter().map(|d| d.chip.model.image_len()).sum();
        let total = image_len + setup.model.image_len();
        if total > MAX_IMAGE_LEN {
            return Err(Violation::at_path(
                at("model"),
                format!(
                    "the rig's images would take {total} bytes a sample; the link carries at \
                     most {MAX_IMAGE_LEN}"
                ),
            ));
        }
        rig.push(Device { name, chip: setup });
    }
    Ok(rig)
}

/// The 7-bit addresses a chip on I2C answers: its own, for the MPU-9250 its AK8963 in bypass
/// mode, for the BMI088 its gyro die.
fn i2c_addresses(chip: &ChipSetup) -> Vec<u8> {
    let second = chip.model.second_die_i2c_address(chip.i2c_address);
    match (chip.bus, chip.model) {
        (BusKind::Spi, _) => vec![],
        (BusKind::I2c, ChipModel::Mpu9250) => vec![chip.i2c_address, AK8963_ADDRESS],
        (BusKind::I2c, _) => [Some(chip.i2c_address), second]
            .into_iter()
            .flatten()
            .collect(),
    }
}

/// The chip selects a chip on SPI takes: its own, and the next for a BMI088's gyro die.
fn chip_selects(chip: &ChipSetup) -> std::ops::Range<u8> {
    match chip.bus {
        BusKind::Spi => chip.chip_select..chip.chip_select + chip.model.spi_selects(),
        BusKind::I2c => 0..0,
    }
}

/// The AK8963's address, which the MPU-9250 answers in bypass mode.
const AK8963_ADDRESS: u8 = margemu_protocol::regmap::ak8963::I2C_ADDRESS;

fn i2c_clash(rig: &[Device], chip: &ChipSetup) -> Option<(String, u8)> {
    let mine = i2c_addresses(chip);
    rig.iter().find_map(|d| {
        let theirs = i2c_addresses(&d.chip);
        let shared = mine.iter().find(|a| theirs.contains(a))?;
        Some((d.name.clone(), *shared))
    })
}

/// Why `chip` cannot have its chip selects: which one is whose already.
fn spi_clash(rig: &[Device], chip: &ChipSetup) -> Option<String> {
    let mine = chip_selects(chip);
    rig.iter().find_map(|d| {
        let theirs = chip_selects(&d.chip);
        let cs = mine.clone().find(|cs| theirs.contains(cs))?;
        let other = &d.name;
        let gyro = |part: &str| format!("the {part}'s gyroscope die (chip_select + 1)");
        Some(if cs != chip.chip_select {
            let part = chip.model.part_name();
            format!(
                "chip select {cs}, {}, is device `{other}`'s already",
                gyro(part)
            )
        } else if cs != d.chip.chip_select {
            let part = d.chip.model.part_name();
            format!(
                "chip select {cs} is device `{other}`'s already: {}",
                gyro(part)
            )
        } else {
            format!("chip select {cs} is device `{other}`'s already")
        })
    })
}

fn check_name(name: &str) -> Result<(), String> {
    let ok = !name.is_empty()
        && name.len() <= 32
        && name
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-');
    if ok {
        Ok(())
    } else {
        Err(format!(
            "{name:?} is not a device name: 1 to 32 letters, digits, `_` or `-`"
        ))
    }
}

fn device_path(i: usize, key: &str) -> Vec<PathPart> {
    vec![
        PathPart::Key("device".to_owned()),
        PathPart::Index(i),
        PathPart::Key(key.to_owned()),
    ]
}

/// A `[chip]` violation moved to `[[device]]` number `i`.
fn in_device(mut v: Violation, i: usize) -> Violation {
    if v.path.first() == Some(&PathPart::Key("chip".to_owned())) {
        v.path.splice(
            ..1,
            [PathPart::Key("device".to_owned()), PathPart::Index(i)],
        );
    }
    v
}
