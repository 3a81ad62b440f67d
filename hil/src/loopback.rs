//! The embedded default: the firmware library's link handler ([`Device`]) running on the host,
//! behind a real pseudo-terminal pair, so a scene streams exactly as to a board.
//!
//! The device buffers [`BUFFER`] samples (256 KB, as a board with a large RAM would; the QEMU
//! board holds 128), so that the lead can absorb what a busy shared machine does to the host's
//! threads: stalls of tens of ms were measured here.
//!
//! [`spawn_device`] starts the device on one end of a `TTYPort::pair()` in a thread. Each turn
//! of its loop waits up to 1 ms for bytes, feeds every byte that has arrived
//! ([`Device::feed`], as a UART interrupt would have), then serves the sample instants that are
//! due and sends what the device has to say ([`Device::poll`]), on a monotonic clock. The host
//! side is an ordinary [`Session`] on the other end; it checks the
//! device's own Served reports against its prediction.

use crate::realtime::{self, Realtime, SystemScheduler};
use crate::stream::{Session, StreamConfig, StreamError, Summary};
use margemu_firmware::link::{Counters, Device};
use margemu_protocol::link::DeviceState;
use margemu_sim::scene::Scene;
use serialport::{SerialPort, TTYPort};
use std::io::{Read, Write};
use std::ops::ControlFlow;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Samples the loopback device buffers (its credit window).
pub const BUFFER: usize = 4096;

/// Stack of the loopback device's thread.
const DEVICE_THREAD_STACK: usize = 16 << 20;

/// The loopback device: the firmware's link handler with a [`BUFFER`]-sample window.
pub type Firmware = Device<BUFFER>;

/// What the loopback device counted, and why it ended.
#[derive(Clone, Debug)]
pub struct DeviceReport {
    /// The device's counters at the end (served, underruns, overruns, receive errors).
    pub counters: Counters,
    /// Its session state at the end.
    pub state: DeviceState,
    /// Why the device loop ended: `stopped` (the stop flag, or the host closed its end after
    /// the device had stopped), `end of file`, a port error, or the hook's reason.
    pub ended: String,
}

/// A running loopback device; [`LoopbackDevice::stop`] ends it and returns its report.
pub struct LoopbackDevice {
    stop: Arc<AtomicBool>,
    thread: JoinHandle<DeviceReport>,
}

impl LoopbackDevice {
    /// Whether the device loop has ended by itself (the port closed or failed, or the hook
    /// ended it).
    pub fn has_ended(&self) -> bool {
        self.thread.is_finished()
    }

    /// Stops the device loop and returns its report.
    pub fn stop(self) -> DeviceReport {
        self.stop.store(true, Ordering::Relaxed);
        self.thread.join().unwrap_or_else(|_| DeviceReport {
            counters: Counters::default(),
            state: DeviceState::Idle,
            ended: "the device thread panicked".into(),
        })
    }
}

/// Streams `scene` with `config` to a loopback device on a fresh PTY pair (the session's logs
/// in `dir`): the session's outcome and the device's report. Fails before streaming if the
/// session cannot be prepared or the PTY pair opened.
pub fn run(
    scene: &Scene,
    config: StreamConfig,
    dir: &Path,
) -> Result<(Result<Summary, StreamError>, DeviceReport), StreamError> {
    let port_err = |e: serialport::Error| StreamError::Port { source: e.into() };
    let (host, device) = TTYPort::pair().map_err(port_err)?;
    let realtime = config.realtime;
    let session = Session::new(scene, config, dir)?;
    let device =
        spawn_device_at(device, realtime).map_err(|source| StreamError::Port { source })?;
    let result = session.run_on_port(host, |_| {});
    Ok((result, device.stop()))
}

