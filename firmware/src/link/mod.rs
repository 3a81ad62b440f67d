//! The device side of the host link (`docs/spec/link.md` §6–7): frames in, the emulated chip's
//! samples served on time, credits, telemetry and register writes out.
//!
//! A [`Device`] is driven by two calls, with time passed in as `now_ns` (the device's monotonic
//! clock, any origin) so the same code runs under a board's UART interrupt and timer, in the
//! host's loopback thread, and in tests with a hand-advanced clock:
//! - [`Device::feed`]: received bytes, in any chunks, through the shared
//!   [`Accumulator`]; handles Hello, Configure, Start, Stop and the sample batches, and counts
//!   damaged frames ([`RxStats`]) and sequence gaps ([`SeqTracker`]);
//! - [`Device::poll`]: serves every sample instant that is due, then sends what is pending
//!   (HelloAck, Error, Served, Credit, RegisterWrites, Telemetry) through the `tx` callback,
//!   one wire frame per call.
//!
//! **Refusals.** Each is answered with an Error frame and counted in `rejected_messages`:
//! a Hello of another protocol version (1), a device → host or unknown kind (2, detail the kind
//! byte), a payload that does not parse or images of another length than the chip's (3), a chip
//! model (also a chip code this version does not know, detail the code), identity, image length
//! or I2C address this device cannot emulate (4), a perturbation or a batch
//! of the other source (5; detail 2 [`VIBRATION_IN_IMAGES`]: an AddVibration in source (a)), a
//! model the shared `Marg` refuses, a Configure or AddVibration while running, or an
//! AddVibration the model cannot hold (6; detail [`VIBRATION_REFUSED`]),
//! Start or samples before Configure (7), a second Start while running (9), an AddFault the
//! schedule cannot take (11; detail [`FAULT_SCHEDULE_FULL`], [`FAULT_OVERLAPS`] an exclusive
//! overlap, [`FAULT_NO_DEVICE`], [`FAULT_UNSUPPORTED`] a chip fault whose chip hook returns
//! `false` or a latch-moving timing fault on a device other than 0; an AddFault while running
//! is 6, before Configure 7). Samples beyond the
//! credit limit are answered with Error 8 (detail: the first dropped index, truncated).
//!
//! **Faults** (`docs/spec/link.md` §5.16). AddFault messages fill a [`FaultSchedule`]
//! ([`Device::faults`], for the bus targets), cleared by Configure and Hello. At each output
//! instant the device fires the chip faults' edges due ([`faults::ChipEdges`]: the chips'
//! `fault_reset`, `fault_identity`, `fault_fifo_overflow` hooks, counted in
//! [`Counters::chip_fault_edges`]), latches at the instant the timing faults give
//! ([`faults::FaultClock`]; the model still steps at the nominal instant) and, for a
//! missing_drdy draw, holds the device's INT level ([`Device::int_pin_at`], what boards drive).
//! In source (b) device 0's sensor faults act in the model ([`setup::model_image`]).
//! A sample latched off its nominal instant is reported in a Served batch of its own, with its
//! latch time. Without faults nothing of this runs.
//!
//! **Register writes** of the device under test are drained from the chip's write log at every
//! poll and stamped with the scene time of that poll (the log itself has no time stamps), so
//! their resolution is one poll; `dropped` counts the entries the log overwrote in between.
//! Configure's register overrides are applied through the chip's own bus targets (the AK8963's
//! through I2C bypass, restored afterwards) and are not reported as writes.
//!
//! **Served reports.** Every instant served is reported in a [`ServedBatch`] (index, scene time,
//! CRC-32C of the image latched, underrun flag), sent once [`SERVED_FLUSH`] entries are
//! waiting, with every Telemetry, and when serving stops, so the host can check byte for byte
//! what the chip presented.
//!
//! **Time base.** Start { t0, end_index } received at local time `s` sets the scene clock to
//! `t0 + (now_ns − s)`. Output sample `k` is served when the scene clock reaches
//! `rate.sample_time_ns(k) = floor(k·den·10⁹/num)` (moved by a timing fault, see **Faults**),
//! the first being the smallest `k` with that
//! instant `≥ t0`; the chip is latched at that scene time, so its registers, INT pulses and
//! AK8963 schedule run on scene time. A late poll serves the missed instants in order (at most
//! [`MAX_CATCH_UP`] per call). At the instant of sample `end_index` the device stops by itself
//! (state Stopped, a Telemetry), serving nothing for it, in either source: the scene's end does
//! not depend on when the host's Stop arrives.
//!
//! **Buffering.** Each sample swaps into the chip's data registers in one step (the chip defers
//! it while a bus transaction is in progress, so a burst never mixes two samples); the ring
//! ([`SampleRing`], `N` samples) holds what the host sent ahead. At an instant whose sample is
//! missing the device counts an **underrun** and holds the last sample (mode (a): the last image
//! is latched again; mode (b): the model steps on the last kinematics). Samples at or beyond
//! the credit limit are dropped and counted as **overruns** (and answered with Error 8).
//!
//! **Source (b).** The host sends kinematics at `truth_rate`; at output instant `t` the device
//! uses the latest kinematics sample `j` with `truth_rate.sample_time_ns(j) ≤ t` (sample and
//! hold), steps the shared [`Marg`](margemu_model::sensor::Marg) (seeded from Configure, at the
//! output rate) behind the chain the AddVibration messages built (`setup::model_chain`: the
//! output or internal path, tones and shocks) and converts with [`setup::model_image`]. The
//! credit window counts kinematics
//! indices. A magnetic perturbation is refused (Error 5, detail 1): its FFT buffers (tens to
//! hundreds of KB) do not fit a generic no-alloc device.
//!
//! ```
//! use margemu_firmware::link::Device;
//! use margemu_protocol::link::{Encoder, Hello, Message, MAX_WIRE_LEN};
//! use margemu_protocol::PROTOCOL_VERSION;
//! let mut device = Device::<64>::new();
//! let mut wire = [0u8; MAX_WIRE_LEN];
//! let mut host = Encoder::new();
//! let hello = Hello { protocol_version: PROTOCOL_VERSION, session: 7 };
//! let n = host.encode(&Message::Hello(hello), &mut wire).unwrap();
//! device.feed(&wire[..n], 0);
//! let mut frames = 0;
//! device.poll(0, &mut |_frame: &[u8]| frames += 1);
//! assert_eq!(frames, 2); // Reset (after boot), HelloAck
//! ```

