//! Real-time streaming of a scene to a device over a serial port, in either source
//! mode of `docs/spec/link.md`: (a) register images, (b) true kinematics for the device's own
//! sensor model.
//!
//! A [`Session`] predicts every register image the device will serve for a validated
//! [`Scene`](margemu_sim::scene::Scene): in mode (a) [`predict_images`] (truth →
//! [`MargSim`](margemu_sim::marg::MargSim) → the chip module's conversion with an explicit
//! [`ImageSettings`]), in mode (b) [`predict_model`] (the firmware's zero-order hold of the
//! kinematics and model steps, see [`model`]; scenes the device cannot run are refused when
//! the session is created, before anything is sent). The prediction runs lazily, in order, just
//! ahead of what is sent ([`Predictions`]), and the session keeps only a bounded window of it
//! (what the device can still ask to be resent or report serving: its buffer capacity, see
//! [`served::served_window`]); pacing statistics are histograms ([`Lateness`]). A session's
//! memory therefore does not depend on the scene's length. Then it speaks the link protocol
//! over any byte port:
//!
//! 1. Hello → HelloAck: the protocol version must match, and the device must emulate the
//!    scene's chip model and support the source mode;
//! 2. Configure (the scene's `[chip]`: model, identity, image length, I2C address and full-scale
//!    overrides; the scene's exact rate, the source and, in mode (b), the model parameters) →
//!    the first Credit;
//! 3. prefill (the items due within the lead, as far as the window allows), then Start
//!    (`t0_ns` = 0, `end_index` = the scene's sample count), which sets scene time 0 on the
//!    session's clock; the device stops by itself at the scene's end;
//! 4. batches paced in real time (`pacing.rs`): the batch that starts at
//!    item `j` is written at `start + t_j − lead`, never beyond the device's credit window; the
//!    time of every write and how late it was are logged (pacing jitter). Items the device
//!    reports missing long after they were written are written again ([`resend`]);
//! 5. Stop after the last sample (in mode (b) once the device reports serving it), which
//!    confirms the end, then wait for Telemetry in the stopped state.
//!
//! **One run, its parts each with their own state.** A [`Session`] owns its settings, what it
//! streams (`source.rs`: the items and their lazy prediction) and its log writer (`logger.rs`).
//! [`Session::run_with`] hands the session to a run (`flow.rs`), which owns it and the port,
//! and composes: the plan (`plan.rs`), what is fixed once the device has answered (counts,
//! rates, batch, lead, the windows of what is kept, timeouts), set once and never changed; the
//! device's reports (`reports.rs`: HelloAck, credit window, Telemetry, the receiver's counts,
//! the Served check); the pacing (`pacing.rs`: the next item, the go-back-N write times, the
//! figures of the writes: lateness, credit stalls, bytes); the ending (`ending.rs`: when Stop
//! is due, whether it was written, how it went). Every one of these keeps its fields private
//! and answers through its methods; the run alone sequences them and is the only one that
//! waits, writes and handles device events. When the run ends it drops the port and hands the
//! log writer back to the session, which writes the `end` row and closes the logs.
//!
//! **Time is injected.** The streaming core (the run: pacing, credit, resend, Served checks,
//! Stop) never reads the operating system's clock: it reads and waits for time only through its
//! [`Port`], which writes its frames, hands over the device's and owns a [`clock::Clock`].
//! [`Session::run`] uses a [`SystemPort`]: the real port, a receive thread ([`rx`]) that
//! decodes the device's frames concurrently and counts damaged ones, and the host's monotonic
//! clock ([`clock::SystemClock`]). [`Session::run_with`] takes any port: a [`VirtualPort`]
//! runs the firmware's link handler on a [`clock::VirtualClock`], with injected faults (a lost
//! batch, credit withheld, a late wake), so a session's every time is exact and independent of
//! the machine's load (`host/tests/stream_core.rs`).
//!
//! ```
//! use margemu_hil::stream::clock::VirtualClock;
//! use margemu_hil::stream::{Session, StreamConfig, VirtualPort};
//! # let text = "duration = 0.1\nrate = 1000.0\nseed = 1\nmotion = \"kinematic\"\n";
//! # let scene = margemu_sim::scene::Scene::parse_str(text, "doc.toml".as_ref()).unwrap();
//! # let dir = std::env::temp_dir().join(format!("margemu-doc-virtual-{}", std::process::id()));
//! # let _ = std::fs::remove_dir_all(&dir);
//! let clock = VirtualClock::new();
//! let device = VirtualPort::<256>::new(clock.clone(), 1_000_000); // polled every 1 ms
//! let session = Session::new(&scene, StreamConfig::default(), &dir).unwrap();
//! let summary = session.run_with(device, |_| {}).unwrap();
//! assert_eq!(summary.served.byte_exact, 100);
//! assert_eq!(summary.jitter.max_ns, 0); // every batch written at its instant, exactly
//! # let _ = std::fs::remove_dir_all(&dir);
//! ```
//!
//! Every sample instant the device reports serving (its Served messages: index, CRC-32C of the
//! image latched) is logged in `served.csv` and checked against the prediction ([`served`]); the
//! [`Summary`] carries the counts. The session stops with a [`StreamError`] on a device
//! Reset after the handshake, a fatal device Error, end of file or an error on the port, a
//! timeout waiting for HelloAck or credit, or the stop flag (Ctrl-C); in every case the logs
//! ([`log`], written by their own thread) are flushed and end with an `end` row in
//! `events.csv`.