/// [`spawn_device`] with the device's thread at `realtime` ([`crate::realtime`]): it stands in
/// for a board, which no other work on the host can hold up, so a benchmark of the host's
/// pacing under load does not measure the device's thread being starved instead.
fn spawn_device_at(port: TTYPort, realtime: Realtime) -> std::io::Result<LoopbackDevice> {
    spawn_device_with_local(port, move || {
        let (guard, _) = realtime::enter(realtime, Arc::new(SystemScheduler));
        move |_: &mut Firmware, _: u64| {
            let _in_this_thread = &guard;
            ControlFlow::Continue(())
        }
    })
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
    port: TTYPort,
    hook: impl FnMut(&mut Firmware, u64) -> ControlFlow<String> + Send + 'static,
) -> std::io::Result<LoopbackDevice> {
    spawn_device_with_local(port, move || hook)
}

/// [`spawn_device_with`] for a hook that must live in the device thread (it need not be `Send`,
/// e.g. a driver sharing the chip through `Rc`): `make_hook` builds it there, before the loop.
pub fn spawn_device_with_local<H>(
    mut port: TTYPort,
    make_hook: impl FnOnce() -> H + Send + 'static,
) -> std::io::Result<LoopbackDevice>
where
    H: FnMut(&mut Firmware, u64) -> ControlFlow<String>,
{
    port.set_timeout(Duration::from_millis(1))?;
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    let thread = std::thread::Builder::new()
        .name("loopback-device".into())
        // The device is built on the stack before it is boxed (and a reboot builds another):
        // with its buffer of rig-sized images it is over half a MB.
        .stack_size(DEVICE_THREAD_STACK)
        .spawn(move || {
            let mut hook = make_hook();
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
                let turned = turn(&mut device, &mut port, now);
                // The host closes its end once its session is over; after the session's Stop
                // that is how a loopback run ends, whichever of the close and `stop` comes first.
                let stopped = device.state() == DeviceState::Stopped;
                match turned {
                    Ok(true) => {}
                    Ok(false) | Err(_) if stopped => break "stopped".to_owned(),
                    Ok(false) => break "end of file".to_owned(),
                    Err(e) => break format!("port error: {e}"),
                }
            };
            DeviceReport {
                counters: *device.counters(),
                state: device.state(),
                ended,
            }
        })?;
    Ok(LoopbackDevice { stop, thread })
}

/// One turn of the device loop: wait up to 1 ms for bytes; at that moment `t`, take every byte
/// the PTY has delivered (as a UART interrupt would have as they came; at most 64 reads), then
/// serve the instants due by `t` and send what the device has to say as of `t`. So a report
/// stamped `t` reflects every byte delivered by `t`, and a sample delivered before its instant
/// is served even if this thread was starved meanwhile (on a loaded machine it can be, for tens
/// of ms). `Ok(false)` at end of file.
fn turn(device: &mut Firmware, port: &mut TTYPort, now: impl Fn() -> u64) -> std::io::Result<bool> {
    let mut buf = [0u8; 4096];
    let n = match port.read(&mut buf) {
        Ok(0) => return Ok(false),
        Ok(n) => n,
        Err(e) if crate::stream::rx::is_transient(&e) => 0,
        Err(e) => return Err(e),
    };
    let t = now();
    device.feed(&buf[..n], t);
    // Whatever the PTY delivered by `t` is counted by `bytes_to_read` now.
    for _ in 0..64 {
        if port.bytes_to_read()? == 0 {
            break;
        }
        match port.read(&mut buf) {
            Ok(n) => device.feed(&buf[..n], now()),
            Err(e) if crate::stream::rx::is_transient(&e) => break,
            Err(e) => return Err(e),
        }
    }
    let mut out = Vec::new();
    device.poll(t, &mut |frame: &[u8]| out.extend_from_slice(frame));
    write_all(port, &out)?;
    Ok(true)
}

/// Writes all of `bytes`, waiting out the port's timeouts (the host reads slower than the
/// device writes now and then); fails on any other error (the host closed its end).
fn write_all(port: &mut TTYPort, mut bytes: &[u8]) -> std::io::Result<()> {
    while !bytes.is_empty() {
        match port.write(bytes) {
            Ok(0) => return Err(std::io::ErrorKind::WriteZero.into()),
            Ok(n) => bytes = &bytes[n..],
            Err(e) if crate::stream::rx::is_transient(&e) => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}