pub mod faults;
pub mod rig;
mod ring;
pub mod setup;

pub use ring::{Insert, SampleRing};

use margemu_model::sensor::Truth;
use margemu_protocol::link::{max_images_per_batch, ServedBatch, ServedSample, CRC32C};
use margemu_protocol::link::{
    Accumulator, AddDevice, AddFault, AddVibration, Bus, Buses, Capabilities, Configure, Credit,
    DeviceState, Encoder, ErrorCode, ErrorReport, FeedResult, FirmwareVersion, Frame, Hello,
    HelloAck, Image, Kind, Message, Modes, Rate, RegisterWrite, RegisterWriteBatch, Reset,
    ResetCause, RxStats, SeqTracker, Source, Start, Telemetry, DEVICE_ID_LEN, MAX_WIRE_LEN,
};
use margemu_protocol::PROTOCOL_VERSION;

use crate::chip::{self, Chip, EmulatedChip};
use crate::fault::{FaultSchedule, ScheduleError};
use faults::{ChipEdge, ChipEdges, FaultClock};
use margemu_model::fault::{FaultClass, FaultKind};
use rig::Rig;
use setup::Model;

/// Error 5's detail for an AddVibration in source (a): the chain is the host's there.
pub const VIBRATION_IN_IMAGES: u32 = 2;
/// Error 6's detail for an AddVibration the model cannot hold: a tone source or shock too many,
/// or a chain the model refuses with it (an invalid source, filter settings the chip does not
/// have at the rate).
pub const VIBRATION_REFUSED: u32 = 7;

/// Error 11's details (`docs/spec/link.md` §5.16): the schedule holds
/// [`MAX_FAULTS`](margemu_model::fault::MAX_FAULTS) faults already.
pub const FAULT_SCHEDULE_FULL: u32 = 1;
/// Error 11: the fault overlaps an earlier one of its exclusive group on its device.
pub const FAULT_OVERLAPS: u32 = 2;
/// Error 11: the rig has no such device.
pub const FAULT_NO_DEVICE: u32 = 3;
/// Error 11: the device's chip cannot apply this chip fault (its hook returned `false`), or a
/// timing fault that moves the latch names a device other than 0 (a rig's devices share one
/// serving clock).
pub const FAULT_UNSUPPORTED: u32 = 4;

/// The shortest image of any model (the standalone magnetometers).
const SMALLEST_IMAGE_LEN: usize = margemu_protocol::regmap::mag_image::IMAGE_LEN;

/// Telemetry period when Configure asks for the default (0): 100 ms.
pub const DEFAULT_TELEMETRY_PERIOD_NS: u64 = 100_000_000;

/// Most sample instants one [`Device::poll`] serves (the rest wait for the next call).
pub const MAX_CATCH_UP: u32 = 4096;

/// Served entries that trigger a [`ServedBatch`] frame (also sent with every Telemetry).
pub const SERVED_FLUSH: usize = 32;

/// Served entries held between two frames.
const SERVED_CAPACITY: usize = 64;

/// Register writes per RegisterWrites frame.
const WRITES_PER_FRAME: usize = 32;

/// Error reports queued between two polls (more are dropped; the counters still count).
const ERROR_QUEUE: usize = 4;

/// One sample slot: a finished image (mode (a)) or a kinematics sample (mode (b)).
#[derive(Clone, Copy, Debug)]
enum Slot {
    Image(Image),
    Truth(Truth),
}

/// What the device has served, cumulative since boot or the last Hello (wrapping).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// Sample instants passed while running (underruns included).
    pub served: u64,
    /// Instants with no sample (last one held).
    pub underruns: u32,
    /// Samples dropped at or beyond the credit limit.
    pub overruns: u32,
    /// Chip-fault hooks the chips applied at window edges (a start, an end).
    pub chip_fault_edges: u32,
    /// Receive-side counters (damaged frames, lost frames, rejected messages).
    pub rx: RxStats,
}

