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

use crate::evaluate::input::{read_first_attitude, seconds, Imu, VectorRows};
use margemu_sim::csv_column::ColumnError;
use margemu_sim::scene::Scene;
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

/// One IMU sample: instant (ns), specific force, angular rate, field.
pub type Sample = (u64, [f64; 3], [f64; 3], [f64; 3]);

/// A recording being read one sample at a time (see the module docs): memory does not grow with
/// its length.
pub struct Samples {
    rows: Rows,
    /// World-frame magnetic reference (any length; only its direction is used).
    pub mag_reference: [f64; 3],
    /// What is read, for messages.
    pub source: String,
}

enum Rows {
    Run(VectorRows<3>),
    External(External),
}

/// Opens a run directory or an external CSV recording (see the module docs) and checks that it
/// has a first sample. `mag_reference` replaces the reference a run directory's scene gives,
/// and is the one an external recording uses (default `(0.5, 0, −0.83)`).
pub fn open(path: &Path, mag_reference: Option<[f64; 3]>) -> Result<Samples, InputError> {
    let (rows, reference, source) = if path.is_dir() {
        let marg = path.join("marg.csv");
        if !marg.is_file() {
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
        // A run that was killed, interrupted or failed is not filtered as if it were whole.
        match margemu_sim::rundir::check_complete(path, false) {
            Ok(_) => {}
            Err(margemu_sim::rundir::RunDirError::Incomplete { why, .. }) => {
                return Err(bad(path, format!("holds an incomplete run: {why}")));
            }
            Err(e) => return Err(bad(path, e.to_string())),
        }
        let rows = VectorRows::open(
            &marg,
            [
                ["acc_x", "acc_y", "acc_z"],
                ["gyr_x", "gyr_y", "gyr_z"],
                ["mag_x", "mag_y", "mag_z"],
            ],
        )?;
        let reference = match mag_reference {
            Some(r) => r,
            None => scene_field(path)?,
        };
        (Rows::Run(rows), reference, marg)
    } else if !path.exists() {
        return Err(bad(path, "no such file or directory"));
    } else {
        let reference = mag_reference.unwrap_or(DEFAULT_MAG_REFERENCE);
        (
            Rows::External(External::open(path)?),
            reference,
            path.to_path_buf(),
        )
    };
    Ok(Samples {
        rows,
        mag_reference: reference,
        source: source.display().to_string(),
    })
}

impl Samples {
    /// The next sample, or `None` at the end.
    pub fn next_sample(&mut self) -> Result<Option<Sample>, InputError> {
        match &mut self.rows {
            Rows::Run(rows) => Ok(rows.next()?.map(|(t, [a, g, m])| (t, a, g, m))),
            Rows::External(rows) => rows.next(),
        }
    }

    /// The first sample: an error when there is none.
    pub fn first_sample(&mut self) -> Result<Sample, InputError> {
        self.next_sample()?
            .ok_or_else(|| bad(Path::new(&self.source), "no samples"))
    }
}

/// Reads a run directory or an external CSV recording into memory (see [`open`]).
pub fn read(path: &Path, mag_reference: Option<[f64; 3]>) -> Result<Recording, InputError> {
    let mut samples = open(path, mag_reference)?;
    let mut imu = Imu::default();
    let mut next = Some(samples.first_sample()?);
    while let Some((t, a, g, m)) = next {
        imu.t_ns.push(t);
        imu.acc.push(a);
        imu.gyr.push(g);
        imu.mag.push(m);
        next = samples.next_sample()?;
    }
    Ok(Recording {
        imu,
        mag_reference: samples.mag_reference,
        source: samples.source,
    })
}

/// The true attitude at the first sample, to start a filter there: of a run directory, the
/// first row of its `truth.csv`; of a CSV recording, the reference quaternion `qw..qz` of its
/// first row (which must have one: the filter starts at that sample).
pub fn first_true_attitude(input: &Path) -> Result<[f64; 4], InputError> {
    first_true_attitude_in(input, crate::frame::Frame::Nwu)
}

/// [`first_true_attitude`] of a CSV recording in `frame` ([`crate::frame`]), in NWU (a run
/// directory is margemu's own).
pub fn first_true_attitude_in(
    input: &Path,
    frame: crate::frame::Frame,
) -> Result<[f64; 4], InputError> {
    if input.is_file() {
        return first_reference(input).map(|q| frame.quat_in(q));
    }
    if !input.is_dir() {
        return Err(bad(
            input,
            "starting from the truth needs a run directory with truth.csv, or a CSV recording with qw,qx,qy,qz",
        ));
    }
    let path = input.join("truth.csv");
    read_first_attitude(&path)?
        .map(|s| s.1)
        .ok_or_else(|| bad(&path, "no samples"))
}

/// The reference quaternion of the first row of the CSV recording at `path`, normalised.
fn first_reference(path: &Path) -> Result<[f64; 4], InputError> {
    let mut table = margemu_sim::csv_table::Table::open(path)?;
    let q = ["qw", "qx", "qy", "qz"].map(|n| table.optional(n));
    let Some(cols) = q
        .iter()
        .all(Option::is_some)
        .then(|| q.map(Option::unwrap_or_default))
    else {
        return Err(bad(
            path,
            "starting from the truth needs the reference columns qw,qx,qy,qz (this recording has none)",
        ));
    };
    let Some(row) = table.next_row()? else {
        return Err(bad(path, "no samples"));
    };
    let mut raw = [0.0; 4];
    for (r, c) in raw.iter_mut().zip(cols) {
        *r = row.opt_f64(c)?.ok_or_else(|| {
            row.error("the first row has no reference quaternion to start from (empty); start from first-sample".into())
        })?;
    }
    let n = raw.iter().map(|x| x * x).sum::<f64>().sqrt();
    if n < 1e-9 {
        return Err(row
            .error(format!("quaternion {raw:?} has no direction (zero norm)"))
            .into());
    }
    Ok(raw.map(|x| x / n))
}

/// The `[field] reference` of the scene text in the `meta.toml` of the run in `dir`.
fn scene_field(dir: &Path) -> Result<[f64; 3], InputError> {
    let file = margemu_sim::meta::read(dir)
        .map_err(|e| bad(&e.path, format!("{}; pass --mag-reference", e.reason)))?;
    let meta = dir.join(margemu_sim::rundir::META_FILE);
    let text = file.scene_text().ok_or_else(|| {
        bad(
            &meta,
            "not written by margemu: it has no scene text; pass --mag-reference",
        )
    })?;
    let scene = Scene::parse_str(text, &meta.join("scene_text"))
        .map_err(|e| bad(&meta, format!("its scene text is not a valid scene: {e}")))?;
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

/// An external recording being read.
struct External {
    path: PathBuf,
    reader: csv::Reader<margemu_sim::input_file::LineBounded<std::fs::File>>,
    header: csv::StringRecord,
    record: csv::StringRecord,
    last: Option<u64>,
}

impl External {
    fn open(path: &Path) -> Result<Self, InputError> {
        let file = margemu_sim::input_file::open_stream(path).map_err(ColumnError::Input)?;
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_reader(file);
        let header = reader
            .headers()
            .map_err(|cause| ColumnError::Read {
                path: path.to_path_buf(),
                cause,
            })?
            .clone();
        if let Some(missing) = COLUMNS.iter().find(|c| !header.iter().any(|h| h == **c)) {
            let found = header.iter().collect::<Vec<_>>().join(", ");
            return Err(bad(
                path,
                format!("no column `{missing}` in the header (columns: {found})"),
            ));
        }
        Ok(Self {
            path: path.to_path_buf(),
            reader,
            header,
            record: csv::StringRecord::new(),
            last: None,
        })
    }

    fn next(&mut self) -> Result<Option<Sample>, InputError> {
        let path = &self.path;
        let more =
            self.reader
                .read_record(&mut self.record)
                .map_err(|cause| ColumnError::Read {
                    path: path.clone(),
                    cause,
                })?;
        if !more {
            return Ok(None);
        }
        let line = self.record.position().map_or(0, |p| p.line());
        let at = |reason: String| InputError::Row {
            path: path.clone(),
            line,
            reason,
        };
        let header = &self.header;
        let row: Row = self.record.deserialize(Some(header)).map_err(|e| {
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
        if let Some(last) = self.last {
            if t_ns <= last {
                return Err(at(format!(
                    "`t_s` = {} does not increase (previous row: {})",
                    row.t_s,
                    seconds(last)
                )));
            }
        }
        self.last = Some(t_ns);
        Ok(Some((
            t_ns,
            [row.ax, row.ay, row.az],
            [row.gx, row.gy, row.gz],
            [row.mx, row.my, row.mz],
        )))
    }
}
