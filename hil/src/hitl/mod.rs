//! Hardware in the loop with a flight controller's own estimator: a scene's MARG samples sent
//! as MAVLink 2 `HIL_SENSOR` to a PX4 board in HITL mode (`SYS_HITL = 1`), which then takes its
//! sensor data from them instead of its IMU, and the attitude it computes read back over the
//! same link, logged and scored like any session's. No emulator board is involved.
//!
//! - [`message`]: what one HIL_SENSOR carries (units, frames, `fields_updated`) and the
//!   HEARTBEAT a simulator sends;
//! - [`link`]: the serial port or UDP socket, its sending end and the end the
//!   device-under-test reader ([`crate::dut`]) reads the replies from;
//! - [`pace`]: waiting for send instants on an injected clock;
//! - [`session`]: one run ([`HitlSession`]) and its files.
//!
//! **What is sent.** Device 0's sensor model in plate axes, exactly the samples `margemu
//! simulate` writes to `marg.csv` for the same scene and seed
//! ([`MargSim::new`](margemu_sim::marg::MargSim::new)): eq. 18 with the scene's noise, biases,
//! perturbations and, when the scene has them, vibration and device 0's sampling chain. No chip
//! is emulated: the chip's register conversion, its mounting rotation and a rig's other devices
//! do not apply (a flight controller in HITL reads no chip; its body axes are the plate's).
//! Sample `k` is written at host time `start_host_ns + t_k` (scene time `t_k`), with a HEARTBEAT
//! at scene time 0 and every second after it, written just before the sample due then.
//!
//! ```
//! use margemu_hil::hitl::{HitlConfig, HitlSession};
//! use margemu_hil::stream::clock::VirtualClock;
//! # let text = "duration = 0.05\nrate = 100.0\nseed = 1\nmotion = \"kinematic\"\n";
//! # let scene = margemu_sim::scene::Scene::parse_str(text, "doc.toml".as_ref()).unwrap();
//! # let dir = std::env::temp_dir().join(format!("margemu-doc-hitl-{}", std::process::id()));
//! # let _ = std::fs::remove_dir_all(&dir);
//! let session = HitlSession::new(&scene, HitlConfig::default(), &dir).unwrap();
//! let clock = VirtualClock::new();
//! let mut wire = Vec::new();
//! let summary = session.run(&mut wire, &clock, &Default::default()).unwrap();
//! assert_eq!(summary.samples, 5);
//! assert_eq!(summary.max_late_ns, 0); // every frame written at its instant, exactly
//! assert_eq!(wire.len() as u64, summary.bytes);
//! # let _ = std::fs::remove_dir_all(&dir);
//! ```

pub mod link;
pub mod message;
pub mod pace;
pub mod session;

pub use link::{Link, Target};
pub use message::SensorMapping;
pub use session::{HitlSession, HitlSummary, HIL_SENSOR_COLUMNS, HIL_SENSOR_FILE};

use margemu_sim::run::RunError;
use std::path::PathBuf;

/// Settings of a HITL session.
#[derive(Clone, Debug, PartialEq)]
pub struct HitlConfig {
    /// The flight controller's link (for `meta.toml`; [`Link::open`] opens it).
    pub target: Target,
    /// Gauss per unit of a normalized ("nu") field; ignored for a field in µT.
    pub gauss_per_unit: f64,
    /// Host time between opening the session and scene time 0 (ns).
    pub start_delay_ns: u64,
    /// Real-time pacing of the thread that runs the session ([`crate::realtime`]; off by
    /// default, the command line's default is auto).
    pub realtime: crate::realtime::Realtime,
}

impl Default for HitlConfig {
    /// No real link (`Target::Udp` to nowhere, for `meta.toml` only), 0.5 G per unit, a 20 ms
    /// start delay.
    fn default() -> Self {
        Self {
            target: Target::Udp {
                remote: "none".into(),
                bind: "none".into(),
            },
            gauss_per_unit: message::DEFAULT_GAUSS_PER_UNIT,
            start_delay_ns: 20_000_000,
            realtime: crate::realtime::Realtime::Off,
        }
    }
}

/// Why a HITL session could not run, or stopped.
#[derive(Debug, thiserror::Error, docsplay::Display)]
pub enum HitlError {
    /// cannot open the flight controller's port {path}: {reason}
    Port {
        /// The port's path.
        path: String,
        /// The cause.
        reason: String,
    },
    /// {what} `{text}` is no usable address (expected HOST:PORT): {reason}
    Address {
        /// The option.
        what: &'static str,
        /// What was given.
        text: String,
        /// The cause.
        reason: String,
    },
    /// cannot open a UDP socket on {bind} towards {remote}: {reason}
    Udp {
        /// The local address.
        bind: String,
        /// The peer.
        remote: String,
        /// The cause.
        reason: String,
    },
    /// the scene's {rate_hz} Hz needs {needed} bit/s of HIL_SENSOR and HEARTBEAT frames, more than the line's {baud} baud: raise --baud (PX4's USB port ignores it) or lower the scene's rate
    LineTooSlow {
        /// The scene's rate (Hz).
        rate_hz: f64,
        /// The line rate.
        baud: u32,
        /// Bits per second needed.
        needed: u64,
    },
    /// --gauss-per-unit must be finite and above 0, not {0}
    BadScale(f64),
    /// the scene's rate, {0} Hz, is above 1 MHz: HIL_SENSOR's time_usec cannot tell its samples apart
    RateTooHigh(f64),
    /// the scene's rate cannot be sent: {0}
    Rate(String),
    /// {0}
    Run(#[from] RunError),
    /// cannot write {path}
    Write {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// cannot write to the flight controller's link after {sent} samples
    Send {
        /// Samples written before.
        sent: u64,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
}