/// The last sample instant served.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Served {
    /// Output sample index.
    pub index: u64,
    /// Scene time of its instant (the chip was latched at it), ns.
    pub time_ns: u64,
    /// The image latched (the held one after an underrun), `None` if none was available yet.
    pub image: Option<Image>,
    /// Whether this instant was an underrun.
    pub underrun: bool,
}

/// Identity reported in HelloAck.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Identity {
    /// Firmware version.
    pub firmware: FirmwareVersion,
    /// MCU unique ID, zero-padded.
    pub device_id: [u8; DEVICE_ID_LEN],
}

#[derive(Clone, Copy, Debug)]
struct Session {
    rate: Rate,
    telemetry_period_ns: u64,
    images: bool,
    /// Bytes per image of the configured chip.
    image_len: u8,
}

#[derive(Clone, Copy, Debug)]
struct Clock {
    start_local_ns: u64,
    t0_ns: u64,
    next_k: u64,
    /// Start's `end_index`: the device stops at this sample's instant.
    end_k: u64,
}

/// The link handler of one emulated chip, with a buffer of `N` samples (see the module docs).
pub struct Device<const N: usize = 128> {
    rx: Accumulator,
    core: Core<N>,
}

struct Core<const N: usize> {
    rig: Rig,
    identity: Identity,
    state: DeviceState,
    session: Option<Session>,
    model: Option<Model>,
    clock: Option<Clock>,
    ring: SampleRing<Slot, N>,
    /// The fault schedule (AddFault), its serving clock and its chip-fault edges.
    faults: FaultSchedule,
    fault_clock: FaultClock,
    chip_edges: ChipEdges,
    /// Until this scene time no fault window opens (`FaultSchedule::quiet_until`): the
    /// serving loop skips the schedule.
    fault_quiet_until: u64,
    /// Whether the last sample served was latched off its nominal instant, and the first of the
    /// Served batch being built.
    last_shifted: bool,
    served_first_shifted: bool,
    counters: Counters,
    seq: SeqTracker,
    last_served: Option<Served>,
    last_image: Option<Image>,
    scene_now_ns: u64,
    // Outgoing.
    tx: Encoder,
    wire: [u8; MAX_WIRE_LEN],
    reset_pending: Option<ResetCause>,
    hello_ack: Option<u32>,
    errors: [Option<ErrorReport>; ERROR_QUEUE],
    credit_pending: bool,
    credit_sent_limit: u64,
    telemetry_pending: bool,
    /// Stop arrived with samples still buffered (image mode): serve them, then stop.
    draining: bool,
    next_telemetry_local_ns: u64,
    writes_dropped_seen: u32,
    served: [ServedSample; SERVED_CAPACITY],
    served_len: usize,
    served_first: (u64, u64),
}

impl<const N: usize> Default for Device<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> Device<N> {
    /// A device just powered on: idle, an MPU-9250 at reset, a Reset (power-on) frame pending.
    pub fn new() -> Self {
        Self::with_identity(Identity::default(), ResetCause::PowerOn)
    }

    /// A device with its HelloAck identity, after a reset of `cause`.
    pub fn with_identity(identity: Identity, cause: ResetCause) -> Self {
        Self {
            rx: Accumulator::new(),
            core: Core {
                rig: Rig::new(EmulatedChip::default()),
                identity,
                state: DeviceState::Idle,
                session: None,
                model: None,
                clock: None,
                ring: SampleRing::new(),
                faults: FaultSchedule::new(),
                fault_clock: FaultClock::new(),
                chip_edges: ChipEdges::new(),
                fault_quiet_until: 0,
                last_shifted: false,
                served_first_shifted: false,
                counters: Counters::default(),
                seq: SeqTracker::new(),
                last_served: None,
                last_image: None,
                scene_now_ns: 0,
                tx: Encoder::new(),
                wire: [0; MAX_WIRE_LEN],
                reset_pending: Some(cause),
                hello_ack: None,
                errors: [None; ERROR_QUEUE],
                credit_pending: false,
                credit_sent_limit: 0,
                telemetry_pending: false,
                draining: false,
                next_telemetry_local_ns: 0,
                writes_dropped_seen: 0,
                served: [ServedSample::default(); SERVED_CAPACITY],
                served_len: 0,
                served_first: (0, 0),
            },
        }
    }

    /// Takes received bytes (any chunking) at local time `now_ns`.
    pub fn feed(&mut self, mut rx: &[u8], now_ns: u64) {
        while !rx.is_empty() {
            let result = self.rx.feed(rx);
            self.core.counters.rx.record(&result);
            rx = result.remaining();
            if let FeedResult::Success { frame, .. } = result {
                self.core.handle(&frame, now_ns);
            }
        }
    }

    /// Serves the sample instants due at local time `now_ns`, then sends what is pending
    /// through `tx` (one complete wire frame per call).
    pub fn poll(&mut self, now_ns: u64, tx: &mut impl FnMut(&[u8])) {
        self.core.poll(now_ns, tx);
    }

