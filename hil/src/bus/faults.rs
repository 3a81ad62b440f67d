//! A device's bus faults as an adapter holds them: the firmware's application
//! ([`margemu_firmware::bus_fault`]) and the chip's scene clock, read at each bus event.

use margemu_firmware::bus_fault::{BusFaults, Faulted};
use margemu_firmware::chip::Chip;
use margemu_firmware::fault::FaultSchedule;
use std::cell::{RefCell, RefMut};
use std::rc::Rc;

/// The faults of the adapter's target and how to read its scene clock.
pub(super) struct TargetFaults<T: ?Sized> {
    faults: BusFaults,
    now_ns: fn(&T) -> u64,
}

impl<T> TargetFaults<T> {
    /// `target` with the faults, at the chip's present instant.
    pub(super) fn on<'a>(&'a mut self, target: &'a mut T) -> Faulted<'a, T> {
        let now = (self.now_ns)(target);
        self.faults.on(target, now)
    }
}

/// An adapter's bus faults, shared: the adapter applies them, and whoever set it up keeps a
/// handle (a clone) to keep them in step with the rig's schedule, also once the adapter
/// belongs to a driver. None until set.
pub struct BusFaultsHandle<T>(Rc<RefCell<Option<TargetFaults<T>>>>);

impl<T> Clone for BusFaultsHandle<T> {
    fn clone(&self) -> Self {
        Self(self.0.clone())
    }
}

impl<T> Default for BusFaultsHandle<T> {
    fn default() -> Self {
        Self(Rc::default())
    }
}

impl<T> BusFaultsHandle<T> {
    /// The faults, for one bus call; `None` while in use by another call (never, on one thread).
    pub(super) fn borrow(&self) -> Option<RefMut<'_, Option<TargetFaults<T>>>> {
        self.0.try_borrow_mut().ok()
    }
}

impl<T: Chip> BusFaultsHandle<T> {
    /// Applies `faults` from now on.
    pub fn set(&self, faults: BusFaults) {
        if let Some(mut slot) = self.borrow() {
            *slot = Some(TargetFaults {
                faults,
                now_ns: T::now_ns,
            });
        }
    }

    /// Keeps them those of `device` in `schedule` ([`BusFaults::sync`]): set up on the first
    /// call (or for another device), only the faults added since on the next ones.
    pub fn sync(&self, schedule: &FaultSchedule, device: u8) {
        let Some(mut slot) = self.borrow() else {
            return;
        };
        match &mut *slot {
            Some(f) if f.faults.device() == device => f.faults.sync(schedule),
            _ => {
                drop(slot);
                self.set(BusFaults::for_device(schedule, device));
            }
        }
    }
}
