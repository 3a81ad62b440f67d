//! margemu firmware for QEMU's `mps2-an386` machine (ARM AN386: Cortex-M4F, 25 MHz), its link on
//! UART0.
//!
//! The firmware library's link handler ([`Device`]) runs in the main loop. UART0's RX interrupt
//! puts each received byte in a ring, and the TX interrupt sends the frames the main loop queues
//! ([`serial`]). Time comes from CMSDK TIMER0 (25 MHz, extended to 64-bit nanoseconds by polling;
//! QEMU does not model the DWT cycle counter).
//!
//! The core sleeps in WFI and the loop body runs when [`RX_BATCH`] bytes are waiting or TIMER1
//! has ticked (every [`TICK_NS`]): it feeds the waiting bytes to [`Device::feed`], then
//! [`Device::poll`] serves the due sample instants (each latched at its exact scene time,
//! however late the poll) and queues the frames it sends. Under QEMU every MMIO access and every
//! wake-up costs the emulator tens of microseconds of host time, and received bytes arrive one
//! per turn of its main loop; waking the loop once per byte instead, or spinning, measurably
//! slows the link (see the QEMU figures in `docs/figures.md`). A real board with a DUT polling the chip
//! would serve each instant from a timer compare instead of a tick.
//!
//! The link is binary from the first byte: no banner (the device's power-on Reset frame is the
//! first thing it sends). A panic or a fault is reported through semihosting and exits QEMU with
//! status 1; the host ends a session by killing QEMU.
#![no_std]
#![no_main]

mod irq;
mod serial;
mod timer;
mod uart;

use core::panic::PanicInfo;

use cortex_m::interrupt;
use cortex_m_rt::{entry, exception, ExceptionFrame};
use cortex_m_semihosting::{debug, hprintln};
use margemu_firmware::link::{Device, Identity};
use margemu_firmware::protocol::link::{FirmwareVersion, ResetCause, DEVICE_ID_LEN};

use crate::serial::Serial;
use crate::timer::{Tick, Timer, TIMER0_BASE, TIMER1_BASE};

/// SYSCLK (and the APB clock of the UART and timers) of the MPS2 FPGA images.
const SYSCLK_HZ: u32 = 25_000_000;
/// UART0 line rate. Under QEMU it only reaches the PTY's termios.
const BAUD: u32 = 115_200;
/// Samples the device buffers ahead of their instants: 1 s of images at 1 kHz, 5 s of
/// kinematics at 200 Hz, so the host's lead can ride out QEMU's uneven UART (~66 B a slot).
const RING: usize = 1024;
/// Most received bytes fed to the device in one go.
const RX_CHUNK: usize = 256;
/// Received bytes that wake the loop body before the tick does.
const RX_BATCH: usize = 64;
/// The wake-up tick's period: a sample instant is served at most this late. Each tick costs
/// QEMU ~50 µs of host time (measured: an idle board takes 5 % of a core at 1 ms, 20 % at
/// 250 µs).
const TICK_NS: u32 = 1_000_000;

// SAFETY: TIMER1 is a CMSDK APB timer on this machine; only `main` (start) and its interrupt
// handler (acknowledge) use it, through this value.
const TICK: Tick = unsafe { Tick::new(TIMER1_BASE) };

#[entry]
fn main() -> ! {
    let mut core = cortex_m::Peripherals::take().expect("taken once");
    let mut serial = Serial::take(SYSCLK_HZ, BAUD).expect("taken once");
    // SAFETY: TIMER0 is a CMSDK APB timer on this machine, and only `main` drives it.
    let mut timer = unsafe { Timer::new(TIMER0_BASE, SYSCLK_HZ) };
    timer.start();
    TICK.start(SYSCLK_HZ / (1_000_000_000 / TICK_NS));

    // ~66 KB, taken once; `singleton!` keeps it out of `main`'s frame for the loop's lifetime.
    let device: &'static mut Device<RING> =
        cortex_m::singleton!(: Device<RING> = Device::with_identity(identity(), ResetCause::PowerOn))
            .expect("taken once");
    irq::enable(&mut core.NVIC);

    let mut rx = [0u8; RX_CHUNK];
    loop {
        sleep_until_work(&serial);
        loop {
            let n = serial.read(&mut rx);
            if n == 0 {
                break;
            }
            device.feed(&rx[..n], timer.now_ns());
        }
        device.poll(timer.now_ns(), &mut |frame: &[u8]| serial.send(frame));
    }
}

/// Sleeps in WFI until [`RX_BATCH`] bytes are waiting or the tick has fired since the last call.
/// The check and the WFI run with interrupts masked: an interrupt that arrives in between stays
/// pending and ends the WFI at once, so no wake-up is lost; its handler runs when they are
/// unmasked.
fn sleep_until_work(serial: &Serial) {
    loop {
        let work = interrupt::free(|_| {
            let work = serial.rx_len() >= RX_BATCH || irq::take_tick();
            if !work {
                cortex_m::asm::wfi();
            }
            work
        });
        if work {
            return;
        }
    }
}

/// HelloAck's identity: this crate's version, and the board's name as the device ID (QEMU's
/// MPS2 has no unique ID).
fn identity() -> Identity {
    let part = |s: &str| s.parse().unwrap_or(0);
    let mut device_id = [0u8; DEVICE_ID_LEN];
    let name = margemu_firmware::budget::QEMU_DEVICE_ID;
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
    if !irq::dispatch(irqn, TICK) {
        hprintln!("margemu: unexpected exception {}", irqn);
        exit_failure()
    }
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
