//! I2C1 as the I2C target of the emulated chips, through the PAC (the HAL has no target mode):
//! the addresses the rig's chips answer now ([`Chip::i2c_addresses_now`], device by device: for
//! the MPU-9250 its own, 0x68 or 0x69 with AD0, unless its I2C interface is disabled, and 0x0C
//! for the AK8963 in bypass mode; a compass's own) in OAR1 and, for a second one, OAR2 (dual
//! addressing); clock stretching on (RM0383, I2C chapter). The peripheral owns two addresses:
//! a rig answering more serves its first two (an IMU and its compass) and leaves the rest
//! unacknowledged. Each transaction goes to the chip that answers the matched address.
//!
//! | pin | function (AF4, open drain) |
//! |-----|----------------------------|
//! | PB6 | I2C1_SCL |
//! | PB7 | I2C1_SDA |
//!
//! The event and error interrupts (priority [`PRIORITY`], below the SPI handler's) drive the
//! chip's [`I2cTarget`] byte by byte, holding the device for a few microseconds each. While the
//! main loop holds the device ([`crate::device::lock`]) they wait, and the target stretches SCL.
//!
//! Reads are fetched only when the controller asks for the byte: the first at the address
//! match, each next one at BTF (the previous byte was acknowledged and the data register is
//! empty: EV3 of RM0383's slave transmitter sequence), with the buffer interrupt off, so a read
//! never pops a FIFO byte the controller does not take. A NACK (AF) ends a read (STOPF is not
//! set after a NACK: RM0383, I2C_SR1). Writes are taken at RXNE.
//!
//! **Bus faults** (`margemu_firmware::bus_fault`, one [`BusFaults`] per rig device, kept in
//! step with the device's schedule by [`configure`]) at the chip's scene clock:
//! - `nak`: the peripheral acknowledges its own addresses in hardware, so [`configure`] leaves
//!   a device's addresses out of OAR1/OAR2 while its `nak` window holds the chip's time (its
//!   START is then not acknowledged); the handlers also drive the chip through the faults, so
//!   a START that the hardware took just before the main loop saw the window reaches nobody
//!   and reads `0xFF`;
//! - `corrupt`: each byte read is drawn through the faults before it goes to DR;
//! - `clock_stretch`: the handler waits the stretch (busy, at [`crate::SYSCLK_HZ`]) before it
//!   writes DR, and the peripheral holds SCL low meanwhile (clock stretching on). The wait
//!   holds the main loop too (not the SPI handler): a long stretch delays the link.

use core::cell::UnsafeCell;
use core::sync::atomic::{AtomicBool, AtomicU8, Ordering};

use cortex_m::peripheral::NVIC;
use margemu_firmware::bus_fault::BusFaults;
use margemu_firmware::chip::{Chip, EmulatedChip, I2cTarget};
use margemu_firmware::fault::FaultSchedule;
use margemu_firmware::link::rig::Rig;
use margemu_firmware::link::Device;
use margemu_firmware::protocol::link::MAX_DEVICES;
use stm32f4xx_hal::pac::{self, interrupt, Interrupt, I2C1};
use stm32f4xx_hal::rcc::{Enable, Rcc, Reset};

use crate::device;

/// Priority of I2C1_EV and I2C1_ER, and the BASEPRI of [`device::lock`].
pub const PRIORITY: u8 = 0x10;

const CR1_PE: u16 = 1 << 0;
const CR1_ACK: u16 = 1 << 10;
const CR2_ITERREN: u16 = 1 << 8;
const CR2_ITEVTEN: u16 = 1 << 9;
const CR2_ITBUFEN: u16 = 1 << 10;
/// OAR1 bit 14 "should always be kept at 1 by software".
const OAR1_KEEP: u16 = 1 << 14;
const OAR2_ENDUAL: u16 = 1 << 0;
/// SR1 error flags (rc_w0): BERR, ARLO, AF, OVR, PECERR, TIMEOUT, SMBALERT.
const SR1_ERRORS: u16 = 0xDF00;

/// A transaction ended since the main loop last looked: the chip may have changed.
static ACTIVITY: AtomicBool = AtomicBool::new(false);

