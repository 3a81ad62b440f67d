//! Damaged frames are counted by class, the stream resynchronises, and nothing panics.

use margemu_protocol::link::{Configure, ImageBatch, Message};
use proptest::prelude::*;

use crate::common::*;

#[test]
fn damaged_frames_are_counted_and_the_stream_resynchronises() {
    let (mut dev, mut host) = configured();
    let ims = images(0, 4);
    let mut bad_crc = host.wire(&Message::Images(ImageBatch::new(0, &ims[..1])));
    bad_crc[20] ^= 0x04;
    let mut dropped_byte = host.wire(&Message::Images(ImageBatch::new(1, &ims[1..2])));
    dropped_byte.remove(15);
    let garbage = [0x13u8, 0x77, 0x00, 0x42, 0x42, 0x42];
    let good = host.wire(&Message::Images(ImageBatch::new(2, &ims[2..4])));
    let mut stream = Vec::new();
    stream.extend_from_slice(&bad_crc);
    stream.extend_from_slice(&dropped_byte);
    stream.extend_from_slice(&garbage);
    stream.extend_from_slice(&good);
    for chunk in stream.chunks(7) {
        dev.feed(chunk, 0);
    }
    let rx = dev.counters().rx;
    assert_eq!(rx.crc_errors, 1);
    assert!(rx.framing_errors >= 2, "{rx:?}"); // the cut frame and the garbage
    assert_eq!(
        rx.lost_frames, 2,
        "two host frames missing by sequence number"
    );
    assert_eq!((dev.buffer_level(), dev.credit().next_index), (2, 0));
    host.start(&mut dev, 0, 0);
    poll(&mut dev, 3 * MS);
    assert_eq!(burst_sensors(&mut dev), image(3)[..14]);
    let t = telemetry(&poll(&mut dev, 200 * MS)).unwrap();
    assert_eq!((t.crc_errors, t.lost_frames), (1, 2));
    assert_eq!(t.framing_errors, rx.framing_errors);
}

#[test]
fn unknown_and_device_bound_kinds_are_rejected() {
    let (mut dev, mut host) = configured();
    let telemetry_kind = host.wire(&Message::Credit(Default::default()));
    dev.feed(&telemetry_kind, 0);
    let out = poll(&mut dev, 0);
    assert!(
        matches!(&out[..], [Out::Error(e)] if e.detail == 0x82),
        "{out:?}"
    );
    assert_eq!(dev.counters().rx.rejected_messages, 1);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn random_bytes_never_panic(
        chunks in prop::collection::vec(prop::collection::vec(any::<u8>(), 0..300), 0..20),
        steps in prop::collection::vec(0u64..3_000_000, 0..20),
    ) {
        let mut dev = Dev::new();
        let mut host = Host::new();
        host.hello(&mut dev, 1);
        host.configure(&mut dev, Configure::new(ChipModel::Mpu9250, rate_1khz()));
        host.start(&mut dev, 0, 0);
        let mut now = 0;
        for (i, chunk) in chunks.iter().enumerate() {
            dev.feed(chunk, now);
            now += steps.get(i).copied().unwrap_or(1);
            dev.poll(now, &mut |_: &[u8]| {});
        }
        // Whatever came before, a good frame after it is recovered.
        host.hello(&mut dev, 77);
        let out = poll(&mut dev, now);
        prop_assert!(out.iter().any(|o| matches!(o, Out::HelloAck(a) if a.session == 77)));
    }

    #[test]
    fn random_host_frames_never_panic(
        kinds in prop::collection::vec((0u8..=0xFF, prop::collection::vec(any::<u8>(), 0..120)), 0..30),
    ) {
        let mut dev = Dev::new();
        let mut host = Host::new();
        host.hello(&mut dev, 1);
        let mut now = 0;
        for (kind, payload) in kinds {
            // A well-framed frame of any kind with any payload.
            let mut frame = vec![1u8, kind, 0, 0];
            frame.extend_from_slice(&(payload.len() as u16).to_le_bytes());
            frame.extend_from_slice(&payload);
            let crc = margemu_protocol::link::CRC32C.checksum(&frame);
            frame.extend_from_slice(&crc.to_le_bytes());
            let mut wire = [0u8; 2048];
            let n = margemu_protocol::link::stuff(&frame, &mut wire).unwrap();
            dev.feed(&wire[..n], now);
            now += 700_000;
            dev.poll(now, &mut |_: &[u8]| {});
        }
    }
}

#[test]
fn indices_at_the_end_of_the_range_are_overruns_not_panics() {
    let (mut dev, mut host) = configured();
    host.images(&mut dev, u64::MAX - 2, &images(0, 5), 0);
    assert_eq!(dev.counters().overruns, 5);
    host.start(&mut dev, u64::MAX - 10, 0);
    poll(&mut dev, u64::MAX);
    poll(&mut dev, u64::MAX);
}
