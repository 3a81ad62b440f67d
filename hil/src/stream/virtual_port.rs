//! [`VirtualPort`]: a [`Port`] for exact tests. Behind it the firmware's link handler
//! ([`Device`], the loopback device's code) runs on a [`VirtualClock`]: the device is polled
//! every tick (1 ms by default) of virtual time, a frame the host writes reaches the device at
//! the virtual instant it is written, and the device's frames reach the host at the tick they
//! are sent. Time moves only when the session waits ([`Port::wait`], [`Port::spin_until`]): to
//! the next tick with something for the host, or to the session's deadline. A session on it
//! therefore runs as fast as the machine allows and gives the same result on any machine,
//! whatever its load.
//!
//! Faults, each at an exact virtual time or item: a batch lost on the way
//! ([`VirtualPort::drop_batch`]), credit withheld ([`VirtualPort::withhold_credit`]: the
//! device's Credit and Telemetry frames do not arrive), a host that wakes late
//! ([`VirtualPort::oversleep`]). What went over the link is kept in a shared [`Trace`].

use super::clock::{Clock, VirtualClock};
use super::port::Port;
use super::rx::{Decoder, DeviceMessage, RxEvent};
use margemu_firmware::link::{Counters, Device};
use margemu_protocol::link::{Accumulator, DeviceState, FeedResult, FrameRepr, Message};
use std::collections::VecDeque;
use std::io;
use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::{Arc, Mutex, MutexGuard};

/// One sample batch the host wrote.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BatchWrite {
    /// Virtual host time of the write, ns.
    pub at_ns: u64,
    /// Its first item.
    pub first: u64,
    /// Its items.
    pub len: u64,
    /// The credit limit the host had been granted by then (the newest that reached it).
    pub granted: u64,
    /// Whether it reached the device (not dropped by [`VirtualPort::drop_batch`]).
    pub delivered: bool,
}

/// What went over a [`VirtualPort`].
#[derive(Clone, Debug, Default)]
pub struct Trace {
    /// Every sample batch the host wrote, in order.
    pub batches: Vec<BatchWrite>,
    /// When the host wrote Start, ns.
    pub start_ns: Option<u64>,
    /// When the host wrote Stop, ns.
    pub stop_ns: Option<u64>,
    /// The device's counters, as of its last poll.
    pub counters: Counters,
    /// The device's state, as of its last poll.
    pub state: Option<DeviceState>,
    /// Credit and Telemetry frames withheld from the host.
    pub withheld: u64,
}

impl Trace {
    /// Batches written beyond the credit the host had been granted.
    pub fn beyond_credit(&self) -> Vec<BatchWrite> {
        let over = |b: &&BatchWrite| b.first + b.len > b.granted;
        self.batches.iter().filter(over).copied().collect()
    }
}

/// The firmware [`Device`] with a buffer of `N` items on a virtual clock (see the module docs).
pub struct VirtualPort<const N: usize> {
    clock: VirtualClock,
    device: Box<Device<N>>,
    tick_ns: u64,
    next_tick_ns: u64,
    decoder: Decoder,
    decoded_tx: Sender<RxEvent>,
    decoded: Receiver<RxEvent>,
    queue: VecDeque<RxEvent>,
    host_frames: Accumulator,
    granted: u64,
    drops: Vec<u64>,
    withhold: Option<(u64, u64)>,
    oversleep: Option<(u64, u64)>,
    trace: Arc<Mutex<Trace>>,
}

impl<const N: usize> VirtualPort<N> {
    /// A powered-on device at virtual time 0 on `clock`, polled every `tick_ns`.
    pub fn new(clock: VirtualClock, tick_ns: u64) -> Self {
        let (decoded_tx, decoded) = channel();
        Self {
            next_tick_ns: clock.now_ns(),
            clock,
            device: Box::default(),
            tick_ns: tick_ns.max(1),
            decoder: Decoder::default(),
            decoded_tx,
            decoded,
            queue: VecDeque::new(),
            host_frames: Accumulator::new(),
            granted: 0,
            drops: Vec::new(),
            withhold: None,
            oversleep: None,
            trace: Arc::default(),
        }
    }

    /// The first write of the batch that starts at item `first` is lost on the way.
    pub fn drop_batch(mut self, first: u64) -> Self {
        self.drops.push(first);
        self
    }

    /// The device's Credit and Telemetry frames sent in `[from_ns, until_ns)` do not reach the
    /// host (its other frames do).
    pub fn withhold_credit(mut self, from_ns: u64, until_ns: u64) -> Self {
        self.withhold = Some((from_ns, until_ns));
        self
    }

