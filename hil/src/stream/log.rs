//! The session directory: one folder per run, CSV files with a header row. During a session the
//! files are written by their own thread (`Logger`), flushed whenever it has written what was
//! queued (after every batch and every device message, unless the disk is slower), so an
//! interrupted run (Ctrl-C, a vanished device) leaves every row so far readable.
//!
//! Host times (`host_ns`, `send_ns`) are nanoseconds on the host's monotonic clock since the
//! session opened the port; `meta.toml`'s `start_host_ns` says when Start was sent, which is scene
//! time 0. Device times are the device's scene time (ns). Columns:
//!
//! | file | columns |
//! |---|---|
//! | `truth.csv` | as `simulate` writes it (`docs/ground-truth.md`), one row per sample, written as the session predicts them (in order, a window ahead of what it sends): every sample of the scene once the session completes |
//! | `device_truth.csv` | a rig's only: `t_ns,device,wx,wy,wz,fx,fy,fz,dwx,dwy,dwz,mx,my,mz`, each sample's truth per device in the device's own axes, the specific force at its mounting point ([`super::device_truth`]) |
//! | `clipping.csv` | `t_ns,device,accel_x,accel_y,accel_z,gyro_x,gyro_y,gyro_z`: each device's front-end clipping counters, cumulative, a row when they change and the totals at the end ([`super::clipping`]) |
//! | `sent.csv` | one row per item written, in the order written. Source images: `index,t_ns,send_ns,late_ns,image,resend`: sample index, its latch instant, when the write of its batch to the port completed, how late that was against the batch's schedule `start_host_ns + t_ns − lead` of its first sample (empty for the prefill, written before Start, and for resends), the register image as two lowercase hex digits per byte (`Image`'s `{:x}`, read back by `Image::parse_hex`; 44 digits for the 22-byte MPU-9250 image), and `1` if the item was written again because the device had not received it (go-back-N; `0` for the first copy). Source model: `index,t_ns,send_ns,late_ns,wx,wy,wz,fx,fy,fz,mx,my,mz,dwx,dwy,dwz,temp_c,resend`: the kinematics sample's index and instant at the kinematics rate, the same times, the `f32` values sent (body rate rad/s, specific force m/s², field in the scene's unit, angular acceleration rad/s², die temperature °C or empty), shortest round-trip, and the resend flag |
//! | `served.csv` | `host_ns,index,time_ns,crc32c,underrun,empty,match`: every sample instant the device reports it served (its Served messages), in the order received: the output sample index, the device scene time it was served at (the message's time for its first entry; the spec's `rate.sample_time_ns(index)` for the others), the CRC-32C of the 22-byte image latched into the chip (8 lowercase hex digits), `1` if the sample was missing (underrun: the previous image was held) or no image existed yet (empty), and `1` if the CRC equals that of the host's predicted image of that index, `0` if not, empty for instants after the scene's last sample and for entries the check cannot verify (see `served.rs`) |
//! | `device.csv` | `host_ns,device_time_ns,samples_served,index,served_time_ns,t_ns,underruns`: what the device reports it served, one row per Telemetry with `samples_served > 0`: the last index served, the device scene time it was served at, and that index's latch instant as the host scheduled it |
//! | `telemetry.csv` | `host_ns,seq` then every Telemetry field: `time_ns,state,samples_served,underruns,overruns,crc_errors,framing_errors,lost_frames,rejected_messages,buffer_level,next_index,credit_limit,last_served_index,last_served_time_ns` |
//! | `register_writes.csv` | `host_ns,time_ns,bus,address,register,value,dropped_before,device`: each write of the device under test (`bus` spi, i2c or aux; `address`: the I2C address, or on SPI the chip select of the device written, 0 for device 0; `dropped_before`: writes the device lost just before this batch; `device`: the name of the scene's device it reached, empty if none answers that address) |
//! | `events.csv` | `host_ns,event,detail`: first a `fault` row per window of the scene's fault schedule (at `host_ns` 0; format: [`margemu_sim::fault_log`]), then `hello_ack`, `configured` (credit, batch, lead), `start` (`start_host_ns`), `host_rx_errors` (the host's receive counters after a damaged or lost device frame), `resend` (a go-back-N: the device's `next_index` and when that item was last written), `resend_out_of_window` (a hole older than the items the session keeps: not resent), `device_error`, `device_reset`, `stopped` or `stop_unconfirmed`, and last `end` (`completed` or `error: …`); with a device under test, a `dut` row (its reader's summary) follows `end` |
//!
//! With [`StreamConfig::mcap`](super::StreamConfig::mcap), `session.mcap` is written beside
//! them, by the same writer, from the same rows (`super::mcap_log`).
//!
//! `meta.toml` ends with the `[completion]` table (status, samples written, why the session
//! ended; [`margemu_sim::rundir`]), written once every file is closed: after the session, or after
//! the device under test's reader when one is attached.

