//! `[chip]`: which chip the device emulates for the scene, on which bus, and how it is mounted.
//!
//! ```toml
//! [chip]
//! model = "icm42688p"        # `margemu chips` lists them; default "mpu9250"
//! bus = "spi"                # or "i2c" (default: SPI if the model has it)
//! address = 0x69             # I2C only: one of the model's addresses (default its first; a
//!                            # BMI088's accel die, its gyro die at 0x68/0x69 alike)
//! who_am_i = 0x47            # an identity variant of the model (default its own)
//! rotation = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]  # plate → chip axes
//! accel_range = 16           # ± g, one of the model's full scales (default: power-on)
//! gyro_range = 2000          # ± °/s
//! mag_range = 8              # ± gauss: a magnetometer with a choice of ranges (QMC5883L: 2, 8)
//! chip_select = 0            # SPI only: the chip-select line, 0..=3 (default 0); a BMI088
//!                            # takes it (accel die) and the next one (gyro die)
//! offset = [0.02, 0.0, -0.01]  # m, plate axes: the lever arm from the plate's reference point
//! name = "imu"               # the device's name in logs (default: the model's name)
//!
//! [chip.filters]             # the sampling chain's filter registers, as codes (the keys of the
//! gyro_aaf_delt = 12         # model's family; any key left out takes the value Betaflight or
//! gyro_ui_bw = 15            # ArduPilot write at the scene's rate: `ChainConfig::default_for`)
//! ```
//!
//! A scene without `[chip]` keeps the MPU-9250 at its power-on settings, mounted with the
//! plate's axes, at any output rate. A scene with `[chip]` must also run at one of the chip's own
//! output rates. The rotation takes plate-frame vectors into the chip's axes (`v_chip = R·v_plate`)
//! before the sensor model, so the model's error terms are in the chip's axes; it must be a proper
//! rotation (orthonormal, determinant +1).

use super::error::Violation;
use margemu_protocol::chip::{
    ChainConfig, ChipChain, ChipModel, ChipSettings, FullScale, SettingsError,
};
use margemu_protocol::link::{AddDevice, Configure, DeviceBus, Rate, RegisterOverride};
use serde::Deserialize;
use std::collections::BTreeMap;

/// Chip-select lines a scene may name (a board's SPI target has at most this many).
pub const MAX_CHIP_SELECTS: u8 = 4;

/// The largest lever arm accepted, m per coordinate (a flight controller is centimetres across;
/// a metre catches a value in mm).
pub const MAX_OFFSET_M: f64 = 1.0;

/// A 3×3 matrix, row by row.
pub type Rotation = [[f64; 3]; 3];

/// The bus the device under test reads the chip on.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum BusKind {
    /// SPI (mode 3, read flag 0x80).
    #[default]
    Spi,
    /// I2C at [`ChipSpec::address`].
    I2c,
}

impl BusKind {
    /// The name in scene files and `meta.toml`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Spi => "spi",
            Self::I2c => "i2c",
        }
    }
}

/// `[chip]` as written.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ChipSpec {
    /// The model's name (`ChipModel::name`).
    pub model: Option<String>,
    /// The bus (default: SPI if the model has it, else I2C).
    pub bus: Option<BusKind>,
    /// The 7-bit I2C address (I2C only).
    pub address: Option<u8>,
    /// The identity variant (WHO_AM_I value).
    pub who_am_i: Option<u8>,
    /// Plate → chip axes.
    pub rotation: Option<Rotation>,
    /// Accelerometer full scale, ± g.
    pub accel_range: Option<f64>,
    /// Gyroscope full scale, ± °/s.
    pub gyro_range: Option<f64>,
    /// Magnetometer range, ± gauss (the QMC5883L's 2 or 8).
    pub mag_range: Option<f64>,
    /// The device's name in logs (a rig's `[[device]]`; default: the model's name).
    pub name: Option<String>,
    /// SPI only: the chip-select line the device under test drives for it (default 0).
    pub chip_select: Option<u8>,
    /// Where the chip sits on the plate, m, plate axes, from the plate's reference point (the
    /// lever arm: the chip senses the specific force of that point).
    pub offset: Option<[f64; 3]>,
    /// `[chip.filters]`: filter register codes by key (`ChainConfig::keys` of the family).
    pub filters: Option<BTreeMap<String, FilterValue>>,
}

