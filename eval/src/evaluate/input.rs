//! The CSV files evaluation reads, parsed into plain vectors; every bad value is located
//! (file, line, column) and every time column is checked for order.
//!
//! | file | columns used | time |
//! |---|---|---|
//! | `truth.csv` | `t_ns`, `qw..qz`, `wx..wz`, `fx..fz`, `ax_b..az_b`, `mx..mz` | ns, strictly increasing |
//! | `dut_attitude.csv` | `host_ns,protocol,message,device_time_us,roll,pitch,yaw,qw,qx,qy,qz` | host ns, not decreasing |
//! | estimates | `t_s,qw,qx,qy,qz` | s from the scene start, strictly increasing |
//! | external recording | `t_s,ax,ay,az,gx,gy,gz,mx,my,mz,qw,qx,qy,qz`, optional `qw_est,qx_est,qy_est,qz_est` | s, strictly increasing |
//! | `perturbation.csv` | `t_ns,mag_x,mag_y,mag_z` | ns |
//! | `marg.csv` | `t_ns,acc_x..acc_z,mag_x..mag_z` | ns |
//!
//! Quaternions are normalised; a zero or non-finite one is an error at its line, except in
//! `dut_attitude.csv`, where such a row (a device's fault) is skipped and counted, and the
//! reference of an external recording, where a row whose `qw..qz` are all empty or hold a `NaN`
//! (public recordings mark the instants the optical reference lost the body so) keeps its IMU
//! sample but has no reference: it is skipped in scoring and counted. An external recording may
//! name a mask column (any finite number; nonzero: the row is scored).

use super::quat::{normalize, Quat};
use super::score::Stamped;
use margemu_sim::csv_column::ColumnError;
use margemu_sim::csv_table::{Row, Table};
use std::path::Path;

/// The truth of a run (`truth.csv`), column groups in order of samples.
#[derive(Clone, Debug, Default)]
pub struct TruthRun {
    /// Instants and attitudes.
    pub attitude: Vec<Stamped>,
    /// Body rate (rad/s).
    pub rate: Vec<[f64; 3]>,
    /// Specific force, body frame (m/s²).
    pub specific_force: Vec<[f64; 3]>,
    /// External acceleration, body frame (m/s²).
    pub accel: Vec<[f64; 3]>,
    /// True magnetic field, body frame (scene unit).
    pub field: Vec<[f64; 3]>,
}

/// Accelerometer, gyroscope and magnetometer samples.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Imu {
    /// Instants (ns).
    pub t_ns: Vec<u64>,
    /// Specific force (m/s²).
    pub acc: Vec<[f64; 3]>,
    /// Angular rate (rad/s); empty when the source has none.
    pub gyr: Vec<[f64; 3]>,
    /// Magnetic field (the source's unit).
    pub mag: Vec<[f64; 3]>,
}

/// One row of `dut_attitude.csv`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DutRow {
    /// Line in the file.
    pub line: u64,
    /// Its message stream: the index in [`DutAttitude::messages`].
    pub stream: usize,
    /// Host arrival time (ns, the session's monotonic clock).
    pub host_ns: i64,
    /// The device's own time stamp (µs), when it sent one.
    pub device_time_us: Option<f64>,
    /// The Euler columns `[roll, pitch, yaw]` (rad).
    pub euler: [f64; 3],
    /// The quaternion, normalised.
    pub q: Quat,
}

/// `dut_attitude.csv`: its rows with a usable quaternion, and what else was there.
#[derive(Clone, Debug, Default)]
pub struct DutAttitude {
    /// Rows with a usable quaternion, in file order.
    pub rows: Vec<DutRow>,
    /// Message streams: rows per `protocol/message`, in order of first appearance.
    pub messages: Vec<(String, usize)>,
    /// The `message` column of each stream.
    pub message_names: Vec<String>,
    /// The stream of each row whose quaternion is unusable (zero, near zero or not finite: a
    /// device's fault, skipped and counted rather than refused).
    pub unusable: Vec<usize>,
}

/// Message names by how exactly they carry an attitude, best first: a quaternion as the device
/// computed it, then float Euler angles, then Euler angles in 0.1°.
pub const MESSAGE_PREFERENCE: [&str; 3] = ["ATTITUDE_QUATERNION", "ATTITUDE", "MSP_ATTITUDE"];

impl DutAttitude {
    /// The streams whose `message` is `message`.
    pub fn streams_of(&self, message: &str) -> Vec<usize> {
        (0..self.message_names.len())
            .filter(|&i| self.message_names[i] == message)
            .collect()
    }

