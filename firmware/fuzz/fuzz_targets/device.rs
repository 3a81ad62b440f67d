//! The firmware's link handler under any sequence of frames of every kind, raw bytes, clock
//! jumps, polls and bus transactions: see `device_ops.rs` for the operations and the invariants.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "../device_ops.rs"]
mod device_ops;

fuzz_target!(|data: &[u8]| {
    device_ops::run(data);
});
