//! MCAP output of runs and sessions: ROS 2 messages (`ros2msg` schemas, CDR) that Foxglove
//! opens and `ros2 bag play` replays, written beside the CSV files, which stay the record that
//! `evaluate` reads.
//!
//! One writer ([`McapLog`]) serves `simulate` (`run.mcap`) and the streaming sessions
//! (`session.mcap`). Its channels (schemas: [`schema`]; CDR encoding: `cdr`):
//!
//! | topic | type | frame | content |
//! |---|---|---|---|
//! | `/truth/pose` | `geometry_msgs/msg/PoseStamped` | `world` | plate position (m) and attitude |
//! | `/truth/twist` | `geometry_msgs/msg/TwistStamped` | `plate` | velocity (m/s) and body rate (rad/s), plate axes |
//! | `/truth/imu` | `sensor_msgs/msg/Imu` | `plate` | attitude, true body rate, true specific force (m/s²) |
//! | `/tf` | `tf2_msgs/msg/TFMessage` | `world` | `world`→`plate` with each truth sample, `world`→`dut` with each attitude of the device under test |
//! | `/<device>/imu` | `sensor_msgs/msg/Imu` | the device's | the MARG sample's gyroscope and accelerometer; orientation unknown (`orientation_covariance[0] = -1`) |
//! | `/<device>/mag` | `sensor_msgs/msg/MagneticField` | the device's | the magnetometer in tesla: µT ÷ 10⁶, a normalized scene's field at [`UT_PER_NU`] (a session's: its `mag_ut_per_unit`), the scale in the channel's `tesla_per_unit` metadata |
//! | `/dut/attitude` | `geometry_msgs/msg/PoseStamped` | `world` | the device under test's attitude (position zero) |
//! | `/events` | `std_msgs/msg/String` | | `event: detail` |
//!
//! `world` is margemu's world frame (NWU, z up with the default field); quaternions are written
//! in ROS order `(x, y, z, w)` from margemu's `(w, x, y, z)`, body to world, which is what a
//! pose's orientation means in ROS. Every message's log time, publish time and header stamp
//! is the scene time of its sample in nanoseconds; a `margemu` metadata record names the
//! scene, seed, frame, field unit and scale, and which clock the times are on.
//!
//! Messages go into uncompressed chunks (the `mcap` crate without its zstd and lz4 features:
//! no C libraries to build). [`McapLog::flush`] ends the open chunk and flushes it to the file,
//! so a writer that stops without [`McapLog::finish`] (a killed process) leaves a file whose
//! complete chunks a streaming reader reads, though it lacks the summary an indexed reader needs
//! (`mcap recover` rebuilds it). Errors are `io::Error`s, as the CSV writers' are.
//!
//! Sources: the MCAP specification and its well-known encodings registry (mcap.dev/spec), the
//! `mcap` crate's API (MIT), the ROS 2 message definitions (`common_interfaces`, Apache-2.0).

pub(crate) mod cdr;
pub mod schema;

use crate::scene::FieldUnit;
use crate::truth::Truth;
use cdr::Cdr;
use schema::MsgType;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{self, BufWriter, Seek, Write};
use std::path::Path;

/// `simulate`'s MCAP file.
pub const RUN_MCAP: &str = "run.mcap";
/// A session's MCAP file.
pub const SESSION_MCAP: &str = "session.mcap";
/// The MCAP files margemu writes (what `--force` may remove).
pub const FILES: [&str; 2] = [RUN_MCAP, SESSION_MCAP];
/// The world frame's id.
pub const WORLD_FRAME: &str = "world";
/// The plate's frame id.
pub const PLATE_FRAME: &str = "plate";
/// The device under test's frame id.
pub const DUT_FRAME: &str = "dut";
/// Microtesla per normalized unit ("nu"): 50 µT, about the Earth's field, which the normalized
/// reference field `(0.5, 0, −0.83)` approximates at unit norm. The scale `/<device>/mag`
/// converts with, and the one register images of normalized scenes are encoded with.
pub const UT_PER_NU: f64 = 50.0;

