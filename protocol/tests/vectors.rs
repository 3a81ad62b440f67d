//! Byte-literal test vectors of whole wire frames (also in `docs/spec/link.md`, computed there
//! by the spec's Python reference), and the link-efficiency table.

mod common;

use common::*;
use margemu_protocol::chip::ChipModel;
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
fn hello_ack() {
    let mut device_id = [0u8; DEVICE_ID_LEN];
    device_id[..4].copy_from_slice(b"MARG");
    let ack = HelloAck {
        protocol_version: 3,
        session: 0xDEAD_BEEF,
        firmware: FirmwareVersion {
            major: 0,
            minor: 4,
            patch: 0,
        },
        device_id,
        capabilities: Capabilities {
            chips: Chips::of(ChipModel::Mpu9250) | Chips::of(ChipModel::Icm42688p),
            modes: Modes::IMAGES | Modes::MODEL,
            buses: Buses::SPI | Buses::I2C,
            max_batch: 68,
            buffer_capacity: 512,
        },
    };
    #[rustfmt::skip]
    let expected = [
        0x00, 0x03, 0x01, 0x81, 0x01, 0x02, 0x25, 0x02, 0x03, 0x05, 0xEF, 0xBE, 0xAD, 0xDE,
        0x02, 0x04, 0x05, 0x4D, 0x41, 0x52, 0x47, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01,
        0x01, 0x01, 0x01, 0x01, 0x02, 0x11, 0x01, 0x01, 0x04, 0x03, 0x03, 0x44, 0x01, 0x02,
        0x02, 0x01, 0x05, 0xBA, 0xEF, 0x95, 0xC7, 0x00,
    ];
    check(Message::HelloAck(ack), 0, &expected);
}

#[test]
fn image_batch() {
    let first: [u8; 22] = core::array::from_fn(|i| i as u8);
    let images = [Image::from(first), Image::from([0xFF; 22])];
    #[rustfmt::skip]
    let expected = [
        0x00, 0x06, 0x01, 0x10, 0x02, 0x01, 0x35, 0x03, 0x80, 0x02, 0x01, 0x01, 0x01, 0x01,
        0x01, 0x02, 0x16, 0x30, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0A,
        0x0B, 0x0C, 0x0D, 0x0E, 0x0F, 0x10, 0x11, 0x12, 0x13, 0x14, 0x15, 0xFF, 0xFF, 0xFF,
        0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF,
        0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x4E, 0x22, 0xB5, 0x6B, 0x00,
    ];
    check(
        Message::Images(ImageBatch::new(640, &images)),
        0x0102,
        &expected,
    );
}

#[test]
fn image_batch_of_one_icm42688p_image() {
    let image: [u8; 32] = core::array::from_fn(|i| 0x20 + i as u8);
    #[rustfmt::skip]
    let expected = [
        0x00, 0x04, 0x01, 0x10, 0x02, 0x02, 0x29, 0x02, 0x07, 0x01, 0x01, 0x01, 0x01, 0x01,
        0x01, 0x26, 0x20, 0x20, 0x21, 0x22, 0x23, 0x24, 0x25, 0x26, 0x27, 0x28, 0x29, 0x2A,
        0x2B, 0x2C, 0x2D, 0x2E, 0x2F, 0x30, 0x31, 0x32, 0x33, 0x34, 0x35, 0x36, 0x37, 0x38,
        0x39, 0x3A, 0x3B, 0x3C, 0x3D, 0x3E, 0x3F, 0x11, 0x11, 0x46, 0xAB, 0x00,
    ];
    check(
        Message::Images(ImageBatch::new(7, &[Image::from(image)])),
        2,
        &expected,
    );
}

