//! Bus faults applied to a chip's bus target: the one application of the schedule's `nak`,
//! `corrupt` and `clock_stretch` faults ([`margemu_model::fault::FaultKind`]), used by the
//! firmware's board paths and by the host's virtual buses (`margemu_hil::bus`) alike, so a
//! driver sees the same bytes on both.
//!
//! [`BusFaults`] holds one device's bus faults (taken from the rig's [`FaultSchedule`] with
//! [`BusFaults::for_device`] or kept up to date with [`BusFaults::sync`]) and the state they need
//! between bus events; [`BusFaults::on`] wraps the device's target for one or more bus events at
//! one instant into a [`Faulted`] target, itself an [`SpiTarget`] and an [`I2cTarget`].
//!
//! **The instant of a bus event** is the one its caller passes to [`BusFaults::on`]: the chip's
//! scene clock ([`Chip::now_ns`](crate::chip::Chip::now_ns)), on the board and on the host, so a
//! window of scene time covers the same transactions in both.
//!
//! **What each kind does:**
//! - `nak`: on I2C the chip does not acknowledge any of its addresses at a START (or repeated
//!   START) inside the window, so the controller sees NoAcknowledge of the address; the chip
//!   sees neither that START nor the bytes up to the next START (writes are NACKed, reads find
//!   the released line, [`RELEASED`]); STOP reaches it. On SPI the chip is dead for any
//!   transaction whose chip select falls in the window: it sees nothing, drives nothing, and
//!   MISO reads [`RELEASED`] (`0xFF`) on every byte. That is what a controller reads from an
//!   undriven MISO on the flight controllers margemu targets: Betaflight configures the MISO
//!   pin of its STM32 SPI buses with a pull-up (`SPI_IO_AF_SDI_CFG` in its STM32 platform
//!   headers), and a released line with a pull-up reads ones; the drivers' probes then find a
//!   WHO_AM_I of `0xFF`, no known chip. (margemu's host adapters read `0xFF` with chip select
//!   released for the same reason.)
//! - `corrupt { probability }`: each byte the chip drives (every MISO byte of a selection,
//!   every byte the controller reads on I2C) inside the window has one bit flipped with that
//!   probability. The draws come from the fault's own stream ([`ScheduledFault::rng`]), in
//!   order, per driven byte: one [`unit_f64`] draw `u`; if `u < probability`, a second draw
//!   `v` picks the bit `floor(8 v)` (0 = LSB). The stream advances only on bytes inside its
//!   window, so the same transactions corrupt the same bits on every run. Time moves forward
//!   within a run: a byte at an instant before the stream's last draw (a new run of the same
//!   schedule) starts the stream again. On SPI the driven bytes are those the chip prepares
//!   ([`SpiTarget`]'s contract): one at select and one after each byte clocked, the last of
//!   which the controller never clocks out; each takes its draw.
//! - `clock_stretch { stretch_ns }`: on I2C the chip holds SCL low `stretch_ns` before each
//!   byte it drives (each byte the controller reads), counted in
//!   [`BusFaults::take_stretch_ns`] for the caller to spend (a board waits that long before
//!   it loads the byte; the host's virtual bus advances its clock and applies its
//!   controller's timeout). SPI has no clock stretching: on an SPI target it does nothing.
//!
//! With no fault active at the instant, the target's bytes pass unchanged and no draw is made.

use crate::chip::{I2cTarget, SpiTarget};
use crate::fault::{FaultSchedule, ScheduledFault};
use margemu_model::fault::{FaultKind, Window, MAX_FAULTS};
use margemu_model::rng::{unit_f64, StreamRng};

/// What a controller reads from a line nobody drives (MISO with its pull-up, the released
/// open-drain SDA): `0xFF`.
pub const RELEASED: u8 = 0xFF;

/// One bus fault of the device.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Entry {
    window: Window,
    effect: Effect,
    /// The fault, for its random stream.
    fault: ScheduledFault,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Effect {
    Nak,
    Corrupt(f64),
    Stretch(u32),
}

/// One device's bus faults and their state between bus events (see the module docs).
#[derive(Clone, Debug)]
pub struct BusFaults {
    device: u8,
    faults: heapless::Vec<Entry, MAX_FAULTS>,
    /// The stream of the corrupt fault in use (its index among the device's faults) and the
    /// instant of its last draw. Corrupt faults of one device never overlap, and time only
    /// moves forward within a run, so one is enough.
    stream: Option<(u8, StreamRng, u64)>,
    /// The current selection (SPI) or START (I2C) was not acknowledged: the chip is absent.
    absent: bool,
    /// Stretch owed to the bus since the last [`BusFaults::take_stretch_ns`].
    stretch_ns: u64,
}

