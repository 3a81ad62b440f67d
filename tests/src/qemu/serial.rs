//! UART0's end on the host: a PTY with deadline-bounded reads, and a frame decoder.

use std::collections::VecDeque;
use std::io::{self, Read, Write};
use std::path::Path;
use std::time::{Duration, Instant};

use margemu_protocol::link::{Accumulator, FeedResult, FrameRepr, Message};
use serialport::TTYPort;

/// The serial port's read timeout: how often a waiting read looks at its deadline.
const POLL: Duration = Duration::from_millis(50);

/// Decodes link frames from a byte stream (any chunking), as the host's receiver does.
#[derive(Default)]
pub struct LinkDecoder {
    accumulator: Accumulator,
    /// Damaged frames and bytes between frames (the accumulator's errors), counted.
    pub damaged: u64,
}

impl LinkDecoder {
    /// Feeds `bytes`; calls `on_message` with every intact frame's message, in order
    /// (frames whose message does not parse count as damaged).
    pub fn feed(&mut self, mut bytes: &[u8], on_message: &mut impl FnMut(&Message<'_>)) {
        while !bytes.is_empty() {
            match self.accumulator.feed(bytes) {
                FeedResult::Consumed => break,
                FeedResult::Success { frame, remaining } => {
                    match FrameRepr::parse(&frame) {
                        Ok(repr) => on_message(&repr.message),
                        Err(_) => self.damaged += 1,
                    }
                    bytes = remaining;
                }
                other => {
                    self.damaged += 1;
                    bytes = other.remaining();
                }
            }
        }
    }
}

/// A serial port (here, a PTY) with deadline-bounded reads.
pub struct SerialLink {
    port: TTYPort,
    pending: VecDeque<u8>,
}

impl SerialLink {
    /// Opens `path` raw at `baud`, 8N1, no flow control.
    pub fn open(path: &Path, baud: u32) -> io::Result<Self> {
        let port = serialport::new(path.to_string_lossy(), baud)
            .timeout(POLL)
            .open_native()
            .map_err(|e| {
                let msg = format!("{}: {e}", path.display());
                io::Error::new(io::Error::from(e).kind(), msg)
            })?;
        Ok(Self {
            port,
            pending: VecDeque::new(),
        })
    }

    /// Sends `bytes` and flushes.
    pub fn write_all(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.port.write_all(bytes)?;
        self.port.flush()
    }

    /// Reads up to and including `delim`, waiting at most `timeout`.
    pub fn read_until(&mut self, delim: u8, timeout: Duration) -> io::Result<Vec<u8>> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(i) = self.pending.iter().position(|&b| b == delim) {
                return Ok(self.pending.drain(..=i).collect());
            }
            self.fill(deadline, timeout)?;
        }
    }

    /// Reads one `\n`-terminated line, without its line ending, waiting at most `timeout`.
    pub fn read_line(&mut self, timeout: Duration) -> io::Result<String> {
        let mut line = self.read_until(b'\n', timeout)?;
        line.pop();
        if line.last() == Some(&b'\r') {
            line.pop();
        }
        String::from_utf8(line).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))
    }

    /// Reads exactly `n` bytes, waiting at most `timeout`.
    pub fn read_exact(&mut self, n: usize, timeout: Duration) -> io::Result<Vec<u8>> {
        let deadline = Instant::now() + timeout;
        while self.pending.len() < n {
            self.fill(deadline, timeout)?;
        }
        Ok(self.pending.drain(..n).collect())
    }

    /// The port itself, for a [`Session`](margemu::stream::Session) or other unbuffered use;
    /// bytes already buffered here are dropped.
    pub fn into_port(self) -> TTYPort {
        self.port
    }

    /// The port itself, for settings and unbuffered use (bytes already buffered here stay here).
    pub fn port_mut(&mut self) -> &mut TTYPort {
        &mut self.port
    }

    /// One read of the port into `pending`; an error once `deadline` has passed.
    fn fill(&mut self, deadline: Instant, timeout: Duration) -> io::Result<()> {
        if Instant::now() >= deadline {
            return Err(io::Error::new(
                io::ErrorKind::TimedOut,
                format!(
                    "nothing more within {timeout:?}; buffered: {:?}",
                    self.pending
                ),
            ));
        }
        let mut buf = [0u8; 256];
        match self.port.read(&mut buf) {
            Ok(0) => Err(io::Error::new(
                io::ErrorKind::UnexpectedEof,
                "serial port closed",
            )),
            Ok(n) => {
                self.pending.extend(&buf[..n]);
                Ok(())
            }
            Err(e) if is_transient(&e) => Ok(()),
            Err(e) => Err(e),
        }
    }
}

/// Whether a port error only means "nothing yet" (a timeout or an interrupted call).
pub(crate) fn is_transient(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted
    )
}
