//! The cost of source mode (b) per output sample on the Cortex-M4F: runs every case of
//! `margemu_firmware::model_bench` (kinematics hold, sensor model with the case's terms, chain,
//! register image, latch into the chip) and prints one line per case through semihosting, then
//! exits QEMU with status 0 (1 if a case could not be built, on a panic or a fault).
//!
//! ```text
//! qemu-system-arm -machine mps2-an386 -nographic -semihosting-config enable=on,target=native \
//!     -icount shift=0 -kernel target/thumbv7em-none-eabihf/release/model-bench
//! ```
//!
//! Instructions are counted as in `chain_bench.rs` (CMSDK TIMER0 under `-icount shift=0`, one
//! tick every 40 instructions, ±40 per case). Output, one line each (the host's
//! `tests/tests/qemu_model_cost.rs` parses it):
//!
//! ```text
//! harness case=<part/terms/chain> samples=<n> hash=<hex> instructions=<n>
//! case=<part/terms/chain> samples=<n> hash=<hex> instructions=<n>
//! model-bench: done
//! ```
#![no_std]
#![no_main]

use core::panic::PanicInfo;
use core::ptr::{addr_of_mut, read_volatile, write_volatile};

use cortex_m_rt::{entry, exception, ExceptionFrame};
use cortex_m_semihosting::{debug, hprintln};
use margemu_firmware::model::perturbation::Complex;
use margemu_firmware::model_bench::{
    self, Chain, Terms, CASES, PERTURBATION_SCRATCH_LEN, PERTURBATION_SIGNAL_LEN,
};

/// CMSDK TIMER0 of the MPS2 images (see `timer.rs`): CTRL, VALUE, RELOAD.
const TIMER0_CTRL: usize = 0x4000_0000;
const TIMER0_VALUE: usize = 0x4000_0004;
const TIMER0_RELOAD: usize = 0x4000_0008;
/// Instructions per TIMER0 tick under `-icount shift=0`: 1 ns each, 25 MHz = 40 ns a tick.
const INSTRUCTIONS_PER_TICK: u64 = 40;

/// The perturbation's buffers (960 KB of .bss), lent to one case at a time.
static mut SCRATCH: [Complex; PERTURBATION_SCRATCH_LEN] = [Complex::ZERO; PERTURBATION_SCRATCH_LEN];
static mut SIGNAL: [f32; PERTURBATION_SIGNAL_LEN] = [0.0; PERTURBATION_SIGNAL_LEN];

#[entry]
fn main() -> ! {
    // SAFETY: `main` runs once and is the only code that names the buffers; no interrupt is
    // enabled.
    let (scratch, signal): (&'static mut [Complex], &'static mut [f32]) =
        unsafe { (&mut *addr_of_mut!(SCRATCH), &mut *addr_of_mut!(SIGNAL)) };
    let mut failed = false;
    for case in &CASES {
        if case.terms == Terms::Ideal && case.chain == Chain::Output {
            restart_counter();
            let (hash, elapsed) = model_bench::harness(case, &mut ticks);
            hprintln!(
                "harness case={} samples={} hash={:016x} instructions={}",
                case,
                case.output_samples(),
                hash,
                elapsed * INSTRUCTIONS_PER_TICK
            );
        }
        restart_counter();
        match model_bench::run(case, scratch, signal, &mut ticks) {
            Ok(o) => hprintln!(
                "case={} samples={} hash={:016x} instructions={}",
                case,
                o.samples,
                o.hash,
                o.elapsed * INSTRUCTIONS_PER_TICK
            ),
            Err(e) => {
                hprintln!("case={} error={}", case, e);
                failed = true;
            }
        }
    }
    hprintln!("model-bench: done");
    match failed {
        true => exit_failure(),
        false => debug::exit(debug::EXIT_SUCCESS),
    }
    loop {
        cortex_m::asm::bkpt();
    }
}

/// Restarts TIMER0 free-running from `0xFFFF_FFFF`, interrupt off.
fn restart_counter() {
    // SAFETY: TIMER0's registers on this machine; only this binary drives it.
    unsafe {
        write_volatile(TIMER0_CTRL as *mut u32, 0);
        write_volatile(TIMER0_RELOAD as *mut u32, u32::MAX);
        write_volatile(TIMER0_VALUE as *mut u32, u32::MAX);
        write_volatile(TIMER0_CTRL as *mut u32, 1);
    }
}

/// TIMER0 ticks since [`restart_counter`] (valid for 2³² ticks).
fn ticks() -> u64 {
    // SAFETY: as in `restart_counter`; reading VALUE has no side effect.
    let value = unsafe { read_volatile(TIMER0_VALUE as *const u32) };
    u64::from(u32::MAX - value)
}

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    hprintln!("model-bench: HardFault at pc={:#010x}", frame.pc());
    exit_failure()
}

#[exception]
unsafe fn DefaultHandler(irqn: i16) {
    hprintln!("model-bench: unexpected exception {}", irqn);
    exit_failure()
}

#[panic_handler]
fn panic(info: &PanicInfo) -> ! {
    hprintln!("model-bench: {}", info);
    exit_failure()
}

/// Exits QEMU with status 1.
fn exit_failure() -> ! {
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::bkpt();
    }
}
