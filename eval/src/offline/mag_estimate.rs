//! The world magnetic reference of an external CSV recording, estimated from its first rest
//! phase, for a filter run given none (`margemu filter REC.csv` without `--mag-reference`, or
//! with `--mag-reference auto`).
//!
//! The rest phase: the first run of consecutive rows whose gyro norm is below [`REST_RATE`] and
//! that lasts at least [`MIN_REST_S`] (and [`MIN_REST_SAMPLES`] rows); its first [`MAX_REST_S`]
//! are used (so a recording at rest throughout is not read to its end). Over them:
//! - with a reference attitude (`qw..qz`, body to world, filled on every row of the run): the
//!   mean of the measured field rotated into the world, `q ⊗ m ⊗ q*`, so both the dip and the
//!   horizontal direction are the recording's own;
//! - without one (or with gaps in it): the dip from the angle `α` between the mean specific
//!   force (up at rest) and the mean field, `dip = α − 90°`, and north along world +x: the
//!   reference `(sin α, 0, cos α)` (margemu's world is z up, see CONVENTIONS "Named world
//!   frames").
//!
//! Only the direction matters to the filters; the result is a unit vector.

use super::input::InputError;
use crate::frame::Frame;
use margemu_sim::csv_table::Table;
use nalgebra::{UnitQuaternion, Vector3};
use std::path::Path;

/// Gyro norm (rad/s) below which a row counts as at rest.
pub const REST_RATE: f64 = 0.1;
/// Shortest rest phase used (s).
pub const MIN_REST_S: f64 = 1.0;
/// Fewest rows in a rest phase used.
pub const MIN_REST_SAMPLES: usize = 10;
/// Longest stretch of a rest phase used (s).
pub const MAX_REST_S: f64 = 10.0;

/// An estimated world magnetic reference and where it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct MagEstimate {
    /// The reference, world frame, unit.
    pub reference: [f64; 3],
    /// Its dip below the horizontal (rad, positive down).
    pub dip: f64,
    /// First and last line of the rest phase in the file (1-based, the header is line 1).
    pub lines: (u64, u64),
    /// Its rows.
    pub rows: usize,
    /// Whether the reference attitude rotated the field into the world (else: dip only).
    pub from_attitude: bool,
}

impl std::fmt::Display for MagEstimate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [x, y, z] = self.reference;
        write!(
            f,
            "magnetic reference estimated: ({x:.4}, {y:.4}, {z:.4}), dip {:.2}°, from the rest phase at lines {}–{} ({} rows; {})",
            self.dip.to_degrees(),
            self.lines.0,
            self.lines.1,
            self.rows,
            if self.from_attitude {
                "field rotated into the world by the reference attitude"
            } else {
                "dip from the angle between gravity and the field, north along +x"
            }
        )
    }
}

/// Sums over one run of rest rows.
#[derive(Default)]
struct Run {
    first_line: u64,
    last_line: u64,
    first_t: f64,
    last_t: f64,
    rows: usize,
    acc: [f64; 3],
    mag: [f64; 3],
    world: [f64; 3],
    world_rows: usize,
}

impl Run {
    fn long_enough(&self) -> bool {
        self.rows >= MIN_REST_SAMPLES && self.last_t - self.first_t >= MIN_REST_S
    }
}

fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    (n > 1e-12 && n.is_finite()).then(|| v.map(|x| x / n))
}

fn add(sum: &mut [f64; 3], v: [f64; 3]) {
    for (s, x) in sum.iter_mut().zip(v) {
        *s += x;
    }
}

/// The estimate from the recording at `path` (see the module docs); reads it up to the end of
/// its first long enough rest phase.
pub fn estimate(path: &Path) -> Result<MagEstimate, InputError> {
    estimate_in(path, Frame::Nwu)
}

/// [`estimate`] for a recording in `frame` ([`crate::frame`]); the result is in NWU.
pub fn estimate_in(path: &Path, frame: Frame) -> Result<MagEstimate, InputError> {
    let mut table = Table::open(path)?;
    let t = table.column("t_s")?;
    let acc = table.columns(["ax", "ay", "az"])?;
    let gyr = table.columns(["gx", "gy", "gz"])?;
    let mag = table.columns(["mx", "my", "mz"])?;
    let q = ["qw", "qx", "qy", "qz"].map(|n| table.optional(n));
    let q = q
        .iter()
        .all(Option::is_some)
        .then(|| q.map(Option::unwrap_or_default));
    let mut run = Run::default();
    let mut found = None;
    while let Some(row) = table.next_row()? {
        let w = row.f64s(gyr)?;
        if w.iter().map(|x| x * x).sum::<f64>().sqrt() >= REST_RATE {
            if run.long_enough() {
                found = Some(std::mem::take(&mut run));
                break;
            }
            run = Run::default();
            continue;
        }
        let (time, a, m) = (row.f64(t)?, row.f64s(acc)?, row.f64s(mag)?);
        if run.rows > 0 && time - run.first_t > MAX_REST_S {
            found = Some(std::mem::take(&mut run));
            break;
        }
        if run.rows == 0 {
            run.first_line = row.line();
            run.first_t = time;
        }
        run.last_line = row.line();
        run.last_t = time;
        run.rows += 1;
        add(&mut run.acc, a);
        add(&mut run.mag, m);
        let attitude = match q {
            Some(cols) => cols
                .iter()
                .map(|&c| row.opt_f64(c).ok().flatten())
                .collect::<Option<Vec<f64>>>(),
            None => None,
        };
        if let Some(c) = attitude {
            let q =
                UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(c[0], c[1], c[2], c[3]));
            let v = q * Vector3::from(m);
            add(&mut run.world, [v.x, v.y, v.z]);
            run.world_rows += 1;
        }
    }
    let run = match found {
        Some(r) => r,
        None if run.long_enough() => run,
        None => {
            return Err(InputError::Bad {
                path: path.to_path_buf(),
                reason: format!(
                    "no rest phase to estimate the magnetic reference from (gyro norm below {REST_RATE} rad/s for {MIN_REST_S} s and {MIN_REST_SAMPLES} rows); pass --mag-reference X,Y,Z"
                ),
            })
        }
    };
    let bad = |what: &str| InputError::Bad {
        path: path.to_path_buf(),
        reason: format!(
            "the rest phase at lines {}–{} has {what}; pass --mag-reference X,Y,Z",
            run.first_line, run.last_line
        ),
    };
    let from_attitude = run.world_rows == run.rows;
    let reference = if from_attitude {
        unit(frame.world_in(run.world)).ok_or_else(|| bad("no magnetic field"))?
    } else {
        let up = unit(run.acc).ok_or_else(|| bad("no specific force"))?;
        let m = unit(run.mag).ok_or_else(|| bad("no magnetic field"))?;
        let cos = (0..3).map(|i| up[i] * m[i]).sum::<f64>().clamp(-1.0, 1.0);
        let sin = (1.0 - cos * cos).sqrt();
        [sin, 0.0, cos]
    };
    let horizontal = reference[0].hypot(reference[1]);
    Ok(MagEstimate {
        reference,
        dip: (-reference[2]).atan2(horizontal),
        lines: (run.first_line, run.last_line),
        rows: run.rows,
        from_attitude,
    })
}