/// A `[chip.filters]` value: a register code or a flag.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum FilterValue {
    /// A code.
    Code(i64),
    /// A one-bit field.
    Flag(bool),
}

/// The chip of a scene, resolved and checked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChipSetup {
    /// The model.
    pub model: ChipModel,
    /// The identity it answers.
    pub who_am_i: u8,
    /// The bus the device under test uses.
    pub bus: BusKind,
    /// The chip's 7-bit I2C address.
    pub i2c_address: u8,
    /// Plate → chip axes; `None`: the plate's own.
    pub rotation: Option<Rotation>,
    /// The conversion settings the images are computed with.
    pub settings: ChipSettings,
    /// SPI: the chip-select line.
    pub chip_select: u8,
    /// The lever arm, m, plate axes; `None`: at the plate's reference point.
    pub offset: Option<[f64; 3]>,
    /// The sampling chain's filter settings, checked against the scene's rate (`None`: a
    /// magnetometer, or the default chip of a scene without `[chip]` at a rate it cannot give).
    pub chain: Option<ChainConfig>,
}

impl Default for ChipSetup {
    /// The MPU-9250 at power-on on SPI, mounted with the plate's axes.
    fn default() -> Self {
        Self::power_on(ChipModel::Mpu9250)
    }
}

impl ChipSetup {
    /// `model` at power-on at its first address, on SPI if it has SPI (else I2C), mounted with
    /// the plate's axes.
    pub fn power_on(model: ChipModel) -> Self {
        let bus = if model.buses().contains(margemu_protocol::link::Buses::SPI) {
            BusKind::Spi
        } else {
            BusKind::I2c
        };
        Self {
            model,
            who_am_i: model.who_am_i(),
            bus,
            i2c_address: model.i2c_addresses()[0],
            rotation: None,
            settings: ChipSettings::power_on(model),
            chip_select: 0,
            offset: None,
            chain: None,
        }
    }

    /// The Configure of this chip at `rate` (the overrides set its full scales and, where the
    /// chip keeps them in one register, its output rate).
    pub fn configure(&self, rate: Rate) -> Configure {
        let mut cfg = Configure {
            who_am_i: self.who_am_i,
            i2c_address: self.i2c_address,
            ..Configure::new(self.model, rate)
        };
        // At most four writes: always within MAX_OVERRIDES.
        cfg.overrides.extend(self.overrides(rate));
        cfg
    }

    /// The AddDevice of this chip as a further device of a rig running at `rate`: its
    /// identity, address or chip select, and the overrides Configure would carry.
    pub fn add_device(&self, rate: Rate) -> AddDevice {
        let bus = match self.bus {
            BusKind::Spi => DeviceBus::Spi,
            BusKind::I2c => DeviceBus::I2c,
        };
        let mut add = AddDevice {
            who_am_i: self.who_am_i,
            i2c_address: self.i2c_address,
            chip_select: self.chip_select,
            ..AddDevice::new(self.model, bus)
        };
        // The same writes as Configure's (at most four): within MAX_DEVICE_OVERRIDES.
        add.overrides.extend(self.overrides(rate));
        add
    }

    /// The register overrides that set this chip's ranges (and, with `rate`, the output rate
    /// where one register holds both): what Configure and AddDevice carry.
    fn overrides(&self, rate: Rate) -> impl Iterator<Item = RegisterOverride> {
        self.settings
            .config_writes(rate.as_hz_f64())
            .map(|(file, register, value)| RegisterOverride {
                file,
                register,
                value,
            })
    }

    /// `v` (plate axes) in the chip's axes.
    pub fn to_chip(&self, v: [f64; 3]) -> [f64; 3] {
        match &self.rotation {
            None => v,
            Some(r) => rotate(r, v),
        }
    }
}

