//! The link handler ([`Device`], which owns the emulated chip), shared by the main loop and the
//! I2C target's interrupt handlers.
//!
//! The main loop takes it only through [`lock`], which raises BASEPRI to the I2C handlers'
//! priority for the duration: they cannot run meanwhile (the I2C bus waits, its clock stretched),
//! while the SPI handler (priority 0, never masked by BASEPRI) keeps running, because it never
//! touches the device. The I2C handlers, both at one priority, take it through [`in_i2c_handler`].

use core::ptr;
use core::sync::atomic::{compiler_fence, AtomicPtr, Ordering};

use cortex_m::register::{basepri, basepri_max};
use margemu_firmware::link::{Device, Identity};
use margemu_firmware::protocol::link::ResetCause;

use crate::i2c;

/// Samples the device buffers ahead of their instants: 24 ms at 8 kHz, more than the host's
/// default lead (20 ms). Each slot holds a rig's image (64 bytes): with the link handler built
/// on the stack once before it moves to its static, a longer ring leaves the stack too little
/// of the 128 KiB.
pub const RING: usize = 192;

static DEVICE: AtomicPtr<Device<RING>> = AtomicPtr::new(ptr::null_mut());

/// Creates the device (once) and makes it reachable through [`lock`].
pub fn install(identity: Identity, cause: ResetCause) {
    let device: &'static mut Device<RING> =
        cortex_m::singleton!(: Device<RING> = Device::with_identity(identity, cause))
            .expect("installed once, at boot");
    DEVICE.store(device, Ordering::Release);
}

/// Runs `f` with the device, the I2C handlers masked.
pub fn lock<R>(f: impl FnOnce(&mut Device<RING>) -> R) -> R {
    let old = basepri::read();
    basepri_max::write(i2c::PRIORITY);
    compiler_fence(Ordering::SeqCst);
    // SAFETY: BASEPRI masks the only other users (the I2C handlers), `lock` is not re-entered
    // (the main loop is its only caller and `f` does not call it), and `install` ran first.
    let result = f(unsafe { &mut *DEVICE.load(Ordering::Acquire) });
    compiler_fence(Ordering::SeqCst);
    // SAFETY: restores the value read above.
    unsafe { basepri::write(old) };
    result
}

/// The device, from an I2C handler (priority [`i2c::PRIORITY`]); `None` before [`install`].
///
/// # Safety
///
/// Only the I2C handlers may call this, and only while they run at [`i2c::PRIORITY`] (so they
/// cannot preempt each other, and the main loop is outside [`lock`]).
pub unsafe fn in_i2c_handler() -> Option<&'static mut Device<RING>> {
    // SAFETY: the caller's contract.
    unsafe { DEVICE.load(Ordering::Acquire).as_mut() }
}
