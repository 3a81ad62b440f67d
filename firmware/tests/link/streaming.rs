//! Source (a): images served at their instants, byte for byte; credits, underruns, overruns.

use margemu_protocol::link::{DeviceState, ErrorCode, Message};

use crate::common::*;

/// Local time at which Start arrives.
const S: u64 = 5 * MS;

#[test]
fn images_are_served_at_their_instants_byte_for_byte_within_credits() {
    let (mut dev, mut host) = configured();
    let total = 1000u64;
    let mut sent = 0u64;
    let mut limit = CAP as u64;
    let send_up_to = |dev: &mut Dev, host: &mut Host, sent: u64, limit: u64, now: u64| {
        let n = (limit - sent).min(total - sent);
        host.images(dev, sent, &images(sent, n as usize), now);
        sent + n
    };
    sent = send_up_to(&mut dev, &mut host, sent, limit, 0);
    host.start(&mut dev, 0, S);
    let mut credit_frames = 0;
    let mut reported = Vec::new();
    for k in 0..total {
        let instant = S + k * MS;
        // Just before the instant the previous sample is still there.
        let mut out = poll(&mut dev, instant - 1);
        if k > 0 {
            assert_eq!(burst_sensors(&mut dev), image(k - 1)[..14]);
        }
        out.extend(poll(&mut dev, instant));
        let last = dev.last_served().unwrap();
        assert_eq!((last.index, last.time_ns), (k, k * MS));
        assert_eq!(last.image, Some(image(k)));
        assert!(!last.underrun);
        assert_eq!(burst_sensors(&mut dev), image(k)[..14], "sample {k}");
        reported.extend(served(&out));
        for c in credits(&out) {
            assert!(c.limit >= limit, "credit windows never shrink");
            limit = c.limit;
            credit_frames += 1;
        }
        assert!(sent <= limit);
        sent = send_up_to(&mut dev, &mut host, sent, limit, instant + 1);
    }
    host.send(&mut dev, &Message::Stop, S + total * MS);
    reported.extend(served(&poll(&mut dev, S + total * MS)));
    let expected: Vec<_> = (0..total)
        .map(|k| (k, served_entry(&image(k), false)))
        .collect();
    assert_eq!(
        reported, expected,
        "Served reports every instant, byte for byte"
    );
    let c = dev.counters();
    assert_eq!((c.served, c.underruns, c.overruns), (total, 0, 0));
    assert_eq!(c.rx.crc_errors + c.rx.framing_errors + c.rx.lost_frames, 0);
    // A credit per quarter buffer (16 samples) plus one per telemetry (every 100 ms).
    assert!((62..=80).contains(&credit_frames), "{credit_frames}");
}

#[test]
fn a_burst_read_in_progress_completes_with_the_old_sample() {
    let (mut dev, mut host) = configured();
    host.images(&mut dev, 0, &images(0, 2), 0);
    host.start(&mut dev, 0, 0);
    poll(&mut dev, 0);
    let chip = dev.chip_mut();
    use margemu_firmware::chip::SpiTarget;
    chip.select();
    let mut got = vec![chip.exchange(0x80 | 0x3B)];
    for _ in 0..6 {
        got.push(chip.exchange(0));
    }
    poll(&mut dev, MS); // sample 1 arrives mid-burst
    let chip = dev.chip_mut();
    for _ in 0..7 {
        got.push(chip.exchange(0));
    }
    chip.deselect();
    assert_eq!(got, image(0)[..14]);
    assert_eq!(burst_sensors(&mut dev), image(1)[..14]);
}

#[test]
fn underrun_holds_the_last_sample_and_is_counted() {
    let (mut dev, mut host) = configured();
    host.images(&mut dev, 0, &images(0, 3), 0);
    host.start(&mut dev, 0, 0);
    poll(&mut dev, 5 * MS); // instants 0..=5: 3 served, 3 missing
    assert_eq!(burst_sensors(&mut dev), image(2)[..14]);
    let s = dev.last_served().unwrap();
    assert_eq!((s.index, s.underrun, s.image), (5, true, Some(image(2))));
    assert_eq!((dev.counters().served, dev.counters().underruns), (6, 3));
    // A batch after a gap is kept; its hole becomes underruns; late samples are ignored.
    host.images(&mut dev, 8, &images(8, 4), 5 * MS);
    host.images(&mut dev, 3, &images(3, 2), 5 * MS);
    poll(&mut dev, 9 * MS);
    assert_eq!(burst_sensors(&mut dev), image(9)[..14]);
    assert_eq!((dev.counters().served, dev.counters().underruns), (10, 5));
    // Stop is graceful: samples 10 and 11 are still buffered, so they are served at their
    // instants, and the device stops at instant 12 without counting an underrun for it.
    host.send(&mut dev, &Message::Stop, 9 * MS);
    let out = poll(&mut dev, 20 * MS);
    let flags = underrun_flags(&out);
    let held = served(&out)[7].1;
    assert_eq!(held, served_entry(&image(2), true));
    assert_eq!(
        flags,
        (0..12)
            .map(|k| (k, (3..8).contains(&k)))
            .collect::<Vec<_>>()
    );
    assert_eq!((dev.counters().served, dev.counters().underruns), (12, 5));
    let t = telemetry(&out).unwrap();
    assert_eq!(t.state, DeviceState::Stopped);
    assert_eq!((t.samples_served, t.underruns, t.overruns), (12, 5, 0));
    assert_eq!((t.last_served_index, t.last_served_time_ns), (11, 11 * MS));
    assert_eq!(
        (t.buffer_level, t.next_index, t.credit_limit),
        (0, 12, 12 + CAP as u64)
    );
    assert_eq!(
        t.time_ns,
        12 * MS,
        "stopped at the first instant with nothing to serve"
    );
    assert_eq!(dev.counters().served, 12, "stopped: nothing more served");
}

