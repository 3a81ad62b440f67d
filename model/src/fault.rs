//! Scripted faults: the one definition of what a scene's `[[fault]]` schedule can do to a device,
//! shared by the host (scene files, `simulate`, the source-(a) images, the virtual buses, the
//! logs, `evaluate`) and the firmware (source (b), the chips, the bus targets, the serving clock).
//!
//! A [`Fault`] is one window `[start_ns, end_ns)` of scene time on one device (its index in the
//! rig) with a [`FaultKind`]. The kinds fall into four [`FaultClass`]es:
//!
//! - **sensor** faults change one sensor's output ([`SensorFaults`] applies them to the model's
//!   [`Sample`], before the chip's conversion, identically on the host and on the device);
//! - **chip** faults change the chip's register behaviour (a reset to power-on values at the
//!   window's start, a wrong identity, a forced FIFO overflow);
//! - **bus** faults change the bus transactions (NAK, corrupted bytes, clock stretching);
//! - **timing** faults change when samples and data-ready pulses appear.
//!
//! Sensor faults active at one instant compose in schedule order (the order of the scene's
//! `[[fault]]` tables), and the replacing kinds (stuck, stuck-at, dropout) act last, on the
//! result.
//! Two replacing faults on one sensor, and two faults of the same exclusive kind on one device,
//! must not overlap ([`overlaps_exclusively`]); the scene check refuses them.
//!
//! Units are those of the model's [`Sample`]: m/s², rad/s and the scene's field unit.
//!
//! **Random draws.** Each fault draws from its own stream, [`fault_rng`]`(seed, index)`, keyed by
//! the device's seed and the fault's index in the device's schedule; a fault's stream advances
//! only inside its window, so adding a fault never shifts the draws of the sensor model or of
//! another fault.
//!
//! ```
//! use margemu_model::fault::{Fault, FaultKind, Sensor, SensorFaults, Window};
//! use margemu_model::sensor::Sample;
//! let stuck = Fault::new(0, Window::new(1_000, 3_000), FaultKind::Stuck { sensor: Sensor::Gyr });
//! let mut faults = SensorFaults::new(7, 1000.0);
//! faults.push(&stuck).unwrap();
//! let mut s = Sample { acc: [0.0; 3], gyr: [0.5, 0.0, 0.0], mag: [0.0; 3] };
//! assert_eq!(faults.apply(0, &mut s), 0); // before the window: unchanged, remembered
//! let mut later = Sample { gyr: [2.0, 0.0, 0.0], ..s };
//! faults.apply(2_000, &mut later);
//! assert_eq!(later.gyr, [0.5, 0.0, 0.0]); // held at the last value before the window
//! ```

use crate::rng::{fnv1a64, standard_normal, unit_f64, StreamRng};
use crate::sensor::Sample;
use crate::vec3::Vec3;
use rand_chacha::ChaCha8Rng;
use rand_core::SeedableRng;

/// Most faults one schedule holds (a whole rig's on a device; one device's in [`SensorFaults`]).
pub const MAX_FAULTS: usize = 16;

/// The end of a window that lasts until the end of the run (`until_end`).
pub const UNTIL_END: u64 = u64::MAX;

/// One of a device's three sensors.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Sensor {
    /// Accelerometer.
    Acc = 0,
    /// Gyroscope.
    Gyr = 1,
    /// Magnetometer.
    Mag = 2,
}

impl Sensor {
    /// Every sensor, in code order.
    pub const ALL: [Sensor; 3] = [Sensor::Acc, Sensor::Gyr, Sensor::Mag];

    /// Its bit in an [`SensorFaults::apply`] dropout mask.
    pub const fn bit(self) -> u8 {
        1 << self as u8
    }

    /// Its name in scene files and logs (`accel`, `gyro`, `mag`).
    pub const fn name(self) -> &'static str {
        match self {
            Sensor::Acc => "accel",
            Sensor::Gyr => "gyro",
            Sensor::Mag => "mag",
        }
    }

    /// The sensor of a wire code.
    pub const fn from_code(code: u8) -> Option<Self> {
        match code {
            0 => Some(Sensor::Acc),
            1 => Some(Sensor::Gyr),
            2 => Some(Sensor::Mag),
            _ => None,
        }
    }

    fn of(self, s: &mut Sample) -> &mut Vec3 {
        match self {
            Sensor::Acc => &mut s.acc,
            Sensor::Gyr => &mut s.gyr,
            Sensor::Mag => &mut s.mag,
        }
    }
}