    /// The one stream to score when none is chosen: a device sends one sample's attitude in
    /// several messages (MAVLink's ATTITUDE and ATTITUDE_QUATERNION with one time stamp), and
    /// scoring them together would count each sample twice. Of the streams with usable rows
    /// (of all, when none has any), the one whose message comes first in
    /// [`MESSAGE_PREFERENCE`] (others after), then the one with most usable rows.
    pub fn preferred_stream(&self) -> Option<usize> {
        let usable = |i: usize| self.rows.iter().filter(|r| r.stream == i).count();
        let rank = |i: usize| {
            MESSAGE_PREFERENCE
                .iter()
                .position(|m| *m == self.message_names[i])
                .unwrap_or(MESSAGE_PREFERENCE.len())
        };
        (0..self.messages.len()).min_by_key(|&i| {
            let n = usable(i);
            (n == 0, rank(i), std::cmp::Reverse(n), i)
        })
    }
}

/// An external recording: IMU samples, the reference attitude and, optionally, an estimate.
#[derive(Clone, Debug, Default)]
pub struct External {
    /// The IMU columns, every row.
    pub imu: Imu,
    /// The reference quaternion of each row that has one.
    pub reference: Vec<Stamped>,
    /// The row (index into `imu`) of each `reference` sample.
    pub reference_rows: Vec<usize>,
    /// Rows without a reference (`qw..qz` empty or `NaN`), skipped.
    pub missing_reference: usize,
    /// The mask column per row (`true`: nonzero, scored), when one was named.
    pub mask: Option<Vec<bool>>,
    /// `qw_est..qz_est` per row where they are filled; `None` without those columns.
    pub estimate: Option<Vec<Stamped>>,
}

/// `q` normalised, or an error at `row` when it has no direction.
pub(super) fn unit(row: &Row<'_>, q: Quat) -> Result<Quat, ColumnError> {
    let u = normalize(q)
        .ok_or_else(|| row.error(format!("quaternion {q:?} has no direction (zero norm)")))?;
    let c = u.into_inner();
    Ok([c.w, c.i, c.j, c.k])
}

/// Column `col` (seconds) as integer nanoseconds.
pub(super) fn seconds_to_ns(row: &Row<'_>, col: usize) -> Result<u64, ColumnError> {
    let t = row.f64(col)?;
    if t < 0.0 || t * 1e9 >= u64::MAX as f64 {
        return Err(row.error(format!("`t_s` = {t} is outside 0 to 1.8e10 s")));
    }
    Ok((t * 1e9).round() as u64)
}

/// Integer nanoseconds as seconds, for messages about a seconds column (`0.01`).
pub fn seconds(ns: u64) -> f64 {
    ns as f64 / 1e9
}

/// An error unless `t_ns`, read from the seconds column `col`, is after `previous_ns`; the
/// message gives both in seconds, as the column has them.
pub(super) fn check_seconds_order(
    row: &Row<'_>,
    col: usize,
    previous_ns: Option<u64>,
    t_ns: u64,
) -> Result<(), ColumnError> {
    match previous_ns {
        Some(p) if t_ns <= p => Err(row.error(format!(
            "`{}` = {} does not increase (previous row: {})",
            row.name(col),
            seconds(t_ns),
            seconds(p)
        ))),
        _ => Ok(()),
    }
}

/// Reads `truth.csv` as `simulate`, `stream` and `loopback` write it.
pub fn read_truth(path: &Path) -> Result<TruthRun, ColumnError> {
    let table = Table::open(path)?;
    let t = table.column("t_ns")?;
    let q = table.columns(["qw", "qx", "qy", "qz"])?;
    let w = table.columns(["wx", "wy", "wz"])?;
    let f = table.columns(["fx", "fy", "fz"])?;
    let a = table.columns(["ax_b", "ay_b", "az_b"])?;
    let m = table.columns(["mx", "my", "mz"])?;
    let mut run = TruthRun::default();
    table.for_each(|row| {
        let t_ns: u64 = row.int(t)?;
        row.check_order(t, run.attitude.last().map(|s| s.0), t_ns, true)?;
        run.attitude.push((t_ns, unit(row, row.f64s(q)?)?));
        run.rate.push(row.f64s(w)?);
        run.specific_force.push(row.f64s(f)?);
        run.accel.push(row.f64s(a)?);
        run.field.push(row.f64s(m)?);
        Ok(())
    })?;
    Ok(run)
}

