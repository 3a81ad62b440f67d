//! What a session directory says about the link: when scene time 0 was on the host's clock, and
//! what the device was sent (`sent.csv`, decoded back to physical units for the norm plots and
//! the magnetic phase).
//!
//! Scene time 0 is `start_host_ns` from `meta.toml` when present, otherwise from the `start`
//! row of `events.csv` (`detail` = `start_host_ns N; …`, as `margemu stream` writes it).
//!
//! Register images are decoded with the `[image]` settings of `meta.toml` (full scales, ASA,
//! offsets; the power-on defaults when absent) by inverting `margemu_protocol::regmap`'s
//! conversions: specific force in m/s², the field in the scene's unit (µT ÷ `mag_ut_per_unit`),
//! both in the MPU-9250's accel/gyro axes (the plate's axes: the chip is mounted with them). What
//! the chip clipped stays clipped: the plots show what the device under test was given.

use crate::csv_column::ColumnError;
use crate::csv_table::Table;
use margemu_protocol::link::IMAGE_LEN;
use margemu_protocol::regmap::ak8963::MagBits;
use margemu_protocol::regmap::mpu6xxx::convert::{asa_factor, STANDARD_GRAVITY};
use margemu_protocol::regmap::mpu6xxx::image::{ImageConfig, ImageRepr};
use margemu_protocol::regmap::mpu6xxx::AccelFs;
use serde::Deserialize;
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

#[derive(Deserialize, Default)]
struct MetaFile {
    start_host_ns: Option<i64>,
    mag_ut_per_unit: Option<f64>,
    image: Option<ImageMeta>,
}

#[derive(Deserialize)]
struct ImageMeta {
    accel_fs: String,
    mag_bits: String,
    asa: [u8; 3],
    accel_offset: [i16; 3],
}

/// What evaluation needs from a session's `meta.toml` and `events.csv`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SessionMeta {
    /// Host time (ns) of scene time 0.
    pub start_host_ns: i64,
    /// Register settings of the images sent.
    pub image: ImageConfig,
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
    let path = dir.join("meta.toml");
    let text = std::fs::read_to_string(&path).map_err(|e| bad(&path, e.to_string()))?;
    let meta: MetaFile = toml::from_str(&text).map_err(|e| bad(&path, e.to_string()))?;
    let start_host_ns = match meta.start_host_ns {
        Some(ns) => ns,
        None => start_from_events(&dir.join("events.csv"))?,
    };
    let mut image = ImageConfig::NOMINAL;
    if let Some(m) = meta.image {
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
        image,
        mag_ut_per_unit: meta.mag_ut_per_unit.unwrap_or(1.0),
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

/// Specific force (m/s²) and field (scene unit) of one register image.
pub fn decode(image: &[u8; IMAGE_LEN], meta: &SessionMeta) -> ([f64; 3], [f64; 3]) {
    let r = ImageRepr::parse(image);
    let cfg = &meta.image;
    let lsb_per_g = f64::from(cfg.accel_fs.lsb_per_g());
    let acc = core::array::from_fn(|i| {
        let offset = f64::from(cfg.accel_offset[i] & !1) * lsb_per_g / 2048.0;
        (f64::from(r.accel[i]) - offset) / lsb_per_g * f64::from(STANDARD_GRAVITY)
    });
    let ut = |i: usize| {
        f64::from(r.mag[i])
            * f64::from(cfg.mag_bits.ut_per_lsb())
            * f64::from(asa_factor(cfg.asa[i]))
    };
    // AK8963 axes back to the MPU-9250's: x = y_ak, y = x_ak, z = −z_ak.
    let mag = [ut(1), ut(0), -ut(2)].map(|b| b / meta.mag_ut_per_unit);
    (acc, mag)
}

/// `sent.csv` decoded: `(t_ns, specific force, field)` per row.
pub fn read_sent(path: &Path, meta: &SessionMeta) -> Result<super::input::Imu, ColumnError> {
    let table = Table::open(path)?;
    let [t, image] = table.columns(["t_ns", "image"])?;
    let mut imu = super::input::Imu::default();
    table.for_each(|row| {
        let t_ns: u64 = row.int(t)?;
        row.check_order(t, imu.t_ns.last().copied(), t_ns, true)?;
        let text = row.text(image);
        let mut bytes = [0u8; IMAGE_LEN];
        let ok = text.len() == 2 * IMAGE_LEN
            && bytes.iter_mut().enumerate().all(|(i, b)| {
                text.get(2 * i..2 * i + 2)
                    .and_then(|h| u8::from_str_radix(h, 16).ok())
                    .map(|v| *b = v)
                    .is_some()
            });
        if !ok {
            return Err(row.error(format!(
                "`image` = {text:?} is not {} hex digits",
                2 * IMAGE_LEN
            )));
        }
        let (acc, mag) = decode(&bytes, meta);
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
    use margemu_protocol::regmap::mpu6xxx::GyroFs;

    #[test]
    fn decode_inverts_the_image_conversion_to_within_one_lsb() {
        let meta = SessionMeta {
            start_host_ns: 0,
            image: ImageConfig {
                accel_fs: AccelFs::G8,
                gyro_fs: GyroFs::Dps2000,
                mag_bits: MagBits::Bits16,
                asa: [120, 128, 140],
                gyro_offset: [0; 3],
                accel_offset: [100, -64, 0],
            },
            mag_ut_per_unit: 50.0,
        };
        let acc = [1.5f32, -30.0, 9.0];
        let field_nu = [0.5f32, -0.1, -0.83];
        let image =
            ImageRepr::from_physical(acc, [0.0; 3], 25.0, field_nu.map(|b| b * 50.0), &meta.image)
                .emit();
        let (a, m) = decode(&image, &meta);
        for i in 0..3 {
            assert!((a[i] - f64::from(acc[i])).abs() < 9.81 / 4096.0, "{a:?}");
            assert!(
                (m[i] - f64::from(field_nu[i])).abs() < 0.15 * 1.1 / 50.0,
                "{m:?}"
            );
        }
    }
}