    /// The first wait that runs to its deadline at or after `at_ns` returns `delay_ns` late (the
    /// host's thread was not scheduled); the device runs on meanwhile.
    pub fn oversleep(mut self, at_ns: u64, delay_ns: u64) -> Self {
        self.oversleep = Some((at_ns, delay_ns));
        self
    }

    /// A handle on what goes over the link, readable after the session has consumed the port.
    pub fn trace(&self) -> Arc<Mutex<Trace>> {
        self.trace.clone()
    }

    fn record(&self) -> MutexGuard<'_, Trace> {
        self.trace.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Polls the device at every tick up to `until_ns`, stopping early once something for the
    /// host has arrived if `stop_early`; then the clock stands at the last tick polled, or at
    /// `until_ns` if nothing arrived.
    fn run_until(&mut self, until_ns: u64, stop_early: bool) {
        while self.next_tick_ns <= until_ns {
            let t = self.next_tick_ns;
            self.next_tick_ns += self.tick_ns;
            self.clock.set(t);
            self.poll_device(t);
            if stop_early && !self.queue.is_empty() {
                return;
            }
        }
        self.clock.set(until_ns);
    }

    fn poll_device(&mut self, t: u64) {
        let mut out = Vec::new();
        self.device
            .poll(t, &mut |frame: &[u8]| out.extend_from_slice(frame));
        let _ = self.decoder.feed(&out, t, &self.decoded_tx);
        while let Ok(event) = self.decoded.try_recv() {
            self.deliver(t, event);
        }
        let (counters, state) = (*self.device.counters(), self.device.state());
        let mut trace = self.record();
        trace.counters = counters;
        trace.state = Some(state);
    }

    /// Passes a device event on to the host, unless credit is withheld at `t`.
    fn deliver(&mut self, t: u64, event: RxEvent) {
        let credit = match &event {
            RxEvent::Message {
                message: DeviceMessage::Credit(c),
                ..
            } => Some(c.limit),
            RxEvent::Message {
                message: DeviceMessage::Telemetry(tm),
                ..
            } => Some(tm.credit_limit),
            _ => None,
        };
        if let Some(limit) = credit {
            if self
                .withhold
                .is_some_and(|(from, until)| (from..until).contains(&t))
            {
                self.record().withheld += 1;
                return;
            }
            self.granted = self.granted.max(limit);
        }
        self.queue.push_back(event);
    }

    /// Notes what the host wrote; whether the frame is to reach the device.
    fn inspect(&mut self, frame: &[u8], now: u64) -> bool {
        let mut deliver = true;
        let mut input = frame;
        while !input.is_empty() {
            let result = self.host_frames.feed(input);
            input = result.remaining();
            let FeedResult::Success { frame, .. } = result else {
                continue;
            };
            let Ok(repr) = FrameRepr::parse(&frame) else {
                continue;
            };
            let batch = match repr.message {
                Message::Images(b) => Some((b.first_index, b.images.len() as u64)),
                Message::Kinematics(b) => Some((b.first_index, b.samples.len() as u64)),
                Message::Start(_) => {
                    self.record().start_ns.get_or_insert(now);
                    None
                }
                Message::Stop => {
                    self.record().stop_ns.get_or_insert(now);
                    None
                }
                _ => None,
            };
            if let Some((first, len)) = batch {
                let dropped = self.drops.iter().position(|&d| d == first);
                if let Some(i) = dropped {
                    self.drops.swap_remove(i);
                    deliver = false;
                }
                let granted = self.granted;
                self.record().batches.push(BatchWrite {
                    at_ns: now,
                    first,
                    len,
                    granted,
                    delivered: dropped.is_none(),
                });
            }
        }
        deliver
    }
}

impl<const N: usize> Port for VirtualPort<N> {
    fn now_ns(&self) -> u64 {
        self.clock.now_ns()
    }

    fn write(&mut self, frame: &[u8]) -> io::Result<()> {
        let now = self.clock.now_ns();
        if self.inspect(frame, now) {
            self.device.feed(frame, now);
        }
        Ok(())
    }

    fn wait(&mut self, deadline_ns: u64) -> Option<RxEvent> {
        if let Some(event) = self.queue.pop_front() {
            return Some(event);
        }
        let deadline = deadline_ns.max(self.clock.now_ns());
        self.run_until(deadline, true);
        if let Some(event) = self.queue.pop_front() {
            return Some(event);
        }
        if let Some((_, delay)) = self.oversleep.filter(|&(at, _)| deadline >= at) {
            self.oversleep = None;
            self.run_until(deadline + delay, false);
        }
        None
    }

    fn try_event(&mut self) -> Option<RxEvent> {
        self.queue.pop_front()
    }

    fn spin_until(&mut self, deadline_ns: u64) {
        let deadline = deadline_ns.max(self.clock.now_ns());
        self.run_until(deadline, false);
    }
}