/// The truth topics, `/tf` and `/events`: the topics every file has.
pub const FIXED_TOPICS: [&str; 5] = [
    "/truth/pose",
    "/truth/twist",
    "/truth/imu",
    "/tf",
    "/events",
];
/// The device under test's attitude topic (with a `--dut` reader).
pub const DUT_TOPIC: &str = "/dut/attitude";

/// µT per unit of `unit`: 1 for µT, [`UT_PER_NU`] for "nu".
pub fn ut_per_unit(unit: FieldUnit) -> f64 {
    match unit {
        FieldUnit::Microtesla => 1.0,
        FieldUnit::Normalized => UT_PER_NU,
    }
}

/// A device's topic prefix: its name, lowercase, with every character but ASCII letters, digits
/// and `_` made `_` (ROS topic names allow no others), and a leading digit prefixed by `d`.
///
/// ```
/// assert_eq!(margemu_sim::mcap::topic_name("MPU-9250 front"), "mpu_9250_front");
/// assert_eq!(margemu_sim::mcap::topic_name("9dof"), "d9dof");
/// ```
pub fn topic_name(device: &str) -> String {
    let mut s: String = device
        .chars()
        .map(|c| match c.to_ascii_lowercase() {
            c @ ('a'..='z' | '0'..='9' | '_') => c,
            _ => '_',
        })
        .collect();
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert(0, 'd');
    }
    s
}

/// What a file is about: its metadata record and its channels.
#[derive(Clone, Debug)]
pub struct McapSetup {
    /// The scene's name.
    pub scene: String,
    /// The scene's seed.
    pub seed: u64,
    /// The scene's field unit.
    pub field_unit: FieldUnit,
    /// µT per unit of the scene's field ([`ut_per_unit`], or a session's own scale).
    pub ut_per_unit: f64,
    /// The devices whose MARG samples are written: name and frame id of its axes.
    pub devices: Vec<(String, String)>,
    /// Which clock the times are on (the metadata's `time`).
    pub clock: String,
}

/// One MARG reading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MargReading {
    /// Latch instant, scene time (ns).
    pub t_ns: u64,
    /// Accelerometer (m/s²).
    pub acc: [f64; 3],
    /// Gyroscope (rad/s).
    pub gyr: [f64; 3],
    /// Magnetometer (µT); `None` for a chip without one (no `/<device>/mag` message).
    pub mag_ut: Option<[f64; 3]>,
}

/// The ids of the channels of [`FIXED_TOPICS`].
#[derive(Default)]
struct Channels {
    pose: u16,
    twist: u16,
    imu: u16,
    tf: u16,
    events: u16,
}

struct DeviceChannels {
    imu: u16,
    mag: u16,
    frame: String,
}

/// An MCAP file being written.
pub struct McapLog<W: Write + Seek = BufWriter<File>> {
    out: mcap::Writer<W>,
    /// Schema ids by type name.
    schemas: BTreeMap<&'static str, u16>,
    channels: Channels,
    /// `/dut/attitude`, added with its first message.
    dut: Option<u16>,
    devices: Vec<DeviceChannels>,
    /// Messages written per channel id (the next sequence number).
    sequence: Vec<u32>,
    /// Messages written since the last chunk ended.
    pending: bool,
    buf: Vec<u8>,
}

fn mcap_err(e: mcap::McapError) -> io::Error {
    match e {
        mcap::McapError::Io(e) => e,
        e => io::Error::other(e),
    }
}

impl McapLog {
    /// Creates `path` and writes the header, schemas, channels and metadata.
    pub fn create(path: &Path, setup: &McapSetup) -> io::Result<Self> {
        let file = File::create(path)?;
        Self::new(BufWriter::with_capacity(1 << 16, file), setup)
    }
}

