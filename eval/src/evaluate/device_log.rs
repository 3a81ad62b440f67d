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
//!
//! **A rig** (`[[other_devices]]`, one `image.NAME` column per device in `sent.csv`) is read as
//! a flight controller reads it: the specific force from device 0 (the IMU, the first `image.`
//! column), the field from the rig's external compass, its first device whose model is a
//! magnetometer alone ([`ExternalCompass`]: its column `image.NAME`, its model and range from
//! its `[[other_devices]]` table), turned from the compass's axes into device 0's with both
//! devices' `rotation`s (`v_0 = R_0 · R_cᵀ · v_c`,
//! [`axes_between`]). A rig without such a compass
//! keeps device 0's own magnetometer, as a single chip does.

use margemu_protocol::chip::{ChipModel, ChipSettings, Conversion, FullScale, Image};
use margemu_protocol::regmap::ak8963::MagBits;
use margemu_protocol::regmap::mpu6xxx::AccelFs;
use margemu_sim::csv_column::ColumnError;
use margemu_sim::csv_table::Table;
use margemu_sim::meta::{ChipMeta, ForeignMeta, MetaFile};
use margemu_sim::scene::chip::{axes_between, rotate, Rotation};
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
#[derive(Clone, Debug, PartialEq)]
pub struct SessionMeta {
    /// Host time (ns) of scene time 0.
    pub start_host_ns: i64,
    /// The chip and the register settings of the images sent (a rig's device 0).
    pub chip: ChipSettings,
    /// µT per unit of the scene's field.
    pub mag_ut_per_unit: f64,
    /// A rig's external compass, whose field replaces device 0's own.
    pub compass: Option<ExternalCompass>,
}

/// A rig's external compass, as `sent.csv` carries it (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct ExternalCompass {
    /// Its column in `sent.csv`: `image.NAME`.
    pub column: String,
    /// Its model and range.
    pub settings: ChipSettings,
    /// Compass axes → device 0's axes.
    pub to_primary: Rotation,
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
        Some(c) => settings(&path, "[chip]", c)?,
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
    let compass = match meta {
        Some(m) => external_compass(&path, m)?,
        None => None,
    };
    Ok(SessionMeta {
        start_host_ns,
        chip,
        mag_ut_per_unit: meta.map_or(1.0, |m| m.mag_ut_per_unit),
        compass,
    })
}

/// The conversion settings of a chip's table (`table` names it in errors).
fn settings(path: &Path, table: &str, c: &ChipMeta) -> Result<ChipSettings, SessionFileError> {
    let model = ChipModel::from_name(&c.model)
        .ok_or_else(|| bad(path, format!("{table} model = {:?} is no chip", c.model)))?;
    let settings = match (c.accel_range_g, c.gyro_range_dps) {
        (Some(accel_g), Some(gyro_dps)) => {
            let fs = FullScale { accel_g, gyro_dps };
            ChipSettings::with_full_scale(model, fs)
                .map_err(|e| bad(path, format!("{table}: {e:?}")))?
        }
        (None, None) => ChipSettings::power_on(model),
        _ => {
            let reason =
                format!("{table} has one of accel_range_g and gyro_range_dps without the other");
            return Err(bad(path, reason));
        }
    };
    match c.mag_range_gauss {
        None => Ok(settings),
        Some(gauss) => settings.with_mag_range(gauss).map_err(|_| {
            let reason = format!(
                "{table} mag_range_gauss = {gauss} is no range of the {}",
                model.part_name()
            );
            bad(path, reason)
        }),
    }
}