#[test]
fn add_fault_stuck_at() {
    use margemu_model::fault::{Fault, FaultKind, Sensor, Window};
    let kind = FaultKind::StuckAt {
        sensor: Sensor::Gyr,
        value: [0.5, -0.25, 1.0],
    };
    let fault = Fault::new(0, Window::new(1_000_000, 3_000_000), kind);
    #[rustfmt::skip]
    let expected = [
        0x00, 0x04, 0x01, 0x07, 0x03, 0x02, 0x27, 0x01, 0x02, 0x07, 0x01, 0x01, 0x01, 0x01,
        0x01, 0x01, 0x04, 0x40, 0x42, 0x0F, 0x01, 0x01, 0x01, 0x01, 0x04, 0xC0, 0xC6, 0x2D,
        0x01, 0x01, 0x01, 0x01, 0x03, 0x01, 0x01, 0x01, 0x01, 0x02, 0x3F, 0x01, 0x03, 0x80,
        0xBE, 0x01, 0x07, 0x80, 0x3F, 0x1C, 0xE1, 0x38, 0xC3, 0x00,
    ];
    check(Message::AddFault(AddFault { fault, seed: 7 }), 3, &expected);
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
    let mut cfg = Configure::new(ChipModel::Mpu9250, Rate::hz(1000).unwrap());
    assert_eq!(
        (cfg.who_am_i, cfg.image_len, cfg.i2c_address),
        (0x71, 22, 0x68)
    );
    cfg.telemetry_period_ns = 10_000_000;
    let gyro_config = RegisterOverride {
        file: 0, // the MPU-9250's own registers
        register: 0x1B,
        value: 0x18,
    };
    cfg.overrides.push(gyro_config).unwrap();
    #[rustfmt::skip]
    let expected = [
        0x00, 0x04, 0x01, 0x02, 0x01, 0x02, 0x19, 0x01, 0x04, 0x71, 0x16, 0x68, 0x03, 0xE8,
        0x03, 0x01, 0x02, 0x01, 0x01, 0x01, 0x04, 0x80, 0x96, 0x98, 0x01, 0x01, 0x01, 0x01,
        0x02, 0x01, 0x07, 0x1B, 0x18, 0xDD, 0x6C, 0xB9, 0x9E, 0x00,
    ];
    check(Message::Configure(cfg), 1, &expected);
}

#[test]
fn link_efficiency_of_image_batches() {
    // Worst case (COBS adds a byte per started 254, two delimiters, 6-byte header, 8-byte first
    // index, 1-byte image length, 4-byte CRC), and the real encoding of images without any zero
    // byte, which is it.
    let table = [
        // MPU-9250 (22 bytes).
        (22, 1, 44, 0.5000),
        (22, 8, 198, 0.8889),
        (22, 16, 375, 0.9387),
        (22, 32, 728, 0.9670),
        (22, 64, 1435, 0.9812),
        // MPU-6500, MPU-6000, ICM-20602 (14 bytes).
        (14, 1, 36, 0.3889),
        (14, 32, 471, 0.9512),
        (14, 64, 921, 0.9729),
        // ICM-42688-P (32 bytes).
        (32, 1, 54, 0.5926),
        (32, 32, 1050, 0.9752),
    ];
    for (len, n, wire_len, efficiency) in table {
        assert_eq!(image_batch_wire_len(n, len), wire_len, "{n} × {len}");
        assert!(
            (image_batch_efficiency(n, len) - efficiency).abs() < 5e-5,
            "{n} × {len}"
        );
        let images = vec![Image::new(&vec![0x3C; len]).unwrap(); n];
        let bytes = wire(0x0101, &Message::Images(ImageBatch::new(u64::MAX, &images)));
        assert_eq!(bytes.len(), wire_len, "{n} × {len}");
    }
    for model in ChipModel::ALL {
        let len = model.image_len();
        for n in 16..=max_images_per_batch(len) {
            assert!(image_batch_efficiency(n, len) >= 0.80, "{n} × {len}");
        }
    }
    assert_eq!(
        [22, 14, 32].map(max_images_per_batch),
        [68, 108, 47],
        "(1526 − 9) / image length"
    );
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
