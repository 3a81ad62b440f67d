//! [`HitlSession`]: one HITL run. [`HitlSession::new`] checks the scene and writes the head of
//! the session directory; [`HitlSession::run`] sends the scene over any writer, paced on any
//! [`Pacer`], and closes its files.
//!
//! # Files
//!
//! Host times are nanoseconds on the session's clock (the device-under-test reader's origin),
//! as in every session ([`crate::stream::log`]).
//!
//! | file | columns |
//! |---|---|
//! | `meta.toml` | a session's ([`margemu_sim::meta::SessionMeta`]) with `source = "hil_sensor"`, `port` the port's path or `udp:HOST:PORT`, `baud` (0 for UDP), `mag_ut_per_unit` = 100 × gauss per unit; the `[chip]` table describes the scene's chip, which is not emulated; `[dut]` and `[completion]` appended at the end |
//! | `truth.csv` | as `simulate` writes it, one row per sample sent |
//! | `hil_sensor.csv` | [`HIL_SENSOR_COLUMNS`]: sample index, scene time, when its write returned (`send_ns`) and how late that was against `start_host_ns + t_ns` (`late_ns`), then every field as sent (`f32`, shortest round trip) and `fields_updated` in decimal |
//! | `events.csv` | `host_ns,event,detail`: `pacing` (the real-time pacing obtained, [`crate::realtime`]), `start` (`start_host_ns N; …`, scene time 0), `end` (`completed`, `interrupted` or `error: …`), then the reader's `dut` row |
//! | `dut_*.csv` | the flight controller's replies ([`crate::dut`]) |

use super::message::{gauss_per_unit, heartbeat, SensorMapping, GAUSS_PER_MICROTESLA};
use super::pace::Pacer;
use super::{HitlConfig, HitlError};
use crate::dut::mavlink_out::MavlinkWriter;
use crate::realtime::{self, Obtained, Realtime, SystemScheduler};
use crate::stream::images::ImageSettings;
use crate::stream::log::EVENTS_FILE;
use crate::stream::{rate_of, StreamConfig};
use margemu_sim::marg::MargSim;
use margemu_sim::output::{TruthWriter, TRUTH_FILE};
use margemu_sim::run::RunError;
use margemu_sim::rundir::{CompletionRecord, Status};
use margemu_sim::scene::Scene;
use margemu_sim::truth::Truth;
use mavlink::dialects::common::{MavMessage, HIL_SENSOR_DATA};
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// `hil_sensor.csv`.
pub const HIL_SENSOR_FILE: &str = "hil_sensor.csv";

/// The columns of `hil_sensor.csv`.
pub const HIL_SENSOR_COLUMNS: [&str; 18] = [
    "index",
    "t_ns",
    "send_ns",
    "late_ns",
    "time_usec",
    "xacc",
    "yacc",
    "zacc",
    "xgyro",
    "ygyro",
    "zgyro",
    "xmag",
    "ymag",
    "zmag",
    "abs_pressure",
    "pressure_alt",
    "temperature",
    "fields_updated",
];

/// The files a HITL session writes besides `meta.toml`, `events.csv`, `truth.csv` and the
/// device under test's (which other lists hold).
pub const HITL_FILES: [&str; 1] = [HIL_SENSOR_FILE];

/// The MAVLink ids margemu sends as: system 255, component 190 (`MAV_COMP_ID_MISSIONPLANNER`),
/// what a ground station on the link would use, so PX4 never takes it for itself.
pub const SENDER_IDS: (u8, u8) = (255, 190);

/// A HITL session, ready to run (see the module docs).
pub struct HitlSession<'a> {
    scene: &'a Scene,
    dir: PathBuf,
    mapping: SensorMapping,
    start_delay_ns: u64,
    realtime: Realtime,
    completion: CompletionRecord,
}

/// What a finished run sent.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct HitlSummary {
    /// HIL_SENSOR messages written (one per scene sample).
    pub samples: u64,
    /// HEARTBEATs written.
    pub heartbeats: u64,
    /// Bytes written.
    pub bytes: u64,
    /// Host time of scene time 0 (ns).
    pub start_host_ns: u64,
    /// The latest write against its instant (ns; 0 if none was late).
    pub max_late_ns: u64,
    /// The real-time pacing obtained (`events.csv`'s `pacing` row).
    pub pacing: Obtained,
}