impl<W: Write + Seek> McapLog<W> {
    /// Starts a file in `out`: header, schemas, channels and metadata.
    pub fn new(out: W, setup: &McapSetup) -> io::Result<Self> {
        let out = mcap::WriteOptions::new()
            .compression(None)
            .profile("ros2")
            .library(concat!("margemu ", env!("CARGO_PKG_VERSION")))
            .create(out)
            .map_err(mcap_err)?;
        let mut log = Self {
            out,
            schemas: BTreeMap::new(),
            channels: Channels::default(),
            dut: None,
            devices: Vec::new(),
            sequence: Vec::new(),
            pending: false,
            buf: Vec::with_capacity(512),
        };
        let none = BTreeMap::new();
        let [pose, twist, imu, tf, events] = FIXED_TOPICS;
        log.channels = Channels {
            pose: log.channel(pose, &schema::POSE_STAMPED, &none)?,
            twist: log.channel(twist, &schema::TWIST_STAMPED, &none)?,
            imu: log.channel(imu, &schema::IMU, &none)?,
            tf: log.channel(tf, &schema::TF_MESSAGE, &none)?,
            events: log.channel(events, &schema::STRING, &none)?,
        };
        let tesla = (setup.ut_per_unit / 1e6).to_string();
        let mag_meta = BTreeMap::from([
            (
                "scene_field_unit".to_string(),
                setup.field_unit.symbol().to_string(),
            ),
            ("tesla_per_unit".to_string(), tesla.clone()),
        ]);
        for (name, frame) in &setup.devices {
            let prefix = topic_name(name);
            let d = DeviceChannels {
                imu: log.channel(&format!("/{prefix}/imu"), &schema::IMU, &none)?,
                mag: log.channel(
                    &format!("/{prefix}/mag"),
                    &schema::MAGNETIC_FIELD,
                    &mag_meta,
                )?,
                frame: frame.clone(),
            };
            log.devices.push(d);
        }
        let metadata = BTreeMap::from([
            ("scene".to_string(), setup.scene.clone()),
            ("seed".to_string(), setup.seed.to_string()),
            ("world_frame".to_string(), "world: NWU, z up".to_string()),
            (
                "field_unit".to_string(),
                setup.field_unit.symbol().to_string(),
            ),
            ("tesla_per_unit".to_string(), tesla),
            ("time".to_string(), setup.clock.clone()),
        ]);
        log.out
            .write_metadata(&mcap::records::Metadata {
                name: "margemu".to_string(),
                metadata,
            })
            .map_err(mcap_err)?;
        Ok(log)
    }

    /// A new channel on `topic` of type `t` (its schema written once).
    fn channel(
        &mut self,
        topic: &str,
        t: &MsgType,
        meta: &BTreeMap<String, String>,
    ) -> io::Result<u16> {
        let schema = match self.schemas.get(t.name) {
            Some(id) => *id,
            None => {
                let text = t.schema_text();
                let id = self
                    .out
                    .add_schema(t.name, "ros2msg", text.as_bytes())
                    .map_err(mcap_err)?;
                self.schemas.insert(t.name, id);
                id
            }
        };
        let id = self
            .out
            .add_channel(schema, topic, "cdr", meta)
            .map_err(mcap_err)?;
        self.sequence.resize(usize::from(id) + 1, 0);
        Ok(id)
    }

