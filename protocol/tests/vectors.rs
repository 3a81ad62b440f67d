//! Byte-literal test vectors of whole wire frames (also in `docs/spec/link.md`, computed there
//! by the spec's Python reference), and the link-efficiency table.

mod common;

use common::*;
use margemu_protocol::link::*;

fn check(message: Message<'_>, seq: u16, expected: &[u8]) {
    assert_eq!(wire(seq, &message), expected, "encode {message:?}");
    let mut acc = Accumulator::new();
    let FeedResult::Success { frame, remaining } = acc.feed(expected) else {
        panic!("decode")
    };
    assert!(remaining.is_empty());
    let repr = FrameRepr::parse(&frame).unwrap();
    assert_eq!(repr, FrameRepr { seq, message });
}

#[test]
fn hello() {
    let hello = Hello {
        protocol_version: 1,
        session: 0xDEAD_BEEF,
    };
    #[rustfmt::skip]
    let expected = [
        0x00, 0x03, 0x01, 0x01, 0x01, 0x02, 0x06, 0x02, 0x01, 0x09, 0xEF, 0xBE, 0xAD, 0xDE,
        0x82, 0x98, 0xAC, 0xD8, 0x00,
    ];
    check(Message::Hello(hello), 0, &expected);
}

#[test]
fn credit() {
    #[rustfmt::skip]
    let expected = [
        0x00, 0x04, 0x01, 0x82, 0x05, 0x02, 0x10, 0x01, 0x02, 0x01, 0x01, 0x01, 0x01, 0x01,
        0x01, 0x03, 0x40, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x05, 0xEF, 0xB2, 0x77, 0xE4,
        0x00,
    ];
    check(
        Message::Credit(Credit {
            next_index: 256,
            limit: 320,
        }),
        5,
        &expected,
    );
}

#[test]
fn image_batch() {
    let mut first = [0u8; IMAGE_LEN];
    first.iter_mut().enumerate().for_each(|(i, b)| *b = i as u8);
    let images = [first, [0xFF; IMAGE_LEN]];
    #[rustfmt::skip]
    let expected = [
        0x00, 0x06, 0x01, 0x10, 0x02, 0x01, 0x34, 0x03, 0x80, 0x02, 0x01, 0x01, 0x01, 0x01,
        0x01, 0x01, 0x30, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0A, 0x0B,
        0x0C, 0x0D, 0x0E, 0x0F, 0x10, 0x11, 0x12, 0x13, 0x14, 0x15, 0xFF, 0xFF, 0xFF, 0xFF,
        0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF,
        0xFF, 0xFF, 0xFF, 0xFF, 0x78, 0x29, 0x10, 0x9F, 0x00,
    ];
    check(
        Message::Images(ImageBatch::new(640, &images)),
        0x0102,
        &expected,
    );
}

#[test]
fn reset() {
    let expected = [
        0x00, 0x03, 0x01, 0x85, 0x01, 0x02, 0x01, 0x06, 0x01, 0x60, 0xBC, 0xDA, 0xC5, 0x00,
    ];
    check(
        Message::Reset(Reset {
            cause: ResetCause::PowerOn,
        }),
        0,
        &expected,
    );
}

#[test]
fn configure_images_with_one_override() {
    let mut cfg = Configure::new(0x71, Rate::hz(1000).unwrap());
    cfg.telemetry_period_ns = 10_000_000;
    let gyro_config = RegisterOverride {
        file: RegisterFile::Mpu9250,
        register: 0x1B,
        value: 0x18,
    };
    cfg.overrides.push(gyro_config).unwrap();
    #[rustfmt::skip]
    let expected = [
        0x00, 0x04, 0x01, 0x02, 0x01, 0x02, 0x16, 0x02, 0x71, 0x03, 0xE8, 0x03, 0x01, 0x02,
        0x01, 0x01, 0x01, 0x04, 0x80, 0x96, 0x98, 0x01, 0x01, 0x01, 0x01, 0x02, 0x01, 0x07,
        0x1B, 0x18, 0x4C, 0xC8, 0x03, 0x96, 0x00,
    ];
    check(Message::Configure(cfg), 1, &expected);
}

#[test]
fn link_efficiency_of_image_batches() {
    // Worst case (COBS adds a byte per started 254, two delimiters, 6-byte header, 8-byte first
    // index, 4-byte CRC), and the real encoding of images without any zero byte, which is it.
    let table = [
        (1, 43, 0.5116),
        (8, 197, 0.8934),
        (16, 374, 0.9412),
        (32, 727, 0.9684),
        (64, 1434, 0.9819),
    ];
    for (n, wire_len, efficiency) in table {
        assert_eq!(image_batch_wire_len(n), wire_len, "n = {n}");
        assert!(
            (image_batch_efficiency(n) - efficiency).abs() < 5e-5,
            "n = {n}"
        );
        let images = vec![[0x3Cu8; IMAGE_LEN]; n];
        let bytes = wire(0x0101, &Message::Images(ImageBatch::new(u64::MAX, &images)));
        assert_eq!(bytes.len(), wire_len, "n = {n}");
    }
    for n in 16..=MAX_IMAGES_PER_BATCH {
        assert!(image_batch_efficiency(n) >= 0.80, "n = {n}");
    }
    assert_eq!(MAX_IMAGES_PER_BATCH, 69);
}

#[test]
fn cobs_edge_cases_match_the_spec() {
    // A full block of 254 non-zero bytes that ends the frame gets no trailing code byte.
    let frame = [0x01u8; 254];
    let mut out = [0u8; 300];
    let n = stuff(&frame, &mut out).unwrap();
    assert_eq!(
        (n, out[0], out[1], out[255], out[256]),
        (257, 0x00, 0xFF, 0x01, 0x00)
    );
    let mut with_zero = [0x01u8; 255];
    with_zero[254] = 0;
    let n = stuff(&with_zero, &mut out).unwrap();
    assert_eq!(&out[256..n], &[0x01, 0x01, 0x00]);
}

/// With `MARGEMU_FUZZ_SEEDS=dir`, writes seed corpora for `protocol/fuzz`: `dir/decode/` (a
/// chunk-size byte, then a wire frame) and `dir/message/` (a kind byte, then a payload).
#[test]
fn write_fuzz_seeds() {
    let Some(dir) = std::env::var_os("MARGEMU_FUZZ_SEEDS") else {
        return;
    };
    use proptest::strategy::{Strategy, ValueTree};
    use proptest::test_runner::{Config, TestRunner};
    use std::path::Path;
    let (decode, message_dir) = (
        Path::new(&dir).join("decode"),
        Path::new(&dir).join("message"),
    );
    std::fs::create_dir_all(&decode).unwrap();
    std::fs::create_dir_all(&message_dir).unwrap();
    let mut runner = TestRunner::new(Config::default());
    for i in 0..64u16 {
        let owned = message().new_tree(&mut runner).unwrap().current();
        let msg = owned.message();
        let seed = [&[i as u8][..], &wire(i, &msg)].concat();
        std::fs::write(decode.join(format!("seed-{i:02}")), seed).unwrap();
        let seed = [&[msg.kind() as u8][..], &payload(&msg)].concat();
        std::fs::write(message_dir.join(format!("seed-{i:02}")), seed).unwrap();
    }
}
