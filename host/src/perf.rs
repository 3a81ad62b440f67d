//! Speed against error, measured on this machine (`margemu bench`).
//!
//! - [`integrator_sweep`]: for each integrator and step, the largest attitude error (geodesic
//!   angle, rad) and position error (m) against a converged reference run (RK4 at a step far
//!   below any in the sweep), and the simulated seconds per wall second of dynamics + ground
//!   truth (no file output).
//! - [`mode_costs`]: the cost per output sample of a static, a kinematic and a bench scene.
//! - [`stream_sweep`]: scenes streamed in real time through a PTY pair to the firmware's link
//!   handler at several rates, in both source modes: samples sent, served byte for byte, lost,
//!   pacing jitter, link efficiency measured on the batches written;
//!   optionally with CPU hogs running ([`hogs`]) and the pacing thread at real-time priority;
//! - [`link_table`]: worst-case link efficiency of image and kinematics batches, and the rates a
//!   UART carries.

pub mod hogs;

use margemu_hil::realtime::{Obtained, Realtime};
use margemu_hil::stream::{JitterStats, ServedStats, SourceMode, StreamConfig};
use margemu_model::time::nanos_from_seconds;
use margemu_sim::reference::ReferenceError;
use margemu_sim::run::for_each;
use margemu_sim::scene::{Method, Scene};
use margemu_sim::truth::geodesic_angle;
use std::hint::black_box;
use std::time::{Duration, Instant};

/// One row of the integrator table.
#[derive(Clone, Copy, Debug)]
pub struct IntegratorRow {
    /// Method.
    pub method: Method,
    /// Largest internal step (s).
    pub step: f64,
    /// Largest attitude error against the reference (rad).
    pub max_attitude_error: f64,
    /// Largest position error against the reference (m).
    pub max_position_error: f64,
    /// Simulated seconds per wall second.
    pub realtime_factor: f64,
}

/// One row of the mode table.
#[derive(Clone, Debug)]
pub struct ModeRow {
    /// Scene name.
    pub name: String,
    /// Motion mode.
    pub mode: String,
    /// Wall time per output sample (ns).
    pub ns_per_sample: f64,
    /// Simulated seconds per wall second.
    pub realtime_factor: f64,
}

/// `scene` with another integrator.
pub fn with_integrator(scene: &Scene, method: Method, step: f64) -> Scene {
    let mut s = scene.clone();
    s.spec.integrator.method = method;
    s.spec.integrator.step = step;
    s.step_ns = nanos_from_seconds(step).expect("a valid step");
    s
}

/// Attitude quaternion and position at every output sample.
type Trajectory = Vec<([f64; 4], [f64; 3])>;

fn trajectory(scene: &Scene) -> Result<Trajectory, ReferenceError> {
    let mut out = Vec::with_capacity(scene.samples() as usize);
    for_each(scene, |t| out.push((t.quaternion, t.position)))?;
    Ok(out)
}

/// Times full runs of `scene` (truth computed, nothing written) for at least `min_wall`;
/// returns wall seconds per run. One untimed run first warms caches and the per-process PID
/// synthesis memo, so the figure is the steady per-sample cost.
pub fn time_run(scene: &Scene, min_wall: Duration) -> Result<f64, ReferenceError> {
    for_each(scene, |_| {})?;
    let mut runs = 0u32;
    let start = Instant::now();
    while runs == 0 || start.elapsed() < min_wall {
        let mut acc = 0.0;
        for_each(scene, |t| acc += t.quaternion[0] + t.specific_force[2])?;
        black_box(acc);
        runs += 1;
    }
    Ok(start.elapsed().as_secs_f64() / runs as f64)
}

