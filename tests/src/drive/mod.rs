//! A scripted host for the link, written with `protocol::link` directly, for either source mode:
//! Hello → HelloAck, Configure → Credit, prefill, Start, batches paced in real time within the
//! credit window, Stop after the last output instant, and the device's stopped Telemetry.
//!
//! It is the test's own host, independent of `margemu::stream`: the batch that starts at sample
//! `i` is written at `start + t_i − lead` (`t_i` on the rate of the samples sent: the output
//! rate for images, the truth rate for kinematics), the last 200 µs busy-waited; a due batch
//! beyond the credit window waits for the next Credit or Telemetry (a credit stall, left out of
//! the pacing figures). A receive thread decodes every device frame, collects the Served
//! reports into a [`ServedLog`] and counts damaged frames.
//!
//! Stop goes out half an output period after the last output instant of the scene on the host's
//! clock, or later, once the device has reported that instant served: the device's scene clock
//! starts when Start *arrives*, behind the prefill, which under QEMU takes tens of milliseconds
//! to cross UART0. In source (b) Stop takes effect at once, so sending it on the host's clock
//! alone would cut the end of the scene off.

use std::io::{self, Read};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver};
use std::sync::Arc;
use std::thread::{self, JoinHandle};
use std::time::Duration;

use margemu::stream::JitterStats;
use margemu_model::sensor::Truth;
use margemu_protocol::link::{
    max_images_per_batch, Configure, Credit, Encoder, ErrorReport, HelloAck, Image, ImageBatch,
    KinematicsBatch, Message, Rate, Telemetry, MAX_KINEMATICS_PER_BATCH,
};
use serialport::TTYPort;

mod host;

use host::Host;

use crate::qemu::{is_transient, LinkDecoder};
use crate::served::ServedLog;

/// What the host streams.
#[derive(Clone, Copy, Debug)]
pub enum Samples<'a> {
    /// Source (a): one register image per output sample.
    Images(&'a [Image]),
    /// Source (b): kinematics at the truth rate.
    Kinematics(&'a [Truth]),
}

impl Samples<'_> {
    /// Samples to send.
    pub fn len(&self) -> usize {
        match self {
            Samples::Images(s) => s.len(),
            Samples::Kinematics(s) => s.len(),
        }
    }

    /// Whether there is nothing to send.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn max_batch(&self) -> usize {
        match self {
            Samples::Images(s) => max_images_per_batch(s.first().map_or(1, |i| i.len())),
            Samples::Kinematics(_) => MAX_KINEMATICS_PER_BATCH,
        }
    }

    /// Encodes samples `first..first + n` as one batch frame.
    fn encode(&self, first: usize, n: usize, encoder: &mut Encoder, wire: &mut [u8]) -> usize {
        let index = first as u64;
        let message = match self {
            Samples::Images(s) => Message::Images(ImageBatch::new(index, &s[first..first + n])),
            Samples::Kinematics(s) => {
                Message::Kinematics(KinematicsBatch::new(index, &s[first..first + n]))
            }
        };
        encoder
            .encode(&message, wire)
            .expect("a batch fits a frame")
    }
}

/// One session to run.
#[derive(Clone, Debug)]
pub struct Script<'a> {
    /// Sent after the handshake (its rate is the output rate).
    pub configure: Configure,
    /// Sent after Configure, in order (source (b)'s sampling chain).
    pub vibration: Vec<margemu_protocol::link::AddVibration>,
    /// Sent after the vibration, in order (the scene's fault schedule).
    pub faults: Vec<margemu_protocol::link::AddFault>,
    /// The samples.
    pub samples: Samples<'a>,
    /// Rate of `samples`: the output rate for images, the truth rate for kinematics.
    pub sample_rate: Rate,
    /// Output samples in the scene: Stop goes out half a period after the last one's instant.
    pub outputs: u64,
    /// How far ahead of its first sample's instant a batch is written.
    pub lead: Duration,
    /// Most samples per batch (also capped by the frame size).
    pub batch: usize,
    /// How long to wait for HelloAck, for credit, and for the stopped Telemetry.
    pub timeout: Duration,
}