/// A window of scene time, `[start_ns, end_ns)`; `end_ns` = [`UNTIL_END`] lasts to the end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Window {
    /// First instant inside, ns.
    pub start_ns: u64,
    /// First instant after, ns.
    pub end_ns: u64,
}

impl Window {
    /// The window `[start_ns, end_ns)`.
    pub const fn new(start_ns: u64, end_ns: u64) -> Self {
        Self { start_ns, end_ns }
    }

    /// Whether `t_ns` is inside.
    #[inline]
    pub const fn contains(&self, t_ns: u64) -> bool {
        self.start_ns <= t_ns && t_ns < self.end_ns
    }

    /// Whether the two windows share an instant.
    pub const fn overlaps(&self, other: &Window) -> bool {
        self.start_ns < other.end_ns && other.start_ns < self.end_ns
    }
}

/// What a fault does. Parameters are in the model's units (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FaultKind {
    // ---- sensor ----
    /// The sensor's output holds the last value before the window.
    Stuck {
        /// Which sensor.
        sensor: Sensor,
    },
    /// The sensor's output is `value` throughout the window.
    StuckAt {
        /// Which sensor.
        sensor: Sensor,
        /// The value served.
        value: Vec3,
    },
    /// The sensor's registers hold the chip's own invalid value (e.g. −32768).
    Dropout {
        /// Which sensor.
        sensor: Sensor,
    },
    /// Spikes of `amplitude` on the axes in `axes` (bit 0 = x), at random samples with a mean
    /// rate of `rate_hz`, each of random sign.
    Spikes {
        /// Which sensor.
        sensor: Sensor,
        /// Mean spikes per second.
        rate_hz: f32,
        /// Height of a spike.
        amplitude: f32,
        /// Axes hit (bit 0 = x, 1 = y, 2 = z).
        axes: u8,
    },
    /// A bias added per axis.
    BiasStep {
        /// Which sensor.
        sensor: Sensor,
        /// The bias.
        bias: Vec3,
    },
    /// The output multiplied per axis.
    Scale {
        /// Which sensor.
        sensor: Sensor,
        /// The factor.
        factor: Vec3,
    },
    /// White noise of standard deviation `std` added per axis.
    Noise {
        /// Which sensor.
        sensor: Sensor,
        /// Standard deviation per axis.
        std: Vec3,
    },
    /// A strong field added to the magnetometer's input (the chip's conversion saturates).
    MagSaturation {
        /// The field added, scene unit.
        field: Vec3,
    },
    // ---- chip ----
    /// The chip resets itself to its power-on values at the window's start.
    Reset,
    /// The identity register reads `value` during the window.
    WrongIdentity {
        /// What WHO_AM_I (or CHIP_ID) returns.
        value: u8,
    },
    /// The FIFO overflows at the window's start (as if nobody had read it), and stays in
    /// overflow through the window.
    FifoOverflow,
    // ---- bus ----
    /// The chip does not acknowledge its I2C address (SPI: MISO reads 0xFF) in the window.
    Nak,
    /// Each byte the chip drives on MISO/SDA is corrupted (one random bit flipped) with
    /// probability `probability`.
    Corrupt {
        /// Probability per byte, `0 ..= 1`.
        probability: f32,
    },
    /// The chip stretches the I2C clock for `stretch_ns` before each byte it drives.
    ClockStretch {
        /// Stretch per byte, ns.
        stretch_ns: u32,
    },
    // ---- timing ----
    /// The chip's output clock runs `ppm` fast (negative: slow), drifting by `drift_ppm_per_s`.
    ClockOffset {
        /// Offset at the window's start, ppm.
        ppm: f32,
        /// Drift, ppm per second.
        drift_ppm_per_s: f32,
    },
    /// Each data-ready pulse is moved by a uniform random offset in `[0, max_ns]`.
    DrdyJitter {
        /// Largest delay, ns.
        max_ns: u32,
    },
    /// Each data-ready pulse is left out with probability `probability` (the data still update).
    MissingDrdy {
        /// Probability per pulse, `0 ..= 1`.
        probability: f32,
    },
    /// Each sample appears in the registers `delay_ns` after its instant.
    Late {
        /// Delay, ns.
        delay_ns: u32,
    },
}

