//! The streaming core's only view of the outside world: a [`Port`] writes the host's frames,
//! hands over the device's frames as [`RxEvent`]s, and tells the time. The core sleeps only
//! through [`Port::wait`] (until the next device event or a deadline) and [`Port::spin_until`]
//! (the last stretch before a send instant), so where its time comes from is the port's
//! business:
//!
//! - [`SystemPort`]: a real port (a serial device or a pseudo-terminal), its receive thread
//!   ([`super::rx`]) and the [`SystemClock`];
//! - [`VirtualPort`](super::virtual_port::VirtualPort): the firmware's link handler driven on a
//!   [`VirtualClock`](super::clock::VirtualClock), for exact tests that do not depend on the
//!   machine's load.

use super::clock::{Clock, SystemClock};
use super::rx::{self, RxEvent};
use std::io::{self, Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Receiver;
use std::sync::Arc;
use std::time::Duration;

/// What a session needs of its link to the device (see the module docs).
pub trait Port {
    /// Host time now, ns since the session's origin.
    fn now_ns(&self) -> u64;
    /// Writes one encoded frame.
    fn write(&mut self, frame: &[u8]) -> io::Result<()>;
    /// The next device event, waiting for it until host time `deadline_ns` at most; `None` if
    /// none came by then.
    fn wait(&mut self, deadline_ns: u64) -> Option<RxEvent>;
    /// A device event already received, without waiting.
    fn try_event(&mut self) -> Option<RxEvent>;
    /// Waits until host time `deadline_ns` precisely, receiving nothing meanwhile (a real port
    /// busy-waits).
    fn spin_until(&mut self, deadline_ns: u64);
}

/// A real port: `writer` takes the frames, a receive thread decodes what the device sends, the
/// time is the [`SystemClock`]'s. Dropping it ends the receive thread (at its next read).
pub struct SystemPort<W: Write> {
    clock: SystemClock,
    writer: W,
    events: Receiver<RxEvent>,
    shutdown: Arc<AtomicBool>,
}

impl<W: Write> SystemPort<W> {
    /// Starts the receive thread on `reader` (which must return from `read` now and then, by
    /// data, timeout or end of file); events are stamped with `clock`.
    pub fn new(reader: impl Read + Send + 'static, writer: W, clock: SystemClock) -> Self {
        let shutdown = Arc::new(AtomicBool::new(false));
        let (events, _thread) = rx::spawn(reader, clock, shutdown.clone());
        Self {
            clock,
            writer,
            events,
            shutdown,
        }
    }
}

impl<W: Write> Drop for SystemPort<W> {
    fn drop(&mut self) {
        self.shutdown.store(true, Ordering::Relaxed);
    }
}

impl<W: Write> Port for SystemPort<W> {
    fn now_ns(&self) -> u64 {
        self.clock.now_ns()
    }

    fn write(&mut self, frame: &[u8]) -> io::Result<()> {
        self.writer.write_all(frame)
    }

    fn wait(&mut self, deadline_ns: u64) -> Option<RxEvent> {
        let now = self.clock.now_ns();
        if deadline_ns <= now {
            return self.events.try_recv().ok();
        }
        let wait = Duration::from_nanos(deadline_ns - now);
        self.events.recv_timeout(wait).ok()
    }

    fn try_event(&mut self) -> Option<RxEvent> {
        self.events.try_recv().ok()
    }

    fn spin_until(&mut self, deadline_ns: u64) {
        while self.clock.now_ns() < deadline_ns {
            std::hint::spin_loop();
        }
    }
}