/// The first magnetometer-only device among `[[other_devices]]`, if any.
fn external_compass(
    path: &Path,
    meta: &margemu_sim::meta::SessionMeta,
) -> Result<Option<ExternalCompass>, SessionFileError> {
    let found =
        meta.other_devices.iter().enumerate().find(|(_, d)| {
            ChipModel::from_name(&d.model).is_some_and(ChipModel::is_magnetometer_only)
        });
    let Some((i, device)) = found else {
        return Ok(None);
    };
    let table = format!("[[other_devices]] {}", i + 1);
    let name = device.name.as_deref().ok_or_else(|| {
        bad(
            path,
            format!("{table} has no name: its images' column in sent.csv is `image.NAME`"),
        )
    })?;
    Ok(Some(ExternalCompass {
        column: format!("image.{name}"),
        settings: settings(path, &table, device)?,
        to_primary: axes_between(device.rotation, meta.chip.rotation),
    }))
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

/// The field (scene unit, device 0's axes) of one image of a rig's external compass; `None` if
/// it is not of the compass's length.
pub fn decode_compass(
    image: &[u8],
    meta: &SessionMeta,
    compass: &ExternalCompass,
) -> Option<[f64; 3]> {
    let ut = compass.settings.decode(image)?.mag_ut?;
    Some(rotate(&compass.to_primary, ut).map(|b| b / meta.mag_ut_per_unit))
}

/// The image of `len` bytes in column `i` of `row`, or the error naming the column.
fn image_at(
    row: &margemu_sim::csv_table::Row<'_>,
    i: usize,
    len: usize,
) -> Result<Image, ColumnError> {
    let text = row.text(i);
    Image::parse_hex(text, len).ok_or_else(|| {
        row.error(format!(
            "`{}` = {text:?} is not {} hex digits",
            row.name(i),
            2 * len
        ))
    })
}

/// `sent.csv` decoded: `(t_ns, specific force, field)` per row. A rig's session has one
/// `image.NAME` column per device: device 0's (the first) gives the specific force, and the
/// field too unless the rig has an external compass ([`SessionMeta::compass`]), whose column
/// gives it (see the module docs).
pub fn read_sent(path: &Path, meta: &SessionMeta) -> Result<super::input::Imu, ColumnError> {
    let table = Table::open(path)?;
    let t = table.column("t_ns")?;
    let image = match table.first_with_prefix("image.") {
        Some(column) if table.optional("image").is_none() => column,
        _ => table.column("image")?,
    };
    let compass = match &meta.compass {
        Some(c) => Some((table.column(&c.column)?, c)),
        None => None,
    };
    let mut imu = super::input::Imu::default();
    table.for_each(|row| {
        let t_ns: u64 = row.int(t)?;
        row.check_order(t, imu.t_ns.last().copied(), t_ns, true)?;
        let len = meta.chip.model.image_len();
        let bytes = image_at(row, image, len)?;
        let Some((acc, own)) = decode(bytes.as_bytes(), meta) else {
            return Err(row.error(format!(
                "`{}` is not a {} image",
                row.name(image),
                meta.chip.model.part_name()
            )));
        };
        let mag = match compass {
            None => own,
            Some((i, c)) => {
                let bytes = image_at(row, i, c.settings.model.image_len())?;
                decode_compass(bytes.as_bytes(), meta, c).ok_or_else(|| {
                    row.error(format!(
                        "`{}` is not a {} image",
                        row.name(i),
                        c.settings.model.part_name()
                    ))
                })?
            }
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
    use margemu_protocol::chip::PhysicalSample;
    use margemu_protocol::regmap::mag_image;
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
            compass: None,
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
            compass: None,
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

    /// An ICM-42688-P turned a quarter about z and an IST8310 upside down, 50 µT per unit.
    fn rig_meta() -> SessionMeta {
        let flipped = [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]];
        let quarter = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        SessionMeta {
            start_host_ns: 0,
            chip: ChipSettings::power_on(ChipModel::Icm42688p),
            mag_ut_per_unit: 50.0,
            compass: Some(ExternalCompass {
                column: "image.compass".into(),
                settings: ChipSettings::power_on(ChipModel::Ist8310),
                to_primary: axes_between(Some(flipped), Some(quarter)),
            }),
        }
    }

    fn hex(bytes: &[u8]) -> String {
        bytes.iter().map(|b| format!("{b:02x}")).collect()
    }

    /// A `sent.csv` of a rig with `rows` of `(t_ns, imu image, compass image text)`.
    fn sent(name: &str, rows: &[(u64, String, String)]) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("margemu-devlog-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut text = String::from("index,t_ns,send_ns,late_ns,image.imu,image.compass,resend\n");
        for (k, (t, imu, compass)) in rows.iter().enumerate() {
            text += &format!("{k},{t},0,0,{imu},{compass},0\n");
        }
        let path = dir.join("sent.csv");
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn a_rigs_field_comes_from_its_compass_in_device_0s_axes() {
        let meta = rig_meta();
        let imu = ChipSettings::power_on(ChipModel::Icm42688p);
        let level = PhysicalSample {
            acc: [0.0, 0.0, 9.80665],
            ..PhysicalSample::default()
        };
        // The plate field (0.5, 0, −0.83) nu reads (25, 0, 41.5) µT on the flipped compass:
        // 83, 0, 138 counts at 0.3 µT/LSB.
        let compass = hex(&mag_image::emit([83, 0, 138]));
        let rows = [(0, hex(imu.image(&level).as_bytes()), compass.clone())];
        let imu_data = read_sent(&sent("rig", &rows), &meta).unwrap();
        let [m] = imu_data.mag[..] else { panic!() };
        // In the IMU's axes (a quarter turn about z): (0, −0.5, −0.83), within 0.15 µT.
        let want = [0.0, -0.5, -0.83];
        for i in 0..3 {
            assert!((m[i] - want[i]).abs() < 0.15 / 50.0, "{m:?}");
        }
        assert!(
            (imu_data.acc[0][2] - 9.80665).abs() < 1e-2,
            "{:?}",
            imu_data.acc
        );
    }

    #[test]
    fn a_bad_compass_image_is_located_at_its_row_and_column() {
        let meta = rig_meta();
        let imu = hex(ChipSettings::power_on(ChipModel::Icm42688p)
            .image(&PhysicalSample::default())
            .as_bytes());
        let rows = [
            (0, imu.clone(), "000000000000".to_string()),
            (1_000_000, imu, "0000zz".to_string()),
        ];
        let path = sent("bad", &rows);
        let e = read_sent(&path, &meta).unwrap_err().to_string();
        assert_eq!(
            e,
            format!(
                "{}:3: `image.compass` = \"0000zz\" is not 12 hex digits",
                path.display()
            )
        );
        // A compass whose column is not there.
        let meta = SessionMeta {
            compass: rig_meta().compass.map(|c| ExternalCompass {
                column: "image.mag".into(),
                ..c
            }),
            ..rig_meta()
        };
        let e = read_sent(&path, &meta).unwrap_err().to_string();
        assert!(e.contains("image.mag"), "{e}");
    }
}
