//! The streaming core on a virtual clock: a [`Session`] run on a [`VirtualPort`] (the real
//! firmware link handler, `margemu_firmware::link::Device`, driven by virtual time, with
//! injected faults), so every time it waits for and logs is exact and the same on any machine
//! under any load. Pacing lateness, the credit window, resend after a lost batch, underruns and
//! the credit timeout at a stall, and the end of a scene, each asserted to the nanosecond or the
//! item. The end-to-end runs over real PTYs are `stream_pty.rs` and its neighbours.

mod common;

use common::{assert_logs_valid, config, read_csv, scene, scratch, served};
use margemu::stream::clock::{Clock, VirtualClock};
use margemu::stream::virtual_port::Trace;
use margemu::stream::{Session, SourceMode, StreamConfig, StreamError, Summary, VirtualPort};
use margemu_protocol::link::{DeviceState, Rate};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Duration;

const MS: u64 = 1_000_000;
/// The device polls its link every millisecond of virtual time.
const TICK: u64 = MS;
/// A small buffer, so the lead is capped (3/8 of it: 96 ms at 1 kHz) and the credit window is
/// close behind the pacing.
const BUFFER: usize = 256;
const LEAD: u64 = 96 * MS;
const BATCH: u64 = 32;
const SAMPLES: u64 = 1000;
const RATE: Rate = match Rate::new(1000, 1) {
    Some(r) => r,
    None => panic!(),
};

type Device = VirtualPort<BUFFER>;

/// How one run went: its outcome, what went over the link, the clock at the end, its logs.
struct Outcome {
    result: Result<Summary, StreamError>,
    trace: Trace,
    end_ns: u64,
    dir: PathBuf,
}

impl Outcome {
    fn summary(&self) -> &Summary {
        self.result.as_ref().unwrap()
    }

    fn start(&self) -> u64 {
        self.trace.start_ns.expect("Start written")
    }

    /// When the batch starting at item `j` is due.
    fn due(&self, j: u64) -> u64 {
        (self.start() + RATE.sample_time_ns(j)).saturating_sub(LEAD)
    }

    /// The batches written after Start, first copies only.
    fn paced(&self) -> Vec<margemu::stream::virtual_port::BatchWrite> {
        let mut high = 0;
        let mut out = Vec::new();
        for b in &self.trace.batches {
            if b.first >= high && b.at_ns > self.start() {
                out.push(*b);
            }
            high = high.max(b.first + b.len);
        }
        out
    }
}

/// Runs a 1 s, 1 kHz scene with `config` on `device` (on `clock`).
fn run(name: &str, clock: VirtualClock, device: Device, config: StreamConfig) -> Outcome {
    let dir = scratch(&format!("core-{name}"));
    let trace = device.trace();
    let session = Session::new(&scene(1.0, 1000.0), config, &dir).unwrap();
    let result = session.run_with(device, |_| {});
    let end_ns = clock.now_ns();
    let trace = take(&trace);
    Outcome {
        result,
        trace,
        end_ns,
        dir,
    }
}

fn take(trace: &Arc<Mutex<Trace>>) -> Trace {
    trace.lock().unwrap().clone()
}

fn virtual_config() -> StreamConfig {
    StreamConfig {
        port: "virtual".into(),
        ..config()
    }
}

fn device(clock: &VirtualClock) -> Device {
    VirtualPort::new(clock.clone(), TICK)
}

/// `sent.csv`: (index, send_ns, late_ns, resend) of every row.
fn sent(dir: &Path) -> Vec<(u64, u64, Option<i64>, bool)> {
    let (_, rows) = read_csv(dir, "sent.csv");
    rows.iter()
        .map(|r| {
            let late = (!r[3].is_empty()).then(|| r[3].parse().unwrap());
            (
                r[0].parse().unwrap(),
                r[2].parse().unwrap(),
                late,
                r[5] == "1",
            )
        })
        .collect()
}

/// `events.csv` rows of `event`: (host_ns, detail).
fn events(dir: &Path, event: &str) -> Vec<(u64, String)> {
    let (_, rows) = read_csv(dir, "events.csv");
    rows.iter()
        .filter(|r| r[1] == event)
        .map(|r| (r[0].parse().unwrap(), r[2].clone()))
        .collect()
}

