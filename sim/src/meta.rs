//! The schema of `meta.toml`, the metadata file of every run and session directory, defined
//! once: every writer serialises these types and every reader deserialises them.
//!
//! A `simulate` run writes a [`RunMeta`], a session (`loopback`, `stream`) a [`SessionMeta`],
//! whole, when it begins ([`write()`]). Tables are appended later, each serialised from its type
//! ([`append`]): a session's [`DeviceMeta`] (`[device]`, after the handshake) and, with a device
//! under test, its reader's [`DutMeta`] (`[dut]`); last, in every directory, the completion
//! record ([`Completion`], `[completion]`; see [`crate::rundir`]). The appended tables are
//! `Option` fields of the file's type, so a file read at any stage parses.
//!
//! Fields, in the order written:
//! - a run: `margemu_version`, `scene_file`, `scene_sha256`, `seed`, `motion`, `rate_hz`,
//!   `duration_s`, `samples`, `integrator`, `integrator_step_s`, `field_unit`, `truth_columns`,
//!   `scene_text`, one `[[pid]]` per joint ([`PidMeta`]), `[completion]`;
//! - a session: `margemu_version`, `protocol_version`, `scene_file`, `scene_sha256`, `seed`,
//!   `samples`, `duration_s`, `rate_hz`, `rate_num`, `rate_den`, `port`, `baud`, `source`,
//!   `kinematics_hold`, `kinematics_rate_hz`, `lead_ns`, `batch`, `telemetry_period_ns`,
//!   `session_id`, `field_unit`, `mag_ut_per_unit`, `default_temp_c`, `scene_text`, `[chip]`
//!   ([`ChipMeta`]), `[image]` ([`ImageMeta`], InvenSense 6xxx only), `[device]`, `[dut]`,
//!   `[completion]`.
//!
//! [`read`] tells the kinds apart by their keys: `protocol_version` makes a session,
//! `margemu_version` alone a run; a file with neither was written by hand or another tool
//! ([`ForeignMeta`]: only `start_host_ns` is read from it).

use crate::rundir::{Completion, META_FILE};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// `meta.toml` of a `simulate` run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunMeta {
    /// The margemu version that wrote the run.
    pub margemu_version: String,
    /// The scene's path, or `builtin:NAME`.
    pub scene_file: String,
    /// SHA-256 of the scene text, hex.
    pub scene_sha256: String,
    /// The scene's seed.
    pub seed: u64,
    /// The motion mode, lower case (`static`, `kinematic`, `bench`).
    pub motion: String,
    /// Output rate (Hz).
    pub rate_hz: f64,
    /// Scene duration (s).
    pub duration_s: f64,
    /// Output samples of the scene.
    pub samples: u64,
    /// The integrator (`Debug` form).
    pub integrator: String,
    /// The integrator's step (s).
    pub integrator_step_s: f64,
    /// The unit of the scene's field.
    pub field_unit: String,
    /// The columns of `truth.csv`.
    pub truth_columns: Vec<String>,
    /// PID gains and tuning per joint.
    pub pid: Vec<PidMeta>,
    /// The scene text.
    pub scene_text: String,
    /// `[completion]`, appended when the run has ended.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub completion: Option<Completion>,
}

/// `[[pid]]` of a run: one joint's gains (NaN without a bench) and, when synthesised, its tuning.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PidMeta {
    /// The joint's name.
    pub joint: String,
    /// Proportional gain.
    pub kp: f64,
    /// Integral gain.
    pub ki: f64,
    /// Derivative gain.
    pub kd: f64,
    /// Damping ratio of the synthesis.
    pub zeta: Option<f64>,
    /// Natural frequency of the synthesis (rad/s).
    pub natural_frequency: Option<f64>,
    /// Time constant of the synthesis (s).
    pub time_constant: Option<f64>,
}