/// Every kind's name, in [`FaultKind`]'s declaration order ([`FaultKind::code`]).
pub const KIND_NAMES: [&str; 18] = [
    "stuck",
    "stuck_at",
    "dropout",
    "spikes",
    "bias_step",
    "scale",
    "noise",
    "mag_saturation",
    "reset",
    "wrong_identity",
    "fifo_overflow",
    "nak",
    "corrupt",
    "clock_stretch",
    "clock_offset",
    "drdy_jitter",
    "missing_drdy",
    "late",
];

/// The four groups of [`FaultKind`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FaultClass {
    /// Changes one sensor's output.
    Sensor,
    /// Changes the chip's registers.
    Chip,
    /// Changes bus transactions.
    Bus,
    /// Changes sample and data-ready timing.
    Timing,
}

impl FaultKind {
    /// Its position in declaration order: its index in [`KIND_NAMES`] and its wire code on the
    /// link (`docs/spec/link.md` §5.16).
    pub const fn code(&self) -> u8 {
        match self {
            FaultKind::Stuck { .. } => 0,
            FaultKind::StuckAt { .. } => 1,
            FaultKind::Dropout { .. } => 2,
            FaultKind::Spikes { .. } => 3,
            FaultKind::BiasStep { .. } => 4,
            FaultKind::Scale { .. } => 5,
            FaultKind::Noise { .. } => 6,
            FaultKind::MagSaturation { .. } => 7,
            FaultKind::Reset => 8,
            FaultKind::WrongIdentity { .. } => 9,
            FaultKind::FifoOverflow => 10,
            FaultKind::Nak => 11,
            FaultKind::Corrupt { .. } => 12,
            FaultKind::ClockStretch { .. } => 13,
            FaultKind::ClockOffset { .. } => 14,
            FaultKind::DrdyJitter { .. } => 15,
            FaultKind::MissingDrdy { .. } => 16,
            FaultKind::Late { .. } => 17,
        }
    }

    /// Its name in scene files and `events.csv` ([`KIND_NAMES`]).
    pub const fn name(&self) -> &'static str {
        let code = self.code() as usize;
        if code < KIND_NAMES.len() {
            KIND_NAMES[code]
        } else {
            ""
        }
    }

    /// Its class.
    pub const fn class(&self) -> FaultClass {
        match self {
            FaultKind::Stuck { .. }
            | FaultKind::StuckAt { .. }
            | FaultKind::Dropout { .. }
            | FaultKind::Spikes { .. }
            | FaultKind::BiasStep { .. }
            | FaultKind::Scale { .. }
            | FaultKind::Noise { .. }
            | FaultKind::MagSaturation { .. } => FaultClass::Sensor,
            FaultKind::Reset | FaultKind::WrongIdentity { .. } | FaultKind::FifoOverflow => {
                FaultClass::Chip
            }
            FaultKind::Nak | FaultKind::Corrupt { .. } | FaultKind::ClockStretch { .. } => {
                FaultClass::Bus
            }
            FaultKind::ClockOffset { .. }
            | FaultKind::DrdyJitter { .. }
            | FaultKind::MissingDrdy { .. }
            | FaultKind::Late { .. } => FaultClass::Timing,
        }
    }

    /// The sensor a sensor fault acts on (the magnetometer for [`FaultKind::MagSaturation`]).
    pub const fn sensor(&self) -> Option<Sensor> {
        match *self {
            FaultKind::Stuck { sensor }
            | FaultKind::StuckAt { sensor, .. }
            | FaultKind::Dropout { sensor }
            | FaultKind::Spikes { sensor, .. }
            | FaultKind::BiasStep { sensor, .. }
            | FaultKind::Scale { sensor, .. }
            | FaultKind::Noise { sensor, .. } => Some(sensor),
            FaultKind::MagSaturation { .. } => Some(Sensor::Mag),
            _ => None,
        }
    }

    /// Whether it moves the instant a sample is latched (clock_offset, late, drdy_jitter). A
    /// rig's devices share one serving clock, so only device 0 may have these.
    pub const fn moves_latch(&self) -> bool {
        matches!(
            self,
            FaultKind::ClockOffset { .. } | FaultKind::Late { .. } | FaultKind::DrdyJitter { .. }
        )
    }

    /// Whether it replaces the sensor's value (stuck, stuck-at, dropout).
    pub const fn replaces_value(&self) -> bool {
        matches!(
            self,
            FaultKind::Stuck { .. } | FaultKind::StuckAt { .. } | FaultKind::Dropout { .. }
        )
    }

    /// The exclusive group: two faults of one device in the same group must not overlap.
    /// Replacing sensor faults group per sensor; every chip, bus and timing kind is its own
    /// group; the additive sensor faults (which compose) have none.
    fn exclusive_group(&self) -> Option<u8> {
        if self.replaces_value() {
            return self.sensor().map(|s| s as u8);
        }
        match self {
            FaultKind::MagSaturation { .. } => Some(3),
            FaultKind::Reset => Some(4),
            FaultKind::WrongIdentity { .. } => Some(5),
            FaultKind::FifoOverflow => Some(6),
            // A NAK and corrupted bytes at once would be two answers to one byte.
            FaultKind::Nak | FaultKind::Corrupt { .. } => Some(7),
            FaultKind::ClockStretch { .. } => Some(8),
            FaultKind::ClockOffset { .. } => Some(9),
            FaultKind::DrdyJitter { .. } => Some(10),
            FaultKind::MissingDrdy { .. } => Some(11),
            FaultKind::Late { .. } => Some(12),
            _ => None,
        }
    }
}