#[test]
fn batches_polled_at_their_wake_times_are_exactly_on_time() {
    let clock = VirtualClock::new();
    let out = run("on-time", clock.clone(), device(&clock), virtual_config());
    let s = out.summary();
    assert_eq!((s.batch, s.lead), (BATCH, Duration::from_nanos(LEAD)));
    // Prefill: items due by the lead (0..=96), in whole batches: 0..128. Then 1000 − 128 items
    // in 28 paced batches, each written exactly at start + t_j − lead.
    let paced = out.paced();
    assert_eq!(paced.len(), 28);
    for b in &paced {
        assert_eq!(b.at_ns, out.due(b.first), "{b:?}");
    }
    assert_eq!(
        (s.jitter.batches, s.jitter.max_ns, s.written_jitter.max_ns),
        (28, 0, 0)
    );
    let rows = sent(&out.dir);
    assert_eq!(rows.len(), 1000);
    assert!(rows[..128].iter().all(|r| r.2.is_none()), "prefill");
    assert!(rows[128..].iter().all(|r| r.2 == Some(0)));
}

#[test]
fn a_late_wake_makes_its_batch_late_by_exactly_the_delay() {
    const DELAY: u64 = 3_456_789;
    let clock = VirtualClock::new();
    let device = device(&clock).oversleep(500 * MS, DELAY);
    // No busy-wait: the wake itself is the write instant.
    let config = StreamConfig {
        spin: Duration::ZERO,
        ..virtual_config()
    };
    let out = run("late", clock.clone(), device, config);
    let s = out.summary();
    let late: Vec<_> = out
        .paced()
        .iter()
        .map(|b| (b.first, b.at_ns - out.due(b.first)))
        .filter(|&(_, late)| late != 0)
        .collect();
    assert_eq!(late.len(), 1, "{late:?}");
    let (first, late_ns) = late[0];
    assert_eq!(late_ns, DELAY);
    assert!(out.due(first) >= 500 * MS);
    assert_eq!(
        (s.jitter.max_ns, s.written_jitter.max_ns),
        (DELAY as i64, DELAY as i64)
    );
    for (index, _, late, _) in sent(&out.dir) {
        let in_batch = (first..first + BATCH).contains(&index);
        if index >= 128 {
            assert_eq!(
                late,
                Some(if in_batch { DELAY as i64 } else { 0 }),
                "{index}"
            );
        }
    }
    assert_eq!(s.served.byte_exact, SAMPLES, "{:?}", s.served);
}

#[test]
fn credit_withheld_stalls_the_pacing_at_the_window_and_the_device_underruns() {
    // The device's Credit and Telemetry frames do not arrive from 100 ms to 400 ms.
    let (from, until) = (100 * MS, 400 * MS);
    let clock = VirtualClock::new();
    let device = device(&clock).withhold_credit(from, until);
    let out = run("stall", clock.clone(), device, virtual_config());
    let s = out.summary();
    assert!(out.trace.withheld > 0);
    // Never beyond the window the host had been granted.
    assert_eq!(out.trace.beyond_credit(), vec![]);
    assert_eq!(out.trace.counters.overruns, 0);
    // The host wrote up to the credit it had when the grants stopped, then waited.
    let during: Vec<_> = out
        .trace
        .batches
        .iter()
        .filter(|b| b.at_ns >= from && b.at_ns < until)
        .collect();
    let stalled_at = during.iter().map(|b| b.first + b.len).max().unwrap();
    assert_eq!(stalled_at, during.last().unwrap().granted);
    assert_eq!(s.credit_stalls, 1);
    // The batch held back went out when credit came back, late by exactly the wait.
    let resumed = out
        .trace
        .batches
        .iter()
        .find(|b| b.first == stalled_at)
        .unwrap();
    assert!(resumed.at_ns >= until);
    let rows = sent(&out.dir);
    let late = rows[stalled_at as usize].2.unwrap();
    assert_eq!(late as u64, resumed.at_ns - out.due(stalled_at));
    assert_eq!(
        s.jitter.batches,
        28 - 1,
        "the held-back batch is not a pacing figure"
    );
    // Every sample whose first copy reached the device at or after its instant (the device
    // serves at its ticks before the host writes at the same instant; the prefill went before
    // Start) was an underrun; every other was served byte for byte.
    let missed: Vec<u64> = rows
        .iter()
        .filter(|r| !r.3 && r.2.is_some() && r.1 >= out.start() + RATE.sample_time_ns(r.0))
        .map(|r| r.0)
        .collect();
    assert!(!missed.is_empty());
    assert_eq!(s.served.underruns, missed.len() as u64, "{:?}", s.served);
    assert_eq!(s.served.byte_exact, SAMPLES - missed.len() as u64);
    assert_eq!((s.served.mismatched, s.served.unreported), (0, 0));
    let flagged: Vec<u64> = served(&out.dir, SAMPLES)
        .into_iter()
        .filter(|r| r.1)
        .map(|r| r.0)
        .collect();
    assert_eq!(flagged, missed);
}

