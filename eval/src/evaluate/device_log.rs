//! What a session directory says about the link: when scene time 0 was on the host's clock, and
//! what the device was sent (`sent.csv`, decoded back to physical units for the norm plots and
//! the magnetic phase).
//!
//! `meta.toml` is read through its schema ([`margemu_sim::meta`]). Scene time 0 is `start_host_ns`
//! from a `meta.toml` written by hand ([`ForeignMeta`]) when present, otherwise from the `start`
//! row of `events.csv` (`detail` = `start_host_ns N; …`, as `margemu stream` writes it).
//!
//! Register images are decoded by the chip module of `meta.toml`'s `[chip] model` (the MPU-9250
//! when absent) with the settings of `[chip]` (full scales) and `[image]` (the 6xxx family's ASA
//! and offsets; the power-on defaults when absent), through
//! [`ChipSettings::decode`](margemu_protocol::chip::ChipSettings::decode): specific force in
//! m/s², the field in the scene's unit (µT ÷ `mag_ut_per_unit`), both in the chip's axes. What
//! the chip clipped stays clipped: the plots show what the device under test was given.

use margemu_protocol::chip::{ChipModel, ChipSettings, Conversion, FullScale, Image};
use margemu_protocol::regmap::ak8963::MagBits;
use margemu_protocol::regmap::mpu6xxx::AccelFs;
use margemu_sim::csv_column::ColumnError;
use margemu_sim::csv_table::Table;
use margemu_sim::meta::{ForeignMeta, MetaFile};
use std::path::{Path, PathBuf};

/// A session file that says something unusable.
#[derive(Debug, thiserror::Error, docsplay::Display)]
pub enum SessionFileError {
    /// {path}: {reason}
    Bad {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// {0}
    Column(ColumnError),
}

impl From<ColumnError> for SessionFileError {
    fn from(e: ColumnError) -> Self {
        Self::Column(e)
    }
}

/// What evaluation needs from a session's `meta.toml` and `events.csv`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SessionMeta {
    /// Host time (ns) of scene time 0.
    pub start_host_ns: i64,
    /// The chip and the register settings of the images sent.
    pub chip: ChipSettings,
    /// µT per unit of the scene's field.
    pub mag_ut_per_unit: f64,
}