/// One scheduled fault.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fault {
    /// The device's index in the rig (0: `[chip]` or the first `[[device]]`).
    pub device: u8,
    /// When.
    pub window: Window,
    /// What.
    pub kind: FaultKind,
}

impl Fault {
    /// A fault of `kind` on device `device` during `window`.
    pub const fn new(device: u8, window: Window, kind: FaultKind) -> Self {
        Self {
            device,
            window,
            kind,
        }
    }
}

/// Whether `a` and `b` may not both be scheduled: same device, same exclusive group, windows
/// overlapping (see the module docs).
pub fn overlaps_exclusively(a: &Fault, b: &Fault) -> bool {
    a.device == b.device
        && a.window.overlaps(&b.window)
        && matches!((a.kind.exclusive_group(), b.kind.exclusive_group()), (Some(x), Some(y)) if x == y)
}

/// `None` if one of `windows` holds `t_ns`; else the first instant after `t_ns` at which one of
/// them starts ([`UNTIL_END`] if none does): until then none of them is active.
pub fn quiet_until<'a>(windows: impl IntoIterator<Item = &'a Window>, t_ns: u64) -> Option<u64> {
    let mut next = UNTIL_END;
    for w in windows {
        if w.contains(t_ns) {
            return None;
        }
        if w.start_ns > t_ns {
            next = next.min(w.start_ns);
        }
    }
    Some(next)
}

/// The random stream of fault `index` of a device whose seed is `seed` (see the module docs).
pub fn fault_rng(seed: u64, index: usize) -> StreamRng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(fnv1a64(b"fault").wrapping_add(index as u64));
    rng
}

/// The schedule is full ([`MAX_FAULTS`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ScheduleFull;

/// One device's sensor faults, applied sample by sample to the model's output.
///
/// Faults of other classes are accepted by [`SensorFaults::push`] (so a device can push its
/// whole schedule) and ignored here; each keeps its index, so the random streams do not depend
/// on which classes a caller pushes.
#[derive(Clone, Debug)]
pub struct SensorFaults {
    seed: u64,
    output_rate_hz: f64,
    /// Each fault, its stream, and (spikes) its probability per sample.
    faults: heapless::Vec<(Fault, StreamRng, f64), MAX_FAULTS>,
    /// The last output per sensor before a stuck window began (what the sensor holds).
    last: Sample,
    held: [Option<Vec3>; 3],
    /// No sensor fault is active in `[idle_from, idle_until)` (from the instant of the last full
    /// pass that found none active to the next window's start): [`SensorFaults::apply`] only
    /// records the sample there.
    idle_from: u64,
    idle_until: u64,
}

impl SensorFaults {
    /// No faults yet, for the device whose seed is `seed` and whose output rate is
    /// `output_rate_hz` (a spike fault's mean rate becomes a probability per sample,
    /// `rate_hz / output_rate_hz` clamped to `[0, 1]`).
    pub fn new(seed: u64, output_rate_hz: f64) -> Self {
        Self {
            seed,
            output_rate_hz,
            faults: heapless::Vec::new(),
            last: Sample {
                acc: [0.0; 3],
                gyr: [0.0; 3],
                mag: [0.0; 3],
            },
            held: [None; 3],
            idle_from: 0,
            idle_until: 0,
        }
    }