impl<'a> HitlSession<'a> {
    /// Checks that the mode can serve `scene` with `config`, then creates `dir` and writes
    /// `meta.toml`'s head. A field in normalized units is sent at `config.gauss_per_unit`.
    pub fn new(scene: &'a Scene, config: HitlConfig, dir: &Path) -> Result<Self, HitlError> {
        let g = config.gauss_per_unit;
        if !(g.is_finite() && g > 0.0) {
            return Err(HitlError::BadScale(g));
        }
        if scene.clock.hz() > 1e6 {
            return Err(HitlError::RateTooHigh(scene.clock.hz()));
        }
        if let super::Target::Serial { baud, .. } = &config.target {
            super::link::check_line(scene.clock.hz(), *baud)?;
        }
        MargSim::new(scene).map_err(RunError::Model)?;
        let rate = rate_of(scene).map_err(|e| HitlError::Rate(e.to_string()))?;
        let mapping = SensorMapping {
            gauss_per_unit: gauss_per_unit(scene.spec.field.unit, g),
            temperature: scene.spec.sensors.temperature,
        };
        let stream = StreamConfig {
            port: config.target.label(),
            baud: config.target.baud(),
            ..StreamConfig::default()
        };
        let settings = ImageSettings::for_scene(scene);
        let mut meta = crate::stream::meta::metadata(scene, &stream, &settings, rate, None);
        meta.source = "hil_sensor".into();
        meta.lead_ns = 0;
        meta.batch = 1;
        meta.telemetry_period_ns = 0;
        meta.mag_ut_per_unit = mapping.gauss_per_unit / GAUSS_PER_MICROTESLA;
        let meta_path = dir.join(margemu_sim::rundir::META_FILE);
        std::fs::create_dir_all(dir)
            .and_then(|()| margemu_sim::meta::write(dir, &meta))
            .map_err(|source| HitlError::Write {
                path: meta_path,
                source,
            })?;
        Ok(Self {
            scene,
            dir: dir.to_path_buf(),
            mapping,
            start_delay_ns: config.start_delay_ns,
            realtime: config.realtime,
            completion: CompletionRecord::new(dir),
        })
    }

    /// The directory's completion record, for the device-under-test reader to share (it is
    /// written when the last holder lets go).
    pub fn completion_record(&self) -> CompletionRecord {
        self.completion.clone()
    }

    /// Sends the whole scene to `wire`: scene time 0 is `start_delay_ns` after now on `pacer`.
    /// Stops early when `stop` is set (interrupted), and on a write error. Every file is closed
    /// and the completion record updated (and written, unless a reader shares it) however it
    /// ends. The calling thread paces the run at [`HitlConfig::realtime`] (put back at the end;
    /// what it obtained is `events.csv`'s `pacing` row and [`HitlSummary::pacing`]).
    pub fn run<W: Write, P: Pacer>(
        self,
        wire: W,
        pacer: &P,
        stop: &AtomicBool,
    ) -> Result<HitlSummary, HitlError> {
        let Self {
            scene,
            dir,
            mapping,
            start_delay_ns,
            realtime,
            completion,
        } = self;
        let (guard, pacing) = realtime::enter(realtime, Arc::new(SystemScheduler));
        realtime::warn_once(&pacing);
        let mut files = Files::create(&dir)?;
        let start = pacer.now_ns() + start_delay_ns;
        let mut sender = Sender {
            wire,
            writer: MavlinkWriter::v2().with_ids(SENDER_IDS.0, SENDER_IDS.1),
            summary: HitlSummary {
                start_host_ns: start,
                ..HitlSummary::default()
            },
            next_heartbeat_ns: 0,
        };
        let events = |files: &mut Files, host_ns: u64, event: &str, detail: &str| {
            writeln!(files.events, "{host_ns},{event},{detail}")
                .map_err(|e| files.err(EVENTS_FILE, e))
        };
        let detail = format!(
            "start_host_ns {start}; {} samples at {} Hz",
            scene.samples(),
            scene.clock.hz()
        );
        let obtained = pacing.to_string().replace(',', ";");
        events(&mut files, pacer.now_ns(), "pacing", &obtained)?;
        sender.summary.pacing = pacing;
        events(&mut files, pacer.now_ns(), "start", &detail)?;
        let outcome = send_all(scene, &mapping, &mut files, &mut sender, pacer, stop);
        drop(guard);
        let (status, ended) = match &outcome {
            Ok(()) => (Status::Complete, "completed".to_string()),
            Err(HitlError::Run(RunError::Interrupted)) => {
                (Status::Interrupted, "interrupted".to_string())
            }
            Err(e) => (Status::Failed, format!("error: {e}")),
        };
        let closed = events(&mut files, pacer.now_ns(), "end", &ended.replace(',', ";"))
            .and_then(|()| files.close());
        let summary = sender.summary;
        completion.update(|c| {
            c.status = status;
            c.samples_written = summary.samples;
            c.samples_expected = Some(scene.samples());
            c.ended = ended;
        });
        if closed.is_err() {
            completion.update(|c| c.fail("cannot close the session's files"));
        }
        let released = completion.release().map_err(|source| HitlError::Write {
            path: dir.join(margemu_sim::rundir::META_FILE),
            source,
        });
        outcome?;
        closed?;
        released?;
        Ok(summary)
    }
}

