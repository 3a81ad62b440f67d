//! `clipping.csv`: each device's front-end clipping counters, as flight controllers keep them
//! (ArduPilot's per-IMU accelerometer clip counts, say), cumulative since the session start.
//!
//! Columns `t_ns,device,accel_x,accel_y,accel_z,gyro_x,gyro_y,gyro_z`: a row for a device at
//! the first output sample whose counts differ from its previous row, then one row per device
//! with an accelerometer and gyroscope at the end of the session (its totals at the last sample
//! predicted), so a file of a session without clipping still says so. A count is one internal
//! sample of one axis that hit the chip's full scale (on the output path, one output sample):
//! see `margemu_model::chain`.
//!
//! ```
//! use margemu_hil::stream::clipping::{ClippingWriter, Clips};
//! use margemu_sim::marg::ClipCounts;
//! let dir = std::env::temp_dir().join(format!("margemu-doc-clipping-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! let mut w = ClippingWriter::create(&dir, &["imu".into()]).unwrap();
//! let mut clips = Clips::default();
//! w.write(0, &clips).unwrap();
//! clips[0] = Some(ClipCounts { accel: [0, 0, 2], gyro: [0; 3] });
//! w.write(125_000, &clips).unwrap();
//! w.finish().unwrap();
//! let text = std::fs::read_to_string(dir.join("clipping.csv")).unwrap();
//! std::fs::remove_dir_all(&dir).unwrap();
//! assert_eq!(text.lines().collect::<Vec<_>>(), [
//!     "t_ns,device,accel_x,accel_y,accel_z,gyro_x,gyro_y,gyro_z",
//!     "125000,imu,0,0,2,0,0,0",
//!     "125000,imu,0,0,2,0,0,0",
//! ]);
//! ```

use margemu_sim::marg::ClipCounts;
use margemu_sim::scene::rig::MAX_DEVICES;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// The file's name.
pub const CLIPPING_FILE: &str = "clipping.csv";

/// Its header.
pub const CLIPPING_COLUMNS: &str = "t_ns,device,accel_x,accel_y,accel_z,gyro_x,gyro_y,gyro_z";

/// Every device's counters at one output sample, in the scene's device order (`None`: a device
/// without accelerometer and gyroscope, or no device there).
pub type Clips = [Option<ClipCounts>; MAX_DEVICES];

/// The open `clipping.csv`.
pub struct ClippingWriter {
    out: BufWriter<File>,
    names: Vec<String>,
    last: Clips,
    last_t_ns: u64,
}

impl ClippingWriter {
    /// Creates `dir/clipping.csv` with its header for the devices `names` (scene order).
    pub fn create(dir: &Path, names: &[String]) -> io::Result<Self> {
        let mut out = BufWriter::with_capacity(1 << 14, File::create(dir.join(CLIPPING_FILE))?);
        writeln!(out, "{CLIPPING_COLUMNS}")?;
        Ok(Self {
            out,
            names: names.to_vec(),
            last: Clips::default(),
            last_t_ns: 0,
        })
    }

    /// The counters at output sample instant `t_ns`: a row per device whose counts changed.
    pub fn write(&mut self, t_ns: u64, clips: &Clips) -> io::Result<()> {
        self.last_t_ns = t_ns;
        for (i, (now, last)) in clips.iter().zip(&mut self.last).enumerate() {
            if let Some(c) = now.filter(|c| Some(*c) != *last && *c != ClipCounts::default()) {
                row(&mut self.out, t_ns, self.names.get(i), &c)?;
            }
            if now.is_some() {
                *last = *now;
            }
        }
        Ok(())
    }

    /// The totals, a row per device with counters, and a flush.
    pub fn finish(&mut self) -> io::Result<()> {
        for (i, c) in self.last.iter().enumerate() {
            if let Some(c) = c {
                row(&mut self.out, self.last_t_ns, self.names.get(i), c)?;
            }
        }
        self.out.flush()
    }

    /// Flushes what was written.
    pub fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
    }
}

fn row(out: &mut impl Write, t_ns: u64, name: Option<&String>, c: &ClipCounts) -> io::Result<()> {
    let name = name.map_or("", String::as_str);
    let [ax, ay, az] = c.accel;
    let [gx, gy, gz] = c.gyro;
    writeln!(out, "{t_ns},{name},{ax},{ay},{az},{gx},{gy},{gz}")
}