/// `m · v`.
pub fn rotate(m: &Rotation, v: [f64; 3]) -> [f64; 3] {
    core::array::from_fn(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
}

/// The rotation that takes a vector in the axes of a chip mounted by `from` into the axes of a
/// chip mounted by `to` (both scene rotations, plate → chip; `None` is the plate's own axes):
/// `R_to · R_fromᵀ`, back to the plate, then into the other chip. A flight controller turns its
/// compass's readings into its IMU's axes so.
///
/// ```
/// use margemu_sim::scene::chip::{axes_between, rotate};
/// let flipped = [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]];
/// let quarter = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
/// // A plate vector (1, 2, 3) reads (1, −2, −3) on the flipped chip and (2, −1, 3) on the other.
/// let m = axes_between(Some(flipped), Some(quarter));
/// assert_eq!(rotate(&m, [1.0, -2.0, -3.0]), [2.0, -1.0, 3.0]);
/// ```
pub fn axes_between(from: Option<Rotation>, to: Option<Rotation>) -> Rotation {
    const IDENTITY: Rotation = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let (f, t) = (from.unwrap_or(IDENTITY), to.unwrap_or(IDENTITY));
    core::array::from_fn(|i| core::array::from_fn(|j| (0..3).map(|k| t[i][k] * f[j][k]).sum()))
}

/// `scene` with its chip replaced by `name` at power-on on SPI (the scene's rotation kept), as
/// `--chip` asks; an error names an unknown model or a scene rate the chip cannot output.
pub fn with_model(scene: &super::Scene, name: &str) -> Result<super::Scene, String> {
    let model = ChipModel::from_name(name)
        .ok_or_else(|| format!("no chip model {name:?}; margemu emulates {}", model_names()))?;
    let rate = scene.spec.rate;
    if !model.has_output_rate(rate) {
        return Err(format!(
            "the {} cannot output the scene's {rate} Hz (`margemu chips {}` lists its rates)",
            model.part_name(),
            model.name()
        ));
    }
    let mut scene = scene.clone();
    if scene.chip_name == scene.chip.model.name() {
        scene.chip_name = model.name().to_owned();
    }
    let setup = ChipSetup::power_on(model);
    scene.chip = ChipSetup {
        rotation: scene.chip.rotation,
        chain: default_chain(&setup.settings, rate),
        ..setup
    };
    Ok(scene)
}

/// The names of every model, for messages.
pub fn model_names() -> String {
    let names: Vec<&str> = ChipModel::ALL.iter().map(|m| m.name()).collect();
    names.join(", ")
}

/// `0x68, 0x69`: register values or addresses, for messages.
pub fn hexes(values: &[u8]) -> String {
    let v: Vec<String> = values.iter().map(|v| format!("{v:#04x}")).collect();
    v.join(", ")
}

/// `2, 4, 8, 16`: full scales, for messages.
pub fn ranges(values: impl Iterator<Item = f64>) -> String {
    let v: Vec<String> = values.map(|v| v.to_string()).collect();
    v.join(", ")
}

/// The conversion settings `spec` asks of `model`: its full scales (an IMU) or its
/// magnetometer range; `table` is the spec's key path, for errors.
fn settings_of(
    spec: &ChipSpec,
    model: ChipModel,
    table: &[&str],
) -> Result<ChipSettings, Violation> {
    let part = model.part_name();
    let at = |key: &'static str| {
        let mut path = table.to_vec();
        path.push(key);
        path
    };
    let power_on = ChipSettings::power_on(model);
    let mut settings = match power_on.full_scale() {
        Some(power_on_fs) => {
            let fs = FullScale {
                accel_g: spec.accel_range.unwrap_or(power_on_fs.accel_g),
                gyro_dps: spec.gyro_range.unwrap_or(power_on_fs.gyro_dps),
            };
            ChipSettings::with_full_scale(model, fs).map_err(|e| match e {
                SettingsError::AccelRange(g) => Violation::at(
                    &at("accel_range"),
                    format!(
                        "the {part} has no ±{g} g range; its ranges are ± {} g",
                        ranges(ChipSettings::accel_ranges_g(model))
                    ),
                ),
                SettingsError::GyroRange(dps) => Violation::at(
                    &at("gyro_range"),
                    format!(
                        "the {part} has no ±{dps} °/s range; its ranges are ± {} °/s",
                        ranges(ChipSettings::gyro_ranges_dps(model))
                    ),
                ),
            })?
        }
        None => {
            let given = [
                ("accel_range", spec.accel_range),
                ("gyro_range", spec.gyro_range),
            ];
            if let Some((key, _)) = given.iter().find(|(_, v)| v.is_some()) {
                return Err(Violation::at(
                    &at(key),
                    format!("the {part} is a magnetometer: it has no {key}"),
                ));
            }
            power_on
        }
    };
    if let Some(gauss) = spec.mag_range {
        let choices = ChipSettings::mag_ranges_gauss(model);
        settings = settings.with_mag_range(gauss).map_err(|_| {
            let reason = if choices.is_empty() {
                format!("the {part} has no magnetometer range to choose")
            } else {
                format!(
                    "the {part} has no ±{gauss} G range; its ranges are ± {} G",
                    ranges(choices.iter().copied())
                )
            };
            Violation::at(&at("mag_range"), reason)
        })?;
    }
    Ok(settings)
}