/// Reads `dut_attitude.csv`: every row with a usable quaternion, the others counted.
pub fn read_dut_attitude(path: &Path) -> Result<DutAttitude, ColumnError> {
    let table = Table::open(path)?;
    let [host, protocol, msg, device] =
        table.columns(["host_ns", "protocol", "message", "device_time_us"])?;
    let e = table.columns(["roll", "pitch", "yaw"])?;
    let q = table.columns(["qw", "qx", "qy", "qz"])?;
    let mut out = DutAttitude::default();
    let mut last_host = None;
    table.for_each(|row| {
        let host_ns: i64 = row.int(host)?;
        row.check_order(host, last_host, host_ns, false)?;
        last_host = Some(host_ns);
        let name = format!("{}/{}", row.text(protocol), row.text(msg));
        let stream = match out.messages.iter().position(|m| m.0 == name) {
            Some(i) => i,
            None => {
                out.messages.push((name, 0));
                out.message_names.push(row.text(msg).to_owned());
                out.messages.len() - 1
            }
        };
        out.messages[stream].1 += 1;
        let mut raw = [0.0; 4];
        for (r, &col) in raw.iter_mut().zip(&q) {
            *r = row.any_f64(col)?;
        }
        let Some(unit) = normalize(raw) else {
            out.unusable.push(stream);
            return Ok(());
        };
        let c = unit.into_inner();
        out.rows.push(DutRow {
            line: row.line(),
            stream,
            host_ns,
            device_time_us: row.opt_f64(device)?,
            euler: row.f64s(e)?,
            q: [c.w, c.i, c.j, c.k],
        });
        Ok(())
    })?;
    Ok(out)
}

/// Reads an estimates file `t_s,qw,qx,qy,qz` (time from the scene start).
pub fn read_estimates(path: &Path) -> Result<Vec<Stamped>, ColumnError> {
    let table = Table::open(path)?;
    let t = table.column("t_s")?;
    let q = table.columns(["qw", "qx", "qy", "qz"])?;
    let mut out: Vec<Stamped> = Vec::new();
    table.for_each(|row| {
        let t_ns = seconds_to_ns(row, t)?;
        check_seconds_order(row, t, out.last().map(|s| s.0), t_ns)?;
        out.push((t_ns, unit(row, row.f64s(q)?)?));
        Ok(())
    })?;
    Ok(out)
}

/// Reads an external recording (see the module docs).
pub fn read_external(path: &Path) -> Result<External, ColumnError> {
    read_external_masked(path, None)
}

/// The reference quaternion of a recording's row: `None` when its cells are all empty or one
/// is `NaN`; an error when partly empty, infinite, not a number or of zero norm.
pub(super) fn reference_of(row: &Row<'_>, cols: [usize; 4]) -> Result<Option<Quat>, ColumnError> {
    let empty = cols.iter().filter(|&&c| row.text(c).is_empty()).count();
    if empty == 4 {
        return Ok(None);
    }
    if empty > 0 {
        return Err(row.error("qw..qz are partly empty".into()));
    }
    let mut raw = [0.0; 4];
    for (r, &c) in raw.iter_mut().zip(&cols) {
        *r = row.any_f64(c)?;
        if r.is_nan() {
            return Ok(None);
        }
        if r.is_infinite() {
            return Err(row.error(format!("`{}` = {} is not finite", row.name(c), *r)));
        }
    }
    unit(row, raw).map(Some)
}

/// Reads an external recording with the mask column `mask_column` when given (see the module
/// docs).
pub fn read_external_masked(
    path: &Path,
    mask_column: Option<&str>,
) -> Result<External, ColumnError> {
    read_external_rows(path, mask_column, true)
}

/// [`read_external_masked`]; without `attitudes`, the reference quaternions are checked but
/// not kept (`reference` stays empty, `reference_rows` is filled) and the estimate columns are
/// not read, for a reader that streams them from the file.
pub(super) fn read_external_rows(
    path: &Path,
    mask_column: Option<&str>,
    attitudes: bool,
) -> Result<External, ColumnError> {
    let table = Table::open(path)?;
    let t = table.column("t_s")?;
    let acc = table.columns(["ax", "ay", "az"])?;
    let gyr = table.columns(["gx", "gy", "gz"])?;
    let mag = table.columns(["mx", "my", "mz"])?;
    let q = table.columns(["qw", "qx", "qy", "qz"])?;
    let mask = mask_column.map(|m| table.column(m)).transpose()?;
    let est_names = ["qw_est", "qx_est", "qy_est", "qz_est"];
    let est = if attitudes && est_names.iter().any(|n| table.optional(n).is_some()) {
        Some(table.columns(est_names)?)
    } else {
        None
    };
    let mut out = External {
        estimate: est.map(|_| Vec::new()),
        mask: mask.map(|_| Vec::new()),
        ..External::default()
    };
    table.for_each(|row| {
        let t_ns = seconds_to_ns(row, t)?;
        check_seconds_order(row, t, out.imu.t_ns.last().copied(), t_ns)?;
        out.imu.t_ns.push(t_ns);
        out.imu.acc.push(row.f64s(acc)?);
        out.imu.gyr.push(row.f64s(gyr)?);
        out.imu.mag.push(row.f64s(mag)?);
        match reference_of(row, q)? {
            Some(r) => {
                out.reference_rows.push(out.imu.t_ns.len() - 1);
                if attitudes {
                    out.reference.push((t_ns, r));
                }
            }
            None => out.missing_reference += 1,
        }
        if let (Some(col), Some(list)) = (mask, out.mask.as_mut()) {
            list.push(row.f64(col)? != 0.0);
        }
        if let (Some(cols), Some(list)) = (est, out.estimate.as_mut()) {
            let values = cols.map(|c| row.opt_f64(c));
            let mut filled = [0.0; 4];
            let mut count = 0;
            for (f, v) in filled.iter_mut().zip(values) {
                if let Some(v) = v? {
                    *f = v;
                    count += 1;
                }
            }
            match count {
                0 => {}
                4 => list.push((t_ns, unit(row, filled)?)),
                _ => return Err(row.error("qw_est..qz_est are partly empty".into())),
            }
        }
        Ok(())
    })?;
    Ok(out)
}