    fn put(&mut self, channel: u16, t_ns: u64) -> io::Result<()> {
        let slot = &mut self.sequence[usize::from(channel)];
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: *slot,
            log_time: t_ns,
            publish_time: t_ns,
        };
        *slot = slot.wrapping_add(1);
        self.pending = true;
        self.out
            .write_to_known_channel(&header, &self.buf)
            .map_err(mcap_err)
    }

    /// One truth sample: `/truth/pose`, `/truth/twist`, `/truth/imu` and `/tf` world→plate.
    pub fn truth(&mut self, t: &Truth) -> io::Result<()> {
        let q = ros_quaternion(&t.quaternion);
        Cdr::new(&mut self.buf)
            .header(t.t_ns, WORLD_FRAME)
            .f64s(&t.position)
            .f64s(&q);
        self.put(self.channels.pose, t.t_ns)?;
        let v_body = body_vector(&t.quaternion, &t.velocity);
        Cdr::new(&mut self.buf)
            .header(t.t_ns, PLATE_FRAME)
            .f64s(&v_body)
            .f64s(&t.body_rate);
        self.put(self.channels.twist, t.t_ns)?;
        Cdr::new(&mut self.buf)
            .header(t.t_ns, PLATE_FRAME)
            .f64s(&q)
            .f64s(&[0.0; 9])
            .f64s(&t.body_rate)
            .f64s(&[0.0; 9])
            .f64s(&t.specific_force)
            .f64s(&[0.0; 9]);
        self.put(self.channels.imu, t.t_ns)?;
        self.transform(t.t_ns, PLATE_FRAME, &t.position, &q)
    }

    fn transform(&mut self, t_ns: u64, child: &str, p: &[f64; 3], q: &[f64; 4]) -> io::Result<()> {
        Cdr::new(&mut self.buf)
            .u32(1)
            .header(t_ns, WORLD_FRAME)
            .string(child)
            .f64s(p)
            .f64s(q);
        self.put(self.channels.tf, t_ns)
    }

    /// One MARG sample of device `device` (its index in [`McapSetup::devices`]):
    /// `/<device>/imu` and `/<device>/mag`. An unknown index is an error.
    pub fn marg(&mut self, device: usize, r: &MargReading) -> io::Result<()> {
        let Some(d) = self.devices.get(device) else {
            return Err(io::Error::other(format!(
                "no MCAP channels for device {device}"
            )));
        };
        let (imu, mag) = (d.imu, d.mag);
        let mut unknown = [0.0; 9];
        unknown[0] = -1.0;
        Cdr::new(&mut self.buf)
            .header(r.t_ns, &d.frame)
            .f64s(&[0.0; 4])
            .f64s(&unknown)
            .f64s(&r.gyr)
            .f64s(&[0.0; 9])
            .f64s(&r.acc)
            .f64s(&[0.0; 9]);
        self.put(imu, r.t_ns)?;
        let Some(mag_ut) = r.mag_ut else {
            return Ok(());
        };
        Cdr::new(&mut self.buf)
            .header(r.t_ns, &self.devices[device].frame)
            .f64s(&mag_ut.map(|b| b / 1e6))
            .f64s(&[0.0; 9]);
        self.put(mag, r.t_ns)
    }

    /// The device under test's attitude `q` (`(w, x, y, z)`, body to world) at `t_ns`:
    /// `/dut/attitude` (its channel added with the first) and `/tf` world→dut.
    pub fn dut_attitude(&mut self, t_ns: u64, q: &[f64; 4]) -> io::Result<()> {
        let dut = match self.dut {
            Some(id) => id,
            None => {
                let id = self.channel(DUT_TOPIC, &schema::POSE_STAMPED, &BTreeMap::new())?;
                *self.dut.insert(id)
            }
        };
        let q = ros_quaternion(q);
        Cdr::new(&mut self.buf)
            .header(t_ns, WORLD_FRAME)
            .f64s(&[0.0; 3])
            .f64s(&q);
        self.put(dut, t_ns)?;
        self.transform(t_ns, DUT_FRAME, &[0.0; 3], &q)
    }

    /// An event at `t_ns`: `/events`, `event: detail` (`event` alone if `detail` is empty).
    pub fn event(&mut self, t_ns: u64, event: &str, detail: &str) -> io::Result<()> {
        let text = match detail {
            "" => event.to_string(),
            d => format!("{event}: {d}"),
        };
        Cdr::new(&mut self.buf).string(&text);
        self.put(self.channels.events, t_ns)
    }

    /// Ends the open chunk (if a message was written since the last) and flushes the file, so
    /// a reader sees every message so far.
    pub fn flush(&mut self) -> io::Result<()> {
        if std::mem::take(&mut self.pending) {
            self.out.flush().map_err(mcap_err)?;
        }
        Ok(())
    }

    /// Writes the last chunk, the summary and the footer; returns the file's writer.
    pub fn finish(mut self) -> io::Result<W> {
        self.out.finish().map_err(mcap_err)?;
        Ok(self.out.into_inner())
    }
}

/// `(w, x, y, z)` to ROS order `(x, y, z, w)`.
fn ros_quaternion(q: &[f64; 4]) -> [f64; 4] {
    [q[1], q[2], q[3], q[0]]
}