    /// The emulated chip (a rig's device 0), for the board's (or the host's) SPI/I2C target.
    pub fn chip_mut(&mut self) -> &mut EmulatedChip {
        self.core.rig.primary_mut()
    }

    /// The emulated chip (a rig's device 0).
    pub fn chip(&self) -> &EmulatedChip {
        self.core.rig.primary()
    }

    /// Every chip served, device 0 first.
    pub fn rig(&self) -> &Rig {
        &self.core.rig
    }

    /// Every chip served, for a board's SPI and I2C targets ([`Rig::spi_target`],
    /// [`Rig::i2c_target`]).
    pub fn rig_mut(&mut self) -> &mut Rig {
        &mut self.core.rig
    }

    /// The fault schedule the host sent (AddFault), for the bus targets.
    pub fn faults(&self) -> &FaultSchedule {
        &self.core.faults
    }

    /// The level of device `device`'s (first) INT pin at local time `now_ns`: the chip's own
    /// ([`Chip::int_pin_at`] at the scene time), except while a missing_drdy fault leaves
    /// the last data-ready pulse out (the level it had before that latch). What a board drives
    /// and a host's virtual flight controller reads; `false` for a device the rig lacks.
    pub fn int_pin_at(&self, device: usize, now_ns: u64) -> bool {
        if let Some(level) = self.core.fault_clock.int_pin(device) {
            return level;
        }
        let t = self.core.scene_time(now_ns);
        self.core.rig.chip(device).is_some_and(|c| c.int_pin_at(t))
    }

    /// The counters.
    pub fn counters(&self) -> &Counters {
        &self.core.counters
    }

    /// The session state.
    pub fn state(&self) -> DeviceState {
        self.core.state
    }

    /// The last sample instant served.
    pub fn last_served(&self) -> Option<Served> {
        self.core.last_served
    }

    /// The current credit window.
    pub fn credit(&self) -> Credit {
        self.core.credit()
    }

    /// Samples buffered now.
    pub fn buffer_level(&self) -> usize {
        self.core.ring.level()
    }

    /// The scene clock at local time `now_ns` (the last one seen when not running).
    pub fn scene_time_ns(&self, now_ns: u64) -> u64 {
        self.core.scene_time(now_ns)
    }

    /// What the device advertises in HelloAck.
    pub fn capabilities() -> Capabilities {
        Capabilities {
            chips: setup::chips(),
            modes: Modes::IMAGES | Modes::MODEL,
            buses: Buses::SPI | Buses::I2C,
            // The most of the smallest images (14 bytes) a frame holds; longer images fit fewer.
            max_batch: max_images_per_batch(SMALLEST_IMAGE_LEN) as u16,
            buffer_capacity: u32::try_from(N).unwrap_or(u32::MAX),
        }
    }
}

impl<const N: usize> Core<N> {
    fn refuse(&mut self, code: ErrorCode, seq: u16, detail: u32) {
        self.counters.rx.rejected_messages = self.counters.rx.rejected_messages.wrapping_add(1);
        self.error(code, seq, detail);
    }

    fn error(&mut self, code: ErrorCode, seq: u16, detail: u32) {
        if let Some(slot) = self.errors.iter_mut().find(|e| e.is_none()) {
            *slot = Some(ErrorReport { code, seq, detail });
        }
    }

    fn handle(&mut self, frame: &Frame<&[u8]>, now_ns: u64) {
        let (kind, seq) = (frame.kind(), frame.seq());
        if kind == Kind::Hello as u8 {
            self.seq.restart();
        }
        let event = self.seq.observe(seq);
        self.counters.rx.record_seq(event);
        let message = match Message::parse(kind, frame.payload()) {
            Ok(m) => m,
            Err(e) => {
                self.counters.rx.record_error(e);
                // An unknown chip code is the first byte of Configure's payload.
                let chip = frame.payload().first().copied().unwrap_or(0);
                let (code, detail) = match (Kind::from_u8(kind), e) {
                    (None, _) => (ErrorCode::UnknownMessage, kind),
                    (Some(_), margemu_protocol::link::Error::UnknownChip) => {
                        (ErrorCode::UnsupportedChip, chip)
                    }
                    (Some(_), _) => (ErrorCode::MalformedMessage, kind),
                };
                self.error(code, seq, u32::from(detail));
                return;
            }
        };
        match message {
            Message::Hello(h) => self.hello(h, seq),
            Message::Configure(c) => self.configure(&c, seq, now_ns),
            Message::Start(s) => self.start(s, seq, now_ns),
            Message::Stop => self.stop(now_ns),
            Message::AddDevice(a) => self.add_device(&a, seq),
            Message::AddVibration(v) => self.add_vibration(&v, seq),
            Message::AddFault(f) => self.add_fault(&f, seq),
            Message::Images(b) => {
                let configured = self.session.map(|s| usize::from(s.image_len));
                if !b.images.is_empty() && configured.is_some_and(|n| n != b.images.image_len()) {
                    let len = b.images.image_len() as u32;
                    return self.refuse(ErrorCode::MalformedMessage, seq, len);
                }
                let samples = b.images.iter().map(Slot::Image);
                self.samples(true, b.first_index, samples, seq);
            }
            Message::Kinematics(b) => {
                let samples = b.samples.iter().map(Slot::Truth);
                self.samples(false, b.first_index, samples, seq);
            }
            _ => self.refuse(ErrorCode::UnknownMessage, seq, u32::from(kind)),
        }
    }

