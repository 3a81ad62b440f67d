//! The embedded default: the firmware library's link handler ([`Device`]) running on the host,
//! behind a real pseudo-terminal pair, so a scene streams exactly as to a board.
//!
//! [`spawn_device`] starts the device on one end of a `TTYPort::pair()` in a thread: it reads
//! what arrives, feeds it to [`Device::feed`] with the time of a monotonic clock, and writes what
//! [`Device::poll`] sends. It also decodes the `Served` reports it sends itself (the CRC-32C of
//! every image it latched into the emulated chip), so the caller can check byte for byte that
//! what the device served is what the host predicted. The host side is an ordinary
//! [`Session`](crate::stream::Session) on the other end.

use margemu_firmware::link::Device;
use margemu_protocol::link::{Accumulator, FeedResult, FrameRepr, Message};
use serialport::{SerialPort, TTYPort};
use std::io::{ErrorKind, Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// What the loopback device saw and served.
#[derive(Clone, Debug, Default)]
pub struct DeviceReport {
    /// `(sample index, CRC-32C of the image served, underrun)` of every instant served.
    pub served: Vec<(u64, u32, bool)>,
    /// Samples served, underruns and overruns, as the device counted them.
    pub counters: (u64, u64, u64),
    /// Why the device loop ended (stop flag, end of file, or a port error).
    pub ended: String,
}

/// A running loopback device; [`LoopbackDevice::stop`] ends it and returns its report.
pub struct LoopbackDevice {
    stop: Arc<AtomicBool>,
    thread: JoinHandle<DeviceReport>,
}

impl LoopbackDevice {
    /// Stops the device loop and returns what it served.
    pub fn stop(self) -> DeviceReport {
        self.stop.store(true, Ordering::Relaxed);
        self.thread.join().unwrap_or_else(|_| DeviceReport {
            ended: "the device thread panicked".into(),
            ..DeviceReport::default()
        })
    }
}

/// Runs the firmware's [`Device`] on `port` (one end of a pseudo-terminal pair) until stopped.
pub fn spawn_device(mut port: TTYPort) -> std::io::Result<LoopbackDevice> {
    port.set_timeout(Duration::from_millis(1))?;
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    let thread = std::thread::Builder::new()
        .name("loopback-device".into())
        .spawn(move || {
            let mut device: Box<Device> = Box::default();
            let mut sniffer = ServedSniffer::default();
            let origin = Instant::now();
            let mut buf = vec![0u8; 4096];
            let now = || origin.elapsed().as_nanos() as u64;
            let ended = loop {
                if flag.load(Ordering::Relaxed) {
                    break "stopped".to_owned();
                }
                match port.read(&mut buf) {
                    Ok(0) => break "end of file".to_owned(),
                    Ok(n) => device.feed(&buf[..n], now()),
                    Err(e)
                        if matches!(
                            e.kind(),
                            ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted
                        ) => {}
                    Err(e) => break format!("port error: {e}"),
                }
                let mut write_error = None;
                device.poll(now(), &mut |frame: &[u8]| {
                    sniffer.observe(frame);
                    if write_error.is_none() {
                        write_error = port.write_all(frame).err();
                    }
                });
                if let Some(e) = write_error {
                    break format!("port error: {e}");
                }
            };
            let c = device.counters();
            DeviceReport {
                served: sniffer.served,
                counters: (c.served, u64::from(c.underruns), u64::from(c.overruns)),
                ended,
            }
        })?;
    Ok(LoopbackDevice { stop, thread })
}

/// Decodes the device's own outgoing frames and keeps its `Served` reports.
#[derive(Default)]
struct ServedSniffer {
    accumulator: Accumulator,
    served: Vec<(u64, u32, bool)>,
}

impl ServedSniffer {
    fn observe(&mut self, wire: &[u8]) {
        let mut rest = wire;
        while !rest.is_empty() {
            match self.accumulator.feed(rest) {
                FeedResult::Consumed => break,
                FeedResult::Success { frame, remaining } => {
                    if let Ok(FrameRepr {
                        message: Message::Served(batch),
                        ..
                    }) = FrameRepr::parse(&frame)
                    {
                        for (k, s) in batch.samples.iter().enumerate() {
                            self.served
                                .push((batch.first_index + k as u64, s.crc32c, s.underrun));
                        }
                    }
                    rest = remaining;
                }
                other => rest = other.remaining(),
            }
        }
    }
}
