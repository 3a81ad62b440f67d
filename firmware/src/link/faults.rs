//! The fault schedule at serving time (`docs/spec/link.md` §5.16): when each output sample is
//! latched under the timing faults, which data-ready pulses are left out, and the chip faults'
//! window edges. [`Device`](super::Device) runs it; a host predicting the served instants runs
//! the same [`FaultClock`].
//!
//! **Timing** (device 0's faults: a rig's devices share one serving clock and are latched
//! together, so the device refuses clock_offset, late and drdy_jitter on another device).
//! Output sample `k`, of nominal instant `t_k`, is latched at
//! `t_k − lead + delay + jitter`, where, for the faults whose window holds `t_k`:
//! - clock_offset: the chip's clock reads `lead` ahead of scene time,
//!   [`clock_lead_ns`]`(ppm, drift, t_k − start)` (`ppm > 0`: a fast clock, samples early);
//!   after the window the clock is nominal again and the accumulated lead is dropped;
//! - late: `delay = delay_ns`;
//! - drdy_jitter: `jitter = ⌊u·max_ns⌋`, `u` uniform in `[0, 1)`, one draw of the fault's
//!   stream per sample in its window (data and data-ready move together);
//!
//! and never before the sample before it (a shift that would reorder two samples latches the
//! later right after the earlier, at the same instant). Without a timing fault the latch is
//! `t_k`, exactly.
//!
//! **Missing data-ready.** For each device with a missing_drdy window holding `t_k`, one draw
//! per sample: below `probability`, that sample's data-ready pulse is left out — the data are
//! latched, and the device's INT pin keeps, until the next latch, the level it had just
//! before ([`FaultClock::int_pin`]).
//!
//! **Random streams** are each fault's own (`ScheduledFault::rng`), started at its window's
//! first sample, so they match the host's draw for draw.

use margemu_model::fault::{FaultClass, FaultKind, MAX_FAULTS, UNTIL_END};
use margemu_model::rng::{unit_f64, StreamRng};
use margemu_protocol::link::MAX_DEVICES;

use crate::fault::FaultSchedule;

/// How far ahead of scene time a chip's clock reads `elapsed_ns` after a clock_offset window
/// began, ns: `(ppm·e + drift·e²/2)·10⁻⁶·10⁹` with `e = elapsed_ns·10⁻⁹` s.
pub fn clock_lead_ns(ppm: f32, drift_ppm_per_s: f32, elapsed_ns: u64) -> f64 {
    let e = elapsed_ns as f64 * 1e-9;
    (f64::from(ppm) * e + f64::from(drift_ppm_per_s) * e * e / 2.0) * 1e3
}

/// Streams held at once: one jitter window and one missing-data-ready window per device.
const STREAMS: usize = MAX_DEVICES + 1;

/// The serving clock under a fault schedule (see the module docs).
#[derive(Clone, Debug, Default)]
pub struct FaultClock {
    /// The sample whose latch was computed last, and that latch.
    pending: Option<(u64, u64)>,
    /// The latch of the last sample served.
    last_latch: Option<u64>,
    /// The drawing faults whose window is open: schedule position and stream.
    streams: heapless::Vec<(u8, StreamRng), STREAMS>,
    /// Per device: the INT level held while its pulse is left out.
    held_int: [Option<bool>; MAX_DEVICES],
}

impl FaultClock {
    /// Nothing served yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// The latch instant of output sample `k` of nominal instant `t_ns` (computed once per
    /// sample, in order: later calls for the same `k` return the same, drawing nothing).
    pub fn latch_ns(&mut self, schedule: &FaultSchedule, k: u64, t_ns: u64) -> u64 {
        if let Some((pk, latch)) = self.pending {
            if pk == k {
                return latch;
            }
        }
        let mut at = i128::from(t_ns);
        for (pos, e) in schedule.iter().enumerate() {
            let f = &e.fault;
            if f.device != 0 || !f.kind.moves_latch() {
                continue;
            }
            if !f.window.contains(t_ns) {
                self.close(pos);
                continue;
            }
            match f.kind {
                FaultKind::ClockOffset {
                    ppm,
                    drift_ppm_per_s,
                } => {
                    let lead = clock_lead_ns(ppm, drift_ppm_per_s, t_ns - f.window.start_ns);
                    // Rounded to the nearest ns (half away from zero; `as` saturates).
                    let half = if lead < 0.0 { -0.5 } else { 0.5 };
                    at -= (lead + half) as i128;
                }
                FaultKind::Late { delay_ns } => at += i128::from(delay_ns),
                FaultKind::DrdyJitter { max_ns } => {
                    if let Some(rng) = self.stream(pos, e) {
                        at += (unit_f64(rng) * f64::from(max_ns)) as i128;
                    }
                }
                _ => {}
            }
        }
        let floor = self.last_latch.map_or(0, i128::from);
        let latch = u64::try_from(at.max(floor)).unwrap_or(u64::MAX);
        self.pending = Some((k, latch));
        latch
    }