/// `meta.toml` of a session (`loopback`, `stream`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SessionMeta {
    /// The margemu version that wrote the session.
    pub margemu_version: String,
    /// The link protocol's version.
    pub protocol_version: u16,
    /// The scene's path, or `builtin:NAME`.
    pub scene_file: String,
    /// SHA-256 of the scene text, hex.
    pub scene_sha256: String,
    /// The scene's seed.
    pub seed: u64,
    /// Output samples of the scene.
    pub samples: u64,
    /// Scene duration (s).
    pub duration_s: f64,
    /// Output rate (Hz).
    pub rate_hz: f64,
    /// The exact rate sent: numerator (Hz).
    pub rate_num: u32,
    /// The exact rate sent: denominator.
    pub rate_den: u32,
    /// The port's name.
    pub port: String,
    /// The line rate.
    pub baud: u32,
    /// The source mode: `images` or `model`.
    pub source: String,
    /// Source mode model: output samples per kinematics message.
    pub kinematics_hold: Option<u32>,
    /// Source mode model: kinematics messages per second.
    pub kinematics_rate_hz: Option<f64>,
    /// How far ahead of its due time a sample is sent (ns).
    pub lead_ns: u64,
    /// Samples per message.
    pub batch: usize,
    /// The device's telemetry period (ns).
    pub telemetry_period_ns: u64,
    /// The session number.
    pub session_id: u32,
    /// The unit of the scene's field.
    pub field_unit: String,
    /// µT per unit of the scene's field.
    pub mag_ut_per_unit: f64,
    /// The temperature of images without one (°C).
    pub default_temp_c: f32,
    /// `[chip]`: the chip, device 0 of a rig.
    pub chip: ChipMeta,
    /// `[[other_devices]]`: a rig's further devices, in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub other_devices: Vec<ChipMeta>,
    /// `[image]`: the InvenSense 6xxx family's further conversion settings.
    pub image: Option<ImageMeta>,
    /// The scene text.
    pub scene_text: String,
    /// `[device]`, appended after the handshake.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub device: Option<DeviceMeta>,
    /// `[dut]`, appended when the device under test's reader has stopped.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dut: Option<DutMeta>,
    /// `[completion]`, appended when the session has ended.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub completion: Option<Completion>,
}

/// `[chip]` of a session: the emulated chip and the full scales of the images.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChipMeta {
    /// The chip's name in scene files (`mpu9250`, `icm42688p`, …).
    pub model: String,
    /// Its WHO_AM_I value.
    pub who_am_i: u8,
    /// The bus (`spi`, `i2c`).
    pub bus: String,
    /// The I²C address.
    pub i2c_address: u8,
    /// Bytes of one register image.
    pub image_len: usize,
    /// Accelerometer full scale (g); absent for a magnetometer.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accel_range_g: Option<f64>,
    /// Gyroscope full scale (°/s); absent for a magnetometer.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gyro_range_dps: Option<f64>,
    /// Magnetometer range (gauss), for a magnetometer whose range a driver chooses.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mag_range_gauss: Option<f64>,
    /// The chip's mounting rotation, rows.
    pub rotation: Option<crate::scene::chip::Rotation>,
    /// The device's name in the logs (`sent.csv`'s `image.NAME` column of a rig).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// SPI: the chip-select line.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chip_select: Option<u8>,
    /// The lever arm, m, plate axes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub offset: Option<[f64; 3]>,
    /// The filter settings its sampling chain runs with: `[chip.filters]` over the family's
    /// defaults, every key of the family (absent for a magnetometer).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filters: Option<std::collections::BTreeMap<String, u8>>,
    /// Where its chain runs: `output` or `internal` (absent for a magnetometer).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sampling_path: Option<String>,
}

/// `[image]` of a session: the InvenSense 6xxx family's conversion settings (offsets, AK8963),
/// enums in their `Debug` form.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ImageMeta {
    /// Accelerometer full-scale setting.
    pub accel_fs: String,
    /// Gyroscope full-scale setting.
    pub gyro_fs: String,
    /// Magnetometer output width.
    pub mag_bits: String,
    /// The AK8963 sensitivity adjustment values.
    pub asa: [u8; 3],
    /// Gyroscope offset registers.
    pub gyro_offset: [i16; 3],
    /// Accelerometer offset registers.
    pub accel_offset: [i16; 3],
}

/// `[device]` of a session: what the device announced in its handshake.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DeviceMeta {
    /// Its link protocol version.
    pub protocol_version: u16,
    /// Its firmware version, `major.minor.patch`.
    pub firmware: String,
    /// Its id, hex.
    pub device_id: String,
    /// The chips it emulates (bit set).
    pub chips: u32,
    /// The source modes it accepts (bit set).
    pub modes: u8,
    /// The buses it serves (bit set).
    pub buses: u8,
    /// Samples per message at most.
    pub max_batch: u16,
    /// Samples it can buffer.
    pub buffer_capacity: u32,
}

/// `[dut]` of a session: the device under test's reader's summary.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DutMeta {
    /// The wire format (`mavlink`, `msp`).
    pub protocol: String,
    /// Messages decoded, all types.
    pub messages: u64,
    /// Rows of `dut_attitude.csv`.
    pub attitude_rows: u64,
    /// Rows of `dut_imu.csv`.
    pub imu_rows: u64,
    /// Bytes read.
    pub bytes: u64,
    /// Bytes outside any frame.
    pub bad_bytes: u64,
    /// Frames that failed their check.
    pub bad_frames: u64,
    /// Frames of unknown message ids.
    pub unknown_ids: u64,
    /// Known messages whose payload did not decode.
    pub undecoded: u64,
    /// MSP requests written.
    pub requests_sent: u64,
    /// How the reader ended.
    pub end: String,
    /// `[dut.per_message]`: decoded messages per name.
    pub per_message: BTreeMap<String, u64>,
}