    fn hello(&mut self, h: Hello, seq: u16) {
        if h.protocol_version != PROTOCOL_VERSION {
            self.refuse(
                ErrorCode::UnsupportedVersion,
                seq,
                u32::from(h.protocol_version),
            );
            return;
        }
        self.state = DeviceState::Idle;
        self.session = None;
        self.model = None;
        self.clock = None;
        self.ring.reset(0);
        self.clear_faults();
        let rx = RxStats {
            frames: 1,
            ..RxStats::default()
        };
        self.counters = Counters {
            rx,
            ..Counters::default()
        };
        self.last_served = None;
        self.last_image = None;
        self.scene_now_ns = 0;
        self.errors = [None; ERROR_QUEUE];
        self.served_len = 0;
        self.credit_pending = false;
        self.telemetry_pending = false;
        self.hello_ack = Some(h.session);
    }

    fn configure(&mut self, c: &Configure, seq: u16, now_ns: u64) {
        if self.state == DeviceState::Running {
            self.refuse(ErrorCode::InvalidConfig, seq, DeviceState::Running as u32);
            return;
        }
        if !setup::source_supported(&c.source) {
            self.refuse(ErrorCode::UnsupportedMode, seq, 1);
            return;
        }
        let chip = match setup::build_chip(c) {
            Ok(chip) => chip,
            Err(code) => return self.refuse(code, seq, u32::from(c.chip.code())),
        };
        let model = match &c.source {
            Source::Images => None,
            Source::Model(p) => match Model::new(p, c.rate, &chip) {
                Some(m) => Some(m),
                None => return self.refuse(ErrorCode::InvalidConfig, seq, 0),
            },
        };
        let period = match c.telemetry_period_ns {
            0 => DEFAULT_TELEMETRY_PERIOD_NS,
            p => p,
        };
        self.session = Some(Session {
            rate: c.rate,
            telemetry_period_ns: period,
            images: model.is_none(),
            image_len: c.image_len,
        });
        self.rig = Rig::new(chip);
        self.model = model;
        self.clock = None;
        self.ring.reset(0);
        self.clear_faults();
        self.last_image = None;
        self.state = DeviceState::Configured;
        self.credit_pending = true;
        self.next_telemetry_local_ns = now_ns.saturating_add(period);
    }

    fn add_device(&mut self, a: &AddDevice, seq: u16) {
        let Some(session) = self.session.as_mut() else {
            return self.refuse(ErrorCode::NotConfigured, seq, 0);
        };
        if self.state == DeviceState::Running {
            return self.refuse(ErrorCode::InvalidConfig, seq, DeviceState::Running as u32);
        }
        if !session.images {
            return self.refuse(ErrorCode::RigRefused, seq, 4);
        }
        match self.rig.add(a) {
            // Within MAX_IMAGE_LEN (64): `Rig::add` refuses more.
            Ok(()) => session.image_len = self.rig.image_len() as u8,
            Err(e) => self.refuse(e.code, seq, e.detail),
        }
    }

    fn add_vibration(&mut self, v: &AddVibration, seq: u16) {
        if self.session.is_none() {
            return self.refuse(ErrorCode::NotConfigured, seq, 0);
        }
        if self.state == DeviceState::Running {
            return self.refuse(ErrorCode::InvalidConfig, seq, DeviceState::Running as u32);
        }
        let Some(model) = self.model.as_mut() else {
            return self.refuse(ErrorCode::UnsupportedMode, seq, VIBRATION_IN_IMAGES);
        };
        if !model.add_vibration(v, self.rig.primary()) {
            self.refuse(ErrorCode::InvalidConfig, seq, VIBRATION_REFUSED);
        }
    }

    fn clear_faults(&mut self) {
        self.faults.clear();
        self.fault_clock = FaultClock::new();
        self.chip_edges = ChipEdges::new();
        self.fault_quiet_until = 0;
    }

    fn add_fault(&mut self, a: &AddFault, seq: u16) {
        if self.session.is_none() {
            return self.refuse(ErrorCode::NotConfigured, seq, 0);
        }
        if self.state == DeviceState::Running {
            return self.refuse(ErrorCode::InvalidConfig, seq, DeviceState::Running as u32);
        }
        let f = &a.fault;
        let Some(chip) = self.rig.chip(usize::from(f.device)) else {
            return self.refuse(ErrorCode::FaultRefused, seq, FAULT_NO_DEVICE);
        };
        let timing_elsewhere = f.device != 0 && f.kind.moves_latch();
        if timing_elsewhere || !chip_fault_supported(chip, &f.kind) {
            return self.refuse(ErrorCode::FaultRefused, seq, FAULT_UNSUPPORTED);
        }
        if let Err(e) = self.faults.push(*f, a.seed) {
            let detail = match e {
                ScheduleError::Full => FAULT_SCHEDULE_FULL,
                ScheduleError::Overlaps => FAULT_OVERLAPS,
            };
            return self.refuse(ErrorCode::FaultRefused, seq, detail);
        }
        // Device 0's model takes every fault of device 0 (each keeps its index among them);
        // it holds as many as the schedule.
        if let Some(model) = self.model.as_mut().filter(|_| f.device == 0) {
            let _ = model.push_fault(f, a.seed);
        }
    }