/// Errors and speed of each `(method, step)` on `scene`, against RK4 at `reference_step`.
pub fn integrator_sweep(
    scene: &Scene,
    configs: &[(Method, f64)],
    reference_step: f64,
    min_wall: Duration,
) -> Result<Vec<IntegratorRow>, ReferenceError> {
    let reference = trajectory(&with_integrator(scene, Method::Rk4, reference_step))?;
    configs
        .iter()
        .map(|&(method, step)| {
            let s = with_integrator(scene, method, step);
            let traj = trajectory(&s)?;
            let (mut att, mut pos) = (0.0f64, 0.0f64);
            for ((q, p), (qr, pr)) in traj.iter().zip(&reference) {
                att = att.max(geodesic_angle(q, qr));
                let d = [p[0] - pr[0], p[1] - pr[1], p[2] - pr[2]];
                pos = pos.max((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt());
            }
            let wall = time_run(&s, min_wall)?;
            Ok(IntegratorRow {
                method,
                step,
                max_attitude_error: att,
                max_position_error: pos,
                realtime_factor: s.spec.duration / wall,
            })
        })
        .collect()
}

/// Cost per output sample of each scene.
pub fn mode_costs(scenes: &[Scene], min_wall: Duration) -> Result<Vec<ModeRow>, ReferenceError> {
    scenes
        .iter()
        .map(|s| {
            let wall = time_run(s, min_wall)?;
            Ok(ModeRow {
                name: s
                    .spec
                    .name
                    .clone()
                    .unwrap_or_else(|| s.path.display().to_string()),
                mode: format!("{:?}", s.spec.motion).to_lowercase(),
                ns_per_sample: wall * 1e9 / s.samples() as f64,
                realtime_factor: s.spec.duration / wall,
            })
        })
        .collect()
}

/// One row of the streaming table: a scene streamed in real time through a PTY pair to the
/// firmware's link handler ([`margemu_hil::loopback`]), checked against the prediction.
#[derive(Clone, Debug)]
pub struct StreamRow {
    /// Output rate, Hz.
    pub rate_hz: f64,
    /// The source mode (kinematics rate resolved).
    pub source: SourceMode,
    /// Samples in the scene.
    pub samples: u64,
    /// Items written (images, or kinematics samples), first copies.
    pub sent: u64,
    /// What the device reported serving, against the prediction.
    pub served: ServedStats,
    /// How late the batches' writes started (pacing) and completed, against the scene clock.
    pub jitter: JitterStats,
    /// How late the same writes completed.
    pub written_jitter: JitterStats,
    /// Batches that waited for credit.
    pub credit_stalls: u64,
    /// Go-backs.
    pub resends: u64,
    /// Measured item bytes per wire byte of the batches written.
    pub efficiency: f64,
    /// Lead used, and items per batch.
    pub lead: Duration,
    /// Items per batch.
    pub batch: u64,
    /// CPU hogs running during the row ([`hogs::Hogs`]).
    pub hogs: usize,
    /// The real-time pacing asked for and obtained.
    pub pacing: Obtained,
    /// The session's error, if it ended early.
    pub error: Option<String>,
}

/// The conditions of a streaming row: the CPU hogs running meanwhile and the pacing thread's
/// real-time request.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StreamLoad {
    /// CPU-bound hog threads at normal priority, started before the row and stopped after it.
    pub hogs: usize,
    /// What the pacing thread asks for.
    pub realtime: Realtime,
}

/// A kinematic scene with noise on every sensor (so consecutive images differ), `seconds` long
/// at `rate_hz`.
pub fn stream_scene(rate_hz: f64, seconds: f64) -> Scene {
    let text = format!(
        "name = \"bench-stream\"\nduration = {seconds}\nrate = {rate_hz}\nseed = 7\n\
         motion = \"kinematic\"\n\
         [joints.roll]\ntype = \"sine\"\namplitude = 0.8\nfrequency = 1.3\n\
         [joints.yaw]\ntype = \"sine\"\namplitude = 1.5\nfrequency = 0.7\n\
         [sensors.gyro]\nnoise_density = [0.01, 0.01, 0.01]\n\
         [sensors.accel]\nnoise_density = [0.02, 0.02, 0.02]\n\
         [sensors.mag]\nnoise_density = [0.002, 0.002, 0.002]\n"
    );
    Scene::parse_str(&text, std::path::Path::new("bench-stream.toml")).expect("a valid scene")
}

/// The devices of [`rig_stream_scene`]: the usual sensor set of a flight controller with two
/// IMUs, an ICM-42688-P and an MPU-6000 on SPI and an IST8310 compass on I2C.
pub const RIG_DEVICES: &str = "[[device]]\nname = \"imu0\"\nmodel = \"icm42688p\"\n\
    [[device]]\nname = \"imu1\"\nmodel = \"mpu6000\"\nchip_select = 1\n\
    [[device]]\nname = \"compass\"\nmodel = \"ist8310\"\n";

/// [`stream_scene`] served by the three-device rig [`RIG_DEVICES`] (`rate_hz` must be an output
/// rate of both IMUs: 1, 2, 4 or 8 kHz, say).
pub fn rig_stream_scene(rate_hz: f64, seconds: f64) -> Result<Scene, String> {
    let text = stream_scene(rate_hz, seconds).text + RIG_DEVICES;
    Scene::parse_str(&text, std::path::Path::new("bench-stream-rig.toml"))
        .map_err(|e| e.to_string())
}

/// What [`stream_sweep`] streams: one chip at power-on (any rate, to find the link's limits),
/// or the three-device rig of [`rig_stream_scene`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Streamed {
    /// One chip.
    Chip(margemu_protocol::chip::ChipModel),
    /// [`RIG_DEVICES`].
    Rig,
}

