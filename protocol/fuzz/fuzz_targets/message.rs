//! Arbitrary payloads of every kind through `Message::parse`, then the whole send path.
//!
//! Checks: nothing panics; a payload that parses re-emits to the same bytes, and the message
//! survives encode → COBS → accumulator → parse unchanged.
#![no_main]

use libfuzzer_sys::fuzz_target;
use margemu_protocol::link::{
    Accumulator, Encoder, FeedResult, FrameRepr, Message, MAX_PAYLOAD_LEN, MAX_WIRE_LEN,
};

fuzz_target!(|data: &[u8]| {
    let Some((&kind, payload)) = data.split_first() else {
        return;
    };
    let Ok(msg) = Message::parse(kind, payload) else {
        return;
    };
    assert_eq!(msg.buffer_len(), payload.len());
    let mut buf = [0u8; MAX_PAYLOAD_LEN];
    let n = msg.emit(&mut buf).expect("emit");
    assert_eq!(&buf[..n], payload);
    let mut wire = [0u8; MAX_WIRE_LEN];
    let Ok(w) = Encoder::new().encode(&msg, &mut wire) else {
        assert!(payload.len() > MAX_PAYLOAD_LEN);
        return;
    };
    let mut acc = Accumulator::new();
    let FeedResult::Success { frame, remaining } = acc.feed(&wire[..w]) else {
        panic!("lost")
    };
    assert!(remaining.is_empty());
    let back = FrameRepr::parse(&frame).expect("parse");
    let mut again = [0u8; MAX_PAYLOAD_LEN];
    let m = back.message.emit(&mut again).expect("emit");
    assert_eq!(&again[..m], payload);
});
