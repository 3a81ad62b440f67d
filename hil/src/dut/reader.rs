//! [`DutReader`]: the thread that reads the device's port, decodes, logs and (for MSP) polls.

use super::decode::{DecodeCounters, Decoded, StreamDecoder};
use super::log::DutLog;
use super::mavlink_in::MavlinkDecoder;
use super::msp::{self, MspDecoder, MspVersion};
use super::{DutEnd, DutError, DutProtocol, DutSummary};
use crate::stream::LogSink;
use std::collections::BTreeMap;
use std::io::{self, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Settings of a reader. [`DutConfig::new`] gives the defaults.
#[derive(Clone, Debug)]
pub struct DutConfig {
    /// The wire format the device speaks.
    pub protocol: DutProtocol,
    /// MSP only: polls per second; each poll sends an `MSP_ATTITUDE` and an `MSP_RAW_IMU`
    /// request. Reads time out between polls, so the port's read timeout bounds the jitter.
    pub msp_poll_hz: f64,
    /// MSP only: the version of the poll requests.
    pub msp_requests: MspVersion,
    /// The CSV files are flushed at least this often (and when the reader ends).
    pub flush_period: Duration,
    /// Where each attitude also goes: the session's `session.mcap`
    /// ([`Session::log_sink`](crate::stream::Session::log_sink)).
    pub session_log: Option<LogSink>,
}

impl DutConfig {
    /// Defaults: MSP polled at 50 Hz with v1 requests, files flushed every 100 ms.
    pub fn new(protocol: DutProtocol) -> Self {
        Self {
            protocol,
            msp_poll_hz: 50.0,
            msp_requests: MspVersion::V1,
            flush_period: Duration::from_millis(100),
            session_log: None,
        }
    }
}

/// What the reader has seen so far (for a progress line).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DutProgress {
    /// Messages decoded.
    pub messages: u64,
    /// Byte and frame counters.
    pub counters: DecodeCounters,
    /// MSP requests written.
    pub requests_sent: u64,
}

/// A running reader of the device under test. Stop it with [`DutReader::stop`].
pub struct DutReader {
    stop: Arc<AtomicBool>,
    progress: Arc<Mutex<DutProgress>>,
    handle: JoinHandle<Result<DutSummary, DutError>>,
}

/// Starts a reader of `protocol` on `port` with the defaults of [`DutConfig::new`]: see
/// [`DutReader::spawn`].
pub fn spawn_dut_reader<P>(
    port: P,
    protocol: DutProtocol,
    dir: &Path,
    origin: Instant,
) -> Result<DutReader, DutError>
where
    P: Read + Write + Send + 'static,
{
    DutReader::spawn(port, DutConfig::new(protocol), dir, origin)
}

impl DutReader {
    /// Creates the three CSV files in `dir` (which must exist) and starts the thread. `port` must
    /// return from `read` now and then (a `TTYPort` times out; see
    /// [`open_dut_port`](super::open_dut_port)). Host times are nanoseconds since `origin`
    /// (negative before it), taken when the read that completed the message returned.
    pub fn spawn<P>(
        port: P,
        config: DutConfig,
        dir: &Path,
        origin: Instant,
    ) -> Result<Self, DutError>
    where
        P: Read + Write + Send + 'static,
    {
        let log = DutLog::create(dir).map_err(|source| DutError::Log {
            path: dir.to_path_buf(),
            source,
        })?;
        let stop = Arc::new(AtomicBool::new(false));
        let progress = Arc::new(Mutex::new(DutProgress::default()));
        let worker = Worker {
            decoder: match config.protocol {
                DutProtocol::Mavlink => Box::new(MavlinkDecoder::new()),
                DutProtocol::Msp => Box::new(MspDecoder::new()),
            },
            config,
            log,
            dir: dir.to_path_buf(),
            origin,
            stop: stop.clone(),
            progress: progress.clone(),
            messages: BTreeMap::new(),
            decoded: Vec::new(),
            rows: [0, 0],
            requests_sent: 0,
        };
        let handle = std::thread::Builder::new()
            .name("margemu-dut".into())
            .spawn(move || worker.run(port))
            .map_err(|source| DutError::Thread { source })?;
        Ok(Self {
            stop,
            progress,
            handle,
        })
    }

    /// What the reader has seen so far.
    pub fn progress(&self) -> DutProgress {
        *self.progress.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Whether the thread has ended by itself (the port vanished or failed).
    pub fn is_finished(&self) -> bool {
        self.handle.is_finished()
    }

    /// Stops the thread (it notices within one read timeout), settles the bytes still pending,
    /// flushes the files and returns the summary.
    pub fn stop(self) -> Result<DutSummary, DutError> {
        self.stop.store(true, Ordering::Relaxed);
        self.handle.join().map_err(|_| DutError::Panicked)?
    }
}

struct Worker {
    config: DutConfig,
    decoder: Box<dyn StreamDecoder>,
    log: DutLog,
    dir: PathBuf,
    origin: Instant,
    stop: Arc<AtomicBool>,
    progress: Arc<Mutex<DutProgress>>,
    messages: BTreeMap<String, u64>,
    decoded: Vec<Decoded>,
    /// Attitude and IMU rows written.
    rows: [u64; 2],
    requests_sent: u64,
}

fn is_transient(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted
    )
}

