//! The flight controller's telemetry UART: a transmit queue of [`QUEUE`] frames drained by its
//! own thread onto one end of a pseudo-terminal pair, like a UART's DMA ring. The flight
//! controller never waits on the port: a frame that finds the queue full is dropped and counted.
//! The thread ends when the sender is dropped (after writing what was queued) or when the port
//! fails.

use serialport::{SerialPort, TTYPort};
use std::io::Write;
use std::sync::mpsc::{self, Receiver, SyncSender, TrySendError};
use std::thread::JoinHandle;
use std::time::Duration;

/// Frames the queue holds.
pub const QUEUE: usize = 256;

/// What the UART thread wrote.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct UartReport {
    /// Frames written whole.
    pub frames: u64,
    /// Bytes written (all frames, partial ones included).
    pub bytes: u64,
    /// Writes that failed (a timeout: the reader stalled; or the error that ended the thread).
    pub write_errors: u64,
    /// The error that ended the thread, if one did.
    pub ended_by: Option<String>,
}

/// The flight controller's side: queues frames.
pub struct UartTx {
    tx: SyncSender<Vec<u8>>,
    dropped: u64,
}

impl UartTx {
    /// Queues `frame`; `false` (and counted) if the queue is full or the thread has ended.
    pub fn send(&mut self, frame: Vec<u8>) -> bool {
        match self.tx.try_send(frame) {
            Ok(()) => true,
            Err(TrySendError::Full(_) | TrySendError::Disconnected(_)) => {
                self.dropped += 1;
                false
            }
        }
    }

    /// Frames dropped so far.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }
}

/// The running thread; [`UartThread::join`] once every [`UartTx`] is dropped.
pub struct UartThread(JoinHandle<UartReport>);

impl UartThread {
    /// Waits for the thread (it ends when the sender is gone and the queue is written).
    pub fn join(self) -> UartReport {
        self.0.join().unwrap_or_else(|_| UartReport {
            ended_by: Some("the UART thread panicked".into()),
            ..UartReport::default()
        })
    }
}

/// Starts the UART on `port` (writes time out after 1 s).
pub fn spawn(mut port: TTYPort) -> std::io::Result<(UartTx, UartThread)> {
    port.set_timeout(Duration::from_secs(1))?;
    let (tx, rx) = mpsc::sync_channel(QUEUE);
    let thread = std::thread::Builder::new()
        .name("vfc-uart".into())
        .spawn(move || drain(port, rx))?;
    Ok((UartTx { tx, dropped: 0 }, UartThread(thread)))
}

fn drain(mut port: TTYPort, rx: Receiver<Vec<u8>>) -> UartReport {
    let mut report = UartReport::default();
    for frame in rx {
        let mut rest = &frame[..];
        while !rest.is_empty() {
            match port.write(rest) {
                Ok(0) => {
                    report.ended_by = Some("the port accepts no more bytes".into());
                    return report;
                }
                Ok(n) => {
                    report.bytes += n as u64;
                    rest = &rest[n..];
                }
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {
                    // The reader stalled for a second: this frame is cut short, the next goes on.
                    report.write_errors += 1;
                    break;
                }
                Err(e) => {
                    report.write_errors += 1;
                    report.ended_by = Some(format!("writing the port: {e}"));
                    return report;
                }
            }
        }
        if rest.is_empty() {
            report.frames += 1;
        }
    }
    let _ = port.flush();
    report
}