/// Enables I2C1 as a target (clock from `pclk1_hz`) and its interrupts. The pins must already be
/// in AF4 open drain. The own address is set by [`configure`].
pub fn init(_i2c: I2C1, rcc: &mut Rcc, pclk1_hz: u32) {
    I2C1::enable(rcc);
    I2C1::reset(rcc);
    let i2c = regs();
    let freq = (pclk1_hz / 1_000_000).clamp(2, 50) as u16;
    i2c.cr2()
        .write(|w| unsafe { w.bits(freq | CR2_ITEVTEN | CR2_ITERREN) });
    i2c.oar1()
        .write(|w| unsafe { w.bits(OAR1_KEEP | u16::from(0x68u8) << 1) });
    i2c.cr1().write(|w| unsafe { w.bits(CR1_PE) });
    // ACK only sticks once PE is set.
    i2c.cr1().write(|w| unsafe { w.bits(CR1_PE | CR1_ACK) });
    // SAFETY: the handlers only use the device once it is installed; priorities before unmasking.
    unsafe {
        let mut nvic = cortex_m::Peripherals::steal().NVIC;
        nvic.set_priority(Interrupt::I2C1_EV, PRIORITY);
        nvic.set_priority(Interrupt::I2C1_ER, PRIORITY);
        NVIC::unmask(Interrupt::I2C1_EV);
        NVIC::unmask(Interrupt::I2C1_ER);
    }
}

/// The address of the transaction in progress (its START matched it).
static ADDRESSED: AtomicU8 = AtomicU8::new(0);

/// Each rig device's bus faults (`None` until [`configure`] first sees the device).
struct FaultsCell(UnsafeCell<[Option<BusFaults>; MAX_DEVICES]>);
// SAFETY: used by `configure` (the device locked: the I2C handlers masked) and by the I2C
// handlers, which run at one priority and so never preempt each other.
unsafe impl Sync for FaultsCell {}

static FAULTS: FaultsCell = FaultsCell(UnsafeCell::new([const { None }; MAX_DEVICES]));

/// Follows the rig's bus state: the addresses its chips answer now, but for those of a device
/// in a `nak` window, the first in OAR1 and a second one in OAR2 (dual addressing on); no
/// address acknowledged when they answer none. Keeps the devices' bus faults in step with
/// `schedule`. Called with the device locked, so no transaction is being handled.
pub fn configure(rig: &Rig, schedule: &FaultSchedule) {
    // SAFETY: see `FaultsCell`: the handlers are masked while the device is locked.
    let faults = unsafe { &mut *FAULTS.0.get() };
    for (d, slot) in (0u8..).zip(faults.iter_mut()) {
        slot.get_or_insert_with(|| BusFaults::new(d)).sync(schedule);
    }
    let i2c = regs();
    let mut answered = rig
        .chips()
        .zip(faults.iter())
        .filter(|(c, f)| !f.as_ref().is_some_and(|f| f.nak(c.now_ns())))
        .flat_map(|(c, _)| c.i2c_addresses_now())
        .flatten();
    let (first, second) = (answered.next(), answered.next());
    let fallback = rig.primary().i2c_address();
    let oar1 = OAR1_KEEP | u16::from(first.unwrap_or(fallback) & 0x7F) << 1;
    let oar2 = second.map_or(0, |a| u16::from(a & 0x7F) << 1 | OAR2_ENDUAL);
    if i2c.oar1().read().bits() != oar1 {
        i2c.oar1().write(|w| unsafe { w.bits(oar1) });
    }
    if i2c.oar2().read().bits() != oar2 {
        i2c.oar2().write(|w| unsafe { w.bits(oar2) });
    }
    let cr1 = i2c.cr1().read().bits();
    let want = if first.is_some() {
        cr1 | CR1_ACK
    } else {
        cr1 & !CR1_ACK
    };
    if want != cr1 {
        i2c.cr1().write(|w| unsafe { w.bits(want) });
    }
}

/// Whether an I2C transaction ended since the last call.
pub fn take_activity() -> bool {
    ACTIVITY.swap(false, Ordering::Relaxed)
}

fn regs() -> &'static pac::i2c1::RegisterBlock {
    // SAFETY: I2C1 belongs to this module since `init`.
    unsafe { &*I2C1::ptr() }
}

/// The device at `address` (by index) and its faults, from an I2C handler.
///
/// # Safety
///
/// Only from the I2C handlers (see `FaultsCell`).
unsafe fn target(
    device: &mut Device<{ device::RING }>,
    address: u8,
) -> Option<(&mut EmulatedChip, &'static mut BusFaults)> {
    let d = device
        .rig()
        .chips()
        .position(|c| c.i2c_addresses_now().contains(&Some(address)))?;
    // SAFETY: the caller's contract.
    let faults = unsafe { &mut *FAULTS.0.get() };
    let faults = faults.get_mut(d)?.as_mut()?;
    Some((device.rig_mut().chip_mut(d)?, faults))
}

