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

use std::io::{self, Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver};
use std::sync::Arc;
use std::thread::{self, JoinHandle};
use std::time::{Duration, Instant};

use margemu::stream::JitterStats;
use margemu_model::sensor::Truth;
use margemu_protocol::link::{
    Configure, Credit, DeviceState, Encoder, ErrorReport, Hello, HelloAck, Image, ImageBatch,
    KinematicsBatch, Message, Rate, Start, Telemetry, MAX_IMAGES_PER_BATCH,
    MAX_KINEMATICS_PER_BATCH, MAX_WIRE_LEN,
};
use margemu_protocol::PROTOCOL_VERSION;
use serialport::TTYPort;

use crate::qemu::LinkDecoder;
use crate::served::ServedLog;

/// The last stretch before a batch's instant is busy-waited.
const SPIN: Duration = Duration::from_micros(200);

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
            Samples::Images(_) => MAX_IMAGES_PER_BATCH,
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
enum Event {
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
    let mut host = Host {
        port,
        events,
        encoder: Encoder::new(),
        wire: vec![0; MAX_WIRE_LEN],
        credit: Credit::default(),
        credit_seen: false,
        ack: None,
        telemetry: None,
        served_through: None,
        errors: Vec::new(),
        bytes_sent: 0,
        timeout: script.timeout,
    };
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

fn is_transient(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted
    )
}

struct Host {
    port: TTYPort,
    events: Receiver<Event>,
    encoder: Encoder,
    wire: Vec<u8>,
    credit: Credit,
    credit_seen: bool,
    ack: Option<HelloAck>,
    telemetry: Option<Telemetry>,
    served_through: Option<u64>,
    errors: Vec<ErrorReport>,
    bytes_sent: u64,
    timeout: Duration,
}

impl Host {
    fn session(&mut self, script: &Script<'_>) -> io::Result<Report> {
        let session = 0x4D4F_4442; // "MODB"
        self.send(&Message::Hello(Hello {
            protocol_version: PROTOCOL_VERSION,
            session,
        }))?;
        self.wait("HelloAck", |h| h.ack.is_some_and(|a| a.session == session))?;
        self.send(&Message::Configure(script.configure.clone()))?;
        self.wait("the first Credit", |h| h.credit_seen)?;

        let samples = script.samples;
        let total = samples.len();
        let batch = script.batch.clamp(1, samples.max_batch());
        let lead_ns = script.lead.as_nanos() as u64;
        let mut next = 0usize;
        let mut batches = 0u64;
        while next < total
            && script.sample_rate.sample_time_ns(next as u64) <= lead_ns
            && self.credit.available(next as u64) > 0
        {
            let n = self.batch_len(batch, next, total);
            self.write_batch(samples, next, n)?;
            next += n;
            batches += 1;
        }
        self.send(&Message::Start(Start { t0_ns: 0 }))?;
        let start = Instant::now();
        let mut lateness_ns = Vec::new();
        let mut credit_stalls = 0u64;
        while next < total {
            let t = Duration::from_nanos(script.sample_rate.sample_time_ns(next as u64));
            let due = (start + t)
                .checked_sub(script.lead)
                .unwrap_or(start)
                .max(start);
            self.pump_until(due.checked_sub(SPIN).unwrap_or(due))?;
            while Instant::now() < due {
                std::hint::spin_loop();
            }
            self.pump_until(Instant::now())?;
            let mut stalled = false;
            if self.credit.available(next as u64) == 0 {
                credit_stalls += 1;
                stalled = true;
                let at = next as u64;
                self.wait("credit", |h| h.credit.available(at) > 0)?;
            }
            let n = self.batch_len(batch, next, total);
            let late = Instant::now().saturating_duration_since(due).as_nanos() as i64;
            self.write_batch(samples, next, n)?;
            if !stalled {
                lateness_ns.push(late);
            }
            next += n;
            batches += 1;
        }

        let out_rate = script.configure.rate;
        let last = script.outputs.saturating_sub(1);
        let (t_last, t_next) = (
            out_rate.sample_time_ns(last),
            out_rate.sample_time_ns(last + 1),
        );
        let stop_at = start + Duration::from_nanos(t_last + (t_next - t_last) / 2);
        self.pump_until(stop_at)?;
        self.wait("the last output served", |h| {
            h.served_through.is_some_and(|s| s >= last)
        })?;
        self.send(&Message::Stop)?;
        let streamed = start.elapsed();
        let stopped = self
            .wait("the stopped Telemetry", |h| {
                h.telemetry.is_some_and(|t| t.state == DeviceState::Stopped)
            })
            .is_ok();
        Ok(Report {
            ack: self.ack.expect("waited for"),
            served: ServedLog::default(),
            damaged: 0,
            telemetry: self.telemetry,
            stopped,
            errors: std::mem::take(&mut self.errors),
            lateness_ns,
            credit_stalls,
            batches,
            bytes_sent: self.bytes_sent,
            streamed,
        })
    }

