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
//! Quaternions are normalised; a zero or non-finite one is an error at its line.

use super::quat::{normalize, Quat};
use super::score::Stamped;
use crate::csv_column::ColumnError;
use crate::csv_table::{Row, Table};
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
    /// Host arrival time (ns, the session's monotonic clock).
    pub host_ns: i64,
    /// The device's own time stamp (µs), when it sent one.
    pub device_time_us: Option<f64>,
    /// The Euler columns `[roll, pitch, yaw]` (rad).
    pub euler: [f64; 3],
    /// The quaternion, normalised.
    pub q: Quat,
}

/// `dut_attitude.csv`: the rows kept and what else was there.
#[derive(Clone, Debug, Default)]
pub struct DutAttitude {
    /// Rows of the selected message (all rows without a filter).
    pub rows: Vec<DutRow>,
    /// Rows per `protocol/message`, in order of first appearance.
    pub messages: Vec<(String, usize)>,
}

/// An external recording: IMU samples, the reference attitude and, optionally, an estimate.
#[derive(Clone, Debug, Default)]
pub struct External {
    /// The IMU columns.
    pub imu: Imu,
    /// The reference quaternion per row.
    pub reference: Vec<Stamped>,
    /// `qw_est..qz_est` per row where they are filled; `None` without those columns.
    pub estimate: Option<Vec<Stamped>>,
}

fn unit(row: &Row<'_>, q: Quat) -> Result<Quat, ColumnError> {
    let u = normalize(q)
        .ok_or_else(|| row.error(format!("quaternion {q:?} has no direction (zero norm)")))?;
    let c = u.into_inner();
    Ok([c.w, c.i, c.j, c.k])
}

fn seconds_to_ns(row: &Row<'_>, col: usize) -> Result<u64, ColumnError> {
    let t = row.f64(col)?;
    if t < 0.0 || t * 1e9 >= u64::MAX as f64 {
        return Err(row.error(format!("`t_s` = {t} is outside 0 to 1.8e10 s")));
    }
    Ok((t * 1e9).round() as u64)
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

/// Reads `dut_attitude.csv`, keeping the rows whose `message` is `message` (all without one).
pub fn read_dut_attitude(path: &Path, message: Option<&str>) -> Result<DutAttitude, ColumnError> {
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
        match out.messages.iter_mut().find(|m| m.0 == name) {
            Some(m) => m.1 += 1,
            None => out.messages.push((name, 1)),
        }
        if message.is_some_and(|m| m != row.text(msg)) {
            return Ok(());
        }
        out.rows.push(DutRow {
            line: row.line(),
            host_ns,
            device_time_us: row.opt_f64(device)?,
            euler: row.f64s(e)?,
            q: unit(row, row.f64s(q)?)?,
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
        row.check_order(t, out.last().map(|s| s.0), t_ns, true)?;
        out.push((t_ns, unit(row, row.f64s(q)?)?));
        Ok(())
    })?;
    Ok(out)
}

/// Reads an external recording (see the module docs).
pub fn read_external(path: &Path) -> Result<External, ColumnError> {
    let table = Table::open(path)?;
    let t = table.column("t_s")?;
    let acc = table.columns(["ax", "ay", "az"])?;
    let gyr = table.columns(["gx", "gy", "gz"])?;
    let mag = table.columns(["mx", "my", "mz"])?;
    let q = table.columns(["qw", "qx", "qy", "qz"])?;
    let est_names = ["qw_est", "qx_est", "qy_est", "qz_est"];
    let est = if est_names.iter().any(|n| table.optional(n).is_some()) {
        Some(table.columns(est_names)?)
    } else {
        None
    };
    let mut out = External {
        estimate: est.map(|_| Vec::new()),
        ..External::default()
    };
    table.for_each(|row| {
        let t_ns = seconds_to_ns(row, t)?;
        row.check_order(t, out.imu.t_ns.last().copied(), t_ns, true)?;
        out.imu.t_ns.push(t_ns);
        out.imu.acc.push(row.f64s(acc)?);
        out.imu.gyr.push(row.f64s(gyr)?);
        out.imu.mag.push(row.f64s(mag)?);
        out.reference.push((t_ns, unit(row, row.f64s(q)?)?));
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

/// Instants (ns) and, per group of three columns, one vector per row.
pub type Vectors<const G: usize> = (Vec<u64>, [Vec<[f64; 3]>; G]);

/// Reads `t_ns` and three-column groups of a simulation's CSV (`perturbation.csv`, `marg.csv`).
pub fn read_vectors<const G: usize>(
    path: &Path,
    groups: [[&str; 3]; G],
) -> Result<Vectors<G>, ColumnError> {
    let table = Table::open(path)?;
    let t = table.column("t_ns")?;
    let mut cols = [[0usize; 3]; G];
    for (c, names) in cols.iter_mut().zip(groups) {
        *c = table.columns(names)?;
    }
    let mut times: Vec<u64> = Vec::new();
    let mut values: [Vec<[f64; 3]>; G] = core::array::from_fn(|_| Vec::new());
    table.for_each(|row| {
        let t_ns: u64 = row.int(t)?;
        row.check_order(t, times.last().copied(), t_ns, true)?;
        times.push(t_ns);
        for (v, c) in values.iter_mut().zip(cols) {
            v.push(row.f64s(c)?);
        }
        Ok(())
    })?;
    Ok((times, values))
}
