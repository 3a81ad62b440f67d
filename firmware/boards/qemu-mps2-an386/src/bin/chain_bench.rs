//! The sampling-chain benchmark on the Cortex-M4F: runs every case of
//! `margemu_firmware::chain_bench` and prints one line per case through semihosting, then
//! exits QEMU with status 0 (1 if a case could not be built, on a panic or a fault).
//!
//! ```text
//! qemu-system-arm -machine mps2-an386 -nographic -semihosting-config enable=on,target=native \
//!     -icount shift=0 -kernel target/thumbv7em-none-eabihf/release/chain-bench
//! ```
//!
//! **Counting instructions.** With `-icount shift=0` QEMU advances its virtual clock by exactly
//! 2⁰ ns per guest instruction, and the board's peripherals run on that clock: CMSDK TIMER0,
//! clocked at 25 MHz, decrements once every 40 instructions. Each measurement restarts TIMER0
//! free-running from `0xFFFF_FFFF` and reads its VALUE register before and after (one load
//! each): the difference × 40 is the instructions spent, to ±40 (one tick at each end), and a
//! measurement may last up to 2³² ticks (171 s, 1.7·10¹¹ instructions) before the counter
//! wraps. The `calibration` lines time a loop of a known instruction count (`subs`/`bne`, two
//! instructions per iteration) for two lengths, so the host can check the method. (QEMU does
//! not model the DWT cycle counter; SysTick runs on the same 25 MHz clock, so it would give the
//! same resolution.)
//!
//! Output, one line each (the host's `tests/tests/qemu_chain.rs` parses it):
//!
//! ```text
//! calibration iterations=<n> instructions=<2n> measured=<instructions>
//! harness samples=<n> hash=<hex> instructions=<n>
//! case=<family/path> samples=<n> hash=<hex> accel_clips=<x>,<y>,<z> gyro_clips=<x>,<y>,<z> internal=<accel>,<gyro> instructions=<n>
//! chain-bench: done
//! ```
#![no_std]
#![no_main]

use core::panic::PanicInfo;
use core::ptr::{addr_of_mut, read_volatile, write_volatile};

use cortex_m_rt::{entry, exception, ExceptionFrame};
use cortex_m_semihosting::{debug, hprintln};
use margemu_firmware::chain_bench::{self, CASES, RANDOM_BUFFER_LEN};
use margemu_firmware::model::perturbation::Complex;

/// CMSDK TIMER0 of the MPS2 images (see `timer.rs`): CTRL, VALUE, RELOAD.
const TIMER0_CTRL: usize = 0x4000_0000;
const TIMER0_VALUE: usize = 0x4000_0004;
const TIMER0_RELOAD: usize = 0x4000_0008;
/// Instructions per TIMER0 tick under `-icount shift=0`: 1 ns each, 25 MHz = 40 ns a tick.
const INSTRUCTIONS_PER_TICK: u64 = 40;

/// The random synthesis's buffer (560 KiB of .bss), lent to one case at a time.
static mut RANDOM: [Complex; RANDOM_BUFFER_LEN] = [Complex::ZERO; RANDOM_BUFFER_LEN];

#[entry]
fn main() -> ! {
    // SAFETY: `main` runs once and is the only code that names `RANDOM`; no interrupt is enabled.
    let random: &'static mut [Complex] = unsafe { &mut *addr_of_mut!(RANDOM) };
    for iterations in [1_000_000u32, 2_000_000] {
        restart_counter();
        let start = ticks();
        spin(iterations);
        let measured = ticks().saturating_sub(start) * INSTRUCTIONS_PER_TICK;
        let expected = 2 * u64::from(iterations);
        hprintln!(
            "calibration iterations={} instructions={} measured={}",
            iterations,
            expected,
            measured
        );
    }

    let longest = CASES.iter().map(|c| c.output_samples()).max().unwrap_or(0);
    restart_counter();
    let (hash, elapsed) = chain_bench::harness(longest, 125_000, &mut ticks);
    let instructions = elapsed * INSTRUCTIONS_PER_TICK;
    hprintln!(
        "harness samples={} hash={:016x} instructions={}",
        longest,
        hash,
        instructions
    );

    let mut failed = false;
    for case in &CASES {
        restart_counter();
        match chain_bench::run(case, random, &mut ticks) {
            Ok(o) => {
                let (a, g, i) = (o.accel_clips, o.gyro_clips, o.internal_samples);
                hprintln!(
                    "case={} samples={} hash={:016x} accel_clips={},{},{} \
                     gyro_clips={},{},{} internal={},{} instructions={}",
                    case,
                    o.samples,
                    o.hash,
                    a[0],
                    a[1],
                    a[2],
                    g[0],
                    g[1],
                    g[2],
                    i[0],
                    i[1],
                    o.elapsed * INSTRUCTIONS_PER_TICK
                );
            }
            Err(e) => {
                hprintln!("case={} error={}", case, e);
                failed = true;
            }
        }
    }
    hprintln!("chain-bench: done");
    match failed {
        true => exit_failure(),
        false => debug::exit(debug::EXIT_SUCCESS),
    }
    loop {
        cortex_m::asm::bkpt();
    }
}

/// Runs `iterations` turns of a two-instruction loop (`subs`, `bne`), for the calibration.
fn spin(iterations: u32) {
    if iterations == 0 {
        return;
    }
    // SAFETY: a register countdown; no memory, no stack, flags clobbered (asm! assumes so).
    unsafe {
        core::arch::asm!(
            "2:",
            "subs {n}, {n}, #1",
            "bne 2b",
            n = inout(reg) iterations => _,
            options(nomem, nostack),
        );
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
    hprintln!("chain-bench: HardFault at pc={:#010x}", frame.pc());
    exit_failure()
}

#[exception]
unsafe fn DefaultHandler(irqn: i16) {
    hprintln!("chain-bench: unexpected exception {}", irqn);
    exit_failure()
}

#[panic_handler]
fn panic(info: &PanicInfo) -> ! {
    hprintln!("chain-bench: {}", info);
    exit_failure()
}

/// Exits QEMU with status 1.
fn exit_failure() -> ! {
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::bkpt();
    }
}
