//! The three CSV files of the device under test (columns in the `dut` module docs).

use super::decode::{Decoded, Sample};
use std::fmt::Write as _;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// Header of `dut_messages.csv`.
pub const MESSAGES_COLUMNS: &str = "host_ns,protocol,message,sys_id,comp_id,seq,length";
/// Header of `dut_attitude.csv`.
pub const ATTITUDE_COLUMNS: &str =
    "host_ns,protocol,message,device_time_us,roll,pitch,yaw,qw,qx,qy,qz";
/// Header of `dut_imu.csv`.
pub const IMU_COLUMNS: &str = "host_ns,protocol,message,device_time_us,ax,ay,az,gx,gy,gz,mx,my,mz";

/// File names in the session directory.
pub const MESSAGES_FILE: &str = "dut_messages.csv";
/// See [`MESSAGES_FILE`].
pub const ATTITUDE_FILE: &str = "dut_attitude.csv";
/// See [`MESSAGES_FILE`].
pub const IMU_FILE: &str = "dut_imu.csv";

/// Every file of the device under test's log.
pub const FILES: [&str; 3] = [MESSAGES_FILE, ATTITUDE_FILE, IMU_FILE];

/// The open CSV files.
pub struct DutLog {
    messages: BufWriter<File>,
    attitude: BufWriter<File>,
    imu: BufWriter<File>,
    line: String,
}

fn create(dir: &Path, name: &str, header: &str) -> io::Result<BufWriter<File>> {
    let mut out = BufWriter::with_capacity(1 << 16, File::create(dir.join(name))?);
    writeln!(out, "{header}")?;
    Ok(out)
}

/// An optional integer, or nothing.
fn opt(line: &mut String, v: Option<impl std::fmt::Display>) {
    if let Some(v) = v {
        let _ = write!(line, "{v}");
    }
}

/// `,v` for each float, in shortest round-trip form.
fn floats(line: &mut String, values: &[f64]) {
    let mut buf = ryu::Buffer::new();
    for v in values {
        line.push(',');
        line.push_str(buf.format(*v));
    }
}

impl DutLog {
    /// Creates (or truncates) the three files in `dir`, which must exist, with their headers.
    pub fn create(dir: &Path) -> io::Result<Self> {
        let mut log = Self {
            messages: create(dir, MESSAGES_FILE, MESSAGES_COLUMNS)?,
            attitude: create(dir, ATTITUDE_FILE, ATTITUDE_COLUMNS)?,
            imu: create(dir, IMU_FILE, IMU_COLUMNS)?,
            line: String::with_capacity(256),
        };
        log.flush()?;
        Ok(log)
    }

    /// The rows of one message received at `host_ns`.
    pub fn write(&mut self, host_ns: i64, d: &Decoded) -> io::Result<()> {
        let m = &d.message;
        let line = &mut self.line;
        line.clear();
        let _ = write!(line, "{host_ns},{},{},", m.wire.as_str(), m.name);
        opt(line, m.sys_id);
        line.push(',');
        opt(line, m.comp_id);
        line.push(',');
        opt(line, m.seq);
        let _ = writeln!(line, ",{}", m.length);
        self.messages.write_all(line.as_bytes())?;
        let Some(sample) = &d.sample else {
            return Ok(());
        };
        line.clear();
        let _ = write!(line, "{host_ns},{},{},", m.wire.as_str(), m.name);
        let out = match sample {
            Sample::Attitude(a) => {
                opt(line, a.device_time_us);
                floats(line, &a.attitude.euler);
                floats(line, &a.attitude.quaternion);
                &mut self.attitude
            }
            Sample::Imu(s) => {
                opt(line, s.device_time_us);
                floats(line, &s.accel);
                floats(line, &s.gyro);
                floats(line, &s.mag);
                &mut self.imu
            }
        };
        line.push('\n');
        out.write_all(line.as_bytes())
    }

    /// Flushes the three files to the operating system.
    pub fn flush(&mut self) -> io::Result<()> {
        self.messages.flush()?;
        self.attitude.flush()?;
        self.imu.flush()
    }
}
