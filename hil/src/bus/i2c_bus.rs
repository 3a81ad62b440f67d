//! Several I2C targets on one bus, seen by the controller as one target: [`I2cBus`].

use super::Shared;
use margemu_firmware::bus_fault::BusFaults;
use margemu_firmware::chip::{Chip, I2cTarget};
use margemu_firmware::fault::FaultSchedule;

/// Several I2C targets on one bus, seen by the controller as one [`I2cTarget`].
///
/// It is the wiring between chips, not a controller: put it behind the [`I2c`] adapter (through
/// [`shared`]) and a driver talks to every chip on it, each at its own addresses.
///
/// **What each target sees** is what it would see on a real bus, where every device watches SDA
/// and SCL:
/// - every START and repeated START, with its address and direction, goes to every target, and
///   each answers for its own addresses (a chip that watches bus activity, as the MPU-9250's
///   bypass multiplexer does, sees the traffic to its neighbours);
/// - the bytes that follow go only to the targets that acknowledged that START; if none did,
///   the address was NACKed ([`I2c`] reports it as
///   [`NoAcknowledge(Address)`](embedded_hal::i2c::NoAcknowledgeSource::Address)), and the
///   bytes until the next START reach nobody: writes are NACKed and reads return `0xFF`, the
///   released open-drain line;
/// - every STOP goes to every target.
///
/// Two targets acknowledging one address (an address conflict, such as two chips strapped
/// alike) behave as open-drain wiring does: a byte written is ACKed if either target ACKs it,
/// and a byte read is the AND of both targets' bytes.
///
/// **Bus faults.** A chip added with its device's faults ([`I2cBus::with_shared_faulted`]) takes
/// part in every bus event through [`margemu_firmware::bus_fault`] at its scene clock, as on
/// the [`I2c`] adapter: in a `nak` window it acknowledges nothing, `corrupt` flips bits of the
/// bytes it drives (the AND with the other targets' bytes comes after), and `clock_stretch`
/// adds up in [`I2cBus::stretched_ns`] (the bus has no clock of its own; the [`I2c`] adapter in
/// front does not see it). [`I2cBus::sync_faults`] keeps them in step with a schedule.
///
/// **Ownership.** A target is either owned by the bus ([`I2cBus::with`]) or shared with the test
/// bench ([`I2cBus::with_shared`]), which keeps its own handle to latch samples or advance time
/// between driver calls. A shared target that is borrowed elsewhere when the bus needs it does
/// not take part in that bus event (as a chip held in reset would not) and the bus counts it in
/// [`I2cBus::missed_events`]; nothing panics.
///
/// ```
/// use embedded_hal::i2c::{Error as _, ErrorKind, I2c as _, NoAcknowledgeSource};
/// use margemu_firmware::chip::{Ist8310, Qmc5883l};
/// use margemu_hil::bus::{self, I2c, I2cBus};
///
/// let ist8310 = bus::shared(Ist8310::new());
/// let wires = I2cBus::new().with_shared(ist8310.clone()).with(Qmc5883l::new());
/// let mut i2c = I2c::new(bus::shared(wires));
///
/// let mut id = [0u8; 1];
/// i2c.write_read(0x0E, &[0x00], &mut id).unwrap(); // IST8310 WAI
/// assert_eq!(id, [0x10]);
/// i2c.write_read(0x0D, &[0x0D], &mut id).unwrap(); // QMC5883L chip ID
/// assert_eq!(id, [0xFF]);
///
/// let err = i2c.write_read(0x1E, &[0x0A], &mut id).unwrap_err(); // nobody at 0x1E
/// assert_eq!(err.kind(), ErrorKind::NoAcknowledge(NoAcknowledgeSource::Address));
///
/// ist8310.borrow_mut().advance(1_000_000, [0.0; 3]); // the bench keeps its handle
/// ```
///
/// [`I2c`]: super::I2c
/// [`shared`]: super::shared
#[derive(Default)]
pub struct I2cBus {
    slots: Vec<Slot>,
    missed: usize,
    stretched_ns: u64,
}

