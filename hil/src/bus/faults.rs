//! A device's bus faults as an adapter holds them: the firmware's application
//! ([`margemu_firmware::bus_fault`]) and the chip's scene clock, read at each bus event.

use margemu_firmware::bus_fault::{BusFaults, Faulted};
use margemu_firmware::chip::Chip;
use margemu_firmware::fault::FaultSchedule;

/// The faults of the adapter's target and how to read its scene clock.
pub(super) struct TargetFaults<T: ?Sized> {
    pub(super) faults: BusFaults,
    now_ns: fn(&T) -> u64,
}

impl<T: Chip> TargetFaults<T> {
    pub(super) fn new(faults: BusFaults) -> Self {
        Self {
            faults,
            now_ns: T::now_ns,
        }
    }
}

impl<T> TargetFaults<T> {
    /// `target` with the faults, at the chip's present instant.
    pub(super) fn on<'a>(&'a mut self, target: &'a mut T) -> Faulted<'a, T> {
        let now = (self.now_ns)(target);
        self.faults.on(target, now)
    }
}

/// Keeps `slot`'s faults those of `device` in `schedule` (see [`BusFaults::sync`]): set up on
/// the first call, only the faults added since on the next ones.
pub(super) fn sync<T: Chip>(
    slot: &mut Option<TargetFaults<T>>,
    schedule: &FaultSchedule,
    device: u8,
) {
    match slot {
        Some(f) if f.faults.device() == device => f.faults.sync(schedule),
        _ => *slot = Some(TargetFaults::new(BusFaults::for_device(schedule, device))),
    }
}
