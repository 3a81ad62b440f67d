//! Run files: `truth.csv` (one row per output sample) and `meta.toml` (what produced them).
//!
//! `truth.csv` has a header row; its columns, in order, with units (field in the scene's unit):
//!
//! | column | meaning |
//! |---|---|
//! | `t_ns` | latch instant, integer nanoseconds from the scene start |
//! | `x,y,z` | plate position, world frame (m) |
//! | `roll,pitch,yaw` | canonical ZYX Euler angles (rad): roll, yaw in (−π, π], pitch in [−π/2, π/2] |
//! | `qw,qx,qy,qz` | attitude quaternion, Hamilton, body to world |
//! | `wx,wy,wz` | body angular rate (rad/s) |
//! | `fx,fy,fz` | specific force, body frame (m/s²); `(0, 0, +g)` level at rest |
//! | `vx,vy,vz` | plate velocity, world frame (m/s) |
//! | `ax_w,ay_w,az_w` | external acceleration, world frame (m/s²) |
//! | `ax_b,ay_b,az_b` | external acceleration, body frame (m/s²) |
//! | `dwx,dwy,dwz` | body angular acceleration (rad/s²) |
//! | `mx,my,mz` | true magnetic field, body frame (scene unit) |
//!
//! Floats are written in their shortest round-trip form ([`crate::csv_row`]), so files are exact and byte-identical
//! for the same scene and seed. `meta.toml` holds no wall-clock time for the same reason.

use crate::csv_row::{self, RowBuf};
use crate::truth::Truth;
use std::io::{self, Write};

/// The files `simulate` writes besides `meta.toml` (`perturbation.csv` only for scenes with a
/// perturbation).
pub const RUN_FILES: [&str; 3] = [TRUTH_FILE, "marg.csv", "perturbation.csv"];

/// The ground truth's file, in run and session directories.
pub const TRUTH_FILE: &str = "truth.csv";

/// Header of `truth.csv`.
pub const TRUTH_COLUMNS: [&str; 32] = [
    "t_ns", "x", "y", "z", "roll", "pitch", "yaw", "qw", "qx", "qy", "qz", "wx", "wy", "wz", "fx",
    "fy", "fz", "vx", "vy", "vz", "ax_w", "ay_w", "az_w", "ax_b", "ay_b", "az_b", "dwx", "dwy",
    "dwz", "mx", "my", "mz",
];

/// Writes truth rows as CSV ([`crate::csv_row`]: one `write_all` per row).
pub struct TruthWriter<W: Write> {
    out: W,
    row: RowBuf,
}

impl<W: Write> TruthWriter<W> {
    /// Writes the header and returns the writer.
    pub fn new(mut out: W) -> io::Result<Self> {
        out.write_all(csv_row::header(&TRUTH_COLUMNS).as_bytes())?;
        Ok(Self {
            out,
            row: RowBuf::default(),
        })
    }

    /// Writes one row.
    pub fn write(&mut self, t: &Truth) -> io::Result<()> {
        self.row.write(&mut self.out, t.t_ns, row_values(t))
    }

    /// Flushes the inner writer.
    pub fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
    }

    /// Flushes and returns the inner writer.
    pub fn finish(mut self) -> io::Result<W> {
        self.out.flush()?;
        Ok(self.out)
    }
}

/// The values of a truth row after `t_ns`, in [`TRUTH_COLUMNS`]' order.
fn row_values(t: &Truth) -> impl Iterator<Item = f64> + '_ {
    let groups: [&[f64]; 10] = [
        &t.position,
        &t.euler,
        &t.quaternion,
        &t.body_rate,
        &t.specific_force,
        &t.velocity,
        &t.accel_world,
        &t.accel_body,
        &t.angular_accel,
        &t.field_body,
    ];
    groups.into_iter().flatten().copied()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_have_as_many_fields_as_the_header() {
        let mut w = TruthWriter::new(Vec::new()).unwrap();
        let truth = Truth {
            t_ns: 5,
            quaternion: [1.0, 0.0, 0.0, 0.0],
            ..Truth::default()
        };
        w.write(&truth).unwrap();
        let text = String::from_utf8(w.finish().unwrap()).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 2);
        assert_eq!(lines[1].split(',').count(), TRUTH_COLUMNS.len());
        assert!(
            lines[1].starts_with("5,0.0,0.0,0.0,0.0,0.0,0.0,1.0,"),
            "{}",
            lines[1]
        );
    }
}