impl BusFaults {
    /// No faults, for device `device` of the rig.
    pub const fn new(device: u8) -> Self {
        Self {
            device,
            faults: heapless::Vec::new(),
            stream: None,
            absent: false,
            stretch_ns: 0,
        }
    }

    /// Device `device`'s bus faults in `schedule`.
    pub fn for_device(schedule: &FaultSchedule, device: u8) -> Self {
        let mut faults = Self::new(device);
        faults.sync(schedule);
        faults
    }

    /// Makes them the device's bus faults in `schedule` (as it is now: a fault added, or a new
    /// Configure's schedule). The faults held on stay as they are, with their streams.
    pub fn sync(&mut self, schedule: &FaultSchedule) {
        let mut fresh = heapless::Vec::<Entry, MAX_FAULTS>::new();
        for e in schedule.for_device(self.device) {
            let effect = match e.fault.kind {
                FaultKind::Nak => Effect::Nak,
                FaultKind::Corrupt { probability } => Effect::Corrupt(f64::from(probability)),
                FaultKind::ClockStretch { stretch_ns } => Effect::Stretch(stretch_ns),
                _ => continue,
            };
            let entry = Entry {
                window: e.fault.window,
                effect,
                fault: *e,
            };
            // Never full: the schedule holds at most as many faults in all.
            let _ = fresh.push(entry);
        }
        if fresh != self.faults {
            let kept = match &self.stream {
                Some((index, ..)) => fresh
                    .iter()
                    .any(|e| self.faults.contains(e) && e.fault.index == *index),
                None => false,
            };
            if !kept {
                self.stream = None;
            }
            self.faults = fresh;
        }
    }

    /// The rig's device these faults belong to.
    pub fn device(&self) -> u8 {
        self.device
    }

    /// Whether the device has no bus fault at all.
    pub fn is_empty(&self) -> bool {
        self.faults.is_empty()
    }

    /// What is in force at `t_ns`, in one pass over the faults.
    fn active(&self, t_ns: u64) -> Active {
        let mut active = Active::default();
        for (i, e) in self.faults.iter().enumerate() {
            if !e.window.contains(t_ns) {
                continue;
            }
            match e.effect {
                Effect::Nak => active.nak = true,
                Effect::Corrupt(_) => active.corrupt = active.corrupt.or(Some(i)),
                Effect::Stretch(ns) => active.stretch_ns = active.stretch_ns.saturating_add(ns),
            }
        }
        active
    }

    /// Whether the chip refuses its bus at `t_ns` (a `nak` window).
    pub fn nak(&self, t_ns: u64) -> bool {
        self.active(t_ns).nak
    }

    /// How long the chip stretches SCL before each byte it drives at `t_ns`.
    pub fn stretch_ns(&self, t_ns: u64) -> u32 {
        self.active(t_ns).stretch_ns
    }

    /// The stretch owed to the bus since the last call (the sum over the bytes driven).
    pub fn take_stretch_ns(&mut self) -> u64 {
        core::mem::take(&mut self.stretch_ns)
    }

    /// `byte`, driven by the chip at `t_ns`, as the controller receives it (`corrupt`).
    pub fn drive(&mut self, t_ns: u64, byte: u8) -> u8 {
        let corrupt = self.active(t_ns).corrupt;
        self.corrupt(corrupt, t_ns, byte)
    }

    /// `byte` through the corrupt fault at `entry` of the faults, if any.
    fn corrupt(&mut self, entry: Option<usize>, t_ns: u64, byte: u8) -> u8 {
        let Some((probability, fault)) =
            entry
                .and_then(|i| self.faults.get(i))
                .and_then(|e| match e.effect {
                    Effect::Corrupt(p) => Some((p, e.fault)),
                    _ => None,
                })
        else {
            return byte;
        };
        // A stream starts at its fault's first byte: another fault's, or an instant before the
        // last draw (a new run of the same schedule), starts it again.
        let fresh = match &self.stream {
            Some((index, _, last_ns)) => *index != fault.index || t_ns < *last_ns,
            None => true,
        };
        if fresh {
            self.stream = Some((fault.index, fault.rng(), t_ns));
        }
        let Some((_, rng, last_ns)) = &mut self.stream else {
            return byte;
        };
        *last_ns = t_ns;
        flip(rng, probability, byte)
    }