/// One target and whether it acknowledged the latest START.
struct Slot {
    target: Target,
    selected: bool,
}

enum Target {
    Owned(Box<dyn I2cTarget>),
    Shared(Shared<dyn I2cTarget>),
    Faulted(Shared<dyn ChipTarget>, Box<BusFaults>),
}

/// A chip's I2C target and its scene clock, for its bus faults.
trait ChipTarget: I2cTarget {
    fn scene_now_ns(&self) -> u64;
}

impl<T: Chip> ChipTarget for T {
    fn scene_now_ns(&self) -> u64 {
        self.now_ns()
    }
}

impl Target {
    /// Runs `event` on the target, or returns `None` if it is borrowed elsewhere; the stretch
    /// its faults owe is added to `stretched_ns`.
    fn with<R>(
        &mut self,
        stretched_ns: &mut u64,
        event: impl FnOnce(&mut dyn I2cTarget) -> R,
    ) -> Option<R> {
        match self {
            Self::Owned(target) => Some(event(target.as_mut())),
            Self::Shared(target) => target.try_borrow_mut().ok().map(|mut t| event(&mut *t)),
            Self::Faulted(target, faults) => {
                let mut chip = target.try_borrow_mut().ok()?;
                let now = chip.scene_now_ns();
                let mut faulted = faults.on(&mut *chip, now);
                let answer = event(&mut faulted);
                *stretched_ns = stretched_ns.saturating_add(faulted.take_stretch_ns());
                Some(answer)
            }
        }
    }
}

impl I2cBus {
    /// A bus with no target on it (every address is NACKed).
    pub fn new() -> Self {
        Self::default()
    }

    /// The bus with `target` added, owned by the bus.
    pub fn with(self, target: impl I2cTarget + 'static) -> Self {
        self.with_target(Target::Owned(Box::new(target)))
    }

    /// The bus with a shared `target` added; the caller keeps its own handle.
    pub fn with_shared<T: I2cTarget + 'static>(self, target: Shared<T>) -> Self {
        let target: Shared<dyn I2cTarget> = target;
        self.with_target(Target::Shared(target))
    }

    /// The bus with a shared chip `target` added, driven through its device's bus `faults`.
    pub fn with_shared_faulted<T: Chip + 'static>(
        self,
        target: Shared<T>,
        faults: BusFaults,
    ) -> Self {
        let target: Shared<dyn ChipTarget> = target;
        self.with_target(Target::Faulted(target, Box::new(faults)))
    }

    /// Keeps the faults of every chip added with its faults those of its device in `schedule`.
    pub fn sync_faults(&mut self, schedule: &FaultSchedule) {
        for slot in &mut self.slots {
            if let Target::Faulted(_, faults) = &mut slot.target {
                faults.sync(schedule);
            }
        }
    }

    /// The time the targets' clock stretching has held SCL low so far.
    pub fn stretched_ns(&self) -> u64 {
        self.stretched_ns
    }

    fn with_target(mut self, target: Target) -> Self {
        self.slots.push(Slot {
            target,
            selected: false,
        });
        self
    }

    /// How many targets are on the bus.
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// Whether no target is on the bus.
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// How many bus events (START, byte, STOP) a shared target missed because it was borrowed
    /// elsewhere at the time.
    pub fn missed_events(&self) -> usize {
        self.missed
    }

    /// Runs `event` on every target the bus addresses (`all`, or those selected by the latest
    /// START), counting the ones that are busy; returns the others' answers by slot index.
    fn each<R>(
        &mut self,
        all: bool,
        mut event: impl FnMut(&mut dyn I2cTarget) -> R,
    ) -> Vec<(usize, R)> {
        let mut answers = Vec::new();
        for (index, slot) in self.slots.iter_mut().enumerate() {
            if !(all || slot.selected) {
                continue;
            }
            match slot.target.with(&mut self.stretched_ns, &mut event) {
                Some(answer) => answers.push((index, answer)),
                None => self.missed += 1,
            }
        }
        answers
    }
}