/// Computes, logs and sends every sample in order.
fn send_all<W: Write, P: Pacer>(
    scene: &Scene,
    mapping: &SensorMapping,
    files: &mut Files,
    sender: &mut Sender<W>,
    pacer: &P,
    stop: &AtomicBool,
) -> Result<(), HitlError> {
    let mut marg = MargSim::new(scene).map_err(RunError::Model)?;
    let sink = |t: &Truth| -> Result<(), HitlError> {
        if stop.load(Ordering::Relaxed) {
            return Err(RunError::Interrupted.into());
        }
        let sample = marg
            .try_sample(scene, t)
            .map_err(|e| HitlError::Run(RunError::NonFinite(e)))?;
        files.truth.write(t).map_err(|e| files.err(TRUTH_FILE, e))?;
        let message = mapping.message(t, &sample);
        let deadline = sender.summary.start_host_ns + t.t_ns;
        pacer.wait_until(deadline);
        sender.send(t.t_ns, &message)?;
        let send_ns = pacer.now_ns();
        let late = send_ns.saturating_sub(deadline);
        sender.summary.max_late_ns = sender.summary.max_late_ns.max(late);
        let index = sender.summary.samples - 1;
        files
            .row(index, t.t_ns, send_ns, late, &message)
            .map_err(|e| files.err(super::HIL_SENSOR_FILE, e))
    };
    margemu_sim::run::run(scene, sink, |_, _| {}).map_err(RunError::Reference)??;
    Ok(())
}

/// The wire and what went over it.
struct Sender<W> {
    wire: W,
    writer: MavlinkWriter,
    summary: HitlSummary,
    next_heartbeat_ns: u64,
}

impl<W: Write> Sender<W> {
    /// The sample's HIL_SENSOR, after a HEARTBEAT if one is due at scene time `t_ns`.
    fn send(&mut self, t_ns: u64, message: &HIL_SENSOR_DATA) -> Result<(), HitlError> {
        if t_ns >= self.next_heartbeat_ns {
            self.frame(&heartbeat())?;
            self.summary.heartbeats += 1;
            self.next_heartbeat_ns = (t_ns / 1_000_000_000 + 1) * 1_000_000_000;
        }
        self.frame(&MavMessage::HIL_SENSOR(message.clone()))?;
        self.summary.samples += 1;
        Ok(())
    }

    fn frame(&mut self, message: &MavMessage) -> Result<(), HitlError> {
        let sent = self.summary.samples;
        let bytes = self.writer.encode(message).map_err(|e| HitlError::Send {
            sent,
            source: io::Error::other(e.to_string()),
        })?;
        self.wire
            .write_all(&bytes)
            .and_then(|()| self.wire.flush())
            .map_err(|source| HitlError::Send { sent, source })?;
        self.summary.bytes += bytes.len() as u64;
        Ok(())
    }
}

/// The session's CSV files.
struct Files {
    dir: PathBuf,
    truth: TruthWriter<BufWriter<File>>,
    sensor: BufWriter<File>,
    events: BufWriter<File>,
}

impl Files {
    fn create(dir: &Path) -> Result<Self, HitlError> {
        let open = |name: &str| -> Result<BufWriter<File>, HitlError> {
            let path = dir.join(name);
            File::create(&path)
                .map(BufWriter::new)
                .map_err(|source| HitlError::Write { path, source })
        };
        let failed = |name: &str| {
            let path = dir.join(name);
            move |source| HitlError::Write { path, source }
        };
        let truth = TruthWriter::new(open(TRUTH_FILE)?).map_err(failed(TRUTH_FILE))?;
        let mut sensor = open(HIL_SENSOR_FILE)?;
        writeln!(sensor, "{}", HIL_SENSOR_COLUMNS.join(",")).map_err(failed(HIL_SENSOR_FILE))?;
        let mut events = open(EVENTS_FILE)?;
        writeln!(events, "host_ns,event,detail").map_err(failed(EVENTS_FILE))?;
        Ok(Self {
            dir: dir.to_path_buf(),
            truth,
            sensor,
            events,
        })
    }

    fn err(&self, name: &str, source: io::Error) -> HitlError {
        HitlError::Write {
            path: self.dir.join(name),
            source,
        }
    }

    fn row(
        &mut self,
        index: u64,
        t_ns: u64,
        send_ns: u64,
        late_ns: u64,
        m: &HIL_SENSOR_DATA,
    ) -> io::Result<()> {
        let values = [
            m.xacc,
            m.yacc,
            m.zacc,
            m.xgyro,
            m.ygyro,
            m.zgyro,
            m.xmag,
            m.ymag,
            m.zmag,
            m.abs_pressure,
            m.pressure_alt,
            m.temperature,
        ];
        write!(
            self.sensor,
            "{index},{t_ns},{send_ns},{late_ns},{}",
            m.time_usec
        )?;
        for v in values {
            write!(self.sensor, ",{v}")?;
        }
        writeln!(self.sensor, ",{}", m.fields_updated.bits())
    }

    fn close(self) -> Result<(), HitlError> {
        let dir = self.dir;
        let failed = |name: &str| {
            let path = dir.join(name);
            move |source| HitlError::Write { path, source }
        };
        self.truth
            .finish()
            .and_then(|mut w| w.flush())
            .map_err(failed(TRUTH_FILE))?;
        let mut sensor = self.sensor;
        sensor.flush().map_err(failed(HIL_SENSOR_FILE))?;
        let mut events = self.events;
        events.flush().map_err(failed(EVENTS_FILE))
    }
}