fn bad(path: &Path, reason: impl Into<String>) -> SessionFileError {
    SessionFileError::Bad {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

/// Reads `dir/meta.toml` (and `dir/events.csv` when `meta.toml` has no `start_host_ns`).
pub fn read_meta(dir: &Path) -> Result<SessionMeta, SessionFileError> {
    let file = margemu_sim::meta::read(dir).map_err(|e| bad(&e.path, e.reason))?;
    let path = dir.join(margemu_sim::rundir::META_FILE);
    let start_host_ns = match &file {
        MetaFile::Foreign(ForeignMeta {
            start_host_ns: Some(ns),
        }) => *ns,
        _ => start_from_events(&dir.join("events.csv"))?,
    };
    let meta = file.session();
    let mut chip = match meta.map(|m| &m.chip) {
        None => ChipSettings::power_on(ChipModel::Mpu9250),
        Some(c) => {
            let model = ChipModel::from_name(&c.model)
                .ok_or_else(|| bad(&path, format!("[chip] model = {:?} is no chip", c.model)))?;
            let settings = match (c.accel_range_g, c.gyro_range_dps) {
                (Some(accel_g), Some(gyro_dps)) => {
                    let fs = FullScale { accel_g, gyro_dps };
                    ChipSettings::with_full_scale(model, fs)
                        .map_err(|e| bad(&path, format!("[chip]: {e:?}")))?
                }
                (None, None) => ChipSettings::power_on(model),
                _ => {
                    let reason =
                        "[chip] has one of accel_range_g and gyro_range_dps without the other";
                    return Err(bad(&path, reason.to_string()));
                }
            };
            match c.mag_range_gauss {
                None => settings,
                Some(gauss) => settings.with_mag_range(gauss).map_err(|_| {
                    let reason = format!(
                        "[chip] mag_range_gauss = {gauss} is no range of the {}",
                        model.part_name()
                    );
                    bad(&path, reason)
                })?,
            }
        }
    };
    if let (Some(m), Conversion::Mpu6xxx(image)) =
        (meta.and_then(|m| m.image.as_ref()), &mut chip.conversion)
    {
        image.accel_fs = pick(&path, "accel_fs", &m.accel_fs, &AccelFs::ALL)?;
        image.mag_bits = pick(
            &path,
            "mag_bits",
            &m.mag_bits,
            &[MagBits::Bits14, MagBits::Bits16],
        )?;
        image.asa = m.asa;
        image.accel_offset = m.accel_offset;
    }
    Ok(SessionMeta {
        start_host_ns,
        chip,
        mag_ut_per_unit: meta.map_or(1.0, |m| m.mag_ut_per_unit),
    })
}

/// The option of `options` whose `Debug` form is `text` (as `meta.toml` writes them).
fn pick<T: Copy + std::fmt::Debug>(
    path: &Path,
    key: &str,
    text: &str,
    options: &[T],
) -> Result<T, SessionFileError> {
    let names: Vec<String> = options.iter().map(|o| format!("{o:?}")).collect();
    names
        .iter()
        .position(|n| n == text)
        .map(|i| options[i])
        .ok_or_else(|| {
            bad(
                path,
                format!("[image] {key} = {text:?} is none of {}", names.join(", ")),
            )
        })
}

fn start_from_events(path: &Path) -> Result<i64, SessionFileError> {
    let table = Table::open(path)?;
    let [event, detail] = table.columns(["event", "detail"])?;
    let mut start = None;
    table.for_each(|row| {
        if start.is_none() && row.text(event) == "start" {
            let text = row.text(detail);
            let value = text
                .strip_prefix("start_host_ns ")
                .and_then(|r| r.split(';').next())
                .and_then(|n| n.trim().parse::<i64>().ok());
            start = Some(value.ok_or_else(|| {
                row.error(format!("`detail` = {text:?} has no `start_host_ns N`"))
            })?);
        }
        Ok(())
    })?;
    start.ok_or_else(|| {
        bad(
            path,
            "no `start` row, and meta.toml has no start_host_ns: the session never started",
        )
    })
}

/// Specific force (m/s²) and field (scene unit; NaN for a chip without magnetometer) of one
/// register image; `None` if it is not of the chip's length.
pub fn decode(image: &[u8], meta: &SessionMeta) -> Option<([f64; 3], [f64; 3])> {
    let r = meta.chip.decode(image)?;
    let mag = r
        .mag_ut
        .map_or([f64::NAN; 3], |m| m.map(|b| b / meta.mag_ut_per_unit));
    Some((r.acc, mag))
}

/// `sent.csv` decoded: `(t_ns, specific force, field)` per row. A rig's session has one
/// `image.NAME` column per device: device 0's (the first) is decoded, with its own
/// magnetometer only (a rig's external compass is not decoded here yet).
pub fn read_sent(path: &Path, meta: &SessionMeta) -> Result<super::input::Imu, ColumnError> {
    let table = Table::open(path)?;
    let t = table.column("t_ns")?;
    let image = match table.first_with_prefix("image.") {
        Some(column) if table.optional("image").is_none() => column,
        _ => table.column("image")?,
    };
    let mut imu = super::input::Imu::default();
    table.for_each(|row| {
        let t_ns: u64 = row.int(t)?;
        row.check_order(t, imu.t_ns.last().copied(), t_ns, true)?;
        let text = row.text(image);
        let len = meta.chip.model.image_len();
        let decoded = Image::parse_hex(text, len).and_then(|bytes| decode(&bytes, meta));
        let Some((acc, mag)) = decoded else {
            return Err(row.error(format!("`image` = {text:?} is not {} hex digits", 2 * len)));
        };
        imu.t_ns.push(t_ns);
        imu.acc.push(acc);
        imu.mag.push(mag);
        Ok(())
    })?;
    Ok(imu)
}

#[cfg(test)]
mod tests {
    use super::*;
    use margemu_protocol::regmap::mpu6xxx::image::{ImageConfig, ImageRepr};
    use margemu_protocol::regmap::mpu6xxx::GyroFs;

    #[test]
    fn decode_inverts_the_image_conversion_to_within_one_lsb() {
        let image = ImageConfig {
            accel_fs: AccelFs::G8,
            gyro_fs: GyroFs::Dps2000,
            mag_bits: MagBits::Bits16,
            asa: [120, 128, 140],
            gyro_offset: [0; 3],
            accel_offset: [100, -64, 0],
            ..ImageConfig::NOMINAL
        };
        let meta = SessionMeta {
            start_host_ns: 0,
            chip: ChipSettings {
                model: ChipModel::Mpu9250,
                conversion: Conversion::Mpu6xxx(image),
            },
            mag_ut_per_unit: 50.0,
        };
        let acc = [1.5f32, -30.0, 9.0];
        let field_nu = [0.5f32, -0.1, -0.83];
        let image =
            ImageRepr::from_physical(acc, [0.0; 3], 25.0, field_nu.map(|b| b * 50.0), &image)
                .emit();
        let (a, m) = decode(&image, &meta).unwrap();
        for i in 0..3 {
            assert!((a[i] - f64::from(acc[i])).abs() < 9.81 / 4096.0, "{a:?}");
            assert!(
                (m[i] - f64::from(field_nu[i])).abs() < 0.15 * 1.1 / 50.0,
                "{m:?}"
            );
        }
    }

    #[test]
    fn a_bmi270_image_decodes_without_a_field() {
        let fs = margemu_protocol::chip::FullScale {
            accel_g: 16.0,
            gyro_dps: 2000.0,
        };
        let meta = SessionMeta {
            start_host_ns: 0,
            chip: ChipSettings::with_full_scale(ChipModel::Bmi270, fs).unwrap(),
            mag_ut_per_unit: 50.0,
        };
        let acc = [1.5f32, -30.0, 9.0];
        let sample = margemu_protocol::chip::PhysicalSample {
            acc,
            ..Default::default()
        };
        let image = meta.chip.image(&sample);
        assert_eq!(image.len(), 14);
        let (a, m) = decode(&image, &meta).unwrap();
        for i in 0..3 {
            assert!((a[i] - f64::from(acc[i])).abs() < 9.81 / 2048.0, "{a:?}");
        }
        assert!(m.iter().all(|b| b.is_nan()), "no magnetometer: {m:?}");
        assert_eq!(decode(&image[..13], &meta), None);
    }
}