impl Worker {
    fn run(mut self, mut port: impl Read + Write) -> Result<DutSummary, DutError> {
        let result = self.pump(&mut port);
        // Whatever ended the loop, the pending bytes are settled and everything is flushed.
        let host_ns = self.host_ns(Instant::now());
        self.decoder.finish(&mut self.decoded);
        let logged = self.log_decoded(host_ns).and_then(|()| self.log.flush());
        let end = result?;
        logged.map_err(|source| self.log_error(source))?;
        self.publish();
        Ok(DutSummary {
            protocol: self.config.protocol,
            dir: self.dir,
            messages: self.messages,
            counters: self.decoder.counters(),
            attitude_rows: self.rows[0],
            imu_rows: self.rows[1],
            requests_sent: self.requests_sent,
            end,
        })
    }

    /// Reads, decodes, logs and polls until stopped or the port ends.
    fn pump(&mut self, port: &mut (impl Read + Write)) -> Result<DutEnd, DutError> {
        let mut buf = vec![0u8; 4096];
        let poll = self.poll_requests();
        let period = Duration::from_secs_f64(1.0 / self.config.msp_poll_hz.max(1e-3));
        let mut next_poll = Instant::now();
        let mut last_flush = Instant::now();
        while !self.stop.load(Ordering::Relaxed) {
            if let Some(requests) = &poll {
                let now = Instant::now();
                if now >= next_poll {
                    match port.write_all(requests).and_then(|()| port.flush()) {
                        Ok(()) => self.requests_sent += 2,
                        // A board that does not read fills the line: this poll is dropped
                        // (a partial request is a false start to the board's parser).
                        Err(e) if is_transient(&e) => {}
                        Err(e) => {
                            return Ok(DutEnd::Disconnected(format!("writing to the port: {e}")))
                        }
                    }
                    next_poll = (next_poll + period).max(now);
                }
            }
            match port.read(&mut buf) {
                Ok(0) => return Ok(DutEnd::Disconnected("end of file".into())),
                Ok(n) => {
                    let host_ns = self.host_ns(Instant::now());
                    self.decoder.feed(&buf[..n], &mut self.decoded);
                    self.log_decoded(host_ns)
                        .map_err(|source| self.log_error(source))?;
                    self.publish();
                }
                Err(e) if is_transient(&e) => {}
                Err(e) => return Ok(DutEnd::Disconnected(format!("reading the port: {e}"))),
            }
            if last_flush.elapsed() >= self.config.flush_period {
                self.log.flush().map_err(|source| self.log_error(source))?;
                last_flush = Instant::now();
            }
        }
        Ok(DutEnd::Stopped)
    }

    /// The bytes of one MSP poll (both requests), or `None` for MAVLink.
    fn poll_requests(&self) -> Option<Vec<u8>> {
        (self.config.protocol == DutProtocol::Msp).then(|| {
            let v = self.config.msp_requests;
            let mut bytes = msp::request(msp::MSP_ATTITUDE, v);
            bytes.extend(msp::request(msp::MSP_RAW_IMU, v));
            bytes
        })
    }

    fn host_ns(&self, at: Instant) -> i64 {
        match at.checked_duration_since(self.origin) {
            Some(d) => d.as_nanos() as i64,
            None => -(self.origin.duration_since(at).as_nanos() as i64),
        }
    }

    fn log_decoded(&mut self, host_ns: i64) -> io::Result<()> {
        for d in self.decoded.drain(..) {
            self.log.write(host_ns, &d)?;
            *self
                .messages
                .entry(d.message.name.clone().into_owned())
                .or_default() += 1;
            match d.sample {
                Some(super::Sample::Attitude(a)) => {
                    self.rows[0] += 1;
                    if let Some(sink) = &self.config.session_log {
                        sink.dut_attitude(host_ns, a.attitude.quaternion);
                    }
                }
                Some(super::Sample::Imu(_)) => self.rows[1] += 1,
                None => {}
            }
        }
        Ok(())
    }

    fn publish(&self) {
        let mut p = self.progress.lock().unwrap_or_else(|e| e.into_inner());
        *p = DutProgress {
            messages: self.messages.values().sum(),
            counters: self.decoder.counters(),
            requests_sent: self.requests_sent,
        };
    }

    fn log_error(&self, source: io::Error) -> DutError {
        DutError::Log {
            path: self.dir.clone(),
            source,
        }
    }
}
