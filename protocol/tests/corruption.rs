//! Damaged streams: every single-bit flip, every dropped byte, every truncation of a frame, and
//! garbage between frames are detected and counted in the right class, the frames around them
//! are recovered, and random bytes never panic the accumulator or the parser.

mod common;

use common::*;
use margemu_protocol::chip::ChipModel;
use margemu_protocol::link::*;
use proptest::prelude::*;

/// Three frames A, B, C: B is the victim.
fn abc() -> (Vec<u8>, Vec<u8>, Vec<u8>) {
    let images = [[0x5Au8; 22], [0x00; 22], [0xA5; 22]].map(Image::from);
    let a = wire(1, &Message::Start(Start::until_stop(7)));
    let b = wire(2, &Message::Images(ImageBatch::new(1 << 40, &images)));
    let c = wire(
        3,
        &Message::Credit(Credit {
            next_index: 3,
            limit: 67,
        }),
    );
    (a, b, c)
}

fn frame_of(wire: &[u8]) -> Outcome {
    let mut acc = Accumulator::new();
    feed(&mut acc, wire, &[wire.len()]).remove(0)
}

/// Feeds A, damaged B, C; checks A and C came out intact around B's outcomes; returns those.
fn around(a: &[u8], damaged_b: &[u8], c: &[u8], chunk: usize) -> Vec<Outcome> {
    let stream = [a, damaged_b, c].concat();
    let mut acc = Accumulator::new();
    let mut out = feed(&mut acc, &stream, &[chunk]);
    assert_eq!(out.first(), Some(&frame_of(a)), "A lost");
    assert_eq!(out.last(), Some(&frame_of(c)), "C lost");
    out.remove(0);
    out.pop();
    out
}

/// Positions of the COBS code bytes in an encoded frame that starts with a 0x00.
fn code_bytes(wire: &[u8]) -> Vec<usize> {
    let mut at = 1;
    let mut codes = Vec::new();
    while at < wire.len() - 1 {
        codes.push(at);
        at += usize::from(wire[at]);
    }
    codes
}

#[test]
fn every_single_bit_flip_is_detected_and_classified() {
    let (a, b, c) = abc();
    let codes = code_bytes(&b);
    for bit in 0..b.len() * 8 {
        let mut bad = b.clone();
        let at = bit / 8;
        bad[at] ^= 1 << (bit % 8);
        let out = around(&a, &bad, &c, 1 + bit % 37);
        assert!(!out.is_empty(), "bit {bit}: nothing reported");
        assert!(
            out.iter()
                .all(|o| matches!(o, Outcome::Damaged(e) if e.is_framing())),
            "bit {bit}: {out:?}"
        );
        // A flipped data byte (not a COBS code byte, not turned into 0x00) past the header is
        // a CRC error, exactly once.
        if at > 7 && at < b.len() - 1 && !codes.contains(&at) && bad[at] != 0 {
            assert_eq!(out, [Outcome::Damaged(Error::FrameBadCrc)], "bit {bit}");
        }
    }
}

#[test]
fn every_dropped_byte_is_detected() {
    let (a, b, c) = abc();
    let codes = code_bytes(&b);
    for at in 0..b.len() {
        let bad = [&b[..at], &b[at + 1..]].concat();
        let out = around(&a, &bad, &c, 5);
        if at == 0 || at == b.len() - 1 {
            // A delimiter: the neighbour's delimiter still closes B, which arrives intact.
            assert_eq!(out, [frame_of(&b)], "delimiter {at}");
            continue;
        }
        assert_eq!(out.len(), 1, "byte {at}: {out:?}");
        let Outcome::Damaged(e) = out[0] else {
            panic!("byte {at}: accepted")
        };
        assert!(e.is_framing(), "byte {at}: {e:?}");
        // A data byte of the last COBS block: that block's code byte now points past the end.
        // (Elsewhere the next code byte is read as data: the frame is misaligned and fails its
        // COBS, length or CRC check.)
        if at > *codes.last().unwrap() {
            assert_eq!(e, Error::FrameBadCobs, "byte {at}");
        }
    }
}

#[test]
fn every_truncation_is_detected() {
    let (a, b, c) = abc();
    let codes = code_bytes(&b);
    // Cut after `keep` bytes (leading 0x00 included); the next frame's 0x00 ends the stub.
    for keep in 2..b.len() - 1 {
        let out = around(&a, &b[..keep], &c, 64);
        // Cut inside a COBS block: the code byte points past the end. At a block boundary: the
        // frame is shorter than its length field.
        let expected = if codes.contains(&keep) {
            Error::FrameTruncated
        } else {
            Error::FrameBadCobs
        };
        assert_eq!(out, [Outcome::Damaged(expected)], "keep {keep}");
    }
}

