//! Property tests: every message survives encode → frame → COBS → accumulator (fed in random
//! chunk sizes) → decode, alone and in streams.

mod common;

use common::*;
use margemu_protocol::link::*;
use proptest::prelude::*;

fn assert_same(parsed: &Message<'_>, sent: &Message<'_>) -> Result<(), TestCaseError> {
    // Bytes first (they carry NaN payloads exactly), then the structure.
    prop_assert_eq!(payload(parsed), payload(sent));
    prop_assert_eq!(format!("{parsed:?}"), format!("{sent:?}"));
    prop_assert_eq!(parsed.kind(), sent.kind());
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn every_message_round_trips(
        owned in message(),
        seq in any::<u16>(),
        chunks in prop::collection::vec(1..80usize, 1..8),
    ) {
        let sent = owned.message();
        let bytes = wire(seq, &sent);
        prop_assert!(bytes.len() <= max_wire_len(HEADER_LEN + sent.buffer_len() + CRC_LEN));
        let mut acc = Accumulator::new();
        let out = feed(&mut acc, &bytes, &chunks);
        let expected = frame(seq, &sent);
        prop_assert_eq!(&out, &vec![Outcome::Frame(expected.clone())]);
        prop_assert_eq!(acc.pending(), 0);
        let f = Frame::new_verified(&expected[..]).unwrap();
        let repr = FrameRepr::parse(&f).unwrap();
        prop_assert_eq!(repr.seq, seq);
        assert_same(&repr.message, &sent)?;
        // The accumulator gives back exactly the frame bytes; re-emitting them is canonical.
        let mut again = vec![0u8; repr.buffer_len()];
        prop_assert_eq!(repr.emit(&mut again), Ok(expected.len()));
        prop_assert_eq!(again, expected);
    }

    #[test]
    fn a_stream_of_messages_round_trips_in_any_chunking(
        owned in prop::collection::vec(message(), 1..6),
        first_seq in any::<u16>(),
        chunks in prop::collection::vec(1..300usize, 1..8),
    ) {
        let mut enc = Encoder::new();
        enc.set_next_seq(first_seq);
        let mut bytes = Vec::new();
        let mut buf = [0u8; MAX_WIRE_LEN];
        for o in &owned {
            let n = enc.encode(&o.message(), &mut buf).unwrap();
            bytes.extend_from_slice(&buf[..n]);
        }
        let mut acc = Accumulator::new();
        let out = feed(&mut acc, &bytes, &chunks);
        prop_assert_eq!(out.len(), owned.len());
        let mut seqs = SeqTracker::new();
        for (i, (o, got)) in owned.iter().zip(&out).enumerate() {
            let Outcome::Frame(bytes) = got else {
                return Err(TestCaseError::fail(format!("frame {i}: {got:?}")));
            };
            let f = Frame::new_verified(&bytes[..]).unwrap();
            let repr = FrameRepr::parse(&f).unwrap();
            prop_assert_eq!(repr.seq, first_seq.wrapping_add(i as u16));
            let event = seqs.observe(repr.seq);
            prop_assert!(matches!(event, SeqEvent::First | SeqEvent::InOrder));
            assert_same(&repr.message, &o.message())?;
        }
    }

    #[test]
    fn message_bytes_parse_back_to_the_same_bytes(owned in message()) {
        let sent = owned.message();
        let bytes = payload(&sent);
        prop_assert_eq!(bytes.len(), sent.buffer_len());
        let parsed = Message::parse(sent.kind() as u8, &bytes).unwrap();
        assert_same(&parsed, &sent)?;
        // Any strict prefix is refused, never misread; except that a batch of 1-byte images
        // one byte short is a whole batch of one image fewer (the frame's length and CRC guard
        // against that).
        if !bytes.is_empty() {
            let prefix = Message::parse(sent.kind() as u8, &bytes[..bytes.len() - 1]);
            match (&sent, prefix) {
                (Message::Images(sent), Ok(Message::Images(short))) => {
                    prop_assert_eq!(sent.images.image_len(), 1);
                    prop_assert_eq!(short.images.image_len(), 1);
                    prop_assert_eq!(short.images.len() + 1, sent.images.len());
                }
                (_, prefix) => prop_assert!(prefix.is_err(), "{:?}", prefix),
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn images_of_every_model_round_trip(
        model in chip_model(),
        first_index in any::<u64>(),
        seed in any::<u8>(),
        count in 0..=47usize,
    ) {
        let len = model.image_len();
        let images: Vec<Image> = (0..count)
            .map(|i| {
                let bytes: Vec<u8> = (0..len).map(|k| seed ^ (i * 7 + k) as u8).collect();
                Image::new(&bytes).unwrap()
            })
            .collect();
        let sent = Message::Images(ImageBatch::new(first_index, &images));
        let bytes = wire(7, &sent);
        let mut acc = Accumulator::new();
        let out = feed(&mut acc, &bytes, &[bytes.len()]);
        let Some(Outcome::Frame(f)) = out.first() else {
            return Err(TestCaseError::fail(format!("{out:?}")));
        };
        let f = Frame::new_verified(&f[..]).unwrap();
        let Message::Images(batch) = FrameRepr::parse(&f).unwrap().message else {
            return Err(TestCaseError::fail("not an image batch"));
        };
        prop_assert_eq!(batch.first_index, first_index);
        prop_assert_eq!(batch.images.image_len(), if count == 0 { 0 } else { len });
        prop_assert_eq!(batch.images.iter().collect::<Vec<_>>(), images);
    }
}
