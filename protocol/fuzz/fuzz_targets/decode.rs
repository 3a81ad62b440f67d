//! Arbitrary bytes, in arbitrary chunks, through the stream accumulator and the message parser.
//!
//! Checks: nothing panics; every intact frame's parsed message re-emits to exactly the frame's
//! bytes (the encoding is canonical); every outcome is counted in exactly one class.
#![no_main]

use libfuzzer_sys::fuzz_target;
use margemu_protocol::link::{
    emit_frame, Accumulator, FeedResult, FrameRepr, RxStats, MAX_FRAME_LEN,
};

fuzz_target!(|data: &[u8]| {
    let Some((&chunk, data)) = data.split_first() else {
        return;
    };
    let chunk = usize::from(chunk % 64) + 1;
    let mut acc = Accumulator::new();
    let mut stats = RxStats::default();
    let mut outcomes = 0u32;
    let mut out = [0u8; MAX_FRAME_LEN];
    for piece in data.chunks(chunk) {
        let mut input = piece;
        loop {
            let result = acc.feed(input);
            stats.record(&result);
            match result {
                FeedResult::Consumed => break,
                FeedResult::Success { frame, remaining } => {
                    outcomes += 1;
                    if let Ok(repr) = FrameRepr::parse(&frame) {
                        let n = emit_frame(repr.seq, &repr.message, &mut out).expect("re-emit");
                        assert_eq!(&out[..n], frame.into_inner(), "non-canonical encoding");
                    }
                    input = remaining;
                }
                damaged => {
                    outcomes += 1;
                    assert!(damaged.error().is_some_and(|e| e.is_framing()));
                    input = damaged.remaining();
                }
            }
        }
    }
    assert_eq!(
        stats.frames + stats.crc_errors + stats.framing_errors,
        outcomes
    );
});