pub mod budget;
pub mod clipping;
pub mod clock;
pub mod device_truth;
mod ending;
pub mod faults;
mod flow;
pub mod images;
mod lateness;
pub mod log;
mod logger;
mod mcap_log;
pub(crate) mod meta;
pub mod model;
mod pacing;
mod plan;
pub mod port;
pub mod predictor;
mod reports;
pub mod resend;
pub mod rx;
pub mod served;
mod session;
mod source;
pub mod virtual_port;
pub mod window;

pub use faults::fault_messages;
pub use images::{predict_images, ImageSettings, PredictedSample};
pub use lateness::Lateness;
pub use logger::LogSink;
pub use model::{
    device_chip, kinematics_hold, model_images, predict_model, ModelPrediction, ModelSample,
};
pub use port::{Port, SystemPort};
pub use predictor::Predictions;
pub use served::{served_window, ServedCheck, ServedStats};
pub use session::{rate_of, Session, SourceMode, StreamConfig};
pub use virtual_port::VirtualPort;

use margemu_protocol::link::{HelloAck, RxStats, Telemetry};
use std::path::PathBuf;
use std::time::Duration;

/// Why a session stopped early.
#[derive(Debug, thiserror::Error, docsplay::Display)]
pub enum StreamError {
    /// cannot predict the scene's samples
    Predict(#[from] margemu_sim::run::RunError),
    /// cannot write the session log in {path}
    Log {
        /// The session directory.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// cannot use the serial port
    Port {
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// the scene's rate ({hz} Hz) is not an exact ratio of 32-bit integers the link can carry
    Rate {
        /// The scene's rate.
        hz: f64,
    },
    /// no HelloAck within {timeout:?}: is a margemu device on this port, and is it running?
    HelloTimeout {
        /// How long the session waited.
        timeout: Duration,
    },
    /// the device speaks link protocol {device}, this host {host}
    VersionMismatch {
        /// The device's version.
        device: u16,
        /// Ours.
        host: u16,
    },
    /// the device cannot serve this session: {reason}
    Unsupported {
        /// What is missing.
        reason: String,
    },
    /// no credit for sample {index} within {timeout:?}: the device stopped granting its window
    CreditTimeout {
        /// The next sample to send.
        index: u64,
        /// How long the session waited.
        timeout: Duration,
    },
    /// the device reset mid-session (cause: {cause})
    DeviceReset {
        /// The reset cause it reported.
        cause: String,
    },
    /// the device refused the session: {detail}
    DeviceRefused {
        /// Its error report.
        detail: String,
    },
    /// the device disconnected: {detail}
    Disconnected {
        /// What the port said.
        detail: String,
    },
    /// source mode model cannot run this scene: {reason}
    Model {
        /// Why.
        reason: String,
    },
    /// the kinematics rate {hz} Hz does not divide the output rate {out_hz} Hz: the device holds each kinematics sample for a whole number of output samples (e.g. {hint})
    KinematicsRate {
        /// The rate asked for.
        hz: f64,
        /// The scene's output rate.
        out_hz: f64,
        /// Rates that would do.
        hint: String,
    },
    /// the prediction ended at sample {index} of {samples}
    PredictionEnded {
        /// The first sample missing.
        index: u64,
        /// Samples in the scene.
        samples: u64,
    },
    /// interrupted; the device was asked to stop and the logs are complete up to here
    Interrupted,
}

/// What a running session reports to its progress callback.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// Items written to the port (images, or kinematics samples in source mode model).
    pub sent: u64,
    /// Items in the stream.
    pub total: u64,
    /// Go-backs so far (items the device had not received, written again).
    pub resends: u64,
    /// Time since Start.
    pub elapsed: Duration,
    /// The device's latest Telemetry (served samples, underruns, its receive errors).
    pub telemetry: Option<Telemetry>,
    /// What the host's receiver counted (damaged and lost device frames).
    pub host_rx: RxStats,
    /// How late the last batch was written against its schedule, ns.
    pub last_late_ns: i64,
    /// The latest batch so far, ns.
    pub max_late_ns: i64,
    /// What the device reported serving so far, against the prediction.
    pub served: ServedStats,
}

/// Pacing jitter: how late batches were written against their schedule, over the batches
/// written after Start that did not wait for credit (those count as credit stalls) and were
/// not resends.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct JitterStats {
    /// Batches measured.
    pub batches: u64,
    /// Median, ns.
    pub p50_ns: i64,
    /// 99th percentile, ns.
    pub p99_ns: i64,
    /// Largest, ns.
    pub max_ns: i64,
}

impl JitterStats {
    /// Exact nearest-rank percentiles of `late` (ns); a session keeps a [`Lateness`] histogram
    /// instead.
    pub fn from_lateness(late: &[i64]) -> Self {
        let mut v = late.to_vec();
        v.sort_unstable();
        let rank = |p: f64| -> i64 {
            if v.is_empty() {
                return 0;
            }
            let i = ((p * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1;
            v[i]
        };
        Self {
            batches: v.len() as u64,
            p50_ns: rank(0.5),
            p99_ns: rank(0.99),
            max_ns: v.last().copied().unwrap_or(0),
        }
    }
}

/// What the host wrote to the port.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LinkStats {
    /// Every byte written (all frames, delimiters included).
    pub wire_bytes: u64,
    /// Sample batch frames written.
    pub batch_frames: u64,
    /// Their bytes on the wire.
    pub batch_wire_bytes: u64,
    /// The item bytes they carried (22 per image, 53 per kinematics sample).
    pub item_bytes: u64,
}

impl LinkStats {
    /// Item bytes per wire byte of the sample batches (link efficiency, before UART framing).
    pub fn efficiency(&self) -> f64 {
        self.item_bytes as f64 / self.batch_wire_bytes.max(1) as f64
    }
}

/// How a completed session went.
#[derive(Clone, Debug)]
pub struct Summary {
    /// Samples in the scene.
    pub samples: u64,
    /// Items written to the port (images, or kinematics samples in source mode model), the
    /// first copy of each.
    pub sent: u64,
    /// Go-backs: times the device reported an item missing that was written long enough
    /// before, and the session wrote it and the items after it again.
    pub resends: u64,
    /// Items written more than once.
    pub resent: u64,
    /// Items in the stream.
    pub stream_len: u64,
    /// The source mode (kinematics rate resolved).
    pub source: SourceMode,
    /// Items per batch.
    pub batch: u64,
    /// How far ahead of their instants batches were written.
    pub lead: Duration,
    /// Bytes written.
    pub link: LinkStats,
    /// The session directory.
    pub dir: PathBuf,
    /// When Start was written, ns since the port was opened (scene time 0).
    pub start_host_ns: Option<i64>,
    /// Pacing jitter: how late each paced batch's write started against the scene clock.
    pub jitter: JitterStats,
    /// How late the same writes completed (the port's time added: a PTY write wakes the
    /// reader).
    pub written_jitter: JitterStats,
    /// The device's last Telemetry.
    pub telemetry: Option<Telemetry>,
    /// The device's HelloAck.
    pub device: Option<HelloAck>,
    /// The host receiver's counters.
    pub host_rx: RxStats,
    /// Times a due batch had to wait for credit.
    pub credit_stalls: u64,
    /// What the device reported serving, against the prediction (`served.csv`).
    pub served: ServedStats,
    /// The register settings of the images.
    pub image_settings: ImageSettings,
    /// Time from Start to the end.
    pub elapsed: Duration,
    /// The real-time pacing obtained ([`crate::realtime`]).
    pub pacing: crate::realtime::Obtained,
}

/// Worst-case wire bytes of a batch frame of `n` items of `item_len` bytes each behind a batch
/// header of `header_len` bytes (an image batch's 9, a kinematics batch's 8): frame header,
/// batch header, items, CRC, worst-case COBS and both delimiters.
pub fn batch_wire_len(n: usize, item_len: usize, header_len: usize) -> usize {
    use margemu_protocol::link::{max_wire_len, CRC_LEN, HEADER_LEN};
    max_wire_len(HEADER_LEN + header_len + n * item_len + CRC_LEN)
}

/// Opens a serial port for a session (no exclusive lock, 50 ms read timeout).
pub fn open_port(path: &str, baud: u32) -> Result<serialport::TTYPort, StreamError> {
    let port = serialport::new(path, baud)
        .timeout(Duration::from_millis(50))
        .open_native()
        .map_err(|e| StreamError::Port { source: e.into() })?;
    Ok(port)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn batch_sizes_agree_with_the_protocol() {
        use margemu_protocol::link::{image_batch_wire_len, IMAGE_BATCH_HEADER_LEN, TRUTH_LEN};
        for len in [14, 22, 32] {
            let host = batch_wire_len(32, len, IMAGE_BATCH_HEADER_LEN);
            assert_eq!(host, image_batch_wire_len(32, len));
        }
        assert_eq!(batch_wire_len(32, 22, IMAGE_BATCH_HEADER_LEN), 728);
        assert_eq!(batch_wire_len(28, TRUTH_LEN, 8), 1510); // docs/spec/link.md §9
    }

    #[test]
    fn jitter_percentiles_by_nearest_rank() {
        let late: Vec<i64> = (1..=100).collect();
        let j = JitterStats::from_lateness(&late);
        assert_eq!(
            (j.batches, j.p50_ns, j.p99_ns, j.max_ns),
            (100, 50, 99, 100)
        );
        assert_eq!(JitterStats::from_lateness(&[]), JitterStats::default());
    }
}