    fn batch_len(&self, batch: usize, next: usize, total: usize) -> usize {
        let available = self.credit.available(next as u64) as usize;
        batch.min(available).min(total - next).max(1)
    }

    fn write_batch(&mut self, samples: Samples<'_>, first: usize, n: usize) -> io::Result<()> {
        let len = samples.encode(first, n, &mut self.encoder, &mut self.wire);
        self.write_wire(len)
    }

    fn send(&mut self, message: &Message<'_>) -> io::Result<()> {
        let len = self
            .encoder
            .encode(message, &mut self.wire)
            .expect("every host message fits a frame");
        self.write_wire(len)
    }

    /// Writes `wire[..len]`, retrying while the PTY is full (the port's write times out).
    fn write_wire(&mut self, len: usize) -> io::Result<()> {
        let deadline = Instant::now() + self.timeout;
        let mut at = 0;
        while at < len {
            match self.port.write(&self.wire[at..len]) {
                Ok(n) => {
                    at += n;
                    self.bytes_sent += n as u64;
                }
                Err(e) if is_transient(&e) && Instant::now() < deadline => {}
                Err(e) => return Err(e),
            }
        }
        Ok(())
    }

    /// Handles the device's messages until `until`.
    fn pump_until(&mut self, until: Instant) -> io::Result<()> {
        loop {
            let left = until.saturating_duration_since(Instant::now());
            match self.events.recv_timeout(left) {
                Ok(event) => self.handle(event)?,
                Err(mpsc::RecvTimeoutError::Timeout) => return Ok(()),
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    return Err(io::Error::other("the receive thread ended"))
                }
            }
            if Instant::now() >= until {
                // Take what is already there, without waiting.
                while let Ok(event) = self.events.try_recv() {
                    self.handle(event)?;
                }
                return Ok(());
            }
        }
    }

    /// Handles the device's messages until `done` holds; an error after the timeout.
    fn wait(&mut self, what: &str, done: impl Fn(&Self) -> bool) -> io::Result<()> {
        let deadline = Instant::now() + self.timeout;
        while !done(self) {
            if Instant::now() >= deadline {
                return Err(io::Error::new(
                    io::ErrorKind::TimedOut,
                    format!(
                        "no {what} within {:?}; last telemetry {:?}; errors {:?}",
                        self.timeout, self.telemetry, self.errors
                    ),
                ));
            }
            self.pump_until((Instant::now() + Duration::from_millis(10)).min(deadline))?;
        }
        Ok(())
    }

    fn handle(&mut self, event: Event) -> io::Result<()> {
        match event {
            Event::Ack(a) => self.ack = Some(a),
            Event::Credit(c) => {
                self.credit = c;
                self.credit_seen = true;
            }
            Event::Telemetry(t) => {
                self.credit = t.credit();
                self.telemetry = Some(t);
            }
            Event::Served(last) => {
                self.served_through = Some(self.served_through.map_or(last, |s| s.max(last)));
            }
            Event::Error(e) => self.errors.push(e),
            Event::Reset if self.ack.is_some() => {
                return Err(io::Error::other("the device reset mid-session"))
            }
            Event::Reset => {}
            Event::Closed(e) => {
                return Err(io::Error::new(
                    io::ErrorKind::UnexpectedEof,
                    format!("the port closed: {e:?}"),
                ))
            }
        }
        Ok(())
    }
}
