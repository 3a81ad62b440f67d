//! `device_truth.csv`: a rig's truth per device, in each device's own axes, as the sensors of
//! that device feel it (written only for a rig: a scene of one chip has `truth.csv` alone).
//!
//! One row per output sample and device, in device order:
//! `t_ns,device,wx,wy,wz,fx,fy,fz,dwx,dwy,dwz,mx,my,mz`: the latch instant, the device's name,
//! then in its axes (the scene's `rotation`, plate → chip) the body rate (rad/s), the specific
//! force at its mounting point (m/s²: `f + ω̇×r + ω×(ω×r)` with its `offset` r, plate axes, on
//! top of `[sensors.accel] lever_arm` which the sensor model adds itself), the angular
//! acceleration (rad/s²) and the field (the scene's unit). These are the values the device's
//! sensor model starts from, before its error terms and any perturbation.
//!
//! ```
//! use margemu_hil::stream::device_truth::at_point;
//! // Spinning at 2 rad/s about z, 0.1 m out on x: the centripetal −ω²r on x.
//! let f = at_point([0.0, 0.0, 9.8], [0.0, 0.0, 2.0], [0.0; 3], [0.1, 0.0, 0.0]);
//! assert!((f[0] + 0.4).abs() < 1e-12 && f[2] == 9.8);
//! ```

use margemu_sim::scene::rig::Device;
use margemu_sim::truth::Truth;
use nalgebra::Vector3;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// The file's name.
pub const DEVICE_TRUTH_FILE: &str = "device_truth.csv";

/// Its header.
pub const DEVICE_TRUTH_COLUMNS: &str = "t_ns,device,wx,wy,wz,fx,fy,fz,dwx,dwy,dwz,mx,my,mz";

/// The specific force at a point `r` (m) of a rigid body whose reference point feels `f`,
/// turning at `w` with angular acceleration `dw` (all in one frame).
pub fn at_point(f: [f64; 3], w: [f64; 3], dw: [f64; 3], r: [f64; 3]) -> [f64; 3] {
    let [f, w, dw, r] = [f, w, dw, r].map(Vector3::from);
    (f + dw.cross(&r) + w.cross(&w.cross(&r))).into()
}

/// The open `device_truth.csv` of a rig.
pub struct DeviceTruthWriter {
    out: BufWriter<File>,
    devices: Vec<Device>,
    float: ryu::Buffer,
}

impl DeviceTruthWriter {
    /// Creates `dir/device_truth.csv` with its header when `devices` are a rig (more than one);
    /// `None` otherwise.
    pub fn create(dir: &Path, devices: &[Device]) -> io::Result<Option<Self>> {
        if devices.len() < 2 {
            return Ok(None);
        }
        let mut out = BufWriter::with_capacity(1 << 16, File::create(dir.join(DEVICE_TRUTH_FILE))?);
        writeln!(out, "{DEVICE_TRUTH_COLUMNS}")?;
        Ok(Some(Self {
            out,
            devices: devices.to_vec(),
            float: ryu::Buffer::new(),
        }))
    }

    /// The rows of `truths`, every device of each, in order.
    pub fn write(&mut self, truths: &[Truth]) -> io::Result<()> {
        for t in truths {
            for d in &self.devices {
                let chip = &d.chip;
                let f = at_point(
                    t.specific_force,
                    t.body_rate,
                    t.angular_accel,
                    chip.offset.unwrap_or([0.0; 3]),
                );
                write!(self.out, "{},{}", t.t_ns, d.name)?;
                let vectors = [t.body_rate, f, t.angular_accel, t.field_body];
                for v in vectors.map(|v| chip.to_chip(v)).iter().flatten() {
                    write!(self.out, ",{}", self.float.format(*v))?;
                }
                writeln!(self.out)?;
            }
        }
        Ok(())
    }

    /// Flushes the file.
    pub fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
    }
}