/// How a session went.
#[derive(Debug)]
pub struct Report {
    /// The device's HelloAck.
    pub ack: HelloAck,
    /// Every Served entry the device sent.
    pub served: ServedLog,
    /// Damaged device frames.
    pub damaged: u64,
    /// The last Telemetry (in the stopped state if [`Report::stopped`]).
    pub telemetry: Option<Telemetry>,
    /// Whether the device confirmed Stop.
    pub stopped: bool,
    /// Error frames from the device.
    pub errors: Vec<ErrorReport>,
    /// How late each paced batch was written against its schedule, ns.
    pub lateness_ns: Vec<i64>,
    /// Due batches that had to wait for credit.
    pub credit_stalls: u64,
    /// Batches written (prefill included).
    pub batches: u64,
    /// Bytes written to the port (every frame, delimiters included).
    pub bytes_sent: u64,
    /// From Start to Stop.
    pub streamed: Duration,
}

impl Report {
    /// Pacing lateness percentiles over the paced batches.
    pub fn jitter(&self) -> JitterStats {
        JitterStats::from_lateness(&self.lateness_ns)
    }
}

/// A device → host control message, owned (Served entries go straight to the log).
pub(crate) enum Event {
    Ack(HelloAck),
    Credit(Credit),
    Telemetry(Telemetry),
    /// The highest output index in a Served frame.
    Served(u64),
    Error(ErrorReport),
    Reset,
    Closed(Option<io::Error>),
}

/// Runs `script` over `port` (UART0's PTY).
pub fn run(port: TTYPort, script: &Script<'_>) -> io::Result<Report> {
    let reader = port.try_clone_native()?;
    let shutdown = Arc::new(AtomicBool::new(false));
    let (events, receiver) = spawn_receiver(reader, Arc::clone(&shutdown));
    let mut host = Host::new(port, events, script.timeout);
    let outcome = host.session(script);
    shutdown.store(true, Ordering::Relaxed);
    let (served, damaged) = receiver
        .join()
        .map_err(|_| io::Error::other("receive thread panicked"))?;
    let mut outcome = outcome?;
    outcome.served = served;
    outcome.damaged = damaged;
    Ok(outcome)
}

fn spawn_receiver(
    mut port: TTYPort,
    shutdown: Arc<AtomicBool>,
) -> (Receiver<Event>, JoinHandle<(ServedLog, u64)>) {
    let (tx, rx) = mpsc::channel();
    let handle = thread::spawn(move || {
        let mut decoder = LinkDecoder::default();
        let mut served = ServedLog::default();
        let mut buf = [0u8; 4096];
        while !shutdown.load(Ordering::Relaxed) {
            let n = match port.read(&mut buf) {
                Ok(0) => {
                    let _ = tx.send(Event::Closed(None));
                    break;
                }
                Ok(n) => n,
                Err(e) if is_transient(&e) => continue,
                Err(e) => {
                    let _ = tx.send(Event::Closed(Some(e)));
                    break;
                }
            };
            decoder.feed(&buf[..n], &mut |m: &Message<'_>| {
                let event = match m {
                    Message::Served(batch) => {
                        served.record(batch);
                        let n = batch.samples.len() as u64;
                        match n.checked_sub(1) {
                            Some(last) => Event::Served(batch.first_index + last),
                            None => return,
                        }
                    }
                    Message::HelloAck(a) => Event::Ack(*a),
                    Message::Credit(c) => Event::Credit(*c),
                    Message::Telemetry(t) => Event::Telemetry(*t),
                    Message::Error(e) => Event::Error(*e),
                    Message::Reset(_) => Event::Reset,
                    _ => return,
                };
                let _ = tx.send(event);
            });
        }
        (served, decoder.damaged)
    });
    (rx, handle)
}
