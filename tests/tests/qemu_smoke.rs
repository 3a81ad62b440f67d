//! QEMU smoke test: the cross-built `qemu-mps2-an386` firmware boots in `qemu-system-arm` and
//! speaks the binary link on UART0 (reached through a PTY): it announces its power-on Reset,
//! answers a Hello with a HelloAck carrying the session number, and skips garbage between
//! frames. QEMU is then killed (the firmware has no exit command: any byte may appear inside a
//! frame).
//!
//! Skipped, with a message, where `qemu-system-arm` or a cross toolchain is missing; under
//! `CI=true` that is a failure instead.

use std::time::{Duration, Instant};

use margemu_protocol::link::{Encoder, Hello, HelloAck, Message, ResetCause, MAX_WIRE_LEN};
use margemu_protocol::PROTOCOL_VERSION;
use margemu_tests::qemu::{self, LinkDecoder, Qemu, SerialLink};

/// Generous: the machine is shared, and QEMU's first translation of the code takes a moment.
const TIMEOUT: Duration = Duration::from_secs(10);

/// What the device sent, decoded and copied out of the accumulator (the strings are read
/// through `Debug`, in failure messages).
#[derive(Debug)]
#[allow(dead_code)]
enum Seen {
    Reset(ResetCause),
    HelloAck(HelloAck),
    Error(String),
    Other(String),
}

/// Reads from `uart0` until `want` matches a decoded message; returns everything seen.
fn read_until_seen(
    uart0: &mut SerialLink,
    decoder: &mut LinkDecoder,
    want: impl Fn(&Seen) -> bool,
    what: &str,
    qemu: &Qemu,
) -> Vec<Seen> {
    let deadline = Instant::now() + TIMEOUT;
    let mut seen = Vec::new();
    while !seen.iter().any(&want) {
        let left = deadline.saturating_duration_since(Instant::now());
        let bytes = uart0.read_exact(1, left).unwrap_or_else(|e| {
            panic!(
                "waiting for {what}: {e}; decoded so far: {seen:?}\nQEMU printed:\n{}",
                qemu.output()
            )
        });
        decoder.feed(&bytes, &mut |m: &Message<'_>| {
            seen.push(match m {
                Message::Reset(r) => Seen::Reset(r.cause),
                Message::HelloAck(a) => Seen::HelloAck(*a),
                Message::Error(e) => Seen::Error(format!("{e:?}")),
                other => Seen::Other(format!("{other:?}")),
            })
        });
    }
    seen
}

#[test]
fn board_boots_and_answers_hello() {
    if !qemu::prerequisites_or_skip("qemu_smoke") {
        return;
    }
    let t = Instant::now();
    let elf = qemu::board_elf().unwrap_or_else(|e| panic!("board ELF: {e}"));
    let build = t.elapsed();

    let t = Instant::now();
    let (qemu, mut uart0) = Qemu::boot(&elf).unwrap_or_else(|e| panic!("boot: {e}"));
    let mut decoder = LinkDecoder::default();

    // The device sends its power-on Reset at its first poll; QEMU holds it for the PTY, which is
    // open before the CPU runs. Send Hello and expect Reset (power-on), then HelloAck.
    let session = 0x5145_4d55; // "QEMU"
    let mut encoder = Encoder::new();
    let mut wire = [0u8; MAX_WIRE_LEN];
    let hello = Hello {
        protocol_version: PROTOCOL_VERSION,
        session,
    };
    let n = encoder
        .encode(&Message::Hello(hello), &mut wire)
        .expect("encode Hello");
    uart0.write_all(&wire[..n]).expect("send Hello");
    let seen = read_until_seen(
        &mut uart0,
        &mut decoder,
        |s| matches!(s, Seen::HelloAck(_)),
        "HelloAck",
        &qemu,
    );
    let hello_rtt = t.elapsed();
    assert!(
        matches!(seen.first(), Some(Seen::Reset(ResetCause::PowerOn))),
        "first message {seen:?}"
    );
    let Some(Seen::HelloAck(ack)) = seen.last() else {
        unreachable!()
    };
    assert_eq!(ack.protocol_version, PROTOCOL_VERSION, "{ack:?}");
    assert_eq!(ack.session, session, "{ack:?}");
    assert_eq!(&ack.device_id[..15], b"qemu-mps2-an386", "{ack:?}");
    assert_eq!(
        (ack.firmware.major, ack.firmware.minor),
        (0, 1),
        "the board crate's version: {ack:?}"
    );
    assert_eq!(
        decoder.damaged, 0,
        "damaged frames from the device: {seen:?}"
    );

    // Garbage between frames is skipped; an intact frame that parses as another message still
    // gets its answer. Here: a second Hello, after a burst of every byte value.
    let garbage: Vec<u8> = (1..=u8::MAX).collect();
    uart0.write_all(&garbage).expect("send garbage");
    let hello = Hello {
        protocol_version: PROTOCOL_VERSION,
        session: session + 1,
    };
    let n = encoder
        .encode(&Message::Hello(hello), &mut wire)
        .expect("encode Hello");
    let t = Instant::now();
    uart0.write_all(&wire[..n]).expect("send Hello");
    let seen = read_until_seen(
        &mut uart0,
        &mut decoder,
        |s| matches!(s, Seen::HelloAck(a) if a.session == session + 1),
        "the second HelloAck",
        &qemu,
    );
    let second = t.elapsed();
    assert_eq!(
        decoder.damaged, 0,
        "damaged frames from the device: {seen:?}"
    );

    eprintln!(
        "qemu_smoke: build {build:.2?}, boot to HelloAck {hello_rtt:.2?}, garbage + Hello to \
         HelloAck {second:.2?}; firmware {}.{}.{}, capabilities {:?}",
        ack.firmware.major, ack.firmware.minor, ack.firmware.patch, ack.capabilities
    );
    drop(qemu); // kills and reaps QEMU
}