use super::clipping::{ClippingWriter, Clips};
use super::device_truth::DeviceTruthWriter;
use super::mcap_log::SessionMcap;
use margemu_model::sensor;
use margemu_protocol::link::{Bus, Image, RegisterWrite, ServedSample, Telemetry};
use margemu_sim::meta::{Appended, SessionMeta};
use margemu_sim::output::{TruthWriter, TRUTH_FILE};
use margemu_sim::scene::rig::Device;
use margemu_sim::truth::Truth;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// `sent.csv`.
pub const SENT_FILE: &str = "sent.csv";
/// `served.csv`.
pub const SERVED_FILE: &str = "served.csv";
/// `device.csv`.
pub const DEVICE_FILE: &str = "device.csv";
/// `telemetry.csv`.
pub const TELEMETRY_FILE: &str = "telemetry.csv";
/// `register_writes.csv`.
pub const REGISTER_WRITES_FILE: &str = "register_writes.csv";
/// `events.csv` (its fault rows: [`margemu_sim::fault_log`]).
pub const EVENTS_FILE: &str = margemu_sim::fault_log::EVENTS_FILE;

/// The files of a session besides `meta.toml`.
pub const SESSION_FILES: [&str; 9] = [
    TRUTH_FILE,
    super::device_truth::DEVICE_TRUTH_FILE,
    super::clipping::CLIPPING_FILE,
    SENT_FILE,
    SERVED_FILE,
    DEVICE_FILE,
    TELEMETRY_FILE,
    REGISTER_WRITES_FILE,
    EVENTS_FILE,
];

/// Header of `sent.csv` in source mode images, for one chip.
pub const SENT_COLUMNS: &str = "index,t_ns,send_ns,late_ns,image,resend";

/// What `sent.csv` holds: the source mode's items.
#[derive(Clone, Debug, PartialEq)]
pub enum SentLayout {
    /// Register images: one chip (`image`), or a rig's devices, each `(name, image length)`,
    /// one `image.NAME` column each, in device order.
    Images(Vec<(String, usize)>),
    /// Kinematics for the device's model.
    Kinematics,
}

impl SentLayout {
    /// The header line.
    pub fn columns(&self) -> String {
        match self {
            Self::Images(devices) if devices.len() > 1 => {
                let images: Vec<String> = devices
                    .iter()
                    .map(|(name, _)| format!("image.{name}"))
                    .collect();
                format!("index,t_ns,send_ns,late_ns,{},resend", images.join(","))
            }
            Self::Images(_) => SENT_COLUMNS.to_owned(),
            Self::Kinematics => SENT_KINEMATICS_COLUMNS.to_owned(),
        }
    }
}
/// Header of `sent.csv` in source mode model.
pub const SENT_KINEMATICS_COLUMNS: &str =
    "index,t_ns,send_ns,late_ns,wx,wy,wz,fx,fy,fz,mx,my,mz,dwx,dwy,dwz,temp_c,resend";
/// Header of `served.csv`.
pub const SERVED_COLUMNS: &str = "host_ns,index,time_ns,crc32c,underrun,empty,match";
/// Header of `device.csv`.
pub const DEVICE_COLUMNS: &str =
    "host_ns,device_time_ns,samples_served,index,served_time_ns,t_ns,underruns";
/// Header of `telemetry.csv`.
pub const TELEMETRY_COLUMNS: &str = "host_ns,seq,time_ns,state,samples_served,underruns,overruns,crc_errors,framing_errors,lost_frames,rejected_messages,buffer_level,next_index,credit_limit,last_served_index,last_served_time_ns";
/// Header of `register_writes.csv`.
pub const REGISTER_WRITES_COLUMNS: &str =
    "host_ns,time_ns,bus,address,register,value,dropped_before,device";