#[test]
fn a_device_that_stops_granting_credit_times_out_at_the_exact_instant() {
    let clock = VirtualClock::new();
    let device = device(&clock).withhold_credit(100 * MS, u64::MAX);
    let out = run("timeout", clock.clone(), device, virtual_config());
    let written = out
        .trace
        .batches
        .iter()
        .map(|b| b.first + b.len)
        .max()
        .unwrap();
    assert_eq!(written, out.trace.batches.last().unwrap().granted);
    let timeout = Duration::from_secs(2);
    match &out.result {
        Err(StreamError::CreditTimeout { index, timeout: t }) => {
            assert_eq!((*index, *t), (written, timeout))
        }
        other => panic!("{other:?}"),
    }
    // The stall began when the batch at the window's edge fell due; the session gave up exactly
    // the credit timeout later.
    let gave_up = out.due(written) + timeout.as_nanos() as u64;
    assert_eq!(out.end_ns, gave_up);
    let ends = events(&out.dir, "end");
    assert_eq!(ends.len(), 1);
    assert_eq!(ends[0].0, gave_up);
    assert!(ends[0]
        .1
        .contains(&format!("no credit for sample {written}")));
    // The device ran dry at the window's edge: every later instant it reported is an underrun.
    let rows = served(&out.dir, SAMPLES);
    assert!(rows.iter().any(|r| r.0 >= written));
    for (k, underrun, matched) in rows {
        assert_eq!((underrun, matched), (k >= written, k < written), "{k}");
    }
    assert_logs_valid(&out.dir);
}

#[test]
fn a_lost_batch_is_resent_after_the_resend_timeout_and_then_served_byte_for_byte() {
    const LOST: u64 = 320;
    let clock = VirtualClock::new();
    let device = device(&clock).drop_batch(LOST);
    let out = run("resend", clock.clone(), device, virtual_config());
    let s = out.summary();
    let copies: Vec<_> = out
        .trace
        .batches
        .iter()
        .filter(|b| b.first == LOST)
        .collect();
    assert_eq!(copies.len(), 2, "{copies:?}");
    assert!(!copies[0].delivered && copies[1].delivered);
    let after = copies[1].at_ns - copies[0].at_ns;
    assert!(after >= 20 * MS, "resent {after} ns after the loss");
    // Go-back-N: from the hole to where the host had got to, once.
    let high = out
        .trace
        .batches
        .iter()
        .filter(|b| b.at_ns < copies[1].at_ns)
        .map(|b| b.first + b.len)
        .max()
        .unwrap();
    assert_eq!((s.resends, s.resent), (1, high - LOST));
    let resent: Vec<_> = sent(&out.dir).into_iter().filter(|r| r.3).collect();
    assert_eq!(resent.len() as u64, high - LOST);
    assert!(resent
        .iter()
        .all(|r| r.1 == copies[1].at_ns && r.2.is_none()));
    assert_eq!(events(&out.dir, "resend").len(), 1);
    let v = s.served;
    assert_eq!(
        (v.byte_exact, v.underruns, v.mismatched, v.unreported),
        (SAMPLES, 0, 0, 0),
        "{v:?}"
    );
}

#[test]
fn the_scene_ends_with_stop_after_the_last_item_and_exact_counts() {
    let clock = VirtualClock::new();
    let out = run("end", clock.clone(), device(&clock), virtual_config());
    let s = out.summary();
    let last_write = out.trace.batches.last().unwrap();
    assert_eq!(last_write.first + last_write.len, SAMPLES);
    // Stop half a period after the last sample's instant (999.5 ms), after the last batch.
    let stop = out.trace.stop_ns.unwrap();
    assert_eq!(stop, out.start() + 999 * MS + MS / 2);
    assert!(stop > last_write.at_ns);
    assert_eq!(
        (s.samples, s.sent, s.stream_len, s.resends, s.resent),
        (SAMPLES, SAMPLES, SAMPLES, 0, 0)
    );
    assert_eq!(s.credit_stalls, 0);
    assert_eq!(s.link.batch_frames, SAMPLES.div_ceil(BATCH));
    assert_eq!(s.link.item_bytes, SAMPLES * 22);
    let v = s.served;
    assert_eq!(
        (
            v.reported,
            v.byte_exact,
            v.underruns,
            v.unreported,
            v.after_end
        ),
        (SAMPLES, SAMPLES, 0, 0, 0),
        "{v:?}"
    );
    assert_eq!(v.last_index, Some(SAMPLES - 1));
    assert_eq!(out.trace.counters.served, SAMPLES);
    assert_eq!(out.trace.counters.underruns, 0);
    assert_eq!(out.trace.state, Some(DeviceState::Stopped));
    assert_eq!(s.start_host_ns, Some(out.start() as i64));
    assert_eq!(s.elapsed, Duration::from_nanos(out.end_ns - out.start()));
    let stopped = events(&out.dir, "stopped");
    assert_eq!(stopped.len(), 1);
    assert!(stopped[0]
        .1
        .starts_with("served 1000 samples; last index 999; underruns 0"));
    assert_eq!(events(&out.dir, "end")[0].1, "completed");
    assert_logs_valid(&out.dir);
}

