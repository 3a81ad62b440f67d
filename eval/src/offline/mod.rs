//! Running a reference attitude filter (`margemu-filters`: ECF, GDA, EKF) offline over recorded
//! IMU samples, and writing its estimates for `margemu evaluate`.
//!
//! - [`params`] (`margemu_sim::filter_params`, re-exported): which filter ([`FilterKind`]), its
//!   tunable parameters ([`FilterParams`]) and the parameters file;
//! - [`input`]: a `simulate` run directory or an external CSV recording, read into samples;
//! - [`mag_estimate`]: an external recording's magnetic reference from its first rest phase;
//! - [`run`]: the filter over the samples, one estimate per sample stamped with its instant
//!   (the filter's `dt` from the stamps, through `evaluate::estimate_with`), in `f64`;
//! - [`filter_to_file`]: the filter from a recording on disk to an estimates file, one sample
//!   at a time (memory bounded; warnings for all-zero accelerometer or magnetometer data);
//! - [`write_estimates`]: `t_s,qw,qx,qy,qz,roll,pitch,yaw` (s from the recording's start of
//!   time, the quaternion body to world, ZYX Euler angles in rad), which `margemu evaluate
//!   RUN --estimates FILE` scores.
//!
//! ```
//! use margemu_eval::evaluate::input::Imu;
//! use margemu_eval::offline::{run, FilterKind, FilterParams, Initial};
//! // One second of a level plate at rest, 100 Hz.
//! let n = 100;
//! let imu = Imu {
//!     t_ns: (0..n).map(|k| k * 10_000_000).collect(),
//!     acc: vec![[0.0, 0.0, 9.80665]; n as usize],
//!     gyr: vec![[0.0; 3]; n as usize],
//!     mag: vec![[0.5, 0.0, -0.83]; n as usize],
//! };
//! let params = FilterParams::defaults(FilterKind::Ekf);
//! let estimates = run(&params, &imu, [0.5, 0.0, -0.83], Initial::FirstSample)?;
//! let (t_ns, q) = estimates[99];
//! assert_eq!(t_ns, 990_000_000);
//! assert!((q[0].abs() - 1.0).abs() < 1e-9);
//! # Ok::<(), margemu_eval::offline::ParamError>(())
//! ```

mod file;
pub mod input;
pub mod mag_estimate;

pub use file::{filter_to_file, filter_to_file_in, FilterError, FilterRun};
pub use input::{
    first_true_attitude, first_true_attitude_in, open, read, InputError, Recording, Samples,
};
pub use margemu_filters::Initial;
pub use margemu_sim::filter_params::{
    self as params, FilterKind, FilterParams, ParamError, ParamSpec,
};

use crate::evaluate::input::Imu;
use crate::evaluate::{estimate_with, Stamped};
use margemu_filters::quat::euler_zyx;
use std::io::{self, Write};

/// Header of the estimates file.
pub const ESTIMATE_COLUMNS: [&str; 8] = ["t_s", "qw", "qx", "qy", "qz", "roll", "pitch", "yaw"];

/// Where a filter run starts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AttitudeStart {
    /// From the first sample (TRIAD), as the filters do on their own (default). A first sample
    /// taken under external acceleration or a magnetic burst starts the filter off, and its
    /// scores then include converging from there.
    #[default]
    FirstSample,
    /// From the true attitude at the first sample: the scores show tracking only.
    Truth,
}

impl std::str::FromStr for AttitudeStart {
    type Err = String;

    /// `first-sample` or `truth`.
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "first-sample" => Ok(Self::FirstSample),
            "truth" => Ok(Self::Truth),
            _ => Err(format!("unknown start `{s}` (first-sample or truth)")),
        }
    }
}

impl std::fmt::Display for AttitudeStart {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::FirstSample => "first-sample",
            Self::Truth => "truth",
        })
    }
}

/// Runs the filter `params` describes, started as `initial` says, over `imu` against the world
/// field `mag_reference`, and returns the attitude after each sample, stamped with the sample's instant. A sample missing
/// a vector (shorter `acc`, `gyr` or `mag`) is given NaN there, which the filter skips and
/// counts.
pub fn run(
    params: &FilterParams,
    imu: &Imu,
    mag_reference: [f64; 3],
    initial: Initial,
) -> Result<Vec<Stamped>, ParamError> {
    let mut filter = params.build(mag_reference, initial)?;
    Ok(estimate_with(imu, |k, dt| {
        let at = |v: &[[f64; 3]]| v.get(k).copied().unwrap_or([f64::NAN; 3]);
        let sample = margemu_filters::Imu {
            gyro: at(&imu.gyr),
            acc: at(&imu.acc),
            mag: at(&imu.mag),
        };
        filter.update(&sample, dt);
        filter.quaternion()
    }))
}

/// Writes `estimates` as the estimates file (header, then one row per estimate; times in
/// seconds written exactly from the integer nanoseconds, floats in shortest round-trip form).
pub fn write_estimates(out: &mut impl Write, estimates: &[Stamped]) -> io::Result<()> {
    writeln!(out, "{}", ESTIMATE_COLUMNS.join(","))?;
    let mut float = ryu::Buffer::new();
    for &(t_ns, q) in estimates {
        write_estimate(out, &mut float, t_ns, q)?;
    }
    out.flush()
}

/// One row of the estimates file.
fn write_estimate(
    out: &mut impl Write,
    float: &mut ryu::Buffer,
    t_ns: u64,
    q: [f64; 4],
) -> io::Result<()> {
    let (s, ns) = (t_ns / 1_000_000_000, t_ns % 1_000_000_000);
    write!(out, "{s}.{ns:09}")?;
    for v in q.iter().chain(&euler_zyx(q)) {
        out.write_all(b",")?;
        out.write_all(float.format(*v).as_bytes())?;
    }
    out.write_all(b"\n")
}
