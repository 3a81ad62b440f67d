//! The session's log writer: a thread that owns the [`SessionLog`] files, so that a write the
//! operating system holds up (a busy disk throttles writers for tens to hundreds of ms) never
//! delays the pacing.
//!
//! The session queues jobs ([`Logger::write`]); the thread runs them in order and flushes every
//! file whenever its queue runs empty, so rows reach the operating system within moments of
//! being queued, and an interrupted session loses nothing that was queued: [`Logger::finish`]
//! (also run on drop) writes the rest, flushes and reports the first error.
//!
//! The logger also holds the session's share of the directory's completion record
//! ([`CompletionRecord`]): [`Logger::end`] sets it and lets go of it after the last row.

use super::log::SessionLog;
use super::StreamError;
use margemu_sim::rundir::{Completion, CompletionRecord};
use std::io;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{channel, Sender};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

/// One queued write.
type Job = Box<dyn FnOnce(&mut SessionLog) -> io::Result<()> + Send>;

/// The handle on the writer thread.
pub(super) struct Logger {
    dir: PathBuf,
    tx: Option<Sender<Job>>,
    thread: Option<JoinHandle<io::Result<()>>>,
    completion: Option<CompletionRecord>,
    /// The senders other threads were given ([`Logger::sink`]): emptied when the writer ends.
    shared: Option<Arc<Mutex<Option<Sender<Job>>>>>,
}

/// A handle another thread (the device under test's reader) queues writes of the session's
/// logs on: they run on the log writer thread, in order with the session's own. Once the
/// session's logs are closed, what it is given is dropped (those rows are in the reader's own
/// CSV files); a write that fails fails the session's logs, as the session's own do.
#[derive(Clone)]
pub struct LogSink {
    tx: Arc<Mutex<Option<Sender<Job>>>>,
}

impl std::fmt::Debug for LogSink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("LogSink")
    }
}

impl LogSink {
    /// The device under test's attitude `q` (`(w, x, y, z)`, body to world), received at host
    /// time `host_ns`: `session.mcap`'s `/dut/attitude` and `/tf` world→dut.
    pub fn dut_attitude(&self, host_ns: i64, q: [f64; 4]) {
        let tx = self.tx.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(tx) = tx.as_ref() {
            let _ = tx.send(Box::new(move |log: &mut SessionLog| {
                log.dut_attitude(host_ns, q)
            }));
        }
    }
}

impl Logger {
    /// Moves `log` to a new writer thread.
    pub(super) fn spawn(mut log: SessionLog) -> io::Result<Self> {
        let dir = log.dir().to_path_buf();
        let completion = Some(CompletionRecord::new(&dir));
        let (tx, rx) = channel::<Job>();
        let thread = std::thread::Builder::new()
            .name("margemu-log".into())
            .spawn(move || {
                while let Ok(job) = rx.recv() {
                    job(&mut log)?;
                    while let Ok(job) = rx.try_recv() {
                        job(&mut log)?;
                    }
                    log.flush()?;
                }
                log.close()
            })?;
        Ok(Self {
            dir,
            tx: Some(tx),
            thread: Some(thread),
            completion,
            shared: None,
        })
    }

    /// A share of the directory's completion record, for another writer of the directory (the
    /// record is written when the last share is let go).
    pub(super) fn completion(&self) -> Option<CompletionRecord> {
        self.completion.clone()
    }

    /// Ends the writer (as [`Logger::finish`]), then records `completion` (failed instead if the
    /// logs could not be written) and lets go of the logger's share of the record.
    pub(super) fn end(&mut self, mut completion: Completion) -> io::Result<()> {
        let finished = self.finish();
        if let Err(e) = &finished {
            completion.fail(format!("cannot write the logs: {e}"));
        }
        let Some(record) = self.completion.take() else {
            return finished;
        };
        record.update(|c| *c = completion);
        finished.and(record.release())
    }

    /// A handle for another thread to queue writes on ([`LogSink`]).
    pub(super) fn sink(&mut self) -> LogSink {
        let tx = self.tx.clone();
        let shared = self
            .shared
            .get_or_insert_with(|| Arc::new(Mutex::new(tx)))
            .clone();
        LogSink { tx: shared }
    }

    /// The session directory.
    pub(super) fn dir(&self) -> &Path {
        &self.dir
    }

    /// Queues `job`; fails with the writer's error once a write has failed.
    pub(super) fn write(
        &mut self,
        job: impl FnOnce(&mut SessionLog) -> io::Result<()> + Send + 'static,
    ) -> io::Result<()> {
        let sent = self.tx.as_ref().map(|tx| tx.send(Box::new(job)));
        match sent {
            Some(Ok(())) => Ok(()),
            _ => self
                .finish()
                .and(Err(io::Error::other("the log writer has ended"))),
        }
    }

    /// Queues `job`, as [`Logger::write`]; a failure is the session's [`StreamError::Log`].
    pub(super) fn queue(
        &mut self,
        job: impl FnOnce(&mut SessionLog) -> io::Result<()> + Send + 'static,
    ) -> Result<(), StreamError> {
        self.write(job).map_err(|source| self.error(source))
    }

    /// A failure to write the session's logs.
    pub(super) fn error(&self, source: io::Error) -> StreamError {
        StreamError::Log {
            path: self.dir.clone(),
            source,
        }
    }

    /// Writes what is queued, flushes, and ends the writer; returns its first error.
    pub(super) fn finish(&mut self) -> io::Result<()> {
        if let Some(shared) = &self.shared {
            shared.lock().unwrap_or_else(|e| e.into_inner()).take();
        }
        drop(self.tx.take());
        match self.thread.take().map(JoinHandle::join) {
            None => Ok(()),
            Some(Ok(result)) => result,
            Some(Err(_)) => Err(io::Error::other("the log writer panicked")),
        }
    }
}

impl Drop for Logger {
    fn drop(&mut self) {
        let _ = self.finish();
    }
}