#[test]
fn in_source_model_stop_waits_for_the_device_to_report_the_last_sample() {
    let clock = VirtualClock::new();
    let config = StreamConfig {
        source: SourceMode::Model {
            kinematics_hz: None,
        },
        ..virtual_config()
    };
    // Polled every 2 ms, the device serves the last instant (999 ms after Start, which went out
    // at a tick) at the next tick, after Stop's half period.
    let device = VirtualPort::new(clock.clone(), 2 * MS);
    let out = run("model", clock.clone(), device, config);
    let s = out.summary();
    // 500 kinematics samples (hold 2) in batches of 28, the lead capped at 96 of them (192 ms).
    assert_eq!((s.stream_len, s.sent, s.batch), (500, 500, 28));
    assert_eq!(s.lead, Duration::from_millis(192));
    assert_eq!(s.link.batch_frames, 500u64.div_ceil(28));
    let v = s.served;
    assert_eq!(
        (v.byte_exact, v.underruns, v.mismatched, v.unreported),
        (SAMPLES, 0, 0, 0),
        "{v:?}"
    );
    // The device stops at once on Stop, so Stop waits for the half period after the last
    // instant and then for the device's first report of the last sample served.
    let stop_at = out.start() + 999 * MS + MS / 2;
    let (_, served_rows) = read_csv(&out.dir, "served.csv");
    let in_served = served_rows.iter().filter(|r| r[1] == "999");
    let (_, device_rows) = read_csv(&out.dir, "device.csv");
    let in_telemetry = device_rows
        .iter()
        .filter(|r| r[2] != "0" && r[3].parse::<u64>().unwrap() >= 999);
    let reported = in_served
        .chain(in_telemetry)
        .map(|r| r[0].parse::<u64>().unwrap())
        .min()
        .unwrap();
    assert!(reported > stop_at, "reported at {reported}");
    assert_eq!(out.trace.stop_ns, Some(reported));
    assert_eq!(out.trace.state, Some(DeviceState::Stopped));
}

#[test]
fn the_stop_flag_sends_stop_at_once_and_the_device_confirms_it() {
    let clock = VirtualClock::new();
    let device = device(&clock);
    let trace = device.trace();
    let dir = scratch("core-interrupted");
    let session = Session::new(&scene(1.0, 1000.0), virtual_config(), &dir).unwrap();
    let stop = session.stop_flag();
    let mut set_at = None;
    let result = session.run_with(device, |p| {
        if p.elapsed >= Duration::from_millis(300) && set_at.is_none() {
            stop.store(true, std::sync::atomic::Ordering::Relaxed);
            set_at = Some(clock.now_ns());
        }
    });
    assert!(
        matches!(result, Err(StreamError::Interrupted)),
        "{result:?}"
    );
    let trace = take(&trace);
    // The flag is seen before the next wait, at the same instant.
    let set_at = set_at.unwrap();
    assert_eq!(trace.stop_ns, Some(set_at));
    assert!(trace.batches.iter().all(|b| b.at_ns <= set_at));
    assert_eq!(trace.state, Some(DeviceState::Stopped));
    assert_eq!(events(&dir, "stopped").len(), 1);
    let end = events(&dir, "end");
    assert!(end[0].1.starts_with("error: interrupted"), "{end:?}");
    let meta = std::fs::read_to_string(dir.join("meta.toml")).unwrap();
    assert!(meta.contains("status = \"interrupted\""), "{meta}");
    assert_logs_valid(&dir);
}

#[test]
fn the_same_session_on_the_virtual_clock_logs_the_same_bytes() {
    let runs: Vec<_> = ["again-1", "again-2"]
        .iter()
        .map(|name| {
            let clock = VirtualClock::new();
            let device = device(&clock).drop_batch(320).oversleep(600 * MS, 7 * MS);
            run(name, clock, device, virtual_config())
        })
        .collect();
    for file in [
        "sent.csv",
        "served.csv",
        "telemetry.csv",
        "device.csv",
        "events.csv",
    ] {
        let read = |o: &Outcome| std::fs::read(o.dir.join(file)).unwrap();
        assert!(read(&runs[0]) == read(&runs[1]), "{file} differs");
    }
}