    fn start(&mut self, s: Start, seq: u16, now_ns: u64) {
        let Some(session) = self.session.filter(|_| self.state != DeviceState::Running) else {
            let code = match self.state {
                DeviceState::Running => ErrorCode::Internal,
                _ => ErrorCode::NotConfigured,
            };
            return self.refuse(code, seq, self.state as u32);
        };
        let rate = session.rate;
        // The first k with floor(k·den·1e9/num) ≥ t0: k = ceil(t0·num / (den·1e9)).
        let den = u128::from(rate.den()) * 1_000_000_000;
        let k0 = (u128::from(s.t0_ns) * u128::from(rate.num())).div_ceil(den);
        self.clock = Some(Clock {
            start_local_ns: now_ns,
            t0_ns: s.t0_ns,
            next_k: u64::try_from(k0).unwrap_or(u64::MAX),
            end_k: s.end_index,
        });
        self.scene_now_ns = s.t0_ns;
        self.draining = false;
        self.state = DeviceState::Running;
    }

    /// Stop. In image mode with samples still buffered the stop is graceful: no more samples
    /// are coming, so the buffered ones are served at their instants and the device stops at
    /// the first instant it has nothing for (no underrun is counted for it). Otherwise, and in
    /// kinematics mode, it stops at once.
    fn stop(&mut self, now_ns: u64) {
        if self.state == DeviceState::Running && self.model.is_none() && self.ring.level() > 0 {
            self.draining = true;
            return;
        }
        self.finish_stop(now_ns);
    }

    fn finish_stop(&mut self, now_ns: u64) {
        self.draining = false;
        if self.state == DeviceState::Running {
            self.scene_now_ns = self.scene_time(now_ns);
            self.state = DeviceState::Stopped;
        }
        self.telemetry_pending = true;
    }

    fn samples(&mut self, images: bool, first: u64, samples: impl Iterator<Item = Slot>, seq: u16) {
        let Some(session) = self.session.filter(|_| self.state != DeviceState::Idle) else {
            return self.refuse(ErrorCode::NotConfigured, seq, first as u32);
        };
        if session.images != images {
            return self.refuse(ErrorCode::UnsupportedMode, seq, u32::from(images));
        }
        let mut first_overrun = None;
        for (i, slot) in (0u64..).zip(samples) {
            // An index past u64::MAX is beyond any credit limit: an overrun too.
            let index = first.saturating_add(i);
            if self.ring.insert(index, slot) == Insert::Overrun {
                self.counters.overruns = self.counters.overruns.wrapping_add(1);
                first_overrun.get_or_insert(index);
            }
        }
        if let Some(index) = first_overrun {
            self.error(ErrorCode::CreditExceeded, seq, index as u32);
        }
    }

    fn scene_time(&self, now_ns: u64) -> u64 {
        match (self.state, self.clock) {
            (DeviceState::Running, Some(c)) => c
                .t0_ns
                .saturating_add(now_ns.saturating_sub(c.start_local_ns)),
            _ => self.scene_now_ns,
        }
    }

    fn credit(&self) -> Credit {
        Credit {
            next_index: self.ring.next_index(),
            limit: self.ring.limit(),
        }
    }

    /// Serves every instant due by `now_ns` (at most [`MAX_CATCH_UP`]).
    fn serve_due(&mut self, now_ns: u64, tx: &mut impl FnMut(&[u8])) {
        if self.state != DeviceState::Running {
            return;
        }
        let (Some(session), Some(mut clock)) = (self.session, self.clock) else {
            return;
        };
        let now = self.scene_time(now_ns);
        self.scene_now_ns = now;
        for _ in 0..MAX_CATCH_UP {
            let t = session.rate.sample_time_ns(clock.next_k);
            if clock.next_k == u64::MAX {
                break;
            }
            if clock.next_k >= clock.end_k || (self.draining && self.ring.level() == 0) {
                if t > now {
                    break;
                }
                // The scene's end, or nothing left after a Stop: stop at this instant, serving
                // nothing for it.
                self.clock = Some(clock);
                self.draining = false;
                self.state = DeviceState::Stopped;
                // (Not before the last latch, which a timing fault may have moved past `t`.)
                self.scene_now_ns = self.last_served.map_or(t, |s| s.time_ns.max(t));
                self.telemetry_pending = true;
                return;
            }
            let latch = match self.fault_quiet(t) {
                Some(latch) => latch,
                None => self.fault_clock.latch_ns(&self.faults, clock.next_k, t),
            };
            if latch > now {
                break;
            }
            self.serve(clock.next_k, t, latch);
            self.log_served(tx);
            clock.next_k += 1;
        }
        self.clock = Some(clock);
        self.rig.advance(now);
    }

