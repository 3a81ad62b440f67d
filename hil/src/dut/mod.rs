//! The device under test's own output: its attitude (and IMU readings) read from a second serial
//! port as MAVLink or MSP, and logged beside the session with the host's receive time.
//!
//! A [`DutReader`] ([`spawn_dut_reader`], or [`DutReader::spawn`] with a [`DutConfig`]) owns the
//! port in a thread: it reads, finds frames (re-synchronising after garbage, damaged frames and
//! false starts, whatever the read boundaries), decodes them, appends rows to three CSV files in
//! the session directory, flushed at least every 100 ms and when the reader ends, and for MSP,
//! which is request/response, polls the board with `MSP_ATTITUDE` and `MSP_RAW_IMU` requests
//! (50 Hz by default). Malformed bytes are counted and skipped, never fatal. The reader ends when
//! stopped ([`DutReader::stop`]) or when the port ends or fails ([`DutEnd::Disconnected`]); in
//! both cases every row decoded so far is on disk and [`DutSummary`] gives the counts.
//!
//! - MAVLink 1 and 2 ([`mavlink_in`]): the `mavlink` crate, common dialect. `ATTITUDE`,
//!   `ATTITUDE_QUATERNION`, `SCALED_IMU`/`2`/`3` and `HIGHRES_IMU` become samples; every other
//!   message of the dialect is logged in `dut_messages.csv` only.
//! - MSP v1 and v2 ([`msp`]): `MSP_ATTITUDE` and `MSP_RAW_IMU`.
//!
//! # Files
//!
//! `host_ns` is nanoseconds on the host's monotonic clock since the `origin` given to the reader
//! (the session's origin), taken when the read that completed the message returned; `protocol` is
//! `mavlink1`, `mavlink2`, `msp1` or `msp2`; an empty field is a value the message lacks.
//!
//! | file | columns |
//! |---|---|
//! | `dut_messages.csv` | `host_ns,protocol,message,sys_id,comp_id,seq,length`: every decoded message, whatever its type. `message` is the MAVLink name (`ATTITUDE`, `HEARTBEAT`, …) or `MSP_ATTITUDE`, `MSP_RAW_IMU`, `MSP_CMD_<n>`, with `_REQUEST` for a frame towards the board and `_ERROR` for the board's error reply; `sys_id,comp_id,seq` are MAVLink's (empty for MSP); `length` is the payload length on the wire (MAVLink 2 trailing zeros truncated) |
//! | `dut_attitude.csv` | `host_ns,protocol,message,device_time_us,roll,pitch,yaw,qw,qx,qy,qz`: canonical ZYX Euler angles (rad; roll, yaw in (−π, π], pitch in [−π/2, π/2]) and the unit quaternion, body to world, in margemu's frames. `ATTITUDE` gives Euler angles and the quaternion is computed from them; `ATTITUDE_QUATERNION` the reverse (normalized; sign as sent; `repr_offset_q` ignored); `MSP_ATTITUDE` like `ATTITUDE`. `device_time_us` is `time_boot_ms × 1000`, empty for MSP |
//! | `dut_imu.csv` | `host_ns,protocol,message,device_time_us,ax,ay,az,gx,gy,gz,mx,my,mz`: accelerometer (specific force, m/s², level at rest `(0, 0, +9.81)`), gyroscope (rad/s), magnetometer (µT), in margemu's body axes. `SCALED_IMU*`: mG × 9.80665·10⁻³, mrad/s × 10⁻³, mgauss × 0.1; `HIGHRES_IMU`: m/s², rad/s, gauss × 100, `device_time_us = time_usec`; `MSP_RAW_IMU`: **raw counts as received**, unscaled and unrotated (see [`msp`]) |
//!
//! # Frames
//!
//! MAVLink reports NED world and FRD body axes; margemu's are z up. Both frames turn by 180° about
//! x: roll stays, pitch and yaw change sign, `q = (w, x, y, z) → (w, x, −y, −z)`, vectors
//! `(x, y, z) → (x, −y, −z)`. MSP (Betaflight, INAV) reports roll right-wing-down positive, pitch
//! nose-down positive and the compass heading: roll and pitch stay, `yaw = −heading`. World x is
//! north in both. Details and sources in [`frames`].
//!
//! # Writing MAVLink
//!
//! [`mavlink_out`] builds ATTITUDE and ATTITUDE_QUATERNION from a margemu attitude and frames them
//! with the crate's encoder, for a virtual flight controller.
//!
//! ```no_run
//! use margemu_hil::dut::{open_dut_port, spawn_dut_reader, DutProtocol};
//! let origin = std::time::Instant::now();
//! let port = open_dut_port("/dev/ttyUSB1", 115_200)?;
//! let reader = spawn_dut_reader(port, DutProtocol::Mavlink, "sessions/run".as_ref(), origin)?;
//! // … the session runs …
//! let summary = reader.stop()?;
//! println!("{summary}");
//! # Ok::<(), margemu_hil::dut::DutError>(())
//! ```

pub mod decode;
pub mod frames;
pub mod log;
pub mod mavlink_in;
pub mod mavlink_out;
pub mod msp;
mod reader;

