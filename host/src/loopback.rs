//! The embedded default: the firmware library's link handler ([`Device`]) running on the host,
//! behind a real pseudo-terminal pair, so a scene streams exactly as to a board.
//!
//! The device buffers [`BUFFER`] samples: more than the QEMU board's 128, as a board with a few
//! tens of KB of RAM to spare would, so that the host's scheduling hiccups on a busy machine
//! (several ms) stay well inside the lead at 8 kHz and beyond.
//!
//! [`spawn_device`] starts the device on one end of a `TTYPort::pair()` in a thread. Each turn
//! of its loop waits up to 1 ms for bytes, serves the sample instants that are due
//! ([`Device::poll`], as a board's timer interrupt would, before acting on the bytes), feeds
//! every byte that has arrived ([`Device::feed`], as a UART interrupt would) and polls again,
//! writing every frame the device sends, on a monotonic clock. The host side is an ordinary [`Session`](crate::stream::Session) on the
//! other end; it checks the device's own Served reports against its prediction.

use margemu_firmware::link::{Counters, Device};
use serialport::{SerialPort, TTYPort};
use std::io::{Read, Write};
use std::ops::ControlFlow;
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
pub fn spawn_device(port: TTYPort) -> std::io::Result<LoopbackDevice> {
    spawn_device_with(port, |_, _| ControlFlow::Continue(()))
}

/// [`spawn_device`] with a `hook` called at the top of every turn of the loop with the device
/// and the local time (ns): it may act as the device under test on the chip
/// ([`Device::chip_mut`]), replace the device (a reboot: a new [`Device::with_identity`]
/// announces its reset cause), or end the loop with a reason (the board vanishes: the port is
/// closed).
pub fn spawn_device_with(
    mut port: TTYPort,
    mut hook: impl FnMut(&mut Box<Firmware>, u64) -> ControlFlow<String> + Send + 'static,
) -> std::io::Result<LoopbackDevice> {
    port.set_timeout(Duration::from_millis(1))?;
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    let thread = std::thread::Builder::new()
        .name("loopback-device".into())
        .spawn(move || {
            let mut device: Box<Firmware> = Box::default();
            let origin = Instant::now();
            let now = || origin.elapsed().as_nanos() as u64;
            let ended = loop {
                if flag.load(Ordering::Relaxed) {
                    break "stopped".to_owned();
                }
                if let ControlFlow::Break(why) = hook(&mut device, now()) {
                    break why;
                }
                match turn(&mut device, &mut port, now) {
                    Ok(true) => {}
                    Ok(false) => break "end of file".to_owned(),
                    Err(e) => break format!("port error: {e}"),
                }
            };
            DeviceReport {
                counters: *device.counters(),
                ended,
            }
        })?;
    Ok(LoopbackDevice { stop, thread })
}

/// One turn of the device loop: wait up to 1 ms for bytes, serve the instants due by then (as a
/// board's timer interrupt would, before the bytes are acted on), take every byte that has
/// arrived (as a UART interrupt would; at most 64 reads), and send what the device has to say. `Ok(false)` at end
/// of file.
fn turn(device: &mut Firmware, port: &mut TTYPort, now: impl Fn() -> u64) -> std::io::Result<bool> {
    let mut buf = [0u8; 4096];
    let mut n = match port.read(&mut buf) {
        Ok(0) => return Ok(false),
        Ok(n) => n,
        Err(e) if crate::stream::rx::is_transient(&e) => 0,
        Err(e) => return Err(e),
    };
    let mut out = Vec::new();
    let mut tx = |frame: &[u8]| out.extend_from_slice(frame);
    device.poll(now(), &mut tx);
    for _ in 0..64 {
        if n == 0 {
            break;
        }
        device.feed(&buf[..n], now());
        n = match port.bytes_to_read()? {
            0 => 0,
            _ => port.read(&mut buf)?,
        };
    }
    device.poll(now(), &mut tx);
    port.write_all(&out)?;
    Ok(true)
}