/// Streams [`stream_scene`] (with `what`) at each rate and source through the loopback device
/// under `load`, writing each session's logs under `dir`.
pub fn stream_sweep(
    what: Streamed,
    rates: &[f64],
    sources: &[SourceMode],
    seconds: f64,
    load: StreamLoad,
    dir: &std::path::Path,
) -> Result<Vec<StreamRow>, margemu_hil::stream::StreamError> {
    let mut rows = Vec::new();
    for &source in sources {
        for &rate_hz in rates {
            let scene = match what {
                Streamed::Chip(chip) => {
                    let mut scene = stream_scene(rate_hz, seconds);
                    scene.chip = margemu_sim::scene::chip::ChipSetup::power_on(chip);
                    scene.chip_name = chip.name().to_owned();
                    scene
                }
                Streamed::Rig => rig_stream_scene(rate_hz, seconds)
                    .map_err(|reason| margemu_hil::stream::StreamError::Model { reason })?,
            };
            let mode = match source {
                SourceMode::Images => "images",
                SourceMode::Model { .. } => "model",
            };
            let config = StreamConfig {
                port: "pty".into(),
                source,
                realtime: load.realtime,
                ..StreamConfig::default()
            };
            let session_dir = match load == StreamLoad::default() {
                true => dir.join(format!("{mode}-{rate_hz}")),
                false => dir.join(format!(
                    "{mode}-{rate_hz}-hogs{}-rt-{}",
                    load.hogs, load.realtime
                )),
            };
            let hogs = hogs::Hogs::start(load.hogs)
                .map_err(|source| margemu_hil::stream::StreamError::Port { source })?;
            hogs.wait_running();
            let run = margemu_hil::loopback::run(&scene, config, &session_dir);
            hogs.stop();
            let (result, device) = run?;
            let summary = result.as_ref().ok();
            rows.push(StreamRow {
                rate_hz,
                source: summary.map_or(source, |s| s.source),
                samples: scene.samples(),
                sent: summary.map_or(0, |s| s.sent),
                served: summary.map_or_else(ServedStats::default, |s| s.served),
                jitter: summary.map_or_else(JitterStats::default, |s| s.jitter),
                written_jitter: summary.map_or_else(JitterStats::default, |s| s.written_jitter),
                credit_stalls: summary.map_or(0, |s| s.credit_stalls),
                resends: summary.map_or(0, |s| s.resends),
                efficiency: summary.map_or(0.0, |s| s.link.efficiency()),
                lead: summary.map_or(Duration::ZERO, |s| s.lead),
                batch: summary.map_or(0, |s| s.batch),
                hogs: load.hogs,
                pacing: summary.map_or_else(Obtained::default, |s| s.pacing.clone()),
                error: result
                    .err()
                    .map(|e| format!("{e} (the device loop ended: {})", device.ended)),
            });
        }
    }
    Ok(rows)
}

/// One row of the link table: a batch of `items` items of `item_len` bytes.
#[derive(Clone, Copy, Debug)]
pub struct LinkRow {
    /// What the items are: a chip model's images, or (`None`) the rig's images ([`Self::rig`])
    /// or kinematics.
    pub chip: Option<margemu_protocol::chip::ChipModel>,
    /// Whether the items are the images of the rig of [`RIG_DEVICES`].
    pub rig: bool,
    /// Items per batch frame.
    pub items: usize,
    /// Bytes per item (the model's image length, 53 for kinematics).
    pub item_len: usize,
    /// Worst-case wire bytes of the frame.
    pub wire_bytes: usize,
}

impl LinkRow {
    /// Item bytes per wire byte.
    pub fn efficiency(&self) -> f64 {
        (self.items * self.item_len) as f64 / self.wire_bytes as f64
    }

    /// Items per second a UART at `baud` carries (10 line bits per byte: 8N1).
    pub fn items_per_s(&self, baud: u32) -> f64 {
        f64::from(baud) / 10.0 / self.wire_bytes as f64 * self.items as f64
    }
}

/// Worst-case link efficiency of image batches of every chip model (1 image to a full frame)
/// and kinematics batches (1 to 28 samples).
pub fn link_table() -> Vec<LinkRow> {
    use margemu_protocol::chip::ChipModel;
    use margemu_protocol::link::{
        max_images_per_batch, IMAGE_BATCH_HEADER_LEN, MAX_KINEMATICS_PER_BATCH, TRUTH_LEN,
    };
    let mut rows = Vec::new();
    let rig_len = [ChipModel::Icm42688p, ChipModel::Mpu6000, ChipModel::Ist8310]
        .map(ChipModel::image_len)
        .iter()
        .sum();
    let images = ChipModel::ALL
        .map(|chip| (Some(chip), chip.image_len()))
        .into_iter()
        .chain([(None, rig_len)]);
    for (chip, len) in images {
        for items in [1, 8, 16, 32, max_images_per_batch(len)] {
            rows.push(LinkRow {
                chip,
                rig: chip.is_none(),
                items,
                item_len: len,
                wire_bytes: margemu_hil::stream::batch_wire_len(items, len, IMAGE_BATCH_HEADER_LEN),
            });
        }
    }
    for items in [1, 8, 16, MAX_KINEMATICS_PER_BATCH] {
        rows.push(LinkRow {
            chip: None,
            rig: false,
            items,
            item_len: TRUTH_LEN,
            wire_bytes: margemu_hil::stream::batch_wire_len(items, TRUTH_LEN, 8),
        });
    }
    rows
}