/// Resolves `[chip]` (absent: the default MPU-9250) and checks it against the scene's `rate`.
pub(crate) fn resolve(spec: Option<&ChipSpec>, rate: f64) -> Result<ChipSetup, Violation> {
    let Some(spec) = spec else {
        // The default chip at any rate: its default chain where that rate has one.
        let setup = ChipSetup::default();
        return Ok(ChipSetup {
            chain: default_chain(&setup.settings, rate),
            ..setup
        });
    };
    let model = match &spec.model {
        None => ChipModel::Mpu9250,
        Some(name) => ChipModel::from_name(name).ok_or_else(|| {
            Violation::at(
                &["chip", "model"],
                format!("no chip model {name:?}; margemu emulates {}", model_names()),
            )
        })?,
    };
    let part = model.part_name();
    let who_am_i = spec.who_am_i.unwrap_or(model.who_am_i());
    if !model.identities().contains(&who_am_i) {
        return Err(Violation::at(
            &["chip", "who_am_i"],
            format!(
                "the {part} answers {}, not {who_am_i:#04x}",
                hexes(model.identities())
            ),
        ));
    }
    let bus = spec.bus.unwrap_or(ChipSetup::power_on(model).bus);
    if !model.buses().contains(match bus {
        BusKind::Spi => margemu_protocol::link::Buses::SPI,
        BusKind::I2c => margemu_protocol::link::Buses::I2C,
    }) {
        return Err(Violation::at(
            &["chip", "bus"],
            format!("the {part} has no {} bus", bus.name()),
        ));
    }
    let i2c_address = match (bus, spec.address) {
        (_, None) => model.i2c_addresses()[0],
        (BusKind::Spi, Some(_)) => {
            return Err(Violation::at(
                &["chip", "address"],
                "an address applies to bus = \"i2c\" only",
            ))
        }
        (BusKind::I2c, Some(a)) if model.i2c_addresses().contains(&a) => a,
        (BusKind::I2c, Some(a)) => {
            return Err(Violation::at(
                &["chip", "address"],
                format!(
                    "the {part} answers I2C at {}, not {a:#04x}",
                    hexes(model.i2c_addresses())
                ),
            ))
        }
    };
    if let Some(r) = &spec.rotation {
        check_rotation(r)?;
    }
    let settings = settings_of(spec, model, &["chip"])?;
    if !model.has_output_rate(rate) {
        return Err(Violation::at(
            &["rate"],
            format!(
                "{rate} Hz is not an output rate of the {part} (model = {:?})",
                model.name()
            ),
        ));
    }
    let last_select = MAX_CHIP_SELECTS - model.spi_selects();
    let chip_select = match (bus, spec.chip_select) {
        (_, None) => 0,
        (BusKind::Spi, Some(cs)) if cs <= last_select => cs,
        (BusKind::Spi, Some(cs)) if model.spi_selects() > 1 && cs < MAX_CHIP_SELECTS => {
            return Err(Violation::at(
                &["chip", "chip_select"],
                format!(
                    "the {part} takes chip select {cs} and the next one (its gyroscope die), \
                     but a board has chip selects 0..={}: use one of 0..={last_select}",
                    MAX_CHIP_SELECTS - 1
                ),
            ))
        }
        (BusKind::Spi, Some(cs)) => {
            return Err(Violation::at(
                &["chip", "chip_select"],
                format!(
                    "chip select {cs} is not one of 0..={}",
                    MAX_CHIP_SELECTS - 1
                ),
            ))
        }
        (BusKind::I2c, Some(_)) => {
            return Err(Violation::at(
                &["chip", "chip_select"],
                "a chip select applies to bus = \"spi\" only",
            ))
        }
    };
    if let Some(offset) = spec.offset {
        if offset
            .iter()
            .any(|x| !x.is_finite() || x.abs() > MAX_OFFSET_M)
        {
            return Err(Violation::at(
                &["chip", "offset"],
                format!("each coordinate must be finite and within ±{MAX_OFFSET_M} m"),
            ));
        }
    }
    Ok(ChipSetup {
        model,
        who_am_i,
        bus,
        i2c_address,
        rotation: spec.rotation,
        settings,
        chip_select,
        offset: spec.offset.filter(|o| *o != [0.0; 3]),
        chain: chain_of(spec, &settings, rate)?,
    })
}