/// `v` (world frame) in the body axes of attitude `q` (body to world): `q* ⊗ v ⊗ q`.
fn body_vector(q: &[f64; 4], v: &[f64; 3]) -> [f64; 3] {
    let q =
        nalgebra::UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]));
    let b = q.inverse_transform_vector(&nalgebra::Vector3::from(*v));
    [b.x, b.y, b.z]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::RefCell;
    use std::io::{Cursor, SeekFrom};
    use std::rc::Rc;

    /// A file in memory that the test can read while the writer still holds it.
    #[derive(Clone, Default)]
    struct Shared(Rc<RefCell<Cursor<Vec<u8>>>>);

    impl Write for Shared {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            self.0.borrow_mut().write(buf)
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    impl Seek for Shared {
        fn seek(&mut self, pos: SeekFrom) -> io::Result<u64> {
            self.0.borrow_mut().seek(pos)
        }
    }

    fn setup() -> McapSetup {
        McapSetup {
            scene: "s".into(),
            seed: 1,
            field_unit: FieldUnit::Normalized,
            ut_per_unit: UT_PER_NU,
            devices: vec![("MPU-9250".into(), PLATE_FRAME.into())],
            clock: "scene time".into(),
        }
    }

    fn truth(t_ns: u64) -> Truth {
        Truth {
            t_ns,
            quaternion: [1.0, 0.0, 0.0, 0.0],
            ..Truth::default()
        }
    }

    #[test]
    fn a_file_left_unfinished_holds_every_message_up_to_the_last_flush() {
        let file = Shared::default();
        let mut log = McapLog::new(file.clone(), &setup()).unwrap();
        for k in 0..10 {
            log.truth(&truth(k * 1_000_000)).unwrap();
        }
        log.flush().unwrap();
        log.truth(&truth(10_000_000)).unwrap();
        // The process dies here: no finish, no summary, no footer, no end magic.
        let bytes = file.0.borrow().get_ref().clone();
        let read = mcap::MessageStream::new_with_options(
            &bytes,
            mcap::read::Options::IgnoreEndMagic.into(),
        )
        .unwrap();
        let times: Vec<u64> = read
            .map_while(Result::ok)
            .filter(|m| m.channel.topic == "/truth/pose")
            .map(|m| m.log_time)
            .collect();
        assert_eq!(times, (0..10).map(|k| k * 1_000_000).collect::<Vec<_>>());
        drop(log);
    }

    #[test]
    fn a_finished_file_has_every_channel_and_the_dut_channel_once_used() {
        let file = Shared::default();
        let mut log = McapLog::new(file.clone(), &setup()).unwrap();
        log.truth(&truth(5)).unwrap();
        log.dut_attitude(7, &[1.0, 0.0, 0.0, 0.0]).unwrap();
        log.event(9, "end", "").unwrap();
        let reading = MargReading {
            t_ns: 5,
            acc: [0.0; 3],
            gyr: [0.0; 3],
            mag_ut: None,
        };
        log.marg(0, &reading).unwrap();
        assert!(log.marg(1, &reading).is_err(), "no such device");
        log.finish().unwrap();
        let bytes = file.0.borrow().get_ref().clone();
        let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
        let mut topics: Vec<&str> = summary.channels.values().map(|c| &*c.topic).collect();
        topics.sort();
        assert_eq!(
            topics,
            [
                "/dut/attitude",
                "/events",
                "/mpu_9250/imu",
                "/mpu_9250/mag",
                "/tf",
                "/truth/imu",
                "/truth/pose",
                "/truth/twist"
            ]
        );
        let counts = &summary.stats.unwrap().channel_message_counts;
        let count = |topic: &str| {
            let id = summary
                .channels
                .values()
                .find(|c| c.topic == topic)
                .unwrap()
                .id;
            counts.get(&id).copied().unwrap_or(0)
        };
        // No magnetometer: an IMU message and no field.
        assert_eq!((count("/mpu_9250/imu"), count("/mpu_9250/mag")), (1, 0));
        assert_eq!(count("/tf"), 2);
    }
}
