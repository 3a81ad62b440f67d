//! The host's side of one scripted session (see the [module docs](super)).

use std::io::{self, Write};
use std::sync::mpsc::{self, Receiver};
use std::time::{Duration, Instant};

use margemu_protocol::link::{
    Credit, DeviceState, Encoder, ErrorReport, Hello, HelloAck, Message, Start, Telemetry,
    MAX_WIRE_LEN,
};
use margemu_protocol::PROTOCOL_VERSION;
use serialport::TTYPort;

use super::{Event, Report, Samples, Script};
use crate::qemu::is_transient;
use crate::served::ServedLog;

/// The last stretch before a batch's instant is busy-waited.
const SPIN: Duration = Duration::from_micros(200);

/// The state of one session on the host side: the port, the device's events, the credit window.
pub(super) struct Host {
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
    pub(super) fn new(port: TTYPort, events: Receiver<Event>, timeout: Duration) -> Self {
        Self {
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
            timeout,
        }
    }

    pub(super) fn session(&mut self, script: &Script<'_>) -> io::Result<Report> {
        let session = 0x4D4F_4442; // "MODB"
        self.send(&Message::Hello(Hello {
            protocol_version: PROTOCOL_VERSION,
            session,
        }))?;
        self.wait("HelloAck", |h| h.ack.is_some_and(|a| a.session == session))?;
        self.send(&Message::Configure(script.configure.clone()))?;
        for piece in &script.vibration {
            self.send(&Message::AddVibration(piece.clone()))?;
        }
        for fault in &script.faults {
            self.send(&Message::AddFault(*fault))?;
        }
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
        self.send(&Message::Start(Start::scene(0, script.outputs)))?;
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