/// A `meta.toml` margemu did not write (made by hand or by another tool).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ForeignMeta {
    /// Host time (ns) of scene time 0, if given.
    pub start_host_ns: Option<i64>,
}

/// A `meta.toml` as read: a run's, a session's, or another's.
#[derive(Clone, Debug, PartialEq)]
pub enum MetaFile {
    /// A `simulate` run.
    Run(Box<RunMeta>),
    /// A session.
    Session(Box<SessionMeta>),
    /// Not written by margemu.
    Foreign(ForeignMeta),
}

impl MetaFile {
    /// The completion record, if the file has one (a foreign file has none).
    pub fn completion(&self) -> Option<&Completion> {
        match self {
            Self::Run(m) => m.completion.as_ref(),
            Self::Session(m) => m.completion.as_ref(),
            Self::Foreign(_) => None,
        }
    }

    /// The scene text, if margemu wrote the file.
    pub fn scene_text(&self) -> Option<&str> {
        match self {
            Self::Run(m) => Some(&m.scene_text),
            Self::Session(m) => Some(&m.scene_text),
            Self::Foreign(_) => None,
        }
    }

    /// The session's meta, if it is one.
    pub fn session(&self) -> Option<&SessionMeta> {
        match self {
            Self::Session(m) => Some(m),
            _ => None,
        }
    }
}

/// A `meta.toml` that cannot be read: {path}: {reason}
#[derive(Debug, thiserror::Error, docsplay::Display)]
pub struct MetaError {
    /// The file.
    pub path: PathBuf,
    /// Why (with line and column where the TOML is at fault).
    pub reason: String,
}

/// Reads `dir/meta.toml` (see the module docs for how its kind is told).
pub fn read(dir: &Path) -> Result<MetaFile, MetaError> {
    let path = dir.join(META_FILE);
    let bad = |reason: String| MetaError {
        path: path.clone(),
        reason,
    };
    let text = crate::input_file::read_to_string(&path).map_err(|e| bad(e.reason()))?;
    let keys: toml::Table = toml::from_str(&text).map_err(|e| bad(e.to_string()))?;
    let meta = if keys.contains_key("protocol_version") {
        toml::from_str(&text).map(|m| MetaFile::Session(Box::new(m)))
    } else if keys.contains_key("margemu_version") {
        toml::from_str(&text).map(|m| MetaFile::Run(Box::new(m)))
    } else {
        toml::from_str(&text).map(MetaFile::Foreign)
    };
    meta.map_err(|e| bad(e.to_string()))
}

/// `meta` as the text of `meta.toml`.
pub fn to_toml(meta: &impl Serialize) -> String {
    toml::to_string(meta).expect("the meta.toml schema serialises")
}

/// Writes `dir/meta.toml` whole from `meta` (a [`RunMeta`] or [`SessionMeta`]): under its
/// temporary name, then renamed.
pub fn write(dir: &Path, meta: &impl Serialize) -> io::Result<()> {
    crate::rundir::write_meta(dir, &to_toml(meta))
}

/// A table appended to `meta.toml` after its head.
#[derive(Clone, Copy, Debug)]
pub enum Appended<'a> {
    /// `[device]`.
    Device(&'a DeviceMeta),
    /// `[dut]`.
    Dut(&'a DutMeta),
    /// `[completion]`.
    Completion(&'a Completion),
}

#[derive(Serialize, Default)]
struct Tables<'a> {
    device: Option<&'a DeviceMeta>,
    dut: Option<&'a DutMeta>,
    completion: Option<&'a Completion>,
}

impl Appended<'_> {
    /// The table's text, with the blank line that separates it from what comes before.
    pub fn to_toml(self) -> String {
        let mut tables = Tables::default();
        match self {
            Self::Device(d) => tables.device = Some(d),
            Self::Dut(d) => tables.dut = Some(d),
            Self::Completion(c) => tables.completion = Some(c),
        }
        format!("\n{}", to_toml(&tables))
    }
}

/// Appends `table` to `dir/meta.toml` in one write. It is not synced to the disk, like every
/// other file of a run directory ([`crate::rundir`], "Completion record").
pub fn append(dir: &Path, table: Appended<'_>) -> io::Result<()> {
    let mut meta = std::fs::OpenOptions::new()
        .append(true)
        .open(dir.join(META_FILE))?;
    meta.write_all(table.to_toml().as_bytes())
}

#[cfg(test)]
mod tests;