    /// Appends the next fault of the device's schedule.
    pub fn push(&mut self, fault: &Fault) -> Result<(), ScheduleFull> {
        let rng = fault_rng(self.seed, self.faults.len());
        let p_spike = match fault.kind {
            FaultKind::Spikes { rate_hz, .. } => {
                let p = f64::from(rate_hz) / self.output_rate_hz;
                if p.is_finite() {
                    p.clamp(0.0, 1.0)
                } else {
                    0.0
                }
            }
            _ => 0.0,
        };
        self.idle_until = 0;
        self.faults
            .push((*fault, rng, p_spike))
            .map_err(|_| ScheduleFull)
    }

    /// Whether any sensor fault is scheduled (a caller may skip [`SensorFaults::apply`]).
    pub fn is_empty(&self) -> bool {
        !self
            .faults
            .iter()
            .any(|(f, _, _)| f.kind.class() == FaultClass::Sensor)
    }

    /// Applies the faults active at `t_ns` to `sample` in place, and returns the dropout mask
    /// ([`Sensor::bit`]s whose registers must hold the chip's invalid value). Call it once per
    /// output sample, in time order.
    pub fn apply(&mut self, t_ns: u64, sample: &mut Sample) -> u8 {
        if self.idle_from <= t_ns && t_ns < self.idle_until {
            self.last = *sample;
            return 0;
        }
        let sensor_windows = self
            .faults
            .iter()
            .filter(|(f, _, _)| f.kind.class() == FaultClass::Sensor)
            .map(|(f, _, _)| &f.window);
        if let Some(next_start) = quiet_until(sensor_windows, t_ns) {
            (self.idle_from, self.idle_until) = (t_ns, next_start);
            self.held = [None; 3];
            self.last = *sample;
            return 0;
        }
        let mut dropout = 0u8;
        let mut replaced = [None::<Vec3>; 3];
        let mut stuck = [false; 3];
        for (fault, rng, p_spike) in self.faults.iter_mut() {
            if !fault.window.contains(t_ns) {
                continue;
            }
            match fault.kind {
                FaultKind::Scale { sensor, factor } => {
                    for (x, k) in sensor.of(sample).iter_mut().zip(factor) {
                        *x *= k;
                    }
                }
                FaultKind::BiasStep { sensor, bias } => {
                    for (x, b) in sensor.of(sample).iter_mut().zip(bias) {
                        *x += b;
                    }
                }
                FaultKind::Noise { sensor, std } => {
                    for (x, s) in sensor.of(sample).iter_mut().zip(std) {
                        *x += s * standard_normal(rng);
                    }
                }
                FaultKind::Spikes {
                    sensor,
                    amplitude,
                    axes,
                    ..
                } => {
                    // Two draws per sample in the window, spike or not.
                    let draw = unit_f64(rng);
                    let sign = unit_f64(rng);
                    if draw < *p_spike {
                        let a = if sign < 0.5 { -amplitude } else { amplitude };
                        let v = sensor.of(sample);
                        for (i, x) in v.iter_mut().enumerate() {
                            if axes & (1 << i) != 0 {
                                *x += a;
                            }
                        }
                    }
                }
                FaultKind::MagSaturation { field } => {
                    for (x, b) in sample.mag.iter_mut().zip(field) {
                        *x += b;
                    }
                }
                FaultKind::Stuck { sensor } => stuck[sensor as usize] = true,
                FaultKind::StuckAt { sensor, value } => replaced[sensor as usize] = Some(value),
                FaultKind::Dropout { sensor } => dropout |= sensor.bit(),
                _ => {}
            }
        }
        for sensor in Sensor::ALL {
            let i = sensor as usize;
            if stuck[i] {
                let held = *self.held[i].get_or_insert(*sensor.of(&mut self.last));
                *sensor.of(sample) = held;
            } else {
                self.held[i] = None;
                if let Some(v) = replaced[i] {
                    *sensor.of(sample) = v;
                }
            }
        }
        self.last = *sample;
        dropout
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(v: f32) -> Sample {
        Sample {
            acc: [v; 3],
            gyr: [v; 3],
            mag: [v; 3],
        }
    }

    #[test]
    fn outside_every_window_the_sample_is_untouched() {
        let mut f = SensorFaults::new(1, 1000.0);
        let kinds = [
            FaultKind::BiasStep {
                sensor: Sensor::Acc,
                bias: [1.0; 3],
            },
            FaultKind::Noise {
                sensor: Sensor::Gyr,
                std: [1.0; 3],
            },
            FaultKind::Dropout {
                sensor: Sensor::Mag,
            },
        ];
        for k in kinds {
            f.push(&Fault::new(0, Window::new(100, 200), k)).unwrap();
        }
        for t in [0, 99, 200, 1_000] {
            let mut s = sample(0.25);
            assert_eq!(f.apply(t, &mut s), 0);
            assert_eq!(s, sample(0.25));
        }
        let mut s = sample(0.25);
        assert_eq!(f.apply(150, &mut s), Sensor::Mag.bit());
        assert_eq!(s.acc, [1.25; 3]);
        assert_ne!(s.gyr, [0.25; 3]);
    }

    #[test]
    fn composition_order_is_scale_bias_then_replacement() {
        let mut f = SensorFaults::new(1, 1000.0);
        let w = Window::new(0, UNTIL_END);
        f.push(&Fault::new(
            0,
            w,
            FaultKind::BiasStep {
                sensor: Sensor::Gyr,
                bias: [1.0; 3],
            },
        ))
        .unwrap();
        f.push(&Fault::new(
            0,
            w,
            FaultKind::Scale {
                sensor: Sensor::Gyr,
                factor: [2.0; 3],
            },
        ))
        .unwrap();
        let mut s = sample(3.0);
        f.apply(0, &mut s);
        // In schedule order: bias first (pushed first), then scale.
        assert_eq!(s.gyr, [8.0; 3]);
        f.push(&Fault::new(
            0,
            w,
            FaultKind::StuckAt {
                sensor: Sensor::Gyr,
                value: [0.5; 3],
            },
        ))
        .unwrap();
        let mut s = sample(3.0);
        f.apply(1, &mut s);
        assert_eq!(s.gyr, [0.5; 3]);
    }

    #[test]
    fn stuck_holds_the_value_before_the_window_and_releases_after() {
        let mut f = SensorFaults::new(1, 1000.0);
        f.push(&Fault::new(
            0,
            Window::new(10, 20),
            FaultKind::Stuck {
                sensor: Sensor::Acc,
            },
        ))
        .unwrap();
        let mut s = sample(1.0);
        f.apply(5, &mut s);
        for t in [10, 15, 19] {
            let mut s = sample(t as f32);
            f.apply(t, &mut s);
            assert_eq!(s.acc, [1.0; 3]);
            assert_eq!(s.gyr, [t as f32; 3]);
        }
        let mut s = sample(9.0);
        f.apply(20, &mut s);
        assert_eq!(s.acc, [9.0; 3]);
    }

    #[test]
    fn spikes_at_the_rate_asked() {
        let mut f = SensorFaults::new(3, 1000.0);
        f.push(&Fault::new(
            0,
            Window::new(0, UNTIL_END),
            FaultKind::Spikes {
                sensor: Sensor::Gyr,
                rate_hz: 10.0,
                amplitude: 5.0,
                axes: 0b100,
            },
        ))
        .unwrap();
        let mut spikes = 0;
        for k in 0..100_000u64 {
            let mut s = sample(0.0);
            f.apply(k * 1_000_000, &mut s);
            assert_eq!((s.gyr[0], s.gyr[1]), (0.0, 0.0));
            if s.gyr[2] != 0.0 {
                assert_eq!(s.gyr[2].abs(), 5.0);
                spikes += 1;
            }
        }
        // 100 s at 10 Hz: 1000 expected, Poisson σ ≈ 32.
        assert!((850..1150).contains(&spikes), "{spikes}");
    }

    #[test]
    fn exclusive_overlaps() {
        let w = |a, b| Window::new(a, b);
        let stuck = |d, s, win| Fault::new(d, win, FaultKind::Stuck { sensor: s });
        let drop = Fault::new(
            0,
            w(5, 15),
            FaultKind::Dropout {
                sensor: Sensor::Gyr,
            },
        );
        assert!(overlaps_exclusively(
            &stuck(0, Sensor::Gyr, w(0, 10)),
            &drop
        ));
        assert!(!overlaps_exclusively(
            &stuck(0, Sensor::Acc, w(0, 10)),
            &drop
        ));
        assert!(!overlaps_exclusively(
            &stuck(1, Sensor::Gyr, w(0, 10)),
            &drop
        ));
        assert!(!overlaps_exclusively(
            &stuck(0, Sensor::Gyr, w(0, 5)),
            &drop
        ));
        let bias = Fault::new(
            0,
            w(0, 10),
            FaultKind::BiasStep {
                sensor: Sensor::Gyr,
                bias: [0.0; 3],
            },
        );
        assert!(!overlaps_exclusively(&bias, &bias));
        let reset = Fault::new(0, w(0, 10), FaultKind::Reset);
        assert!(overlaps_exclusively(&reset, &reset));
    }
}
