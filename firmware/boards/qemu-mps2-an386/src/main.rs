//! margemu firmware for QEMU's `mps2-an386` machine (ARM AN386: Cortex-M4F, 25 MHz), its link on
//! UART0.
//!
//! For now (before the link handler lands) it prints a boot banner and one FPU result on UART0,
//! then echoes every byte it receives; receiving `q` exits QEMU with status 0 through
//! semihosting. A panic or a fault is reported through semihosting and exits QEMU with status 1.
//!
//! Boot lines, each ending in `\n`:
//!
//! ```text
//! margemu-firmware qemu-mps2-an386 0.1.0
//! fpu sinf(0.5)*sqrtf(2)=0x3f2d9212
//! ```
//!
//! (the hex is the `f32` bit pattern of `libm::sinf(0.5) * libm::sqrtf(2.0)`, which the host
//! recomputes with the same `libm` and compares bit for bit).
#![no_std]
#![no_main]

mod uart;

use core::fmt::Write;
use core::hint::black_box;
use core::panic::PanicInfo;

use cortex_m_rt::{entry, exception, ExceptionFrame};
use cortex_m_semihosting::{debug, hprintln};
// Linked in so the board builds against the library it will run.
use margemu_firmware as _;

use crate::uart::{Uart, UART0_BASE};

/// SYSCLK (and the APB clock of the UART and timers) of the MPS2 FPGA images.
const SYSCLK_HZ: u32 = 25_000_000;
/// UART0 line rate. Under QEMU it only reaches the PTY's termios.
const BAUD: u32 = 115_200;

#[entry]
fn main() -> ! {
    // SAFETY: UART0 is a CMSDK APB UART on this machine, and only `main` drives it.
    let mut uart = unsafe { Uart::new(UART0_BASE) };
    uart.init(SYSCLK_HZ, BAUD);

    let _ = writeln!(
        uart,
        "margemu-firmware qemu-mps2-an386 {}",
        env!("CARGO_PKG_VERSION")
    );
    let _ = writeln!(
        uart,
        "fpu sinf(0.5)*sqrtf(2)={:#010x}",
        fpu_probe().to_bits()
    );

    loop {
        let byte = uart.read_byte();
        uart.write_byte(byte);
        if byte == b'q' {
            uart.flush();
            debug::exit(debug::EXIT_SUCCESS);
        }
    }
}

/// One single-precision expression, evaluated at run time (the inputs go through `black_box`
/// so the compiler cannot fold it). cortex-m-rt's reset handler turns the FPU on (CPACR CP10
/// and CP11 full access) for `-eabihf` targets before `main`; without that the first VFP
/// instruction would fault.
fn fpu_probe() -> f32 {
    libm::sinf(black_box(0.5)) * libm::sqrtf(black_box(2.0))
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