    /// The latch of a sample at nominal `t` while the schedule is quiet (no window holds it and
    /// none opens by its latch: nothing to do but keep the latches in order); `None` when the
    /// schedule must run.
    #[inline]
    fn fault_quiet(&self, t: u64) -> Option<u64> {
        if self.faults.is_empty() {
            return Some(t);
        }
        let latch = self.fault_clock.idle_latch_ns(t);
        (latch < self.fault_quiet_until).then_some(latch)
    }

    /// Fires the chip faults' edges due by `latch` and records the latch with the fault clock
    /// (the data-ready pulses it leaves out), before sample `k` (nominal `t`) is latched.
    fn fault_edges(&mut self, t: u64, latch: u64) {
        let (rig, counters) = (&mut self.rig, &mut self.counters);
        self.chip_edges.fire_due(&self.faults, latch, |edge| {
            if let Some(chip) = rig.chip_mut(usize::from(edge.device)) {
                if apply_chip_edge(chip, &edge) {
                    counters.chip_fault_edges = counters.chip_fault_edges.wrapping_add(1);
                }
            }
        });
        let rig = &self.rig;
        self.fault_clock.latch(&self.faults, latch, t, |d| {
            rig.chip(d).map(|c| c.int_pin_at(latch))
        });
    }

    /// Serves output sample `k` of nominal instant `t`, latched at `latch` (`t` unless a
    /// timing fault moves it): the model steps at `t`, the chips latch at `latch`.
    fn serve(&mut self, k: u64, t: u64, latch: u64) {
        if !self.faults.is_empty() {
            match self.fault_quiet(t) {
                Some(_) => self.fault_clock.idle_latch(latch),
                None => {
                    self.fault_edges(t, latch);
                    self.fault_quiet_until = self.faults.quiet_until(t).unwrap_or(0);
                }
            }
        }
        let (image, underrun) = match self.model.as_mut() {
            None => match self.ring.take(k) {
                Some(Slot::Image(image)) => (Some(image), false),
                _ => (self.last_image, true),
            },
            Some(model) => {
                let j = model.truth_index_at(t);
                self.ring.advance_to(j);
                let fresh = match self.ring.get(j) {
                    Some(Slot::Truth(truth)) => {
                        model.hold(truth);
                        true
                    }
                    _ => false,
                };
                (model.image(t, self.rig.primary()), !fresh)
            }
        };
        if let Some(image) = &image {
            self.rig.latch_image_at(image, latch);
        }
        self.last_image = image.or(self.last_image);
        let c = &mut self.counters;
        c.served = c.served.wrapping_add(1);
        if underrun {
            c.underruns = c.underruns.wrapping_add(1);
        }
        self.last_shifted = latch != t;
        self.last_served = Some(Served {
            index: k,
            time_ns: latch,
            image,
            underrun,
        });
    }

    /// Appends the last instant served to the Served log (sending the log first when it is
    /// full or the new index does not follow it).
    fn log_served(&mut self, tx: &mut impl FnMut(&[u8])) {
        let Some(s) = self.last_served else { return };
        let (first, _) = self.served_first;
        let follows = first.checked_add(self.served_len as u64) == Some(s.index);
        // An entry latched off its nominal instant (a timing fault) is a batch of its own, so
        // the batch's time is its own (§5.16).
        let on_time = !self.last_shifted && !self.served_first_shifted;
        if self.served_len == SERVED_CAPACITY || (self.served_len > 0 && !(follows && on_time)) {
            self.flush_served(tx);
        }
        if self.served_len == 0 {
            self.served_first = (s.index, s.time_ns);
            self.served_first_shifted = self.last_shifted;
        }
        if let Some(slot) = self.served.get_mut(self.served_len) {
            *slot = ServedSample {
                crc32c: s.image.map_or(0, |im| CRC32C.checksum(&im)),
                underrun: s.underrun,
                empty: s.image.is_none(),
            };
            self.served_len += 1;
        }
    }

    fn flush_served(&mut self, tx: &mut impl FnMut(&[u8])) {
        let n = core::mem::take(&mut self.served_len);
        if n == 0 {
            return;
        }
        let (first, time) = self.served_first;
        let served = self.served;
        let samples = served.get(..n).unwrap_or(&[]);
        self.send(&Message::Served(ServedBatch::new(first, time, samples)), tx);
    }

    fn telemetry(&self) -> Telemetry {
        let credit = self.credit();
        let last = self.last_served;
        Telemetry {
            time_ns: self.scene_now_ns,
            state: self.state,
            samples_served: self.counters.served,
            underruns: self.counters.underruns,
            overruns: self.counters.overruns,
            crc_errors: self.counters.rx.crc_errors,
            framing_errors: self.counters.rx.framing_errors,
            lost_frames: self.counters.rx.lost_frames,
            rejected_messages: self.counters.rx.rejected_messages,
            buffer_level: u32::try_from(self.ring.level()).unwrap_or(u32::MAX),
            next_index: credit.next_index,
            credit_limit: credit.limit,
            last_served_index: last.map_or(0, |s| s.index),
            last_served_time_ns: last.map_or(0, |s| s.time_ns),
        }
    }