impl I2cTarget for I2cBus {
    fn start(&mut self, address: u8, read: bool) -> bool {
        let acks = self.each(true, |t| t.start(address, read));
        for slot in &mut self.slots {
            slot.selected = false;
        }
        for &(index, ack) in &acks {
            if let Some(slot) = self.slots.get_mut(index) {
                slot.selected = ack;
            }
        }
        acks.iter().any(|&(_, ack)| ack)
    }

    fn write(&mut self, byte: u8) -> bool {
        // Every selected target takes the byte; the line is ACKed if any of them pulls it low.
        let acks = self.each(false, |t| t.write(byte));
        acks.iter().any(|&(_, ack)| ack)
    }

    fn read(&mut self) -> u8 {
        // Open drain: a bit reads 1 only if no selected target drives it low.
        let bytes = self.each(false, |t| t.read());
        bytes.iter().fold(0xFF, |line, &(_, byte)| line & byte)
    }

    fn stop(&mut self) {
        self.each(true, |t| t.stop());
        for slot in &mut self.slots {
            slot.selected = false;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::fake::{Event, Regs};
    use super::super::{shared, I2c, I2cError};
    use super::*;
    use embedded_hal::i2c::{Error as _, ErrorKind, I2c as _, NoAcknowledgeSource};
    use margemu_firmware::chip::Ist8310;
    use Event::{Read, Start, Stop, Write};

    const A: u8 = 0x1C;
    const B: u8 = 0x68;
    const ADDRESS_NACK: ErrorKind = ErrorKind::NoAcknowledge(NoAcknowledgeSource::Address);

    /// Two fakes at `A` (registers 0x20 + i) and `B` (0x40 + i), shared with the test.
    fn two() -> (Shared<Regs>, Shared<Regs>, I2cBus) {
        let a = shared(Regs::counting_at(A, 0x20));
        let b = shared(Regs::counting_at(B, 0x40));
        let bus = I2cBus::new().with_shared(a.clone()).with_shared(b.clone());
        (a, b, bus)
    }

    fn saw_bytes(target: &Shared<Regs>) -> bool {
        let log = &target.borrow().log;
        log.iter().any(|e| matches!(e, Write(_) | Read))
    }

    #[test]
    fn each_address_reaches_its_own_target() {
        let (a, b, bus) = two();
        let mut i2c = I2c::new(shared(bus));
        let mut buf = [0u8; 2];
        i2c.write_read(A, &[0x03], &mut buf).unwrap();
        assert_eq!(buf, [0x23, 0x24]);
        i2c.write_read(B, &[0x03], &mut buf).unwrap();
        assert_eq!(buf, [0x43, 0x44]);
        i2c.write(B, &[0x05, 0xAB]).unwrap();
        assert_eq!((a.borrow().regs[5], b.borrow().regs[5]), (0x25, 0xAB));
        // A saw every START and STOP on the bus, and only its own bytes.
        let expected = [
            Start(A, false),
            Write(0x03),
            Start(A, true),
            Read,
            Read,
            Stop,
            Start(B, false),
            Start(B, true),
            Stop,
            Start(B, false),
            Stop,
        ];
        assert_eq!(a.borrow().log[..], expected);
        assert_eq!(i2c.target().borrow().missed_events(), 0);
    }

    #[test]
    fn an_absent_address_is_nacked_and_its_bytes_reach_nobody() {
        let (a, b, bus) = two();
        let mut i2c = I2c::new(shared(bus));
        let err = i2c.write(0x0C, &[0x05, 0x99]).unwrap_err();
        assert_eq!(
            (err, err.kind()),
            (I2cError::AddressNack(0x0C), ADDRESS_NACK)
        );
        let err = i2c.read(0x0C, &mut [0; 2]).unwrap_err();
        assert_eq!(err.kind(), ADDRESS_NACK);
        // A controller that goes on after the NACK anyway: the bytes reach nobody.
        let mut wires = i2c.target().replace(I2cBus::new());
        assert!(!wires.start(0x0C, false));
        assert!(!wires.write(0x05));
        assert!(!wires.write(0x99));
        assert_eq!([wires.read(), wires.read()], [0xFF, 0xFF]);
        wires.stop();
        for target in [&a, &b] {
            assert!(!saw_bytes(target), "{:?}", target.borrow().log);
            assert_eq!(target.borrow().log.len(), 6, "three STARTs and STOPs");
        }
        assert_eq!((a.borrow().regs[5], b.borrow().regs[5]), (0x25, 0x45));
    }

    #[test]
    fn a_repeated_start_moves_the_bytes_to_another_target() {
        let (a, b, mut wires) = two();
        // Pointer write to A, then a repeated START reading B: B's bytes, A gets none.
        assert!(wires.start(A, false));
        assert!(wires.write(0x02));
        assert!(wires.start(B, true));
        assert_eq!([wires.read(), wires.read()], [0x40, 0x41]);
        // Then a repeated START writing B: A's registers stay as they were.
        assert!(wires.start(B, false));
        assert!(wires.write(0x07));
        assert!(wires.write(0x77));
        // And back to A without a STOP.
        assert!(wires.start(A, true));
        assert_eq!(wires.read(), 0x22);
        wires.stop();
        assert_eq!((a.borrow().regs[7], b.borrow().regs[7]), (0x27, 0x77));
        let expected = [
            Start(A, false),
            Write(0x02),
            Start(B, true),
            Start(B, false),
            Start(A, true),
            Read,
            Stop,
        ];
        assert_eq!(a.borrow().log[..], expected);
    }

    #[test]
    fn two_targets_at_one_address_share_the_open_drain_lines() {
        let ist8310 = shared(Ist8310::new());
        let regs = shared(Regs::counting_at(0x0E, 0x30));
        let mut wires = I2cBus::new()
            .with_shared(ist8310.clone())
            .with_shared(regs.clone());
        // Both take the pointer; reads are the AND of WAI (0x10) and 0x30.
        assert!(wires.start(0x0E, false));
        assert!(wires.write(0x00));
        assert!(wires.start(0x0E, true));
        assert_eq!(wires.read(), 0x10);
        // 0x0F is read-only in the fake (NACK) but the IST8310 ACKs: ACK.
        assert!(wires.start(0x0E, false));
        assert!(wires.write(0x0F));
        assert!(wires.write(0x5A));
        wires.stop();
        assert_eq!(regs.borrow().regs[0x0F], 0x3F);
        assert_eq!(ist8310.borrow().pointer(), 0x10);
    }

    #[test]
    fn a_busy_shared_target_misses_events_without_panicking() {
        let (a, b, bus) = two();
        let mut i2c = I2c::new(shared(bus));
        {
            let _held = a.borrow();
            i2c.write(B, &[0x05, 0xAB]).unwrap();
            let err = i2c.write(A, &[0x05, 0xCD]).unwrap_err();
            assert_eq!(err.kind(), ADDRESS_NACK);
        }
        // A missed both transactions' START and STOP; B was never busy.
        assert_eq!(i2c.target().borrow().missed_events(), 4);
        assert_eq!((a.borrow().regs[5], b.borrow().regs[5]), (0x25, 0xAB));
        assert!(a.borrow().log.is_empty());
    }

    #[test]
    fn owned_targets_and_the_empty_bus() {
        let mut empty = I2c::new(shared(I2cBus::new()));
        assert!(empty.target().borrow().is_empty());
        let err = empty.read(B, &mut [0]).unwrap_err();
        assert_eq!(err.kind(), ADDRESS_NACK);
        let wires = I2cBus::new()
            .with(Regs::counting_at(A, 0x20))
            .with(Ist8310::new());
        assert_eq!(wires.len(), 2);
        let mut i2c = I2c::new(shared(wires));
        let mut id = [0u8; 1];
        i2c.write_read(0x0E, &[0x00], &mut id).unwrap();
        assert_eq!(id, [0x10]);
        i2c.write_read(A, &[0x0A], &mut id).unwrap();
        assert_eq!(id, [0x2A]);
    }
}