/// The scene's rate as the link's ratio (mHz resolution; the chain rounds periods to ns).
pub fn link_rate(hz: f64) -> Option<Rate> {
    let mhz = (hz * 1000.0).round();
    (mhz >= 1.0 && mhz <= f64::from(u32::MAX)).then(|| Rate::new(mhz as u32, 1000))?
}

/// The default chain of `settings.model` at `rate`, if it builds there.
pub fn default_chain(settings: &ChipSettings, rate: f64) -> Option<ChainConfig> {
    let link = link_rate(rate)?;
    ChainConfig::default_for(settings.model, link)
        .filter(|c| ChipChain::new(settings, c, link).is_ok())
}

/// `[chip.filters]` over the family's defaults at `rate`, checked by building the chain.
fn chain_of(
    spec: &ChipSpec,
    settings: &ChipSettings,
    rate: f64,
) -> Result<Option<ChainConfig>, Violation> {
    let model = settings.model;
    let part = model.part_name();
    let link = link_rate(rate)
        .ok_or_else(|| Violation::at(&["rate"], format!("{rate} Hz is out of range")))?;
    let Some(default) = ChainConfig::default_for(model, link) else {
        return match &spec.filters {
            Some(_) => Err(Violation::at(
                &["chip", "filters"],
                format!("the {part} is a magnetometer: it has no filters"),
            )),
            None => Ok(None),
        };
    };
    let family = default.family();
    let keys = ChainConfig::keys(family);
    let mut values = default.values();
    for (key, value) in spec.filters.iter().flatten() {
        let at = |reason: String| {
            Violation::at_keys(vec!["chip".into(), "filters".into(), key.clone()], reason)
        };
        let Some(i) = keys.iter().position(|k| k == key) else {
            return Err(at(format!(
                "the {part} takes the filter keys {}",
                keys.join(", ")
            )));
        };
        let code = match *value {
            FilterValue::Flag(b) => u8::from(b),
            FilterValue::Code(c) => {
                u8::try_from(c).map_err(|_| at(format!("{c} is not a register code (0-255)")))?
            }
        };
        if let Some(slot) = values.get_mut(i) {
            *slot = code;
        }
    }
    let config = ChainConfig::from_values(family, &values)
        .ok_or_else(|| Violation::at(&["chip", "filters"], "internal: key count"))?;
    ChipChain::new(settings, &config, link)
        .map_err(|e| Violation::at(&["chip", "filters"], e.to_string()))?;
    Ok(Some(config))
}

fn check_rotation(r: &Rotation) -> Result<(), Violation> {
    let bad = |why: &str| Violation::at(&["chip", "rotation"], why.to_owned());
    if r.iter().flatten().any(|x| !x.is_finite()) {
        return Err(bad("every element must be finite"));
    }
    for i in 0..3 {
        for j in 0..3 {
            let dot: f64 = (0..3).map(|k| r[i][k] * r[j][k]).sum();
            let want = if i == j { 1.0 } else { 0.0 };
            if (dot - want).abs() > 1e-6 {
                return Err(bad(
                    "is not orthonormal (rows must be unit vectors at right angles)",
                ));
            }
        }
    }
    let det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
        - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
        + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
    if det < 0.0 {
        return Err(bad("is a reflection (determinant −1), not a rotation"));
    }
    Ok(())
}
