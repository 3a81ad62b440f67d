//! The fuzz target's operations (`firmware/fuzz/device_ops.rs`) on random inputs and on seeds
//! that reach a streaming session, so every `cargo test` runs the fuzz harness and its checks.

use proptest::prelude::*;

#[path = "../../fuzz/device_ops.rs"]
mod device_ops;

/// Hello, Configure (MPU-9250 at 1 kHz), images 0..8, a fault, Start, time passes, polls and a
/// burst.
fn streaming_seed() -> Vec<u8> {
    let mut s = vec![2, 0, 1, 0, 0, 0]; // Hello, this version, session 1
    s.extend([3, 0, 0xE8, 0x03, 0, 0, 0, 0, 0, 0]); // Configure: MPU-9250, 1001/1 Hz
    s.extend([6, 0, 0, 0, 0, 0, 0, 0, 0, 8, 22]); // 8 images of 22 bytes from index 0
    s.extend((0..8 * 22).map(|i| i as u8));
    // AddFault, a valid message: device 0, seed 7, from 0 for 5 ms, the gyroscope stuck.
    s.extend([11, 0, 7, 0, 0, 0, 0, 0, 0, 0]);
    s.extend([0; 8]);
    s.extend(5_000_000u32.to_le_bytes());
    s.extend([0, 1, 0]);
    s.extend([4, 0, 0, 0, 0, 0, 0, 0, 0, 63, 0, 0, 0, 0]); // Start until Stop at t0 = 0
    for _ in 0..12 {
        s.extend([7, 0x40, 0x42, 0x0F, 0x00, 0]); // +1 ms
        s.extend([8]); // poll
        s.extend([9, 0xBB, 14, 1]); // SPI burst from ACCEL_XOUT_H
        s.extend([0; 14]);
    }
    s.extend([5, 8]); // Stop, poll
    s
}

#[test]
fn a_streaming_session_passes_the_harness_checks() {
    // Polls 1 ms apart up to 12 ms from t0 = 0 at 1001 Hz: instants 0..=12 (8 images, then
    // underruns).
    assert_eq!(device_ops::run(&streaming_seed()), 13);
}

/// With `MARGEMU_FUZZ_SEEDS=dir`, writes the seed corpus for `firmware/fuzz`: `dir/device/`
/// (the streaming session above, which the fuzzer then mutates).
#[test]
fn write_fuzz_seeds() {
    let Some(dir) = std::env::var_os("MARGEMU_FUZZ_SEEDS") else {
        return;
    };
    let device = std::path::Path::new(&dir).join("device");
    std::fs::create_dir_all(&device).unwrap();
    std::fs::write(device.join("streaming-session"), streaming_seed()).unwrap();
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn random_operations_keep_the_device_intact(data in prop::collection::vec(any::<u8>(), 0..2048)) {
        device_ops::run(&data);
    }

    #[test]
    fn mutated_sessions_keep_the_device_intact(
        flips in prop::collection::vec((any::<u16>(), any::<u8>()), 1..16),
    ) {
        let mut data = streaming_seed();
        for (at, xor) in flips {
            let i = usize::from(at) % data.len();
            data[i] ^= xor;
        }
        device_ops::run(&data);
    }
}
