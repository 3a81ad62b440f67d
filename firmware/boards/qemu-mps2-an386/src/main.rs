//! margemu firmware for QEMU's `mps2-an386` machine (ARM AN386: Cortex-M4F, 25 MHz), its link on
//! UART0.
//!
//! The firmware library's link handler ([`Device`]) runs in a polled main loop: the bytes UART0
//! has received are fed to [`Device::feed`], and [`Device::poll`] serves the due samples and
//! sends its frames back on UART0. Time comes from CMSDK TIMER0 (25 MHz, extended to 64-bit
//! nanoseconds by polling; QEMU does not model the DWT cycle counter).
//!
//! The link is binary from the first byte: no banner (the device's power-on Reset frame is the
//! first thing it sends). Under QEMU the UART holds back the next received byte until DATA is
//! read, so polling loses nothing. A panic or a fault is reported through semihosting and exits
//! QEMU with status 1; the host ends a session by killing QEMU.
#![no_std]
#![no_main]

mod timer;
mod uart;

use core::panic::PanicInfo;

use cortex_m_rt::{entry, exception, ExceptionFrame};
use cortex_m_semihosting::{debug, hprintln};
use margemu_firmware::link::{Device, Identity};
use margemu_firmware::protocol::link::{FirmwareVersion, ResetCause, DEVICE_ID_LEN};

use crate::timer::{Timer, TIMER0_BASE};
use crate::uart::{Uart, UART0_BASE};

/// SYSCLK (and the APB clock of the UART and timers) of the MPS2 FPGA images.
const SYSCLK_HZ: u32 = 25_000_000;
/// UART0 line rate. Under QEMU it only reaches the PTY's termios.
const BAUD: u32 = 115_200;
/// Samples the device buffers ahead of their instants.
const RING: usize = 128;
/// Most received bytes fed to the device in one go.
const RX_CHUNK: usize = 256;

#[entry]
fn main() -> ! {
    // SAFETY: UART0 is a CMSDK APB UART on this machine, and only `main` drives it.
    let mut uart = unsafe { Uart::new(UART0_BASE) };
    uart.init(SYSCLK_HZ, BAUD);
    // SAFETY: TIMER0 is a CMSDK APB timer on this machine, and only `main` drives it.
    let mut timer = unsafe { Timer::new(TIMER0_BASE, SYSCLK_HZ) };
    timer.start();

    // ~17 KB, taken once; `singleton!` keeps it out of `main`'s frame for the loop's lifetime.
    let device: &'static mut Device<RING> =
        cortex_m::singleton!(: Device<RING> = Device::with_identity(identity(), ResetCause::PowerOn))
            .expect("taken once");

    let mut rx = [0u8; RX_CHUNK];
    loop {
        let mut n = 0;
        while n < rx.len() {
            match uart.try_read_byte() {
                Some(b) => {
                    rx[n] = b;
                    n += 1;
                }
                None => break,
            }
        }
        if n > 0 {
            device.feed(&rx[..n], timer.now_ns());
        }
        device.poll(timer.now_ns(), &mut |frame: &[u8]| uart.write_all(frame));
    }
}

/// HelloAck's identity: this crate's version, and the board's name as the device ID (QEMU's
/// MPS2 has no unique ID).
fn identity() -> Identity {
    let part = |s: &str| s.parse().unwrap_or(0);
    let mut device_id = [0u8; DEVICE_ID_LEN];
    let name = b"qemu-mps2-an386";
    device_id[..name.len()].copy_from_slice(name);
    Identity {
        firmware: FirmwareVersion {
            major: part(env!("CARGO_PKG_VERSION_MAJOR")),
            minor: part(env!("CARGO_PKG_VERSION_MINOR")),
            patch: part(env!("CARGO_PKG_VERSION_PATCH")),
        },
        device_id,
    }
}

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    hprintln!("margemu: HardFault at pc={:#010x}", frame.pc());
    exit_failure()
}

#[exception]
unsafe fn DefaultHandler(irqn: i16) {
    hprintln!("margemu: unexpected exception {}", irqn);
    exit_failure()
}

#[panic_handler]
fn panic(info: &PanicInfo) -> ! {
    hprintln!("margemu: {}", info);
    exit_failure()
}

/// Exits QEMU with status 1 (semihosting `SYS_EXIT`, `ADP_Stopped_RunTimeErrorUnknown`).
fn exit_failure() -> ! {
    debug::exit(debug::EXIT_FAILURE);
    // Only reached without a semihosting host (a debugger that ignores the call).
    loop {
        cortex_m::asm::bkpt();
    }
}