/// A device of the session, as `register_writes.csv` names the device each write reached.
#[derive(Clone, Debug, PartialEq)]
pub struct WrittenDevice {
    /// Its name (the scene's `name`, or its model's).
    pub name: String,
    /// SPI writes of this chip select reach it (device 0: 0, as the device reports them).
    pub chip_select: Option<u8>,
    /// I2C writes to these addresses reach it (an MPU-9250's AK8963 included).
    pub i2c_addresses: Vec<u8>,
}

/// The name of the device a write of `bus` to `address` (an SPI write: its chip select)
/// reached: the first of `devices` that answers it; the auxiliary master's writes are device 0's.
fn written_device(devices: &[WrittenDevice], bus: Bus, address: u8) -> &str {
    let found = devices.iter().find(|d| match bus {
        Bus::Spi => d.chip_select == Some(address),
        Bus::I2c => d.i2c_addresses.contains(&address),
        Bus::AuxMaster => true,
    });
    found.map_or("", |d| d.name.as_str())
}
/// Header of `events.csv`.
pub const EVENTS_COLUMNS: &str = margemu_sim::fault_log::EVENTS_COLUMNS;

/// The open CSV files of one session.
pub struct SessionLog {
    dir: PathBuf,
    float: ryu::Buffer,
    sent: BufWriter<File>,
    served: BufWriter<File>,
    device: BufWriter<File>,
    telemetry: BufWriter<File>,
    register_writes: BufWriter<File>,
    events: BufWriter<File>,
    truth: TruthWriter<BufWriter<File>>,
    /// A rig's image lengths, one `sent.csv` column each (empty: one column).
    image_split: Vec<usize>,
    /// Who register writes reach.
    devices: Vec<WrittenDevice>,
    /// A rig's `device_truth.csv`.
    device_truth: Option<DeviceTruthWriter>,
    /// `clipping.csv`.
    clipping: ClippingWriter,
    /// `session.mcap`, when asked for.
    mcap: Option<SessionMcap>,
}

fn create(dir: &Path, name: &str, header: &str) -> io::Result<BufWriter<File>> {
    let mut out = BufWriter::with_capacity(1 << 16, File::create(dir.join(name))?);
    writeln!(out, "{header}")?;
    Ok(out)
}

impl SessionLog {
    /// Creates `dir` and every file, with their headers (`sent`: what `sent.csv` holds), and
    /// writes `meta.toml`; `devices` are the scene's (they name the device of each register
    /// write, and a rig's get their truth in `device_truth.csv`).
    pub fn create(
        dir: &Path,
        meta: &SessionMeta,
        sent: &SentLayout,
        devices: &[Device],
    ) -> io::Result<Self> {
        let image_split = match sent {
            SentLayout::Images(devices) if devices.len() > 1 => {
                devices.iter().map(|(_, len)| *len).collect()
            }
            _ => Vec::new(),
        };
        std::fs::create_dir_all(dir)?;
        margemu_sim::meta::write(dir, meta)?;
        let mut log = Self {
            dir: dir.to_path_buf(),
            float: ryu::Buffer::new(),
            sent: create(dir, SENT_FILE, &sent.columns())?,
            served: create(dir, SERVED_FILE, SERVED_COLUMNS)?,
            device: create(dir, DEVICE_FILE, DEVICE_COLUMNS)?,
            telemetry: create(dir, TELEMETRY_FILE, TELEMETRY_COLUMNS)?,
            register_writes: create(dir, REGISTER_WRITES_FILE, REGISTER_WRITES_COLUMNS)?,
            events: create(dir, EVENTS_FILE, EVENTS_COLUMNS)?,
            truth: TruthWriter::new(BufWriter::with_capacity(
                1 << 16,
                File::create(dir.join(TRUTH_FILE))?,
            ))?,
            image_split,
            devices: written_devices(devices),
            device_truth: DeviceTruthWriter::create(dir, devices)?,
            clipping: ClippingWriter::create(
                dir,
                &devices.iter().map(|d| d.name.clone()).collect::<Vec<_>>(),
            )?,
            mcap: None,
        };
        log.flush()?;
        Ok(log)
    }

