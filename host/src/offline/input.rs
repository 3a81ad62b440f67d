//! The recordings an offline filter run reads, as IMU samples on one time axis plus the world
//! magnetic reference to filter against.
//!
//! | input | read | magnetic reference |
//! |---|---|---|
//! | a `simulate` run directory | `marg.csv` (`t_ns`, `acc_*`, `gyr_*`, `mag_*`) | the scene's `[field] reference`, from `meta.toml`'s scene text |
//! | a CSV file (external recording) | `t_s,ax,ay,az,gx,gy,gz,mx,my,mz` (other columns ignored) | the caller's (default `(0.5, 0, −0.83)`) |
//!
//! Units: m/s², rad/s and any field unit (only directions are used). Times must increase
//! strictly; every value must be a finite number. Each failure names the file and, for a bad
//! row, its line and column.
//!
//! Session directories (`sent.csv`) are refused with a clear error for now: the evaluation's
//! decoder of `sent.csv` (`evaluate::device_log::read_sent`) recovers the accelerometer and
//! magnetometer only, not the gyroscope a filter needs.

use crate::csv_column::ColumnError;
use crate::evaluate::input::{read_truth, read_vectors, Imu};
use crate::scene::Scene;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The default world magnetic reference (the author's normalized field).
pub const DEFAULT_MAG_REFERENCE: [f64; 3] = margemu_filters::init::DEFAULT_MAG_REFERENCE;

/// IMU samples ready to filter.
#[derive(Clone, Debug, PartialEq)]
pub struct Recording {
    /// The samples (every vector filled, gyroscope included).
    pub imu: Imu,
    /// World-frame magnetic reference (any length; only its direction is used).
    pub mag_reference: [f64; 3],
    /// What was read, for messages.
    pub source: String,
}

/// A recording that could not be read.
#[derive(Debug, thiserror::Error, docsplay::Display)]
pub enum InputError {
    /// {0}
    Column(#[from] ColumnError),
    /// {path}: {reason}
    Bad {
        /// The file or directory.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// {path}:{line}: {reason}
    Row {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: u64,
        /// What is wrong.
        reason: String,
    },
}

fn bad(path: &Path, reason: impl Into<String>) -> InputError {
    InputError::Bad {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

/// Reads a run directory or an external CSV recording (see the module docs). `mag_reference`
/// replaces the reference a run directory's scene gives, and is the one an external recording
/// uses (default `(0.5, 0, −0.83)`).
pub fn read(path: &Path, mag_reference: Option<[f64; 3]>) -> Result<Recording, InputError> {
    if path.is_dir() {
        let marg = path.join("marg.csv");
        if marg.is_file() {
            return read_run(path, &marg, mag_reference);
        }
        if path.join("sent.csv").is_file() {
            return Err(bad(
                path,
                "a session directory: filtering sessions is not supported yet (sent.csv's \
                 images are decoded without the gyroscope); filter the simulate run of its \
                 scene instead",
            ));
        }
        return Err(bad(
            path,
            "no marg.csv here (expected a `simulate` run directory)",
        ));
    }
    if !path.exists() {
        return Err(bad(path, "no such file or directory"));
    }
    read_external(path, mag_reference.unwrap_or(DEFAULT_MAG_REFERENCE))
}

fn read_run(
    dir: &Path,
    marg: &Path,
    mag_reference: Option<[f64; 3]>,
) -> Result<Recording, InputError> {
    let (t_ns, [acc, gyr, mag]) = read_vectors(
        marg,
        [
            ["acc_x", "acc_y", "acc_z"],
            ["gyr_x", "gyr_y", "gyr_z"],
            ["mag_x", "mag_y", "mag_z"],
        ],
    )?;
    if t_ns.is_empty() {
        return Err(bad(marg, "no samples"));
    }
    let mag_reference = match mag_reference {
        Some(r) => r,
        None => scene_field(&dir.join("meta.toml"))?,
    };
    Ok(Recording {
        imu: Imu {
            t_ns,
            acc,
            gyr,
            mag,
        },
        mag_reference,
        source: marg.display().to_string(),
    })
}

/// The true attitude at the first sample of a run directory (`truth.csv`), to start a filter
/// there.
pub fn first_true_attitude(dir: &Path) -> Result<[f64; 4], InputError> {
    if !dir.is_dir() {
        return Err(bad(
            dir,
            "starting from the truth needs a run directory with truth.csv",
        ));
    }
    let truth = read_truth(&dir.join("truth.csv"))?;
    truth
        .attitude
        .first()
        .map(|s| s.1)
        .ok_or_else(|| bad(&dir.join("truth.csv"), "no samples"))
}

/// The `[field] reference` of the scene text in a run's `meta.toml`.
fn scene_field(meta: &Path) -> Result<[f64; 3], InputError> {
    #[derive(Deserialize)]
    struct Meta {
        scene_text: String,
    }
    let text = std::fs::read_to_string(meta)
        .map_err(|e| bad(meta, format!("cannot read ({e}); pass --mag-reference")))?;
    let m: Meta = toml::from_str(&text).map_err(|e| bad(meta, e.message().trim().to_owned()))?;
    let scene = Scene::parse_str(&m.scene_text, &meta.join("scene_text"))
        .map_err(|e| bad(meta, format!("its scene text is not a valid scene: {e}")))?;
    Ok(scene.spec.field.reference)
}

/// The columns of an external recording, in the order of [`Row`].
const COLUMNS: [&str; 10] = ["t_s", "ax", "ay", "az", "gx", "gy", "gz", "mx", "my", "mz"];

/// One row of an external recording.
#[derive(Deserialize)]
struct Row {
    t_s: f64,
    ax: f64,
    ay: f64,
    az: f64,
    gx: f64,
    gy: f64,
    gz: f64,
    mx: f64,
    my: f64,
    mz: f64,
}

fn read_external(path: &Path, mag_reference: [f64; 3]) -> Result<Recording, InputError> {
    let file = std::fs::File::open(path).map_err(|e| bad(path, format!("cannot read: {e}")))?;
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(std::io::BufReader::new(file));
    let read_err = |cause| ColumnError::Read {
        path: path.to_path_buf(),
        cause,
    };
    let header = reader.headers().map_err(read_err)?.clone();
    if let Some(missing) = COLUMNS.iter().find(|c| !header.iter().any(|h| h == **c)) {
        let found = header.iter().collect::<Vec<_>>().join(", ");
        return Err(bad(
            path,
            format!("no column `{missing}` in the header (columns: {found})"),
        ));
    }
    let mut imu = Imu::default();
    let mut record = csv::StringRecord::new();
    while reader.read_record(&mut record).map_err(read_err)? {
        let line = record.position().map_or(0, |p| p.line());
        let at = |reason: String| InputError::Row {
            path: path.to_path_buf(),
            line,
            reason,
        };
        let row: Row = record.deserialize(Some(&header)).map_err(|e| {
            at(match e.kind() {
                csv::ErrorKind::Deserialize { err, .. } => {
                    let column = err
                        .field()
                        .and_then(|i| header.get(i as usize))
                        .map_or(String::new(), |c| format!("`{c}`: "));
                    format!("{column}{}", err.kind())
                }
                other => format!("{other:?}"),
            })
        })?;
        let values = [
            row.t_s, row.ax, row.ay, row.az, row.gx, row.gy, row.gz, row.mx, row.my, row.mz,
        ];
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            let name = COLUMNS[i];
            return Err(at(format!("`{name}` = {} is not finite", values[i])));
        }
        if !(0.0..1.8e10).contains(&row.t_s) {
            return Err(at(format!("`t_s` = {} is outside 0 to 1.8e10 s", row.t_s)));
        }
        let t_ns = (row.t_s * 1e9).round() as u64;
        if let Some(&last) = imu.t_ns.last() {
            if t_ns <= last {
                return Err(at(format!(
                    "`t_s` = {} does not increase (previous row: {})",
                    row.t_s,
                    last as f64 * 1e-9
                )));
            }
        }
        imu.t_ns.push(t_ns);
        imu.acc.push([row.ax, row.ay, row.az]);
        imu.gyr.push([row.gx, row.gy, row.gz]);
        imu.mag.push([row.mx, row.my, row.mz]);
    }
    if imu.t_ns.is_empty() {
        return Err(bad(path, "no samples"));
    }
    Ok(Recording {
        imu,
        mag_reference,
        source: path.display().to_string(),
    })
}