    fn send(&mut self, message: &Message<'_>, tx: &mut impl FnMut(&[u8])) {
        if let Ok(n) = self.tx.encode(message, &mut self.wire) {
            if let Some(bytes) = self.wire.get(..n) {
                tx(bytes);
            }
        }
    }

    fn poll(&mut self, now_ns: u64, tx: &mut impl FnMut(&[u8])) {
        if let Some(cause) = self.reset_pending.take() {
            self.send(&Message::Reset(Reset { cause }), tx);
        }
        if let Some(session) = self.hello_ack.take() {
            let ack = HelloAck {
                protocol_version: PROTOCOL_VERSION,
                session,
                firmware: self.identity.firmware,
                device_id: self.identity.device_id,
                capabilities: Device::<N>::capabilities(),
            };
            self.send(&Message::HelloAck(ack), tx);
        }
        for i in 0..ERROR_QUEUE {
            if let Some(e) = self.errors.get_mut(i).and_then(Option::take) {
                self.send(&Message::Error(e), tx);
            }
        }
        self.serve_due(now_ns, tx);
        self.send_writes(tx);
        let active = matches!(self.state, DeviceState::Configured | DeviceState::Running);
        if active && now_ns >= self.next_telemetry_local_ns {
            self.telemetry_pending = true;
        }
        let running = self.state == DeviceState::Running;
        if self.served_len >= SERVED_FLUSH || self.telemetry_pending || !running {
            self.flush_served(tx);
        }
        let quarter = (N as u64 / 4).max(1);
        let advanced = self.ring.limit().saturating_sub(self.credit_sent_limit) >= quarter;
        let configured = self.session.is_some() && self.state != DeviceState::Idle;
        if configured && (self.credit_pending || self.telemetry_pending || advanced) {
            self.credit_pending = false;
            self.credit_sent_limit = self.ring.limit();
            self.send(&Message::Credit(self.credit()), tx);
        }
        if self.telemetry_pending {
            self.telemetry_pending = false;
            let period = self
                .session
                .map_or(DEFAULT_TELEMETRY_PERIOD_NS, |s| s.telemetry_period_ns);
            self.next_telemetry_local_ns = now_ns.saturating_add(period);
            self.send(&Message::Telemetry(self.telemetry()), tx);
        }
    }

    /// Drains the chip's write log into RegisterWrites frames, stamped with the scene time.
    fn send_writes(&mut self, tx: &mut impl FnMut(&[u8])) {
        let time_ns = self.scene_now_ns;
        loop {
            let mut batch = [RegisterWrite {
                time_ns,
                bus: Bus::Spi,
                address: 0,
                register: 0,
                value: 0,
            }; WRITES_PER_FRAME];
            let mut n = 0;
            while n < WRITES_PER_FRAME {
                let Some((w, chip_select)) = self.rig.pop_write() else {
                    break;
                };
                if let Some(slot) = batch.get_mut(n) {
                    *slot = wire_write(&w, chip_select, time_ns);
                }
                n += 1;
            }
            let total = self.rig.writes_dropped();
            let dropped = total.wrapping_sub(self.writes_dropped_seen);
            if n == 0 && dropped == 0 {
                return;
            }
            self.writes_dropped_seen = total;
            let writes = batch.get(..n).unwrap_or(&[]);
            self.send(
                &Message::RegisterWrites(RegisterWriteBatch::new(dropped, writes)),
                tx,
            );
        }
    }
}

/// A chip's register write on the wire; an SPI write carries its device's `chip_select`.
fn wire_write(w: &chip::RegisterWrite, chip_select: u8, time_ns: u64) -> RegisterWrite {
    let (bus, address) = match w.bus {
        chip::Bus::Spi => (Bus::Spi, chip_select),
        chip::Bus::I2c => (Bus::I2c, w.device),
        chip::Bus::Aux => (Bus::AuxMaster, w.device),
    };
    RegisterWrite {
        time_ns,
        bus,
        address,
        register: w.register,
        value: w.value,
    }
}

/// Whether `chip` can apply `kind`: `true` for every kind but the chip faults, for which the
/// chip's hook is tried on a copy (a hook returning `false` is not implemented for this chip).
fn chip_fault_supported(chip: &EmulatedChip, kind: &FaultKind) -> bool {
    if kind.class() != FaultClass::Chip {
        return true;
    }
    let mut probe = chip.clone();
    apply_chip_edge(
        &mut probe,
        &ChipEdge {
            device: 0,
            kind: *kind,
            begins: true,
        },
    )
}

/// Calls the chip's hook for a chip-fault edge; whether the chip applied it (a reset's end
/// calls nothing: `false`).
fn apply_chip_edge(chip: &mut EmulatedChip, edge: &ChipEdge) -> bool {
    match (edge.kind, edge.begins) {
        (FaultKind::Reset, true) => chip.fault_reset(),
        (FaultKind::WrongIdentity { value }, begins) => {
            chip.fault_identity(begins.then_some(value))
        }
        (FaultKind::FifoOverflow, on) => chip.fault_fifo_overflow(on),
        _ => false,
    }
}
