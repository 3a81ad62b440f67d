//! The device's fault schedule: the faults the host sent for the rig's devices
//! (`margemu_model::fault` defines them), held without allocation, asked by time.
//!
//! Each entry keeps the fault's index among its own device's faults and that device's seed, so
//! its random stream is [`fault_rng`]`(seed, index)` on the device exactly as on the host.
//!
//! ```
//! use margemu_firmware::fault::FaultSchedule;
//! use margemu_model::fault::{Fault, FaultKind, Window};
//! let mut s = FaultSchedule::new();
//! s.push(Fault::new(1, Window::new(0, 10), FaultKind::Nak), 99).unwrap();
//! s.push(Fault::new(0, Window::new(5, 20), FaultKind::Reset), 7).unwrap();
//! s.push(Fault::new(1, Window::new(30, 40), FaultKind::Nak), 99).unwrap();
//! assert_eq!(s.active(1, 35).map(|e| e.index).collect::<Vec<_>>(), [1]);
//! assert_eq!(s.active(0, 35).count(), 0);
//! // Nothing happens between 20 and 30, nor after 40.
//! assert_eq!((s.quiet_until(25), s.quiet_until(35), s.quiet_until(45)), (Some(30), None, Some(u64::MAX)));
//! ```

use margemu_model::fault::{
    self, fault_rng, overlaps_exclusively, Fault, ScheduleFull, MAX_FAULTS,
};
use margemu_model::rng::StreamRng;

/// One fault of the schedule.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScheduledFault {
    /// The fault.
    pub fault: Fault,
    /// Its index among its device's faults.
    pub index: u8,
    /// Its device's seed.
    pub seed: u64,
}

impl ScheduledFault {
    /// Its random stream, from the start.
    pub fn rng(&self) -> StreamRng {
        fault_rng(self.seed, usize::from(self.index))
    }
}

/// Why a fault was not taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScheduleError {
    /// [`MAX_FAULTS`] are held already.
    Full,
    /// It overlaps a fault it may not overlap (`margemu_model::fault::overlaps_exclusively`).
    Overlaps,
}

impl From<ScheduleFull> for ScheduleError {
    fn from(_: ScheduleFull) -> Self {
        ScheduleError::Full
    }
}

/// The rig's faults, in the order received.
#[derive(Clone, Debug, Default)]
pub struct FaultSchedule {
    faults: heapless::Vec<ScheduledFault, MAX_FAULTS>,
}

impl FaultSchedule {
    /// No faults.
    pub const fn new() -> Self {
        Self {
            faults: heapless::Vec::new(),
        }
    }

    /// Appends a fault of the device whose seed is `seed`.
    pub fn push(&mut self, fault: Fault, seed: u64) -> Result<(), ScheduleError> {
        if self
            .faults
            .iter()
            .any(|e| overlaps_exclusively(&e.fault, &fault))
        {
            return Err(ScheduleError::Overlaps);
        }
        let index = self.for_device(fault.device).count() as u8;
        self.faults
            .push(ScheduledFault { fault, index, seed })
            .map_err(|_| ScheduleError::Full)
    }

    /// Forgets every fault (a new Configure).
    pub fn clear(&mut self) {
        self.faults.clear();
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.faults.is_empty()
    }

    /// Every fault, in order.
    pub fn iter(&self) -> impl Iterator<Item = &ScheduledFault> {
        self.faults.iter()
    }

    /// Device `device`'s faults, in order.
    pub fn for_device(&self, device: u8) -> impl Iterator<Item = &ScheduledFault> {
        self.faults.iter().filter(move |e| e.fault.device == device)
    }

    /// `None` if some fault's window holds `t_ns`; else the first instant after `t_ns` a window
    /// starts at ([`UNTIL_END`](margemu_model::fault::UNTIL_END) if none does): until then the
    /// schedule does nothing.
    pub fn quiet_until(&self, t_ns: u64) -> Option<u64> {
        fault::quiet_until(self.faults.iter().map(|e| &e.fault.window), t_ns)
    }

    /// Device `device`'s faults whose window holds `t_ns`.
    pub fn active(&self, device: u8, t_ns: u64) -> impl Iterator<Item = &ScheduledFault> {
        self.for_device(device)
            .filter(move |e| e.fault.window.contains(t_ns))
    }
}