    /// Applies to `bytes`, the next bytes the chip will drive at `t_ns` in order, the
    /// corruption [`BusFaults::drive`] will apply to them, without drawing: for a board that
    /// loads its MISO stream ahead of the transaction, and then replays the transaction
    /// through [`BusFaults::on`], which draws the same.
    pub fn preview(&self, t_ns: u64, bytes: &mut [u8]) {
        let Some(e) = self.active(t_ns).corrupt.and_then(|i| self.faults.get(i)) else {
            return;
        };
        let Effect::Corrupt(probability) = e.effect else {
            return;
        };
        let mut rng = match &self.stream {
            Some((index, rng, last_ns)) if *index == e.fault.index && t_ns >= *last_ns => {
                rng.clone()
            }
            _ => e.fault.rng(),
        };
        for byte in bytes {
            *byte = flip(&mut rng, probability, *byte);
        }
    }

    /// `target` with these faults, for bus events at the instant `now_ns`.
    pub fn on<'a, T: ?Sized>(&'a mut self, target: &'a mut T, now_ns: u64) -> Faulted<'a, T> {
        Faulted {
            target,
            active: self.active(now_ns),
            faults: self,
            now_ns,
        }
    }
}

/// `byte` with one bit flipped with `probability`, by the module docs' rule.
fn flip(rng: &mut StreamRng, probability: f64, byte: u8) -> u8 {
    if unit_f64(rng) < probability {
        let bit = (unit_f64(rng) * 8.0) as u32; // in 0..8: the draw is below 1
        byte ^ 1u8.wrapping_shl(bit)
    } else {
        byte
    }
}

/// The faults in force at one instant.
#[derive(Clone, Copy, Debug, Default)]
struct Active {
    nak: bool,
    /// The corrupt fault's position among the faults.
    corrupt: Option<usize>,
    stretch_ns: u32,
}

/// A target seen through its device's [`BusFaults`] at one instant ([`BusFaults::on`]).
pub struct Faulted<'a, T: ?Sized> {
    target: &'a mut T,
    faults: &'a mut BusFaults,
    now_ns: u64,
    active: Active,
}

impl<T: ?Sized> Faulted<'_, T> {
    /// A byte the chip drives (`corrupt`).
    fn drive(&mut self, byte: u8) -> u8 {
        match self.active.corrupt {
            None => byte,
            some => self.faults.corrupt(some, self.now_ns, byte),
        }
    }
}

impl<T: ?Sized> Faulted<'_, T> {
    /// The instant of its bus events.
    pub fn now_ns(&self) -> u64 {
        self.now_ns
    }

    /// [`BusFaults::take_stretch_ns`]: the stretch its bytes owe the bus so far.
    pub fn take_stretch_ns(&mut self) -> u64 {
        self.faults.take_stretch_ns()
    }
}

impl<T: SpiTarget + ?Sized> SpiTarget for Faulted<'_, T> {
    fn select(&mut self) -> u8 {
        self.faults.absent = self.active.nak;
        if self.faults.absent {
            return RELEASED;
        }
        let miso = self.target.select();
        self.drive(miso)
    }

    fn exchange(&mut self, mosi: u8) -> u8 {
        if self.faults.absent {
            return RELEASED;
        }
        let miso = self.target.exchange(mosi);
        self.drive(miso)
    }

    fn deselect(&mut self) {
        if !core::mem::take(&mut self.faults.absent) {
            self.target.deselect();
        }
    }
}

impl<T: I2cTarget + ?Sized> I2cTarget for Faulted<'_, T> {
    fn start(&mut self, address: u8, read: bool) -> bool {
        self.faults.absent = self.active.nak;
        !self.faults.absent && self.target.start(address, read)
    }

    fn write(&mut self, byte: u8) -> bool {
        !self.faults.absent && self.target.write(byte)
    }

    fn read(&mut self) -> u8 {
        if self.faults.absent {
            return RELEASED;
        }
        let byte = self.target.read();
        // SCL held low before the byte, then the byte driven.
        let stretch = u64::from(self.active.stretch_ns);
        self.faults.stretch_ns = self.faults.stretch_ns.saturating_add(stretch);
        self.drive(byte)
    }

    fn stop(&mut self) {
        self.faults.absent = false;
        self.target.stop();
    }
}

#[cfg(test)]
mod tests;