    /// Also writes `session.mcap` from now on.
    pub(super) fn with_mcap(mut self, mcap: SessionMcap) -> Self {
        self.mcap = Some(mcap);
        self
    }

    /// Start was sent at `host_ns` (`session.mcap`'s events are at scene time from now on).
    pub(super) fn started(&mut self, host_ns: i64) {
        if let Some(m) = &mut self.mcap {
            m.started(host_ns);
        }
    }

    /// The device under test's attitude, received at `host_ns` (`session.mcap` only).
    pub(super) fn dut_attitude(&mut self, host_ns: i64, q: [f64; 4]) -> io::Result<()> {
        match &mut self.mcap {
            Some(m) => m.dut_attitude(host_ns, q),
            None => Ok(()),
        }
    }

    /// The session directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Appends `table` to `meta.toml`.
    pub fn append_meta(&mut self, table: Appended<'_>) -> io::Result<()> {
        margemu_sim::meta::append(&self.dir, table)
    }

    /// Rows of `truth.csv` (and a rig's `device_truth.csv`), in order.
    pub fn truth(&mut self, truths: &[Truth]) -> io::Result<()> {
        truths.iter().try_for_each(|t| self.truth.write(t))?;
        if let Some(m) = &mut self.mcap {
            m.truth(truths)?;
        }
        match &mut self.device_truth {
            Some(d) => d.write(truths),
            None => Ok(()),
        }
    }

    /// Each output sample's clipping counters (`t_ns`, every device's), in order.
    pub fn clipping(&mut self, clips: &[(u64, Clips)]) -> io::Result<()> {
        clips
            .iter()
            .try_for_each(|(t_ns, c)| self.clipping.write(*t_ns, c))
    }

    /// One row of `sent.csv` in source mode images.
    pub fn sent_image(
        &mut self,
        index: u64,
        t_ns: u64,
        send_ns: i64,
        late_ns: Option<i64>,
        image: &Image,
        resend: bool,
    ) -> io::Result<()> {
        self.sent_times(index, t_ns, send_ns, late_ns)?;
        let mut rest: &[u8] = image;
        for len in &self.image_split {
            let (device, others) = rest.split_at((*len).min(rest.len()));
            self.sent.write_all(b",")?;
            device
                .iter()
                .try_for_each(|b| write!(self.sent, "{b:02x}"))?;
            rest = others;
        }
        if self.image_split.is_empty() {
            write!(self.sent, ",{image:x}")?;
        }
        if let (Some(m), false) = (&mut self.mcap, resend) {
            m.image(t_ns, image)?;
        }
        writeln!(self.sent, ",{}", u8::from(resend))
    }

    /// One row of `sent.csv` in source mode model.
    pub fn sent_kinematics(
        &mut self,
        index: u64,
        t_ns: u64,
        send_ns: i64,
        late_ns: Option<i64>,
        k: &sensor::Truth,
        resend: bool,
    ) -> io::Result<()> {
        self.sent_times(index, t_ns, send_ns, late_ns)?;
        let values = k
            .angular_rate
            .iter()
            .chain(&k.specific_force)
            .chain(&k.magnetic_field)
            .chain(&k.angular_acceleration)
            .chain(&k.temperature_c);
        for v in values {
            write!(self.sent, ",{}", self.float.format(*v))?;
        }
        if k.temperature_c.is_none() {
            self.sent.write_all(b",")?;
        }
        writeln!(self.sent, ",{}", u8::from(resend))
    }

    fn sent_times(
        &mut self,
        index: u64,
        t_ns: u64,
        send_ns: i64,
        late_ns: Option<i64>,
    ) -> io::Result<()> {
        let late = late_ns.map_or(String::new(), |v| v.to_string());
        write!(self.sent, "{index},{t_ns},{send_ns},{late}")
    }

    /// One row of `served.csv`; `matches` is `None` after the scene's last sample.
    pub fn served(
        &mut self,
        host_ns: i64,
        index: u64,
        time_ns: u64,
        entry: &ServedSample,
        matches: Option<bool>,
    ) -> io::Result<()> {
        let matches = matches.map_or("", |m| if m { "1" } else { "0" });
        writeln!(
            self.served,
            "{host_ns},{index},{time_ns},{:08x},{},{},{matches}",
            entry.crc32c,
            u8::from(entry.underrun),
            u8::from(entry.empty)
        )
    }