/// Waits `ns` with SCL held low (the peripheral stretches until DR is written).
fn stretch(ns: u64) {
    if ns > 0 {
        let cycles = ns.saturating_mul(u64::from(crate::SYSCLK_HZ / 1_000_000)) / 1_000;
        cortex_m::asm::delay(u32::try_from(cycles).unwrap_or(u32::MAX));
    }
}

#[interrupt]
fn I2C1_EV() {
    let i2c = regs();
    let sr1 = i2c.sr1().read();
    // SAFETY: an I2C handler at PRIORITY.
    let Some(device) = (unsafe { device::in_i2c_handler() }) else {
        return;
    };
    if sr1.addr().bit_is_set() {
        let sr2 = i2c.sr2().read(); // SR1 then SR2 clears ADDR
        let read = sr2.tra().bit_is_set();
        // The address matched, as `configure` set it from the rig.
        let own = if sr2.dualf().bit_is_set() {
            i2c.oar2().read().bits()
        } else {
            i2c.oar1().read().bits()
        };
        let address = (own >> 1) as u8 & 0x7F;
        ADDRESSED.store(address, Ordering::Relaxed);
        // SAFETY: an I2C handler.
        let Some((chip, faults)) = (unsafe { target(device, address) }) else {
            return;
        };
        let now = chip.now_ns();
        let mut chip = faults.on(chip, now);
        chip.start(address, read);
        let cr2 = i2c.cr2().read().bits();
        if read {
            i2c.cr2().write(|w| unsafe { w.bits(cr2 & !CR2_ITBUFEN) });
            let byte = chip.read();
            stretch(chip.take_stretch_ns());
            i2c.dr().write(|w| unsafe { w.bits(u16::from(byte)) });
        } else {
            i2c.cr2().write(|w| unsafe { w.bits(cr2 | CR2_ITBUFEN) });
        }
        return;
    }
    // SAFETY: an I2C handler.
    let Some((chip, faults)) = (unsafe { target(device, ADDRESSED.load(Ordering::Relaxed)) })
    else {
        // Nobody answers the address any more (a reset mid-transaction): drain, and end.
        if sr1.rx_ne().bit_is_set() {
            let _ = i2c.dr().read().bits();
        }
        if sr1.stopf().bit_is_set() {
            i2c.cr1().modify(|r, w| unsafe { w.bits(r.bits()) });
        }
        return;
    };
    let now = chip.now_ns();
    let mut chip = faults.on(chip, now);
    if sr1.rx_ne().bit_is_set() {
        let byte = i2c.dr().read().bits() as u8;
        chip.write(byte);
    } else if sr1.tx_e().bit_is_set() && sr1.btf().bit_is_set() {
        let byte = chip.read();
        stretch(chip.take_stretch_ns());
        i2c.dr().write(|w| unsafe { w.bits(u16::from(byte)) });
    }
    if sr1.stopf().bit_is_set() {
        // SR1 read, then a CR1 write, clears STOPF.
        i2c.cr1().modify(|r, w| unsafe { w.bits(r.bits()) });
        end(&mut chip);
    }
}

#[interrupt]
fn I2C1_ER() {
    let i2c = regs();
    let sr1 = i2c.sr1().read();
    i2c.sr1().write(|w| unsafe { w.bits(!SR1_ERRORS) });
    if sr1.af().bit_is_set() {
        // SAFETY: an I2C handler at PRIORITY.
        if let Some(device) = unsafe { device::in_i2c_handler() } {
            // SAFETY: an I2C handler.
            let address = ADDRESSED.load(Ordering::Relaxed);
            if let Some((chip, faults)) = unsafe { target(device, address) } {
                let now = chip.now_ns();
                end(&mut faults.on(chip, now));
            }
        }
    }
}

fn end(chip: &mut impl I2cTarget) {
    chip.stop();
    let i2c = regs();
    i2c.cr2()
        .modify(|r, w| unsafe { w.bits(r.bits() & !CR2_ITBUFEN) });
    ACTIVITY.store(true, Ordering::Relaxed);
}
