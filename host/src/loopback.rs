//! The embedded default: the firmware library's link handler ([`Device`]) running on the host,
//! behind a real pseudo-terminal pair, so a scene streams exactly as to a board.
//!
//! The device buffers [`BUFFER`] samples: more than the QEMU board's 128, as a board with a few
//! tens of KB of RAM to spare would, so that the host's scheduling hiccups on a busy machine
//! (several ms) stay well inside the lead at 8 kHz and beyond.
//!
//! [`spawn_device`] starts the device on one end of a `TTYPort::pair()` in a thread. Each turn
//! of its loop reads what arrived (1 ms timeout), serves the sample instants that are due
//! ([`Device::poll`], as a board's timer interrupt would, before acting on the bytes), feeds the
//! bytes ([`Device::feed`]) and polls again, writing every frame the device sends, on a
//! monotonic clock. The host side is an ordinary [`Session`](crate::stream::Session) on the
//! other end; it checks the device's own Served reports against its prediction.

use margemu_firmware::link::{Counters, Device};
use serialport::{SerialPort, TTYPort};
use std::io::{Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Samples the loopback device buffers (its credit window).
pub const BUFFER: usize = 1024;

/// The loopback device: the firmware's link handler with a [`BUFFER`]-sample window.
pub type Firmware = Device<BUFFER>;

/// What the loopback device counted, and why it ended.
#[derive(Clone, Debug, Default)]
pub struct DeviceReport {
    /// The device's counters at the end (served, underruns, overruns, receive errors).
    pub counters: Counters,
    /// Why the device loop ended (stop flag, end of file, or a port error).
    pub ended: String,
}

/// A running loopback device; [`LoopbackDevice::stop`] ends it and returns its report.
pub struct LoopbackDevice {
    stop: Arc<AtomicBool>,
    thread: JoinHandle<DeviceReport>,
}

impl LoopbackDevice {
    /// Stops the device loop and returns its report.
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
            let mut device: Box<Firmware> = Box::default();
            let origin = Instant::now();
            let now = || origin.elapsed().as_nanos() as u64;
            let mut buf = vec![0u8; 4096];
            let ended = loop {
                if flag.load(Ordering::Relaxed) {
                    break "stopped".to_owned();
                }
                let n = match port.read(&mut buf) {
                    Ok(0) => break "end of file".to_owned(),
                    Ok(n) => n,
                    Err(e) if crate::stream::rx::is_transient(&e) => 0,
                    Err(e) => break format!("port error: {e}"),
                };
                if let Err(e) = serve(&mut device, &mut port, &buf[..n], now()) {
                    break format!("port error: {e}");
                }
            };
            DeviceReport {
                counters: *device.counters(),
                ended,
            }
        })?;
    Ok(LoopbackDevice { stop, thread })
}

/// One turn of the device loop at local time `now_ns`: serve what is due, take `input`, send.
fn serve(
    device: &mut Firmware,
    port: &mut impl Write,
    input: &[u8],
    now_ns: u64,
) -> std::io::Result<()> {
    let mut result = Ok(());
    let mut tx = |frame: &[u8]| {
        if result.is_ok() {
            result = port.write_all(frame);
        }
    };
    device.poll(now_ns, &mut tx);
    if !input.is_empty() {
        device.feed(input, now_ns);
        device.poll(now_ns, &mut tx);
    }
    result
}