pub use decode::{DecodeCounters, Decoded, MessageInfo, Sample, Wire};
pub use frames::Attitude;
pub use reader::{spawn_dut_reader, DutConfig, DutProgress, DutReader};

use margemu_sim::meta::DutMeta;
use std::collections::BTreeMap;
use std::fmt;
use std::path::PathBuf;
use std::time::Duration;

/// The wire format of the device under test (`--dut-protocol mavlink|msp`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DutProtocol {
    /// MAVLink 1 and 2, common dialect; the device streams on its own.
    Mavlink,
    /// MSP v1 and v2; the host polls the board.
    Msp,
}

impl DutProtocol {
    /// `mavlink` or `msp`.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Mavlink => "mavlink",
            Self::Msp => "msp",
        }
    }
}

impl fmt::Display for DutProtocol {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::str::FromStr for DutProtocol {
    type Err = String;

    /// `mavlink` or `msp`.
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "mavlink" => Ok(Self::Mavlink),
            "msp" => Ok(Self::Msp),
            other => Err(format!(
                "unknown protocol `{other}` (expected mavlink or msp)"
            )),
        }
    }
}

/// Why the device-under-test reader could not run.
#[derive(Debug, thiserror::Error, docsplay::Display)]
pub enum DutError {
    /// cannot open the device-under-test port {path}
    Port {
        /// The port's name.
        path: String,
        /// The cause.
        #[source]
        source: serialport::Error,
    },
    /// cannot write the device-under-test logs in {path}
    Log {
        /// The session directory.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// cannot start the device-under-test reader thread
    Thread {
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// the device-under-test reader thread panicked
    Panicked,
}

/// How the reader ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DutEnd {
    /// [`DutReader::stop`] was called.
    Stopped,
    /// The port ended or failed first (the device vanished); the detail says how.
    Disconnected(String),
}

/// What a reader saw, for the caller to print and to record in `events.csv` and `meta.toml`.
#[derive(Clone, Debug, PartialEq)]
pub struct DutSummary {
    /// The wire format.
    pub protocol: DutProtocol,
    /// The session directory.
    pub dir: PathBuf,
    /// Decoded messages per `message` name (as in `dut_messages.csv`).
    pub messages: BTreeMap<String, u64>,
    /// Bytes, bad bytes, bad frames, unknown ids, undecoded payloads.
    pub counters: DecodeCounters,
    /// Rows of `dut_attitude.csv`.
    pub attitude_rows: u64,
    /// Rows of `dut_imu.csv`.
    pub imu_rows: u64,
    /// MSP requests written.
    pub requests_sent: u64,
    /// How the reader ended.
    pub end: DutEnd,
}

impl DutSummary {
    /// Messages decoded, all types.
    pub fn total_messages(&self) -> u64 {
        self.messages.values().sum()
    }

    /// The `[dut]` table of `meta.toml`.
    pub fn meta(&self) -> DutMeta {
        let c = &self.counters;
        DutMeta {
            protocol: self.protocol.as_str().to_string(),
            messages: self.total_messages(),
            attitude_rows: self.attitude_rows,
            imu_rows: self.imu_rows,
            bytes: c.bytes,
            bad_bytes: c.bad_bytes,
            bad_frames: c.bad_frames,
            unknown_ids: c.unknown_ids,
            undecoded: c.undecoded,
            requests_sent: self.requests_sent,
            end: self.end.to_string(),
            per_message: self.messages.clone(),
        }
    }
}

impl fmt::Display for DutEnd {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Stopped => f.write_str("stopped"),
            Self::Disconnected(d) => write!(f, "disconnected ({d})"),
        }
    }
}

/// One line: `mavlink: 1200 messages (ATTITUDE 600, HEARTBEAT 10), 600 attitude rows, 0 IMU
/// rows; 12 bad bytes, 0 bad frames, 0 unknown ids, 0 undecoded; stopped`.
impl fmt::Display for DutSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let per: Vec<String> = self
            .messages
            .iter()
            .map(|(name, n)| format!("{name} {n}"))
            .collect();
        let c = &self.counters;
        write!(
            f,
            "{}: {} messages ({}), {} attitude rows, {} IMU rows; {} bad bytes, {} bad frames, {} unknown ids, {} undecoded",
            self.protocol.as_str(),
            self.total_messages(),
            per.join(", "),
            self.attitude_rows,
            self.imu_rows,
            c.bad_bytes,
            c.bad_frames,
            c.unknown_ids,
            c.undecoded
        )?;
        if self.protocol == DutProtocol::Msp {
            write!(f, ", {} requests sent", self.requests_sent)?;
        }
        write!(f, "; {}", self.end)
    }
}

/// Opens the device's serial port with a 5 ms read timeout (the reader's stop latency and MSP
/// poll jitter).
pub fn open_dut_port(path: &str, baud: u32) -> Result<serialport::TTYPort, DutError> {
    serialport::new(path, baud)
        .timeout(Duration::from_millis(5))
        .open_native()
        .map_err(|source| DutError::Port {
            path: path.to_string(),
            source,
        })
}