    /// The latch of a sample at `t_ns` that no fault window holds: `t_ns`, not before the last
    /// latch.
    pub fn idle_latch_ns(&self, t_ns: u64) -> u64 {
        self.last_latch.map_or(t_ns, |l| l.max(t_ns))
    }

    /// Records a latch at `latch_ns` with no fault window open (no pulse left out), in place of
    /// [`FaultClock::latch`].
    pub fn idle_latch(&mut self, latch_ns: u64) {
        self.last_latch = Some(latch_ns);
        self.pending = None;
        self.held_int = [None; MAX_DEVICES];
    }

    /// Draws, for each device, whether sample `k`'s data-ready pulse is left out; call once per
    /// sample served, with each device's INT level just before the latch (`int_before`), before
    /// latching. Records the latch as the last one.
    pub fn latch(
        &mut self,
        schedule: &FaultSchedule,
        latch_ns: u64,
        t_ns: u64,
        int_before: impl Fn(usize) -> Option<bool>,
    ) {
        self.last_latch = Some(latch_ns);
        self.pending = None;
        self.held_int = [None; MAX_DEVICES];
        for (pos, e) in schedule.iter().enumerate() {
            let FaultKind::MissingDrdy { probability } = e.fault.kind else {
                continue;
            };
            if !e.fault.window.contains(t_ns) {
                self.close(pos);
                continue;
            }
            let device = usize::from(e.fault.device);
            let missing = self
                .stream(pos, e)
                .is_some_and(|rng| unit_f64(rng) < f64::from(probability));
            if missing {
                if let Some(slot) = self.held_int.get_mut(device) {
                    *slot = int_before(device);
                }
            }
        }
    }

    /// Device `device`'s INT level: `Some` held level while its pulse is left out, `None`
    /// when the chip's own level stands.
    pub fn int_pin(&self, device: usize) -> Option<bool> {
        self.held_int.get(device).copied().flatten()
    }

    /// The stream of the fault at schedule position `pos`, started at its window's first draw.
    fn stream(&mut self, pos: usize, e: &crate::fault::ScheduledFault) -> Option<&mut StreamRng> {
        let pos = u8::try_from(pos).ok()?;
        let i = match self.streams.iter().position(|(p, _)| *p == pos) {
            Some(i) => i,
            None => {
                self.streams.push((pos, e.rng())).ok()?;
                self.streams.len() - 1
            }
        };
        self.streams.get_mut(i).map(|(_, rng)| rng)
    }

    /// Forgets the stream of a closed window.
    fn close(&mut self, pos: usize) {
        if let Some(i) = self
            .streams
            .iter()
            .position(|(p, _)| usize::from(*p) == pos)
        {
            self.streams.swap_remove(i);
        }
    }
}

/// The chip faults' window edges (reset at its start; wrong identity and FIFO overflow from
/// start to end), fired at the first latch at or after each edge (a window until the end has
/// no end edge).
#[derive(Clone, Debug, Default)]
pub struct ChipEdges {
    /// Per schedule position: 0 before the window, 1 inside, 2 after.
    phase: [u8; MAX_FAULTS],
}

/// A chip hook to call: device, what, and whether it starts (`true`) or ends.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChipEdge {
    /// The device's index in the rig.
    pub device: u8,
    /// The chip fault.
    pub kind: FaultKind,
    /// Its window begins (else ends).
    pub begins: bool,
}

impl ChipEdges {
    /// No edge fired.
    pub fn new() -> Self {
        Self::default()
    }

    /// Calls `fire` for each chip-fault edge at or before `now_ns` not fired yet, in schedule
    /// order (a window wholly before `now_ns` fires its start, then its end).
    pub fn fire_due(
        &mut self,
        schedule: &FaultSchedule,
        now_ns: u64,
        mut fire: impl FnMut(ChipEdge),
    ) {
        for (e, phase) in schedule.iter().zip(self.phase.iter_mut()) {
            let f = &e.fault;
            if f.kind.class() != FaultClass::Chip {
                continue;
            }
            let edge = |begins| ChipEdge {
                device: f.device,
                kind: f.kind,
                begins,
            };
            if *phase == 0 && f.window.start_ns <= now_ns {
                *phase = 1;
                fire(edge(true));
            }
            if *phase == 1 && f.window.end_ns != UNTIL_END && f.window.end_ns <= now_ns {
                *phase = 2;
                fire(edge(false));
            }
        }
    }
}