#[test]
fn the_scene_end_stops_the_device_at_its_instant_however_late_stop_comes() {
    let (mut dev, mut host) = configured();
    // More images than the scene holds: the device still stops at the scene's end.
    host.images(&mut dev, 0, &images(0, 8), 0);
    host.start_scene(&mut dev, 5, 0);
    let out = poll(&mut dev, 20 * MS); // no Stop: the host's Stop is late
    let flags = underrun_flags(&out);
    assert_eq!(flags, (0..5).map(|k| (k, false)).collect::<Vec<_>>());
    let t = telemetry(&out).expect("a Telemetry when the device stops");
    assert_eq!(t.state, DeviceState::Stopped);
    assert_eq!((t.samples_served, t.underruns), (5, 0));
    assert_eq!((t.last_served_index, t.time_ns), (4, 5 * MS));
    assert_eq!(
        burst_sensors(&mut dev),
        image(4)[..14],
        "holds the last sample"
    );
    // The late Stop only confirms it.
    host.send(&mut dev, &Message::Stop, 30 * MS);
    let out = poll(&mut dev, 30 * MS);
    assert!(served(&out).is_empty());
    let t = telemetry(&out).unwrap();
    assert_eq!(
        (t.state, t.samples_served, t.underruns),
        (DeviceState::Stopped, 5, 0)
    );
}

#[test]
fn a_missing_last_sample_is_an_underrun_and_the_scene_still_ends() {
    let (mut dev, mut host) = configured();
    host.images(&mut dev, 0, &images(0, 4), 0);
    host.start_scene(&mut dev, 5, 0);
    let out = poll(&mut dev, 20 * MS);
    let flags = underrun_flags(&out);
    assert_eq!(flags, (0..5).map(|k| (k, k == 4)).collect::<Vec<_>>());
    let t = telemetry(&out).unwrap();
    assert_eq!(
        (t.state, t.samples_served, t.underruns),
        (DeviceState::Stopped, 5, 1)
    );
}

#[test]
fn overrun_is_counted_and_answered() {
    let (mut dev, mut host) = configured();
    host.images(&mut dev, 0, &images(0, CAP + 6), 0);
    let out = poll(&mut dev, 0);
    let errors: Vec<_> = out
        .iter()
        .filter_map(|o| match o {
            Out::Error(e) => Some((e.code, e.detail)),
            _ => None,
        })
        .collect();
    assert_eq!(errors, vec![(ErrorCode::CreditExceeded, CAP as u32)]);
    assert_eq!((dev.counters().overruns, dev.buffer_level()), (6, CAP));
    host.start(&mut dev, 0, 0);
    poll(&mut dev, (CAP as u64 + 5) * MS);
    let c = dev.counters();
    assert_eq!((c.served, c.underruns), (CAP as u64 + 6, 6));
}

#[test]
fn start_time_picks_the_first_instant_and_rational_rates_are_exact() {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    let rate = margemu_protocol::link::Rate::new(1000, 3).unwrap();
    host.configure(
        &mut dev,
        margemu_protocol::link::Configure::new(ChipModel::Mpu9250, rate),
    );
    host.images(&mut dev, 0, &images(0, 20), 0);
    host.start(&mut dev, 4_000_000, 0); // first instant ≥ 4 ms: k = 2 at 6 ms
    poll(&mut dev, 1_999_999);
    assert_eq!(dev.counters().served, 0);
    poll(&mut dev, 2_000_000);
    let s = dev.last_served().unwrap();
    assert_eq!(
        (s.index, s.time_ns, s.image),
        (2, 6_000_000, Some(image(2)))
    );
    poll(&mut dev, 5_000_000); // scene 9 ms: k = 3
    assert_eq!(dev.last_served().unwrap().index, 3);
    assert_eq!(dev.counters().underruns, 0);
}