#[test]
fn an_oversized_frame_is_dropped_up_to_its_delimiter() {
    let (a, _, c) = abc();
    let junk = vec![0x42u8; MAX_ENCODED_LEN + 10];
    let out = around(&a, &junk, &c, 100);
    assert_eq!(out, [Outcome::Damaged(Error::FrameOverFull)]);
    // Exactly the buffer size still fits (and then fails its checks as a frame).
    let junk = vec![0x42u8; MAX_ENCODED_LEN];
    let out = around(&a, &junk, &c, 100);
    assert_eq!(out, [Outcome::Damaged(Error::FrameBadCobs)]);
}

#[test]
fn a_largest_frame_fits_the_accumulator_in_the_worst_case() {
    // No zero byte at all: COBS overhead is at its maximum. Every model's image length, and
    // 1-byte images, which fill the payload to its last byte (1517 images, a 1536-byte frame).
    let lengths = ChipModel::ALL.map(|m| m.image_len());
    for len in lengths.into_iter().chain([1]) {
        let n = max_images_per_batch(len);
        let images = vec![Image::new(&vec![0x77u8; len]).unwrap(); n];
        let msg = Message::Images(ImageBatch::new(u64::MAX, &images));
        let bytes = wire(0xFFFF, &msg);
        assert!(bytes.len() <= MAX_WIRE_LEN, "{len}");
        assert_eq!(bytes.len(), image_batch_wire_len(n, len), "{len}");
        assert_eq!(frame_of(&bytes), Outcome::Frame(frame(0xFFFF, &msg)));
        let mut too_many = vec![images[0]; n + 1];
        too_many[0].as_mut_bytes()[0] = 1;
        let msg = Message::Images(ImageBatch::new(0, &too_many));
        let mut out = [0u8; MAX_WIRE_LEN];
        assert_eq!(
            Encoder::new().encode(&msg, &mut out),
            Err(Error::MessageTooLarge),
            "{len}"
        );
    }
}

#[test]
fn a_frame_from_a_newer_version_is_refused_after_its_crc() {
    let mut f = frame(9, &Message::Stop);
    f[0] = 2;
    Frame::new_unchecked(&mut f[..]).fill_crc();
    let mut w = vec![0u8; max_wire_len(f.len())];
    let n = stuff(&f, &mut w).unwrap();
    assert_eq!(frame_of(&w[..n]), Outcome::Damaged(Error::FrameBadVersion));
}

#[test]
fn counters_follow_outcomes_and_sequence_gaps() {
    let (a, b, c) = abc();
    let mut bad = b.clone();
    bad[20] ^= 0x04;
    let stream = [&a[..], &bad, &[0x13, 0x37, 0x00], &c].concat();
    let mut acc = Accumulator::new();
    let (mut stats, mut seqs) = (RxStats::default(), SeqTracker::new());
    let mut input = &stream[..];
    loop {
        let r = acc.feed(input);
        stats.record(&r);
        match r {
            FeedResult::Consumed => break,
            FeedResult::Success { frame, remaining } => {
                stats.record_seq(seqs.observe(frame.seq()));
                input = remaining;
            }
            other => input = other.remaining(),
        }
    }
    let expected = RxStats {
        frames: 2,
        crc_errors: 1,
        framing_errors: 1,
        lost_frames: 1,
        rejected_messages: 0,
    };
    assert_eq!(stats, expected);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn the_next_good_frame_after_garbage_is_always_recovered(
        m1 in message(),
        m2 in message(),
        garbage in prop::collection::vec(any::<u8>(), 0..4000),
        chunks in prop::collection::vec(1..200usize, 1..6),
    ) {
        let (a, c) = (wire(10, &m1.message()), wire(11, &m2.message()));
        let stream = [&a[..], &garbage, &c].concat();
        let mut acc = Accumulator::new();
        let out = feed(&mut acc, &stream, &chunks);
        prop_assert_eq!(out.first(), Some(&frame_of(&a)));
        prop_assert_eq!(out.last(), Some(&frame_of(&c)));
        for o in &out[1..out.len() - 1] {
            prop_assert!(matches!(o, Outcome::Damaged(e) if e.is_framing()), "{:?}", o);
        }
        // Garbage with a non-zero byte is reported at least once.
        prop_assert_eq!(out.len() > 2, garbage.iter().any(|&g| g != 0));
    }

    #[test]
    fn random_bytes_never_panic(
        bytes in prop::collection::vec(any::<u8>(), 0..6000),
        chunks in prop::collection::vec(1..100usize, 1..6),
    ) {
        let mut acc = Accumulator::new();
        for o in feed(&mut acc, &bytes, &chunks) {
            if let Outcome::Frame(f) = o {
                let frame = Frame::new_verified(&f[..]).unwrap();
                let _ = FrameRepr::parse(&frame);
            }
        }
    }

    #[test]
    fn random_payloads_never_panic_the_parser(
        kind in any::<u8>(),
        bytes in prop::collection::vec(any::<u8>(), 0..1600),
    ) {
        if let Ok(msg) = Message::parse(kind, &bytes) {
            prop_assert_eq!(&payload(&msg), &bytes);
        }
        let f = Frame::new_unchecked(&bytes[..]);
        let _ = (f.payload(), f.crc(), f.check_crc(), FrameRepr::parse(&f));
    }
}