/// A row of [`VectorRows`]: its instant (ns) and a vector per group.
pub(crate) type VectorRow<const G: usize> = (u64, [[f64; 3]; G]);

/// `t_ns` and three-column groups of a simulation's CSV (`perturbation.csv`, `marg.csv`), read
/// a row at a time, `t_ns` strictly increasing.
pub(crate) struct VectorRows<const G: usize> {
    table: Table,
    t: usize,
    cols: [[usize; 3]; G],
    last: Option<u64>,
    ahead: Option<VectorRow<G>>,
}

impl<const G: usize> VectorRows<G> {
    /// Opens `path` and finds its columns.
    pub(crate) fn open(path: &Path, groups: [[&str; 3]; G]) -> Result<Self, ColumnError> {
        let table = Table::open(path)?;
        let t = table.column("t_ns")?;
        let mut cols = [[0usize; 3]; G];
        for (c, names) in cols.iter_mut().zip(groups) {
            *c = table.columns(names)?;
        }
        Ok(Self {
            table,
            t,
            cols,
            last: None,
            ahead: None,
        })
    }

    /// The next row: its instant and a vector per group.
    pub(crate) fn next(&mut self) -> Result<Option<VectorRow<G>>, ColumnError> {
        if let Some(row) = self.ahead.take() {
            return Ok(Some(row));
        }
        let Some(row) = self.table.next_row()? else {
            return Ok(None);
        };
        let t: u64 = row.int(self.t)?;
        row.check_order(self.t, self.last, t, true)?;
        let mut values = [[0.0; 3]; G];
        for (v, c) in values.iter_mut().zip(self.cols) {
            *v = row.f64s(c)?;
        }
        self.last = Some(t);
        Ok(Some((t, values)))
    }

    /// The row at instant `t` if there is one; `t` must increase from call to call.
    pub(crate) fn at(&mut self, t: u64) -> Result<Option<[[f64; 3]; G]>, ColumnError> {
        while let Some((s, values)) = self.next()? {
            if s >= t {
                self.ahead = Some((s, values));
                return Ok((s == t).then_some(values));
            }
        }
        Ok(None)
    }
}

/// Instants (ns) and, per group of three columns, one vector per row.
pub type Vectors<const G: usize> = (Vec<u64>, [Vec<[f64; 3]>; G]);

/// Reads `t_ns` and three-column groups of a simulation's CSV (`perturbation.csv`, `marg.csv`).
pub fn read_vectors<const G: usize>(
    path: &Path,
    groups: [[&str; 3]; G],
) -> Result<Vectors<G>, ColumnError> {
    let mut rows = VectorRows::open(path, groups)?;
    let mut times: Vec<u64> = Vec::new();
    let mut values: [Vec<[f64; 3]>; G] = core::array::from_fn(|_| Vec::new());
    while let Some((t, row)) = rows.next()? {
        times.push(t);
        for (v, r) in values.iter_mut().zip(row) {
            v.push(r);
        }
    }
    Ok((times, values))
}

/// The first sample of `truth.csv` (its instant and attitude, normalised), `None` when it has
/// no data row; the rest of the file is not read.
pub fn read_first_attitude(path: &Path) -> Result<Option<Stamped>, ColumnError> {
    let mut table = Table::open(path)?;
    let t = table.column("t_ns")?;
    let q = table.columns(["qw", "qx", "qy", "qz"])?;
    let Some(row) = table.next_row()? else {
        return Ok(None);
    };
    Ok(Some((row.int(t)?, unit(&row, row.f64s(q)?)?)))
}
