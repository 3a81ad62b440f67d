//! QEMU smoke test: the cross-built `qemu-mps2-an386` firmware boots in `qemu-system-arm`,
//! prints its banner and one FPU result on UART0 (reached through a PTY), echoes bytes back both
//! ways, and exits QEMU with status 0 when it receives `q`.
//!
//! Skipped, with a message, where `qemu-system-arm` or a cross toolchain is missing; under
//! `CI=true` that is a failure instead.

use std::time::{Duration, Instant};

use margemu_tests::qemu::{self, Qemu};

/// Generous: the machine is shared, and QEMU's first translation of the code takes a moment.
const TIMEOUT: Duration = Duration::from_secs(10);

#[test]
fn board_boots_echoes_and_exits_cleanly() {
    if !qemu::prerequisites_or_skip("qemu_smoke") {
        return;
    }
    let t = Instant::now();
    let elf = qemu::board_elf().unwrap_or_else(|e| panic!("board ELF: {e}"));
    let build = t.elapsed();

    let t = Instant::now();
    let (mut qemu, mut uart0) = Qemu::boot(&elf).unwrap_or_else(|e| panic!("boot: {e}"));
    let banner = uart0
        .read_line(TIMEOUT)
        .unwrap_or_else(|e| panic!("banner: {e}\nQEMU printed:\n{}", qemu.output()));
    let boot = t.elapsed();
    assert!(
        banner.starts_with("margemu-firmware qemu-mps2-an386 "),
        "banner {banner:?}"
    );

    // The Cortex-M4F's FPU and the host compute the same bits with the same `libm`.
    let fpu = uart0.read_line(TIMEOUT).expect("FPU line");
    let expected = libm::sinf(0.5) * libm::sqrtf(2.0);
    assert_eq!(
        fpu,
        format!("fpu sinf(0.5)*sqrtf(2)={:#010x}", expected.to_bits())
    );

    // Every byte value but the exit command, sent in one go: UART RX and TX, both ways.
    let payload: Vec<u8> = (0..=u8::MAX).filter(|&b| b != b'q').collect();
    let t = Instant::now();
    uart0.write_all(&payload).expect("send");
    let echoed = uart0.read_exact(payload.len(), TIMEOUT).expect("echo");
    let echo = t.elapsed();
    assert_eq!(echoed, payload);

    let t = Instant::now();
    uart0.write_all(b"q").expect("send q");
    assert_eq!(uart0.read_exact(1, TIMEOUT).expect("echo of q"), b"q");
    let status = qemu
        .wait_exit(TIMEOUT)
        .unwrap_or_else(|e| panic!("exit: {e}\nQEMU printed:\n{}", qemu.output()));
    let exit = t.elapsed();
    assert_eq!(status.code(), Some(0), "QEMU printed:\n{}", qemu.output());

    eprintln!(
        "qemu_smoke: build {build:.2?}, boot to banner {boot:.2?}, echo of {} bytes {echo:.2?}, \
         q to exit {exit:.2?}; {banner}; {fpu}",
        payload.len()
    );
}
