//! The loopback lengths, in real time against the real firmware `Device` behind a PTY
//! pair: 60 s of a 1 kHz scene and 10 s at 8 kHz, every sample served, none lost, each image
//! byte for byte the host's prediction (the device's Served CRC-32C against the prediction's).
//! In their own file so that they run beside the other test binaries' tests.

mod common;

use common::{assert_logs_valid, config, loopback, scene, scratch};

fn long_run(duration: f64, rate: f64) {
    let scene = scene(duration, rate);
    let dir = scratch(&format!("long-{rate}"));
    let (result, device) = loopback(&scene, &dir, config());
    let summary = result.unwrap();
    let total = scene.samples();
    let s = summary.served;
    assert_eq!(s.samples, total);
    assert_eq!(
        (
            s.byte_exact,
            s.underruns,
            s.mismatched,
            s.unreported,
            s.after_end
        ),
        (total, 0, 0, 0, 0),
        "{s:?}"
    );
    assert_eq!(device.counters.overruns, 0);
    assert_eq!(summary.sent, total);
    let served = common::served(&dir, total);
    assert_eq!(served.len() as u64, total);
    assert!(served
        .iter()
        .enumerate()
        .all(|(i, &(k, u, ok))| k == i as u64 && !u && ok));
    assert_logs_valid(&dir);
    let j = summary.jitter;
    println!(
        "{duration} s at {rate} Hz: {total} samples served byte for byte; {} batches, pacing late p50 {} µs, p99 {} µs, max {} µs; credit stalls {}; resends {}",
        j.batches,
        j.p50_ns / 1000,
        j.p99_ns / 1000,
        j.max_ns / 1000,
        summary.credit_stalls,
        summary.resends
    );
    std::fs::remove_dir_all(&dir).unwrap(); // tens of MB; kept only when the test fails
}

#[test]
fn sixty_seconds_at_1_khz_lose_nothing() {
    long_run(60.0, 1000.0);
}

#[test]
fn ten_seconds_at_8_khz_lose_nothing() {
    long_run(10.0, 8000.0);
}