    /// A Telemetry: one row of `telemetry.csv` and, once samples were served, of `device.csv`
    /// (`t_ns` is the host's latch instant of the last served index).
    pub fn telemetry(
        &mut self,
        host_ns: i64,
        seq: u16,
        t: &Telemetry,
        t_ns: Option<u64>,
    ) -> io::Result<()> {
        writeln!(
            self.telemetry,
            "{host_ns},{seq},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            t.time_ns,
            t.state as u8,
            t.samples_served,
            t.underruns,
            t.overruns,
            t.crc_errors,
            t.framing_errors,
            t.lost_frames,
            t.rejected_messages,
            t.buffer_level,
            t.next_index,
            t.credit_limit,
            t.last_served_index,
            t.last_served_time_ns
        )?;
        if t.samples_served > 0 {
            let t_ns = t_ns.map_or(String::new(), |v| v.to_string());
            writeln!(
                self.device,
                "{host_ns},{},{},{},{},{t_ns},{}",
                t.time_ns,
                t.samples_served,
                t.last_served_index,
                t.last_served_time_ns,
                t.underruns
            )?;
        }
        Ok(())
    }

    /// Rows of `register_writes.csv`.
    pub fn register_writes(
        &mut self,
        host_ns: i64,
        dropped: u32,
        writes: &[RegisterWrite],
    ) -> io::Result<()> {
        for w in writes {
            let bus = match w.bus {
                Bus::Spi => "spi",
                Bus::I2c => "i2c",
                Bus::AuxMaster => "aux",
            };
            let device = written_device(&self.devices, w.bus, w.address);
            writeln!(
                self.register_writes,
                "{host_ns},{},{bus},{},{},{},{dropped},{device}",
                w.time_ns, w.address, w.register, w.value
            )?;
        }
        Ok(())
    }

    /// One row of `events.csv` (commas in `detail` become semicolons).
    pub fn event(&mut self, host_ns: i64, event: &str, detail: &str) -> io::Result<()> {
        if let Some(m) = &mut self.mcap {
            m.event(host_ns, event, detail)?;
        }
        writeln!(
            self.events,
            "{host_ns},{event},{}",
            detail.replace([',', '\n'], ";")
        )
    }

    /// Writes what closes a file (the clipping totals, `session.mcap`'s summary) and flushes
    /// every file.
    pub fn close(&mut self) -> io::Result<()> {
        self.clipping.finish()?;
        if let Some(m) = self.mcap.take() {
            m.finish()?;
        }
        self.flush()
    }

    /// Flushes every file to the operating system.
    pub fn flush(&mut self) -> io::Result<()> {
        self.clipping.flush()?;
        self.sent.flush()?;
        self.served.flush()?;
        self.device.flush()?;
        self.telemetry.flush()?;
        self.register_writes.flush()?;
        self.truth.flush()?;
        if let Some(d) = &mut self.device_truth {
            d.flush()?;
        }
        if let Some(m) = &mut self.mcap {
            m.flush()?;
        }
        self.events.flush()
    }
}

/// The scene's devices as `register_writes.csv` names them: device 0 on chip select 0 (the
/// device reports its SPI writes so), the others on their own; every I2C address each answers.
fn written_devices(devices: &[Device]) -> Vec<WrittenDevice> {
    use margemu_sim::scene::chip::BusKind;
    devices
        .iter()
        .enumerate()
        .map(|(i, d)| {
            let chip = d.chip;
            let chip_select = match (i, chip.bus) {
                (0, _) => Some(0),
                (_, BusKind::Spi) => Some(chip.chip_select),
                (_, BusKind::I2c) => None,
            };
            let mut i2c_addresses = vec![chip.i2c_address];
            if chip.model.has_magnetometer() && !chip.model.is_magnetometer_only() {
                i2c_addresses.push(margemu_protocol::regmap::ak8963::I2C_ADDRESS);
            }
            WrittenDevice {
                name: d.name.clone(),
                chip_select,
                i2c_addresses,
            }
        })
        .collect()
}
